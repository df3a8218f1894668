#include "coplanar_facets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "plc_edit.hpp"
#include "union_find.hpp"

namespace foxi::detail {

namespace {

struct Facets {
  const Plc& plc;
  std::size_t polygon_count(std::size_t f) const {
    return plc.facet_polygon_begin[f + 1] - plc.facet_polygon_begin[f];
  }
  std::pair<const std::uint32_t*, std::size_t> polygon(std::size_t g) const {
    const std::uint32_t b = plc.polygon_vertex_begin[g], e = plc.polygon_vertex_begin[g + 1];
    return {plc.polygon_vertices.data() + b, e - b};
  }
  // Calls f(a, b) for each edge of facet f's polygons (a 2-vertex polygon is one edge).
  template <class F>
  void for_each_edge(std::size_t f, F&& fn) const {
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
      const auto [v, n] = polygon(g);
      if (n < 2) continue;
      for (std::size_t i = 0; i < (n == 2 ? 1 : n); ++i) fn(v[i], v[(i + 1) % n]);
    }
  }
};

struct Plane {
  Vec n{};  // unit
  double d = 0;
  bool ok = false;
};

// A point strictly inside the simple polygon `loop` (2D coordinates u, w of the 3D points): near its
// leftmost vertex, which is convex.
Vec inside_point(const Plc& plc, const std::vector<std::uint32_t>& loop, std::size_t u, std::size_t w) {
  auto p2 = [&](std::uint32_t v) {
    return std::array<double, 2>{plc.points[3 * v + u], plc.points[3 * v + w]};
  };
  const std::size_t n = loop.size();
  std::size_t i = 0;
  for (std::size_t k = 1; k < n; ++k) {
    const auto a = p2(loop[k]), b = p2(loop[i]);
    if (a[0] < b[0] || (a[0] == b[0] && a[1] < b[1])) i = k;
  }
  const std::uint32_t va = loop[(i + n - 1) % n], vv = loop[i], vb = loop[(i + 1) % n];
  const auto A = p2(va), V = p2(vv), B = p2(vb);
  auto orient = [](const std::array<double, 2>& p, const std::array<double, 2>& q,
                   const std::array<double, 2>& r) {
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
  };
  const double s = orient(A, V, B) > 0 ? 1 : -1;
  std::uint32_t best = vv;
  double best_dist = -1;
  for (std::uint32_t v : loop) {
    if (v == va || v == vv || v == vb) continue;
    const auto P = p2(v);
    if (s * orient(A, V, P) > 0 && s * orient(V, B, P) > 0 && s * orient(B, A, P) > 0) {
      const double dist = std::abs(orient(A, B, P));
      if (dist > best_dist) {
        best_dist = dist;
        best = v;
      }
    }
  }
  if (best == vv) return scale(add(add(at(plc.points, va), at(plc.points, vv)), at(plc.points, vb)), 1.0 / 3);
  return scale(add(at(plc.points, vv), at(plc.points, best)), 0.5);
}

double loop_area(const Plc& plc, const std::vector<std::uint32_t>& loop, std::size_t u, std::size_t w) {
  double a = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const std::uint32_t p = loop[i], q = loop[(i + 1) % loop.size()];
    a += plc.points[3 * p + u] * plc.points[3 * q + w] - plc.points[3 * q + u] * plc.points[3 * p + w];
  }
  return 0.5 * a;
}

struct MergedFacet {
  std::vector<std::vector<std::uint32_t>> polygons;
  std::vector<double> holes;
};

}  // namespace

