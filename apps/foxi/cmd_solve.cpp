// foxi solve MESH --physics thermal|electrostatic|current ...: a finite-element solve on a mesh
// file, results printed and written as fields.
#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "mesh_input.hpp"
#include "model_run.hpp"
#include "run_results.hpp"
#include "solve_options.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi::cli {

namespace {

const char* kSolveUsage =
    "foxi solve MODEL.toml --physics thermal|electrostatic|current [--set NAME=VALUE]... [options below]\n"
    "  (--physics thermoelastic: see 'foxi solve --physics thermoelastic --help';\n"
    "   --physics transient: see 'foxi solve --physics transient --help';\n"
    "   --with ccx, the model solved by CalculiX: see 'foxi solve --with ccx --help')\n"
    "  Meshes the model (TetGen, its [mesh] controls) and solves with its [[conditions]] and [[loads]];\n"
    "  the options below add to them, boundaries and regions named as in 'foxi model check'.\n"
    "  Values take units as model files write them: --fix top=300K, --fix 'top=25 degC', --power die=3W,\n"
    "  --k die='150 W/(m*K)', --convect 'top=10 W/(m^2*K),25degC'; a bare number is SI; a unit of\n"
    "  another dimension is refused, and so is an absolute temperature not above 0 K.\n"
    "  --json [FILE.json]   every printed figure as one JSON record (key results marked; see the\n"
    "                       README) on stdout, the text silenced, or in FILE besides the text\n"
    "  --size-scale S       the model's mesh sizes ([mesh] max_size, parts, boxes) times S\n"
    "  --max-tets N         refuse a model whose mesh would have more tets (default 4e6)\n"
    "  --convergence K [--ratio R]  the solve on K meshes, sizes divided by R (default 1.5) each\n"
    "                       time: each key result per level, its observed order, the Richardson-\n"
    "                       extrapolated value and its error estimate (levels run as child processes)\n"
    "  Every solve prints the Zienkiewicz-Zhu error indicator of its temperature or potential, and,\n"
    "  on a terminal, the progress of a long solve (CG iterations, residual) on stderr.\n"
    "\n"
    "foxi solve MESH --physics thermal [--fix TAG=T] [--flux TAG=q] [--convect TAG=h,Tinf]\n"
    "                [--power REGION=W] [--power-density REGION=W/m3] [--k REGION=k]\n"
    "                [--theta JUNCTION:REFERENCE] [--solver auto|direct|amg|ichol] [--tol REL]\n"
    "                [--threads N] [-o OUT]\n"
    "  Steady heat conduction with linear tets. Options may be repeated. TAG is a boundary tag\n"
    "  number or name, REGION a region id or name; SI units: T and Tinf in K, q in W/m^2 (into the\n"
    "  body), h in W/(m^2 K), k in W/(m K) (default: the region's material). Boundaries with no\n"
    "  condition are insulated; at least one --fix or --convect is needed. --power gives a region's\n"
    "  total heat in W, --power-density in W/m^3 (either replaces a model's load on the region, said\n"
    "  on a line). Prints the maximum temperature and where, per-region\n"
    "  maximum and mean, heat through each boundary and its mean surface temperature, the energy\n"
    "  balance (sources + boundary heat, ~0), and the solver's work; OUT (any mesh format,\n"
    "  .vtu for ParaView) gets the fields 'temperature' (K, nodes) and 'heat_flux' (W/m^2, cells).\n"
    "  --theta prints a thermal resistance theta = (T_junction - T_reference) / P in K/W, P the total\n"
    "  power (sources + heat-flux boundaries), as JEDEC's theta_JC / theta_JA, and dT over the heat\n"
    "  leaving through the reference boundary (the path's own resistance). Each side is NAME or\n"
    "  KIND=NAME: max=REGION (the region's hottest node; a bare JUNCTION), mean=REGION (volume mean),\n"
    "  surface=TAG (area-mean surface temperature; a bare REFERENCE), ambient=TAG (Tinf of a\n"
    "  --convect tag). E.g. --theta die:bottom (theta_JC), --theta die:ambient=top (theta_JA).\n"
    "\n"
    "foxi solve MESH --physics electrostatic --conductor TAG[,TAG...]=NAME[:V] ... [--eps REGION=eps_r]\n"
    "  Electrostatics: each conductor is a set of boundary tags at one potential (V, default 0 V, used\n"
    "  for the written fields); other boundaries carry no normal field. A region whose material\n"
    "  conducts at least 1e4 S/m (and has no --eps) is metal: a metal body touching a conductor is part\n"
    "  of it, one touching none floats uncharged. Prints the capacitance matrix (F; C_ij = charge on i\n"
    "  with 1 V on j, 0 V on the others), the charges and each conductor's metal, the energy.\n"
    "  eps_r defaults to the region's material. OUT gets 'potential' (V) and 'electric_field' (V/m).\n"
    "\n"
    "foxi solve MESH --physics current --terminal TAG[,TAG...]=V ... [--terminal-current TAG[,TAG...]=A]\n"
    "                [--sigma REGION=S/m]\n"
    "  DC conduction: terminals at a fixed voltage (V) or a fixed total current into the body (A; at\n"
    "  least one terminal needs a voltage). Prints the current and voltage of each terminal, the\n"
    "  resistance (two terminals: (V1 - V2) / I1), the conductance matrix and the Joule heat per region.\n"
    "  sigma defaults to the region's material. OUT gets 'potential' (V), 'current_density' (A/m^2)\n"
    "  and 'joule_heat' (W/m^3).\n"
    "\n"
    "  Every physics prints its own checks (heat balance against the heat that flows; Kirchhoff,\n"
    "  Maxwell matrix signs, energy and the solve's residual for the electric ones); a failed check is\n"
    "  an UNRELIABLE line with the figures and exit status 4.\n"
    "\n"
    "foxi solve MESH --physics thermoelastic ... : thermal stress, see 'foxi solve --physics thermoelastic "
    "--help'.";

}  // namespace

