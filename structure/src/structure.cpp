// Parts -> PLC by z slabs and planar subdivisions (see structure.hpp).
//
// Every part is a set of vertical prisms. The z values of all prism tops and bottoms cut space into
// slabs. In slab k, the footprint edges of the prisms active there are split where they meet (CGAL's
// surface sweep, exact constructions) and form a planar subdivision; every bounded face is owned by
// the last part whose prism covers it. At level z, the subdivision of the edges of both neighbouring
// slabs gives the horizontal facets: a face whose owner below differs from its owner above becomes a
// facet (outer boundary, inner boundaries with hole points). An edge of slab k whose two faces have
// different owners becomes a vertical facet; its bottom and top edges carry every vertex that the
// level subdivisions put on them, so all facets meet along whole segments (a conforming PLC).
// (CGAL's Arrangement_2 would give the faces too, but its handles make UBSan report bad downcasts,
// CGAL issues #5241 and #9140, so the faces are traced here from the swept segments.)
#include "foxi/model/structure.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Surface_sweep_2_algorithms.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <tuple>

#include "foxi/model/io_error.hpp"
#include "foxi/model/surfaces.hpp"
#include "structure_solids.hpp"

namespace foxi {

namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Traits = CGAL::Arr_segment_traits_2<K>;
using Pt = K::Point_2;
using XY = std::pair<double, double>;

struct Item {
  std::size_t part;
  const Prism* prism;
  std::size_t z0, z1;  // level indices
};

// Whether (x, y) is inside the closed polygon of vertices at(0) .. at(n - 1) (either orientation,
// convex or not), by the crossing number. Only called with points well inside a face of a
// subdivision, so points on the outline do not occur.
template <class At>
bool inside_ring(std::size_t n, At at, double x, double y) {
  bool in = false;
  for (std::size_t i = 0; i < n; ++i) {
    const XY a = at(i), b = at((i + 1) % n);
    if ((a.second > y) != (b.second > y) &&
        x < a.first + (y - a.second) * (b.first - a.first) / (b.second - a.second))
      in = !in;
  }
  return in;
}

bool inside_polygon(const std::vector<double>& xy, double x, double y) {  // 2 doubles per vertex
  return inside_ring(
      xy.size() / 2,
      [&](std::size_t i) {
        return XY{xy[2 * i], xy[2 * i + 1]};
      },
      x, y);
}

// A planar subdivision by segments: vertices, edges (halfedge 2e runs u -> v, 2e + 1 back; each has
// its face on the left, -1 for the unbounded face) and bounded faces (rings of halfedges: the outer
// one counter-clockwise first, then the inner ones), each with a point inside and its area.
struct Plane {
  std::vector<XY> vertex;
  std::vector<XY> sorted_vertex;
  std::vector<std::uint32_t> he_from;  // source vertex of each halfedge
  std::vector<long> he_face;
  struct Face {
    std::vector<std::vector<std::uint32_t>> rings;  // halfedges
    double area = 0;
    XY inner;
  };
  std::vector<Face> faces;
  std::size_t edge_count() const { return he_from.size() / 2; }
  const XY& from(std::uint32_t h) const { return vertex[he_from[h]]; }
};

double cycle_area(const Plane& pl, const std::vector<std::uint32_t>& ring) {
  double a = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const XY& p = pl.from(ring[i]);
    const XY& q = pl.from(ring[(i + 1) % ring.size()]);
    a += p.first * q.second - q.first * p.second;
  }
  return 0.5 * a;
}

bool in_ring(const Plane& pl, const std::vector<std::uint32_t>& ring, double x, double y) {
  return inside_ring(
      ring.size(), [&](std::size_t i) { return pl.from(ring[i]); }, x, y);
}

