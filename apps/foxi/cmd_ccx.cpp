// foxi export-ccx MODEL -o deck.inp and foxi solve MODEL --physics thermal --with ccx: a model's
// steady heat problem as a CalculiX deck (foxi::solver's writer), run by ccx as a child process, its
// .frd read back as foxi fields (foxi::solver's solve_*_calculix: the one CalculiX pipeline) and, with
// --compare, checked against foxi's own solve.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"
#include "mesh_input.hpp"
#include "model_run.hpp"
#include "run_results.hpp"
#include "signals.hpp"
#include "solve_options.hpp"

namespace foxi::cli {

namespace {

namespace fs = std::filesystem;

const char* kExportUsage =
    "foxi export-ccx MODEL.toml [--set NAME=VALUE]... [--physics thermal|thermoelastic] [--order 1|2]\n"
    "                -o DECK.inp\n"
    "  Meshes the model and writes its problem as a CalculiX deck, node i of the mesh ccx node i + 1.\n"
    "  thermal: *NODE, C3D4 elements in one ELSET per region, *CONDUCTIVITY per region, the model's\n"
    "  fixed temperatures (*BOUNDARY), heat fluxes (*DFLUX S), convection (*FILM) and sources\n"
    "  (*DFLUX BF), *NODE OUTPUT NT (ccx then writes a binary .frd, float32 values). thermoelastic:\n"
    "  C3D4 (C3D10 with --order 2), *ELASTIC and *EXPANSION per region, the model's displacement\n"
    "  conditions, its temperature_change as *INITIAL CONDITIONS and *TEMPERATURE, *NODE OUTPUT U,\n"
    "  *ELEMENT OUTPUT S. DECK is written whole or not at all.";

const char* kSolveCcxUsage =
    "foxi solve MODEL.toml|MESH --physics thermal|thermoelastic --with ccx [--set NAME=VALUE]...\n"
    "                      [--fix TAG=T] [--flux TAG=q] [--convect TAG=h,Tinf] [--power REGION=W]\n"
    "                      [--power-density REGION=W/m3] [--k REGION=k] [--theta JUNCTION:REFERENCE]\n"
    "                      [--temperature-from-thermal] [--order 1|2] [--compare] [--keep]\n"
    "                      [--json [FILE.json]] [-o OUT]\n"
    "  The problem solved by CalculiX: the deck (as foxi export-ccx writes it) is run by ccx in\n"
    "  a work folder and its results come back as foxi fields on foxi's mesh (node i = ccx node i + 1).\n"
    "  thermal: a model's conditions and loads and the thermal options of 'foxi solve --help' added to\n"
    "  them (a MESH file: those options alone; at least one --fix or --convect). The .frd's NDTEMP\n"
    "  becomes 'temperature' (K) and foxi prints what its own solve prints, computed by foxi from ccx's\n"
    "  temperatures: the maximum and where, per-region maximum and mean, heat through each boundary\n"
    "  (the P1 reactions of ccx's temperatures at fixed nodes) and its mean temperature, the energy\n"
    "  balance, thermal resistances, the error indicator; OUT also gets 'heat_flux'. The energy\n"
    "  check's tolerance takes in what ccx's float32 output can unbalance; a failed check is exit 4.\n"
    "  --json writes the record foxi solve --json writes (solver \"ccx\", its solver figures 0).\n"
    "  thermoelastic (a model file; C3D4, or C3D10 with --order 2; the model's displacement conditions\n"
    "  and temperature_change, or with --temperature-from-thermal ccx's steady temperatures of the\n"
    "  model's thermal problem):\n"
    "  DISP as 'displacement' (m), ccx's nodal STRESS (its element values averaged at the nodes) as\n"
    "  'stress_nodal' (Pa, xx yy zz xy yz xz); prints the largest |u| and where, the largest nodal von\n"
    "  Mises stress and the balance checks (the force balance's tolerance takes in ccx's float32\n"
    "  output; exit 4 on a failure). --compare also solves with foxi on the same mesh and\n"
    "  temperatures (thermal: with ccx's centroid rule for *FILM) and prints the largest difference\n"
    "  of the temperature or the displacement, relative to its largest value (about 5e-8: ccx's\n"
    "  binary .frd holds float32; exit 4 above 1e-5); OUT then also holds foxi's 'temperature_foxi'\n"
    "  or 'displacement_foxi'.\n"
    "  On a terminal ccx's increments and Newton iterations show as it runs (stderr). The work\n"
    "  folder is removed after a successful run (--keep keeps it) and kept, with ccx's\n"
    "  output shown, when ccx fails. --solver and --tol are for foxi's solver: a usage error here.\n"
    "  Exit status: 0 ok, 1 ccx failed or is not installed, 2 usage, 3 bad model or mesh, or a .frd\n"
    "  that cannot be read (its file, line and reason named) or does not fit the mesh, 4 a failed\n"
    "  check or --compare off.";

MeshedModel model_for_ccx(Args& args, const char* usage, const char* command, const std::string& physics) {
  const std::vector<std::string> sets = all_options(args, "--set");
  const auto files = args.positional(1, 1, usage);
  if (!is_model_path(files[0]))
    throw UsageError(
        "give a model file (MODEL.toml): ccx needs its conditions, which a mesh file does not hold");
  MeshedModel run = mesh_model_for_solve(files[0], sets, physics);
  require_usable(run.mesh, files[0], command);
  return run;
}

std::string read_text(const fs::path& p) {
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) throw IoError(p.string(), 0, IoError::kNoOffset, "cannot open");
  std::string s;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
  std::fclose(f);
  return s;
}

// max_i |a_i - b_i| over max_i |a_i|, and the former.
std::pair<double, double> largest_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, std::abs(a[i] - b[i]));
    scale = std::max(scale, std::abs(a[i]));
  }
  return {diff, scale > 0 ? diff / scale : diff};
}

}  // namespace

