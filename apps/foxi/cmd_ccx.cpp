// foxi export-ccx MODEL -o deck.inp and foxi solve MODEL --physics thermal --with ccx: a model's
// steady heat problem as a CalculiX deck (foxi::solver's writer), run by ccx as a child process, its
// .frd read back as foxi fields (foxi::fields) and, with --compare, checked against foxi's own solve.
#include <stdlib.h>
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
#include "foxi/fields.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/solver/calculix.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/thermal.hpp"
#include "mesh_input.hpp"
#include "model_run.hpp"
#include "signals.hpp"
#include "solve_options.hpp"

namespace foxi::cli {

namespace {

namespace fs = std::filesystem;

const char* kExportUsage =
    "foxi export-ccx MODEL.toml [--set NAME=VALUE]... [--physics thermal] -o DECK.inp\n"
    "  Meshes the model and writes its steady heat problem as a CalculiX deck: *NODE, C3D4 elements\n"
    "  in one ELSET per region, *CONDUCTIVITY per region, the model's fixed temperatures (*BOUNDARY),\n"
    "  heat fluxes (*DFLUX S), convection (*FILM) and sources (*DFLUX BF), *NODE FILE NT. Node i of the\n"
    "  mesh is ccx node i + 1. DECK is written whole or not at all. (thermoelastic: not yet.)";

const char* kSolveCcxUsage =
    "foxi solve MODEL.toml --physics thermal --with ccx [--set NAME=VALUE]... [--compare] [--keep]\n"
    "                      [-o OUT]\n"
    "  The model's steady heat problem solved by CalculiX: the deck (as foxi export-ccx writes it) is\n"
    "  run by ccx in a work folder; its temperatures (the .frd's NDTEMP) come back as the field\n"
    "  'temperature' (K) on foxi's mesh. Prints the maximum temperature and where, and each region's\n"
    "  maximum. --compare also solves with foxi (with ccx's centroid rule for *FILM) and prints the\n"
    "  largest difference, relative to the largest temperature (about 1e-6: ccx's .frd prints 6\n"
    "  digits; exit 4 above 1e-5). OUT gets 'temperature' and, with --compare, 'temperature_foxi'.\n"
    "  The work folder is removed after a successful run (--keep keeps it) and kept, with ccx's\n"
    "  output shown, when ccx fails. --solver and --tol are for foxi's solver: a usage error here.\n"
    "  Exit status: 0 ok, 1 ccx failed or is not installed, 2 usage, 3 bad model, 4 --compare off.";

MeshedModel model_for_ccx(Args& args, const char* usage, const char* command) {
  const std::vector<std::string> sets = all_options(args, "--set");
  const std::string physics = args.option("--physics", "thermal");
  if (physics != "thermal")
    throw UsageError(std::string(command) + " --physics takes thermal (thermoelastic with ccx: not yet)");
  const auto files = args.positional(1, 1, usage);
  if (!is_model_path(files[0]))
    throw UsageError("give a model file (MODEL.toml): ccx needs its conditions, which a mesh file does not hold");
  MeshedModel run = mesh_model_for_solve(files[0], sets, "thermal");
  require_usable(run.mesh, files[0], command);
  return run;
}

// A fresh folder under the system temp folder.
fs::path make_work_folder() {
  std::string tmpl = (fs::temp_directory_path() / "foxi-ccx-XXXXXX").string();
  if (::mkdtemp(tmpl.data()) == nullptr) throw IoError(tmpl, 0, IoError::kNoOffset, "cannot create the work folder");
  return tmpl;
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

}  // namespace

int cmd_export_ccx(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kExportUsage);
    return kExitOk;
  }
  const std::string out = args.option("-o");
  if (out.empty()) throw UsageError("give the deck: -o DECK.inp");
  check_output_path(out);
  MeshedModel run = model_for_ccx(args, kExportUsage, "export-ccx");
  const ThermalParams params = thermal_params_from_model(run.model, run.mesh);
  // Written beside nothing of the user's, then copied through a durable file: whole or not at all.
  const fs::path work = make_work_folder();
  try {
    write_calculix_thermal(run.mesh, params, work / "deck.inp");
    DurableFile file(out);
    file.write(read_text(work / "deck.inp"));
    file.commit();
  } catch (...) {
    std::error_code ec;
    fs::remove_all(work, ec);
    throw;
  }
  std::error_code ec;
  fs::remove_all(work, ec);
  std::printf("wrote %s: %zu nodes, %zu C3D4 elements, %zu regions; %zu fixed, %zu flux, %zu convection "
              "conditions, %zu sources\n",
              out.c_str(), run.mesh.node_count(), run.mesh.tet_count(), run.mesh.regions.size(), params.fixed.size(),
              params.flux.size(), params.convection.size(), params.sources.size());
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
  if (physics != "thermal") throw UsageError("--with ccx solves --physics thermal (thermoelastic: not yet)");
  const bool compare = args.flag("--compare");
  const bool keep = args.flag("--keep");
  const std::string out = args.option("-o");
  if (!out.empty()) {
    (void)format_from_path(out);
    check_output_path(out);
  }
  MeshedModel run = model_for_ccx(args, kSolveCcxUsage, "solve");
  Mesh& mesh = run.mesh;
  ThermalParams params = thermal_params_from_model(run.model, mesh);