void build_plane(Plane& pl, const std::vector<const Prism*>& prisms) {
  std::vector<Traits::Curve_2> segs;
  for (const Prism* p : prisms) {
    const std::size_t n = p->xy.size() / 2;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      segs.emplace_back(Pt(p->xy[2 * i], p->xy[2 * i + 1]), Pt(p->xy[2 * j], p->xy[2 * j + 1]));
    }
  }
  std::vector<Traits::X_monotone_curve_2> sub;
  CGAL::compute_subcurves(segs.begin(), segs.end(), std::back_inserter(sub));
  std::map<Pt, std::uint32_t> ids;
  auto id = [&](const Pt& p) {
    auto [it, fresh] = ids.emplace(p, static_cast<std::uint32_t>(pl.vertex.size()));
    if (fresh) pl.vertex.emplace_back(CGAL::to_double(p.x()), CGAL::to_double(p.y()));
    return it->second;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, bool> seen;
  for (const auto& s : sub) {
    const std::uint32_t u = id(s.source()), v = id(s.target());
    if (u == v || !seen.emplace(std::minmax(u, v), true).second) continue;
    pl.he_from.push_back(u);
    pl.he_from.push_back(v);
  }
  pl.sorted_vertex = pl.vertex;
  std::sort(pl.sorted_vertex.begin(), pl.sorted_vertex.end());
  const std::size_t H = pl.he_from.size(), V = pl.vertex.size();
  auto to = [&](std::size_t h) { return pl.he_from[h ^ 1]; };
  // outgoing halfedges around each vertex, counter-clockwise
  std::vector<std::vector<std::uint32_t>> out(V);
  for (std::size_t h = 0; h < H; ++h) out[pl.he_from[h]].push_back(static_cast<std::uint32_t>(h));
  auto angle = [&](std::uint32_t h) {
    const XY& a = pl.vertex[pl.he_from[h]];
    const XY& b = pl.vertex[to(h)];
    return std::atan2(b.second - a.second, b.first - a.first);
  };
  std::vector<std::uint32_t> pos(H);
  for (auto& o : out) {
    std::sort(o.begin(), o.end(), [&](std::uint32_t a, std::uint32_t b) { return angle(a) < angle(b); });
    for (std::size_t i = 0; i < o.size(); ++i) pos[o[i]] = static_cast<std::uint32_t>(i);
  }
  // next halfedge with the same face on the left: at the target, the first one clockwise from the twin
  auto next = [&](std::uint32_t h) {
    const std::uint32_t t = h ^ 1u;
    const auto& o = out[pl.he_from[t]];
    return o[(pos[t] + o.size() - 1) % o.size()];
  };
  // connected components (union-find over vertices)
  std::vector<std::uint32_t> comp(V);
  std::iota(comp.begin(), comp.end(), 0u);
  std::function<std::uint32_t(std::uint32_t)> find = [&](std::uint32_t x) {
    while (comp[x] != x) x = comp[x] = comp[comp[x]];
    return x;
  };
  for (std::size_t h = 0; h < H; h += 2) comp[find(pl.he_from[h])] = find(pl.he_from[h + 1]);
  // cycles
  std::vector<std::vector<std::uint32_t>> cycles;
  std::vector<long> cycle_of(H, -1);
  for (std::uint32_t h = 0; h < H; ++h) {
    if (cycle_of[h] >= 0) continue;
    std::vector<std::uint32_t> c;
    std::uint32_t e = h;
    do {
      cycle_of[e] = static_cast<long>(cycles.size());
      c.push_back(e);
      e = next(e);
    } while (e != h && c.size() <= H);
    cycles.push_back(std::move(c));
  }
  std::vector<long> face_of_cycle(cycles.size(), -1);
  std::vector<double> area(cycles.size());
  for (std::size_t c = 0; c < cycles.size(); ++c) {
    area[c] = cycle_area(pl, cycles[c]);
    if (area[c] > 0) {
      face_of_cycle[c] = static_cast<long>(pl.faces.size());
      pl.faces.emplace_back();
      pl.faces.back().rings.push_back(cycles[c]);
    }
  }
  // each clockwise cycle bounds a hole of the smallest face (of another component) around it
  for (std::size_t c = 0; c < cycles.size(); ++c) {
    if (area[c] > 0) continue;
    const std::uint32_t v0 = pl.he_from[cycles[c][0]];
    const XY& p = pl.vertex[v0];
    long best = -1;
    for (std::size_t d = 0; d < cycles.size(); ++d) {
      if (area[d] <= 0 || find(pl.he_from[cycles[d][0]]) == find(v0)) continue;
      if ((best < 0 || area[d] < area[static_cast<std::size_t>(best)]) &&
          in_ring(pl, cycles[d], p.first, p.second))
        best = static_cast<long>(d);
    }
    if (best < 0) continue;
    face_of_cycle[c] = face_of_cycle[static_cast<std::size_t>(best)];
    pl.faces[static_cast<std::size_t>(face_of_cycle[c])].rings.push_back(cycles[c]);
  }
  pl.he_face.resize(H);
  for (std::size_t h = 0; h < H; ++h) pl.he_face[h] = face_of_cycle[static_cast<std::size_t>(cycle_of[h])];
  // area and a point inside each face: from the middle of the longest outer edge, halfway to the
  // nearest boundary crossed by the inward normal (the face lies left of its outer boundary)
  for (auto& f : pl.faces) {
    for (const auto& r : f.rings) f.area += cycle_area(pl, r);  // inner rings are negative
    const auto& o = f.rings[0];
    std::size_t best = 0;
    double best_len = -1;
    for (std::size_t i = 0; i < o.size(); ++i) {
      const XY& p = pl.from(o[i]);
      const XY& q = pl.vertex[to(o[i])];
      const double len = std::hypot(q.first - p.first, q.second - p.second);
      if (len > best_len) best_len = len, best = i;
    }
    const XY& p = pl.from(o[best]);
    const XY& q = pl.vertex[to(o[best])];
    const double mx = 0.5 * (p.first + q.first), my = 0.5 * (p.second + q.second);
    const double nx = -(q.second - p.second) / best_len, ny = (q.first - p.first) / best_len;
    double tmin = 1e300;
    for (const auto& r : f.rings)
      for (std::uint32_t h : r) {
        if (h == o[best]) continue;
        const XY& a = pl.from(h);
        const XY& b = pl.vertex[to(h)];
        const double dx = b.first - a.first, dy = b.second - a.second;
        const double den = nx * (-dy) - ny * (-dx);
        if (den == 0) continue;
        const double rx = a.first - mx, ry = a.second - my;
        const double t = (rx * (-dy) - ry * (-dx)) / den;
        const double s = (nx * ry - ny * rx) / den;
        if (t > 1e-12 * best_len && s >= -1e-12 && s <= 1 + 1e-12) tmin = std::min(tmin, t);
      }
    if (tmin > 1e299) tmin = best_len;  // cannot happen for a closed face; keep a finite point
    f.inner = {mx + 0.5 * tmin * nx, my + 0.5 * tmin * ny};
  }
}

