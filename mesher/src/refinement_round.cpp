#include "refinement_round.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

#include "plc_edit.hpp"

namespace foxi::detail {

std::optional<DelaunayCertificate> RefinementRounds::run(std::size_t it, Plc& current, Mesh& mesh,
                                                         bool mesh_given) {
  try {
    if (it > 0 || !mesh_given) {
      MeshParams p = params_;
      // A later round's PLC is the first one's with some points more: a run that takes many times
      // longer is TetGen looping, not working.
      if (it > 0) p.time_limit = std::max(30.0, 20 * first_seconds_);
      const auto t0 = std::chrono::steady_clock::now();
      mesh = mesh_plc(current, p, &rep_.tetgen);
      if (it == 0)
        first_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    if (it == 0) first_volumes_ = region_volumes(mesh);
    if (it > 0 && !same_region_volumes(first_volumes_, region_volumes(mesh)))
      throw MesherError(2, "regions lost");
  } catch (const MesherError& e) {
    if (it == 0 || e.tetgen_code() != 2) throw;
    current = std::move(previous_);
    mesh = std::move(previous_mesh_);
    rep_.tetgen_failed = true;
    return std::nullopt;
  }
  CertificateOptions copt;
  copt.max_listed = std::numeric_limits<std::size_t>::max();
  const auto c0 = std::chrono::steady_clock::now();
  DelaunayCertificate cert = compute_delaunay_certificate(mesh, copt);
  rep_.certificate_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
  rep_.violations.push_back(cert.violating_tet_count);
  if (it == 0) {
    rep_.first_mesh_points = mesh.node_count();
    rep_.first_mesh_violations = cert.violating_tet_count;
  }
  rep_.delaunay = cert.delaunay;
  return cert;
}

}  // namespace foxi::detail
