#include "plc_edit.hpp"

#include <limits>

namespace foxi::detail {

namespace {

double polygon_area2(const EditablePlc& e, const std::vector<std::uint32_t>& poly) {
  Vec n{0, 0, 0};
  for (std::size_t i = 0; i < poly.size(); ++i)
    n = add(n, cross(e.point(poly[i]), e.point(poly[(i + 1) % poly.size()])));
  return norm2(n);
}

}  // namespace

bool EditablePlc::in_facet(std::size_t f, const Vec& p0, const Vec& p1, const Vec& p2, const Vec& p) const {
  bool inside = false;
  for (const auto& poly : facets[f])
    if (poly.size() >= 3 && in_polygon(poly, p0, p1, p2, p)) inside = true;
  if (!inside) return false;
  for (std::uint32_t h = plc.facet_hole_begin[f]; h < plc.facet_hole_begin[f + 1]; ++h) {
    const Vec hole = at(plc.facet_holes, h);
    const std::vector<std::uint32_t>* smallest = nullptr;
    double smallest_area = 0;
    for (const auto& poly : facets[f])
      if (poly.size() >= 3 && in_polygon(poly, p0, p1, p2, hole)) {
        const double a = polygon_area2(*this, poly);
        if (!smallest || a < smallest_area) {
          smallest = &poly;
          smallest_area = a;
        }
      }
    if (smallest && in_polygon(*smallest, p0, p1, p2, p)) return false;
  }
  return true;
}

std::size_t EditablePlc::facet_at(const Vec& p) const {
  for (std::size_t f = 0; f < facets.size(); ++f)
    for (const auto& poly : facets[f]) {
      if (poly.size() < 3) continue;
      Vec n{0, 0, 0};
      add_newell_normal(plc.points, poly.data(), poly.size(), n);
      const double nn = std::sqrt(norm2(n));
      if (!(nn > 0) || std::abs(dot(sub(p, point(poly[0])), n)) > tol * nn) continue;
      const Vec p0 = point(poly[0]);
      const Vec u = cross(n, Vec{1, 0, 0}), w = cross(n, Vec{0, 1, 0});
      const Vec e = norm2(u) > norm2(w) ? u : w;  // any in-plane direction
      if (in_facet(f, p0, add(p0, e), add(p0, cross(n, e)), p)) return f;
    }
  return facets.size();
}

bool EditablePlc::nearest_facet_edge(std::size_t f, const Vec& p, double within, std::uint32_t& a,
                                     std::uint32_t& b) const {
  double best = within * within;
  bool found = false;
  for (const auto& poly : facets[f]) {
    if (poly.size() < 2) continue;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      if (poly.size() == 2 && i == 1) break;
      const std::uint32_t u = poly[i], v = poly[(i + 1) % poly.size()];
      const Vec pu = point(u), d = sub(point(v), pu);
      const double l2 = norm2(d);
      if (!(l2 > 0)) continue;
      const double t = std::clamp(dot(sub(p, pu), d) / l2, 0.0, 1.0);
      const double d2 = norm2(sub(p, add(pu, scale(d, t))));
      if (d2 < best && t > 0 && t < 1) {
        best = d2;
        a = u;
        b = v;
        found = true;
      }
    }
  }
  return found;
}

bool EditablePlc::insert_surface_point(const Vec& p) {
  std::uint32_t a = 0, b = 0;
  if (find_segment(p, p, a, b)) {
    split_segment(a, b, add_point(p));
    return true;
  }
  const std::size_t f = facet_at(p);
  if (f == facets.size()) return false;
  facet_points[f].push_back(add_point(p));
  return true;
}

namespace {

std::vector<std::uint32_t> used_vertices(const Mesh& mesh) {
  std::vector<char> used(mesh.node_count(), 0);
  for (std::uint32_t v : mesh.tet) used[v] = 1;
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t v = 0; v < used.size(); ++v)
    if (used[v]) vertices.push_back(v);
  return vertices;
}

}  // namespace