CoplanarMerge merge_coplanar_facets(Plc& plc, double relative_tol) {
  CoplanarMerge out;
  const std::size_t nf = plc.facet_count();
  out.facets_before = out.facets_after = nf;
  if (nf == 0 || plc.point_count() == 0) return out;
  const Facets F{plc};
  Vec lo = at(plc.points, 0), hi = lo;
  for (std::uint32_t i = 0; i < plc.point_count(); ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], plc.points[3 * i + k]);
      hi[k] = std::max(hi[k], plc.points[3 * i + k]);
    }
  const double tol = relative_tol * std::sqrt(norm2(sub(hi, lo)));

  // Segment facets whose edges all belong to larger polygons say nothing TetGen does not know.
  std::unordered_set<std::uint64_t> polygon_edges;
  std::vector<char> segment_facet(nf, 0), keep(nf, 1);
  for (std::size_t f = 0; f < nf; ++f) {
    bool only_segments = F.polygon_count(f) > 0;
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
      const auto [v, n] = F.polygon(g);
      if (n != 2) only_segments = false;
      if (n >= 3)
        for (std::size_t i = 0; i < n; ++i) polygon_edges.insert(edge_key(v[i], v[(i + 1) % n]));
    }
    segment_facet[f] = only_segments;
  }
  for (std::size_t f = 0; f < nf; ++f) {
    if (!segment_facet[f]) continue;
    bool redundant = true;
    F.for_each_edge(f, [&](std::uint32_t a, std::uint32_t b) {
      redundant = redundant && polygon_edges.count(edge_key(a, b));
    });
    if (redundant) {
      keep[f] = 0;
      ++out.segment_facets_dropped;
    }
  }

  // Candidates: one polygon of 3+ vertices (and maybe lone points), no holes, planar.
  std::vector<Plane> plane(nf);
  std::vector<std::uint32_t> main_polygon(nf, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    if (!keep[f] || plc.facet_hole_begin[f + 1] != plc.facet_hole_begin[f]) continue;
    int big = 0;
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
      const std::size_t n = F.polygon(g).second;
      if (n == 2) big = 2;
      if (n >= 3) {
        ++big;
        main_polygon[f] = g;
      }
    }
    if (big != 1) continue;
    const auto [v, n] = F.polygon(main_polygon[f]);
    Vec nn{0, 0, 0};
    add_newell_normal(plc.points, v, n, nn);
    const double len = std::sqrt(norm2(nn));
    if (!(len > 0)) continue;
    Plane& p = plane[f];
    p.n = scale(nn, 1 / len);
    p.d = dot(p.n, at(plc.points, v[0]));
    p.ok = true;
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1] && p.ok; ++g) {
      const auto [w, m] = F.polygon(g);
      for (std::size_t i = 0; i < m; ++i)
        if (std::abs(dot(p.n, at(plc.points, w[i])) - p.d) > tol) p.ok = false;
    }
  }

  // Edge -> the kept facets that use it; coplanar candidates across an edge join.
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> edge_facets;
  for (std::size_t f = 0; f < nf; ++f)
    if (keep[f])
      F.for_each_edge(f, [&](std::uint32_t a, std::uint32_t b) {
        auto& list = edge_facets[edge_key(a, b)];
        if (list.empty() || list.back() != f) list.push_back(static_cast<std::uint32_t>(f));
      });
  UnionFind groups(nf);
  for (const auto& [key, list] : edge_facets)
    for (std::size_t i = 0; i < list.size(); ++i)
      for (std::size_t j = i + 1; j < list.size(); ++j) {
        const std::uint32_t a = list[i], b = list[j];
        if (!plane[a].ok || !plane[b].ok || plc.facet_marker[a] != plc.facet_marker[b]) continue;
        if (std::sqrt(norm2(cross(plane[a].n, plane[b].n))) > 1e-9) continue;
        const std::uint32_t vb = plc.polygon_vertices[plc.polygon_vertex_begin[main_polygon[b]]];
        if (std::abs(dot(plane[a].n, at(plc.points, vb)) - plane[a].d) > tol) continue;
        groups.unite(a, b);
      }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> members;
  for (std::uint32_t f = 0; f < nf; ++f)
    if (plane[f].ok && groups.find(f) != f) members[groups.find(f)].push_back(f);

  // Each group's outline.
  std::unordered_map<std::uint32_t, MergedFacet> merged;  // by the group's first facet
  for (auto& [root, rest] : members) {
    std::vector<std::uint32_t> group{root};
    group.insert(group.end(), rest.begin(), rest.end());
    std::unordered_map<std::uint64_t, int> count;
    for (std::uint32_t f : group)
      F.for_each_edge(f, [&](std::uint32_t a, std::uint32_t b) { ++count[edge_key(a, b)]; });
    std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> next;
    bool simple = true;
    MergedFacet m;
    std::unordered_set<std::uint32_t> used;
    for (const auto& [key, c] : count) {
      const std::uint32_t a = std::uint32_t(key >> 32), b = std::uint32_t(key & 0xffffffffu);
      if (c > 2) simple = false;
      if (c == 1) {
        next[a].push_back(b);
        next[b].push_back(a);
      } else if (edge_facets[key].size() > 2) {  // an inner edge some other facet needs
        m.polygons.push_back({a, b});
        used.insert(a);
        used.insert(b);
      }
    }
    for (const auto& [v, nb] : next)
      if (nb.size() != 2) simple = false;
    if (!simple || next.empty()) {
      ++out.groups_skipped;
      continue;
    }
    const Vec& n = plane[root].n;
    std::size_t drop = 0;
    for (std::size_t k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[drop])) drop = k;
    const std::size_t u = (drop + 1) % 3, w = (drop + 2) % 3;
    std::vector<std::vector<std::uint32_t>> loops;
    std::unordered_set<std::uint32_t> visited;
    for (const auto& [start, nb] : next) {
      if (visited.count(start)) continue;
      std::vector<std::uint32_t> loop{start};
      visited.insert(start);
      std::uint32_t prev = start, cur = nb[0];
      while (cur != start) {
        if (!visited.insert(cur).second) {
          simple = false;
          break;
        }
        loop.push_back(cur);
        const auto& c = next[cur];
        const std::uint32_t nxt = c[0] == prev ? c[1] : c[0];
        prev = cur;
        cur = nxt;
      }
      if (!simple) break;
      loops.push_back(std::move(loop));
    }
    std::size_t outer = 0;
    std::vector<double> area(loops.size());
    for (std::size_t i = 0; i < loops.size() && simple; ++i) {
      area[i] = std::abs(loop_area(plc, loops[i], u, w));
      if (!(area[i] > 0)) simple = false;
      if (area[i] > area[outer]) outer = i;
    }
    if (!simple) {
      ++out.groups_skipped;
      continue;
    }
    for (std::size_t i = 0; i < loops.size(); ++i) {
      for (std::uint32_t v : loops[i]) used.insert(v);
      if (i != outer) {
        const Vec h = inside_point(plc, loops[i], u, w);
        m.holes.insert(m.holes.end(), h.begin(), h.end());
      }
    }
    std::vector<std::vector<std::uint32_t>> polygons{loops[outer]};
    for (std::size_t i = 0; i < loops.size(); ++i)
      if (i != outer) polygons.push_back(std::move(loops[i]));
    polygons.insert(polygons.end(), m.polygons.begin(), m.polygons.end());
    // Inner vertices stay in the facet: elsewhere TetGen would take them as points in the volume.
    for (std::uint32_t f : group)
      for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
        const auto [v, cnt] = F.polygon(g);
        for (std::size_t i = 0; i < cnt; ++i)
          if (used.insert(v[i]).second) polygons.push_back({v[i]});
      }
    m.polygons = std::move(polygons);
    for (std::uint32_t f : rest) keep[f] = 0;
    merged[root] = std::move(m);
    ++out.groups;
  }
  if (out.groups == 0 && out.segment_facets_dropped == 0) return out;

  Plc next;
  next.points = plc.points;
  next.holes = plc.holes;
  next.regions = plc.regions;
  auto add_polygon = [&](const std::uint32_t* v, std::size_t n) {
    next.polygon_vertices.insert(next.polygon_vertices.end(), v, v + n);
    next.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(next.polygon_vertices.size()));
  };
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (!keep[f]) continue;
    if (const auto it = merged.find(f); it != merged.end()) {
      for (const auto& poly : it->second.polygons) add_polygon(poly.data(), poly.size());
      next.facet_holes.insert(next.facet_holes.end(), it->second.holes.begin(), it->second.holes.end());
    } else {
      for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
        const auto [v, n] = F.polygon(g);
        add_polygon(v, n);
      }
      next.facet_holes.insert(next.facet_holes.end(),
                              plc.facet_holes.begin() + 3 * std::ptrdiff_t(plc.facet_hole_begin[f]),
                              plc.facet_holes.begin() + 3 * std::ptrdiff_t(plc.facet_hole_begin[f + 1]));
    }
    next.facet_polygon_begin.push_back(static_cast<std::uint32_t>(next.polygon_vertex_begin.size() - 1));
    next.facet_hole_begin.push_back(static_cast<std::uint32_t>(next.facet_holes.size() / 3));
    next.facet_marker.push_back(plc.facet_marker[f]);
  }
  plc = std::move(next);
  out.facets_after = plc.facet_count();
  return out;
}

}  // namespace foxi::detail
