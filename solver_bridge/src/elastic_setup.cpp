// Materials, temperature change and displacement constraints of the thermoelastic solver (see
// elastic_setup.hpp). A node's constraints (fixed components, sliding-plane normals) become an
// orthonormal frame whose first m axes are constrained, so that the solver can rotate the node's
// unknowns into it and eliminate the constrained ones exactly.
#include "elastic_setup.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "p1_assembly.hpp"

namespace foxi::detail {

namespace {

// The unit normal of the plane that holds every triangle of `tag` (triangle orientations may differ);
// SolverError when the triangles are not coplanar to 1e-6 of the tag's extent. Components below 1e-12
// are snapped to 0, so an axis-aligned plane gives an exact axis.
Vec3 plane_normal(const Mesh& mesh, std::int32_t tag) {
  Vec3 n{0, 0, 0}, lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  Vec3 first{0, 0, 0};
  std::uint32_t anchor = kNone;
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    if (mesh.bface_tag[f] != tag) continue;
    const Vec3 a = point(mesh, mesh.bface[3 * f]), b = point(mesh, mesh.bface[3 * f + 1]),
               c = point(mesh, mesh.bface[3 * f + 2]);
    Vec3 nf = cross({b[0] - a[0], b[1] - a[1], b[2] - a[2]}, {c[0] - a[0], c[1] - a[1], c[2] - a[2]});
    if (anchor == kNone) {
      anchor = mesh.bface[3 * f];
      first = nf;
    }
    const double s = dot(nf, first) < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; ++i) n[i] += s * nf[i];
    for (const Vec3* p : {&a, &b, &c})
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(lo[i], (*p)[i]);
        hi[i] = std::max(hi[i], (*p)[i]);
      }
  }
  const double len = std::sqrt(dot(n, n));
  if (!(len > 0)) throw SolverInputError("sliding " + tag_label(mesh, tag) + " has no area");
  for (double& c : n) c /= len;
  for (double& c : n)
    if (std::abs(c) < 1e-12) c = 0;
  const double renorm = std::sqrt(dot(n, n));
  for (double& c : n) c /= renorm;
  const Vec3 extent{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  const double tol = 1e-6 * std::sqrt(dot(extent, extent));
  const Vec3 p0 = point(mesh, anchor);
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    if (mesh.bface_tag[f] != tag) continue;
    for (int i = 0; i < 3; ++i) {
      const Vec3 p = point(mesh, mesh.bface[3 * f + i]);
      const double off = dot({p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]}, n);
      if (std::abs(off) > tol)
        throw SolverInputError("sliding " + tag_label(mesh, tag) + " is not planar: node " +
                               std::to_string(mesh.bface[3 * f + i]) + " lies " + std::to_string(off) +
                               " m off the plane of its triangles; sliding needs one plane per tag");
    }
  }
  return n;
}
// One constraint d . u = value at a node.
struct Constraint {
  std::uint32_t node;
  Vec3 d;
  double value;
};

// Gram-Schmidt of the node's constraints into its frame. A constraint that depends on the earlier ones
// must agree with them (else SolverError naming the node).
void build_frame(const Mesh& mesh, std::uint32_t v, const Constraint* c, std::size_t count, NodeFrames& fr) {
  Vec3 q[3];
  double g[3] = {0, 0, 0};
  int m = 0;
  double scale = 0;
  for (std::size_t k = 0; k < count; ++k) scale = std::max(scale, std::abs(c[k].value));
  for (std::size_t k = 0; k < count && m < 3; ++k) {
    Vec3 d = c[k].d;
    double val = c[k].value;
    for (int j = 0; j < m; ++j) {
      const double p = dot(c[k].d, q[j]);
      for (int i = 0; i < 3; ++i) d[i] -= p * q[j][i];
      val -= p * g[j];
    }
    const double len = std::sqrt(dot(d, d));
    if (len < 1e-6) {
      if (std::abs(val) > 1e-9 * scale + 1e-300) {
        const Vec3 x = point(mesh, v);
        char where[96];
        std::snprintf(where, sizeof where, " (%.6g, %.6g, %.6g)", x[0], x[1], x[2]);
        throw SolverInputError(
            "contradictory displacement constraints at node " + std::to_string(v) + where +
            ": a sliding plane or a fixed component asks for another value than the others");
      }
      continue;
    }
    for (int i = 0; i < 3; ++i) q[m][i] = d[i] / len;
    g[m] = val / len;
    ++m;
  }
  if (m == 1) {
    // The axis least aligned with q0 completes the frame.
    int axis = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(q[0][i]) < std::abs(q[0][axis])) axis = i;
    Vec3 e{0, 0, 0};
    e[axis] = 1;
    const double p = dot(e, q[0]);
    for (int i = 0; i < 3; ++i) e[i] -= p * q[0][i];
    const double len = std::sqrt(dot(e, e));
    for (int i = 0; i < 3; ++i) q[1][i] = e[i] / len;
  }
  if (m <= 2 && m > 0) q[2] = cross(q[0], q[1]);
  fr.m[v] = static_cast<std::uint8_t>(m);
  if (m == 0) return;
  for (int a = 0; a < 3; ++a) {
    for (int i = 0; i < 3; ++i) fr.r[9 * v + 3 * a + i] = q[a][i];
    fr.g[3 * v + a] = g[a];
  }
}

}  // namespace