double parse_number(const std::string& text, const std::string& option) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v))
    throw UsageError(option + ": '" + text + "' is not a number");
  return v;
}

// Splits "KEY=VALUE"; UsageError naming the option when malformed.
std::pair<std::string, std::string> split_assignment(const std::string& text, const std::string& option) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw UsageError(option + " takes KEY=VALUE, not '" + text + "'");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

bool parse_int(const std::string& s, std::int32_t& out) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || v < INT32_MIN || v > INT32_MAX)
    return false;  // 99999999999 was cast to a wrong int
  out = static_cast<std::int32_t>(v);
  return true;
}

// A name that several boundaries (or regions) share names none of them: `--fix face=300K` fixed the
// first of two Gmsh physical surfaces called "face" (an outside probe).
template <class Items, class Id>
void refuse_shared_name(const Items& items, const std::string& key, Id id, const std::string& option,
                        const char* what) {
  std::string ids;
  int count = 0;
  for (const auto& item : items)
    if (item.name == key && !key.empty()) {
      ids += (count++ ? " and " : "") + std::to_string(id(item));
    }
  if (count > 1)
    throw UsageError(option + ": the name '" + key + "' names the " + what + " " + ids + "; give the number");
}

std::int32_t boundary_tag(const Mesh& mesh, const std::string& key, const std::string& option) {
  refuse_shared_name(
      mesh.boundaries, key, [](const Boundary& b) { return b.tag; }, option, "boundaries");
  if (const auto tag = boundary_tag_of(mesh, key)) return *tag;
  std::string names;
  for (const Boundary& b : mesh.boundaries)
    if (!b.name.empty()) names += (names.empty() ? "" : ", ") + b.name;
  throw UsageError(option + ": no boundary named '" + key + "'" +
                   (names.empty() ? "" : " (named: " + names + ")"));
}

std::int32_t region_id(const Mesh& mesh, const std::string& key, const std::string& option) {
  refuse_shared_name(
      mesh.regions, key, [](const Region& r) { return r.id; }, option, "regions");
  if (const auto id = region_id_of(mesh, key)) return *id;
  throw UsageError(option + ": no region named '" + key + "'");
}