MeshSearch::MeshSearch(const Mesh& m) : mesh(m), vertices(m.xyz, used_vertices(m)) {
  const std::size_t nf = m.bface_count();
  face_ball.resize(nf);
  for (std::size_t f = 0; f < nf; ++f)
    face_ball[f] = triangle_ball(at(m.xyz, m.bface[3 * f]), at(m.xyz, m.bface[3 * f + 1]),
                                 at(m.xyz, m.bface[3 * f + 2]));
  // Each triangle goes into the cells its ball's box covers; balls covering very many cells are
  // checked for every query instead.
  const std::size_t cells = vertices.dim[0] * vertices.dim[1] * vertices.dim[2];
  face_begin_.assign(cells + 1, 0);
  auto cover = [&](std::uint32_t f, auto&& visit) {
    const Ball& b = face_ball[f];
    const double r = std::sqrt(b.r2);
    const std::array<std::size_t, 3> lo{vertices.coord(b.c[0] - r, 0), vertices.coord(b.c[1] - r, 1),
                                        vertices.coord(b.c[2] - r, 2)};
    const std::array<std::size_t, 3> hi{vertices.coord(b.c[0] + r, 0), vertices.coord(b.c[1] + r, 1),
                                        vertices.coord(b.c[2] + r, 2)};
    if ((hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1) > 512) return false;
    for (std::size_t z = lo[2]; z <= hi[2]; ++z)
      for (std::size_t y = lo[1]; y <= hi[1]; ++y)
        for (std::size_t x = lo[0]; x <= hi[0]; ++x) visit(vertices.index({x, y, z}));
    return true;
  };
  std::vector<char> big(nf, 0);
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (face_ball[f].r2 < 0) continue;
    if (!cover(f, [&](std::size_t cell) { ++face_begin_[cell + 1]; })) {
      big[f] = 1;
      big_faces_.push_back(f);
    }
  }
  for (std::size_t i = 1; i < face_begin_.size(); ++i) face_begin_[i] += face_begin_[i - 1];
  face_items_.resize(face_begin_.back());
  std::vector<std::uint32_t> fill(face_begin_.begin(), face_begin_.end() - 1);
  for (std::uint32_t f = 0; f < nf; ++f)
    if (face_ball[f].r2 >= 0 && !big[f]) cover(f, [&](std::size_t cell) { face_items_[fill[cell]++] = f; });
}

void mark_faces_for_violations(const MeshSearch& search, const std::vector<std::uint32_t>& violating_tets,
                               std::vector<char>& split) {
  const Mesh& mesh = search.mesh;
  for (std::uint32_t t : violating_tets) {
    if (t >= mesh.tet_count()) continue;
    const std::uint32_t* tv = &mesh.tet[4 * std::size_t(t)];
    const Ball b =
        tet_ball(at(mesh.xyz, tv[0]), at(mesh.xyz, tv[1]), at(mesh.xyz, tv[2]), at(mesh.xyz, tv[3]));
    if (b.r2 < 0) continue;
    const double r = std::sqrt(b.r2);
    // The vertices inside; the certificate is exact, so if rounding hides them take the deepest one.
    std::vector<std::uint32_t> inside;
    std::uint32_t deepest = kNone;
    double deepest_ratio = std::numeric_limits<double>::infinity();
    search.vertices.for_each_in_box(b.c, r * (1 + 1e-9), [&](std::uint32_t v) {
      if (v == tv[0] || v == tv[1] || v == tv[2] || v == tv[3]) return;
      const double ratio = norm2(sub(at(mesh.xyz, v), b.c)) / b.r2;
      if (ratio < 1 - 1e-12) inside.push_back(v);
      if (ratio < deepest_ratio) {
        deepest_ratio = ratio;
        deepest = v;
      }
    });
    if (inside.empty() && deepest != kNone && deepest_ratio < 1 + 1e-9) inside.push_back(deepest);
    std::size_t marked = 0;
    for (std::uint32_t q : inside)
      search.for_each_encroached(at(mesh.xyz, q), [&](std::uint32_t f) {
        const std::uint32_t* fv = &mesh.bface[3 * std::size_t(f)];
        if (fv[0] == q || fv[1] == q || fv[2] == q) return;
        const Ball& fb = search.face_ball[f];
        if (std::sqrt(norm2(sub(fb.c, b.c))) < std::sqrt(fb.r2) + r) {
          split[f] = 1;
          ++marked;
        }
      });
    if (marked > 0) continue;
    const Vec centroid = scale(
        add(add(at(mesh.xyz, tv[0]), at(mesh.xyz, tv[1])), add(at(mesh.xyz, tv[2]), at(mesh.xyz, tv[3]))),
        0.25);
    for (std::uint32_t q : inside)
      search.for_each_face_crossed(centroid, at(mesh.xyz, q), [&](std::uint32_t f) {
        const std::uint32_t* fv = &mesh.bface[3 * std::size_t(f)];
        if (fv[0] != q && fv[1] != q && fv[2] != q) split[f] = 1;
      });
  }
}

