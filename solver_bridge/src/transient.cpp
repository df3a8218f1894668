// Transient heat conduction: the steady solver's system (thermal_setup.hpp), a lumped heat capacity
// and implicit steps with one factorization or AMG hierarchy per step matrix (see transient.hpp).
#include "foxi/solver/transient.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>

#include "foxi/model/io_error.hpp"
#include "linear_solve.hpp"
#include "scalar_p1.hpp"
#include "thermal_setup.hpp"

namespace foxi {

double PowerWaveform::at(double t) const {
  switch (kind) {
    case Kind::step:
      return t >= 0 ? power : 0.0;
    case Kind::pulse: {
      if (t < 0 || !(period > 0)) return 0.0;
      const double k = std::floor(t / period);
      if (count != 0 && k >= static_cast<double>(count)) return 0.0;
      return t - k * period < width ? power : 0.0;
    }
    case Kind::table: {
      if (table.empty()) return 0.0;
      if (t <= table.front().first) return table.front().second;
      if (t >= table.back().first) return table.back().second;
      auto it = std::upper_bound(table.begin(), table.end(), t,
                                 [](double x, const std::pair<double, double>& p) { return x < p.first; });
      const auto& [t1, p1] = *it;
      const auto& [t0, p0] = *(it - 1);
      return p0 + (p1 - p0) * (t - t0) / (t1 - t0);
    }
  }
  return 0.0;
}

double PowerWaveform::energy(double t) const {
  if (!(t > 0)) return 0.0;
  switch (kind) {
    case Kind::step:
      return power * t;
    case Kind::pulse: {
      if (!(period > 0)) return 0.0;
      double k = std::floor(t / period);
      double e = 0;
      if (count != 0 && k >= static_cast<double>(count)) {
        k = static_cast<double>(count);
      } else {
        e = power * std::min(t - k * period, width);
      }
      return e + power * width * k;
    }
    case Kind::table: {
      if (table.empty()) return 0.0;
      double e = 0, at = 0;  // the energy up to `at`
      // held constant before the first point
      const double first = std::min(t, table.front().first);
      if (first > 0) {
        e += table.front().second * first;
        at = first;
      }
      for (std::size_t i = 1; i < table.size() && at < t; ++i) {
        const auto [t0, p0] = table[i - 1];
        const auto [t1, p1] = table[i];
        const double a = std::max(at, t0), b = std::min(t, t1);
        if (b <= a) continue;
        const double pa = p0 + (p1 - p0) * (a - t0) / (t1 - t0), pb = p0 + (p1 - p0) * (b - t0) / (t1 - t0);
        e += 0.5 * (pa + pb) * (b - a);
        at = b;
      }
      if (t > std::max(at, table.back().first))
        e += table.back().second * (t - std::max(at, table.back().first));
      return e;
    }
  }
  return 0.0;
}

bool PowerWaveform::jumps_in(double t0, double t1) const {
  if ((kind != Kind::table && power == 0) || !(t1 > t0)) return false;
  auto in = [&](double t) { return t > t0 && t <= t1; };
  switch (kind) {
    case Kind::step:
      return in(0.0);
    case Kind::pulse: {
      if (!(period > 0)) return false;
      if (width >= period)  // back to back: on at 0, off after the last
        return in(0.0) || (count != 0 && in(static_cast<double>(count) * period));
      // Pulse k rises at k period and falls at k period + width; at most a few are near the window
      // (more than 3 pulses in it: it holds edges).
      const double first = std::max(0.0, std::floor((t0 - width) / period));
      for (double k = first; k * period <= t1; k += 1) {
        if (count != 0 && k >= static_cast<double>(count)) break;
        if (k - first > 3 || in(k * period) || in(k * period + width)) return true;
      }
      return false;
    }
    case Kind::table: {
      // Continuous, but a vertex where the slope turns by enough to move the power by a tenth of its
      // largest over the window is a jump to BDF2's history (3 W for 5 s then 0 within a millisecond
      // stored 18.9 J for 15 J over 7 steps; an outside probe).
      double scale = 0;
      for (const auto& [t, p] : table) scale = std::max(scale, std::abs(p));
      const std::size_t n = table.size();
      auto slope = [&](std::size_t i) {  // of the segment after vertex i (0 past the last)
        return i + 1 < n ? (table[i + 1].second - table[i].second) / (table[i + 1].first - table[i].first)
                         : 0.0;
      };
      for (std::size_t i = 0; i < n; ++i) {
        if (!in(table[i].first)) continue;
        const double turn = std::abs(slope(i) - (i > 0 ? slope(i - 1) : 0.0));
        if (turn * (t1 - t0) > 0.1 * scale) return true;
      }
      return false;
    }
  }
  return false;
}

double PowerWaveform::mean(double t0, double t1) const {
  if (!(t1 > t0)) return at(t1);
  return (energy(t1) - energy(t0)) / (t1 - t0);
}

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

bool parse_double(std::string_view s, double& v) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && !s.empty();
}

}  // namespace