// One side of --theta: NAME or KIND=NAME (see kSolveUsage); a bare NAME is `bare`.
ThermalProbe theta_probe(const Mesh& mesh, const std::string& text, ThermalProbeKind bare) {
  const auto eq = text.find('=');
  ThermalProbe probe{bare, 0};
  std::string name = text;
  if (eq != std::string::npos) {
    const std::string kind = text.substr(0, eq);
    name = text.substr(eq + 1);
    if (kind == "max")
      probe.kind = ThermalProbeKind::region_max;
    else if (kind == "mean")
      probe.kind = ThermalProbeKind::region_mean;
    else if (kind == "surface")
      probe.kind = ThermalProbeKind::boundary_mean;
    else if (kind == "ambient")
      probe.kind = ThermalProbeKind::ambient;
    else
      throw UsageError("--theta: '" + kind + "' is not max, mean, surface or ambient (in '" + text + "')");
  }
  if (name.empty()) throw UsageError("--theta: empty name in '" + text + "'");
  const bool region =
      probe.kind == ThermalProbeKind::region_max || probe.kind == ThermalProbeKind::region_mean;
  probe.id = region ? region_id(mesh, name, "--theta") : boundary_tag(mesh, name, "--theta");
  return probe;
}

std::vector<std::string> all_options(Args& args, const char* name) {
  std::vector<std::string> values;
  while (args.has_option(name)) values.push_back(args.option(name));
  return values;
}

std::string boundary_label(const Mesh& mesh, std::int32_t tag) {
  const Boundary* b = mesh.find_boundary(tag);
  return std::to_string(tag) + (b && !b->name.empty() ? " (" + b->name + ")" : "");
}

std::string region_label(const Mesh& mesh, std::int32_t id) {
  const Region* r = mesh.find_region(id);
  return std::to_string(id) + (r && !r->name.empty() ? " (" + r->name + ")" : "");
}

namespace {
std::string regions_label(const Mesh& mesh, const std::vector<std::int32_t>& ids) {
  std::string s;
  for (std::int32_t id : ids) s += (s.empty() ? "region " : ", ") + region_label(mesh, id);
  return s;
}
}  // namespace

std::vector<std::int32_t> boundary_tags(const Mesh& mesh, const std::string& list,
                                        const std::string& option) {
  std::vector<std::int32_t> tags;
  std::size_t at = 0;
  while (at <= list.size()) {
    const std::size_t comma = std::min(list.find(',', at), list.size());
    const std::string key = list.substr(at, comma - at);
    if (key.empty()) throw UsageError(option + ": empty tag in '" + list + "'");
    tags.push_back(boundary_tag(mesh, key, option));
    at = comma + 1;
  }
  return tags;
}

std::string tags_label(const Mesh& mesh, const std::vector<std::int32_t>& tags) {
  std::string s;
  for (std::int32_t t : tags) s += (s.empty() ? "" : ",") + boundary_label(mesh, t);
  return s;
}

LinearSolverOptions parse_solver_options(Args& args) {
  LinearSolverOptions options;
  const std::string solver = args.option("--solver", "auto");
  const std::string tol = args.option("--tol", "");
  if (solver == "direct")
    options.kind = LinearSolverKind::direct;
  else if (solver == "amg")
    options.kind = LinearSolverKind::cg_amg;
  else if (solver == "ichol")
    options.kind = LinearSolverKind::cg_ichol;
  else if (solver != "auto")
    throw UsageError("--solver takes auto, direct, amg or ichol, not '" + solver + "'");
  if (!tol.empty()) {
    options.relative_tolerance = parse_number(tol, "--tol");
    // The result checks' tolerances follow it (100 x, at most 1e-3): a looser one would be no check
    // (--tol 0.9 printed a temperature 54 K off with "check energy ok").
    if (!(options.relative_tolerance >= 1e-14 && options.relative_tolerance <= 1e-3))
      throw UsageError("--tol takes a relative residual in [1e-14, 1e-3], not '" + tol + "'");
  }
  const std::string threads = args.option("--threads", "");
  if (!threads.empty()) {
    std::int32_t n = 0;
    if (!parse_int(threads, n) || n < 1 || n > 4096)
      throw UsageError("--threads takes a whole number from 1 to 4096, not '" + threads + "'");
    options.threads = unsigned(n);
  }
  return options;
}