class Builder {
 public:
  explicit Builder(const Model& m) : m_(m) {}

  Structure build() {
    collect();
    const std::size_t L = levels_.size();
    std::vector<std::vector<std::size_t>> active(L ? L - 1 : 0);
    for (std::size_t i = 0; i < items_.size(); ++i)
      for (std::size_t k = items_[i].z0; k < items_[i].z1; ++k) active[k].push_back(i);
    s_.part_volume.assign(m_.parts.size(), 0);

    // the level arrangements (edges of both neighbouring slabs) and their horizontal facets
    static const std::vector<std::size_t> kEmpty;
    std::vector<Plane> level(L);
    for (std::size_t z = 0; z < L; ++z) {
      const auto& below = z > 0 ? active[z - 1] : kEmpty;
      const auto& above = z + 1 < L ? active[z] : kEmpty;
      std::vector<const Prism*> prisms;
      for (std::size_t i : below) prisms.push_back(items_[i].prism);
      for (std::size_t i : above) prisms.push_back(items_[i].prism);
      Plane& pl = level[z];
      build_plane(pl, prisms);
      for (std::size_t fi = 0; fi < pl.faces.size(); ++fi) {
        const Plane::Face& f = pl.faces[fi];
        const auto [x, y] = f.inner;
        const long lb = label(x, y, below), la = label(x, y, above);
        if (lb == la) continue;
        const std::string name = lb < 0   ? part_name(la) + ".bottom"
                                 : la < 0 ? part_name(lb) + ".top"
                                          : interface_name(lb, la);
        const std::int32_t marker = marker_of(name);
        s_.plc.facet_polygon_begin.push_back(s_.plc.facet_polygon_begin.back());
        add_ring(pl, f.rings[0], z);
        for (std::size_t r = 1; r < f.rings.size(); ++r) {
          add_ring(pl, f.rings[r], z);
          // hole points: inside each face across this inner boundary (several where the boundary
          // pinches, e.g. around two footprints that touch at a corner)
          std::vector<long> across;
          for (std::uint32_t h : f.rings[r]) {
            const long t = pl.he_face[h ^ 1u];
            if (t >= 0 && t != static_cast<long>(fi) &&
                std::find(across.begin(), across.end(), t) == across.end())
              across.push_back(t);
          }
          for (long t : across) {
            const XY hp = pl.faces[static_cast<std::size_t>(t)].inner;
            s_.plc.facet_holes.insert(s_.plc.facet_holes.end(), {hp.first, hp.second, levels_[z]});
          }
        }
        s_.plc.facet_marker.push_back(marker);
        s_.plc.facet_hole_begin.push_back(static_cast<std::uint32_t>(s_.plc.facet_holes.size() / 3));
        s_.boundary_area[static_cast<std::size_t>(marker - 1)] += f.area;
      }
    }

    // the slab arrangements: owners, volumes, region seeds and walls
    for (std::size_t k = 0; k + 1 < L; ++k) {
      std::vector<const Prism*> prisms;
      for (std::size_t i : active[k]) prisms.push_back(items_[i].prism);
      Plane pl;
      build_plane(pl, prisms);
      const double dz = levels_[k + 1] - levels_[k];
      std::vector<long> owner(pl.faces.size());
      for (std::size_t fi = 0; fi < pl.faces.size(); ++fi) {
        const auto [x, y] = pl.faces[fi].inner;
        const long o = label(x, y, active[k]);
        owner[fi] = o;
        if (o < 0) continue;
        s_.part_volume[static_cast<std::size_t>(o)] += pl.faces[fi].area * dz;
        RegionSeed seed;
        seed.point[0] = x;
        seed.point[1] = y;
        seed.point[2] = 0.5 * (levels_[k] + levels_[k + 1]);
        seed.id = static_cast<std::int32_t>(o + 1);
        s_.plc.regions.push_back(seed);
      }
      auto owner_of = [&](long f) { return f < 0 ? -1L : owner[static_cast<std::size_t>(f)]; };
      for (std::uint32_t e = 0; e < pl.edge_count(); ++e) {
        const long a = owner_of(pl.he_face[2 * e]), b = owner_of(pl.he_face[2 * e + 1]);
        if (a == b) continue;
        const std::string name = a < 0   ? part_name(b) + ".side"
                                 : b < 0 ? part_name(a) + ".side"
                                         : interface_name(a, b);
        const std::int32_t marker = marker_of(name);
        const auto [px, py] = pl.from(2 * e);
        const auto [qx, qy] = pl.from(2 * e + 1);
        // bottom p -> q with the level-k vertices on it, top q -> p with the level-(k+1) ones
        std::vector<std::uint32_t> poly;
        for (const auto& v : on_segment(level[k], px, py, qx, qy))
          poly.push_back(point(v.first, v.second, k));
        const auto top = on_segment(level[k + 1], qx, qy, px, py);
        for (const auto& v : top) poly.push_back(point(v.first, v.second, k + 1));
        s_.plc.facet_polygon_begin.push_back(s_.plc.facet_polygon_begin.back() + 1);
        s_.plc.polygon_vertices.insert(s_.plc.polygon_vertices.end(), poly.begin(), poly.end());
        s_.plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(s_.plc.polygon_vertices.size()));
        s_.plc.facet_marker.push_back(marker);
        s_.plc.facet_hole_begin.push_back(s_.plc.facet_hole_begin.back());
        s_.boundary_area[static_cast<std::size_t>(marker - 1)] += std::hypot(qx - px, qy - py) * dz;
      }
    }

