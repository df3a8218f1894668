#include "foxi/mesher/size_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "foxi/mesher/tetgen_mesher.hpp"

namespace foxi {

namespace {

double longest_edge(const Mesh& m, std::size_t t) {
  const std::uint32_t* v = &m.tet[4 * t];
  double l2 = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k) {
        const double e = m.xyz[3 * v[j] + std::size_t(k)] - m.xyz[3 * v[i] + std::size_t(k)];
        d += e * e;
      }
      l2 = std::max(l2, d);
    }
  return std::sqrt(l2);
}

// The gradient of the linear interpolant of u on tet t, and the tet's volume (unsigned).
double tet_gradient(const Mesh& m, std::size_t t, const double* u, double g[3]) {
  const std::uint32_t* v = &m.tet[4 * t];
  const double* p0 = &m.xyz[3 * v[0]];
  double e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) e[i][k] = m.xyz[3 * v[i + 1] + std::size_t(k)] - p0[k];
  // Rows of the inverse of E (rows e_i) are (e_j x e_k) / det; grad u = E^-1 (u_i - u_0).
  const double c0[3] = {e[1][1] * e[2][2] - e[1][2] * e[2][1], e[1][2] * e[2][0] - e[1][0] * e[2][2],
                        e[1][0] * e[2][1] - e[1][1] * e[2][0]};
  const double c1[3] = {e[2][1] * e[0][2] - e[2][2] * e[0][1], e[2][2] * e[0][0] - e[2][0] * e[0][2],
                        e[2][0] * e[0][1] - e[2][1] * e[0][0]};
  const double c2[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                        e[0][0] * e[1][1] - e[0][1] * e[1][0]};
  const double det = e[0][0] * c0[0] + e[0][1] * c0[1] + e[0][2] * c0[2];
  if (!(std::abs(det) > 0)) {
    g[0] = g[1] = g[2] = 0;
    return 0;
  }
  const double du[3] = {u[v[1]] - u[v[0]], u[v[2]] - u[v[0]], u[v[3]] - u[v[0]]};
  for (int k = 0; k < 3; ++k) g[k] = (c0[k] * du[0] + c1[k] * du[1] + c2[k] * du[2]) / det;
  return std::abs(det) / 6;
}

// The distance from p to the box (0 inside it).
double distance_to_box(const double* p, const RefinementBox& b) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double out = std::max({b.lo[k] - p[k], 0.0, p[k] - b.hi[k]});
    d2 += out * out;
  }
  return std::sqrt(d2);
}

// Whether every box holds at least one node of `mesh`.
bool every_box_holds_a_node(const Mesh& mesh, const SizeControls& controls) {
  for (const RefinementBox& b : controls.boxes) {
    bool held = false;
    for (std::size_t n = 0; n < mesh.node_count() && !held; ++n)
      held = distance_to_box(&mesh.xyz[3 * n], b) == 0;
    if (!held) return false;
  }
  return true;
}

}  // namespace

double regular_tet_volume(double edge) { return edge * edge * edge / (6 * std::sqrt(2.0)); }
double regular_tet_circumradius(double volume) {
  return std::cbrt(6 * std::sqrt(2.0) * volume) * std::sqrt(6.0) / 4;
}

Plc with_region_sizes(const Plc& plc, const SizeControls& controls) {
  Plc out = plc;
  for (std::size_t i = 0; i < controls.region_ids.size() && i < controls.region_sizes.size(); ++i) {
    bool found = false;
    for (RegionSeed& s : out.regions)
      if (s.id == controls.region_ids[i]) {
        found = true;
        const double v = regular_tet_volume(controls.region_sizes[i]);
        s.max_volume = s.max_volume > 0 ? std::min(s.max_volume, v) : v;
      }
    if (!found)
      throw MesherError(10,
                        "no region " + std::to_string(controls.region_ids[i]) + " in the PLC for its size");
  }
  return out;
}

SizeField size_field_from_boxes(const Mesh& background, const SizeControls& controls) {
  SizeField f;
  f.xyz = background.xyz;
  f.tet = background.tet;
  double fallback = controls.max_size;
  if (!(fallback > 0))
    for (std::size_t t = 0; t < background.tet_count(); ++t)
      fallback = std::max(fallback, longest_edge(background, t));
  f.size.assign(background.node_count(), fallback);
  for (std::size_t n = 0; n < background.node_count(); ++n) {
    const double* p = &background.xyz[3 * n];
    for (const RefinementBox& b : controls.boxes)
      f.size[n] = std::min(f.size[n], b.size + distance_to_box(p, b));
  }
  return f;
}

