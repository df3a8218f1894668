// foxi export-ccx MODEL -o deck.inp and foxi solve MODEL --physics thermal --with ccx: a model's
// steady heat problem as a CalculiX deck (foxi::solver's writer), run by ccx as a child process, its
// .frd read back as foxi fields (foxi::fields) and, with --compare, checked against foxi's own solve.
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/fields.hpp"
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
    "  Mises stress. --compare also solves with foxi on the same mesh and temperatures (thermal: with\n"
    "  ccx's centroid rule for *FILM) and prints the largest difference of the temperature or the\n"
    "  displacement, relative to its largest value (about 5e-8: ccx's binary .frd holds float32; exit 4\n"
    "  above 1e-5); OUT then also holds foxi's 'temperature_foxi' or 'displacement_foxi'.\n"
    "  On a terminal ccx's increments and Newton iterations show as it runs (stderr). The work\n"
    "  folder is removed after a successful run (--keep keeps it) and kept, with ccx's\n"
    "  output shown, when ccx fails. --solver and --tol are for foxi's solver: a usage error here.\n"
    "  Exit status: 0 ok, 1 ccx failed or is not installed, 2 usage, 3 bad model or mesh, 4 a failed\n"
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

// A fresh folder under the system temp folder, recorded for removal if foxi is stopped
// (foxi/model/cleanup.hpp); removed when this goes out of scope unless `keep` was set.
struct WorkFolder {
  fs::path path;
  bool keep = false;
  WorkFolder() {
    std::string tmpl = (fs::temp_directory_path() / "foxi-ccx-XXXXXX").string();
    cleanup::with_lock([&] {
      if (::mkdtemp(tmpl.data()) == nullptr) return;
      path = tmpl;
      cleanup::track(path, true);
    });
    if (path.empty()) throw IoError(tmpl, 0, IoError::kNoOffset, "cannot create the work folder");
  }
  ~WorkFolder() {
    cleanup::untrack(path);
    std::error_code ec;
    if (!keep) fs::remove_all(path, ec);
  }
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
};

std::string read_text(const fs::path& p) {
  std::FILE* f = std::fopen(p.c_str(), "rb");
  if (!f) throw IoError(p.string(), 0, IoError::kNoOffset, "cannot open");
  std::string s;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
  std::fclose(f);
  return s;
}

// The last lines of a text file (ccx's output on failure).
std::string tail_of(const fs::path& p, std::size_t lines) {
  std::string s;
  try {
    s = read_text(p);
  } catch (const IoError&) {
    return {};
  }
  std::size_t pos = s.size();
  for (std::size_t k = 0; k <= lines && pos > 0; ++k) {
    const std::size_t nl = s.rfind('\n', pos - 1);
    pos = nl == std::string::npos ? 0 : nl;
  }
  return s.substr(pos);
}

// While `running`, prints on stderr (a terminal only) the lines of ccx's output `log` that say
// where it is: its increments, Newton iterations and their convergence, the end.
void show_ccx_progress(const fs::path& log, const std::atomic<bool>& running) {
  std::size_t done = 0;
  std::string pending;
  auto scan = [&] {
    std::FILE* f = std::fopen(log.c_str(), "rb");
    if (!f) return;
    if (std::fseek(f, long(done), SEEK_SET) == 0) {
      char buf[4096];
      for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) {
        pending.append(buf, n);
        done += n;
      }
    }
    std::fclose(f);
    for (std::size_t nl; (nl = pending.find('\n')) != std::string::npos; pending.erase(0, nl + 1)) {
      const std::size_t b = pending.find_first_not_of(' ');
      const std::size_t e = nl == 0 ? std::string::npos : pending.find_last_not_of(" \r", nl - 1);
      const std::string line =
          b < nl && e != std::string::npos && e >= b ? pending.substr(b, e - b + 1) : std::string();
      // (ccx's Fortran and C parts buffer their output apart, so "STEP" lines come out of order.)
      for (const char* key : {"increment ", "iteration ", "convergence", "no convergence", "Job finished"})
        if (line.rfind(key, 0) == 0 &&
            (key[0] != 'i' || key[1] != 'n' || line.find("attempt") != std::string::npos)) {
          std::fprintf(stderr, "ccx: %s\n", line.c_str());
          break;
        }
    }
  };
  while (running.load()) {
    scan();
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  scan();
}