namespace {

void print_matrix(const char* title, const char* unit, const std::vector<ElectrodeResult>& e,
                  const std::vector<std::vector<double>>& m) {
  std::printf("%s (%s):\n  %-16s", title, unit, "");
  for (const ElectrodeResult& r : e) std::printf(" %14.14s", r.name.c_str());
  std::printf("\n");
  for (std::size_t i = 0; i < e.size(); ++i) {
    std::printf("  %-16.16s", e[i].name.c_str());
    for (std::size_t j = 0; j < e.size(); ++j) std::printf(" %14.6e", m[i][j]);
    std::printf("\n");
  }
}

std::string regions_label(const Mesh& mesh, const std::vector<std::int32_t>& ids);

}  // namespace

// One line per check; a failed one is a loud UNRELIABLE line (on stdout with the figures, and on
// stderr). Returns the exit status: kExitUnreliable when a check failed.
int print_checks(const std::vector<BalanceCheck>& checks) {
  int status = kExitOk;
  for (const BalanceCheck& c : checks) {
    std::printf("check %-14s %-5s %.3g (tolerance %.3g): %s\n", c.name.c_str(), c.passed ? "ok" : "FAIL",
                c.figure, c.tolerance, c.what.c_str());
    if (!c.passed) {
      std::printf("UNRELIABLE: the %s check failed (%.3g > %.3g); the figures above are not to be trusted\n",
                  c.name.c_str(), c.figure, c.tolerance);
      std::fprintf(stderr, "foxi solve: UNRELIABLE result: the %s check failed (%.3g > %.3g: %s)\n",
                   c.name.c_str(), c.figure, c.tolerance, c.what.c_str());
      status = kExitUnreliable;
    }
  }
  return status;
}

ThermalOptions thermal_options(Args& args) {
  ThermalOptions o;
  o.fix = all_options(args, "--fix"), o.flux = all_options(args, "--flux");
  o.convect = all_options(args, "--convect"), o.power = all_options(args, "--power");
  o.density = all_options(args, "--power-density"), o.cond = all_options(args, "--k");
  o.theta = all_options(args, "--theta");
  auto values = [](const std::vector<std::string>& list, const char* option, const char* unit) {
    for (const std::string& s : list) (void)parse_value(split_assignment(s, option).second, option, unit);
  };
  for (const std::string& s : o.fix)
    (void)parse_temperature(split_assignment(s, "--fix").second, "--fix", TemperatureKind::absolute);
  for (const std::string& s : o.convect) {
    const auto [h, tinf] = split_pair(split_assignment(s, "--convect").second, "--convect", "TAG=h,Tinf");
    (void)parse_value(h, "--convect", "W/(m^2*K)");
    (void)parse_temperature(tinf, "--convect", TemperatureKind::absolute);
  }
  values(o.flux, "--flux", "W/m^2");
  values(o.power, "--power", "W");
  values(o.density, "--power-density", "W/m^3");
  values(o.cond, "--k", "W/(m*K)");
  return o;
}