  const fs::path work = make_work_folder();
  const auto t0 = std::chrono::steady_clock::now();
  write_calculix_thermal(mesh, params, work / "heat.inp");
  const int status = run_program({"/bin/sh", "-c", "cd '" + work.string() + "' && OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} exec ccx -i heat"},
                                 (work / "ccx.log").string());
  const auto t1 = std::chrono::steady_clock::now();
  const std::string log_tail = tail_of(work / "ccx.log", 15);
  const bool ccx_error = log_tail.find("*ERROR") != std::string::npos;
  if (status == 127) {
    fs::remove_all(work);
    throw std::runtime_error("ccx (CalculiX) is not installed: no 'ccx' in PATH (Debian: apt-get install calculix-ccx)");
  }
  if (status != 0 || ccx_error || !fs::exists(work / "heat.frd")) {
    std::fprintf(stderr, "foxi solve: ccx failed (exit status %d); its last output:\n%s\n", status, log_tail.c_str());
    std::fprintf(stderr, "foxi solve: the deck and ccx's files are kept in %s\n", work.c_str());
    return kExitFailure;
  }
  const FieldSource frd = read_frd_source(work / "heat.frd");
  TransferParams tp;
  tp.by = MatchBy::id;
  tp.names = {"NDTEMP"};
  TransferReport rep;
  try {
    rep = transfer_fields(frd, mesh, tp);
  } catch (const FieldError& e) {
    std::fprintf(stderr, "foxi solve: ccx's results do not fit the mesh (%s); files kept in %s\n", e.what(), work.c_str());
    return kExitFailure;
  }
  Field t = std::move(rep.fields[0]);
  t.name = "temperature";
  t.unit = "K";
  t.step_values.clear();
  t.values.resize(mesh.node_count());  // the one step of a steady run
  if (rep.nan_values > 0) {
    std::fprintf(stderr, "foxi solve: ccx gave no temperature for %zu nodes; files kept in %s\n", rep.nan_values, work.c_str());
    return kExitUnreliable;
  }
  std::size_t arg = 0;
  for (std::size_t i = 0; i < t.values.size(); ++i)
    if (t.values[i] > t.values[arg]) arg = i;
  std::printf("ccx: %zu nodes, %zu C3D4 elements, %.3f s; max temperature %.6g K at (%.6g, %.6g, %.6g) m\n",
              mesh.node_count(), mesh.tet_count(), std::chrono::duration<double>(t1 - t0).count(), t.values[arg],
              mesh.xyz[3 * arg], mesh.xyz[3 * arg + 1], mesh.xyz[3 * arg + 2]);
  for (const Region& r : mesh.regions) {
    double hi = -INFINITY;
    for (std::size_t e = 0; e < mesh.tet_count(); ++e)
      if (mesh.region_of(e) == r.id)
        for (int j = 0; j < 4; ++j) hi = std::max(hi, t.values[mesh.tet[4 * e + j]]);
    if (std::isfinite(hi)) std::printf("  region %-16s max %.6g K\n", region_label(mesh, r.id).c_str(), hi);
  }
  int result = kExitOk;
  mesh.fields.erase(std::remove_if(mesh.fields.begin(), mesh.fields.end(),
                                   [](const Field& f) { return f.name == "temperature" || f.name == "temperature_foxi"; }),
                    mesh.fields.end());
  if (compare) {
    Mesh own = mesh;
    params.convection_centroid_rule = true;  // ccx's *FILM rule, so that the two agree to its print precision
    solve_thermal(own, params);
    const Field* f = own.find_field("temperature");
    double diff = 0, scale = 0;
    for (std::size_t i = 0; i < t.values.size(); ++i) {
      diff = std::max(diff, std::abs(f->values[i] - t.values[i]));
      scale = std::max(scale, std::abs(t.values[i]));
    }
    const double rel = diff / scale;
    std::printf("compare: largest |T_ccx - T_foxi| %.3g K, %.3g of the largest temperature (%s)\n", diff, rel,
                rel <= 1e-5 ? "agree to ccx's output precision" : "MORE than ccx's output precision explains");
    Field g = *f;
    g.name = "temperature_foxi";
    mesh.fields.push_back(std::move(g));
    if (!(rel <= 1e-5)) result = kExitUnreliable;
  }
  mesh.fields.insert(mesh.fields.begin(), std::move(t));
  if (!out.empty()) {
    write_mesh(mesh, out);
    std::printf("wrote %s\n", out.c_str());
  }
  if (keep) {
    std::printf("ccx's work folder: %s\n", work.c_str());
  } else {
    std::error_code ec;
    fs::remove_all(work, ec);
  }
  return result;
}

}  // namespace foxi::cli
