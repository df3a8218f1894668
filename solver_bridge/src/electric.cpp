// Electrostatics and DC conduction: one Laplace problem per electrode on the shared P1 machinery
// (scalar_p1.hpp), the Maxwell matrix from the reactions, the operating field by superposition.
#include "foxi/solver/electric.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "scalar_p1.hpp"

namespace foxi {

namespace {

using namespace detail;

struct ElectrodeSolve {
  RegionTable regions;
  std::vector<double> coefficient;  // per region, scaled (eps0 eps_r or sigma)
  std::vector<double> region_volume;
  std::vector<double> area;                 // per electrode
  std::vector<std::vector<double>> unit;    // per electrode: nodal potential with 1 V on it
  std::vector<std::vector<double>> matrix;  // M[i][j]: reaction on i in solve j
  std::vector<double> energy2;              // per electrode: u_j^T K u_j (twice the energy)
  double asymmetry = 0;
  LinearSolveResult lin;
  std::size_t unknowns = 0;
  double assembly_seconds = 0, solve_seconds = 0;
};

ElectrodeSolve solve_electrodes(const Mesh& mesh, const std::vector<Electrode>& electrodes,
                                const std::function<double(const Material&)>& from_material,
                                const std::vector<RegionCoefficient>& overrides, double scale,
                                const std::string& what, const std::string& hint, const std::string& problem,
                                const std::string& kind, const LinearSolverOptions& options) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  check_mesh(mesh);
  const unsigned threads = thread_count(options.threads);
  report_progress(options, "assemble", 0.0);
  ElectrodeSolve s;
  s.regions = region_table(mesh);
  std::vector<std::pair<std::int32_t, double>> ov;
  for (const RegionCoefficient& c : overrides) ov.emplace_back(c.region, c.value);
  s.coefficient = region_coefficients(mesh, s.regions, from_material, ov, what, hint);
  for (double& c : s.coefficient) c *= scale;
  (void)tet_volumes(mesh, s.regions, threads, s.region_volume);