void add_thermal_options(const Mesh& mesh, const ThermalOptions& o, ThermalParams& params) {
  for (const std::string& s : o.fix) {
    auto [k, v] = split_assignment(s, "--fix");
    params.fixed.push_back(
        {boundary_tag(mesh, k, "--fix"), parse_temperature(v, "--fix", TemperatureKind::absolute)});
  }
  for (const std::string& s : o.flux) {
    auto [k, v] = split_assignment(s, "--flux");
    params.flux.push_back({boundary_tag(mesh, k, "--flux"), parse_value(v, "--flux", "W/m^2")});
  }
  for (const std::string& s : o.convect) {
    auto [k, v] = split_assignment(s, "--convect");
    const auto [h, tinf] = split_pair(v, "--convect", "TAG=h,Tinf");
    params.convection.push_back({boundary_tag(mesh, k, "--convect"), parse_value(h, "--convect", "W/(m^2*K)"),
                                 parse_temperature(tinf, "--convect", TemperatureKind::absolute)});
  }
  // --power and --power-density replace the model's load on their region (said on a line); a region
  // given twice on the command line is a usage error.
  const std::size_t model_sources = params.sources.size();
  std::vector<bool> replaced(model_sources, false);
  auto add_source = [&](const std::string& s, const char* option, const char* unit, bool total) {
    auto [k, v] = split_assignment(s, option);
    const HeatSource source{region_id(mesh, k, option), parse_value(v, option, unit), total};
    for (std::size_t i = model_sources; i < params.sources.size(); ++i)
      if (params.sources[i].region == source.region)
        throw UsageError(std::string(option) + " " + k +
                         ": the region has a --power or --power-density already");
    for (std::size_t i = 0; i < model_sources; ++i)
      if (params.sources[i].region == source.region && !replaced[i]) {
        const HeatSource& old = params.sources[i];
        std::printf("%s %s replaces the model's load on %s (%.6g %s)\n", option, s.c_str(),
                    region_label(mesh, old.region).c_str(), old.value, old.total ? "W" : "W/m^3");
        replaced[i] = true;
      }
    params.sources.push_back(source);
  };
  for (const std::string& s : o.power) add_source(s, "--power", "W", true);
  for (const std::string& s : o.density) add_source(s, "--power-density", "W/m^3", false);
  for (std::size_t i = model_sources; i-- > 0;)
    if (replaced[i]) params.sources.erase(params.sources.begin() + std::ptrdiff_t(i));
  for (const std::string& s : o.cond) {
    auto [k, v] = split_assignment(s, "--k");
    params.conductivity.push_back({region_id(mesh, k, "--k"), parse_value(v, "--k", "W/(m*K)")});
  }
  for (const std::string& s : o.theta) {
    const auto colon = s.find(':');
    if (colon == std::string::npos || s.find(':', colon + 1) != std::string::npos)
      throw UsageError("--theta takes JUNCTION:REFERENCE, not '" + s + "'");
    params.resistances.push_back({theta_probe(mesh, s.substr(0, colon), ThermalProbeKind::region_max),
                                  theta_probe(mesh, s.substr(colon + 1), ThermalProbeKind::boundary_mean)});
  }
}

void print_thermal_report(const Mesh& mesh, const ThermalReport& r) {
  const double* p = &mesh.xyz[3 * std::size_t{r.max_node}];
  std::printf("max temperature %.6g K (%.6g C) at node %u (%.6g, %.6g, %.6g)\n", r.max_temperature,
              r.max_temperature - 273.15, r.max_node, p[0], p[1], p[2]);
  std::printf("%-24s %12s %12s %12s %10s %12s %12s\n", "regions", "k W/(m K)", "power W", "max T K",
              "max T C", "mean T K", "volume m^3");
  for (const RegionTemperature& t : r.regions)
    std::printf("  %-22s %12.4g %12.4g %12.6g %10.4g %12.6g %12.4g\n", region_label(mesh, t.region).c_str(),
                t.conductivity, t.power, t.max_temperature, t.max_temperature - 273.15, t.mean_temperature,
                t.volume);
  std::printf("%-24s %-10s %12s %14s %12s\n", "boundaries", "condition", "area m^2", "heat in W", "mean T K");
  double boundary_heat = 0;
  for (const BoundaryHeat& b : r.boundaries) {
    std::printf("  %-22s %-10s %12.4g %14.6g %12.6g", boundary_label(mesh, b.tag).c_str(), b.kind.c_str(),
                b.area, b.heat_in, b.mean_temperature);
    // A heat whose round-off bound reaches its sixth digit says how far it is known.
    if (b.heat_bound > 1e-6 * std::abs(b.heat_in)) std::printf("  (+-%.2g W round-off)", b.heat_bound);
    std::printf("\n");
    boundary_heat += b.heat_in;
  }
  std::printf("energy balance: sources %.6g W + heat in through the boundaries %.6g W = %.3g W",
              r.total_power, boundary_heat, r.imbalance);
  if (r.heat_flow > 0)
    std::printf(" (%.2g of the %.6g W that flow)", std::abs(r.imbalance) / r.heat_flow, r.heat_flow);
  std::printf("\n");
  for (const ThermalResistance& t : r.resistances) {
    auto side = [&](const ThermalProbe& probe) {
      switch (probe.kind) {
        case ThermalProbeKind::region_max:
          return "max of region " + region_label(mesh, probe.id);
        case ThermalProbeKind::region_mean:
          return "mean of region " + region_label(mesh, probe.id);
        case ThermalProbeKind::boundary_mean:
          return "surface mean of boundary " + boundary_label(mesh, probe.id);
        case ThermalProbeKind::ambient:
          return "ambient of boundary " + boundary_label(mesh, probe.id);
      }
      return std::string();
    };
    std::printf("thermal resistance %s %.6g K -> %s %.6g K: dT %.6g K, P %.6g W, ",
                side(t.spec.junction).c_str(), t.junction_temperature, side(t.spec.reference).c_str(),
                t.reference_temperature, t.delta_t, t.power);
    if (std::isnan(t.theta))
      std::printf("theta undefined (no power); ");
    else
      std::printf("theta %.6g K/W; ", t.theta);
    if (std::isnan(t.reference_heat_out))
      std::printf("no boundary heat at a region reference\n");
    else if (std::isnan(t.path_theta))
      std::printf("heat out there %.6g W, dT/heat undefined (no heat or no difference there)\n",
                  t.reference_heat_out);
    else
      std::printf("heat out there %.6g W, dT/heat %.6g K/W\n", t.reference_heat_out, t.path_theta);
  }
}

