// Marching tetrahedra (iso_polygon) and the interval tree of the tets' value ranges (TetIntervals);
// the painter of the polygons is in iso_paint.cpp.
#include "foxi/viz/isosurface.hpp"

#include <algorithm>
#include <cmath>

#include "iso_detail.hpp"

namespace foxi {

namespace iso_detail {

void edge_point(const MeshView& mesh, std::uint32_t tet, const double corner[4], double v, int i, int j,
                const double* attr, double xyz[3], double* attr_out) {
  const std::uint32_t* n = &mesh.tet[4 * std::size_t(tet)];
  if (n[i] > n[j]) std::swap(i, j);  // the same bits from every tet sharing the edge
  const double t = (v - corner[i]) / (corner[j] - corner[i]);
  const double* a = &mesh.xyz[3 * std::size_t(n[i])];
  const double* b = &mesh.xyz[3 * std::size_t(n[j])];
  for (int k = 0; k < 3; ++k) xyz[k] = a[k] + t * (b[k] - a[k]);
  if (attr != nullptr) *attr_out = attr[i] + t * (attr[j] - attr[i]);
}

}  // namespace iso_detail

IsoPolygon iso_polygon(const MeshView& mesh, std::uint32_t tet, const double corner[4], double v,
                       const double* attr) {
  IsoPolygon p;
  int hot[4], cold[4], nh = 0, nc = 0;
  for (int k = 0; k < 4; ++k) {
    if (std::isnan(corner[k])) return p;
    (corner[k] >= v ? hot[nh++] : cold[nc++]) = k;
  }
  if (nh == 0 || nc == 0) return p;
  int edges[4][2];
  if (nh == 1 || nc == 1) {
    const int lone = nh == 1 ? hot[0] : cold[0];
    const int* others = nh == 1 ? cold : hot;
    for (int e = 0; e < 3; ++e) edges[e][0] = lone, edges[e][1] = others[e];
    p.count = 3;
  } else {
    // Consecutive edges share a corner (h0, c1, h1, c0), so they bound one face: the quad is cyclic.
    const int q[4][2] = {{hot[0], cold[0]}, {hot[0], cold[1]}, {hot[1], cold[1]}, {hot[1], cold[0]}};
    for (int e = 0; e < 4; ++e) edges[e][0] = q[e][0], edges[e][1] = q[e][1];
    p.count = 4;
  }
  for (int e = 0; e < p.count; ++e)
    iso_detail::edge_point(mesh, tet, corner, v, edges[e][0], edges[e][1], attr, p.xyz[e], &p.attr[e]);
  // The plane's normal (the diagonals' cross product for a quad), turned toward increasing values:
  // along the linear field's gradient g, g . (x_max - x_min) = max - min > 0.
  double u[3], w[3], n[3];
  const int a = p.count == 4 ? 1 : 0;
  for (int k = 0; k < 3; ++k) {
    u[k] = p.xyz[2][k] - p.xyz[0][k];
    w[k] = p.xyz[p.count == 4 ? 3 : 1][k] - p.xyz[a][k];
  }
  n[0] = u[1] * w[2] - u[2] * w[1];
  n[1] = u[2] * w[0] - u[0] * w[2];
  n[2] = u[0] * w[1] - u[1] * w[0];
  int kmax = 0, kmin = 0;
  for (int k = 1; k < 4; ++k) {
    if (corner[k] > corner[kmax]) kmax = k;
    if (corner[k] < corner[kmin]) kmin = k;
  }
  const double* xmax = &mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(tet) + std::size_t(kmax)])];
  const double* xmin = &mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(tet) + std::size_t(kmin)])];
  double s = 0, len = 0;
  for (int k = 0; k < 3; ++k) {
    s += n[k] * (xmax[k] - xmin[k]);
    len += n[k] * n[k];
  }
  len = std::sqrt(len);
  if (len > 0)
    for (int k = 0; k < 3; ++k) p.hot[k] = (s < 0 ? -n[k] : n[k]) / len;
  return p;
}

