// Internal to the mesher: small geometry helpers and an editable copy of a PLC's facets, shared by
// the conforming refinement (conforming.cpp) and the thin-layer refinement (layer_refinement.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/mesher/thin_layers.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/vec3.hpp"

namespace foxi::detail {

using Vec = Vec3;  // sub, add, scale, dot, cross, norm2: foxi/model/vec3.hpp
inline Vec at(const std::vector<double>& xyz, std::uint32_t i) {
  return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
}

// An undirected edge as one integer (the smaller index in the high half).
inline std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(a) << 32) | b;
}

// Adds the Newell normal of the closed polygon v[0..n) (twice its vector area; no need to choose
// three vertices) to `normal`.
inline void add_newell_normal(const std::vector<double>& xyz, const std::uint32_t* v, std::size_t n,
                              Vec& normal) {
  for (std::size_t i = 0; i < n; ++i) {
    const Vec a = at(xyz, v[i]), b = at(xyz, v[i + 1 < n ? i + 1 : 0]);
    normal[0] += (a[1] - b[1]) * (a[2] + b[2]);
    normal[1] += (a[2] - b[2]) * (a[0] + b[0]);
    normal[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
}

struct Ball {
  Vec c{};
  double r2 = -1;  // negative: none (degenerate simplex)
};

// Circumsphere of a tet, in double (good enough to choose what to split; the certificate is exact).
inline Ball tet_ball(const Vec& p0, const Vec& p1, const Vec& p2, const Vec& p3) {
  const Vec a = sub(p1, p0), b = sub(p2, p0), c = sub(p3, p0);
  const double det = dot(a, cross(b, c));
  if (!(std::abs(det) > 0)) return {};
  const Vec num =
      add(add(scale(cross(b, c), norm2(a)), scale(cross(c, a), norm2(b))), scale(cross(a, b), norm2(c)));
  const Vec off = scale(num, 0.5 / det);
  return {add(p0, off), norm2(off)};
}

// Diametral sphere of a triangle: centred on its circumcentre, in its plane.
inline Ball triangle_ball(const Vec& p0, const Vec& p1, const Vec& p2) {
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

  std::size_t index(const std::array<std::size_t, 3>& c) const {
    return (c[2] * dim[1] + c[1]) * dim[0] + c[0];
  }
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
    cell = std::max({std::cbrt(vol / double(std::max<std::size_t>(vertices.size(), 1))), ext[0] / 256,
                     ext[1] / 256, ext[2] / 256, 1e-300});
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

// p moved along the layer's normal onto the plane normal . x = level. For a layer normal to an axis
// the other two coordinates are kept bit for bit: a point and its mirror then lie exactly on one
// normal line, so four of them make an exact rectangle and TetGen makes no near-flat tet across it.
inline Vec onto_layer_plane(const ThinLayer& l, const Vec& p, double level) {
  for (std::size_t k = 0; k < 3; ++k)
    if (l.normal[k] == 1 && l.normal[(k + 1) % 3] == 0 && l.normal[(k + 2) % 3] == 0) {
      Vec q = p;
      q[k] = level;
      return q;
    }
  const Vec n{l.normal[0], l.normal[1], l.normal[2]};
  return add(p, scale(n, level - dot(n, p)));
}

// The PLC's facets as nested lists while points are being added.
struct EditablePlc {
  Plc& plc;
  std::vector<std::vector<std::vector<std::uint32_t>>> facets;  // facet -> polygons (2+ vertices) -> vertices
  std::vector<std::vector<std::uint32_t>> facet_points;  // facet -> its lone vertices (1-vertex polygons)
  double tol = 0;                                        // "on a segment / plane", metres
  // Surface mode (index_surface()): the PLC is a mesh's surface (surface_plc), facet f is the mesh's
  // boundary triangle f and PLC point i its vertex i, and edges are found through these maps instead
  // of by scanning every facet, which is quadratic on a surface of 10^5 triangles.
  bool surface = false;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> edge_facets;  // polygon edge -> facets
  std::unordered_map<std::uint64_t, std::uint32_t> split_at;                  // split edge -> its new point

  void index_surface() {
    surface = true;
    for (std::uint32_t f = 0; f < facets.size(); ++f)
      for (const auto& poly : facets[f])
        for (std::size_t i = 0; i < poly.size() && poly.size() >= 2; ++i) {
          if (poly.size() == 2 && i == 1) break;
          edge_facets[edge_key(poly[i], poly[(i + 1) % poly.size()])].push_back(f);
        }
  }
  // Surface mode: the current piece of the (maybe already split) PLC edge (a, b) that holds p.
  void piece_holding(const Vec& p, std::uint32_t& a, std::uint32_t& b) const {
    for (auto it = split_at.find(edge_key(a, b)); it != split_at.end(); it = split_at.find(edge_key(a, b))) {
      const std::uint32_t k = it->second;
      if (on_segment(p, a, k))
        b = k;
      else
        a = k;
    }
  }

  explicit EditablePlc(Plc& p) : plc(p) {
    facets.resize(plc.facet_count());
    facet_points.resize(plc.facet_count());
    for (std::size_t f = 0; f < plc.facet_count(); ++f)
      for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
        const std::uint32_t b = plc.polygon_vertex_begin[g], e = plc.polygon_vertex_begin[g + 1];
        if (e - b == 1)
          facet_points[f].push_back(plc.polygon_vertices[b]);
        else
          facets[f].emplace_back(plc.polygon_vertices.begin() + b, plc.polygon_vertices.begin() + e);
      }
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
  // Puts the new point k into every polygon edge that holds it: the edge (a, b) and any longer
  // edge of another polygon through it (a T-junction in the PLC), so that no facet keeps a segment
  // with a vertex of the PLC lying inside it.
  void split_segment(std::uint32_t a, std::uint32_t b, std::uint32_t k) {
    if (surface) {
      // A mesh's surface has no T-junctions: the polygons with the edge (a, b) are all there is.
      const auto it = edge_facets.find(edge_key(a, b));
      if (it == edge_facets.end()) return;
      const std::vector<std::uint32_t> owners = std::move(it->second);
      edge_facets.erase(it);
      for (std::uint32_t f : owners)
        for (auto& poly : facets[f])
          for (std::size_t i = 0; i < poly.size(); ++i) {
            const std::uint32_t u = poly[i], v = poly[(i + 1) % poly.size()];
            if (edge_key(u, v) != edge_key(a, b)) continue;
            poly.insert(poly.begin() + std::ptrdiff_t(i + 1), k);
            break;
          }
      auto& ak = edge_facets[edge_key(a, k)];
      ak.insert(ak.end(), owners.begin(), owners.end());
      auto& kb = edge_facets[edge_key(k, b)];
      kb.insert(kb.end(), owners.begin(), owners.end());
      split_at[edge_key(a, b)] = k;
      return;
    }
    const Vec pk = point(k);
    auto holds = [&](std::uint32_t u, std::uint32_t v) {
      return ((u == a && v == b) || (u == b && v == a)) ||
             (u != k && v != k && on_segment(pk, u, v) && norm2(sub(pk, point(u))) > tol * tol &&
              norm2(sub(pk, point(v))) > tol * tol);
    };
    const std::size_t facet_count = facets.size();
    for (std::size_t f = 0; f < facet_count; ++f) {
      const std::size_t count = facets[f].size();
      for (std::size_t g = 0; g < count; ++g) {
        auto& poly = facets[f][g];
        if (poly.size() == 2) {
          // A lone segment becomes two, the second in a facet of its own: TetGen triangulates the
          // vertices of one facet in its plane, and three almost collinear vertices make a sliver
          // triangle that it then finds crossing the facets along the segment.
          if (holds(poly[0], poly[1])) {
            const std::uint32_t end = poly[1];
            poly[1] = k;
            add_segment_facet(k, end, plc.facet_marker[f]);
          }
          continue;
        }
        if (poly.size() < 3) continue;
        for (std::size_t i = 0; i < poly.size(); ++i)
          if (holds(poly[i], poly[(i + 1) % poly.size()])) {
            poly.insert(poly.begin() + std::ptrdiff_t(i + 1), k);
            break;
          }
      }
    }
  }

  // A new facet holding the single segment (a, b).
  void add_segment_facet(std::uint32_t a, std::uint32_t b, std::int32_t marker) {
    facets.push_back({{a, b}});
    facet_points.emplace_back();
    plc.facet_marker.push_back(marker);
    plc.facet_hole_begin.push_back(plc.facet_hole_begin.back());
  }

  // The facet with marker `marker` whose plane holds the triangle and whose polygons hold its centroid.
  std::size_t find_facet(std::int32_t marker, const Vec& p0, const Vec& p1, const Vec& p2) const {
    const Vec centroid = scale(add(add(p0, p1), p2), 1.0 / 3);
    for (std::size_t f = 0; f < facets.size(); ++f)
      if (plc.facet_marker[f] == marker && in_facet(f, p0, p1, p2, centroid)) return f;
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

  // Inside one of the facet's polygons and not in one of its holes (the smallest polygon around a
  // hole point). The triangle p0 p1 p2 gives the plane.
  bool in_facet(std::size_t f, const Vec& p0, const Vec& p1, const Vec& p2, const Vec& p) const;

  // The edge (a, b) of one of facet f's polygons nearest to p, if closer than `within` and p projects
  // inside it.
  bool nearest_facet_edge(std::size_t f, const Vec& p, double within, std::uint32_t& a,
                          std::uint32_t& b) const;
  // The facet whose plane and polygons hold p, or facets.size().
  std::size_t facet_at(const Vec& p) const;
  // Adds p to the PLC segment that holds it (splitting that segment in every polygon) or else, as a
  // one-vertex polygon, to the facet that holds it; returns false (and adds nothing) if neither does.
  bool insert_surface_point(const Vec& p);
  // Thin layers: a point added on one face of a layer is mirrored onto the opposite face, so the two
  // faces keep the same vertices in projection and the flat tets between them stay Delaunay.
  std::vector<ThinLayer> layers;
  // The mirror images of p (on a layer face) that `insert_surface_point` accepted; `exists` tells
  // whether a vertex is already at a position (then nothing is added there).
  template <class Exists>
  std::size_t mirror(const Vec& p, Exists&& exists) {
    std::size_t n = 0;
    for (const ThinLayer& l : layers) {
      const Vec nrm{l.normal[0], l.normal[1], l.normal[2]};
      if (!l.contains(p.data())) continue;
      const double h = dot(nrm, p);
      Vec q;
      if (std::abs(h - l.lo) <= l.tolerance)
        q = onto_layer_plane(l, p, l.hi);
      else if (std::abs(h - l.hi) <= l.tolerance)
        q = onto_layer_plane(l, p, l.lo);
      else
        continue;
      if (!exists(q) && insert_surface_point(q)) ++n;
    }
    return n;
  }

  void write_back() {
    plc.facet_polygon_begin.assign(1, 0);
    plc.polygon_vertex_begin.assign(1, 0);
    plc.polygon_vertices.clear();
    for (std::size_t f = 0; f < facets.size(); ++f) {
      for (const auto& poly : facets[f]) {
        plc.polygon_vertices.insert(plc.polygon_vertices.end(), poly.begin(), poly.end());
        plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertices.size()));
      }
      for (std::uint32_t v : facet_points[f]) {
        plc.polygon_vertices.push_back(v);
        plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertices.size()));
      }
      plc.facet_polygon_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertex_begin.size() - 1));
    }
  }
};