    for (std::size_t p = 0; p < m_.parts.size(); ++p)
      if (!(s_.part_volume[p] > 0))
        throw IoError(m_.file, m_.parts[p].line, IoError::kNoOffset,
                      "part '" + m_.parts[p].name + "' is carved away entirely by later parts");
    refuse_short_edges();
    return std::move(s_);
  }

  // Two parts whose edges nearly meet (a box at x = 0.9999999 mm on the corner of one ending at
  // 1 mm) leave an edge in the PLC far below any part's own features (each at least kMinFeature of
  // the extent: model_file.cpp), and TetGen's refinement then runs without end at that scale
  // (foxi mesh and foxi solve ran until killed; an outside probe). Refused, with where and which
  // boundary holds it. Edges under 1e-12 of the extent are round-off (power_module has one of
  // 3.5e-15 mm), welded by the mesher.
  void refuse_short_edges() const {
    const Plc& plc = s_.plc;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (std::size_t i = 0; i < plc.points.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], plc.points[i]);
      hi[i % 3] = std::max(hi[i % 3], plc.points[i]);
    }
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    const double tol = model_limits::kMinFeature * extent;
    for (std::size_t f = 0; f < plc.facet_count(); ++f)
      for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
        const std::uint32_t b = plc.polygon_vertex_begin[g], e = plc.polygon_vertex_begin[g + 1];
        for (std::uint32_t k = b; e - b >= 2 && k < e; ++k) {
          const double* p = &plc.points[3 * std::size_t{plc.polygon_vertices[k]}];
          const double* q = &plc.points[3 * std::size_t{plc.polygon_vertices[k + 1 < e ? k + 1 : b]}];
          const double len = std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
          // Below 1e-12: round-off of two constructions of one point, welded by the mesher.
          if (len >= tol || len <= 1e-12 * extent) continue;
          const double u = m_.length_scale;
          char where[200];
          std::snprintf(where, sizeof where, "(%.9g, %.9g, %.9g) %s", p[0] / u, p[1] / u, p[2] / u,
                        m_.length_unit.c_str());
          const std::string& name = s_.boundary_names[static_cast<std::size_t>(plc.facet_marker[f] - 1)];
          char size[64], limit[64];
          std::snprintf(size, sizeof size, "%.3g", len / u);
          std::snprintf(limit, sizeof limit, "%.3g", extent / u);
          throw IoError(
              m_.file, 0, IoError::kNoOffset,
              "the parts leave an edge of " + std::string(size) + " " + m_.length_unit + " at " + where +
                  " on boundary '" + name +
                  "', below the smallest feature foxi meshes (1e-06 of the model's extent, " + limit + " " +
                  m_.length_unit +
                  "): two parts nearly meet there; move one onto the other's edge or face, or apart");
        }
      }
  }

 private:
  void collect() {
    double lo = 1e300, hi = -1e300, span = 0;
    for (const Part& p : m_.parts)
      for (const Prism& q : p.prisms) {
        lo = std::min(lo, q.z0);
        hi = std::max(hi, q.z1);
        for (double c : q.xy) span = std::max(span, std::abs(c));
      }
    eps_ = std::max(1e-9 * std::max(hi - lo, span), 1e-300);
    std::vector<double> zs;
    for (const Part& p : m_.parts)
      for (const Prism& q : p.prisms) zs.insert(zs.end(), {q.z0, q.z1});
    std::sort(zs.begin(), zs.end());
    for (double z : zs)
      if (levels_.empty() || z - levels_.back() > eps_) levels_.push_back(z);
    auto level = [&](double z) {
      return static_cast<std::size_t>(std::lower_bound(levels_.begin(), levels_.end(), z - eps_) -
                                      levels_.begin());
    };
    for (std::size_t pi = 0; pi < m_.parts.size(); ++pi)
      for (const Prism& q : m_.parts[pi].prisms) items_.push_back(Item{pi, &q, level(q.z0), level(q.z1)});
  }

  // the last part among `act` whose prism covers (x, y); -1 if none
  long label(double x, double y, const std::vector<std::size_t>& act) const {
    long best = -1;
    for (std::size_t i : act)
      if (static_cast<long>(items_[i].part) > best && inside_polygon(items_[i].prism->xy, x, y))
        best = static_cast<long>(items_[i].part);
    return best;
  }

  // the vertices of `pl` on the segment p -> q, in order from p to q (p and q included)
  static std::vector<std::pair<double, double>> on_segment(const Plane& pl, double px, double py, double qx,
                                                           double qy) {
    const double len2 = (qx - px) * (qx - px) + (qy - py) * (qy - py);
    const double tol = 1e-9 * std::sqrt(len2);
    std::vector<std::pair<double, std::pair<double, double>>> hits;
    const double xlo = std::min(px, qx) - tol, xhi = std::max(px, qx) + tol;
    auto it = std::lower_bound(pl.sorted_vertex.begin(), pl.sorted_vertex.end(), std::make_pair(xlo, -1e300));
    for (; it != pl.sorted_vertex.end() && it->first <= xhi; ++it) {
      const double vx = it->first, vy = it->second;
      if (vy < std::min(py, qy) - tol || vy > std::max(py, qy) + tol) continue;
      const double cross = (qx - px) * (vy - py) - (qy - py) * (vx - px);
      if (std::abs(cross) > tol * std::sqrt(len2)) continue;
      const double t = ((vx - px) * (qx - px) + (vy - py) * (qy - py)) / len2;
      hits.push_back({t, {vx, vy}});
    }
    std::sort(hits.begin(), hits.end());
    std::vector<std::pair<double, double>> out;
    for (auto& h : hits) out.push_back(h.second);
    return out;
  }

  std::string part_name(long p) const { return m_.parts[static_cast<std::size_t>(p)].name; }
  std::string interface_name(long a, long b) const {
    if (a > b) std::swap(a, b);
    return part_name(a) + "/" + part_name(b);
  }

  std::int32_t marker_of(const std::string& name) { return boundary_marker(s_, name); }

  std::uint32_t point(double x, double y, std::size_t z) {
    auto key = std::make_tuple(x, y, z);
    auto it = points_.find(key);
    if (it != points_.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(s_.plc.point_count());
    s_.plc.points.insert(s_.plc.points.end(), {x, y, levels_[z]});
    points_.emplace(key, id);
    return id;
  }

  void add_ring(const Plane& pl, const std::vector<std::uint32_t>& ring, std::size_t z) {
    for (std::uint32_t h : ring)
      s_.plc.polygon_vertices.push_back(point(pl.from(h).first, pl.from(h).second, z));
    s_.plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(s_.plc.polygon_vertices.size()));
    ++s_.plc.facet_polygon_begin.back();
  }

  const Model& m_;
  Structure s_;
  double eps_ = 0;
  std::vector<double> levels_;
  std::vector<Item> items_;
  std::map<std::tuple<double, double, std::size_t>, std::uint32_t> points_;
};

}  // namespace

