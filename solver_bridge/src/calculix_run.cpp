// solve_thermal_calculix and solve_thermoelastic_calculix: the deck written in a tracked work folder,
// ccx run there as a child process (cancellable), its .frd read back onto the mesh and reported by
// foxi's own report functions (calculix.hpp). The one CalculiX pipeline: foxi solve --with ccx and the
// workbench's solve panel both call these.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "foxi/fields.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/run_program.hpp"
#include "foxi/solver/calculix.hpp"

namespace foxi {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// The last `lines` lines of a text file (ccx's output when it fails).
std::string tail_of(const fs::path& p, std::size_t lines) {
  std::string s;
  if (std::FILE* f = std::fopen(p.c_str(), "rb")) {
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) s.append(buf, n);
    std::fclose(f);
  }
  std::size_t pos = s.size();
  for (std::size_t k = 0; k <= lines && pos > 0; ++k) {
    const std::size_t nl = s.rfind('\n', pos - 1);
    pos = nl == std::string::npos ? 0 : nl;
  }
  return s.substr(pos);
}

// Reads what ccx has added to its log since the last call and gives `on_output` the lines that say
// where it is (ccx's Fortran and C parts buffer their output apart, so "STEP" lines come out of
// order and are left out).
class LogFollower {
 public:
  LogFollower(fs::path log, const std::function<void(const std::string&)>& on_output)
      : log_(std::move(log)), on_output_(on_output) {}
  void scan() {
    if (!on_output_) return;
    std::FILE* f = std::fopen(log_.c_str(), "rb");
    if (!f) return;
    if (std::fseek(f, long(done_), SEEK_SET) == 0) {
      char buf[4096];
      for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) {
        pending_.append(buf, n);
        done_ += n;
      }
    }
    std::fclose(f);
    for (std::size_t nl; (nl = pending_.find('\n')) != std::string::npos; pending_.erase(0, nl + 1)) {
      const std::size_t b = pending_.find_first_not_of(' ');
      const std::size_t e = nl == 0 ? std::string::npos : pending_.find_last_not_of(" \r", nl - 1);
      const std::string line =
          b < nl && e != std::string::npos && e >= b ? pending_.substr(b, e - b + 1) : std::string();
      for (const char* key : {"increment ", "iteration ", "convergence", "no convergence", "Job finished"})
        if (line.rfind(key, 0) == 0 &&
            (key[0] != 'i' || key[1] != 'n' || line.find("attempt") != std::string::npos)) {
          on_output_(line);
          break;
        }
    }
  }

 private:
  fs::path log_;
  const std::function<void(const std::string&)>& on_output_;
  std::size_t done_ = 0;
  std::string pending_;
};

// A work folder kept or removed as the options say; `failed` marks a ccx failure or unfitting results.
struct Work {
  cleanup::TemporaryFolder folder{"foxi-ccx"};
  const CalculixRunOptions& options;
  explicit Work(const CalculixRunOptions& o) : options(o) {}
  // Throws `e` with the folder kept when the options ask for it on a failure (ccx not installed left
  // nothing of its own to look into).
  [[noreturn]] void fail(CalculixError e) {
    if (options.keep != KeepWorkFolder::never && e.kind != CalculixError::Kind::not_installed) {
      folder.keep();
      e.work_folder = folder.path();
    }
    throw e;
  }
  // The path to report on success (kept folder), or empty (removed on return).
  fs::path on_success() {
    if (options.keep != KeepWorkFolder::always) return {};
    folder.keep();
    return folder.path();
  }
};

// Runs `ccx -i JOB` in the work folder (JOB.inp written there); throws unless JOB.frd came out.
void run_ccx(Work& work, const std::string& job) {
  const fs::path& dir = work.folder.path();
  const fs::path log = dir / (job + ".log");
  const CalculixRunOptions& options = work.options;
  LogFollower follower(log, options.on_output);
  const ProgressFn& progress = options.progress;
  const int status = run_program({"/bin/sh", "-c",
                                  "cd '" + dir.string() + "' && OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} exec " +
                                      options.program + " -i " + job},
                                 log.string(), {}, [&] {
                                   follower.scan();
                                   return !progress || progress("ccx", -1);
                                 });
  if (status == kProgramCancelled) throw SolverCancelled("solve cancelled while ccx ran (ccx killed)");
  follower.scan();
  if (status == 127)
    work.fail(CalculixError(CalculixError::Kind::not_installed,
                            "ccx (CalculiX) is not installed: no '" + options.program +
                                "' in PATH (Debian: apt-get install calculix-ccx)",
                            status));
  const std::string tail = tail_of(log, options.log_tail_lines);
  if (status != 0 || tail.find("*ERROR") != std::string::npos || !fs::exists(dir / (job + ".frd")))
    work.fail(CalculixError(
        CalculixError::Kind::failed,
        "ccx failed (exit status " + std::to_string(status) + "); its last output:\n" + tail, status, tail));
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

// The nodal block `block` of `frd` (read from WORK/JOB.frd) on `mesh`'s nodes (by node id,
// coordinates checked), renamed; CalculixError (bad_results) when it does not fit the mesh or leaves
// nodes without a value.
Field ccx_field(Work& work, FieldSource frd, const Mesh& mesh, const char* block, const char* name,
                const char* unit) {
  drop_nodes_beyond(frd, mesh.node_count());
  TransferParams tp;
  tp.by = MatchBy::id;
  tp.names = {block};
  TransferReport rep;
  try {
    rep = transfer_fields(frd, mesh, tp);
  } catch (const FieldError& e) {
    work.fail(CalculixError(CalculixError::Kind::bad_results,
                            std::string("ccx's results do not fit the mesh (") + e.what() + ")"));
  }
  if (rep.fields.empty() || rep.nan_values > 0)
    work.fail(CalculixError(
        CalculixError::Kind::bad_results,
        std::string("ccx's ") + block + " has no value for " + std::to_string(rep.nan_values) + " entries"));
  Field f = std::move(rep.fields[0]);
  f.name = name;
  f.unit = unit;
  f.values.resize(mesh.node_count() * f.components);  // a static run has one step: its values
  f.step_values.clear();
  return f;
}

// The values of nodal block `block` of `frd` at the deck's C3D10 mid-edge nodes (ids after the mesh's
// `n` nodes, every one from n + 1 on, in order); CalculixError (bad_results) when the block is missing
// or leaves one out.
std::vector<double> ccx_mid_edge_values(Work& work, const FieldSource& frd, std::size_t n,
                                        const char* block) {
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
  if (!f || found != mid || std::any_of(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }))
    work.fail(CalculixError(CalculixError::Kind::bad_results,
                            std::string("ccx's ") + block + " does not give every mid-edge node a value"));
  return v;
}