  const std::size_t ne = electrodes.size(), nn = mesh.node_count(), nt = mesh.tet_count();
  if (ne == 0)
    throw SolverError("ill-posed " + problem + ": no " + kind +
                      " is given, so the potential is undetermined; name at least one");
  const std::vector<std::int32_t> tags = boundary_tag_list(mesh);
  std::map<std::int32_t, FixedTag> fixed_tags;
  for (std::size_t e = 0; e < ne; ++e) {
    const Electrode& el = electrodes[e];
    if (el.tags.empty()) throw SolverError(kind + " '" + el.name + "' has no boundary tags");
    for (std::size_t f = 0; f < e; ++f)
      if (electrodes[f].name == el.name && !el.name.empty())
        throw SolverError("two " + kind + "s are named '" + el.name + "'");
    for (std::int32_t tag : el.tags) {
      if (!std::binary_search(tags.begin(), tags.end(), tag))
        throw SolverError(kind + " '" + el.name + "' is on " + tag_label(mesh, tag) +
                          ", which tags no boundary triangle");
      auto [it, inserted] = fixed_tags.emplace(tag, FixedTag{static_cast<double>(e), e});
      if (!inserted && it->second.slot != e)
        throw SolverError(tag_label(mesh, tag) + " belongs to two " + kind + "s ('" +
                          electrodes[it->second.slot].name + "' and '" + el.name + "')");
    }
  }
  std::vector<double> tet_c(nt);
  for (std::size_t t = 0; t < nt; ++t) tet_c[t] = s.coefficient[s.regions.tet_rix[t]];
  const P1Stiffness k = assemble_stiffness(mesh, tet_c, threads);
  std::vector<double>().swap(tet_c);
  report_progress(options, "assemble", 0.5);
  // The value of each tag is its electrode's index; a node whose tags belong to two electrodes
  // would be averaged between them: refuse it.
  Dirichlet d = dirichlet_from_tags(mesh, k, fixed_tags, ne);
  s.area = d.area;
  {
    std::vector<std::uint32_t> owner(nn, UINT32_MAX);
    for (const Dirichlet::Share& sh : d.shares) {
      if (owner[sh.node] != UINT32_MAX && owner[sh.node] != sh.slot)
        throw SolverError(kind + "s '" + electrodes[owner[sh.node]].name + "' and '" +
                          electrodes[sh.slot].name + "' touch (node " + std::to_string(sh.node) +
                          " is on both): they would be one electrode; merge them or separate them");
      owner[sh.node] = sh.slot;
    }
    for (std::size_t v = 0; v < nn; ++v)
      if (d.fixed[v]) d.value[v] = static_cast<double>(owner[v]);
  }
  check_anchored(mesh, d.fixed, "ill-posed " + problem,
                 "touches no " + kind + ", so its potential is undetermined");
  const ReducedSystem r = reduce(k, d.fixed, threads);
  s.unknowns = r.a.rows();
  std::vector<std::vector<double>> rhs(ne);
  std::vector<std::vector<double>> fixed_u(ne, std::vector<double>(nn, 0.0));
  for (std::size_t e = 0; e < ne; ++e) {
    for (std::size_t v = 0; v < nn; ++v)
      if (d.fixed[v]) fixed_u[e][v] = d.value[v] == static_cast<double>(e) ? 1.0 : 0.0;
    rhs[e] = reduced_rhs(k, r, {}, d.fixed, fixed_u[e], threads);
  }
  report_progress(options, "assemble", 1.0);
  const auto t1 = clock::now();
  std::vector<std::vector<double>> x;
  s.lin = solve_spd_many(r.a, rhs, x, options);
  const auto t2 = clock::now();
  s.unit.resize(ne);
  s.matrix.assign(ne, std::vector<double>(ne, 0.0));
  s.energy2.assign(ne, 0.0);
  for (std::size_t j = 0; j < ne; ++j) {
    std::vector<double>& u = fixed_u[j];
    for (std::size_t v = 0; v < nn; ++v)
      if (!k.has_tets(v)) u[v] = std::numeric_limits<double>::quiet_NaN();
    scatter(r, x[j], u);
    const std::vector<double> react = slot_reactions(k, d, {}, u, ne);
    for (std::size_t i = 0; i < ne; ++i) s.matrix[i][j] = react[i];
    std::vector<double> e2;
    (void)cell_gradients(mesh, s.regions, s.coefficient, u, 1.0, threads, &e2);
    for (double v : e2) s.energy2[j] += v;
    s.unit[j] = std::move(u);
  }
  double big = 0;
  for (std::size_t i = 0; i < ne; ++i)
    for (std::size_t j = 0; j < ne; ++j) big = std::max(big, std::abs(s.matrix[i][j]));
  for (std::size_t i = 0; i < ne; ++i)
    for (std::size_t j = 0; j < i; ++j) {
      if (big > 0) s.asymmetry = std::max(s.asymmetry, std::abs(s.matrix[i][j] - s.matrix[j][i]) / big);
      s.matrix[i][j] = s.matrix[j][i] = 0.5 * (s.matrix[i][j] + s.matrix[j][i]);
    }
  s.assembly_seconds = std::chrono::duration<double>(t1 - t0).count();
  s.solve_seconds = std::chrono::duration<double>(t2 - t1).count();
  return s;
}

// sum_j V_j u_j
std::vector<double> superpose(const ElectrodeSolve& s, const std::vector<double>& voltage) {
  std::vector<double> u(s.unit.empty() ? 0 : s.unit[0].size(), 0.0);
  for (std::size_t j = 0; j < s.unit.size(); ++j)
    for (std::size_t v = 0; v < u.size(); ++v) u[v] += voltage[j] * s.unit[j][v];
  return u;
}

Field node_field(std::string name, std::string unit, std::vector<double> values) {
  Field f;
  f.name = std::move(name);
  f.location = FieldLocation::node;
  f.components = 1;
  f.unit = std::move(unit);
  f.values = std::move(values);
  return f;
}

Field cell_field(std::string name, std::string unit, int components, std::vector<double> values) {
  Field f;
  f.name = std::move(name);
  f.location = FieldLocation::cell;
  f.components = components;
  f.unit = std::move(unit);
  f.values = std::move(values);
  return f;
}

}  // namespace

ElectrostaticReport solve_electrostatic(Mesh& mesh, const ElectrostaticParams& params) {
  for (const Electrode& e : params.conductors) {
    detail::check_finite(e.voltage, "voltage of conductor '" + e.name + "'");
    if (e.fixed_current)
      throw SolverError("conductor '" + e.name + "': a fixed current has no meaning in electrostatics");
  }
  const ElectrodeSolve s = solve_electrodes(
      mesh, params.conductors, [](const Material& m) { return m.relative_permittivity; }, params.permittivity,
      kVacuumPermittivity, "relative permittivity", "ElectrostaticParams::permittivity (foxi solve --eps",
      "electrostatic problem", "conductor", params.solver);
  const std::size_t ne = params.conductors.size();
  ElectrostaticReport rep;
  rep.capacitance = s.matrix;
  rep.asymmetry = s.asymmetry;
  rep.energy_capacitance = s.energy2;
  std::vector<double> volt(ne);
  for (std::size_t i = 0; i < ne; ++i) volt[i] = params.conductors[i].voltage;
  for (std::size_t i = 0; i < ne; ++i) {
    ElectrodeResult c;
    c.name = params.conductors[i].name;
    c.area = s.area[i];
    c.voltage = volt[i];
    for (std::size_t j = 0; j < ne; ++j) c.charge += s.matrix[i][j] * volt[j];
    rep.energy += 0.5 * c.charge * c.voltage;
    rep.conductors.push_back(c);
  }
  std::vector<double> u = superpose(s, volt);
  const unsigned threads = detail::thread_count(params.solver.threads);
  std::vector<double> one(s.regions.size(), 1.0);
  detail::set_field(mesh,
                    cell_field("electric_field", "V/m", 3,
                               detail::cell_gradients(mesh, s.regions, one, u, -1.0, threads, nullptr)));
  detail::set_field(mesh, node_field("potential", "V", std::move(u)));
  rep.solver = s.lin.solver;
  rep.unknowns = s.unknowns;
  rep.iterations = s.lin.iterations;
  rep.relative_residual = s.lin.relative_residual;
  rep.assembly_seconds = s.assembly_seconds;
  rep.solve_seconds = s.solve_seconds;
  return rep;
}

