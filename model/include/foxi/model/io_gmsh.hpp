// Gmsh .msh 2.2 and 4.1, ASCII and binary.
//
// Read: nodes; 4-node tets (type 4) become tets, 3-node triangles (type 2) boundary triangles;
// second-order 10-node tets (11) and 6-node triangles (9) are read as their corners (the mid-edge
// nodes stay in the node list, unused); points and lines (15, 1, 8) are skipped; any other element
// type is an error naming it. Physical groups: the first
// tag of a tet is its region id, of a triangle its boundary tag ($PhysicalNames give the names).
// $NodeData / $ElementData become fields (several time steps of one name become one field's steps).
// Write: files that gmsh itself loads (4.1 with an $Entities section).
//
// Reading details: nodes are numbered densely in file order (tags may be sparse, unordered, 64-bit
// in 4.1); tets and triangles keep file order. An element with no physical group (2.2: no tags or
// tag 0; 4.1: its entity has no physical tag, or there is no $Entities) gets region / boundary 0.
// NaN and Inf coordinates are accepted (validate() reports them); non-numbers are errors. Binary
// files must be little-endian with 8-byte size_t (byte-swapped files are rejected). $ElementData
// values of non-tet elements are ignored; entities a field does not list are NaN. Partitioned files
// ($PartitionedEntities) are rejected; other unknown sections are skipped.
// Writing details: node tags 1..n in mesh order, tet i is element i+1, triangles follow; one
// $NodeData/$ElementData block per step (entities whose values are all NaN are left out). Field
// units and Region::material are not stored; a field without step values gets step value 0.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

struct GmshWriteOptions {
  int version = 41;  // 22 or 41
  bool binary = true;
};

FOXI_API Mesh read_gmsh(const std::filesystem::path& path);
// Parses a whole file held in memory; `name` is used in error messages.
FOXI_API Mesh parse_gmsh(std::string_view bytes, const std::string& name);
FOXI_API void write_gmsh(const Mesh& mesh, const std::filesystem::path& path,
                         const GmshWriteOptions& options = {});

}  // namespace foxi
