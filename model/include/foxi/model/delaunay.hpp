// The Delaunay certificate: every tet's circumsphere is empty of every mesh vertex (vertices on the
// sphere are allowed), decided with CGAL's exact predicates. For meshes with vertex weights the
// orthosphere is used instead (regular triangulation: no vertex has negative power distance to any
// tet's orthosphere). The check is global (a spatial grid of the vertices), not only across faces,
// so non-convex and disconnected meshes are certified correctly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "foxi/model/mesh.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

struct DelaunayCertificate {
  bool delaunay = false;                   // true when no tet is violated and none is degenerate
  bool weighted = false;                   // orthospheres were used
  std::size_t tets_checked = 0;
  std::size_t violating_tet_count = 0;     // tets with a vertex strictly inside
  std::vector<std::uint32_t> violating_tets;  // their indices, ascending (at most max_listed)
  std::size_t degenerate_tet_count = 0;    // zero-volume tets: no sphere, counted as violations
  double max_relative_depth = 0;           // max over violations of (r - |q - c|) / r (unweighted)
  bool cancelled = false;
};

struct CertificateOptions {
  std::size_t max_listed = 1000;
  ProgressFn progress;                     // may be empty; returning false cancels
};

DelaunayCertificate compute_delaunay_certificate(const Mesh& mesh, const CertificateOptions& options = {});
// Cached on the mesh (computed with default options).
const DelaunayCertificate& delaunay_certificate(const Mesh& mesh);

}  // namespace foxi