int cmd_export_ccx(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kExportUsage);
    return kExitOk;
  }
  const std::string out = args.option("-o");
  if (out.empty()) throw UsageError("give the deck: -o DECK.inp");
  check_output_path(out);
  const std::string physics = args.option("--physics", "thermal");
  if (physics != "thermal" && physics != "thermoelastic")
    throw UsageError("export-ccx --physics takes thermal or thermoelastic, not '" + physics + "'");
  const bool stress = physics == "thermoelastic";
  const std::string order = args.option("--order", "1");
  if (order != "1" && order != "2") throw UsageError("--order takes 1 or 2, not '" + order + "'");
  if (order == "2" && !stress) throw UsageError("--order 2 is for --physics thermoelastic");
  MeshedModel run = model_for_ccx(args, kExportUsage, "export-ccx",
                                  stress ? physics_name(Physics::thermal_stress) : "thermal");
  // Written in a work folder, then copied through a durable file: whole or not at all.
  const cleanup::TemporaryFolder work("foxi-ccx");
  std::string summary;
  if (stress) {
    ThermoelasticParams ep = thermoelastic_params_from_model(run.model, run.mesh);
    ep.order = order == "2" ? 2 : 1;
    write_calculix_thermoelastic(run.mesh, ep, work.path() / "deck.inp");
    summary = std::string(ep.order == 2 ? "C3D10" : "C3D4") + " elements; " +
              std::to_string(ep.fixed.size()) + " displacement and " + std::to_string(ep.sliding.size()) +
              " sliding conditions";
  } else {
    const ThermalParams params = thermal_params_from_model(run.model, run.mesh);
    write_calculix_thermal(run.mesh, params, work.path() / "deck.inp");
    summary = "C3D4 elements; " + std::to_string(params.fixed.size()) + " fixed, " +
              std::to_string(params.flux.size()) + " flux, " + std::to_string(params.convection.size()) +
              " convection conditions, " + std::to_string(params.sources.size()) + " sources";
  }
  DurableFile file(out);
  file.write(read_text(work.path() / "deck.inp"));
  file.commit();
  std::printf("wrote %s: %zu nodes, %zu tets as %s, %zu regions\n", out.c_str(), run.mesh.node_count(),
              run.mesh.tet_count(), summary.c_str(), run.mesh.regions.size());
  return kExitOk;
}