// The .frd of JOB, read; a malformed one (IoError) is ccx's results not fitting.
FieldSource read_job_frd(Work& work, const std::string& job) {
  try {
    return read_frd_source(work.folder.path() / (job + ".frd"));
  } catch (const IoError& e) {
    work.fail(CalculixError(CalculixError::Kind::bad_results,
                            std::string("ccx's results cannot be read: ") + e.what()));
  }
}

// ccx's steady temperatures of `params` on `mesh` (deck heat.inp), reported and stored; a copy of them
// in `temperature` when given.
ThermalReport thermal_run(Work& work, Mesh& mesh, ThermalParams params,
                          std::vector<double>* temperature = nullptr) {
  const auto t0 = Clock::now();
  write_calculix_thermal(mesh, params, work.folder.path() / "heat.inp");
  run_ccx(work, "heat");
  Field t = ccx_field(work, read_job_frd(work, "heat"), mesh, "NDTEMP", "temperature", "K");
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  params.convection_centroid_rule = true;  // ccx's *FILM rule: the heat balance of its solution
  if (temperature) *temperature = t.values;
  ThermalReport report = thermal_report(mesh, params, std::move(t.values), kFrdPrecision);
  report.solver = "ccx";
  report.solve_seconds = seconds;
  return report;
}

// The largest von Mises stress of a nodal stress field (6 components per node).
double max_von_mises(const std::vector<double>& s) {
  double vm_max = 0;
  for (std::size_t i = 0; i + 6 <= s.size(); i += 6) {
    const double* s6 = &s[i];
    const double vm = std::sqrt(0.5 * ((s6[0] - s6[1]) * (s6[0] - s6[1]) + (s6[1] - s6[2]) * (s6[1] - s6[2]) +
                                       (s6[2] - s6[0]) * (s6[2] - s6[0])) +
                                3 * (s6[3] * s6[3] + s6[4] * s6[4] + s6[5] * s6[5]));
    vm_max = std::max(vm_max, vm);
  }
  return vm_max;
}

}  // namespace

CalculixThermal solve_thermal_calculix(Mesh& mesh, ThermalParams params, const CalculixRunOptions& options) {
  Work work(options);
  CalculixThermal out;
  out.report = thermal_run(work, mesh, std::move(params));
  out.work_folder = work.on_success();
  return out;
}

CalculixThermoelastic solve_thermoelastic_calculix(Mesh& mesh, ThermoelasticParams params,
                                                   const CalculixRunOptions& options,
                                                   const ThermalParams* temperature_from) {
  Work work(options);
  CalculixThermoelastic out;
  if (temperature_from) {
    out.thermal = thermal_run(work, mesh, *temperature_from, &params.temperature);
    params.delta_t = 0;
  }
  const auto t0 = Clock::now();
  write_calculix_thermoelastic(mesh, params, work.folder.path() / "stress.inp");
  run_ccx(work, "stress");
  const FieldSource frd = read_job_frd(work, "stress");
  Field u = ccx_field(work, frd, mesh, "DISP", "displacement", "m");
  Field sn = ccx_field(work, frd, mesh, "STRESS", "stress_nodal", "Pa");
  // foxi's report of ccx's displacements (with C3D10 the mid-edge nodes' too): stress, von Mises and
  // principal stress per tet, the maxima per region and interface, as solve_thermoelastic gives them.
  std::vector<double> solver_u = std::move(u.values);
  if (params.order == 2) {
    const std::vector<double> mid = ccx_mid_edge_values(work, frd, mesh.node_count(), "DISP");
    solver_u.insert(solver_u.end(), mid.begin(), mid.end());
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  out.report = thermoelastic_report(mesh, params, std::move(solver_u), kFrdPrecision);
  out.report.solver = "ccx";
  out.report.solve_seconds = seconds;
  out.max_nodal_von_mises = max_von_mises(sn.values);
  std::erase_if(mesh.fields, [](const Field& f) { return f.name == "stress_nodal"; });
  mesh.fields.push_back(std::move(sn));
  out.work_folder = work.on_success();
  return out;
}

}  // namespace foxi
