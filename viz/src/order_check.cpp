// Checking an order and its baseline: count_violations (pairs of face neighbours drawn in the wrong
// order) and centroid_order (the centroid-depth sort that VTK's vtkCellCenterDepthSort does).
#include <algorithm>
#include <cstdint>
#include <queue>
#include <utility>
#include <vector>

#include "foxi/model/adjacency.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "order_geometry.hpp"

namespace foxi {

using namespace order_detail;

std::vector<std::uint32_t> centroid_order(const MeshView& mesh, const View& view,
                                          std::span<const std::uint32_t> subset) {
  std::vector<std::uint32_t> tets;
  if (subset.empty()) {
    tets.resize(mesh.tet_count());
    for (std::size_t i = 0; i < tets.size(); ++i) tets[i] = static_cast<std::uint32_t>(i);
  } else {
    tets.assign(subset.begin(), subset.end());
  }
  std::vector<std::pair<double, std::uint32_t>> keyed(tets.size());
  for (std::size_t i = 0; i < tets.size(); ++i) {
    const std::uint32_t* v = mesh.tet.data() + 4 * std::size_t(tets[i]);
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) c[j] += 0.25 * mesh.xyz[3 * std::size_t(v[k]) + j];
    double d;
    if (view.perspective) {
      d = (c[0] - view.eye[0]) * (c[0] - view.eye[0]) + (c[1] - view.eye[1]) * (c[1] - view.eye[1]) +
          (c[2] - view.eye[2]) * (c[2] - view.eye[2]);
    } else {
      d = c[0] * view.dir[0] + c[1] * view.dir[1] + c[2] * view.dir[2];
    }
    keyed[i] = {d, tets[i]};
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t i = 0; i < tets.size(); ++i) tets[i] = keyed[i].second;
  return tets;
}

ViolationReport count_violations(const MeshView& mesh, const View& view,
                                 std::span<const std::uint32_t> order) {
  const std::size_t n = mesh.tet_count();
  std::vector<std::uint32_t> pos(n, kNone);
  for (std::size_t i = 0; i < order.size(); ++i) pos[order[i]] = static_cast<std::uint32_t>(i);
  const FaceAdjacency& adj = face_adjacency(mesh);
  ViolationReport r;
  std::size_t checked[2] = {0, 0}, wrong[2] = {0, 0};
  parallel_for(order.size(), [&](std::size_t b, std::size_t e, int part) {
    for (std::size_t i = b; i < e; ++i) {
      std::uint32_t t = order[i];
      const std::uint32_t* v = mesh.tet.data() + 4 * std::size_t(t);
      for (int f = 0; f < 4; ++f) {
        std::uint32_t nb = adj.neighbour[4 * std::size_t(t) + f];
        if (nb == kNone) continue;
        std::uint32_t u = nb >> 2;
        if (u < t || pos[u] == kNone) continue;
        int side = eye_side(view, node(mesh, v[kFace[f][0]]), node(mesh, v[kFace[f][1]]),
                            node(mesh, v[kFace[f][2]]));
        if (side == 0) continue;
        ++checked[part];
        // side < 0: the eye is on t's side, t is in front and must come after u.
        bool ok = side < 0 ? pos[u] < pos[t] : pos[t] < pos[u];
        if (!ok) ++wrong[part];
      }
    }
  });
  r.pairs_checked = checked[0] + checked[1];
  r.violations = wrong[0] + wrong[1];
  return r;
}

}  // namespace foxi
