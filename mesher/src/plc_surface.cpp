#include "plc_surface.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Projection_traits_3.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

#include "foxi/mesher/tetgen_mesher.hpp"  // MesherError
#include "union_find.hpp"

namespace foxi::detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Vec = K::Vector_3;
using Proj = CGAL::Projection_traits_3<K>;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, Proj>;
using Fb =
    CGAL::Constrained_triangulation_face_base_2<Proj, CGAL::Triangulation_face_base_with_info_2<int, Proj>>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Crossing constraints would need new points: a PLC whose facet edges cross is rejected.
using Cdt =
    CGAL::Constrained_Delaunay_triangulation_2<Proj, Tds,
                                               CGAL::No_constraint_intersection_requiring_constructions_tag>;

constexpr std::uint32_t kNoTri = 0xffffffffu;

[[noreturn]] void reject(const std::string& why) { throw MesherError(10, why); }

Point point(const std::vector<double>& xyz, std::uint32_t i) {
  return Point(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
}

// A facet's polygons (point ids after merging duplicates), their edges split at every PLC point lying
// strictly inside them, so that facets meeting at a T-junction share edges.
std::vector<std::vector<std::uint32_t>> split_polygons(const Plc& plc, std::size_t f,
                                                       const std::vector<std::uint32_t>& id,
                                                       const std::vector<double>& xyz) {
  std::vector<std::vector<std::uint32_t>> out;
  const std::size_t n_points = xyz.size() / 3;
  for (std::uint32_t p = plc.facet_polygon_begin[f]; p < plc.facet_polygon_begin[f + 1]; ++p) {
    std::vector<std::uint32_t> poly;
    for (std::uint32_t i = plc.polygon_vertex_begin[p]; i < plc.polygon_vertex_begin[p + 1]; ++i) {
      const std::uint32_t v = id[plc.polygon_vertices[i]];
      if (poly.empty() || poly.back() != v) poly.push_back(v);
    }
    if (poly.size() > 2 && poly.front() == poly.back()) poly.pop_back();
    std::vector<std::uint32_t> split;
    const std::size_t edges = poly.size() < 3 ? poly.size() - 1 : poly.size();
    for (std::size_t e = 0; e < poly.size(); ++e) {
      split.push_back(poly[e]);
      if (e >= edges) continue;
      const Point a = point(xyz, poly[e]), b = point(xyz, poly[(e + 1) % poly.size()]);
      const CGAL::Bbox_3 box = a.bbox() + b.bbox();
      std::vector<std::pair<double, std::uint32_t>> inner;
      for (std::uint32_t q = 0; q < n_points; ++q) {
        const Point c = point(xyz, q);
        if (!CGAL::do_overlap(box, c.bbox())) continue;
        if (CGAL::collinear(a, c, b) && CGAL::collinear_are_strictly_ordered_along_line(a, c, b))
          inner.push_back({CGAL::squared_distance(a, c), q});
      }
      std::sort(inner.begin(), inner.end());
      for (const auto& [d, q] : inner) split.push_back(q);
    }
    out.push_back(std::move(split));
  }
  return out;
}

// Appends the facet's triangles, oriented along its Newell normal.
void triangulate_facet(const Plc& plc, std::size_t f, const std::vector<std::uint32_t>& id, PlcSurface& s) {
  const auto polys = split_polygons(plc, f, id, s.points);
  Vec normal(0, 0, 0);
  for (const auto& poly : polys) {
    if (poly.size() < 3) continue;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Point a = point(s.points, poly[i]), b = point(s.points, poly[(i + 1) % poly.size()]);
      normal = normal + Vec((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                            (a.x() - b.x()) * (a.y() + b.y()));
    }
    if (normal.squared_length() > 0)
      break;  // the first polygon with an area fixes the plane; the others lie in it
  }
  if (normal.squared_length() == 0) {
    // A polygon whose points are not all on one line but whose signed area is zero crosses itself.
    for (const auto& poly : polys)
      for (std::size_t i = 2; i < poly.size(); ++i)
        if (!CGAL::collinear(point(s.points, poly[0]), point(s.points, poly[1]), point(s.points, poly[i])))
          reject("facet " + std::to_string(f + 1) + " has crossing edges (a polygon's signed area is zero)");
    // Only segments, points or collinear polygons: TetGen takes such a facet as edges to keep, but it
    // bounds no area, and every PLC point already splits the polygon edges it lies on.
    ++s.facets_without_area;
    return;
  }

  Cdt cdt{Proj(normal)};
  try {
    for (const auto& poly : polys) {
      std::vector<Cdt::Vertex_handle> vh;
      for (std::uint32_t v : poly) {
        vh.push_back(cdt.insert(point(s.points, v)));
        vh.back()->info() = v;
      }
      for (std::size_t i = 0; i + 1 < vh.size(); ++i) cdt.insert_constraint(vh[i], vh[i + 1]);
      if (vh.size() > 2) cdt.insert_constraint(vh.back(), vh.front());
    }
  } catch (const Cdt::Intersection_of_constraints_exception&) {
    reject("facet " + std::to_string(f + 1) + " has crossing edges");
  }
  // Mark faces: 0 outside every polygon or in a facet hole, 1 in the facet.
  for (auto fh = cdt.all_faces_begin(); fh != cdt.all_faces_end(); ++fh) fh->info() = 1;
  auto flood = [&](Cdt::Face_handle start) {
    std::vector<Cdt::Face_handle> stack{start};
    start->info() = 0;
    while (!stack.empty()) {
      Cdt::Face_handle fh = stack.back();
      stack.pop_back();
      for (int i = 0; i < 3; ++i) {
        Cdt::Face_handle nb = fh->neighbor(i);
        if (nb->info() == 0 || cdt.is_constrained(Cdt::Edge(fh, i))) continue;
        nb->info() = 0;
        stack.push_back(nb);
      }
    }
  };
  flood(cdt.infinite_face());
  for (std::uint32_t h = plc.facet_hole_begin[f]; h < plc.facet_hole_begin[f + 1]; ++h) {
    Cdt::Face_handle fh = cdt.locate(point(plc.facet_holes, h));
    if (fh != nullptr && !cdt.is_infinite(fh) && fh->info() == 1) flood(fh);
  }
  for (auto fh = cdt.finite_faces_begin(); fh != cdt.finite_faces_end(); ++fh) {
    if (fh->info() != 1) continue;
    std::uint32_t v[3] = {fh->vertex(0)->info(), fh->vertex(1)->info(), fh->vertex(2)->info()};
    const Point a = point(s.points, v[0]), b = point(s.points, v[1]), c = point(s.points, v[2]);
    if (CGAL::cross_product(b - a, c - a) * normal < 0) std::swap(v[1], v[2]);
    s.tri.insert(s.tri.end(), v, v + 3);
    s.tri_facet.push_back(static_cast<std::uint32_t>(f));
  }
}

Vec tri_normal(const PlcSurface& s, std::size_t t) {
  const Point a = point(s.points, s.tri[3 * t]), b = point(s.points, s.tri[3 * t + 1]),
              c = point(s.points, s.tri[3 * t + 2]);
  return CGAL::cross_product(b - a, c - a);
}

// Joins, around every edge, the two triangle sides that face each other across each wedge between
// consecutive triangles (radially sorted): sides joined this way bound the same cell.
void join_sides_around_edges(const PlcSurface& s, UnionFind& uf) {
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> edge_tris;
  const std::size_t nt = s.tri.size() / 3;
  for (std::uint32_t t = 0; t < nt; ++t)
    for (int i = 0; i < 3; ++i) {
      std::uint64_t a = s.tri[3 * t + i], b = s.tri[3 * t + (i + 1) % 3];
      if (a > b) std::swap(a, b);
      edge_tris[a << 32 | b].push_back(t);
    }
  for (const auto& [key, tris] : edge_tris) {
    const std::uint32_t u = static_cast<std::uint32_t>(key >> 32),
                        v = static_cast<std::uint32_t>(key & 0xffffffffu);
    const Point pu = point(s.points, u);
    const Vec e = point(s.points, v) - pu;
    // An orthonormal frame (x, y) of the plane normal to the edge.
    Vec x = std::abs(e.x()) <= std::abs(e.y()) && std::abs(e.x()) <= std::abs(e.z()) ? Vec(0, -e.z(), e.y())
            : std::abs(e.y()) <= std::abs(e.z())                                     ? Vec(-e.z(), 0, e.x())
                                                                                     : Vec(-e.y(), e.x(), 0);
    x = x / std::sqrt(x.squared_length());
    Vec y = CGAL::cross_product(e, x);
    y = y / std::sqrt(y.squared_length());
    struct Around {
      double angle;
      std::uint32_t toward_increasing, toward_decreasing;  // the triangle's sides facing either way
    };
    std::vector<Around> around;
    for (std::uint32_t t : tris) {
      std::uint32_t w = s.tri[3 * t];
      for (int i = 0; i < 3; ++i)
        if (s.tri[3 * t + i] != u && s.tri[3 * t + i] != v) w = s.tri[3 * t + i];
      const Vec r = point(s.points, w) - pu;
      const bool front_increasing = tri_normal(s, t) * CGAL::cross_product(e, r) > 0;
      around.push_back({std::atan2(r * y, r * x), front_increasing ? 2 * t : 2 * t + 1,
                        front_increasing ? 2 * t + 1 : 2 * t});
    }
    std::sort(around.begin(), around.end(),
              [](const Around& a, const Around& b) { return a.angle < b.angle; });
    for (std::size_t i = 0; i < around.size(); ++i)
      uf.unite(around[i].toward_increasing, around[(i + 1) % around.size()].toward_decreasing);
  }
}

// The first triangle side a ray meets, or none; `ambiguous` when it passes too near an edge to tell.
struct RayHit {
  bool hit = false, ambiguous = false;
  std::uint32_t side = 0;
  double distance = 0;
};

RayHit shoot(const PlcSurface& s, const Point& origin, const Vec& dir, std::uint32_t skip_tri, double tol) {
  RayHit best;
  const std::size_t nt = s.tri.size() / 3;
  for (std::uint32_t t = 0; t < nt; ++t) {
    if (t == skip_tri) continue;
    const Point a = point(s.points, s.tri[3 * t]), b = point(s.points, s.tri[3 * t + 1]),
                c = point(s.points, s.tri[3 * t + 2]);
    const Vec e1 = b - a, e2 = c - a, pv = CGAL::cross_product(dir, e2);
    const double det = e1 * pv;
    const double scale = std::sqrt(e1.squared_length() * pv.squared_length());
    if (std::abs(det) <= 1e-12 * scale) continue;  // parallel to the triangle
    const Vec tv = origin - a;
    const double bu = (tv * pv) / det;
    const Vec qv = CGAL::cross_product(tv, e1);
    const double bv = (dir * qv) / det, dist = (e2 * qv) / det;
    const double eps = 1e-9;
    if (bu < -eps || bv < -eps || bu + bv > 1 + eps || dist < -tol) continue;
    if (best.hit && dist >= best.distance) continue;
    best.hit = true;
    best.distance = dist;
    best.ambiguous = bu < eps || bv < eps || bu + bv > 1 - eps || dist <= tol;
    best.side = tri_normal(s, t) * dir < 0 ? 2 * t : 2 * t + 1;  // the side facing the origin
  }
  return best;
}

// Generic directions: a ray along them from a PLC's point rarely runs along a facet or an edge.
const std::array<Vec, 4> kGeneric = {Vec(0.5773, 0.6180, 0.5345), Vec(-0.3217, 0.8123, 0.4866),
                                     Vec(0.7071, -0.1234, 0.6962), Vec(-0.4142, -0.5176, 0.7483)};

RayHit shoot_generic(const PlcSurface& s, const Point& origin, const Vec& base, std::uint32_t skip_tri,
                     double tol) {
  RayHit h;
  for (const Vec& g : kGeneric) {
    h = shoot(s, origin, base + 0.1 * g, skip_tri, tol);
    if (!h.ambiguous) return h;
  }
  return h;
}

}  // namespace

