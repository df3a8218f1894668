// Parts -> PLC through closed triangle surfaces and CGAL corefinement booleans (see structure.hpp).
//
// 1. Every part becomes a closed triangle surface (Surface_mesh, exact kernel): prisms from their
//    outlines (flat ends triangulated, convex or not), balls and STL files as given. A surface that
//    is not a consistently oriented closed manifold, or that intersects itself, is an error naming
//    the part; an inward oriented one is turned around.
// 2. Carving: the solid of part i is its surface minus every later part whose box meets it
//    (corefine_and_compute_difference, exact), so a later part carves its volume out of earlier ones.
// 3. Conforming: the carved solids are corefined pairwise (boxes that meet), which puts every curve
//    where two surfaces meet into both, so a shared area has the same outline in both solids (its
//    inside may be triangulated differently). Each shared triangle (its centroid on the other
//    solid's surface, an exact test) is emitted by the earlier part only, as the interface "A/B";
//    the rest are "P.top" / "P.bottom" (horizontal, facing up / down) or "P.side". The emitted
//    triangles must pair up along every edge; if they do not (new vertices from a later pair), the
//    pairwise corefinement runs again.
// 4. Region seeds: for each outer shell of each carved solid, a ray from the centroid of one of its
//    largest triangles inwards to the nearest triangle of that solid; the midpoint, checked to be
//    strictly inside with CGAL's exact Side_of_triangle_mesh.
// Exact coordinates are rounded to doubles only in the PLC.
#include "structure_solids.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>

#include "foxi/model/io_error.hpp"
#include "foxi/model/vec3.hpp"

namespace foxi {

namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using K = CGAL::Exact_predicates_exact_constructions_kernel;
using P3 = K::Point_3;
using SMesh = CGAL::Surface_mesh<P3>;
using Side = CGAL::Side_of_triangle_mesh<SMesh, K>;
using V3 = detail::Vec3;
using detail::cross;
using detail::dot;
using detail::sub;
V3 to_v3(const P3& p) { return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())}; }

// The triangles of a mesh as corner points (a triangulated mesh).
std::vector<std::array<P3, 3>> triangles_of(const SMesh& m) {
  std::vector<std::array<P3, 3>> out;
  out.reserve(m.number_of_faces());
  for (auto f : m.faces()) {
    std::array<P3, 3> t;
    int i = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m))
      t[static_cast<std::size_t>(i++ % 3)] = m.point(v);
    out.push_back(t);
  }
  return out;
}

// Distance along the ray o + t d (t > tmin) to the nearest of `tris`, or +inf (Moller-Trumbore).
double ray_hit(const V3& o, const V3& d, const std::vector<std::array<V3, 3>>& tris, double tmin) {
  double best = INFINITY;
  for (const auto& t : tris) {
    const V3 e1 = sub(t[1], t[0]), e2 = sub(t[2], t[0]);
    const V3 p = cross(d, e2);
    const double det = dot(e1, p);
    if (det == 0) continue;
    const V3 s = sub(o, t[0]);
    const double u = dot(s, p) / det;
    if (u < 0 || u > 1) continue;
    const V3 q = cross(s, e1);
    const double v = dot(d, q) / det;
    if (v < 0 || u + v > 1) continue;
    const double h = dot(e2, q) / det;
    if (h > tmin) best = std::min(best, h);
  }
  return best;
}

class SolidBuilder {
 public:
  SolidBuilder(const Model& m, const ProgressFn& progress) : m_(m), progress_(progress) {}