SizeField box_size_field(const Plc& plc, const MeshParams& params, const SizeControls& controls, int passes) {
  MeshParams p = params;
  p.size_field = nullptr;
  Mesh m = mesh_plc(plc, p);
  SizeField field = size_field_from_boxes(m, controls);
  // A box narrower than the first mesh's tets may hold none of its nodes: the graded sizes of the
  // nodes around it refine there, pass by pass, until it holds some (a box outside the domain never
  // does: the passes end at the bound).
  constexpr int max_passes = 8;
  for (int i = 1; i < max_passes && (i < passes || !every_box_holds_a_node(m, controls)); ++i) {
    p.size_field = &field;
    m = mesh_plc(plc, p);
    field = size_field_from_boxes(m, controls);
  }
  return field;
}

ErrorIndicator zz_error_indicator(const Mesh& mesh, const Field& field) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  if (field.location != FieldLocation::node || field.components < 1 ||
      field.values.size() < nn * field.components)
    throw MesherError(10, "field '" + field.name + "' is not a node field of this mesh");
  std::vector<double> u(nn);
  for (std::size_t n = 0; n < nn; ++n) u[n] = field.values[n * field.components];
  std::vector<double> grad(3 * nt), vol(nt), rec(3 * nn, 0), wsum(nn, 0);
  // A tet with a node of no value (NaN: an imported field outside its source) has no gradient: it
  // takes no part in the recovery or the norms, and its error is NaN.
  std::vector<char> valued(nt, 1);
  ErrorIndicator e;
  for (std::size_t t = 0; t < nt; ++t) {
    for (int i = 0; i < 4; ++i)
      if (!std::isfinite(u[mesh.tet[4 * t + std::size_t(i)]])) valued[t] = 0;
    vol[t] = tet_gradient(mesh, t, u.data(), &grad[3 * t]);
    if (!valued[t]) {
      ++e.tets_without_value;
      continue;
    }
    for (int i = 0; i < 4; ++i) {
      const std::uint32_t v = mesh.tet[4 * t + std::size_t(i)];
      wsum[v] += vol[t];
      for (int k = 0; k < 3; ++k) rec[3 * v + std::size_t(k)] += vol[t] * grad[3 * t + std::size_t(k)];
    }
  }
  for (std::size_t n = 0; n < nn; ++n)
    if (wsum[n] > 0)
      for (int k = 0; k < 3; ++k) rec[3 * n + std::size_t(k)] /= wsum[n];
  e.tet_error.resize(nt);
  double sum2 = 0, g2 = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    if (!valued[t]) {
      e.tet_error[t] = NAN;
      continue;
    }
    double d2 = 0, gg = 0;
    for (int k = 0; k < 3; ++k) {
      double c = 0;
      for (int i = 0; i < 4; ++i) c += 0.25 * rec[3 * mesh.tet[4 * t + std::size_t(i)] + std::size_t(k)];
      const double d = c - grad[3 * t + std::size_t(k)];
      d2 += d * d;
      gg += grad[3 * t + std::size_t(k)] * grad[3 * t + std::size_t(k)];
    }
    e.tet_error[t] = std::sqrt(d2 * vol[t]);
    sum2 += d2 * vol[t];
    g2 += gg * vol[t];
  }
  e.total_error = std::sqrt(sum2);
  e.gradient_norm = std::sqrt(g2);
  return e;
}

SizeField size_field_from_error(const Mesh& mesh, const Field& field, double target_error, double min_size,
                                double max_size) {
  if (!(target_error > 0)) throw MesherError(10, "the target error must be > 0");
  const ErrorIndicator e = zz_error_indicator(mesh, field);
  const std::size_t nt = mesh.tet_count();
  if (nt > 0 && e.tets_without_value == nt)
    throw MesherError(
        10, "field '" + field.name + "' has no value (NaN) at a node of every tet: no error to refine by");
  const std::size_t valued = nt - e.tets_without_value;
  const double per_tet = valued ? target_error * e.gradient_norm / std::sqrt(double(valued)) : 0;
  SizeField f;
  f.xyz = mesh.xyz;
  f.tet = mesh.tet;
  f.size.assign(mesh.node_count(), std::numeric_limits<double>::infinity());
  for (std::size_t t = 0; t < nt; ++t) {
    const double h = longest_edge(mesh, t);
    // no value: no error known, the tet keeps its size
    double ratio = std::isnan(e.tet_error[t]) ? 1.0 : e.tet_error[t] > 0 ? per_tet / e.tet_error[t] : 2.0;
    ratio = std::clamp(ratio, 0.25, 2.0);
    double target = h * ratio;
    if (max_size > 0) target = std::min(target, max_size);
    if (min_size > 0) target = std::max(target, min_size);
    for (int i = 0; i < 4; ++i) {
      double& s = f.size[mesh.tet[4 * t + std::size_t(i)]];
      s = std::min(s, target);
    }
  }
  // Nodes no tet uses: any positive size (TetGen never looks them up inside a tet).
  for (double& s : f.size)
    if (!std::isfinite(s)) s = max_size > 0 ? max_size : 1;
  return f;
}

}  // namespace foxi