// A mesh's vertices and its constraint triangles' diametral spheres, bucketed for the questions the
// refinements ask: which vertices lie in a ball, which triangles a point encroaches.
struct MeshSearch {
  explicit MeshSearch(const Mesh& mesh);
  const Mesh& mesh;
  PointGrid vertices;
  std::vector<Ball> face_ball;  // per mesh.bface; r2 < 0 for a degenerate triangle

  // Calls f(face) once for each constraint triangle that the segment p q crosses or touches (in
  // double, with a relative tolerance; enough to choose what to split).
  template <class F>
  void for_each_face_crossed(const Vec& p, const Vec& q, F&& f) const {
    std::vector<std::uint32_t> seen;
    auto test = [&](std::uint32_t face) {
      if (segment_crosses_face(p, q, face)) seen.push_back(face);
    };
    for (std::uint32_t face : big_faces_) test(face);
    // A face that the segment crosses at x holds x in its diametral ball, so it is listed in x's
    // cell; the cells along the segment are visited by sampling at a quarter cell with their
    // neighbours.
    const double len = std::sqrt(norm2(sub(q, p)));
    const std::size_t steps = std::size_t(std::min(4 * len / vertices.cell, 1e6)) + 1;
    std::vector<std::size_t> cells;
    for (std::size_t i = 0; i <= steps; ++i) {
      const Vec x = add(p, scale(sub(q, p), double(i) / double(steps)));
      const std::array<std::size_t, 3> c{vertices.coord(x[0], 0), vertices.coord(x[1], 1),
                                         vertices.coord(x[2], 2)};
      for (std::size_t dz = 0; dz < 3; ++dz)
        for (std::size_t dy = 0; dy < 3; ++dy)
          for (std::size_t dx = 0; dx < 3; ++dx) {
            const std::array<std::size_t, 3> n{c[0] + dx, c[1] + dy, c[2] + dz};
            if (n[0] == 0 || n[1] == 0 || n[2] == 0 || n[0] > vertices.dim[0] || n[1] > vertices.dim[1] ||
                n[2] > vertices.dim[2])
              continue;
            cells.push_back(vertices.index({n[0] - 1, n[1] - 1, n[2] - 1}));
          }
    }
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    for (std::size_t cell : cells)
      for (std::uint32_t k = face_begin_[cell]; k < face_begin_[cell + 1]; ++k) test(face_items_[k]);
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    for (std::uint32_t face : seen) f(face);
  }

