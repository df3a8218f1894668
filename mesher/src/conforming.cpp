#include "foxi/mesher/conforming.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

#include "foxi/model/delaunay.hpp"

namespace foxi {

namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec add(const Vec& a, const Vec& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec scale(const Vec& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm2(const Vec& a) { return dot(a, a); }
Vec at(const std::vector<double>& xyz, std::uint32_t i) { return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }

struct Ball {
  Vec c{};
  double r2 = -1;  // negative: none (degenerate simplex)
};

// Circumsphere of a tet, in double (good enough to choose what to split; the certificate is exact).
Ball tet_ball(const Vec& p0, const Vec& p1, const Vec& p2, const Vec& p3) {
  const Vec a = sub(p1, p0), b = sub(p2, p0), c = sub(p3, p0);
  const double det = dot(a, cross(b, c));
  if (!(std::abs(det) > 0)) return {};
  const Vec num = add(add(scale(cross(b, c), norm2(a)), scale(cross(c, a), norm2(b))), scale(cross(a, b), norm2(c)));
  const Vec off = scale(num, 0.5 / det);
  return {add(p0, off), norm2(off)};
}

// Diametral sphere of a triangle: centred on its circumcentre, in its plane.
Ball triangle_ball(const Vec& p0, const Vec& p1, const Vec& p2) {
  const Vec a = sub(p1, p0), b = sub(p2, p0);
  const Vec n = cross(a, b);
  const double n2 = norm2(n);
  if (!(n2 > 0)) return {};
  const Vec off = scale(cross(sub(scale(b, norm2(a)), scale(a, norm2(b))), n), 0.5 / n2);
  return {add(p0, off), norm2(off)};
}

// Vertices bucketed in a uniform grid, for "which vertices lie in this ball".
struct PointGrid {
  Vec lo{};
  double cell = 1;
  std::array<std::size_t, 3> dim{1, 1, 1};
  std::vector<std::uint32_t> begin, items;

  std::size_t index(const std::array<std::size_t, 3>& c) const { return (c[2] * dim[1] + c[1]) * dim[0] + c[0]; }
  std::size_t coord(double v, int axis) const {
    const double k = std::floor((v - lo[std::size_t(axis)]) / cell);
    if (!(k > 0)) return 0;
    const std::size_t last = dim[std::size_t(axis)] - 1;
    return k >= double(last) ? last : std::size_t(k);  // no out-of-range conversion for huge balls
  }

  PointGrid(const std::vector<double>& xyz, const std::vector<std::uint32_t>& vertices) {
    Vec hi{};
    lo = hi = at(xyz, vertices.empty() ? 0 : vertices[0]);
    for (std::uint32_t v : vertices)
      for (int k = 0; k < 3; ++k) {
        lo[std::size_t(k)] = std::min(lo[std::size_t(k)], xyz[3 * v + std::size_t(k)]);
        hi[std::size_t(k)] = std::max(hi[std::size_t(k)], xyz[3 * v + std::size_t(k)]);
      }
    const Vec ext = sub(hi, lo);
    const double vol = std::max(ext[0], 1e-300) * std::max(ext[1], 1e-300) * std::max(ext[2], 1e-300);
    cell = std::max({std::cbrt(vol / double(std::max<std::size_t>(vertices.size(), 1))), ext[0] / 256, ext[1] / 256,
                     ext[2] / 256, 1e-300});
    for (int k = 0; k < 3; ++k) dim[std::size_t(k)] = std::size_t(ext[std::size_t(k)] / cell) + 1;
    begin.assign(dim[0] * dim[1] * dim[2] + 1, 0);
    std::vector<std::size_t> slot(vertices.size());
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const std::uint32_t v = vertices[i];
      slot[i] = index({coord(xyz[3 * v], 0), coord(xyz[3 * v + 1], 1), coord(xyz[3 * v + 2], 2)});
      ++begin[slot[i] + 1];
    }
    for (std::size_t i = 1; i < begin.size(); ++i) begin[i] += begin[i - 1];
    items.resize(vertices.size());
    std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
    for (std::size_t i = 0; i < vertices.size(); ++i) items[fill[slot[i]]++] = vertices[i];
  }

  template <class F>
  void for_each_in_box(const Vec& c, double r, F&& f) const {
    const std::array<std::size_t, 3> a{coord(c[0] - r, 0), coord(c[1] - r, 1), coord(c[2] - r, 2)};
    const std::array<std::size_t, 3> b{coord(c[0] + r, 0), coord(c[1] + r, 1), coord(c[2] + r, 2)};
    for (std::size_t z = a[2]; z <= b[2]; ++z)
      for (std::size_t y = a[1]; y <= b[1]; ++y)
        for (std::size_t x = a[0]; x <= b[0]; ++x) {
          const std::size_t i = index({x, y, z});
          for (std::uint32_t k = begin[i]; k < begin[i + 1]; ++k) f(items[k]);
        }
  }
};

// The PLC's facets as nested lists while points are being added.
struct EditablePlc {
  Plc& plc;
  std::vector<std::vector<std::vector<std::uint32_t>>> facets;  // facet -> polygons -> vertices
  double tol = 0;                                               // "on a segment / plane", metres

  explicit EditablePlc(Plc& p) : plc(p) {
    facets.resize(plc.facet_count());
    for (std::size_t f = 0; f < plc.facet_count(); ++f)
      for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g)
        facets[f].emplace_back(plc.polygon_vertices.begin() + plc.polygon_vertex_begin[g],
                               plc.polygon_vertices.begin() + plc.polygon_vertex_begin[g + 1]);
    Vec lo{}, hi{};
    for (std::size_t i = 0; i < plc.point_count(); ++i)
      for (std::size_t k = 0; k < 3; ++k) {
        lo[k] = i == 0 ? plc.points[k] : std::min(lo[k], plc.points[3 * i + k]);
        hi[k] = i == 0 ? plc.points[k] : std::max(hi[k], plc.points[3 * i + k]);
      }
    tol = 1e-9 * std::sqrt(norm2(sub(hi, lo)));
  }

  Vec point(std::uint32_t i) const { return at(plc.points, i); }

  bool on_segment(const Vec& p, std::uint32_t a, std::uint32_t b) const {
    const Vec pa = point(a), d = sub(point(b), pa), w = sub(p, pa);
    const double l2 = norm2(d);
    if (!(l2 > 0)) return false;
    const double t = dot(w, d);
    if (t < -tol * std::sqrt(l2) || t > l2 + tol * std::sqrt(l2)) return false;
    return norm2(cross(d, w)) <= tol * tol * l2;
  }

  // A PLC segment (consecutive vertices of some polygon) that holds both p and q, as (a, b).
  bool find_segment(const Vec& p, const Vec& q, std::uint32_t& a, std::uint32_t& b) const {
    for (const auto& polys : facets)
      for (const auto& poly : polys) {
        if (poly.size() < 2) continue;
        for (std::size_t i = 0; i < poly.size(); ++i) {
          const std::uint32_t u = poly[i], v = poly[(i + 1) % poly.size()];
          if (poly.size() == 2 && i == 1) break;
          if (on_segment(p, u, v) && on_segment(q, u, v)) {
            a = u;
            b = v;
            return true;
          }
        }
      }
    return false;
  }

  std::uint32_t add_point(const Vec& p) {
    plc.points.insert(plc.points.end(), p.begin(), p.end());
    return static_cast<std::uint32_t>(plc.point_count() - 1);
  }

  // Splits every polygon edge (a, b) or (b, a) with the new point k.
  void split_segment(std::uint32_t a, std::uint32_t b, std::uint32_t k) {
    for (auto& polys : facets)
      for (auto& poly : polys) {
        if (poly.size() < 2) continue;
        for (std::size_t i = 0; i < poly.size(); ++i) {
          const std::size_t j = (i + 1) % poly.size();
          if (poly.size() == 2 && i == 1) break;
          if ((poly[i] == a && poly[j] == b) || (poly[i] == b && poly[j] == a)) {
            poly.insert(poly.begin() + std::ptrdiff_t(i + 1), k);
            break;
          }
        }
      }
  }

  // The facet with marker `marker` whose plane holds the triangle and whose polygons hold its centroid.
  std::size_t find_facet(std::int32_t marker, const Vec& p0, const Vec& p1, const Vec& p2) const {
    const Vec centroid = scale(add(add(p0, p1), p2), 1.0 / 3);
    for (std::size_t f = 0; f < facets.size(); ++f) {
      if (plc.facet_marker[f] != marker) continue;
      for (const auto& poly : facets[f])
        if (poly.size() >= 3 && in_polygon(poly, p0, p1, p2, centroid)) return f;
    }
    return facets.size();
  }

  // Whether p lies in the plane of the polygon and inside it (the triangle p0 p1 p2 gives the plane).
  bool in_polygon(const std::vector<std::uint32_t>& poly, const Vec& p0, const Vec& p1, const Vec& p2,
                  const Vec& p) const {
    const Vec n = cross(sub(p1, p0), sub(p2, p0));
    const double nn = std::sqrt(norm2(n));
    if (!(nn > 0)) return false;
    for (std::uint32_t v : poly)
      if (std::abs(dot(sub(point(v), p0), n)) > tol * nn) return false;
    // Drop the dominant axis of the normal and count crossings.
    std::size_t drop = 0;
    for (std::size_t k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[drop])) drop = k;
    const std::size_t u = (drop + 1) % 3, w = (drop + 2) % 3;
    bool inside = false;
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
      const Vec a = point(poly[i]), b = point(poly[j]);
      if ((a[w] > p[w]) != (b[w] > p[w])) {
        const double x = a[u] + (p[w] - a[w]) / (b[w] - a[w]) * (b[u] - a[u]);
        if (p[u] < x) inside = !inside;
      }
    }
    return inside;
  }

  bool in_facet(std::size_t f, const Vec& p0, const Vec& p1, const Vec& p2, const Vec& p) const {
    for (const auto& poly : facets[f])
      if (poly.size() >= 3 && in_polygon(poly, p0, p1, p2, p)) return true;
    return false;
  }

  void write_back() {
    plc.facet_polygon_begin.assign(1, 0);
    plc.polygon_vertex_begin.assign(1, 0);
    plc.polygon_vertices.clear();
    for (const auto& polys : facets) {
      for (const auto& poly : polys) {
        plc.polygon_vertices.insert(plc.polygon_vertices.end(), poly.begin(), poly.end());
        plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertices.size()));
      }
      plc.facet_polygon_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertex_begin.size() - 1));
    }
  }
};

}  // namespace