TetIntervals::TetIntervals(std::span<const double> corner_values) : tet_count_(corner_values.size() / 4) {
  // Each tet with finite corners and min < max is an interval (min, max]; the others cross nothing.
  std::vector<std::uint32_t> items;
  std::vector<double> lo(tet_count_), hi(tet_count_);
  items.reserve(tet_count_);
  max_sorted_.reserve(tet_count_);
  for (std::size_t t = 0; t < tet_count_; ++t) {
    const double* c = &corner_values[4 * t];
    if (std::isnan(c[0]) || std::isnan(c[1]) || std::isnan(c[2]) || std::isnan(c[3])) continue;
    lo[t] = std::min({c[0], c[1], c[2], c[3]});
    hi[t] = std::max({c[0], c[1], c[2], c[3]});
    max_sorted_.push_back({hi[t], std::uint32_t(t)});
    if (lo[t] < hi[t]) items.push_back(std::uint32_t(t));
  }
  std::sort(max_sorted_.begin(), max_sorted_.end(),
            [](const Entry& a, const Entry& b) { return a.key < b.key; });
  by_min_.reserve(items.size());
  by_max_.reserve(items.size());
  // Centred interval tree: a node's centre is the median of its intervals' midpoints; the intervals
  // holding it (min < c <= max) stay at the node, those wholly below (max < c) go left, those wholly
  // above (min >= c) go right: each side gets at most half, so the depth is O(log n).
  std::vector<double> mid;
  auto build = [&](auto& self, std::vector<std::uint32_t>& set) -> std::uint32_t {
    if (set.empty()) return kNone;
    mid.resize(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) mid[i] = 0.5 * lo[set[i]] + 0.5 * hi[set[i]];
    std::nth_element(mid.begin(), mid.begin() + std::ptrdiff_t(mid.size() / 2), mid.end());
    const double c = mid[mid.size() / 2];
    std::vector<std::uint32_t> left, right;
    const std::uint32_t node = std::uint32_t(nodes_.size());
    nodes_.push_back({c, std::uint32_t(by_min_.size()), 0, kNone, kNone});
    for (std::uint32_t t : set) {
      if (hi[t] < c) {
        left.push_back(t);
      } else if (lo[t] >= c) {
        right.push_back(t);
      } else {
        by_min_.push_back({lo[t], t});
        by_max_.push_back({hi[t], t});
      }
    }
    const std::uint32_t b = nodes_[node].begin, e = std::uint32_t(by_min_.size());
    nodes_[node].end = e;
    std::sort(by_min_.begin() + b, by_min_.begin() + e,
              [](const Entry& x, const Entry& y) { return x.key < y.key; });
    std::sort(by_max_.begin() + b, by_max_.begin() + e,
              [](const Entry& x, const Entry& y) { return x.key > y.key; });
    std::vector<std::uint32_t>().swap(set);
    const std::uint32_t l = self(self, left);
    const std::uint32_t r = self(self, right);
    nodes_[node].left = l;
    nodes_[node].right = r;
    return node;
  };
  build(build, items);
}

std::vector<std::uint32_t> crossing_scan(std::span<const double> corner_values, double v) {
  std::vector<std::uint32_t> out;
  for (std::size_t t = 0; 4 * t + 3 < corner_values.size(); ++t) {
    const double* c = &corner_values[4 * t];
    const bool nan = std::isnan(c[0]) || std::isnan(c[1]) || std::isnan(c[2]) || std::isnan(c[3]);
    if (!nan && std::min({c[0], c[1], c[2], c[3]}) < v && v <= std::max({c[0], c[1], c[2], c[3]}))
      out.push_back(std::uint32_t(t));
  }
  return out;
}

void TetIntervals::crossing(double v, std::vector<std::uint32_t>& out) const {
  if (std::isnan(v) || nodes_.empty()) return;
  std::uint32_t node = 0;
  while (node != kNone) {
    const Node& n = nodes_[node];
    if (v < n.centre) {  // every interval here has max >= centre > v: those with min < v cross
      for (std::uint32_t i = n.begin; i < n.end && by_min_[i].key < v; ++i) out.push_back(by_min_[i].tet);
      node = n.left;
    } else {  // every interval here has min < centre <= v: those with max >= v cross
      for (std::uint32_t i = n.begin; i < n.end && by_max_[i].key >= v; ++i) out.push_back(by_max_[i].tet);
      node = n.right;
    }
  }
}

void TetIntervals::crossing_any(std::span<const double> values, std::vector<std::uint32_t>& out) const {
  const std::size_t first = out.size();
  for (double v : values) crossing(v, out);
  if (values.size() > 1) {
    std::sort(out.begin() + std::ptrdiff_t(first), out.end());
    out.erase(std::unique(out.begin() + std::ptrdiff_t(first), out.end()), out.end());
  }
}

void TetIntervals::reaching(double v, std::vector<std::uint32_t>& out) const {
  if (std::isnan(v)) return;
  auto it = std::lower_bound(max_sorted_.begin(), max_sorted_.end(), v,
                             [](const Entry& e, double x) { return e.key < x; });
  for (; it != max_sorted_.end(); ++it) out.push_back(it->tet);
}

}  // namespace foxi