  // Calls f(face) for each constraint triangle whose diametral sphere holds p strictly inside.
  template <class F>
  void for_each_encroached(const Vec& p, F&& f) const {
    auto test = [&](std::uint32_t face) {
      const Ball& b = face_ball[face];
      if (b.r2 > 0 && norm2(sub(p, b.c)) < b.r2 * (1 - 1e-12)) f(face);
    };
    for (std::uint32_t face : big_faces_) test(face);
    const std::size_t cell =
        vertices.index({vertices.coord(p[0], 0), vertices.coord(p[1], 1), vertices.coord(p[2], 2)});
    for (std::uint32_t k = face_begin_[cell]; k < face_begin_[cell + 1]; ++k) test(face_items_[k]);
  }

 private:
  bool segment_crosses_face(const Vec& p, const Vec& q, std::uint32_t face) const;
  std::vector<std::uint32_t> face_begin_, face_items_, big_faces_;
};

// The constraint triangles to split for the non-Delaunay tets `violating_tets`: those encroached by
// a vertex inside a violated circumsphere whose diametral sphere meets that circumsphere (the
// triangle lies between the two). When no vertex inside a tet's circumsphere encroaches a triangle
// (the sphere reaches past a non-convex part of the boundary, e.g. under an overhanging plate, to a
// vertex hidden behind a triangle whose diametral sphere is smaller than that sphere's cap), the
// triangles that separate the tet from those vertices (crossed by the segment from the tet's centroid)
// are split instead: otherwise nothing is found to split and the violation stays. Sets split[face] = 1.
void mark_faces_for_violations(const MeshSearch& search, const std::vector<std::uint32_t>& violating_tets,
                               std::vector<char>& split);

