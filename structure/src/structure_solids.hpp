// The structure builder's general path (not a public header): every part as a closed triangle
// surface, carved by the later parts with CGAL's corefinement booleans, the carved solids corefined
// pairwise so that shared areas carry the same edges, each shared area emitted once. See
// structure_solids.cpp and structure.hpp.
#pragma once

#include <cstdint>
#include <string>

#include "foxi/model/model_file.hpp"
#include "foxi/model/structure.hpp"

namespace foxi {

Structure build_structure_from_solids(const Model& model, const ProgressFn& progress);

// The 1-based marker of the boundary `name` in s.boundary_names, appended (area 0) if new.
std::int32_t boundary_marker(Structure& s, const std::string& name);

}  // namespace foxi
