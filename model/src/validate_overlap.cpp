// Overlapping tets: the checks of validation that look at more than one tet. Every other check of
// validate.cpp is local to a tet; a mesh can pass them all and still not be a mesh (tets that cover
// the same space), which breaks the promise of every algorithm downstream: the visibility order, the
// undoable painter, the solvers' assembly. All predicates are CGAL's exact ones (Epick's filtered
// orientation, coplanar orientation, angle and triangle/segment tests).
//
// When the tets are consistently oriented, the number of tets that cover a point, w(x), is constant
// across every face two tets share on opposite sides, and steps by one across a boundary face. So
// the tets tile their union exactly once (w is 0 or 1 everywhere) when
//  1. no face is shared by three or more tets, nor by two on the same side of it (a fold);
//  2. the boundary faces (faces of one tet) meet only in the vertices and edges they share
//     (box_self_intersection_d over their bounding boxes, then exact tests);
//  3. w = 1 at one point strictly inside a tet on each connected piece of the boundary: with 2, w is
//     the winding number of an embedded surface, constant inside each piece, and this catches a
//     shell nested in another with the same orientation (a small mesh inside a large one).
#include "validate_overlap.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <numeric>

#include "foxi/model/adjacency.hpp"

namespace foxi {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::uint32_t>;

constexpr int kFaceVertex[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

Point point_of(const MeshView& m, std::uint32_t v) {
  return Point(m.xyz[3 * std::size_t(v)], m.xyz[3 * std::size_t(v) + 1], m.xyz[3 * std::size_t(v) + 2]);
}

std::array<std::uint32_t, 3> face_nodes(const MeshView& m, std::size_t t, int f) {
  const std::uint32_t* v = &m.tet[4 * t];
  return {v[kFaceVertex[f][0]], v[kFaceVertex[f][1]], v[kFaceVertex[f][2]]};
}

// For coplanar rays from p: whether the open angles (p; a, b) and (p; c, d), each less than a half
// turn, share a direction. coplanar_orientation(p, u, v) orients every triple of the plane alike.
bool wedges_overlap(const Point& p, Point a, Point b, Point c, Point d) {
  auto turn = [&](const Point& u, const Point& v) { return CGAL::coplanar_orientation(p, u, v); };
  if (turn(a, b) == CGAL::NEGATIVE) std::swap(a, b);
  if (turn(c, d) == CGAL::NEGATIVE) std::swap(c, d);
  auto inside = [&](const Point& x, const Point& lo, const Point& hi) {
    return turn(lo, x) == CGAL::POSITIVE && turn(x, hi) == CGAL::POSITIVE;
  };
  auto same_ray = [&](const Point& u, const Point& v) {
    return turn(u, v) == CGAL::COLLINEAR && CGAL::angle(u, p, v) == CGAL::ACUTE;
  };
  return inside(c, a, b) || inside(d, a, b) || inside(a, c, d) || inside(b, c, d) ||
         (same_ray(a, c) && same_ray(b, d));
}

// Whether two boundary triangles meet in more than the vertices they share (exact).
bool triangles_overlap(const MeshView& m, const std::array<std::uint32_t, 3>& a,
                       const std::array<std::uint32_t, 3>& b) {
  int shared = 0, sa[3] = {-1, -1, -1};  // sa[i]: index in b of a[i], or -1
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] == b[j]) {
        sa[i] = j;
        ++shared;
      }
  const Point pa[3] = {point_of(m, a[0]), point_of(m, a[1]), point_of(m, a[2])};
  const Point pb[3] = {point_of(m, b[0]), point_of(m, b[1]), point_of(m, b[2])};
  if (shared == 3) return true;  // the same triangle twice on the boundary: two tets on one side
  if (shared == 0)
    return CGAL::do_intersect(K::Triangle_3(pa[0], pa[1], pa[2]), K::Triangle_3(pb[0], pb[1], pb[2]));
  if (shared == 2) {
    // A shared edge pq: they overlap only if coplanar with the third vertices on one side of pq.
    int ia = 0;
    while (sa[ia] != -1) ++ia;  // a's vertex off the edge
    int ib = 0;
    while (ib == sa[0] || ib == sa[1] || ib == sa[2]) ++ib;  // b's vertex off the edge
    const int p = (ia + 1) % 3, q = (ia + 2) % 3;
    if (CGAL::orientation(pa[p], pa[q], pa[ia], pb[ib]) != CGAL::COPLANAR) return false;
    return CGAL::coplanar_orientation(pa[p], pa[q], pa[ia], pb[ib]) == CGAL::POSITIVE;
  }
  // One shared vertex p: the edge of each opposite p must miss the other triangle.
  int ia = 0;
  while (sa[ia] == -1) ++ia;
  const int ib = sa[ia];
  const K::Segment_3 opposite_a(pa[(ia + 1) % 3], pa[(ia + 2) % 3]);
  const K::Segment_3 opposite_b(pb[(ib + 1) % 3], pb[(ib + 2) % 3]);
  const K::Triangle_3 ta(pa[0], pa[1], pa[2]), tb(pb[0], pb[1], pb[2]);
  if (CGAL::do_intersect(opposite_a, tb) || CGAL::do_intersect(opposite_b, ta)) return true;
  if (CGAL::orientation(pa[0], pa[1], pa[2], pb[(ib + 1) % 3]) != CGAL::COPLANAR ||
      CGAL::orientation(pa[0], pa[1], pa[2], pb[(ib + 2) % 3]) != CGAL::COPLANAR)
    return false;  // not coplanar: the two meet on a line through p, which an opposite edge would cross
  // Coplanar with one shared vertex p (every pair of neighbours on a flat side of the boundary):
  // with no edge crossing, they overlap exactly when their angles at p overlap.
  return wedges_overlap(pa[ia], pa[(ia + 1) % 3], pa[(ia + 2) % 3], pb[(ib + 1) % 3], pb[(ib + 2) % 3]);
}