bool MeshSearch::segment_crosses_face(const Vec& p, const Vec& q, std::uint32_t face) const {
  const std::uint32_t* fv = &mesh.bface[3 * std::size_t(face)];
  const Vec a = at(mesh.xyz, fv[0]), e1 = sub(at(mesh.xyz, fv[1]), a), e2 = sub(at(mesh.xyz, fv[2]), a);
  const Vec d = sub(q, p), h = cross(d, e2);
  const double det = dot(e1, h);
  if (!(std::abs(det) > 1e-12 * std::sqrt(norm2(d) * norm2(e1) * norm2(e2)))) return false;  // parallel
  const double eps = 1e-9;
  const Vec s = sub(p, a);
  const double u = dot(s, h) / det;
  if (u < -eps || u > 1 + eps) return false;
  const Vec sxe = cross(s, e1);
  const double v = dot(d, sxe) / det;
  if (v < -eps || u + v > 1 + eps) return false;
  const double t = dot(e2, sxe) / det;
  return t > -eps && t < 1 + eps;
}

Plc surface_plc(const Mesh& mesh, const Plc& plc) {
  Plc out;
  out.points = mesh.xyz;
  const std::size_t nf = mesh.bface_count();
  out.polygon_vertices = mesh.bface;
  out.polygon_vertex_begin.resize(nf + 1);
  out.facet_polygon_begin.resize(nf + 1);
  for (std::uint32_t f = 0; f <= nf; ++f) {
    out.polygon_vertex_begin[f] = 3 * f;
    out.facet_polygon_begin[f] = f;
  }
  out.facet_marker = mesh.bface_tag;
  out.facet_hole_begin.assign(nf + 1, 0);
  out.holes = plc.holes;
  out.regions = plc.regions;
  return out;
}

std::size_t snap_coordinates(Plc& plc, double relative_tol) {
  const std::size_t n = plc.point_count();
  if (n == 0) return 0;
  std::size_t changed = 0;
  std::vector<std::uint32_t> order(n);
  for (std::size_t k = 0; k < 3; ++k) {
    auto value = [&](std::uint32_t i) { return plc.points[3 * i + k]; };
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return value(a) < value(b); });
    const double tol = relative_tol * (std::abs(value(order.front())) + std::abs(value(order.back())) +
                                       (value(order.back()) - value(order.front())));
    // Clusters no wider than tol (no chaining along a dense run); the most common value wins.
    for (std::size_t a = 0; a < n;) {
      std::size_t b = a + 1;
      while (b < n && value(order[b]) - value(order[a]) <= tol) ++b;
      if (value(order[b - 1]) != value(order[a])) {
        double best = value(order[a]);
        std::size_t best_count = 0;
        for (std::size_t i = a; i < b;) {
          std::size_t j = i;
          while (j < b && value(order[j]) == value(order[i])) ++j;
          if (j - i > best_count) {
            best_count = j - i;
            best = value(order[i]);
          }
          i = j;
        }
        for (std::size_t i = a; i < b; ++i)
          if (value(order[i]) != best) {
            plc.points[3 * order[i] + k] = best;
            ++changed;
          }
      }
      a = b;
    }
  }
  return changed;
}

