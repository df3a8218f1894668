// Validation of a mesh database: what a reader cannot see locally and a user must be told.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"

namespace foxi {

struct ValidationReport {
  std::string size_problem;            // from check_sizes(); when not empty nothing else is checked
  bool no_tets = false;                // the mesh has no tets: nothing to order, draw or solve
  std::size_t index_out_of_range = 0;  // tets and boundary triangles with an index >= node_count
  std::size_t repeated_vertex = 0;     // tets or triangles naming one node twice
  std::size_t nonfinite_nodes = 0;     // NaN or Inf coordinates or weight
  std::size_t zero_volume = 0;         // exactly flat tets (exact orientation predicate)
  std::size_t inverted = 0;            // negatively oriented tets (re-oriented by repair)
  std::size_t duplicate_tets = 0;      // tets with the same four nodes as an earlier tet
  std::size_t duplicate_nodes = 0;     // nodes used by tets at the very point of an earlier such node
  // Tets whose geometry leaves the range where foxi's arithmetic holds it: 6 x volume, the
  // circumcentre's terms or the circumradius^2 overflow, or 6 x volume is below 2^-969 (it has
  // underflowed or lost its precision), e.g. coordinates near 1e300 or 1e-300 or scaled by 1e154;
  // or the circumsphere reaches beyond 1e24 from the bounding box's centre, or the whole mesh is
  // less than 1e-12 across (the visibility order's error bounds are floats). Volumes, gradients,
  // circumspheres and visibility keys of such tets would be inf, 0, NaN or wrongly bounded.
  std::size_t out_of_range = 0;
  std::size_t unused_nodes = 0;  // nodes no tet uses
  // Tets that cover the same space (checked only when nothing above is wrong): faces shared by three
  // or more tets, faces whose two tets lie on the same side (folds), boundary faces that cross, and
  // points covered by two tets (a mesh nested inside another). Such a mesh is not a mesh: the
  // visibility order, the painter and the solvers' assembly all assume each point is in one tet.
  std::size_t overlapping = 0;
  std::vector<std::string> messages;  // first few problems, human-readable, with element numbers

  // No error that makes the mesh unusable (unused nodes and inverted tets, which every command
  // re-orients, are only warnings).
  bool ok() const {
    return size_problem.empty() && !no_tets && index_out_of_range == 0 && repeated_vertex == 0 &&
           nonfinite_nodes == 0 && zero_volume == 0 && duplicate_tets == 0 && duplicate_nodes == 0 &&
           out_of_range == 0 && overlapping == 0;
  }
  // Nothing to say at all.
  bool clean() const { return ok() && inverted == 0 && unused_nodes == 0; }
};

// Checks without changing anything. Positive orientation means det[p1-p0, p2-p0, p3-p0] > 0 (CGAL's
// orientation(p0,p1,p2,p3) == POSITIVE). At most 20 messages.
FOXI_API ValidationReport validate(const Mesh& mesh);
// The same for a host's arrays (mesh_view.hpp): its sizes checked by check_sizes(MeshView).
FOXI_API ValidationReport validate(const MeshView& mesh);
// Checks and re-orients inverted tets (swapping their last two vertices); the report counts them
// (as found before the repair). Calls invalidate_derived(mesh) when it changed anything.
FOXI_API ValidationReport validate_and_repair(Mesh& mesh);

// One line per kind of problem found ("3 inverted tets (negative orientation)", ...), in the order
// of the report's fields; empty when the report is clean. For the programs to print.
FOXI_API std::vector<std::string> describe(const ValidationReport& report);

}  // namespace foxi
