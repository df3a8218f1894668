// foxi solve MESH --physics thermoelastic ...: linear thermal stress on a mesh file; maximum von Mises
// stress and where, per region and per material interface; fields written with -o.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "mesh_input.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/thermoelastic.hpp"
#include "model_run.hpp"
#include "run_results.hpp"
#include "solve_options.hpp"

namespace foxi::cli {

namespace {

const char* kThermoelasticUsage =
    "foxi solve MODEL.toml --physics thermoelastic [--set NAME=VALUE]... [--temperature-from-thermal]\n"
    "                [--tref K] [the options below]\n"
    "  Meshes the model (its [mesh] controls) and solves with its displacement and sliding conditions,\n"
    "  its materials' E, nu, alpha and its uniform temperature_change load; the options below add to\n"
    "  them (--dT replaces the load). --temperature-from-thermal first solves the model's steady heat\n"
    "  (its thermal conditions and power loads) and takes that temperature field as the load against\n"
    "  the stress-free --tref (default 293.15 K) instead of a temperature_change load.\n"
    "  --json [FILE.json], --size-scale S and --convergence K as for the other physics (foxi solve --help).\n"
    "\n"
    "foxi solve MESH --physics thermoelastic [--fix TAG[=COMPONENTS]] [--slide TAG]\n"
    "                (--dT K | --temperature FILE[:FIELD] [--tref K])\n"
    "                [--E REGION=Pa] [--nu REGION=nu] [--alpha REGION=1/K]\n"
    "                [--order 1|2] [--solver auto|direct|amg|ichol] [--tol REL] [-o OUT]\n"
    "  Linear thermoelasticity with linear tets. Options may be repeated; TAG is a boundary tag number\n"
    "  or name, REGION a region id or name. Values take units as model files write them (--E die=130GPa,\n"
    "  --alpha die='2.6 ppm/K', --dT 5degC = --dT 5K, --tref '25 degC'); a bare number is SI.\n"
    "  --order 2            quadratic (10-node) tets for stress accuracy: mid-edge unknowns internal to\n"
    "                       the solver (about 7x the unknowns); results still at the mesh's nodes and\n"
    "                       per tet (stress at the centroid = the tet's mean stress)\n"
    "  --fix TAG            every displacement component 0 on the tag's nodes\n"
    "  --fix TAG=ux,uz:1e-6 only the named components (ux, uy, uz), each 0 or the value after ':' (m)\n"
    "  --slide TAG          zero normal displacement on a planar tag (any orientation)\n"
    "  Other boundaries are free. The connected parts must be held against every rigid motion (the\n"
    "  solver names the motions left otherwise).\n"
    "  --dT K               uniform temperature change\n"
    "  --temperature FILE[:FIELD]  nodal temperatures (K) from a mesh file with the same nodes (e.g.\n"
    "                       the -o of --physics thermal; FIELD defaults to 'temperature'); the\n"
    "                       stress-free temperature is --tref (default 293.15 K)\n"
    "  --E, --nu, --alpha   Young's modulus, Poisson ratio, thermal expansion (default: the region's\n"
    "                       material)\n"
    "  Prints the maximum von Mises stress and where, the largest displacement, the maximum per region\n"
    "  and at each material interface, the solver's work and the checks (the thermal load's nodal forces\n"
    "  sum to zero; the reactions at the constrained nodes balance: exit 4 if not). OUT gets\n"
    "  'displacement' (m, nodes), 'stress' (Pa, cells, xx yy zz xy yz xz), 'von_mises' and\n"
    "  'principal_stress' (Pa, cells).";

FixedDisplacement parse_fix(const Mesh& mesh, const std::string& text) {
  FixedDisplacement f;
  const auto eq = text.find('=');
  f.tag = boundary_tag(mesh, text.substr(0, eq), "--fix");
  if (eq == std::string::npos) return f;
  f.fix[0] = f.fix[1] = f.fix[2] = false;
  std::size_t at = eq + 1;
  while (at <= text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, comma - at);
    const auto colon = item.find(':');
    const std::string name = item.substr(0, colon);
    const int c = name == "ux" ? 0 : name == "uy" ? 1 : name == "uz" ? 2 : -1;
    if (c < 0) throw UsageError("--fix: '" + name + "' is no component (ux, uy, uz) in '" + text + "'");
    f.fix[c] = true;
    if (colon != std::string::npos) f.value[c] = parse_value(item.substr(colon + 1), "--fix", "m");
    at = comma + 1;
  }
  return f;
}

// The node field FIELD of FILE, checked to be on the same nodes as `mesh`.
std::vector<double> read_temperature(const Mesh& mesh, const std::string& spec) {
  std::string file = spec, name = "temperature";
  if (const auto colon = spec.rfind(':'); colon != std::string::npos && colon > 1) {
    file = spec.substr(0, colon);
    name = spec.substr(colon + 1);
  }
  const Mesh source = read_mesh(file);
  const Field* f = source.find_field(name);
  if (!f || f->location != FieldLocation::node || f->components != 1)
    throw UsageError("--temperature: " + file + " has no scalar node field '" + name + "'");
  if (source.node_count() != mesh.node_count())
    throw UsageError("--temperature: " + file + " has " + std::to_string(source.node_count()) +
                     " nodes, the mesh " + std::to_string(mesh.node_count()));
  double size = 0, worst = 0;
  for (std::size_t i = 0; i < mesh.xyz.size(); ++i) {
    size = std::max(size, std::abs(mesh.xyz[i]));
    worst = std::max(worst, std::abs(mesh.xyz[i] - source.xyz[i]));
  }
  if (worst > 1e-9 * size)
    throw UsageError("--temperature: the nodes of " + file + " are not those of the mesh (moved by up to " +
                     std::to_string(worst) + " m)");
  const std::span<const double> last = f->step(f->step_count() - 1, source.node_count());
  return {last.begin(), last.end()};
}

}  // namespace