std::size_t weld_coincident_points(Plc& plc, double relative_tol) {
  const std::size_t n = plc.point_count();
  if (n == 0) return 0;
  Vec lo = at(plc.points, 0), hi = lo;
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], plc.points[3 * i + k]);
      hi[k] = std::max(hi[k], plc.points[3 * i + k]);
    }
  const double tol = relative_tol * std::sqrt(norm2(sub(hi, lo)));
  std::vector<std::uint32_t> order(n), target(n);
  for (std::uint32_t i = 0; i < n; ++i) order[i] = target[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return plc.points[3 * a] < plc.points[3 * b]; });
  std::size_t merged = 0;
  for (std::size_t a = 0; a < n; ++a) {
    const std::uint32_t i = order[a];
    if (target[i] != i) continue;
    for (std::size_t b = a + 1; b < n && plc.points[3 * order[b]] - plc.points[3 * i] <= tol; ++b) {
      const std::uint32_t j = order[b];
      if (target[j] == j && norm2(sub(at(plc.points, j), at(plc.points, i))) <= tol * tol) {
        target[j] = std::min(i, j);
        target[i] = std::min(i, j);
        ++merged;
      }
    }
  }
  if (merged == 0) return 0;
  for (std::uint32_t i = 0; i < n; ++i)  // chains end at a point that is its own target
    while (target[target[i]] != target[i]) target[i] = target[target[i]];
  // Drop the merged points, renumbering the others in order.
  std::vector<std::uint32_t> renumber(n);
  std::vector<double> kept;
  kept.reserve(plc.points.size());
  for (std::uint32_t i = 0; i < n; ++i)
    if (target[i] == i) {
      renumber[i] = static_cast<std::uint32_t>(kept.size() / 3);
      kept.insert(kept.end(), plc.points.begin() + 3 * std::ptrdiff_t(i),
                  plc.points.begin() + 3 * std::ptrdiff_t(i) + 3);
    }
  for (std::uint32_t i = 0; i < n; ++i) target[i] = renumber[target[i]];
  plc.points = std::move(kept);
  std::vector<std::uint32_t> begin{0}, vertices;
  for (std::size_t g = 0; g + 1 < plc.polygon_vertex_begin.size(); ++g) {
    const std::size_t first = vertices.size();
    for (std::uint32_t k = plc.polygon_vertex_begin[g]; k < plc.polygon_vertex_begin[g + 1]; ++k) {
      const std::uint32_t v = target[plc.polygon_vertices[k]];
      if (vertices.size() > first && vertices.back() == v) continue;
      vertices.push_back(v);
    }
    while (vertices.size() > first + 1 && vertices.back() == vertices[first]) vertices.pop_back();
    begin.push_back(static_cast<std::uint32_t>(vertices.size()));
  }
  plc.polygon_vertices = std::move(vertices);
  plc.polygon_vertex_begin = std::move(begin);
  return merged;
}

std::map<std::int32_t, double> region_volumes(const Mesh& mesh) {
  std::map<std::int32_t, double> v;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::uint32_t* n = &mesh.tet[4 * t];
    const Vec a = at(mesh.xyz, n[0]);
    v[mesh.region_of(t)] += std::abs(dot(sub(at(mesh.xyz, n[1]), a),
                                         cross(sub(at(mesh.xyz, n[2]), a), sub(at(mesh.xyz, n[3]), a)))) /
                            6;
  }
  return v;
}

bool same_region_volumes(const std::map<std::int32_t, double>& a, const std::map<std::int32_t, double>& b) {
  if (a.size() != b.size()) return false;
  for (const auto& [id, vol] : a) {
    const auto it = b.find(id);
    if (it == b.end() || std::abs(it->second - vol) > 1e-9 * std::max(vol, it->second)) return false;
  }
  return true;
}

