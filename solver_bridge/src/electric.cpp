// Electrostatics and DC conduction: one Laplace problem per electrode on the shared P1 machinery
// (scalar_p1.hpp), the Maxwell matrix from the reactions, the operating field by superposition.
#include "foxi/solver/electric.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <array>
#include <limits>
#include <map>

#include "scalar_p1.hpp"

namespace foxi {

namespace {

using namespace detail;

struct ElectrodeSolve {
  RegionTable regions;
  std::vector<double> coefficient;  // per region, scaled (eps0 eps_r or sigma); 0 for metal
  std::vector<char> metal;          // per region (electrostatics)
  std::vector<double> region_volume;
  std::vector<double> area;                                // per electrode
  std::vector<std::vector<double>> unit;                   // per electrode: nodal potential with 1 V on it
  std::vector<std::vector<double>> matrix;                 // M[i][j]: energy form a(u_i, u_j)
  std::vector<std::vector<std::int32_t>> electrode_metal;  // per electrode: metal regions in it
  struct Floating {
    std::vector<std::int32_t> regions;
    std::size_t nodes = 0;
    std::uint32_t node = 0;  // one of its nodes
  };
  std::vector<Floating> floating;
  double residual = 0;  // max over solves of |r_k| / A_kk
  LinearSolveResult lin;
  std::size_t unknowns = 0;
  double assembly_seconds = 0, solve_seconds = 0;
};

// The system on the unknowns: dof[v] >= 0 is node v's unknown (several nodes of a floating metal body
// share one: their rows and columns are summed, P^T K P), -1 a fixed node or one without tets.
SymmetricCsr merged_system(const P1Stiffness& k, const std::vector<int>& dof, std::size_t ndof) {
  const std::size_t nn = dof.size();
  std::vector<std::size_t> count(ndof + 1, 0);
  for (std::size_t v = 0; v < nn; ++v)
    if (dof[v] >= 0)
      count[static_cast<std::size_t>(dof[v]) + 1] += k.pat.row_start[v + 1] - k.pat.row_start[v];
  for (std::size_t i = 0; i < ndof; ++i) count[i + 1] += count[i];
  std::vector<std::pair<int, double>> entries(count[ndof]);
  std::vector<std::size_t> at(count.begin(), count.end() - 1);
  for (std::size_t v = 0; v < nn; ++v) {
    if (dof[v] < 0) continue;
    for (std::size_t p = k.pat.row_start[v]; p < k.pat.row_start[v + 1]; ++p)
      if (const int c = dof[k.pat.col[p]]; c >= 0)
        entries[at[static_cast<std::size_t>(dof[v])]++] = {c, k.val[p]};
  }
  SymmetricCsr a;
  a.start.assign(ndof + 1, 0);
  for (std::size_t i = 0; i < ndof; ++i) {
    auto b = entries.begin() + static_cast<std::ptrdiff_t>(count[i]);
    auto e = entries.begin() + static_cast<std::ptrdiff_t>(at[i]);
    std::sort(b, e, [](const auto& x, const auto& y) { return x.first < y.first; });
    for (auto it = b; it != e; ++it) {
      if (!a.col.empty() && static_cast<std::size_t>(a.start[i]) < a.col.size() && a.col.back() == it->first)
        a.val.back() += it->second;
      else {
        a.col.push_back(it->first);
        a.val.push_back(it->second);
      }
    }
    if (a.col.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw SolverError("the system has more than 2^31 nonzeros");
    a.start[i + 1] = static_cast<int>(a.col.size());
  }
  return a;
}

// The energy form M_ij = sum_t c_t V_t grad(u_i) . grad(u_j) for every pair of the given fields.
std::vector<std::vector<double>> energy_matrix(const Mesh& mesh, const RegionTable& regions,
                                               const std::vector<double>& coefficient,
                                               const std::vector<std::vector<double>>& u, unsigned threads) {
  const std::size_t ne = u.size(), nt = mesh.tet_count();
  std::vector<std::vector<double>> part(threads, std::vector<double>(ne * ne, 0.0));
  parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned th) {
    std::array<std::array<double, 3>, 4> g;
    std::vector<double> grad(3 * ne);
    for (std::size_t t = b; t < e; ++t) {
      const double c = coefficient[regions.tet_rix[t]];
      if (c == 0) continue;
      const double cv = c * p1_gradients(mesh, t, g);
      for (std::size_t i = 0; i < ne; ++i) {
        double* gi = &grad[3 * i];
        gi[0] = gi[1] = gi[2] = 0;
        for (int a = 0; a < 4; ++a) {
          const double ua = u[i][mesh.tet[4 * t + a]];
          for (int d = 0; d < 3; ++d) gi[d] += ua * g[a][d];
        }
      }
      for (std::size_t i = 0; i < ne; ++i)
        for (std::size_t j = 0; j <= i; ++j)
          part[th][i * ne + j] += cv * (grad[3 * i] * grad[3 * j] + grad[3 * i + 1] * grad[3 * j + 1] +
                                        grad[3 * i + 2] * grad[3 * j + 2]);
    }
  });
  std::vector<std::vector<double>> m(ne, std::vector<double>(ne, 0.0));
  for (std::size_t i = 0; i < ne; ++i)
    for (std::size_t j = 0; j <= i; ++j) {
      for (unsigned th = 0; th < threads; ++th) m[i][j] += part[th][i * ne + j];
      m[j][i] = m[i][j];
    }
  return m;
}

// Each unit solution u_j with every connected set of tets on which it is flat to kFlat (a metal body
// that carries none of that solve's current: its potential differences are round-off) made exactly
// constant: 1 where the set touches electrode j, 0 where it touches another, else its value at one
// node. The Maxwell matrix a(w_i, w_j) then takes nothing from such tets, whose c |grad u|^2 would be
// round-off times the metal's conductivity (1e-7 of the FR-4 current in a copper-FR-4 series pair,
// where the copper's true share is 1e-21). The true energy left out is at most c (flat / h)^2 per tet.
// flat (V per volt applied): 1e-9, or 10 times a looser solver tolerance (whose error in the metal is
// of that order).
std::vector<std::vector<double>> flattened(const Mesh& mesh, const std::vector<std::vector<double>>& unit,
                                           const std::vector<std::uint32_t>& electrode_of, double flat) {
  const std::size_t nn = mesh.node_count();
  std::vector<std::vector<double>> out = unit;
  for (std::size_t j = 0; j < unit.size(); ++j) {
    const std::vector<double>& u = unit[j];
    const std::vector<std::uint32_t> set = tet_set_components(mesh, [&](std::size_t t) {
      const std::uint32_t* n = &mesh.tet[4 * t];
      const double lo = std::min({u[n[0]], u[n[1]], u[n[2]], u[n[3]]});
      const double hi = std::max({u[n[0]], u[n[1]], u[n[2]], u[n[3]]});
      return hi - lo <= flat;
    });
    // The value of each flat set: an electrode's where it touches one, else its root's.
    std::vector<double> value(nn, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t v = 0; v < nn; ++v)
      if (set[v] != UINT32_MAX && electrode_of[v] != UINT32_MAX)
        value[set[v]] = electrode_of[v] == j ? 1.0 : 0.0;
    for (std::size_t v = 0; v < nn; ++v) {
      if (set[v] == UINT32_MAX) continue;
      if (std::isnan(value[set[v]])) value[set[v]] = u[set[v]];
      out[j][v] = value[set[v]];
    }
  }
  return out;
}

ElectrodeSolve solve_electrodes(const Mesh& mesh, const std::vector<Electrode>& electrodes,
                                const std::function<double(const Material&)>& from_material,
                                const std::vector<RegionCoefficient>& overrides, double scale,
                                const std::string& what, const std::string& hint, const std::string& problem,
                                const std::string& kind, const LinearSolverOptions& options,
                                const std::function<bool(std::int32_t region)>& is_metal = {}) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  check_mesh(mesh);
  const unsigned threads = thread_count(options.threads);
  report_progress(options, "assemble", 0.0);
  ElectrodeSolve s;
  s.regions = region_table(mesh);
  const std::size_t nr = s.regions.size();
  s.metal.assign(nr, 0);
  if (is_metal)
    for (std::size_t i = 0; i < nr; ++i) s.metal[i] = is_metal(s.regions.ids[i]) ? 1 : 0;
  std::vector<std::pair<std::int32_t, double>> ov;
  for (const RegionCoefficient& c : overrides) ov.emplace_back(c.region, c.value);
  for (std::size_t i = 0; i < nr; ++i)
    if (s.metal[i]) ov.emplace_back(s.regions.ids[i], 1.0);  // unused: metal is no dielectric
  s.coefficient = region_coefficients(mesh, s.regions, from_material, ov, what, hint);
  for (std::size_t i = 0; i < nr; ++i) s.coefficient[i] = s.metal[i] ? 0.0 : s.coefficient[i] * scale;
  (void)tet_volumes(mesh, s.regions, threads, s.region_volume);

