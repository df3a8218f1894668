// TetGen .node / .ele / .face and (declared in io_medit.hpp) Medit .mesh.
//
// TetGen: `base` is the path without extension (x.1 for x.1.node, x.1.ele, x.1.face). The .ele's
// first attribute (rounded to an integer) is the region id; the .face's boundary marker the boundary
// tag; .node attributes are ignored; 0- or 1-based numbering as declared by the first index. The
// .face file is optional on reading.
// Medit: Vertices, Tetrahedra (ref -> region), Triangles (ref -> boundary tag); other keywords skipped.
//
// Details (added by the implementation):
// - TetGen records are one per line; '#' starts a comment anywhere; CR, LF and CRLF line ends mix
//   freely. Node numbers must be consecutive from 0 or 1 (the first one decides); .ele and .face
//   indices use that base. 10-node tets keep their 4 corners and 6-node faces their 3 corners (the
//   mid-edge nodes stay, unused). Tet vertex order is kept: TetGen's and gmsh's Medit output are
//   already positively oriented (see io_tetgen.cpp for how that was verified).
// - Medit: keywords case-insensitive, numbers may span lines, 1-based; Edges, Corners, Ridges,
//   Required*, Normals, NormalAt*, Tangent*, Identifier/Geometry and a few others are skipped;
//   Quadrilaterals, Hexahedra, Prisms, Pyramids and P2 elements are an error (not representable);
//   a missing End is accepted; anything after End is ignored.
// - Both readers reject non-finite coordinates (IoError with the line), out-of-range indices, counts
//   that the rest of the file cannot hold (checked before allocating) and data beyond the declared
//   TetGen counts. Mesh::regions and Mesh::boundaries list the ids found, with empty names.
// - Writers: TetGen 1-based, nodes without attributes or markers, the region as the one .ele
//   attribute (none when tet_region is empty), .face always written with one marker column; Medit
//   version 2 with vertex refs 0. Coordinates use shortest round-trip text, so reading gives the
//   same bits back. A mesh with inconsistent sizes, out-of-range indices or non-finite coordinates
//   is refused (IoError). The three TetGen files are committed together: if one cannot be written
//   or renamed into place, none is left (one already renamed is removed again).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/api.hpp"
#include "foxi/model/io_medit.hpp"  // read_medit, write_medit were declared here; kept for includers
#include "foxi/model/mesh.hpp"

namespace foxi {

FOXI_API Mesh read_tetgen(const std::filesystem::path& base);
// In-memory: the .node and .ele texts are required, .face may be empty; names are for messages.
FOXI_API Mesh parse_tetgen(std::string_view node_text, std::string_view ele_text, std::string_view face_text,
                           const std::string& base_name);
FOXI_API void write_tetgen(const Mesh& mesh, const std::filesystem::path& base);

}  // namespace foxi