int cmd_solve(Args args) {
  const std::string physics = args.option("--physics", "thermal");
  if (args.has_option("--with")) return cmd_solve_with(std::move(args), physics);
  if (args.has_option("--convergence")) return cmd_solve_convergence(std::move(args), physics);
  if (physics == "thermoelastic") return cmd_solve_thermoelastic(std::move(args));
  if (physics == "transient") return cmd_solve_transient(std::move(args));
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kSolveUsage);
    return kExitOk;
  }
  if (physics != "thermal" && physics != "electrostatic" && physics != "current")
    throw UsageError("--physics takes thermal, electrostatic, current or thermoelastic, not '" + physics +
                     "'");
  const std::vector<std::string> conductor = all_options(args, "--conductor"),
                                 eps = all_options(args, "--eps"), terminal = all_options(args, "--terminal"),
                                 terminal_current = all_options(args, "--terminal-current"),
                                 sigma = all_options(args, "--sigma");
  const ThermalOptions thermal = thermal_options(args);
  const LinearSolverOptions solver_options = parse_solver_options(args);
  std::string out = args.option("-o", "");
  if (out.empty()) out = args.option("--output", "");
  const std::vector<std::string> sets = all_options(args, "--set");
  JsonOutput json = json_option(args);
  const double size_scale = size_scale_option(args);
  const double max_tets = max_tets_option(args);
  const auto files = args.positional(1, 1, kSolveUsage);

  ThermalParams params;
  params.solver = solver_options;
  params.solver.progress = terminal_progress(params.solver);
  if (!out.empty()) (void)format_from_path(out);  // a bad extension fails before the work
  if (!out.empty()) check_output_path(out);       // and so does a folder that cannot be written

  // The values are checked before the meshing, which may take long (tags and regions need the mesh).
  auto values = [](const std::vector<std::string>& list, const char* option, const char* unit) {
    for (const std::string& s : list) (void)parse_value(split_assignment(s, option).second, option, unit);
  };
  values(terminal, "--terminal", "V");
  values(terminal_current, "--terminal-current", "A");
  values(sigma, "--sigma", "S/m");

  const bool from_model = is_model_path(files[0]);
  if (!from_model && !sets.empty()) throw UsageError("--set is for model files (MODEL.toml)");
  if (!from_model && size_scale != 1) throw UsageError("--size-scale is for model files (MODEL.toml)");
  silence_text_for_json(json);
  auto t0 = std::chrono::steady_clock::now();
  MeshedModel model_run;
  if (from_model) model_run = mesh_model_for_solve(files[0], sets, physics, size_scale, max_tets);
  Mesh mesh = from_model ? std::move(model_run.mesh) : read_mesh(files[0]);
  require_usable(mesh, files[0], "solve");
  auto t1 = std::chrono::steady_clock::now();
  // The record of the run: the error indicator printed, the mesh written (-o), then the JSON (a
  // failed -o, a full disk, leaves no record saying ok); the exit status of the checks.
  auto finish = [&](RunResults res, const char* field, const char* fields_written) {
    res.model = files[0];
    res.parameters = run_parameters(sets);
    res.mesh_seconds = std::chrono::duration<double>(t1 - t0).count();
    res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.error_indicator = error_indicator(mesh, field);
    print_error_indicator(res.error_indicator, field);
    const int status = print_checks(res.checks);
    if (!out.empty()) {
      write_mesh(mesh, out);
      std::printf("wrote %s (fields %s)\n", out.c_str(), fields_written);
    }
    write_json(json, results_json(res));
    return status;
  };

  if (physics != "thermal") {
    if (!thermal.empty())
      throw UsageError(
          "--fix, --flux, --convect, --power, --power-density, --k and --theta are for --physics "
          "thermal");
    LinearSolverOptions so = params.solver;
    if (physics == "electrostatic") {
      if (!terminal.empty() || !terminal_current.empty() || !sigma.empty())
        throw UsageError("--terminal, --terminal-current and --sigma are for --physics current");
      ElectrostaticParams ep;
      ep.solver = so;
      if (from_model) ep.conductors = electrostatic_params_from_model(model_run.model, mesh).conductors;
      for (const std::string& s : conductor) {
        auto [k, v] = split_assignment(s, "--conductor");
        Electrode e;
        e.tags = boundary_tags(mesh, k, "--conductor");
        const auto colon = v.rfind(':');
        e.name = v.substr(0, colon);
        if (colon != std::string::npos) e.voltage = parse_value(v.substr(colon + 1), "--conductor", "V");
        ep.conductors.push_back(e);
      }
      for (const std::string& s : eps) {
        auto [k, v] = split_assignment(s, "--eps");
        ep.permittivity.push_back({region_id(mesh, k, "--eps"), parse_number(v, "--eps")});
      }
      const ElectrostaticReport r = solve_electrostatic(mesh, ep);
      std::printf("%s: %zu nodes, %zu tets; electrostatics, %zu unknowns, %zu conductors\n", files[0].c_str(),
                  mesh.node_count(), mesh.tet_count(), r.unknowns, r.conductors.size());
      print_matrix("capacitance matrix", "F", r.conductors, r.capacitance);
      std::printf("conductors at their potentials:\n");
      for (std::size_t i = 0; i < r.conductors.size(); ++i) {
        std::printf("  %-16s tags %-20s area %-10.4g m^2  %.6g V  charge %.6e C\n",
                    r.conductors[i].name.c_str(), tags_label(mesh, ep.conductors[i].tags).c_str(),
                    r.conductors[i].area, r.conductors[i].voltage, r.conductors[i].charge);
        if (!r.conductors[i].metal_regions.empty())
          std::printf("  %-16s with the metal of %s\n", "",
                      regions_label(mesh, r.conductors[i].metal_regions).c_str());
      }
      for (const FloatingMetal& f : r.floating)
        std::printf("  floating metal   %s (%zu nodes): %.6g V, no net charge\n",
                    regions_label(mesh, f.regions).c_str(), f.nodes, f.voltage);
      std::printf("stored energy %.6e J (1/2 sum Q V), field energy %.6e J\n", r.energy, r.field_energy);
      std::printf("solver %s, %zu iterations, relative residual %.3g; assemble %.3f s, solve %.3f s\n",
                  r.solver.c_str(), r.iterations, r.relative_residual, r.assembly_seconds, r.solve_seconds);
      return finish(electrostatic_results(mesh, r), "potential", "potential [V], electric_field [V/m]");
    }
    if (!conductor.empty() || !eps.empty())
      throw UsageError("--conductor and --eps are for --physics electrostatic");
    CurrentParams cp;
    cp.solver = so;
    if (from_model) cp.terminals = current_params_from_model(model_run.model, mesh).terminals;
    auto add_terminal = [&](const std::string& s, const char* option, bool current) {
      auto [k, v] = split_assignment(s, option);
      Electrode e;
      e.tags = boundary_tags(mesh, k, option);
      e.name = tags_label(mesh, e.tags);
      e.fixed_current = current;
      (current ? e.current : e.voltage) = parse_value(v, option, current ? "A" : "V");
      cp.terminals.push_back(e);
    };
    for (const std::string& s : terminal) add_terminal(s, "--terminal", false);
    for (const std::string& s : terminal_current) add_terminal(s, "--terminal-current", true);
    for (const std::string& s : sigma) {
      auto [k, v] = split_assignment(s, "--sigma");
      cp.conductivity.push_back({region_id(mesh, k, "--sigma"), parse_value(v, "--sigma", "S/m")});
    }
    const CurrentReport r = solve_current(mesh, cp);
    std::printf("%s: %zu nodes, %zu tets; DC conduction, %zu unknowns, %zu terminals\n", files[0].c_str(),
                mesh.node_count(), mesh.tet_count(), r.unknowns, r.terminals.size());
    std::printf("terminals (current into the body):\n");
    for (std::size_t i = 0; i < r.terminals.size(); ++i)
      std::printf("  %-24s %-8s area %-10.4g m^2  %.6g V  %.6e A\n", r.terminals[i].name.c_str(),
                  cp.terminals[i].fixed_current ? "current" : "voltage", r.terminals[i].area,
                  r.terminals[i].voltage, r.terminals[i].charge);
    std::printf(
        "resistance %.6e ohm%s\n", r.resistance,
        r.terminals.size() == 2 ? " (between the two terminals)" : " (1 / G_00, the others grounded)");
    print_matrix("conductance matrix", "S", r.terminals, r.conductance);
    std::printf("Joule heat per region:\n");
    for (const RegionJoule& j : r.regions)
      std::printf("  %-20s sigma %-10.4g S/m  volume %-10.4g m^3  %.6e W\n",
                  region_label(mesh, j.region).c_str(), j.conductivity, j.volume, j.power);
    std::printf("total Joule heat %.6e W (sum V I %.6e W)\n", r.total_power, r.terminal_power);
    std::printf("solver %s, %zu iterations, relative residual %.3g; assemble %.3f s, solve %.3f s\n",
                r.solver.c_str(), r.iterations, r.relative_residual, r.assembly_seconds, r.solve_seconds);
    return finish(current_results(mesh, r), "potential",
                  "potential [V], current_density [A/m^2], joule_heat [W/m^3]");
  }
  if (!conductor.empty() || !eps.empty() || !terminal.empty() || !terminal_current.empty() || !sigma.empty())
    throw UsageError("--conductor/--eps are for --physics electrostatic, --terminal/--sigma for current");

  if (from_model) {
    ThermalParams mp = thermal_params_from_model(model_run.model, mesh);
    params.fixed = mp.fixed, params.flux = mp.flux, params.convection = mp.convection;
    params.sources = mp.sources;
  }
  add_thermal_options(mesh, thermal, params);

  const ThermalReport r = solve_thermal(mesh, params);
  auto t2 = std::chrono::steady_clock::now();

  std::printf("%s: %zu nodes, %zu tets; steady heat conduction, %zu unknowns\n", files[0].c_str(),
              mesh.node_count(), mesh.tet_count(), r.unknowns);
  print_thermal_report(mesh, r);
  std::printf(
      "solver %s, %zu nonzeros, %zu iterations, relative residual %.3g; read %.3f s, assemble %.3f s, "
      "solve %.3f s\n",
      r.solver.c_str(), r.nonzeros, r.iterations, r.relative_residual,
      std::chrono::duration<double>(t1 - t0).count(), r.assembly_seconds, r.solve_seconds);
  (void)t2;
  return finish(thermal_results(mesh, r), "temperature", "temperature [K], heat_flux [W/m^2]");
}

}  // namespace foxi::cli