bool NearPoints::near(const Vec& p, double r) const {
  const std::int64_t x0 = cell_of(p[0] - r), x1 = cell_of(p[0] + r), y0 = cell_of(p[1] - r),
                     y1 = cell_of(p[1] + r), z0 = cell_of(p[2] - r), z1 = cell_of(p[2] + r);
  const std::int64_t span = std::max({x1 - x0, y1 - y0, z1 - z0}) + 1;
  if (span > 16) {  // a huge ball: look at every point
    for (const auto& kv : cells_)
      for (const Vec& q : kv.second)
        if (norm2(sub(q, p)) < r * r) return true;
    return false;
  }
  for (std::int64_t z = z0; z <= z1; ++z)
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) {
        const auto it = cells_.find(key(x, y, z));
        if (it == cells_.end()) continue;
        for (const Vec& q : it->second)
          if (norm2(sub(q, p)) < r * r) return true;
      }
  return false;
}

void NearPoints::add(const Vec& p) { cells_[key(cell_of(p[0]), cell_of(p[1]), cell_of(p[2]))].push_back(p); }

std::size_t split_faces(const Mesh& mesh, const std::vector<Ball>& face_ball, const std::vector<char>& split,
                        EditablePlc& edit, NearPoints& added, double spacing) {
  const std::size_t before = edit.plc.point_count();
  auto exists = [&](const Vec& q) { return added.near(q, 1e-9 * std::sqrt(norm2(q)) + edit.tol); };
  auto accept = [&](const Vec& q) {
    added.add(q);
    edit.mirror(q, [&](const Vec& m) {
      if (exists(m)) return true;
      added.add(m);
      return false;
    });
  };
  std::vector<std::uint32_t> order;
  for (std::uint32_t f = 0; f < split.size(); ++f)
    if (split[f]) order.push_back(f);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return face_ball[a].r2 > face_ball[b].r2; });
  for (std::uint32_t f : order) {
    const std::uint32_t* fv = &mesh.bface[3 * f];
    const Vec p[3] = {at(mesh.xyz, fv[0]), at(mesh.xyz, fv[1]), at(mesh.xyz, fv[2])};
    const Ball& fb = face_ball[f];
    const double size = std::sqrt(fb.r2);
    const std::size_t facet = edit.surface ? f : edit.find_facet(mesh.bface_tag[f], p[0], p[1], p[2]);
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
      if (edit.surface) {
        a = fv[e];
        b = fv[(e + 1) % 3];
        if (!edit.edge_facets.count(edge_key(a, b)) && !edit.split_at.count(edge_key(a, b))) continue;
      } else if (!edit.find_segment(u, v, a, b)) {
        continue;
      }
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
      if (added.near(mid, spacing * size)) continue;
      // The segment may have been split already in this pass: find the piece that holds mid now.
      std::uint32_t a = sa, b = sb;
      if (edit.surface)
        edit.piece_holding(mid, a, b);
      else if (!edit.on_segment(mid, a, b) || !edit.find_segment(mid, mid, a, b))
        continue;
      edit.split_segment(a, b, edit.add_point(mid));
      accept(mid);
    } else if (facet < edit.facets.size()) {
      Vec c = centre_in_facet ? fb.c : scale(add(add(p[0], p[1]), p[2]), 1.0 / 3);
      // A point almost on a segment of its facet makes TetGen's segment recovery fail (it sees the
      // point on the segment within its own tolerance): such a point splits that subsegment at its
      // midpoint instead.
      std::uint32_t a = 0, b = 0;
      if (edit.nearest_facet_edge(facet, c, 0.05 * size, a, b)) {
        const Vec mid = scale(add(edit.point(a), edit.point(b)), 0.5);
        if (added.near(mid, spacing * size)) continue;
        edit.split_segment(a, b, edit.add_point(mid));
        accept(mid);
        continue;
      }
      if (added.near(c, spacing * size)) continue;
      // A point on some segment of the facet would be a second copy of a segment vertex to TetGen.
      const std::uint32_t k = edit.add_point(c);
      if (!edit.surface && edit.find_segment(c, c, a, b))
        edit.split_segment(a, b, k);
      else
        edit.facet_points[facet].push_back(k);
      accept(c);
    }
  }
  return edit.plc.point_count() - before;
}

}  // namespace foxi::detail