  Structure build() {
    const std::size_t n = m_.parts.size();
    solid_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      report("surfaces", i, n);
      solid_[i] = closed_surface(i);
    }
    std::vector<CGAL::Bbox_3> box(n);
    for (std::size_t i = 0; i < n; ++i) box[i] = PMP::bbox(solid_[i]);
    // 2. carve: part i minus the later parts that may overlap it
    for (std::size_t i = 0; i < n; ++i) {
      report("carve", i, n);
      for (std::size_t j = i + 1; j < n; ++j) {
        if (!CGAL::do_overlap(box[i], box[j]) || solid_[i].is_empty()) continue;
        SMesh later = solid_[j];  // corefinement refines both operands; keep part j's own surface
        bool ok = false;
        try {
          ok = PMP::corefine_and_compute_difference(solid_[i], later, solid_[i]);
        } catch (const std::exception& e) {
          fail(i, "carving by part '" + m_.parts[j].name + "' failed: " + e.what());
        }
        if (!ok)
          fail(i, "carving by part '" + m_.parts[j].name +
                      "' leaves a non-manifold solid (parts that "
                      "touch along an edge or at a point inside it)");
      }
      if (solid_[i].is_empty())
        fail(i, "part '" + m_.parts[i].name + "' is carved away entirely by later parts");
      box[i] = PMP::bbox(solid_[i]);
    }
    // 3. conforming interfaces
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = i + 1; j < n; ++j)
        if (CGAL::do_overlap(box[i], box[j])) pairs.emplace_back(i, j);
    for (int round = 0;; ++round) {
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        report("conform", k, pairs.size());
        PMP::corefine(solid_[pairs[k].first], solid_[pairs[k].second]);
      }
      if (emit(pairs)) break;
      if (round == 3)
        throw IoError(m_.file, 0, IoError::kNoOffset,
                      "the parts' surfaces could not be made conforming (shared areas keep different edges)");
    }
    // 4. volumes and seeds
    s_.part_volume.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      report("seeds", i, n);
      s_.part_volume[i] = CGAL::to_double(PMP::volume(solid_[i]));
      seeds(i);
    }
    return std::move(s_);
  }

 private:
  void report(const char* stage, std::size_t done, std::size_t total) const {
    if (progress_ &&
        !progress_(stage, static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(total, 1))))
      throw StructureCancelled();
  }

  [[noreturn]] void fail(std::size_t part, const std::string& reason) const {
    throw IoError(m_.file, m_.parts[part].line, IoError::kNoOffset, reason);
  }

  // 1. the part as a closed, outward oriented, triangulated exact mesh
  SMesh closed_surface(std::size_t pi) {
    const Part& part = m_.parts[pi];
    std::vector<P3> pts;
    std::vector<std::vector<std::size_t>> polys;
    for (const Prism& p : part.prisms) {
      const std::size_t k = p.xy.size() / 2, base = pts.size();
      for (double z : {p.z0, p.z1})
        for (std::size_t v = 0; v < k; ++v) pts.emplace_back(p.xy[2 * v], p.xy[2 * v + 1], z);
      std::vector<std::size_t> bottom, top;
      for (std::size_t v = 0; v < k; ++v) {
        bottom.push_back(base + k - 1 - v);  // seen from below: clockwise from above
        top.push_back(base + k + v);
        const std::size_t w = (v + 1) % k;
        polys.push_back({base + v, base + w, base + k + w, base + k + v});
      }
      polys.push_back(bottom);
      polys.push_back(top);
    }
    const TriSurface& s = part.surface;
    const std::size_t base = pts.size();
    for (std::size_t v = 0; v < s.vertex_count(); ++v)
      pts.emplace_back(s.xyz[3 * v], s.xyz[3 * v + 1], s.xyz[3 * v + 2]);
    for (std::size_t t = 0; t < s.triangle_count(); ++t)
      polys.push_back({base + s.tri[3 * t], base + s.tri[3 * t + 1], base + s.tri[3 * t + 2]});
    const std::string who =
        "part '" + part.name + "'" + (part.source.empty() ? std::string() : " (" + part.source + ")");
    if (!PMP::is_polygon_soup_a_polygon_mesh(polys))
      fail(pi, who +
                   ": the surface is not a consistently oriented manifold (an edge with more than two "
                   "triangles, or neighbours that disagree on their orientation)");
    SMesh mesh;
    PMP::polygon_soup_to_polygon_mesh(pts, polys, mesh);
    if (!CGAL::is_closed(mesh)) fail(pi, who + ": the surface is not closed (it has border edges)");
    if (!PMP::triangulate_faces(mesh)) fail(pi, who + ": a flat end could not be triangulated");
    if (PMP::does_self_intersect(mesh))
      fail(pi, who + ": the surface intersects itself (or two of its items overlap or touch)");
    if (!PMP::is_outward_oriented(mesh)) PMP::reverse_face_orientations(mesh);
    return mesh;
  }

  std::string part_name(std::size_t p) const { return m_.parts[p].name; }

  std::int32_t marker_of(const std::string& name) { return boundary_marker(s_, name); }

  std::uint32_t point(const P3& p) {
    auto [it, fresh] = ids_.emplace(p, static_cast<std::uint32_t>(ids_.size()));
    if (fresh) {
      const V3 d = to_v3(p);
      s_.plc.points.insert(s_.plc.points.end(), d.begin(), d.end());
    }
    return it->second;
  }

  // Emits the triangles into a fresh PLC; false if some edge has one triangle only (not conforming).
  bool emit(const std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
    s_ = Structure{};
    ids_.clear();
    const std::size_t n = solid_.size();
    std::vector<std::unique_ptr<Side>> side(n);
    std::vector<CGAL::Bbox_3> box(n);
    for (std::size_t i = 0; i < n; ++i) {
      side[i] = std::make_unique<Side>(solid_[i]);
      box[i] = PMP::bbox(solid_[i]);
    }
    std::vector<std::vector<std::size_t>> near(n);
    for (auto [i, j] : pairs) near[i].push_back(j), near[j].push_back(i);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_use;
    for (std::size_t i = 0; i < n; ++i)
      for (const auto& t : triangles_of(solid_[i])) {
        const P3 c = CGAL::centroid(t[0], t[1], t[2]);
        const CGAL::Bbox_3 cb = c.bbox();
        long other = -1;
        for (std::size_t j : near[i])
          if (CGAL::do_overlap(cb, box[j]) && (*side[j])(c) == CGAL::ON_BOUNDARY)
            other = static_cast<long>(j);
        if (other >= 0 && static_cast<std::size_t>(other) < i) continue;  // the earlier part emits it
        std::string name;
        if (other >= 0) {
          name = part_name(i) + "/" + part_name(static_cast<std::size_t>(other));
        } else if (t[0].z() == t[1].z() && t[1].z() == t[2].z()) {
          const auto o = CGAL::orientation(K::Point_2(t[0].x(), t[0].y()), K::Point_2(t[1].x(), t[1].y()),
                                           K::Point_2(t[2].x(), t[2].y()));
          name = part_name(i) + (o == CGAL::LEFT_TURN ? ".top" : ".bottom");
        } else {
          name = part_name(i) + ".side";
        }
        const std::int32_t marker = marker_of(name);
        const std::uint32_t a = point(t[0]), b = point(t[1]), d = point(t[2]);
        s_.plc.add_facet({a, b, d}, marker);
        for (auto [u, v] : {std::pair{a, b}, std::pair{b, d}, std::pair{d, a}}) ++edge_use[std::minmax(u, v)];
        const V3 p0 = to_v3(t[0]);
        const V3 nrm = cross(sub(to_v3(t[1]), p0), sub(to_v3(t[2]), p0));
        s_.boundary_area[static_cast<std::size_t>(marker - 1)] += 0.5 * std::sqrt(dot(nrm, nrm));
      }
    for (const auto& [e, uses] : edge_use)
      if (uses < 2) return false;
    return true;
  }

  // 4. a region seed inside every outer shell of the carved solid of part i
  void seeds(std::size_t pi) {
    SMesh& m = solid_[pi];
    std::vector<std::array<V3, 3>> tris;
    for (const auto& t : triangles_of(m)) tris.push_back({to_v3(t[0]), to_v3(t[1]), to_v3(t[2])});
    auto fcc = m.add_property_map<SMesh::Face_index, std::size_t>("f:foxi_cc", 0).first;
    const std::size_t shells = PMP::connected_components(m, fcc);
    std::vector<std::vector<std::size_t>> shell_faces(shells);
    std::size_t f = 0;
    for (auto face : m.faces()) shell_faces[fcc[face]].push_back(f++);
    m.remove_property_map(fcc);
    const Side inside(m);
    for (const auto& faces : shell_faces) {
      // signed volume, from the shell's first vertex: positive for an outer shell, negative for a cavity
      const V3 o = tris[faces[0]][0];
      double vol = 0;
      std::vector<std::pair<double, std::size_t>> by_area;
      for (std::size_t t : faces) {
        const V3 a = sub(tris[t][0], o), b = sub(tris[t][1], o), c = sub(tris[t][2], o);
        vol += dot(a, cross(b, c)) / 6;
        const V3 nrm = cross(sub(tris[t][1], tris[t][0]), sub(tris[t][2], tris[t][0]));
        by_area.emplace_back(-dot(nrm, nrm), t);
      }
      if (!(vol > 0)) continue;
      std::sort(by_area.begin(), by_area.end());
      bool found = false;
      for (std::size_t k = 0; k < by_area.size() && k < 16 && !found; ++k) {
        const auto& t = tris[by_area[k].second];
        V3 nrm = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        const double len = std::sqrt(dot(nrm, nrm));
        const V3 d = {-nrm[0] / len, -nrm[1] / len, -nrm[2] / len};  // inwards
        const V3 c = {(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3,
                      (t[0][2] + t[1][2] + t[2][2]) / 3};
        const double hit = ray_hit(c, d, tris, 1e-9 * std::sqrt(len));
        if (!std::isfinite(hit)) continue;
        const V3 seed = {c[0] + 0.5 * hit * d[0], c[1] + 0.5 * hit * d[1], c[2] + 0.5 * hit * d[2]};
        if (inside(P3(seed[0], seed[1], seed[2])) != CGAL::ON_BOUNDED_SIDE) continue;
        RegionSeed r;
        std::copy(seed.begin(), seed.end(), r.point);
        r.id = static_cast<std::int32_t>(pi + 1);
        s_.plc.regions.push_back(r);
        found = true;
      }
      if (!found)
        fail(pi, "no point strictly inside part '" + m_.parts[pi].name + "' was found for its region");
    }
  }

  const Model& m_;
  const ProgressFn& progress_;
  Structure s_;
  std::vector<SMesh> solid_;
  std::map<P3, std::uint32_t> ids_;
};

}  // namespace

Structure build_structure_from_solids(const Model& model, const ProgressFn& progress) {
  return SolidBuilder(model, progress).build();
}

}  // namespace foxi
