// foxi solve MESH --physics thermal ...: a finite-element solve on a mesh file, results printed and
// written as fields.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi::cli {

namespace {

const char* kSolveUsage =
    "foxi solve MESH --physics thermal [--fix TAG=T] [--flux TAG=q] [--convect TAG=h,Tinf]\n"
    "                [--power REGION=W] [--power-density REGION=W/m3] [--k REGION=k]\n"
    "                [--solver auto|direct|amg|ichol] [--tol REL] [-o OUT]\n"
    "  Steady heat conduction with linear tets. Options may be repeated. TAG is a boundary tag\n"
    "  number or name, REGION a region id or name; SI units: T and Tinf in K, q in W/m^2 (into the\n"
    "  body), h in W/(m^2 K), k in W/(m K) (default: the region's material). Boundaries with no\n"
    "  condition are insulated; at least one --fix or --convect is needed. --power gives a region's\n"
    "  total heat in W, --power-density in W/m^3. Prints the maximum temperature and where, per-region\n"
    "  maximum and mean, heat through each boundary, and the solver's work; OUT (any mesh format,\n"
    "  .vtu for ParaView) gets the fields 'temperature' (K, nodes) and 'heat_flux' (W/m^2, cells).";

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
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size()) return false;
  out = static_cast<std::int32_t>(v);
  return true;
}

std::int32_t boundary_tag(const Mesh& mesh, const std::string& key, const std::string& option) {
  std::int32_t tag = 0;
  if (parse_int(key, tag)) return tag;
  for (const Boundary& b : mesh.boundaries)
    if (b.name == key) return b.tag;
  std::string names;
  for (const Boundary& b : mesh.boundaries)
    if (!b.name.empty()) names += (names.empty() ? "" : ", ") + b.name;
  throw UsageError(option + ": no boundary named '" + key + "'" +
                   (names.empty() ? "" : " (named: " + names + ")"));
}

std::int32_t region_id(const Mesh& mesh, const std::string& key, const std::string& option) {
  std::int32_t id = 0;
  if (parse_int(key, id)) return id;
  for (const Region& r : mesh.regions)
    if (r.name == key) return r.id;
  throw UsageError(option + ": no region named '" + key + "'");
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

}  // namespace

int cmd_solve(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kSolveUsage);
    return 0;
  }
  const std::string physics = args.option("--physics", "thermal");
  if (physics != "thermal")
    throw UsageError("--physics: only 'thermal' is implemented so far, not '" + physics + "'");
  const std::vector<std::string> fix = all_options(args, "--fix"), flux = all_options(args, "--flux"),
                                 convect = all_options(args, "--convect"),
                                 power = all_options(args, "--power"),
                                 density = all_options(args, "--power-density"),
                                 cond = all_options(args, "--k");
  const std::string solver = args.option("--solver", "auto");
  const std::string tol = args.option("--tol", "");
  std::string out = args.option("-o", "");
  if (out.empty()) out = args.option("--output", "");
  const auto files = args.positional(1, 1, kSolveUsage);

  ThermalParams params;
  if (solver == "direct")
    params.solver.kind = LinearSolverKind::direct;
  else if (solver == "amg")
    params.solver.kind = LinearSolverKind::cg_amg;
  else if (solver == "ichol")
    params.solver.kind = LinearSolverKind::cg_ichol;
  else if (solver != "auto")
    throw UsageError("--solver takes auto, direct, amg or ichol, not '" + solver + "'");
  if (!tol.empty()) params.solver.relative_tolerance = parse_number(tol, "--tol");
  if (!out.empty()) (void)format_from_path(out);  // a bad extension fails before the work

  auto t0 = std::chrono::steady_clock::now();
  Mesh mesh = read_mesh(files[0]);
  const ValidationReport validation = validate_and_repair(mesh);
  if (!validation.ok()) {
    std::fprintf(stderr, "foxi solve: warning: %s has problems:\n", files[0].c_str());
    for (const std::string& m : validation.messages) std::fprintf(stderr, "  %s\n", m.c_str());
  }
  auto t1 = std::chrono::steady_clock::now();

  for (const std::string& s : fix) {
    auto [k, v] = split_assignment(s, "--fix");
    params.fixed.push_back({boundary_tag(mesh, k, "--fix"), parse_number(v, "--fix")});
  }
  for (const std::string& s : flux) {
    auto [k, v] = split_assignment(s, "--flux");
    params.flux.push_back({boundary_tag(mesh, k, "--flux"), parse_number(v, "--flux")});
  }
  for (const std::string& s : convect) {
    auto [k, v] = split_assignment(s, "--convect");
    const auto comma = v.find(',');
    if (comma == std::string::npos) throw UsageError("--convect takes TAG=h,Tinf, not '" + s + "'");
    params.convection.push_back({boundary_tag(mesh, k, "--convect"),
                                 parse_number(v.substr(0, comma), "--convect"),
                                 parse_number(v.substr(comma + 1), "--convect")});
  }
  for (const std::string& s : power) {
    auto [k, v] = split_assignment(s, "--power");
    params.sources.push_back({region_id(mesh, k, "--power"), parse_number(v, "--power"), true});
  }
  for (const std::string& s : density) {
    auto [k, v] = split_assignment(s, "--power-density");
    params.sources.push_back(
        {region_id(mesh, k, "--power-density"), parse_number(v, "--power-density"), false});
  }
  for (const std::string& s : cond) {
    auto [k, v] = split_assignment(s, "--k");
    params.conductivity.push_back({region_id(mesh, k, "--k"), parse_number(v, "--k")});
  }

  const ThermalReport r = solve_thermal(mesh, params);
  auto t2 = std::chrono::steady_clock::now();

  std::printf("%s: %zu nodes, %zu tets; steady heat conduction, %zu unknowns\n", files[0].c_str(),
              mesh.node_count(), mesh.tet_count(), r.unknowns);
  const double* p = &mesh.xyz[3 * std::size_t{r.max_node}];
  std::printf("max temperature %.6g K (%.6g C) at node %u (%.6g, %.6g, %.6g)\n", r.max_temperature,
              r.max_temperature - 273.15, r.max_node, p[0], p[1], p[2]);
  std::printf("regions:\n");
  for (const RegionTemperature& t : r.regions)
    std::printf("  %-20s k %-10.4g W/(m K)  power %-10.4g W  max %.6g K  mean %.6g K  volume %.4g m^3\n",
                region_label(mesh, t.region).c_str(), t.conductivity, t.power, t.max_temperature,
                t.mean_temperature, t.volume);
  std::printf("boundaries (heat into the body):\n");
  double net = r.total_power;
  for (const BoundaryHeat& b : r.boundaries) {
    std::printf("  %-20s %-10s area %-10.4g m^2  heat %.6g W\n", boundary_label(mesh, b.tag).c_str(),
                b.kind.c_str(), b.area, b.heat_in);
    net += b.heat_in;
  }
  std::printf("total source power %.6g W; energy balance (sources + boundary heat) %.3g W\n", r.total_power,
              net);
  std::printf(
      "solver %s, %zu nonzeros, %zu iterations, relative residual %.3g; read %.3f s, assemble %.3f s, "
      "solve %.3f s\n",
      r.solver.c_str(), r.nonzeros, r.iterations, r.relative_residual,
      std::chrono::duration<double>(t1 - t0).count(), r.assembly_seconds, r.solve_seconds);
  (void)t2;
  if (!out.empty()) {
    write_mesh(mesh, out);
    std::printf("wrote %s (fields temperature [K], heat_flux [W/m^2])\n", out.c_str());
  }
  return 0;
}

}  // namespace foxi::cli
