// Validation's checks across tets: folds, non-manifold faces and overlapping tets (see
// validate_overlap.cpp for the argument that they are complete). Internal to validate.cpp.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"

namespace foxi {

struct OverlapReport {
  std::size_t nonmanifold_faces = 0;        // triangles that are a face of three or more tets
  std::size_t folded_faces = 0;             // faces whose two tets lie on the same side of them
  std::size_t crossing_boundary_faces = 0;  // pairs of boundary faces meeting beyond shared vertices/edges
  std::size_t covered_twice = 0;            // probe points inside a tet covered by another tet too
  std::size_t boundary_pieces = 0;          // connected pieces of the boundary (through shared edges)
  std::vector<std::string> examples;        // the first few, with tet numbers

  std::size_t problems() const {
    return nonmanifold_faces + folded_faces + crossing_boundary_faces + covered_twice;
  }
};

// Needs a mesh that passes validation's local checks (indices in range, no repeated vertex, finite,
// no flat tet, in range); the orientation of the tets does not matter. Each check runs only when the
// ones before it found nothing (a fold makes the boundary cross itself too).
OverlapReport check_overlap(const MeshView& mesh, std::size_t max_examples);

}  // namespace foxi