  const std::size_t ne = electrodes.size(), nn = mesh.node_count(), nt = mesh.tet_count();
  if (ne == 0)
    throw SolverInputError("ill-posed " + problem + ": no " + kind +
                           " is given, so the potential is undetermined; name at least one");
  const std::vector<std::int32_t> tags = boundary_tag_list(mesh);
  std::map<std::int32_t, FixedTag> fixed_tags;
  for (std::size_t e = 0; e < ne; ++e) {
    const Electrode& el = electrodes[e];
    if (el.tags.empty()) throw SolverInputError(kind + " '" + el.name + "' has no boundary tags");
    for (std::size_t f = 0; f < e; ++f)
      if (electrodes[f].name == el.name && !el.name.empty())
        throw SolverInputError("two " + kind + "s are named '" + el.name + "'");
    for (std::int32_t tag : el.tags) {
      if (!std::binary_search(tags.begin(), tags.end(), tag))
        throw SolverInputError(kind + " '" + el.name + "' is on " + tag_label(mesh, tag) +
                               ", which tags no boundary triangle");
      auto [it, inserted] = fixed_tags.emplace(tag, FixedTag{static_cast<double>(e), e});
      if (!inserted && it->second.slot != e)
        throw SolverInputError(tag_label(mesh, tag) + " belongs to two " + kind + "s ('" +
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
  std::vector<std::uint32_t> owner(nn, UINT32_MAX);
  for (const Dirichlet::Share& sh : d.shares) {
    if (owner[sh.node] != UINT32_MAX && owner[sh.node] != sh.slot)
      throw SolverInputError(kind + "s '" + electrodes[owner[sh.node]].name + "' and '" +
                             electrodes[sh.slot].name + "' touch (node " + std::to_string(sh.node) +
                             " is on both): they would be one electrode; merge them or separate them");
    owner[sh.node] = sh.slot;
  }
  // Metal bodies: the connected sets of metal tets (through shared nodes).
  std::vector<int> dof(nn, -1);
  std::size_t ndof = 0;
  s.electrode_metal.assign(ne, {});
  std::vector<std::uint32_t> body(nn, UINT32_MAX);
  if (std::find(s.metal.begin(), s.metal.end(), 1) != s.metal.end()) {
    const std::vector<std::uint32_t> metal_set =
        tet_set_components(mesh, [&](std::size_t t) { return s.metal[s.regions.tet_rix[t]] != 0; });
    // Per body root: the electrode it touches (UINT32_MAX none), its regions, its node count.
    std::map<std::uint32_t, std::uint32_t> touches;
    std::map<std::uint32_t, std::vector<std::int32_t>> body_regions;
    std::map<std::uint32_t, std::size_t> body_nodes;
    for (std::size_t v = 0; v < nn; ++v) {
      if (metal_set[v] == UINT32_MAX) continue;
      const std::uint32_t r = body[v] = metal_set[v];
      ++body_nodes[r];
      auto [it, inserted] = touches.emplace(r, owner[v]);
      if (owner[v] == UINT32_MAX) continue;
      if (it->second == UINT32_MAX) it->second = owner[v];
      if (it->second != owner[v])
        throw SolverInputError("conductors '" + electrodes[it->second].name + "' and '" +
                               electrodes[owner[v]].name +
                               "' are joined by metal (the body containing node " + std::to_string(v) +
                               "): they are one conductor; merge them, or make the metal a dielectric");
    }
    for (std::size_t t = 0; t < nt; ++t)
      if (s.metal[s.regions.tet_rix[t]]) {
        std::vector<std::int32_t>& rs = body_regions[body[mesh.tet[4 * t]]];
        if (std::find(rs.begin(), rs.end(), mesh.region_of(t)) == rs.end()) rs.push_back(mesh.region_of(t));
      }
    std::map<std::uint32_t, int> floating_dof;
    for (auto& [r, e] : touches) {
      std::vector<std::int32_t>& rs = body_regions[r];
      std::sort(rs.begin(), rs.end());
      if (e != UINT32_MAX) {
        for (std::int32_t id : rs) {
          std::vector<std::int32_t>& em = s.electrode_metal[e];
          if (std::find(em.begin(), em.end(), id) == em.end()) em.push_back(id);
        }
      } else {
        floating_dof[r] = static_cast<int>(ndof++);
        s.floating.push_back({rs, body_nodes[r], r});
      }
    }
    for (std::vector<std::int32_t>& em : s.electrode_metal) std::sort(em.begin(), em.end());
    for (std::size_t v = 0; v < nn; ++v) {
      if (body[v] == UINT32_MAX) continue;
      if (const std::uint32_t e = touches[body[v]]; e != UINT32_MAX) {
        owner[v] = e;
        d.fixed[v] = 1;
      } else {
        dof[v] = floating_dof[body[v]];
      }
    }
  }
  for (std::size_t v = 0; v < nn; ++v)
    if (d.fixed[v]) d.value[v] = static_cast<double>(owner[v]);
  check_anchored(mesh, d.fixed, "ill-posed " + problem,
                 "touches no " + kind + ", so its potential is undetermined");
  for (std::size_t v = 0; v < nn; ++v)
    if (!d.fixed[v] && k.has_tets(v) && body[v] == UINT32_MAX) dof[v] = static_cast<int>(ndof++);
  SymmetricCsr a = merged_system(k, dof, ndof);
  s.unknowns = ndof;
  std::vector<std::vector<double>> rhs(ne, std::vector<double>(ndof, 0.0));
  std::vector<std::vector<double>> fixed_u(ne, std::vector<double>(nn, 0.0));
  for (std::size_t e = 0; e < ne; ++e) {
    for (std::size_t v = 0; v < nn; ++v)
      if (d.fixed[v]) fixed_u[e][v] = owner[v] == e ? 1.0 : 0.0;
    for (std::size_t v = 0; v < nn; ++v) {
      if (dof[v] < 0) continue;
      double sum = 0;
      for (std::size_t p = k.pat.row_start[v]; p < k.pat.row_start[v + 1]; ++p)
        if (d.fixed[k.pat.col[p]]) sum -= k.val[p] * fixed_u[e][k.pat.col[p]];
      rhs[e][static_cast<std::size_t>(dof[v])] += sum;
    }
  }
  report_progress(options, "assemble", 1.0);
  const auto t1 = clock::now();
  std::vector<std::vector<double>> x;
  s.lin = solve_spd_many(a, rhs, x, options);
  const auto t2 = clock::now();
  // The residual of each solve, row by row against the row's diagonal: volts of potential per volt
  // applied, recomputed from the solution (CG's own residual is a recursion).
  {
    std::vector<double> diag(ndof, 0.0), ax(ndof);
    for (std::size_t i = 0; i < ndof; ++i)
      for (int p = a.start[i]; p < a.start[i + 1]; ++p)
        if (static_cast<std::size_t>(a.col[static_cast<std::size_t>(p)]) == i)
          diag[i] = a.val[static_cast<std::size_t>(p)];
    for (std::size_t e = 0; e < ne; ++e) {
      multiply(a, x[e].data(), ax.data(), threads);
      for (std::size_t i = 0; i < ndof; ++i)
        s.residual = std::max(s.residual, std::abs(rhs[e][i] - ax[i]) / diag[i]);
    }
  }
  s.unit.resize(ne);
  for (std::size_t j = 0; j < ne; ++j) {
    std::vector<double>& u = fixed_u[j];
    for (std::size_t v = 0; v < nn; ++v) {
      if (!k.has_tets(v))
        u[v] = std::numeric_limits<double>::quiet_NaN();
      else if (dof[v] >= 0)
        u[v] = x[j][static_cast<std::size_t>(dof[v])];
    }
    s.unit[j] = std::move(u);
  }
  // The flattened fields are the solution from here on: the matrix, the operating field by
  // superposition, its Joule heat or field energy and the written fields (which so carry no
  // round-off energy in the metal either).
  s.unit = flattened(mesh, s.unit, owner, std::max(1e-9, 10 * options.relative_tolerance));
  s.matrix = energy_matrix(mesh, s.regions, s.coefficient, s.unit, threads);
  s.assembly_seconds = std::chrono::duration<double>(t1 - t0).count();
  s.solve_seconds = std::chrono::duration<double>(t2 - t1).count();
  return s;
}

}  // namespace

std::vector<BalanceCheck> maxwell_matrix_checks(const std::vector<std::vector<double>>& m, double residual,
                                                double tolerance, const std::string& flow) {
  std::vector<BalanceCheck> checks;
  const std::size_t ne = m.size();
  double kirchhoff = 0, sign = 0;
  for (std::size_t j = 0; j < ne; ++j) {
    double sum = 0, mag = 0;
    for (std::size_t i = 0; i < ne; ++i) {
      sum += m[i][j];
      mag = std::max(mag, std::abs(m[i][j]));
    }
    kirchhoff = std::max(kirchhoff, mag > 0 ? std::abs(sum) / mag : 0.0);
    if (!(m[j][j] > 0)) sign = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < ne; ++i)
      if (i != j && m[i][j] > 0 && m[i][i] > 0 && m[j][j] > 0)
        sign = std::max(sign, m[i][j] / std::sqrt(m[i][i] * m[j][j]));
  }
  if (ne > 1)
    checks.push_back(make_check("Kirchhoff",
                                "largest |column sum| / largest |entry| of the matrix (" + flow +
                                    " into all electrodes with one at 1 V must add to 0)",
                                kirchhoff, tolerance));
  checks.push_back(make_check("Maxwell signs",
                              "largest positive off-diagonal M_ij / sqrt(M_ii M_jj) (inf: a diagonal <= 0)",
                              sign, tolerance));
  checks.push_back(make_check("residual", "largest |b - A x|_k / A_kk per volt applied, over the solves",
                              residual, tolerance));
  return checks;
}

namespace {

// The matrix checks and the energy check: `reported` (from the matrix: sum V I, 1/2 sum Q V) against
// `field` (the written field's energy), relative to the larger of `scale` (sum |V I|) and `field`.
std::vector<BalanceCheck> electrode_checks(const ElectrodeSolve& s, const LinearSolverOptions& o,
                                           const std::string& flow, const std::string& energy_what,
                                           double reported, double scale, double field) {
  const double tol = std::min(1e-3, std::max(1e-6, 100 * o.relative_tolerance));  // a loose --tol is no check
  std::vector<BalanceCheck> checks = maxwell_matrix_checks(s.matrix, s.residual, tol, flow);
  scale = std::max(scale, field);
  checks.push_back(
      make_check("energy", energy_what, scale > 0 ? std::abs(reported - field) / scale : 0.0, tol));
  return checks;
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
      throw SolverInputError("conductor '" + e.name + "': a fixed current has no meaning in electrostatics");
  }
  auto is_metal = [&](std::int32_t id) {
    for (const RegionCoefficient& c : params.permittivity)
      if (c.region == id) return false;
    if (std::find(params.metal_regions.begin(), params.metal_regions.end(), id) != params.metal_regions.end())
      return true;
    const Region* r = mesh.find_region(id);
    if (!r || r->material >= mesh.materials.size()) return false;
    const double sigma = mesh.materials[r->material].electrical_conductivity;
    return !std::isnan(sigma) && sigma >= params.metal_conductivity;
  };
  const ElectrodeSolve s = solve_electrodes(
      mesh, params.conductors, [](const Material& m) { return m.relative_permittivity; }, params.permittivity,
      kVacuumPermittivity, "relative permittivity", "ElectrostaticParams::permittivity (foxi solve --eps",
      "electrostatic problem", "conductor", params.solver, is_metal);
  const std::size_t ne = params.conductors.size();
  ElectrostaticReport rep;
  rep.capacitance = s.matrix;
  std::vector<double> volt(ne);
  for (std::size_t i = 0; i < ne; ++i) volt[i] = params.conductors[i].voltage;
  double qv = 0;  // sum |Q_i V_i|: the scale of the energy check
  for (std::size_t i = 0; i < ne; ++i) {
    ElectrodeResult c;
    c.name = params.conductors[i].name;
    c.area = s.area[i];
    c.voltage = volt[i];
    c.metal_regions = s.electrode_metal[i];
    for (std::size_t j = 0; j < ne; ++j) c.charge += s.matrix[i][j] * volt[j];
    rep.energy += 0.5 * c.charge * c.voltage;
    qv += 0.5 * std::abs(c.charge * c.voltage);
    rep.conductors.push_back(c);
  }
  std::vector<double> u = superpose(s, volt);
  for (const ElectrodeSolve::Floating& f : s.floating)
    rep.floating.push_back({f.regions, f.nodes, u[f.node]});
  const unsigned threads = detail::thread_count(params.solver.threads);
  std::vector<double> e2;
  std::vector<double> one(s.regions.size(), 1.0);
  (void)detail::cell_gradients(mesh, s.regions, s.coefficient, u, 1.0, threads, &e2);
  for (double v : e2) rep.field_energy += 0.5 * v;
  rep.residual = s.residual;
  rep.checks =
      electrode_checks(s, params.solver, "the charges", "|1/2 sum Q V - field energy| / field energy",
                       rep.energy, qv, rep.field_energy);
  // In a metal body the field is zero (its tets have no coefficient): write that, not the gradient of
  // the round-off.
  std::vector<double> field = detail::cell_gradients(mesh, s.regions, one, u, -1.0, threads, nullptr);
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    if (s.metal[s.regions.tet_rix[t]]) field[3 * t] = field[3 * t + 1] = field[3 * t + 2] = 0;
  detail::set_field(mesh, cell_field("electric_field", "V/m", 3, std::move(field)));
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
    throw SolverInputError(
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
  // Two terminals at one voltage carry round-off, not a current: the resistance is the matrix's then
  // (it once printed -0 ohm).
  if (ne == 2 && rep.terminals[0].charge != 0 && volt[0] != volt[1])
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
  double vi = 0;  // sum |V_i I_i|: the scale of the energy check
  for (const ElectrodeResult& t : rep.terminals) {
    rep.terminal_power += t.voltage * t.charge;
    vi += std::abs(t.voltage * t.charge);
  }
  // At least sum G_ii V_i^2, the power each terminal would drive alone: terminals at one voltage
  // drive none, and the round-off left (3e-31 W) failed the check against itself.
  double alone = 0;
  for (std::size_t i = 0; i < ne; ++i) alone += std::abs(s.matrix[i][i]) * volt[i] * volt[i];
  vi = std::max(vi, alone);
  rep.residual = s.residual;
  rep.checks = electrode_checks(s, params.solver, "the currents", "|sum V I - Joule heat| / Joule heat",
                                rep.terminal_power, vi, rep.total_power);
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