void print_thermoelastic_report(const Mesh& mesh, const ThermoelasticReport& r) {
  auto centroid = [&](std::uint32_t t) {
    double c[3] = {0, 0, 0};
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) c[i] += 0.25 * mesh.xyz[3 * std::size_t{mesh.tet[4 * t + a]} + i];
    char text[96];
    std::snprintf(text, sizeof text, "tet %u at (%.6g, %.6g, %.6g)", t, c[0], c[1], c[2]);
    return std::string(text);
  };
  std::printf("max von Mises stress %.6g Pa in %s, %s\n", r.max_von_mises, centroid(r.max_tet).c_str(),
              ("region " + region_label(mesh, mesh.region_of(r.max_tet))).c_str());
  const double* p = &mesh.xyz[3 * std::size_t{r.max_displacement_node}];
  std::printf("max displacement %.6g m at node %u (%.6g, %.6g, %.6g)\n", r.max_displacement,
              r.max_displacement_node, p[0], p[1], p[2]);
  std::printf("regions:\n");
  for (const RegionStress& s : r.regions)
    std::printf("  %-20s E %-10.4g Pa  nu %-6.4g  alpha %-10.4g 1/K  max von Mises %.6g Pa in %s\n",
                region_label(mesh, s.region).c_str(), s.youngs_modulus, s.poisson_ratio, s.thermal_expansion,
                s.max_von_mises, centroid(s.max_tet).c_str());
  if (!r.interfaces.empty()) std::printf("material interfaces (tets touching them):\n");
  for (const InterfaceStress& s : r.interfaces)
    std::printf("  %s / %s  area %.4g m^2  max von Mises %.6g Pa in %s\n",
                region_label(mesh, s.region_a).c_str(), region_label(mesh, s.region_b).c_str(), s.area,
                s.max_von_mises, centroid(s.max_tet).c_str());
}