std::vector<std::pair<double, double>> read_power_table(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path, 0, 0, "cannot open the power table");
  std::vector<std::pair<double, double>> rows;
  std::string line;
  std::uint64_t n = 0;
  bool header_allowed = true;
  while (std::getline(in, line)) {
    ++n;
    const std::string_view s = trim(line);
    if (s.empty() || s.front() == '#') continue;
    const std::size_t comma = s.find(',');
    double t = 0, p = 0;
    const bool two = comma != std::string_view::npos && s.find(',', comma + 1) == std::string_view::npos;
    if (two && header_allowed && !parse_double(s.substr(0, comma), t)) {
      header_allowed = false;  // "time_s,power_W"
      continue;
    }
    header_allowed = false;
    if (!two) throw IoError(path, n, 0, "expected two fields 'time_s,power_W'");
    if (!parse_double(s.substr(0, comma), t)) throw IoError(path, n, 0, "the time is not a number");
    if (!parse_double(s.substr(comma + 1), p)) throw IoError(path, n, 0, "the power is not a number");
    if (!std::isfinite(t) || !std::isfinite(p)) throw IoError(path, n, 0, "time and power must be finite");
    if (!rows.empty() && !(t > rows.back().first))
      throw IoError(path, n, 0, "the time is not above the previous row's");
    rows.emplace_back(t, p);
  }
  if (in.bad()) throw IoError(path, n, 0, "read error");
  if (rows.empty()) throw IoError(path, n, 0, "the power table has no rows");
  return rows;
}

namespace {

void check_waveform(const Mesh& mesh, const TransientPower& p) {
  const std::string what = "power of " + detail::region_label(mesh, p.region);
  const PowerWaveform& w = p.power;
  switch (w.kind) {
    case PowerWaveform::Kind::step:
      detail::check_finite(w.power, what);
      break;
    case PowerWaveform::Kind::pulse:
      detail::check_finite(w.power, what);
      if (!(w.period > 0) || !std::isfinite(w.period) || !(w.width > 0) || !(w.width <= w.period))
        throw SolverInputError(what + ": a pulse needs 0 < width <= period, finite");
      break;
    case PowerWaveform::Kind::table:
      if (w.table.empty()) throw SolverInputError(what + ": the power table is empty");
      for (std::size_t i = 0; i < w.table.size(); ++i) {
        detail::check_finite(w.table[i].first, what + " (table time)");
        detail::check_finite(w.table[i].second, what + " (table power)");
        if (i > 0 && !(w.table[i].first > w.table[i - 1].first))
          throw SolverInputError(what + ": the table's times must increase");
      }
      break;
  }
}

// K + c0 / dt M on the free nodes: the stiffness with the lumped capacity added to its diagonal.
detail::ReducedSystem step_matrix(const detail::P1Stiffness& k, const std::vector<double>& mass, double c0_dt,
                                  const std::vector<char>& fixed, unsigned threads) {
  detail::P1Stiffness a;
  a.pat = k.pat;
  a.val = k.val;
  a.ntets = k.ntets;
  for (std::size_t v = 0; v < mass.size(); ++v) {
    if (mass[v] == 0) continue;
    const auto n = static_cast<std::uint32_t>(v);
    a.val[a.pat.find(n, n)] += c0_dt * mass[v];
  }
  return detail::reduce(a, fixed, threads);
}

}  // namespace