ElasticMaterials elastic_materials(const Mesh& mesh, const ThermoelasticParams& params) {
  ElasticMaterials out;
  out.regions = region_table(mesh);
  std::vector<std::pair<std::int32_t, double>> e_over, nu_over, alpha_over;
  for (const RegionElasticity& m : params.materials) {
    if (!std::isnan(m.youngs_modulus)) e_over.emplace_back(m.region, m.youngs_modulus);
    if (!std::isnan(m.poisson_ratio)) nu_over.emplace_back(m.region, m.poisson_ratio);
    if (!std::isnan(m.thermal_expansion)) alpha_over.emplace_back(m.region, m.thermal_expansion);
  }
  const std::string hint = "ThermoelasticParams::materials (foxi solve --";
  out.young = region_coefficients(
      mesh, out.regions, [](const Material& m) { return m.youngs_modulus; }, e_over, "Young's modulus",
      hint + "E");
  out.poisson = region_values(
      mesh, out.regions, [](const Material& m) { return m.poisson_ratio; }, nu_over, "Poisson ratio",
      hint + "nu", [](double v) { return v > -1 && v < 0.5; }, "in (-1, 0.5)");
  out.expansion = region_values(
      mesh, out.regions, [](const Material& m) { return m.thermal_expansion; }, alpha_over,
      "thermal expansion", hint + "alpha", [](double v) { return std::isfinite(v); }, "finite");
  return out;
}

std::vector<double> tet_temperature_change(const Mesh& mesh, const ThermoelasticParams& params) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  std::vector<double> tet_dt(nt, params.delta_t);
  check_finite(params.delta_t, "temperature change");
  if (!params.temperature.empty()) {
    if (params.temperature.size() != nn)
      throw SolverInputError("the temperature field has " + std::to_string(params.temperature.size()) +
                             " values for " + std::to_string(nn) + " nodes");
    check_finite(params.reference_temperature, "reference temperature");
    for (std::size_t t = 0; t < nt; ++t) {
      double s = 0;
      for (int a = 0; a < 4; ++a) {
        const std::uint32_t v = mesh.tet[4 * t + a];
        if (!std::isfinite(params.temperature[v]))
          throw SolverInputError("the temperature of node " + std::to_string(v) + " (used by tet " +
                                 std::to_string(t) + ") is not a finite number");
        s += params.temperature[v];
      }
      tet_dt[t] = s / 4 - params.reference_temperature;
    }
  }
  return tet_dt;
}

NodeFrames displacement_frames(const Mesh& mesh, const ThermoelasticParams& params,
                               const std::vector<char>& used) {
  const std::size_t nn = mesh.node_count(), nf = mesh.bface_count();
  const std::vector<std::int32_t> tags = boundary_tag_list(mesh);
  std::map<std::int32_t, int> bc_kind;  // 1 fixed, 2 sliding
  auto claim = [&](std::int32_t tag, int kind, const char* name) {
    if (!std::binary_search(tags.begin(), tags.end(), tag))
      throw SolverInputError(std::string(name) + " condition on " + tag_label(mesh, tag) +
                             ", which tags no boundary triangle");
    if (!bc_kind.emplace(tag, kind).second)
      throw SolverInputError(tag_label(mesh, tag) + " has more than one boundary condition");
  };
  std::map<std::int32_t, const FixedDisplacement*> fixed_by_tag;
  for (const FixedDisplacement& f : params.fixed) {
    claim(f.tag, 1, "fixed-displacement");
    for (int c = 0; c < 3; ++c)
      if (f.fix[c]) check_finite(f.value[c], "fixed displacement on " + tag_label(mesh, f.tag));
    fixed_by_tag[f.tag] = &f;
  }
  std::map<std::int32_t, Vec3> slide_normal;
  for (const SlidingBoundary& s : params.sliding) {
    claim(s.tag, 2, "sliding");
    slide_normal[s.tag] = plane_normal(mesh, s.tag);
  }
  NodeFrames fr;
  fr.m.assign(nn, 0);
  fr.r.assign(9 * nn, 0.0);
  fr.g.assign(3 * nn, 0.0);
  {
    std::vector<double> sum(3 * nn, 0.0), weight(3 * nn, 0.0), plain(3 * nn, 0.0);
    std::vector<std::uint32_t> count(3 * nn, 0);
    std::vector<Constraint> cons;
    for (std::size_t f = 0; f < nf; ++f) {
      const std::int32_t tag = mesh.bface_tag[f];
      auto fit = fixed_by_tag.find(tag);
      auto sit = slide_normal.find(tag);
      if (fit == fixed_by_tag.end() && sit == slide_normal.end()) continue;
      const double area = triangle_area(mesh, f);
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t v = mesh.bface[3 * f + i];
        if (sit != slide_normal.end()) {
          cons.push_back({v, sit->second, 0.0});
          continue;
        }
        for (int c = 0; c < 3; ++c) {
          if (!fit->second->fix[c]) continue;
          sum[3 * v + c] += area / 3 * fit->second->value[c];
          weight[3 * v + c] += area / 3;
          plain[3 * v + c] += fit->second->value[c];
          ++count[3 * v + c];
        }
      }
    }
    for (std::uint32_t v = 0; v < nn; ++v)
      for (int c = 0; c < 3; ++c)
        if (count[3 * v + c]) {
          Vec3 d{0, 0, 0};
          d[c] = 1;
          const std::size_t k = 3 * v + c;
          cons.push_back({v, d, weight[k] > 0 ? sum[k] / weight[k] : plain[k] / count[k]});
        }
    // Fixed components first (they carry values), then the sliding normals, node by node.
    std::stable_sort(cons.begin(), cons.end(), [](const Constraint& a, const Constraint& b) {
      return a.node != b.node ? a.node < b.node : (a.value != 0) > (b.value != 0);
    });
    for (std::size_t i = 0; i < cons.size();) {
      std::size_t j = i;
      while (j < cons.size() && cons[j].node == cons[i].node) ++j;
      if (used[cons[i].node]) build_frame(mesh, cons[i].node, &cons[i], j - i, fr);
      i = j;
    }
  }
  return fr;
}