// Runs ccx on WORK/JOB.inp. Throws (exit 1) when ccx is not installed; returns false, with ccx's
// output printed and the folder kept, when it fails.
bool run_ccx(WorkFolder& folder, const std::string& job) {
  const fs::path& work = folder.path;
  std::atomic<bool> running{true};
  std::thread progress;
  if (::isatty(2)) progress = std::thread(show_ccx_progress, work / (job + ".log"), std::cref(running));
  const int status =
      run_program({"/bin/sh", "-c",
                   "cd '" + work.string() + "' && OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} exec ccx -i " + job},
                  (work / (job + ".log")).string());
  running = false;
  if (progress.joinable()) progress.join();
  const std::string log_tail = tail_of(work / (job + ".log"), 15);
  if (status == 127)
    throw std::runtime_error(
        "ccx (CalculiX) is not installed: no 'ccx' in PATH (Debian: apt-get install calculix-ccx)");
  if (status != 0 || log_tail.find("*ERROR") != std::string::npos || !fs::exists(work / (job + ".frd"))) {
    std::fprintf(stderr, "foxi solve: ccx failed (exit status %d); its last output:\n%s\n", status,
                 log_tail.c_str());
    std::fprintf(stderr, "foxi solve: the deck and ccx's files are kept in %s\n", work.c_str());
    folder.keep = true;
    return false;
  }
  return true;
}

// Drops the nodes with ids beyond n (the deck's C3D10 mid-edge nodes, numbered after the mesh's) from
// a source keyed by node id, with their values; the tets go too (they would name dropped nodes).
void drop_nodes_beyond(FieldSource& s, std::size_t n) {
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < s.node_id.size(); ++i)
    if (s.node_id[i] <= n) keep.push_back(i);
  if (keep.size() == s.node_id.size()) return;
  const std::size_t old_n = s.node_id.size();
  std::vector<std::uint64_t> ids;
  std::vector<double> xyz;
  for (std::size_t i : keep) {
    ids.push_back(s.node_id[i]);
    xyz.insert(xyz.end(), s.mesh.xyz.begin() + 3 * i, s.mesh.xyz.begin() + 3 * i + 3);
  }
  for (Field& f : s.mesh.fields) {
    std::vector<double> v;
    for (std::size_t st = 0; st < f.step_count(); ++st)
      for (std::size_t i : keep)
        v.insert(v.end(), f.values.begin() + (st * old_n + i) * f.components,
                 f.values.begin() + (st * old_n + i + 1) * f.components);
    f.values = std::move(v);
  }
  s.node_id = std::move(ids);
  s.mesh.xyz = std::move(xyz);
  s.mesh.tet.clear();
  s.mesh.tet_region.clear();
}

// The nodal block `block` of WORK/JOB.frd on `mesh` (by node id, coordinates checked), renamed;
// nullopt (message printed, folder kept) when it does not fit the mesh or leaves nodes without a value.
std::optional<Field> ccx_field(WorkFolder& folder, const std::string& job, const Mesh& mesh,
                               const char* block, const char* name, const char* unit) {
  const fs::path& work = folder.path;
  FieldSource frd = read_frd_source(work / (job + ".frd"));
  drop_nodes_beyond(frd, mesh.node_count());
  TransferParams tp;
  tp.by = MatchBy::id;
  tp.names = {block};
  TransferReport rep;
  try {
    rep = transfer_fields(frd, mesh, tp);
  } catch (const FieldError& e) {
    std::fprintf(stderr, "foxi solve: ccx's results do not fit the mesh (%s); files kept in %s\n", e.what(),
                 work.c_str());
    folder.keep = true;
    return std::nullopt;
  }
  if (rep.nan_values > 0) {
    std::fprintf(stderr, "foxi solve: ccx's %s has no value for %zu entries; files kept in %s\n", block,
                 rep.nan_values, work.c_str());
    folder.keep = true;
    return std::nullopt;
  }
  Field f = std::move(rep.fields[0]);
  f.name = name;
  f.unit = unit;
  f.values.resize(mesh.node_count() * f.components);  // a static run has one step: its values
  f.step_values.clear();
  return f;
}

