// Validation of a mesh database: what a reader cannot see locally and a user must be told.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "foxi/model/mesh.hpp"

namespace foxi {

struct ValidationReport {
  std::string size_problem;            // from check_sizes(); when not empty nothing else is checked
  std::size_t index_out_of_range = 0;  // tets and boundary triangles with an index >= node_count
  std::size_t repeated_vertex = 0;     // tets or triangles naming one node twice
  std::size_t nonfinite_nodes = 0;     // NaN or Inf coordinates or weight
  std::size_t zero_volume = 0;         // exactly flat tets (exact orientation predicate)
  std::size_t inverted = 0;            // negatively oriented tets (re-oriented by repair)
  std::size_t unused_nodes = 0;        // nodes no tet uses
  std::vector<std::string> messages;   // first few problems, human-readable, with element numbers

  // No error that makes the mesh unusable (unused nodes and re-oriented tets are only warnings).
  bool ok() const {
    return size_problem.empty() && index_out_of_range == 0 && repeated_vertex == 0 &&
           nonfinite_nodes == 0 && zero_volume == 0;
  }
};

// Checks without changing anything. Positive orientation means det[p1-p0, p2-p0, p3-p0] > 0 (CGAL's
// orientation(p0,p1,p2,p3) == POSITIVE). At most 20 messages.
ValidationReport validate(const Mesh& mesh);
// Checks and re-orients inverted tets (swapping their last two vertices); the report counts them
// (as found before the repair). Calls invalidate_derived(mesh) when it changed anything.
ValidationReport validate_and_repair(Mesh& mesh);

}  // namespace foxi