std::size_t split_encroached_constraints(const Mesh& mesh, const std::vector<std::uint32_t>& violating_tets,
                                         Plc& plc) {
  const std::size_t nt = mesh.tet_count(), nf = mesh.bface_count();
  std::vector<char> used(mesh.node_count(), 0);
  for (std::uint32_t v : mesh.tet) used[v] = 1;
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t v = 0; v < used.size(); ++v)
    if (used[v]) vertices.push_back(v);
  const PointGrid grid(mesh.xyz, vertices);

  std::vector<Ball> face_ball(nf);
  for (std::size_t f = 0; f < nf; ++f)
    face_ball[f] = triangle_ball(at(mesh.xyz, mesh.bface[3 * f]), at(mesh.xyz, mesh.bface[3 * f + 1]),
                                 at(mesh.xyz, mesh.bface[3 * f + 2]));

  // Constraint triangles to split: those encroached by a vertex inside a violated circumsphere,
  // whose diametral sphere meets that circumsphere (the triangle lies between the two).
  std::vector<char> split(nf, 0);
  for (std::uint32_t t : violating_tets) {
    if (t >= nt) continue;
    const std::uint32_t* tv = &mesh.tet[4 * std::size_t(t)];
    const Ball b = tet_ball(at(mesh.xyz, tv[0]), at(mesh.xyz, tv[1]), at(mesh.xyz, tv[2]), at(mesh.xyz, tv[3]));
    if (b.r2 < 0) continue;
    const double r = std::sqrt(b.r2);
    // The vertices inside; the certificate is exact, so if rounding hides them take the deepest one.
    std::vector<std::uint32_t> inside;
    std::uint32_t deepest = kNone;
    double deepest_ratio = std::numeric_limits<double>::infinity();
    grid.for_each_in_box(b.c, r * (1 + 1e-9), [&](std::uint32_t v) {
      if (v == tv[0] || v == tv[1] || v == tv[2] || v == tv[3]) return;
      const double ratio = norm2(sub(at(mesh.xyz, v), b.c)) / b.r2;
      if (ratio < 1 - 1e-12) inside.push_back(v);
      if (ratio < deepest_ratio) {
        deepest_ratio = ratio;
        deepest = v;
      }
    });
    if (inside.empty() && deepest != kNone && deepest_ratio < 1 + 1e-9) inside.push_back(deepest);
    for (std::uint32_t q : inside) {
      const Vec pq = at(mesh.xyz, q);
      for (std::size_t f = 0; f < nf; ++f) {
        const Ball& fb = face_ball[f];
        if (fb.r2 < 0 || split[f]) continue;
        const std::uint32_t* fv = &mesh.bface[3 * f];
        if (fv[0] == q || fv[1] == q || fv[2] == q) continue;
        if (!(norm2(sub(pq, fb.c)) < fb.r2 * (1 - 1e-12))) continue;
        const double d = std::sqrt(norm2(sub(fb.c, b.c)));
        if (d < std::sqrt(fb.r2) + r) split[f] = 1;
      }
    }
  }

  EditablePlc edit(plc);
  const std::size_t before = plc.point_count();
  std::vector<Vec> added;
  auto fresh = [&](const Vec& p, double size) {
    for (const Vec& a : added)
      if (norm2(sub(a, p)) < 1e-6 * size * size) return false;
    return true;
  };
  for (std::size_t f = 0; f < nf; ++f) {
    if (!split[f]) continue;
    const std::uint32_t* fv = &mesh.bface[3 * f];
    const Vec p[3] = {at(mesh.xyz, fv[0]), at(mesh.xyz, fv[1]), at(mesh.xyz, fv[2])};
    const Ball& fb = face_ball[f];
    const double size = std::sqrt(fb.r2);
    const std::size_t facet = edit.find_facet(mesh.bface_tag[f], p[0], p[1], p[2]);
    // Subsegments among the triangle's edges; the circumcentre encroaching one, or falling outside
    // the facet, splits the subsegment instead (nearest to the centre first).
    int seg_edge = -1;
    double seg_dist = std::numeric_limits<double>::infinity();
    std::uint32_t sa = 0, sb = 0;
    const bool centre_in_facet = facet < edit.facets.size() && edit.in_facet(facet, p[0], p[1], p[2], fb.c);
    for (int e = 0; e < 3; ++e) {
      const Vec& u = p[e];
      const Vec& v = p[(e + 1) % 3];
      std::uint32_t a = 0, b = 0;
      if (!edit.find_segment(u, v, a, b)) continue;
      const Vec mid = scale(add(u, v), 0.5);
      const double d2 = norm2(sub(fb.c, mid));
      const bool encroached = d2 < 0.25 * norm2(sub(v, u));
      if ((encroached || !centre_in_facet) && d2 < seg_dist) {
        seg_dist = d2;
        seg_edge = e;
        sa = a;
        sb = b;
      }
    }
    if (seg_edge >= 0) {
      const Vec mid = scale(add(p[seg_edge], p[(seg_edge + 1) % 3]), 0.5);
      if (!fresh(mid, size)) continue;
      // The segment may have been split already in this pass: find the piece that holds mid now.
      std::uint32_t a = sa, b = sb;
      if (!edit.on_segment(mid, a, b) || !edit.find_segment(mid, mid, a, b)) continue;
      const std::uint32_t k = edit.add_point(mid);
      edit.split_segment(a, b, k);
      added.push_back(mid);
    } else if (facet < edit.facets.size()) {
      const Vec c = centre_in_facet ? fb.c : scale(add(add(p[0], p[1]), p[2]), 1.0 / 3);
      if (!fresh(c, size)) continue;
      // A point on some segment of the facet would be a second copy of a segment vertex to TetGen.
      std::uint32_t a = 0, b = 0;
      const std::uint32_t k = edit.add_point(c);
      if (edit.find_segment(c, c, a, b))
        edit.split_segment(a, b, k);
      else
        edit.facets[facet].push_back({k});
      added.push_back(c);
    }
  }
  edit.write_back();
  return plc.point_count() - before;
}

