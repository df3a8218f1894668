// Validation of the mesh database: sizes, indices, repeated vertices, non-finite coordinates, exact
// orientation of every tet (CGAL's filtered exact predicate), geometry beyond the range of double,
// duplicate tets and coincident nodes, overlapping tets (validate_overlap.cpp), unused nodes.
#include "foxi/model/validate.hpp"

#include "validate_overlap.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace foxi {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;

constexpr std::size_t kMaxMessages = 20;

void note(ValidationReport& r, std::string message) {
  if (r.messages.size() < kMaxMessages) r.messages.push_back(std::move(message));
}

std::string ids(const std::uint32_t* v, int count) {
  std::string s = "(";
  for (int j = 0; j < count; ++j) s += (j ? " " : "") + std::to_string(v[j]);
  return s + ")";
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// 6 x volume below this has underflowed or lost bits to subnormal products (2^-1022 x 2^53).
constexpr double kMinSixVolume = 0x1p-969;
// The visibility order keeps its keys' error bounds as floats (viz/spheres.hpp: key_a, key_b), about
// 64 eps (|a - origin| + r)^2 for a tet's first vertex a and circumradius r. Beyond 1e24 they
// overflow to inf (measured: a Delaunay mesh of points out to 1e40 was ordered with 5,500 violations
// per view); below a mesh extent of 1e-12 they underflow into subnormal floats.
constexpr double kMaxSphereReach = 1e24;
constexpr double kMinExtent = 1e-12;

// Whether the tet's geometry stays within double range as the certificate, the sphere table and the
// solvers compute it: 6 x volume and the circumcentre relative to the first vertex (centre =
// N / (2 x 6V), N = |B|^2 (C x D) + |C|^2 (D x B) + |D|^2 (B x C)), the circumradius^2 and the
// centre's squared distance from `origin` (the sphere table's frame). On failure `why` says which.
bool geometry_in_range(const double* a, const double* b, const double* c, const double* d,
                       const double* origin, std::string& why) {
  double B[3], C[3], D[3];
  for (int k = 0; k < 3; ++k) {
    B[k] = b[k] - a[k];
    C[k] = c[k] - a[k];
    D[k] = d[k] - a[k];
  }
  auto cross = [](const double* p, const double* q, double* r) {
    r[0] = p[1] * q[2] - p[2] * q[1];
    r[1] = p[2] * q[0] - p[0] * q[2];
    r[2] = p[0] * q[1] - p[1] * q[0];
  };
  double CD[3], DB[3], BC[3];
  cross(C, D, CD);
  cross(D, B, DB);
  cross(B, C, BC);
  const double six_v = B[0] * CD[0] + B[1] * CD[1] + B[2] * CD[2];
  if (!std::isfinite(six_v)) {
    why = "6 x volume overflows double (" + num(six_v) + "; rescale the coordinates)";
    return false;
  }
  const double lB = B[0] * B[0] + B[1] * B[1] + B[2] * B[2];
  const double lC = C[0] * C[0] + C[1] * C[1] + C[2] * C[2];
  const double lD = D[0] * D[0] + D[1] * D[1] + D[2] * D[2];
  if (!(std::abs(six_v) >= kMinSixVolume)) {
    // Edges of normal size: the volume cancelled, the four corners coplanar to their last bits (a
    // mesher's flat sliver), which no rescaling mends.
    const double edge = std::sqrt(std::max({lB, lC, lD}));
    why = edge * edge * edge >= 1e30 * kMinSixVolume
              ? "nearly flat: 6 x volume is " + num(six_v) + " in double against edges of " + num(edge) +
                    " (its corners coplanar to their last bits; mesh again)"
              : "6 x volume underflows double (" + num(six_v) + "; rescale the coordinates)";
    return false;
  }
  double r2 = 0, o2 = 0;
  for (int k = 0; k < 3; ++k) {
    // Each term on its own: a sum of finite terms may hide an overflowed one only as inf or NaN.
    const double n0 = lB * CD[k], n1 = lC * DB[k], n2 = lD * BC[k];
    const double x = (n0 + n1 + n2) / (2 * six_v);
    if (!(std::isfinite(n0) && std::isfinite(n1) && std::isfinite(n2) && std::isfinite(x))) {
      why = "the circumcentre overflows double (rescale the coordinates)";
      return false;
    }
    r2 += x * x;
    const double rel = a[k] - origin[k];
    o2 += rel * rel;
  }
  if (!std::isfinite(r2)) {
    why = "the circumradius^2 overflows double (" + num(r2) + "; rescale the coordinates)";
    return false;
  }
  const double reach = std::sqrt(o2) + std::sqrt(r2);
  if (!(reach <= kMaxSphereReach)) {
    why = "the circumsphere reaches " + num(reach) + " from the mesh's centre, beyond the " +
          num(kMaxSphereReach) +
          " that the visibility order's float error bounds hold (rescale the coordinates)";
    return false;
  }
  return true;
}

// Checks everything; collects the inverted tets when `inverted` is not null.
// size_problem: check_sizes of the Mesh (all its arrays) or of the view.
ValidationReport check(const MeshView& mesh, std::string size_problem, std::vector<std::size_t>* inverted) {
  ValidationReport r;
  r.size_problem = std::move(size_problem);
  // size_problem and no_tets are listed by describe(); messages carry only the per-element details,
  // so a caller printing both does not say the same thing twice.
  if (!r.size_problem.empty()) return r;
  const std::size_t nv = mesh.node_count();
  if (mesh.tet_count() == 0) r.no_tets = true;
  std::vector<std::uint8_t> finite(nv, 1);
  for (std::size_t v = 0; v < nv; ++v) {
    const double* p = &mesh.xyz[3 * v];
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) {
      finite[v] = 0;
      ++r.nonfinite_nodes;
      note(r, "node " + std::to_string(v) + ": non-finite coordinate");
    } else if (!mesh.weight.empty() && !std::isfinite(mesh.weight[v])) {
      // A weight (read from a .vtu/.vtk 'weight' array) that is NaN or infinite has no orthosphere.
      finite[v] = 0;
      ++r.nonfinite_nodes;
      note(r, "node " + std::to_string(v) + ": non-finite weight");
    }
  }
  // The sphere table's frame: the centre of the bounding box of the finite coordinates.
  double origin[3] = {0, 0, 0};
  bool tiny_mesh = false;
  {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = -lo[k];
    }
    for (std::size_t v = 0; v < nv; ++v)
      if (finite[v])
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], mesh.xyz[3 * v + k]);
          hi[k] = std::max(hi[k], mesh.xyz[3 * v + k]);
        }
    double extent2 = 0;
    for (int k = 0; k < 3; ++k)
      if (lo[k] <= hi[k]) {
        origin[k] = 0.5 * lo[k] + 0.5 * hi[k];  // halves first: no overflow
        extent2 += (0.5 * hi[k] - 0.5 * lo[k]) * (0.5 * hi[k] - 0.5 * lo[k]);
      }
    const double extent = 2 * std::sqrt(extent2);
    if (mesh.tet_count() > 0 && extent < kMinExtent) {
      // Every tet is affected; counted as such, with one message for the mesh.
      tiny_mesh = true;
      note(r, "geometry beyond the range foxi computes in: the mesh is " + num(extent) +
                  " across, below the " + num(kMinExtent) +
                  " that the visibility order's float error bounds hold (rescale the coordinates)");
    }
  }
  std::vector<std::uint8_t> used(nv, 0);
  // Sorted node quadruples of the well-formed tets, for the duplicate search.
  std::vector<std::pair<std::array<std::uint32_t, 4>, std::uint32_t>> keys;
  keys.reserve(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    bool in_range = true;
    for (int j = 0; j < 4; ++j)
      if (v[j] >= nv)
        in_range = false;
      else
        used[v[j]] = 1;
    if (!in_range) {
      ++r.index_out_of_range;
      note(r,
           "tet " + std::to_string(t) + " " + ids(v, 4) + ": node index >= node count " + std::to_string(nv));
      continue;
    }
    if (v[0] == v[1] || v[0] == v[2] || v[0] == v[3] || v[1] == v[2] || v[1] == v[3] || v[2] == v[3]) {
      ++r.repeated_vertex;
      note(r, "tet " + std::to_string(t) + " " + ids(v, 4) + ": repeated node");
      continue;
    }
    std::array<std::uint32_t, 4> key = {v[0], v[1], v[2], v[3]};
    std::sort(key.begin(), key.end());
    keys.emplace_back(key, static_cast<std::uint32_t>(t));
    if (!(finite[v[0]] && finite[v[1]] && finite[v[2]] && finite[v[3]])) continue;
    auto pt = [&](std::uint32_t i) {
      return Point(mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]);
    };
    const CGAL::Orientation o = CGAL::orientation(pt(v[0]), pt(v[1]), pt(v[2]), pt(v[3]));
    if (o == CGAL::COPLANAR) {
      ++r.zero_volume;
      note(r, "tet " + std::to_string(t) + " " + ids(v, 4) + ": zero volume");
      continue;
    }
    // One message per tet: a tet both inverted and beyond the range is one line naming both.
    const std::string inverted_note = o == CGAL::NEGATIVE ? "tet " + std::to_string(t) + " " + ids(v, 4) +
                                                                ": inverted (negative orientation)"
                                                          : std::string();
    if (o == CGAL::NEGATIVE) {
      ++r.inverted;
      if (inverted) inverted->push_back(t);
    }
    if (tiny_mesh) {
      ++r.out_of_range;
      if (!inverted_note.empty()) note(r, inverted_note);
      continue;
    }
    std::string why;
    const double* x = mesh.xyz.data();
    // Positively oriented order, so that the signs are those after a repair.
    const bool pos = o == CGAL::POSITIVE;
    if (!geometry_in_range(x + 3 * std::size_t(v[0]), x + 3 * std::size_t(v[1]),
                           x + 3 * std::size_t(v[pos ? 2 : 3]), x + 3 * std::size_t(v[pos ? 3 : 2]), origin,
                           why)) {
      ++r.out_of_range;
      note(r, (inverted_note.empty() ? "tet " + std::to_string(t) + " " + ids(v, 4) + ":"
                                     : inverted_note + ", and") +
                  " geometry beyond the range foxi computes in: " + why);
    } else if (!inverted_note.empty()) {
      note(r, inverted_note);
    }
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (keys[i].first == keys[i - 1].first) {
      ++r.duplicate_tets;
      std::size_t first = i - 1;
      while (first > 0 && keys[first - 1].first == keys[i].first) --first;
      note(r, "tet " + std::to_string(keys[i].second) + " " + ids(keys[i].first.data(), 4) +
                  ": the same nodes as tet " + std::to_string(keys[first].second));
    }
  {
    // Coincident nodes that tets use: the mesh is torn there (the tets do not share the node).
    std::vector<std::uint32_t> pts;
    for (std::size_t v = 0; v < nv; ++v)
      if (used[v] && finite[v]) pts.push_back(static_cast<std::uint32_t>(v));
    auto at = [&](std::uint32_t v) {
      return std::array<double, 3>{mesh.xyz[3 * std::size_t(v)], mesh.xyz[3 * std::size_t(v) + 1],
                                   mesh.xyz[3 * std::size_t(v) + 2]};
    };
    std::sort(pts.begin(), pts.end(),
              [&](std::uint32_t p, std::uint32_t q) { return std::pair(at(p), p) < std::pair(at(q), q); });
    for (std::size_t i = 1; i < pts.size(); ++i)
      if (at(pts[i]) == at(pts[i - 1])) {
        ++r.duplicate_nodes;
        std::size_t first = i - 1;
        while (first > 0 && at(pts[first - 1]) == at(pts[i])) --first;
        const auto p = at(pts[i]);
        note(r, "nodes " + std::to_string(pts[first]) + " and " + std::to_string(pts[i]) +
                    ": the same point (" + num(p[0]) + ", " + num(p[1]) + ", " + num(p[2]) +
                    "), both used by tets");
      }
  }
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    const std::uint32_t* v = &mesh.bface[3 * f];
    if (v[0] >= nv || v[1] >= nv || v[2] >= nv) {
      ++r.index_out_of_range;
      note(r, "boundary triangle " + std::to_string(f) + " " + ids(v, 3) + ": node index >= node count " +
                  std::to_string(nv));
    } else if (v[0] == v[1] || v[0] == v[2] || v[1] == v[2]) {
      ++r.repeated_vertex;
      note(r, "boundary triangle " + std::to_string(f) + " " + ids(v, 3) + ": repeated node");
    }
  }
  if (r.ok()) {
    const OverlapReport o = check_overlap(mesh, kMaxMessages);
    r.overlapping = o.problems();
    for (const std::string& m : o.examples) note(r, m);
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (!used[v]) {
      if (r.unused_nodes == 0)
        note(r, "node " + std::to_string(v) + ": used by no tet (first of the unused)");
      ++r.unused_nodes;
    }
  return r;
}

}  // namespace