std::int32_t boundary_marker(Structure& s, const std::string& name) {
  for (std::size_t i = 0; i < s.boundary_names.size(); ++i)
    if (s.boundary_names[i] == name) return static_cast<std::int32_t>(i + 1);
  s.boundary_names.push_back(name);
  s.boundary_area.push_back(0);
  return static_cast<std::int32_t>(s.boundary_names.size());
}

Structure build_structure(const Model& model, const ProgressFn& progress) {
  bool solids = false;
  for (const Part& p : model.parts) solids = solids || !p.surface.tri.empty();
  Structure s = solids ? build_structure_from_solids(model, progress) : Builder(model).build();
  s.facet_own_marker = s.plc.facet_marker;
  tag_selected_surfaces(model, s);
  check_conditions(model, s);
  return s;
}
void name_mesh(const Model& model, const Structure& structure, Mesh& mesh) {
  mesh.materials.clear();
  for (const Material& m : model.materials) mesh.materials.push_back(m);
  for (std::size_t p = 0; p < model.parts.size(); ++p) {
    const auto id = static_cast<std::int32_t>(p + 1);
    Region* r = nullptr;
    for (Region& x : mesh.regions)
      if (x.id == id) r = &x;
    if (r == nullptr) r = &mesh.regions.emplace_back();
    r->id = id;
    r->name = model.parts[p].name;
    for (std::size_t i = 0; i < model.materials.size(); ++i)
      if (model.materials[i].name == model.parts[p].material) r->material = static_cast<std::uint32_t>(i);
  }
  for (std::size_t b = 0; b < structure.boundary_names.size(); ++b) {
    const auto tag = static_cast<std::int32_t>(b + 1);
    Boundary* x = nullptr;
    for (Boundary& y : mesh.boundaries)
      if (y.tag == tag) x = &y;
    if (x == nullptr) x = &mesh.boundaries.emplace_back();
    x->tag = tag;
    x->name = structure.boundary_names[b];
  }
}

}  // namespace foxi