// Whether p lies in the closed tet t (exact; either orientation).
bool tet_contains(const MeshView& m, std::size_t t, const Point& p) {
  const std::uint32_t* v = &m.tet[4 * t];
  const Point q[4] = {point_of(m, v[0]), point_of(m, v[1]), point_of(m, v[2]), point_of(m, v[3])};
  const CGAL::Orientation o = CGAL::orientation(q[0], q[1], q[2], q[3]);
  for (int f = 0; f < 4; ++f) {
    Point r[4] = {q[0], q[1], q[2], q[3]};
    r[f] = p;
    const CGAL::Orientation s = CGAL::orientation(r[0], r[1], r[2], r[3]);
    if (s != CGAL::COPLANAR && s != o) return false;
  }
  return true;
}

std::uint32_t find(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

OverlapReport check_overlap(const MeshView& mesh, std::size_t max_examples) {
  OverlapReport r;
  const FaceAdjacency& adj = face_adjacency(mesh);
  r.nonmanifold_faces = adj.nonmanifold_faces;
  auto example = [&](std::string s) {
    if (r.examples.size() < max_examples) r.examples.push_back(std::move(s));
  };
  if (adj.nonmanifold_faces > 0) example("a triangle is a face of three or more tets (they overlap)");

  // 1. Folds: the two tets on a face must lie on its two sides.
  std::vector<std::size_t> boundary;  // 4t+f of the boundary faces
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::uint32_t n = adj.neighbour[4 * t + f];
      if (n == kNone) {
        boundary.push_back(4 * t + f);
        continue;
      }
      const std::size_t u = n / 4;
      if (u < t) continue;  // each pair once
      const auto tri = face_nodes(mesh, t, f);
      const Point a = point_of(mesh, tri[0]), b = point_of(mesh, tri[1]), c = point_of(mesh, tri[2]);
      const CGAL::Orientation st = CGAL::orientation(a, b, c, point_of(mesh, mesh.tet[4 * t + f]));
      const CGAL::Orientation su = CGAL::orientation(a, b, c, point_of(mesh, mesh.tet[n]));
      if (st == su) {
        ++r.folded_faces;
        example("tets " + std::to_string(t) + " and " + std::to_string(u) +
                " lie on the same side of their shared face (they overlap)");
      }
    }
  // A non-manifold face has no neighbour in the adjacency; its tets are counted there, not here.
  if (r.nonmanifold_faces > 0 || r.folded_faces > 0) return r;

  // 2. The boundary faces meet only where they share vertices and edges.
  std::vector<Box> boxes;
  boxes.reserve(boundary.size());
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const auto tri = face_nodes(mesh, boundary[i] / 4, int(boundary[i] % 4));
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = hi[k] = mesh.xyz[3 * std::size_t(tri[0]) + k];
      for (int j = 1; j < 3; ++j) {
        lo[k] = std::min(lo[k], mesh.xyz[3 * std::size_t(tri[j]) + k]);
        hi[k] = std::max(hi[k], mesh.xyz[3 * std::size_t(tri[j]) + k]);
      }
    }
    boxes.emplace_back(lo, hi, static_cast<std::uint32_t>(i));
  }
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& x, const Box& y) {
    const std::size_t fx = boundary[x.info()], fy = boundary[y.info()];
    if (triangles_overlap(mesh, face_nodes(mesh, fx / 4, int(fx % 4)),
                          face_nodes(mesh, fy / 4, int(fy % 4)))) {
      ++r.crossing_boundary_faces;
      example("boundary faces of tets " + std::to_string(fx / 4) + " and " + std::to_string(fy / 4) +
              " cross (the tets overlap)");
    }
  });
  if (r.crossing_boundary_faces > 0) return r;

  // 3. One point inside a tet of each connected piece of the boundary is covered by that tet only.
  std::vector<std::uint32_t> parent(boundary.size());
  std::iota(parent.begin(), parent.end(), 0u);
  {
    // Pieces: boundary faces joined through shared edges (sorted edge keys, no hashing).
    std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
    edges.reserve(3 * boundary.size());
    for (std::size_t i = 0; i < boundary.size(); ++i) {
      const auto tri = face_nodes(mesh, boundary[i] / 4, int(boundary[i] % 4));
      for (int e = 0; e < 3; ++e) {
        const std::uint64_t p = std::min(tri[e], tri[(e + 1) % 3]), q = std::max(tri[e], tri[(e + 1) % 3]);
        edges.emplace_back(p << 32 | q, static_cast<std::uint32_t>(i));
      }
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 1; i < edges.size(); ++i)
      if (edges[i].first == edges[i - 1].first)
        parent[find(parent, edges[i].second)] = find(parent, edges[i - 1].second);
  }
  std::vector<std::uint32_t> probe_tets;  // one tet on each piece
  for (std::uint32_t i = 0; i < boundary.size(); ++i)
    if (find(parent, i) == i) probe_tets.push_back(static_cast<std::uint32_t>(boundary[i] / 4));
  r.boundary_pieces = probe_tets.size();
  // The probe: the centroid, kept only if it is strictly inside its tet (it is, unless the tet is
  // too thin for the rounded centroid, when the piece is left unprobed).
  std::vector<Box> probes;
  std::vector<Point> probe_points;
  for (std::uint32_t t : probe_tets) {
    const std::uint32_t* v = &mesh.tet[4 * std::size_t(t)];
    double c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = 0.25 * (mesh.xyz[3 * std::size_t(v[0]) + k] + mesh.xyz[3 * std::size_t(v[1]) + k] +
                     mesh.xyz[3 * std::size_t(v[2]) + k] + mesh.xyz[3 * std::size_t(v[3]) + k]);
    const Point p(c[0], c[1], c[2]);
    const Point q[4] = {point_of(mesh, v[0]), point_of(mesh, v[1]), point_of(mesh, v[2]),
                        point_of(mesh, v[3])};
    bool strictly = true;
    for (int f = 0; f < 4; ++f) {
      Point s[4] = {q[0], q[1], q[2], q[3]};
      s[f] = p;
      if (CGAL::orientation(s[0], s[1], s[2], s[3]) != CGAL::orientation(q[0], q[1], q[2], q[3]))
        strictly = false;
    }
    if (!strictly) continue;
    probes.emplace_back(c, c, t);
    probe_points.push_back(p);
  }
  if (probes.empty()) return r;
  auto covered = [&](std::size_t probe, std::uint32_t t) {
    if (probes[probe].info() == t || !tet_contains(mesh, t, probe_points[probe])) return;
    ++r.covered_twice;
    example("tet " + std::to_string(t) + " covers the inside of tet " + std::to_string(probes[probe].info()) +
            " (the tets overlap)");
  };
  auto tet_box = [&](std::size_t t, double* lo, double* hi) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    for (int k = 0; k < 3; ++k) {
      lo[k] = hi[k] = mesh.xyz[3 * std::size_t(v[0]) + k];
      for (int j = 1; j < 4; ++j) {
        lo[k] = std::min(lo[k], mesh.xyz[3 * std::size_t(v[j]) + k]);
        hi[k] = std::max(hi[k], mesh.xyz[3 * std::size_t(v[j]) + k]);
      }
    }
  };
  if (probes.size() <= 16) {
    // Few pieces (the usual case): one pass over the tets' boxes, no box tree to build.
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      double lo[3], hi[3];
      tet_box(t, lo, hi);
      for (std::size_t i = 0; i < probes.size(); ++i) {
        const Point& c = probe_points[i];
        if (lo[0] <= c.x() && c.x() <= hi[0] && lo[1] <= c.y() && c.y() <= hi[1] && lo[2] <= c.z() &&
            c.z() <= hi[2])
          covered(i, static_cast<std::uint32_t>(t));
      }
    }
    return r;
  }
  std::vector<Box> tets;
  tets.reserve(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    double lo[3], hi[3];
    tet_box(t, lo, hi);
    tets.emplace_back(lo, hi, static_cast<std::uint32_t>(t));
  }
  // The probes' boxes are points; a probe's index is found from its tet.
  std::vector<std::pair<std::uint32_t, std::size_t>> probe_of;  // (tet, probe index)
  for (std::size_t i = 0; i < probes.size(); ++i) probe_of.emplace_back(probes[i].info(), i);
  std::sort(probe_of.begin(), probe_of.end());
  CGAL::box_intersection_d(
      probes.begin(), probes.end(), tets.begin(), tets.end(), [&](const Box& p, const Box& t) {
        covered(
            std::lower_bound(probe_of.begin(), probe_of.end(), std::pair(p.info(), std::size_t(0)))->second,
            t.info());
      });
  return r;
}

}  // namespace foxi
