// Gmsh .msh 2.2 and 4.1, ASCII and binary.
//
// Read: nodes; 4-node tets (type 4) become tets, 3-node triangles (type 2) boundary triangles; points
// and lines are skipped; any other element type is an error naming it. Physical groups: the first
// tag of a tet is its region id, of a triangle its boundary tag ($PhysicalNames give the names).
// $NodeData / $ElementData become fields (several time steps of one name become one field's steps).
// Write: files that gmsh itself loads (4.1 with an $Entities section).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/model/mesh.hpp"

namespace foxi {

struct GmshWriteOptions {
  int version = 41;    // 22 or 41
  bool binary = true;
};

Mesh read_gmsh(const std::filesystem::path& path);
// Parses a whole file held in memory; `name` is used in error messages.
Mesh parse_gmsh(std::string_view bytes, const std::string& name);
void write_gmsh(const Mesh& mesh, const std::filesystem::path& path, const GmshWriteOptions& options = {});

}  // namespace foxi