// Merges PLC points closer than `relative_tol` times the PLC's bounding-box diagonal (a builder may
// emit one corner twice for two parts). The merged copies are removed (points renumbered in order);
// polygons are remapped and lose repeated consecutive vertices. A segment split by the refinement must be one
// segment for every polygon that has it, which index-based splitting only sees when shared corners are one
// point. Returns the number of points merged.
std::size_t weld_coincident_points(Plc& plc, double relative_tol = 1e-12);

// The mesh's constraint triangles as a PLC: every mesh vertex a point, every boundary/interface
// triangle a facet of its own (its tag the marker), the volume holes and region seeds of `plc`.
// A refinement round edits this PLC, not the model's: a triangle's three corners are always coplanar,
// so points added to it never leave TetGen a large facet that is planar only to rounding, and the
// vertices of every earlier round (TetGen's own among them) stay where they were.
Plc surface_plc(const Mesh& mesh, const Plc& plc);

// Makes coordinates that differ by rounding alone (within relative_tol of the PLC's extent, per axis)
// equal: the value most points have wins. A model's arithmetic leaves the corners of one straight
// edge at x = 0.0025 and x = 0.0025000000000000005; to TetGen's exact predicates that edge then has a
// kink, and its segment recovery loops or asserts on the split points along it. Returns the number
// of coordinates changed.
std::size_t snap_coordinates(Plc& plc, double relative_tol = 1e-12);

// Volume per tet region. A refinement only adds points on the PLC's facets and inside its regions,
// so every round's mesh must have the first mesh's regions and volumes: a round that does not
// (TetGen lost a facet of the refined PLC and a region leaked into another) is rejected.
std::map<std::int32_t, double> region_volumes(const Mesh& mesh);
bool same_region_volumes(const std::map<std::int32_t, double>& a, const std::map<std::int32_t, double>& b);

// Points added in one refinement pass, for "is there one within r of p" (a hashed uniform grid).
class NearPoints {
 public:
  explicit NearPoints(double cell) : cell_(cell > 0 ? cell : 1) {}
  bool near(const Vec& p, double r) const;
  void add(const Vec& p);

 private:
  std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  }
  std::int64_t cell_of(double v) const { return static_cast<std::int64_t>(std::floor(v / cell_)); }
  double cell_;
  std::unordered_map<std::int64_t, std::vector<Vec>> cells_;
};

// Splits the constraint triangles flagged in `split` (mesh.bface indices; `face_ball` their
// diametral spheres): a triangle's circumcentre goes into its facet, or, when that centre falls
// outside the facet or encroaches a PLC segment among the triangle's edges, the nearest such
// subsegment's midpoint into the segment (Ruppert/Shewchuk's rule); points on thin-layer faces are
// mirrored. `added` holds this pass's points: a split point closer to one of them than `spacing`
// times the triangle's circumradius is skipped. Larger triangles are split first. Returns the number
// of points added.
std::size_t split_faces(const Mesh& mesh, const std::vector<Ball>& face_ball, const std::vector<char>& split,
                        EditablePlc& edit, NearPoints& added, double spacing = 1e-3);

}  // namespace foxi::detail
