// Medit .mesh (version 2 ASCII, 3-D): Vertices, Tetrahedra (ref -> region), Triangles (ref -> boundary
// tag); other keywords skipped.
//
// Details (added by the implementation):
// - Keywords case-insensitive, numbers may span lines, 1-based; Edges, Corners, Ridges,
//   Required*, Normals, NormalAt*, Tangent*, Identifier/Geometry and a few others are skipped;
//   Quadrilaterals, Hexahedra, Prisms, Pyramids and P2 elements are an error (not representable);
//   a missing End is accepted; anything after End is ignored.
// - Tet vertex order is kept: gmsh's Medit output is already positively oriented.
// - The reader rejects non-finite coordinates (IoError with the line), out-of-range indices and counts
//   that the rest of the file cannot hold (checked before allocating). Mesh::regions and
//   Mesh::boundaries list the ids found, with empty names.
// - The writer writes version 2 with vertex refs 0 and shortest round-trip coordinates, so reading
//   gives the same bits back. A mesh with inconsistent sizes, out-of-range indices or non-finite
//   coordinates is refused (IoError).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

FOXI_API Mesh read_medit(const std::filesystem::path& path);
FOXI_API Mesh parse_medit(std::string_view bytes, const std::string& name);
FOXI_API void write_medit(const Mesh& mesh, const std::filesystem::path& path);

}  // namespace foxi
