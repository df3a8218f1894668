// solve_thermal_calculix: the deck written, ccx run as a child process, its temperatures read back and
// reported (calculix.hpp).
#include <stdlib.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "foxi/fields.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/run_program.hpp"
#include "foxi/solver/calculix.hpp"

namespace foxi {

namespace {

namespace fs = std::filesystem;

// A work folder of its own under the temporary directory, tracked (cleanup.hpp) and removed when it goes.
struct WorkFolder {
  fs::path path;
  WorkFolder() {
    std::string tmpl = (fs::temp_directory_path() / "foxi-ccx-XXXXXX").string();
    cleanup::with_lock([&] {
      if (::mkdtemp(tmpl.data()) == nullptr) return;
      path = tmpl;
      cleanup::track(path, true);
    });
    if (path.empty()) throw SolverError("cannot create a work folder for ccx in " + tmpl);
  }
  ~WorkFolder() {
    cleanup::with_lock([&] {
      std::error_code ec;
      fs::remove_all(path, ec);
      cleanup::untrack(path);
    });
  }
  WorkFolder(const WorkFolder&) = delete;
  WorkFolder& operator=(const WorkFolder&) = delete;
};

// The last `lines` lines of a text file (ccx's output when it fails).
std::string tail_of(const fs::path& p, int lines) {
  std::string s;
  if (std::FILE* f = std::fopen(p.c_str(), "rb")) {
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
    std::fclose(f);
  }
  std::size_t pos = s.size();
  for (int k = 0; k <= lines && pos > 0; ++k) {
    const std::size_t nl = s.rfind('\n', pos - 1);
    pos = nl == std::string::npos ? 0 : nl;
  }
  return s.substr(pos);
}

}  // namespace

ThermalReport solve_thermal_calculix(Mesh& mesh, ThermalParams params, const CalculixRunOptions& options) {
  const WorkFolder work;
  write_calculix_thermal(mesh, params, work.path / "heat.inp");
  const fs::path log = work.path / "heat.log";
  const ProgressFn& progress = options.progress;
  const int status =
      run_program({"/bin/sh", "-c",
                   "cd '" + work.path.string() + "' && OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} exec " +
                       options.program + " -i heat"},
                  log.string(), {}, [&progress] { return !progress || progress("ccx", -1); });
  if (status == kProgramCancelled) throw SolverCancelled("solve cancelled while ccx ran (ccx killed)");
  const std::string tail = tail_of(log, 12);
  if (status == 127)
    throw SolverError("ccx (CalculiX) is not installed: no '" + options.program +
                      "' in PATH (Debian: apt-get install calculix-ccx)");
  if (status != 0 || tail.find("*ERROR") != std::string::npos || !fs::exists(work.path / "heat.frd"))
    throw SolverError("ccx failed (exit status " + std::to_string(status) + "); its last output:" + tail);
  const FieldSource frd = read_frd_source(work.path / "heat.frd");
  TransferParams tp;
  tp.by = MatchBy::id;
  tp.names = {"NDTEMP"};
  TransferReport rep;
  try {
    rep = transfer_fields(frd, mesh, tp);
  } catch (const FieldError& e) {
    throw SolverError(std::string("ccx's temperatures do not fit the mesh: ") + e.what());
  }
  if (rep.fields.empty() || rep.nan_values > 0)
    throw SolverError("ccx's NDTEMP leaves " + std::to_string(rep.nan_values) + " nodes without a value");
  std::vector<double> temperature = std::move(rep.fields[0].values);
  temperature.resize(mesh.node_count());   // a static run has one step: its values
  params.convection_centroid_rule = true;  // ccx's *FILM rule: the heat balance of its solution
  ThermalReport report = thermal_report(mesh, params, std::move(temperature), kFrdPrecision);
  report.solver = "ccx";
  return report;
}

}  // namespace foxi
