// MPVO (Williams' meshed polyhedra visibility ordering): the order by a topological sort of the
// face-adjacency "behind" graph, cycles broken by the farthest power key; the fallback for meshes
// whose power order is not certified.
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

std::vector<std::uint32_t> mpvo_order(const MeshView& mesh, const SphereTable& table, const View& view,
                                      std::span<const std::uint32_t> subset, std::size_t* cycles_broken) {
  const std::size_t n = mesh.tet_count();
  std::vector<std::uint32_t> tets;
  if (subset.empty()) {
    tets.resize(n);
    for (std::size_t i = 0; i < n; ++i) tets[i] = static_cast<std::uint32_t>(i);
  } else {
    tets.assign(subset.begin(), subset.end());
  }
  std::vector<std::uint8_t> member(n, 0);
  for (std::uint32_t t : tets) member[t] = 1;
  const double e[3] = {view.eye[0] - table.origin[0], view.eye[1] - table.origin[1],
                       view.eye[2] - table.origin[2]};
  auto key = [&](std::uint32_t t) {
    const double* c = table.c.data() + 3 * std::size_t(t);
    return view.perspective ? table.s[t] - 2 * (c[0] * e[0] + c[1] * e[1] + c[2] * e[2])
                            : c[0] * view.dir[0] + c[1] * view.dir[1] + c[2] * view.dir[2];
  };
  const FaceAdjacency& adj = face_adjacency(mesh);
  // behind[4t+f]: 1 if the neighbour across face f must be drawn before t (it is behind t).
  std::vector<std::uint32_t> indeg(n, 0);
  std::vector<std::uint8_t> edge_out(4 * n, 0);  // 1: t -> neighbour (t drawn first)
  for (std::uint32_t t : tets) {
    const std::uint32_t* v = mesh.tet.data() + 4 * std::size_t(t);
    for (int f = 0; f < 4; ++f) {
      std::uint32_t nb = adj.neighbour[4 * std::size_t(t) + f];
      if (nb == kNone || !member[nb >> 2]) continue;
      std::uint32_t u = nb >> 2;
      if (u < t) continue;
      int side =
          eye_side(view, node(mesh, v[kFace[f][0]]), node(mesh, v[kFace[f][1]]), node(mesh, v[kFace[f][2]]));
      if (side == 0) continue;
      // t's own vertex is on the negative side: side < 0 means the eye is on t's side (t in front).
      if (side < 0) {
        ++indeg[t];  // u first
        edge_out[(std::size_t(u) << 2) | (nb & 3)] = 1;
      } else {
        ++indeg[u];
        edge_out[4 * std::size_t(t) + f] = 1;
      }
    }
  }
  using Ready = std::pair<double, std::uint32_t>;
  std::priority_queue<Ready> ready;  // largest key (farthest) first
  for (std::uint32_t t : tets)
    if (indeg[t] == 0) ready.emplace(key(t), t);
  // For breaking cycles: all tets by decreasing key.
  std::vector<std::uint32_t> by_key = tets;
  std::sort(by_key.begin(), by_key.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) > key(b); });
  std::size_t scan = 0, cycles = 0;
  std::vector<std::uint8_t> done(n, 0);
  std::vector<std::uint32_t> out;
  out.reserve(tets.size());
  while (out.size() < tets.size()) {
    if (ready.empty()) {
      while (done[by_key[scan]]) ++scan;
      ready.emplace(key(by_key[scan]), by_key[scan]);
      ++cycles;
    }
    std::uint32_t t = ready.top().second;
    ready.pop();
    if (done[t]) continue;
    done[t] = 1;
    out.push_back(t);
    for (int f = 0; f < 4; ++f) {
      if (!edge_out[4 * std::size_t(t) + f]) continue;
      std::uint32_t u = adj.neighbour[4 * std::size_t(t) + f] >> 2;
      if (!done[u] && indeg[u] > 0 && --indeg[u] == 0) ready.emplace(key(u), u);
    }
  }
  if (cycles_broken) *cycles_broken = cycles;
  return out;
}

}  // namespace foxi