TetEdges tet_edges(const Mesh& mesh) {
  const std::size_t nt = mesh.tet_count();
  std::vector<std::pair<std::uint64_t, std::size_t>> keys(6 * nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 6; ++k) {
      const std::uint32_t p = mesh.tet[4 * t + kTetEdge[k][0]], q = mesh.tet[4 * t + kTetEdge[k][1]];
      keys[6 * t + k] = {(std::uint64_t{std::min(p, q)} << 32) | std::max(p, q),
                         6 * t + static_cast<std::size_t>(k)};
    }
  std::sort(keys.begin(), keys.end());
  TetEdges e;
  e.tet_edge.resize(6 * nt);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (i == 0 || keys[i].first != keys[i - 1].first) {
      e.a.push_back(static_cast<std::uint32_t>(keys[i].first >> 32));
      e.b.push_back(static_cast<std::uint32_t>(keys[i].first & 0xffffffffu));
    }
    e.tet_edge[keys[i].second] = static_cast<std::uint32_t>(e.a.size() - 1);
  }
  return e;
}

std::uint32_t TetEdges::find(std::uint32_t p, std::uint32_t q) const {
  const std::uint32_t lo = std::min(p, q), hi = std::max(p, q);
  std::size_t first = 0, count = a.size();
  while (count > 0) {  // lower bound of (lo, hi) in the (a, b)-sorted edges
    const std::size_t half = count / 2, mid = first + half;
    if (a[mid] < lo || (a[mid] == lo && b[mid] < hi)) {
      first = mid + 1;
      count -= half + 1;
    } else {
      count = half;
    }
  }
  return first < a.size() && a[first] == lo && b[first] == hi ? static_cast<std::uint32_t>(first) : kNone;
}

Mesh quadratic_boundary(const Mesh& mesh, const TetEdges& edges) {
  const std::size_t nn = mesh.node_count(), ne = edges.size();
  Mesh out;
  out.boundaries = mesh.boundaries;
  out.xyz = mesh.xyz;
  out.xyz.resize(3 * (nn + ne));
  for (std::size_t e = 0; e < ne; ++e)
    for (int i = 0; i < 3; ++i)
      out.xyz[3 * (nn + e) + static_cast<std::size_t>(i)] =
          (mesh.xyz[3 * std::size_t{edges.a[e]} + static_cast<std::size_t>(i)] +
           mesh.xyz[3 * std::size_t{edges.b[e]} + static_cast<std::size_t>(i)]) /
          2;
  out.bface.reserve(12 * mesh.bface_count());
  out.bface_tag.reserve(4 * mesh.bface_count());
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    const std::uint32_t* c = &mesh.bface[3 * f];
    std::uint32_t mid[3];  // mid[i]: edge c[i] c[i + 1]
    bool split_it = true;
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t e = edges.find(c[i], c[(i + 1) % 3]);
      split_it = split_it && e != kNone;
      mid[i] = static_cast<std::uint32_t>(nn + e);
    }
    if (!split_it) {  // not on a tet's face: no mid-edge nodes to constrain, the corners as for P1
      out.bface.insert(out.bface.end(), c, c + 3);
      out.bface_tag.push_back(mesh.bface_tag[f]);
      continue;
    }
    const std::uint32_t split[4][3] = {
        {c[0], mid[0], mid[2]}, {mid[0], c[1], mid[1]}, {mid[2], mid[1], c[2]}, {mid[0], mid[1], mid[2]}};
    for (const auto& tri : split) {
      out.bface.insert(out.bface.end(), tri, tri + 3);
      out.bface_tag.push_back(mesh.bface_tag[f]);
    }
  }
  return out;
}

}  // namespace foxi::detail