CurrentReport solve_current(Mesh& mesh, const CurrentParams& params) {
  bool any_voltage = false;
  for (const Electrode& e : params.terminals) {
    detail::check_finite(
        e.fixed_current ? e.current : e.voltage,
        std::string(e.fixed_current ? "current" : "voltage") + " of terminal '" + e.name + "'");
    any_voltage = any_voltage || !e.fixed_current;
  }
  if (!params.terminals.empty() && !any_voltage)
    throw SolverError(
        "ill-posed DC conduction problem: every terminal has a fixed current, so the potential is determined "
        "only up to a constant; give one terminal a fixed voltage (e.g. 0 V)");
  const ElectrodeSolve s = solve_electrodes(
      mesh, params.terminals, [](const Material& m) { return m.electrical_conductivity; },
      params.conductivity, 1.0, "electrical conductivity", "CurrentParams::conductivity (foxi solve --sigma",
      "DC conduction problem", "terminal", params.solver);
  const std::size_t ne = params.terminals.size();
  // Voltages of current terminals: G_cc V_c = I_c - G_cv V_v.
  std::vector<double> volt(ne, 0.0);
  std::vector<std::size_t> cur;
  for (std::size_t i = 0; i < ne; ++i) {
    if (params.terminals[i].fixed_current)
      cur.push_back(i);
    else
      volt[i] = params.terminals[i].voltage;
  }
  if (!cur.empty()) {
    const auto m = static_cast<Eigen::Index>(cur.size());
    Eigen::MatrixXd g(m, m);
    Eigen::VectorXd b(m);
    for (Eigen::Index a = 0; a < m; ++a) {
      const std::size_t i = cur[static_cast<std::size_t>(a)];
      b[a] = params.terminals[i].current;
      for (std::size_t j = 0; j < ne; ++j)
        if (!params.terminals[j].fixed_current) b[a] -= s.matrix[i][j] * volt[j];
      for (Eigen::Index c = 0; c < m; ++c) g(a, c) = s.matrix[i][cur[static_cast<std::size_t>(c)]];
    }
    Eigen::LDLT<Eigen::MatrixXd> ldlt(g);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0))
      throw SolverError("the current terminals' conductance matrix is singular");
    const Eigen::VectorXd vc = ldlt.solve(b);
    for (Eigen::Index a = 0; a < m; ++a) volt[cur[static_cast<std::size_t>(a)]] = vc[a];
  }
  CurrentReport rep;
  rep.conductance = s.matrix;
  for (std::size_t i = 0; i < ne; ++i) {
    ElectrodeResult c;
    c.name = params.terminals[i].name;
    c.area = s.area[i];
    c.voltage = volt[i];
    for (std::size_t j = 0; j < ne; ++j) c.charge += s.matrix[i][j] * volt[j];
    rep.terminals.push_back(c);
  }
  if (ne == 2 && rep.terminals[0].charge != 0)
    rep.resistance = (volt[0] - volt[1]) / rep.terminals[0].charge;
  else
    rep.resistance = s.matrix[0][0] > 0 ? 1.0 / s.matrix[0][0] : std::numeric_limits<double>::infinity();
  std::vector<double> u = superpose(s, volt);
  const unsigned threads = detail::thread_count(params.solver.threads);
  std::vector<double> power;
  std::vector<double> j = detail::cell_gradients(mesh, s.regions, s.coefficient, u, -1.0, threads, &power);
  const std::size_t nt = mesh.tet_count();
  std::vector<double> joule(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const double c = s.coefficient[s.regions.tet_rix[t]];
    joule[t] = (j[3 * t] * j[3 * t] + j[3 * t + 1] * j[3 * t + 1] + j[3 * t + 2] * j[3 * t + 2]) / c;
  }
  for (std::size_t i = 0; i < s.regions.size(); ++i) {
    rep.regions.push_back({s.regions.ids[i], s.coefficient[i], s.region_volume[i], power[i]});
    rep.total_power += power[i];
  }
  detail::set_field(mesh, cell_field("current_density", "A/m^2", 3, std::move(j)));
  detail::set_field(mesh, cell_field("joule_heat", "W/m^3", 1, std::move(joule)));
  detail::set_field(mesh, node_field("potential", "V", std::move(u)));
  rep.solver = s.lin.solver;
  rep.unknowns = s.unknowns;
  rep.iterations = s.lin.iterations;
  rep.relative_residual = s.lin.relative_residual;
  rep.assembly_seconds = s.assembly_seconds;
  rep.solve_seconds = s.solve_seconds;
  return rep;
}

std::vector<HeatSource> joule_heat_sources(const CurrentReport& report) {
  std::vector<HeatSource> out;
  for (const RegionJoule& r : report.regions) out.push_back({r.region, r.power, true});
  return out;
}

}  // namespace foxi