// The values of nodal block `block` of WORK/JOB.frd at the deck's C3D10 mid-edge nodes (ids after the
// mesh's `n` nodes, every one from n + 1 on, in order); nullopt (message printed, folder kept) when
// the block is missing or leaves one out.
std::optional<std::vector<double>> ccx_mid_edge_values(WorkFolder& folder, const std::string& job,
                                                       std::size_t n, const char* block) {
  const FieldSource frd = read_frd_source(folder.path / (job + ".frd"));
  const Field* f = nullptr;
  for (const Field& g : frd.mesh.fields)
    if (g.name == block && g.location == FieldLocation::node) f = &g;
  std::size_t mid = 0;
  for (std::uint64_t id : frd.node_id) mid += id > n;
  std::vector<double> v(f ? mid * f->components : 0, NAN);
  std::size_t found = 0;
  for (std::size_t i = 0; f && i < frd.node_id.size(); ++i) {
    const std::uint64_t id = frd.node_id[i];
    if (id <= n || id > n + mid) continue;
    ++found;
    std::copy_n(f->values.begin() + std::ptrdiff_t(i * f->components), f->components,
                v.begin() + std::ptrdiff_t((id - n - 1) * f->components));
  }
  if (!f || found != mid || std::any_of(v.begin(), v.end(), [](double x) { return !std::isfinite(x); })) {
    std::fprintf(stderr, "foxi solve: ccx's %s does not give every mid-edge node a value; files kept in %s\n",
                 block, folder.path.c_str());
    folder.keep = true;
    return std::nullopt;
  }
  return v;
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
  const WorkFolder work;
  std::string summary;
  if (stress) {
    ThermoelasticParams ep = thermoelastic_params_from_model(run.model, run.mesh);
    ep.order = order == "2" ? 2 : 1;
    write_calculix_thermoelastic(run.mesh, ep, work.path / "deck.inp");
    summary = std::string(ep.order == 2 ? "C3D10" : "C3D4") + " elements; " +
              std::to_string(ep.fixed.size()) + " displacement and " + std::to_string(ep.sliding.size()) +
              " sliding conditions";
  } else {
    const ThermalParams params = thermal_params_from_model(run.model, run.mesh);
    write_calculix_thermal(run.mesh, params, work.path / "deck.inp");
    summary = "C3D4 elements; " + std::to_string(params.fixed.size()) + " fixed, " +
              std::to_string(params.flux.size()) + " flux, " + std::to_string(params.convection.size()) +
              " convection conditions, " + std::to_string(params.sources.size()) + " sources";
  }
  DurableFile file(out);
  file.write(read_text(work.path / "deck.inp"));
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
  WorkFolder work;
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

  std::vector<double> temperature;
  if (!stress || from_thermal) {
    ThermalParams params;
    if (from_model) params = thermal_params_from_model(run.model, mesh);
    add_thermal_options(mesh, cli_conditions, params);
    if (params.fixed.empty() && params.convection.empty())
      throw UsageError("give at least one --fix or --convect: the temperature is otherwise undetermined");
    write_calculix_thermal(mesh, params, work.path / "heat.inp");
    if (!run_ccx(work, "heat")) return kExitFailure;
    std::optional<Field> t = ccx_field(work, "heat", mesh, "NDTEMP", "temperature", "K");
    if (!t) return kExitFailure;
    temperature = t->values;
    const double ccx_seconds = clock() - mesh_seconds;
    // foxi's report of ccx's temperatures (stored, with the heat flux, on the mesh): the lines and
    // the record foxi solve prints, the energy check's tolerance widened to ccx's float32 values.
    params.convection_centroid_rule = true;  // ccx's *FILM rule: the heat balance of its solution
    ThermalReport rep = thermal_report(mesh, params, temperature, kFrdPrecision);
    rep.solver = "ccx";
    rep.solve_seconds = ccx_seconds;
    std::printf("%s: %zu nodes, %zu tets; steady heat conduction by ccx (C3D4), %.3f s\n", files[0].c_str(),
                mesh.node_count(), mesh.tet_count(), ccx_seconds);
    print_thermal_report(mesh, rep);
    results = thermal_results(mesh, rep);
    if (compare && !stress) {
      Mesh own = mesh;
      solve_thermal(own, params);
      Field g = *own.find_field("temperature");
      report_compare("T", temperature, g.values, "K");
      g.name = "temperature_foxi";
      fields.push_back(std::move(g));
    }
  }
  if (stress) {
    ThermoelasticParams ep = thermoelastic_params_from_model(run.model, mesh);
    ep.order = order == "2" ? 2 : 1;
    if (from_thermal) {
      ep.temperature = temperature;
      ep.delta_t = 0;
    }
    write_calculix_thermoelastic(mesh, ep, work.path / "stress.inp");
    if (!run_ccx(work, "stress")) return kExitFailure;
    std::optional<Field> u = ccx_field(work, "stress", mesh, "DISP", "displacement", "m");
    std::optional<Field> sn = ccx_field(work, "stress", mesh, "STRESS", "stress_nodal", "Pa");
    if (!u || !sn) return kExitFailure;
    // foxi's report of ccx's displacements (with C3D10 the mid-edge nodes' too): stress, von Mises
    // and principal stress per tet, the maxima per region and interface, as foxi solve prints them.
    std::vector<double> solver_u = u->values;
    if (ep.order == 2) {
      const std::optional<std::vector<double>> mid =
          ccx_mid_edge_values(work, "stress", mesh.node_count(), "DISP");
      if (!mid) return kExitFailure;
      solver_u.insert(solver_u.end(), mid->begin(), mid->end());
    }
    const double ccx_seconds = clock() - mesh_seconds;
    ThermoelasticReport rep = thermoelastic_report(mesh, ep, std::move(solver_u));
    rep.solver = "ccx";
    rep.solve_seconds = ccx_seconds;
    double vm_max = 0;
    for (std::size_t i = 0; i < mesh.node_count(); ++i) {
      const double* s6 = &sn->values[6 * i];
      const double vm =
          std::sqrt(0.5 * ((s6[0] - s6[1]) * (s6[0] - s6[1]) + (s6[1] - s6[2]) * (s6[1] - s6[2]) +
                           (s6[2] - s6[0]) * (s6[2] - s6[0])) +
                    3 * (s6[3] * s6[3] + s6[4] * s6[4] + s6[5] * s6[5]));
      vm_max = std::max(vm_max, vm);
    }
    std::printf("%s: %zu nodes, %zu tets; linear thermoelasticity by ccx (%s), %.3f s\n", files[0].c_str(),
                mesh.node_count(), mesh.tet_count(), ep.order == 2 ? "C3D10" : "C3D4", ccx_seconds);
    print_thermoelastic_report(mesh, rep);
    std::printf(
        "largest von Mises of ccx's nodal stress (its element values averaged at the nodes) %.6g Pa\n",
        vm_max);
    RunResults elastic = thermoelastic_results(mesh, rep);
    elastic.checks.insert(elastic.checks.begin(), results.checks.begin(),
                          results.checks.end());  // the thermal run's
    results = std::move(elastic);
    if (compare) {
      Mesh own = mesh;
      solve_thermoelastic(own, ep);
      Field g = *own.find_field("displacement");
      report_compare("u", u->values, g.values, "m");
      g.name = "displacement_foxi";
      fields.push_back(std::move(*u));
      fields.push_back(std::move(g));
    } else {
      fields.push_back(std::move(*u));
    }
    fields.push_back(std::move(*sn));
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
  if (keep) {
    std::printf("ccx's work folder: %s\n", work.path.c_str());
    work.keep = true;
  }
  write_json(json, results_json(results));
  return result;
}

}  // namespace foxi::cli