Mesh mesh_conforming(const Plc& plc, const MeshParams& params, const ConformingParams& conforming,
                     ConformingReport* report, Plc* refined_plc) {
  const auto t0 = std::chrono::steady_clock::now();
  ConformingReport rep;
  MeshParams p = params;
  p.optimize = false;
  Plc current = plc;
  Mesh mesh;
  CertificateOptions copt;
  copt.max_listed = std::numeric_limits<std::size_t>::max();
  for (std::size_t it = 0;; ++it) {
    mesh = mesh_plc(current, p, &rep.tetgen);
    const auto c0 = std::chrono::steady_clock::now();
    const DelaunayCertificate cert = compute_delaunay_certificate(mesh, copt);
    rep.certificate_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
    rep.violations.push_back(cert.violating_tet_count);
    if (it == 0) {
      rep.first_mesh_points = mesh.node_count();
      rep.first_mesh_violations = cert.violating_tet_count;
    }
    rep.delaunay = cert.delaunay;
    if (cert.delaunay || it >= conforming.max_iterations) break;
    const double budget =
        std::max(conforming.max_added_fraction * double(rep.first_mesh_points), double(conforming.min_added_budget));
    if (double(rep.added_points) >= budget) break;
    if (params.progress &&
        !params.progress("conforming refinement", double(it + 1) / double(conforming.max_iterations + 1)))
      throw MesherError(-1, "meshing cancelled");
    const std::size_t n = split_encroached_constraints(mesh, cert.violating_tets, current);
    if (n == 0) break;
    rep.added_points += n;
    rep.iterations = it + 1;
  }
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = rep;
  if (refined_plc) *refined_plc = std::move(current);
  return mesh;
}

}  // namespace foxi