int cmd_solve_with(Args args, const std::string& physics) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kSolveCcxUsage);
    return kExitOk;
  }
  const std::string with = args.option("--with");
  if (with != "ccx") throw UsageError("--with takes ccx (CalculiX), not '" + with + "'");
  if (args.has_option("--solver") || args.has_option("--tol"))
    throw UsageError("--solver and --tol choose foxi's linear solver: not with --with ccx");
  if (physics != "thermal" && physics != "thermoelastic")
    throw UsageError("--with ccx solves --physics thermal or thermoelastic, not '" + physics + "'");
  const std::string order = args.option("--order", "1");
  if (order != "1" && order != "2") throw UsageError("--order takes 1 or 2, not '" + order + "'");
  const bool stress = physics == "thermoelastic";
  if (order == "2" && !stress) throw UsageError("--order 2 is for --physics thermoelastic");
  const bool from_thermal = args.flag("--temperature-from-thermal");
  if (from_thermal && !stress) throw UsageError("--temperature-from-thermal is for --physics thermoelastic");
  const bool compare = args.flag("--compare");
  const bool keep = args.flag("--keep");
  const std::string out = args.option("-o");
  if (!out.empty()) {
    (void)format_from_path(out);
    check_output_path(out);
  }
  JsonOutput json = json_option(args);
  const ThermalOptions cli_conditions = thermal_options(args);
  if (stress && !cli_conditions.empty())
    throw UsageError(
        "--fix, --flux, --convect, --power, --power-density, --k and --theta are for --physics thermal");
  const std::vector<std::string> sets = all_options(args, "--set");
  const auto files = args.positional(1, 1, kSolveCcxUsage);
  const bool from_model = is_model_path(files[0]);
  if (!from_model && stress)
    throw UsageError(
        "--physics thermoelastic --with ccx needs a model file (MODEL.toml): its displacement conditions");
  if (!from_model && !sets.empty()) throw UsageError("--set is for model files (MODEL.toml)");
  silence_text_for_json(json);
  const auto t0 = std::chrono::steady_clock::now();
  MeshedModel run;
  if (from_model)
    run = mesh_model_for_solve(files[0], sets, stress ? physics_name(Physics::thermal_stress) : "thermal");
  else
    run.mesh = read_mesh(files[0]);
  Mesh& mesh = run.mesh;
  require_usable(mesh, files[0], "solve");
  const double mesh_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  RunResults results;  // the record of the run (--json)
  int result = kExitOk;
  std::vector<Field> fields;  // written to OUT in this order
  const auto clock = [t0] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  auto report_compare = [&](const char* what, const std::vector<double>& ccx, const std::vector<double>& own,
                            const char* unit) {
    const auto [diff, rel] = largest_difference(ccx, own);
    std::printf(
        "compare: largest |%s_ccx - %s_foxi| %.3g %s, %.3g of the largest (%s)\n", what, what, diff, unit,
        rel, rel <= 1e-5 ? "agree to ccx's output precision" : "MORE than ccx's output precision explains");
    if (!(rel <= 1e-5)) result = kExitUnreliable;
  };
  // The run itself is foxi::solver's (calculix.hpp): the work folder kept on a failure (its path
  // printed) or with --keep, ccx's progress lines shown on a terminal.
  CalculixRunOptions ccx;
  ccx.keep = keep ? KeepWorkFolder::always : KeepWorkFolder::on_failure;
  if (::isatty(2))
    ccx.on_output = [](const std::string& line) { std::fprintf(stderr, "ccx: %s\n", line.c_str()); };
  std::filesystem::path work_folder;
  auto print_thermal = [&](const ThermalReport& rep) {
    std::printf("%s: %zu nodes, %zu tets; steady heat conduction by ccx (C3D4), %.3f s\n", files[0].c_str(),
                mesh.node_count(), mesh.tet_count(), rep.solve_seconds);
    print_thermal_report(mesh, rep);
    results = thermal_results(mesh, rep);
  };
  try {
    ThermalParams params;
    if (!stress || from_thermal) {
      if (from_model) params = thermal_params_from_model(run.model, mesh);
      add_thermal_options(mesh, cli_conditions, params);
      if (params.fixed.empty() && params.convection.empty())
        throw UsageError("give at least one --fix or --convect: the temperature is otherwise undetermined");
    }
    if (!stress) {
      const CalculixThermal c = solve_thermal_calculix(mesh, params, ccx);
      work_folder = c.work_folder;
      print_thermal(c.report);
      if (compare) {
        Mesh own = mesh;
        params.convection_centroid_rule = true;  // ccx's *FILM rule
        solve_thermal(own, params);
        Field g = *own.find_field("temperature");
        report_compare("T", mesh.find_field("temperature")->values, g.values, "K");
        g.name = "temperature_foxi";
        fields.push_back(std::move(g));
      }
    } else {
      ThermoelasticParams ep = thermoelastic_params_from_model(run.model, mesh);
      ep.order = order == "2" ? 2 : 1;
      const CalculixThermoelastic c =
          solve_thermoelastic_calculix(mesh, ep, ccx, from_thermal ? &params : nullptr);
      work_folder = c.work_folder;
      if (c.thermal) print_thermal(*c.thermal);
      std::printf("%s: %zu nodes, %zu tets; linear thermoelasticity by ccx (%s), %.3f s\n", files[0].c_str(),
                  mesh.node_count(), mesh.tet_count(), ep.order == 2 ? "C3D10" : "C3D4",
                  c.report.solve_seconds);
      print_thermoelastic_report(mesh, c.report);
      std::printf(
          "largest von Mises of ccx's nodal stress (its element values averaged at the nodes) %.6g Pa\n",
          c.max_nodal_von_mises);
      RunResults elastic = thermoelastic_results(mesh, c.report);
      elastic.checks.insert(elastic.checks.begin(), results.checks.begin(),
                            results.checks.end());  // the thermal run's
      results = std::move(elastic);
      // OUT's fields in the order of before (ccx's displacement and nodal stress last).
      fields.push_back(*mesh.find_field("displacement"));
      if (compare) {
        if (from_thermal) ep.temperature = mesh.find_field("temperature")->values, ep.delta_t = 0;
        Mesh own = mesh;
        solve_thermoelastic(own, ep);
        Field g = *own.find_field("displacement");
        report_compare("u", fields.back().values, g.values, "m");
        g.name = "displacement_foxi";
        fields.push_back(std::move(g));
      }
      fields.push_back(*mesh.find_field("stress_nodal"));
    }
  } catch (const CalculixError& e) {
    if (e.kind == CalculixError::Kind::not_installed) throw;
    if (e.kind == CalculixError::Kind::failed)
      std::fprintf(stderr, "foxi solve: ccx failed (exit status %d); its last output:\n%s\n", e.exit_status,
                   e.log_tail.c_str());
    else
      std::fprintf(stderr, "foxi solve: %s\n", e.what());
    if (!e.work_folder.empty())
      std::fprintf(stderr, "foxi solve: the deck and ccx's files are kept in %s\n", e.work_folder.c_str());
    // A .frd that cannot be read (its file, line and reason named) or does not fit the mesh is a bad
    // input file, as the same .frd given to foxi fields is; a ccx that failed is a failure.
    return e.kind == CalculixError::Kind::bad_results ? kExitBadInput : kExitFailure;
  }
  results.model = files[0];
  results.parameters = run_parameters(sets);
  results.mesh_seconds = mesh_seconds;
  results.wall_seconds = clock();
  if (!stress) {
    results.error_indicator = error_indicator(mesh, "temperature");
    print_error_indicator(results.error_indicator, "temperature");
  }
  if (print_checks(results.checks) != kExitOk) result = kExitUnreliable;
  if (result == kExitUnreliable) results.status = RunStatus::unreliable;
  if (!out.empty()) {
    for (Field& f : fields) {
      std::erase_if(mesh.fields, [&](const Field& g) { return g.name == f.name; });
      mesh.fields.push_back(std::move(f));
    }
    write_mesh(mesh, out);
    std::printf("wrote %s\n", out.c_str());
  }
  if (!work_folder.empty()) std::printf("ccx's work folder: %s\n", work_folder.c_str());
  write_json(json, results_json(results));
  return result;
}

}  // namespace foxi::cli