int cmd_solve_thermoelastic(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kThermoelasticUsage);
    return kExitOk;
  }
  const std::vector<std::string> fix = all_options(args, "--fix"), slide = all_options(args, "--slide"),
                                 young = all_options(args, "--E"), nu = all_options(args, "--nu"),
                                 alpha = all_options(args, "--alpha");
  const std::string dt = args.option("--dT", ""), temperature = args.option("--temperature", ""),
                    tref = args.option("--tref", ""), order = args.option("--order", "1");
  ThermoelasticParams params;
  params.solver = parse_solver_options(args);
  params.solver.progress = terminal_progress(params.solver);
  std::string out = args.option("-o", "");
  if (out.empty()) out = args.option("--output", "");
  const bool from_thermal = args.flag("--temperature-from-thermal");
  const std::vector<std::string> sets = all_options(args, "--set");
  JsonOutput json = json_option(args);
  const double size_scale = size_scale_option(args);
  const double max_tets = max_tets_option(args);
  const auto files = args.positional(1, 1, kThermoelasticUsage);
  const bool from_model = is_model_path(files[0]);
  if (!from_model && (from_thermal || !sets.empty() || size_scale != 1))
    throw UsageError("--set, --size-scale and --temperature-from-thermal are for model files (MODEL.toml)");
  if (!dt.empty() + !temperature.empty() + from_thermal > 1)
    throw UsageError(
        "--physics thermoelastic takes one of --dT, --temperature and --temperature-from-thermal");
  if (!from_model && dt.empty() && temperature.empty())
    throw UsageError("--physics thermoelastic on a mesh takes one of --dT and --temperature");
  if (!tref.empty() && temperature.empty() && !from_thermal)
    throw UsageError("--tref goes with --temperature or --temperature-from-thermal");
  if (order != "1" && order != "2") throw UsageError("--order takes 1 or 2, not '" + order + "'");
  params.order = order == "2" ? 2 : 1;
  if (!out.empty()) (void)format_from_path(out);  // a bad extension fails before the work
  if (!out.empty()) check_output_path(out);       // and so does a folder that cannot be written

  // the temperatures are checked before the meshing, which may take long
  if (!dt.empty()) (void)parse_temperature(dt, "--dT", TemperatureKind::difference);
  if (!tref.empty()) (void)parse_temperature(tref, "--tref", TemperatureKind::absolute);
  silence_text_for_json(json);
  const auto t0 = std::chrono::steady_clock::now();
  // the thermal conditions are checked before meshing, as mesh_model checks the stress conditions
  if (from_thermal) check_physics(load_model(files[0], sets, "--set"), Physics::thermal);
  MeshedModel run;
  if (from_model)
    run = mesh_model_for_solve(files[0], sets, physics_name(Physics::thermal_stress), size_scale, max_tets);
  Mesh mesh = from_model ? std::move(run.mesh) : read_mesh(files[0]);
  const auto t_mesh = std::chrono::steady_clock::now();
  require_usable(mesh, files[0], "solve");
  if (from_model) {
    const ThermoelasticParams mp = thermoelastic_params_from_model(run.model, mesh);
    params.materials = mp.materials, params.fixed = mp.fixed, params.sliding = mp.sliding;
    params.delta_t = mp.delta_t;
    bool has_load = false;
    for (const Load& l : run.model.loads) has_load = has_load || l.kind == LoadKind::temperature_change;
    if (!has_load && dt.empty() && temperature.empty() && !from_thermal)
      throw UsageError(
          files[0] +
          ": no temperature_change load; give one, --dT, --temperature or --temperature-from-thermal");
    if (has_load && from_thermal)
      std::printf("note: the thermal solve's temperatures replace the model's temperature_change load\n");
  }
  if (from_thermal) {
    ThermalParams tp = thermal_params_from_model(run.model, mesh);
    tp.solver = params.solver;
    const ThermalReport tr = solve_thermal(mesh, tp);
    const Field* t = mesh.find_field("temperature");
    params.temperature.assign(t->values.begin(), t->values.end());
    params.delta_t = 0;
    std::printf(
        "thermal solve (the model's thermal conditions and power loads): max temperature %.6g K (%.6g C), "
        "%zu iterations, %.3f s; stress-free at %.6g K\n",
        tr.max_temperature, tr.max_temperature - 273.15, tr.iterations, tr.solve_seconds,
        tref.empty() ? 293.15 : parse_temperature(tref, "--tref", TemperatureKind::absolute));  // "300K K"
  }
  for (const std::string& s : fix) params.fixed.push_back(parse_fix(mesh, s));
  for (const std::string& s : slide) params.sliding.push_back({boundary_tag(mesh, s, "--slide")});
  // unit: what the option's value is in (nullptr: dimensionless)
  auto material = [&](const std::vector<std::string>& values, const char* option, const char* unit,
                      double RegionElasticity::*field) {
    for (const std::string& s : values) {
      auto [k, v] = split_assignment(s, option);
      const std::int32_t id = region_id(mesh, k, option);
      RegionElasticity* r = nullptr;
      for (RegionElasticity& e : params.materials)
        if (e.region == id) r = &e;
      if (!r) r = &params.materials.emplace_back(RegionElasticity{id});
      r->*field = unit ? parse_value(v, option, unit) : parse_number(v, option);
    }
  };
  material(young, "--E", "Pa", &RegionElasticity::youngs_modulus);
  material(nu, "--nu", nullptr, &RegionElasticity::poisson_ratio);
  material(alpha, "--alpha", "1/K", &RegionElasticity::thermal_expansion);
  if (!dt.empty()) params.delta_t = parse_temperature(dt, "--dT", TemperatureKind::difference);
  if (!temperature.empty()) params.temperature = read_temperature(mesh, temperature);
  if (!tref.empty())
    params.reference_temperature = parse_temperature(tref, "--tref", TemperatureKind::absolute);
  const auto t1 = std::chrono::steady_clock::now();

  const ThermoelasticReport r = solve_thermoelastic(mesh, params);
  std::printf("%s: %zu nodes, %zu tets; linear thermoelasticity (P%d), %zu unknowns, %zu constrained nodes\n",
              files[0].c_str(), mesh.node_count(), mesh.tet_count(), params.order, r.unknowns,
              r.constrained_nodes);
  print_thermoelastic_report(mesh, r);
  std::printf(
      "solver %s, %zu nonzeros, %zu iterations, relative residual %.3g; read %.3f s, assemble %.3f s, "
      "solve %.3f s\n",
      r.solver.c_str(), r.nonzeros, r.iterations, r.relative_residual,
      std::chrono::duration<double>(t1 - t0).count(), r.assembly_seconds, r.solve_seconds);
  RunResults res = thermoelastic_results(mesh, r);
  res.model = files[0];
  res.parameters = run_parameters(sets);
  res.mesh_seconds = std::chrono::duration<double>(t_mesh - t0).count();
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // the displacement is a vector field (the indicator takes a scalar): no indicator for the stress
  const int status = print_checks(r.checks);
  if (!out.empty()) {  // before the JSON: a failed -o leaves no record saying ok
    write_mesh(mesh, out);
    std::printf("wrote %s (fields displacement [m], stress, von_mises, principal_stress [Pa])\n",
                out.c_str());
  }
  write_json(json, results_json(res));
  return status;
}

}  // namespace foxi::cli