PlcSurface plc_surface(const Plc& plc) {
  PlcSurface s;
  std::map<std::array<double, 3>, std::uint32_t> unique;
  std::vector<std::uint32_t> id(plc.point_count());
  for (std::size_t i = 0; i < plc.point_count(); ++i) {
    const std::array<double, 3> p = {plc.points[3 * i], plc.points[3 * i + 1], plc.points[3 * i + 2]};
    const auto [it, fresh] = unique.emplace(p, static_cast<std::uint32_t>(s.points.size() / 3));
    if (fresh) s.points.insert(s.points.end(), p.begin(), p.end());
    id[i] = it->second;
  }
  for (std::uint32_t v : plc.polygon_vertices)
    if (v >= plc.point_count())
      reject("a facet names point " + std::to_string(v + 1) + " of " + std::to_string(plc.point_count()));
  for (std::size_t f = 0; f < plc.facet_count(); ++f) triangulate_facet(plc, f, id, s);
  const std::size_t nt = s.tri.size() / 3;
  if (nt == 0) reject("the PLC has no facet with an area");

  CGAL::Bbox_3 box;
  for (std::size_t i = 0; i < s.points.size() / 3; ++i)
    box += point(s.points, static_cast<std::uint32_t>(i)).bbox();
  const double diag =
      std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                CGAL::square(box.zmax() - box.zmin()));
  const double tol = 1e-9 * diag;

  const std::uint32_t outside = static_cast<std::uint32_t>(2 * nt);
  UnionFind uf(2 * nt + 1);
  join_sides_around_edges(s, uf);
  // Each shell (sides joined around edges) lies in the cell that a ray leaving it meets first.
  std::vector<std::uint32_t> shells;
  for (std::uint32_t side = 0; side < 2 * nt; ++side)
    if (uf.find(side) == side) shells.push_back(side);
  for (std::uint32_t side : shells) {
    const std::uint32_t t = side / 2;
    const Point c = CGAL::centroid(point(s.points, s.tri[3 * t]), point(s.points, s.tri[3 * t + 1]),
                                   point(s.points, s.tri[3 * t + 2]));
    Vec n = tri_normal(s, t);
    n = n / std::sqrt(n.squared_length());
    const RayHit h = shoot_generic(s, c, side % 2 == 0 ? n : -n, t, tol);
    uf.unite(side, h.hit ? h.side : outside);
  }
  for (std::size_t i = 0; i < plc.holes.size() / 3; ++i) {
    const RayHit h =
        shoot_generic(s, point(plc.holes, static_cast<std::uint32_t>(i)), Vec(0, 0, 0), kNoTri, tol);
    if (h.hit) uf.unite(h.side, outside);
  }
  std::vector<std::uint32_t> cell_of_root(2 * nt + 1, kNoTri);
  cell_of_root[uf.find(outside)] = PlcSurface::kOutside;
  s.cell_count = 1;
  s.side_cell.resize(2 * nt);
  for (std::uint32_t side = 0; side < 2 * nt; ++side) {
    std::uint32_t& c = cell_of_root[uf.find(side)];
    if (c == kNoTri) c = static_cast<std::uint32_t>(s.cell_count++);
    s.side_cell[side] = c;
  }
  s.cell_region.assign(s.cell_count, 0);
  std::vector<bool> seeded(s.cell_count, false);
  for (std::size_t k = 0; k < plc.regions.size(); ++k) {
    const RegionSeed& seed = plc.regions[k];
    const RayHit h =
        shoot_generic(s, Point(seed.point[0], seed.point[1], seed.point[2]), Vec(0, 0, 0), kNoTri, tol);
    const std::string name =
        "region seed " + std::to_string(k + 1) + " (region " + std::to_string(seed.id) + ")";
    if (!h.hit) reject(name + " lies outside every closed surface of the PLC");
    if (h.distance <= tol) reject(name + " lies on a facet");
    const std::uint32_t c = s.side_cell[h.side];
    if (c == PlcSurface::kOutside || seeded[c])
      continue;  // in a volume hole, or a second seed: the first wins
    seeded[c] = true;
    s.cell_region[c] = seed.id;
  }
  return s;
}

}  // namespace foxi::detail