ValidationReport validate(const Mesh& mesh) { return check(mesh, check_sizes(mesh), nullptr); }

ValidationReport validate(const MeshView& mesh) { return check(mesh, check_sizes(mesh), nullptr); }

std::vector<std::string> describe(const ValidationReport& r) {
  std::vector<std::string> out;
  auto add = [&](std::size_t n, const char* one, const char* many, const char* tail) {
    if (n) out.push_back(std::to_string(n) + " " + (n == 1 ? one : many) + tail);
  };
  if (!r.size_problem.empty()) out.push_back(r.size_problem);
  if (r.no_tets) out.push_back("no tets: not a volume mesh (nothing to order, draw or solve)");
  add(r.index_out_of_range, "element", "elements", " with a node index out of range");
  add(r.repeated_vertex, "element", "elements", " naming one node twice");
  add(r.nonfinite_nodes, "node", "nodes", " with NaN or infinite coordinates");
  add(r.zero_volume, "tet", "tets", " of zero volume");
  add(r.out_of_range, "tet", "tets",
      " with geometry beyond the range foxi computes in (volumes, circumspheres, keys)");
  add(r.duplicate_tets, "tet", "tets", " repeating an earlier tet's nodes");
  add(r.overlapping, "place", "places",
      " where tets overlap (folded or crossing faces, or a tet inside another)");
  add(r.duplicate_nodes, "node", "nodes", " at the point of another node (the mesh is torn there)");
  add(r.inverted, "inverted tet", "inverted tets", " (negative orientation; every command re-orients them)");
  add(r.unused_nodes, "node", "nodes", " used by no tet");
  return out;
}

ValidationReport validate_and_repair(Mesh& mesh) {
  std::vector<std::size_t> inverted;
  ValidationReport r = check(mesh, check_sizes(mesh), &inverted);
  for (std::size_t t : inverted) std::swap(mesh.tet[4 * t + 2], mesh.tet[4 * t + 3]);
  if (!inverted.empty()) invalidate_derived(mesh);
  return r;
}

}  // namespace foxi