TransientReport solve_transient_thermal(Mesh& mesh, const TransientParams& params) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  if (!(params.end_time > 0) || !std::isfinite(params.end_time))
    throw SolverInputError("transient: the end time must be positive and finite");
  if (params.steps == 0) throw SolverInputError("transient: the number of steps must be positive");
  TransientReport out;
  out.scheme = params.scheme;
  ThermalReport& rep = out.final;
  const bool uniform_start = !std::isnan(params.initial_temperature);
  const detail::ThermalSystem sys = detail::assemble_thermal(mesh, params.thermal, rep, !uniform_start);
  if (!uniform_start)
    detail::require_anchored(sys,
                             "transient: the start (the steady state with no power; "
                             "TransientParams::initial_temperature, foxi's --initial, gives one instead)");
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nr = sys.regions.size();
  const unsigned threads = sys.threads;
  const std::vector<std::uint32_t>& tet_rix = sys.regions.tet_rix;
  const std::vector<char>& fixed = sys.dir.fixed;

  // Heat capacity per region, lumped per node; unit-power load per transient power.
  std::vector<std::pair<std::int32_t, double>> overrides;
  for (const RegionHeatCapacity& c : params.heat_capacity) overrides.emplace_back(c.region, c.rho_c);
  const std::vector<double> region_rc = detail::region_coefficients(
      mesh, sys.regions, [](const Material& m) { return m.density * m.specific_heat; }, overrides,
      "heat capacity (density * specific heat)", "TransientParams::heat_capacity (density and specific_heat");
  std::vector<double> region_volume;
  const std::vector<double> tet_volume = detail::tet_volumes(mesh, sys.regions, threads, region_volume);
  std::vector<double> mass(nn, 0.0);
  for (std::size_t t = 0; t < nt; ++t)
    for (int a = 0; a < 4; ++a) mass[mesh.tet[4 * t + a]] += region_rc[tet_rix[t]] * tet_volume[t] / 4;
  std::vector<std::vector<double>> unit_load;
  std::vector<char> region_has_power(nr, 0);
  for (const TransientPower& p : params.power) {
    const std::size_t r = sys.regions.index(p.region);
    if (r == SIZE_MAX)
      throw SolverInputError("power given for " + detail::region_label(mesh, p.region) +
                             ", which has no tets");
    if (region_has_power[r])
      throw SolverInputError(detail::region_label(mesh, p.region) + " has more than one power");
    region_has_power[r] = 1;
    check_waveform(mesh, p);
    std::vector<double> u(nn, 0.0);
    for (std::size_t t = 0; t < nt; ++t)
      if (tet_rix[t] == r)
        for (int a = 0; a < 4; ++a) u[mesh.tet[4 * t + a]] += tet_volume[t] / 4 / region_volume[r];
    unit_load.push_back(std::move(u));
  }
  std::vector<std::vector<std::uint32_t>> junction_nodes;
  for (std::int32_t id : params.junctions) {
    const std::size_t r = sys.regions.index(id);
    if (r == SIZE_MAX) throw SolverInputError("junction " + detail::region_label(mesh, id) + " has no tets");
    std::vector<std::uint32_t> nodes;
    for (std::size_t t = 0; t < nt; ++t)
      if (tet_rix[t] == r) nodes.insert(nodes.end(), &mesh.tet[4 * t], &mesh.tet[4 * t] + 4);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    junction_nodes.push_back(std::move(nodes));
  }
  auto waveform_power = [&](double t) {
    double p = 0;
    for (const TransientPower& w : params.power) p += w.power.at(t);
    return p;
  };
  // The waveforms' mean power over [t0, t1] (their value at t1 where t0 == t1).
  auto waveform_mean = [&](double t0, double t1) {
    double p = 0;
    for (const TransientPower& w : params.power) p += w.power.mean(t0, t1);
    return p;
  };
  auto load_at = [&](double t0, double t1) {
    std::vector<double> f = sys.load;
    for (std::size_t i = 0; i < params.power.size(); ++i) {
      const double p = params.power[i].power.mean(t0, t1);
      if (p != 0)
        for (std::size_t v = 0; v < nn; ++v) f[v] += p * unit_load[i][v];
    }
    return f;
  };

  const double dt = params.end_time / static_cast<double>(params.steps);
  out.time_step = dt;
  const LinearSolverOptions& user = params.thermal.solver;
  auto progress = [&](double fraction) {
    if (user.progress && !user.progress("time steps", fraction))
      throw SolverCancelled("transient solve cancelled");
  };
  progress(0.0);

  // Initial state: the steady solution with the constant sources, or a uniform temperature.
  std::vector<double> temp = sys.dir.value;
  if (!uniform_start) {
    const detail::ReducedSystem red = detail::reduce(sys.stiff, fixed, threads);
    const std::vector<double> rhs = detail::reduced_rhs(sys.stiff, red, sys.load, fixed, temp, threads);
    LinearSolverOptions o = user;
    o.progress = nullptr;
    std::vector<double> x;
    const detail::LinearSolveResult lin = detail::solve_spd(red.a, rhs, x, o);
    out.iterations += lin.iterations;
    detail::scatter(red, x, temp);
  } else {
    detail::check_finite(params.initial_temperature, "initial temperature");
    for (std::size_t v = 0; v < nn; ++v)
      if (!fixed[v] && mass[v] > 0) temp[v] = params.initial_temperature;
  }
  const std::vector<double> temp0 = temp;

  double constant_power = 0;
  for (std::size_t r = 0; r < nr; ++r) constant_power += sys.region_q[r] * region_volume[r];
  auto record = [&](std::size_t step, double time) {
    out.times.push_back(time);
    out.power.push_back(constant_power + waveform_power(time));
    out.junction_temperature.resize(junction_nodes.size());
    for (std::size_t j = 0; j < junction_nodes.size(); ++j) {
      double m = -std::numeric_limits<double>::infinity();
      for (std::uint32_t v : junction_nodes[j]) m = std::max(m, temp[v]);
      out.junction_temperature[j].push_back(m);
    }
    if (params.on_step && !params.on_step(step, time, temp))
      throw SolverCancelled("transient solve cancelled at step " + std::to_string(step));
  };
  record(0, 0.0);

  // Step matrices: Euler's, and BDF2's (3/2 M/dt + K) after its Euler first step; a solver for each,
  // made when first needed and kept (BDF2 restarts with Euler steps across a jump of the power).
  const detail::ReducedSystem euler = step_matrix(sys.stiff, mass, 1 / dt, fixed, threads);
  std::unique_ptr<detail::ReducedSystem> bdf2;
  std::unique_ptr<detail::SpdSolver> solvers[2];  // Euler's, BDF2's
  LinearSolverOptions o = user;
  std::size_t step_now = 0;
  // The CG's progress within a step, as the fraction of all steps (and its cancel).
  o.progress = [&](std::string_view, double f) {
    return !user.progress ||
           user.progress("time steps", (static_cast<double>(step_now) + std::clamp(f, 0.0, 1.0)) /
                                           static_cast<double>(params.steps));
  };
  out.unknowns = euler.a.rows();
  const auto t_setup = clock::now();
  double setup_seconds = std::chrono::duration<double>(t_setup - t_start).count();
  std::vector<double> previous = temp, hist(nn), x, r(euler.a.rows());
  double imbalance = 0, flowed = 0, noise = 0, lowest = std::numeric_limits<double>::infinity();
  std::vector<BoundaryHeat> boundaries = rep.boundaries;
  std::vector<double> magnitude;
  for (std::size_t n = 0; n < params.steps; ++n) {
    step_now = n;
    const double time = dt * static_cast<double>(n + 1);
    // BDF2's history spans the step before; its power window reaches half a step past the step's
    // end. A jump of the power there (a pulse's edge) carries into the history: after a pulse
    // within one step BDF2 kept adding half the pulse's energy (2.25 mJ stored for a 1.5 mJ pulse;
    // an outside probe). Such steps are Euler steps, which have no history.
    bool jump = false;
    for (const TransientPower& w : params.power)
      jump = jump || w.power.jumps_in(time - 2 * dt, time + 0.5 * dt);
    const bool use_bdf2 = params.scheme == TimeScheme::bdf2 && n > 0 && !jump;
    const double c0 = use_bdf2 ? 1.5 : 1.0;
    const detail::ReducedSystem* sysm = &euler;
    if (use_bdf2) {
      if (!bdf2)
        bdf2 = std::make_unique<detail::ReducedSystem>(step_matrix(sys.stiff, mass, c0 / dt, fixed, threads));
      sysm = bdf2.get();
    }
    std::unique_ptr<detail::SpdSolver>& solver = solvers[use_bdf2 ? 1 : 0];
    if (!solver) {
      const auto t0 = clock::now();
      solver = std::make_unique<detail::SpdSolver>(sysm->a, o);
      out.solver = solver->name();
      setup_seconds += std::chrono::duration<double>(clock::now() - t0).count();
    }
    // Steps of power have no jump after t = 0: Euler's solver (its factor or hierarchy) is not needed
    // again once BDF2 runs.
    if (use_bdf2 && solvers[0] &&
        std::all_of(params.power.begin(), params.power.end(),
                    [](const TransientPower& w) { return w.power.kind == PowerWaveform::Kind::step; }))
      solvers[0].reset();
    for (std::size_t v = 0; v < nn; ++v) hist[v] = use_bdf2 ? 2 * temp[v] - 0.5 * previous[v] : temp[v];
    // The power over the step, not its value at the step's end: a pulse shorter than a step, or one
    // between two step ends, was missed or counted a whole step (an outside probe: 10 pulses of 3 W
    // for 0.5 ms stored 0.030 J for 0.015 J, the energy check passing). Euler: the mean over the
    // step, so the energy put in is the waveform's to rounding; BDF2 (second order at t_n+1): the
    // mean over the step's length centred on its end, the same to O(dt^2) where the power is smooth
    // (the last window ends at the end time). A jump in or next to it makes the step an Euler step
    // (jumps_in above), so no pulse falls between windows; a BDF2 step after an Euler step centres its
    // window too (one starting where Euler's ended, 1.5 steps long, lost 1/12 J at each tooth of a
    // 3 W sawtooth; an outside probe).
    const double t_from = use_bdf2 ? time - 0.5 * dt : time - dt;
    const double t_to = use_bdf2 ? std::min(time + 0.5 * dt, params.end_time) : time;
    std::vector<double> f = load_at(t_from, t_to);
    std::vector<double> g = f;
    for (std::size_t v = 0; v < nn; ++v)
      if (mass[v] > 0) g[v] += mass[v] / dt * hist[v];
    const std::vector<double> rhs = detail::reduced_rhs(sys.stiff, *sysm, g, fixed, sys.dir.value, threads);
    // Solve for the increment from the previous temperature (a warm start).
    std::vector<double> x0(rhs.size());
    for (std::size_t v = 0; v < nn; ++v)
      if (sysm->dof[v] >= 0) x0[static_cast<std::size_t>(sysm->dof[v])] = temp[v];
    detail::multiply(sysm->a, x0.data(), r.data(), threads);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = rhs[i] - r[i];
    // The goal relative to the step's whole right-hand side, as a solve from zero would have it.
    const detail::LinearSolveResult lin = solver->solve(r, x, &rhs);
    out.iterations += lin.iterations;
    out.relative_residual = std::max(out.relative_residual, lin.relative_residual);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += x0[i];
    previous = temp;
    detail::scatter(*sysm, x, temp);
    for (std::size_t v = 0; v < nn; ++v)
      if (mass[v] > 0 && !std::isfinite(temp[v]))
        throw SolverError("transient: the temperature is NaN or infinite at step " + std::to_string(n + 1));

    // Energy of the step: heat in (sources and boundaries at the new time) against the scheme's change
    // of stored energy.
    detail::boundary_heat(mesh, sys, f, temp, boundaries, &magnitude);
    const double power = constant_power + waveform_mean(t_from, t_to);
    double q = power, in = std::max(0.0, power), outflow = std::max(0.0, -power);
    for (const BoundaryHeat& b : boundaries) {
      q += b.heat_in;
      (b.heat_in > 0 ? in : outflow) += std::abs(b.heat_in);
    }
    double stored = 0, stored_terms = 0, boundary_terms = 0;
    for (std::size_t v = 0; v < nn; ++v)
      if (mass[v] > 0) {
        stored += mass[v] * (c0 * temp[v] - hist[v]);
        stored_terms += mass[v] * (c0 * std::abs(temp[v]) + std::abs(hist[v]));
        // The conduction rows' round-off moves heat too (rows of K summing to ~eps K_vv T, not 0).
        for (std::size_t i = sys.stiff.pat.row_start[v]; i < sys.stiff.pat.row_start[v + 1]; ++i)
          stored_terms += dt * std::abs(sys.stiff.val[i] * temp[sys.stiff.pat.col[i]]);
      }
    for (const double m : magnitude) boundary_terms += m;
    imbalance += dt * q - stored;
    // What the step's imbalance can be from round-off (of the temperatures, the stored energy and the
    // conduction rows): a run with no power and the body at the ambient moves nothing but that, and
    // its imbalance against its "flow" of round-off failed the check (0.83). An iterative solve's
    // residual is not counted: the check is there to see it.
    noise += 4 * std::numeric_limits<double>::epsilon() * (stored_terms + dt * boundary_terms);
    for (std::size_t v = 0; v < nn; ++v)
      if (mass[v] > 0) lowest = std::min(lowest, temp[v]);
    flowed += dt * std::max(in, outflow);
    out.heat_in += dt * q;
    record(n + 1, time);
    progress(static_cast<double>(n + 1) / static_cast<double>(params.steps));
  }
  for (std::size_t v = 0; v < nn; ++v)
    if (mass[v] > 0) {
      out.stored_energy += mass[v] * (temp[v] - temp0[v]);
      out.capacity_moment += mass[v] * (temp[v] - temp0[v]) * (temp[v] - temp0[v]);
    }
  // flowed also covers the heat only stored (a body heated with adiabatic walls): the sources count.
  out.heat_flow = flowed;
  // The imbalance beyond what the temperatures' own error can make (noise), against the heat that flowed.
  const double unexplained = std::max(0.0, std::abs(imbalance) - noise);
  out.checks.push_back(make_check("energy",
                                  "(|sum over steps of (heat in - stored energy change)| less its round-off "
                                  "bound) / the heat that flowed",
                                  unexplained > 0 ? unexplained / flowed : 0.0,
                                  std::min(1e-3, std::max(1e-6, 100 * user.relative_tolerance))));
  // As the steady check: a power drawn out past what the conditions supply takes the temperature
  // below 0 K (-1362 K was printed, exit 0; an outside probe). Minus the lowest temperature of any
  // step, below 0.
  out.checks.push_back(
      BalanceCheck{"absolute zero",
                   "minus the lowest temperature of any step, K: below 0 (else the powers or "
                   "conditions are not physical)",
                   -lowest, 0, -lowest < 0});

  // The last state as the steady solver reports one (its sources include the waveforms' power now).
  const double t_end = params.end_time;
  for (std::size_t i = 0; i < params.power.size(); ++i) {
    const std::size_t ri = sys.regions.index(params.power[i].region);
    rep.regions[ri].power += params.power[i].power.at(t_end);
  }
  rep.total_power = constant_power + waveform_power(t_end);
  detail::boundary_heat(mesh, sys, load_at(t_end, t_end), temp, rep.boundaries);
  Field flux = detail::region_results(mesh, params.thermal, sys, temp, rep);
  rep.solver = out.solver;
  rep.unknowns = out.unknowns;
  rep.iterations = out.iterations;
  rep.relative_residual = out.relative_residual;
  detail::store_temperature(mesh, std::move(temp), std::move(flux));
  out.setup_seconds = setup_seconds;
  out.solve_seconds = std::chrono::duration<double>(clock::now() - t_setup).count() -
                      (setup_seconds - std::chrono::duration<double>(t_setup - t_start).count());
  return out;
}

}  // namespace foxi
