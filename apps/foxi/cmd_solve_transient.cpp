// foxi solve MODEL --physics transient ...: transient heat conduction (foxi/solver/transient.hpp);
// the temperature of every written step as OUT_NNNN.vtu with the OUT.pvd collection, and the
// junction temperatures and Zth(t) against time as OUT_junction.csv, drawn as OUT_zth.png, and the
// structure function (transient_charts.hpp).
#include <fcntl.h>
#include <sys/file.h>
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
#include "foxi/model/io_vtk.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/transient.hpp"
#include "io_util.hpp"  // model/src: io::xml_escape
#include "mesh_input.hpp"
#include "model_run.hpp"
#include "run_results.hpp"
#include "solve_options.hpp"
#include "transient_charts.hpp"

namespace foxi::cli {

namespace {

// The files of a series while they are written (the frames OUT_NNNN.vtu and the companions
// OUT_junction.csv, OUT_zth.png or OUT_tj.png, OUT_structure.csv and .png): a folder beside OUT.pvd
// that a stop (cleanup) or a failure (the destructor) removes, and commit(), which puts them and the
// .pvd in place of the series before.
class SeriesStaging {
 public:
  explicit SeriesStaging(const std::string& out) : out_(out) {
    remove_stale_temporaries(out_);  // a killed run's folder
    folder_ = out_.string() + ".foxi-tmp-" + std::to_string(::getpid()) + "-frames";
    cleanup::with_lock([&] {
      std::error_code ec;
      std::filesystem::remove_all(folder_, ec);
      if (!std::filesystem::create_directory(folder_, ec))
        throw IoError(folder_.string(), 0, IoError::kNoOffset,
                      "cannot make the folder for the series' files: " + ec.message());
      cleanup::track(folder_, true);
    });
  }
  ~SeriesStaging() {
    if (folder_.empty()) return;
    cleanup::with_lock([&] {
      std::error_code ec;
      std::filesystem::remove_all(folder_, ec);
      cleanup::untrack(folder_);
    });
  }
  SeriesStaging(const SeriesStaging&) = delete;
  SeriesStaging& operator=(const SeriesStaging&) = delete;
  const std::filesystem::path& folder() const { return folder_; }
  // Where a file of the series is written first: OUT's stem + `suffix` in the folder.
  std::string staged(const std::string& suffix) const {
    return (folder_ / (out_.stem().string() + suffix)).string();
  }

  // All with the cleanup list locked (a stop waits for the whole of it, the .pvd included: a stop in
  // between left neither series) and the folder flock()ed (two runs to one OUT commit one after the
  // other, not mixed): first each target is checked to be a plain file or absent (a folder in a
  // frame's place failed half-way); then the old OUT.pvd goes (no .pvd names a half-replaced series),
  // the old frames (OUT's stem + _NNNN.vtu, the names foxi gives a series for this OUT) and
  // companions, the new files are renamed in, and the new .pvd is written last.
  void commit(const std::string& pvd) {
    const std::string stem = out_.stem().string();
    const std::filesystem::path dir = out_.parent_path().empty() ? "." : out_.parent_path();
    const int lock_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (lock_fd >= 0) (void)::flock(lock_fd, LOCK_EX);
    try {
      cleanup::with_lock([&] {
        std::error_code ec;
        std::vector<std::string> files;
        for (std::filesystem::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec))
          files.push_back(it->path().filename().string());
        for (const std::string& f : files) {
          const auto st = std::filesystem::symlink_status(dir / f, ec);
          if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
            throw WriteError((dir / f).string(), 0, IoError::kNoOffset,
                             "is not a file; the series is not written (the one before is left as it was)");
        }
        std::filesystem::remove(out_, ec);
        const std::string prefix = stem + "_";
        std::vector<std::filesystem::path> old;
        for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
          const std::string name = it->path().filename().string();
          if (name.size() < prefix.size() + 8 || name.compare(0, prefix.size(), prefix) != 0 ||
              name.compare(name.size() - 4, 4, ".vtu") != 0)
            continue;
          const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 4);
          if (std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
            old.push_back(it->path());
        }
        for (const char* companion :
             {"_junction.csv", "_zth.png", "_tj.png", "_structure.csv", "_structure.png"})
          old.push_back(dir / (stem + companion));
        for (const auto& p : old) std::filesystem::remove(p, ec);
        for (const std::string& f : files) {
          std::filesystem::rename(folder_ / f, dir / f, ec);
          if (ec)
            throw WriteError((dir / f).string(), 0, IoError::kNoOffset,
                             "cannot move the series' file into place: " + ec.message());
        }
        DurableFile index(out_);
        index.write(pvd);
        index.commit();
        std::filesystem::remove_all(folder_, ec);
        cleanup::untrack(folder_);
        folder_.clear();
      });
    } catch (...) {
      if (lock_fd >= 0) ::close(lock_fd);
      throw;
    }
    if (lock_fd >= 0) ::close(lock_fd);
  }

 private:
  std::filesystem::path out_, folder_;
};

const char* kTransientUsage =
    "foxi solve MODEL.toml|MESH --physics transient --time T (--time-step DT | --steps N)\n"
    "                [--power REGION=step:P | REGION=pulse:P,WIDTH,PERIOD[,COUNT] | "
    "REGION=table:FILE.csv]...\n"
    "                [--scheme bdf2|euler] [--write-every K] [--initial T] [--set NAME=VALUE]...\n"
    "                [--fix TAG=T] [--convect TAG=h,Tinf] [--solver ...] [--json [FILE]] [--size-scale S]\n"
    "                [--max-tets N] -o OUT.pvd\n"
    "  Transient heat conduction with the model's thermal conditions (or --fix/--convect on a mesh),\n"
    "  its materials' conductivity, density and specific heat. The model's power loads become steps\n"
    "  at t = 0 unless --power gives that region another waveform. The start is the steady state\n"
    "  with no power (--initial T: a uniform temperature instead). Time steps are implicit: bdf2\n"
    "  (second order, default) or euler (first order); --time-step is rounded so that it divides\n"
    "  --time. A table is CSV 'time_s,power_W' (linear between rows).\n"
    "  Writes OUT_NNNN.vtu every K steps (and the last; default K = steps / 100, at least 1) with\n"
    "  OUT.pvd, and OUT_junction.csv: time, power and per powered region (a junction) its maximum\n"
    "  temperature and, for a step power, Zth(t) = (Tj(t) - Tj(0)) / P in K/W; OUT_zth.png draws\n"
    "  Zth against log time and Tj against time (OUT_tj.png, Tj alone, when no power is a step: Zth\n"
    "  is defined for a step only). With one powered region and a step, the cumulative structure\n"
    "  function (JESD51-14: Zth fitted by a time-constant spectrum, Foster -> Cauer ladder; cumulative\n"
    "  thermal capacitance against cumulative thermal resistance from the junction) goes to\n"
    "  OUT_structure.csv (stage, R, C, cumulative R, cumulative C) and OUT_structure.png. Run to the\n"
    "  steady state (--time several times the slowest time constant) for the whole heat path.";

PowerWaveform parse_waveform(const std::string& text) {
  const auto colon = text.find(':');
  const std::string kind = colon == std::string::npos ? "step" : text.substr(0, colon);
  const std::string rest = colon == std::string::npos ? text : text.substr(colon + 1);
  PowerWaveform w;
  if (kind == "step") {
    w.kind = PowerWaveform::Kind::step;
    w.power = parse_value(rest, "--power", "W");
  } else if (kind == "pulse") {
    w.kind = PowerWaveform::Kind::pulse;
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t c; (c = rest.find(',', start)) != std::string::npos; start = c + 1)
      parts.push_back(rest.substr(start, c - start));
    parts.push_back(rest.substr(start));
    if (parts.size() != 3 && parts.size() != 4)
      throw UsageError("--power REGION=pulse:P,WIDTH,PERIOD[,COUNT], not '" + text + "'");
    w.power = parse_value(parts[0], "--power", "W");
    w.width = parse_value(parts[1], "--power", "s");
    w.period = parse_value(parts[2], "--power", "s");
    if (!(w.width > 0) || !(w.width <= w.period))
      throw UsageError("--power pulse: needs 0 < WIDTH <= PERIOD, not '" + text + "'");
    if (parts.size() == 4) {
      std::int32_t n = 0;
      if (!parse_int(parts[3], n) || n < 1) throw UsageError("--power pulse: COUNT is a whole number >= 1");
      w.count = static_cast<std::size_t>(n);
    }
  } else if (kind == "table") {
    w.kind = PowerWaveform::Kind::table;
    w.table = read_power_table(rest);  // IoError naming the file and line
  } else {
    throw UsageError("--power takes REGION=step:P, pulse:P,WIDTH,PERIOD[,COUNT] or table:FILE.csv, not '" +
                     text + "'");
  }
  return w;
}

std::string csv_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

int cmd_solve_transient(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kTransientUsage);
    return kExitOk;
  }
  (void)args.option("--physics", "transient");
  const std::vector<std::string> fix = all_options(args, "--fix"), convect = all_options(args, "--convect"),
                                 power = all_options(args, "--power"), sets = all_options(args, "--set");
  const LinearSolverOptions solver_options = parse_solver_options(args);
  std::string out = args.option("-o", "");
  if (out.empty()) out = args.option("--output", "");
  const std::string time_text = args.option("--time", ""), dt_text = args.option("--time-step", ""),
                    steps_text = args.option("--steps", ""), scheme = args.option("--scheme", "bdf2"),
                    every_text = args.option("--write-every", ""), initial = args.option("--initial", "");
  JsonOutput json = json_option(args);
  const double size_scale = size_scale_option(args);
  const double max_tets = max_tets_option(args);
  const auto files = args.positional(1, 1, kTransientUsage);
  if (time_text.empty()) throw UsageError("--physics transient needs --time T (e.g. --time 10s)");
  const double end_time = parse_value(time_text, "--time", "s");
  if (!(end_time > 0)) throw UsageError("--time must be positive");
  if (dt_text.empty() == steps_text.empty()) throw UsageError("give one of --time-step DT and --steps N");
  std::size_t steps = 0;
  if (!steps_text.empty()) {
    std::int32_t n = 0;
    if (!parse_int(steps_text, n) || n < 1) throw UsageError("--steps takes a whole number >= 1");
    steps = static_cast<std::size_t>(n);
  } else {
    const double dt = parse_value(dt_text, "--time-step", "s");
    if (!(dt > 0) || dt > end_time) throw UsageError("--time-step must be in (0, --time]");
    const double n = std::ceil(end_time / dt - 1e-9);
    if (n > 1e7) throw UsageError("--time / --time-step is over 1e7 steps");
    steps = static_cast<std::size_t>(n);
  }
  if (scheme != "bdf2" && scheme != "euler")
    throw UsageError("--scheme takes bdf2 or euler, not '" + scheme + "'");
  std::size_t every = std::max<std::size_t>(1, steps / 100);
  if (!every_text.empty()) {
    std::int32_t k = 0;
    if (!parse_int(every_text, k) || k < 1) throw UsageError("--write-every takes a whole number >= 1");
    every = static_cast<std::size_t>(k);
  }
  if (out.empty() || std::filesystem::path(out).extension() != ".pvd")
    throw UsageError("--physics transient writes a series: give -o OUT.pvd");
  check_output_path(out);
  const std::string stem = out.substr(0, out.size() - 4);
  check_output_path(stem + "_000000.vtu");  // the frames' names (and their temporaries) fit too
  std::vector<std::pair<std::string, PowerWaveform>> waves;
  for (const std::string& s : power) {
    auto [k, v] = split_assignment(s, "--power");
    waves.emplace_back(k, parse_waveform(v));
  }

  const bool from_model = is_model_path(files[0]);
  if (!from_model && (!sets.empty() || size_scale != 1))
    throw UsageError("--set and --size-scale are for model files (MODEL.toml)");
  silence_text_for_json(json);
  const TextRenderer text(find_font_file());  // before the work: a missing font fails at once
  const auto t0 = std::chrono::steady_clock::now();
  MeshedModel model_run;
  if (from_model) model_run = mesh_model_for_solve(files[0], sets, "thermal", size_scale, max_tets);
  Mesh mesh = from_model ? std::move(model_run.mesh) : read_mesh(files[0]);
  require_usable(mesh, files[0], "solve");
  const auto t1 = std::chrono::steady_clock::now();

  TransientParams params;
  params.thermal.solver = solver_options;
  params.thermal.solver.progress = terminal_progress(params.thermal.solver);
  params.end_time = end_time;
  params.steps = steps;
  params.scheme = scheme == "euler" ? TimeScheme::euler : TimeScheme::bdf2;
  if (!initial.empty())
    params.initial_temperature = parse_temperature(initial, "--initial", TemperatureKind::absolute);
  std::vector<HeatSource> model_sources;
  if (from_model) {
    ThermalParams mp = thermal_params_from_model(model_run.model, mesh);
    params.thermal.fixed = mp.fixed, params.thermal.flux = mp.flux, params.thermal.convection = mp.convection;
    model_sources = mp.sources;
  }
  for (const std::string& s : fix) {
    auto [k, v] = split_assignment(s, "--fix");
    params.thermal.fixed.push_back(
        {boundary_tag(mesh, k, "--fix"), parse_temperature(v, "--fix", TemperatureKind::absolute)});
  }
  for (const std::string& s : convect) {
    auto [k, v] = split_assignment(s, "--convect");
    const auto [h, tinf] = split_pair(v, "--convect", "TAG=h,Tinf");
    params.thermal.convection.push_back({boundary_tag(mesh, k, "--convect"),
                                         parse_value(h, "--convect", "W/(m^2*K)"),
                                         parse_temperature(tinf, "--convect", TemperatureKind::absolute)});
  }
  for (auto& [k, w] : waves) params.power.push_back({region_id(mesh, k, "--power"), std::move(w)});
  // The model's loads: a step at t = 0 (W; a density times the region's volume) unless --power has
  // the region.
  for (const HeatSource& s : model_sources) {
    if (std::any_of(params.power.begin(), params.power.end(),
                    [&](const TransientPower& p) { return p.region == s.region; }))
      continue;
    double volume = 0;
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      if (mesh.tet_region[t] != s.region) continue;
      const double* p[4];
      for (int a = 0; a < 4; ++a) p[a] = &mesh.xyz[3 * std::size_t{mesh.tet[4 * t + a]}];
      double e[3][3];
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) e[a][c] = p[a + 1][c] - p[0][c];
      volume += (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                 e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                 e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
                6;
    }
    params.power.push_back({s.region, PowerWaveform::step_of(s.total ? s.value : s.value * volume)});
  }
  if (params.power.empty())
    throw UsageError("no power: give --power REGION=... (or a model with power loads)");
  for (const TransientPower& p : params.power) params.junctions.push_back(p.region);

  // Each written step goes to a folder beside OUT (OUT.foxi-tmp-PID-frames: removed on a stop or a
  // failure, swept as a stale temporary after a kill) and replaces the series of the run before only
  // when this run is done (SeriesStaging::commit): a stop left the old .pvd naming frames it had deleted, and
  // a shorter rerun left the old frames past its own.
  SeriesStaging staging(out);
  std::vector<std::pair<double, std::string>> written;  // time, the frame's name (OUT's stem + _NNNN.vtu)
  Mesh frame = mesh;
  frame.fields.clear();
  params.on_step = [&](std::size_t step, double time, std::span<const double> temperature) {
    if (step % every != 0 && step != steps) return true;
    char name[32];
    std::snprintf(name, sizeof name, "_%04zu.vtu", written.size());
    const std::string file = std::filesystem::path(stem).filename().string() + name;
    Field f{"temperature", FieldLocation::node, 1, "K", {}, {temperature.begin(), temperature.end()}};
    frame.fields = {std::move(f)};
    write_vtu(frame, staging.folder() / file);
    written.emplace_back(time, file);
    return true;
  };
  const TransientReport r = solve_transient_thermal(mesh, params);
  const auto t2 = std::chrono::steady_clock::now();

  std::printf("%s: %zu nodes, %zu tets; transient heat conduction, %zu unknowns, %zu %s steps of %.6g s\n",
              files[0].c_str(), mesh.node_count(), mesh.tet_count(), r.unknowns, steps,
              scheme == "euler" ? "backward Euler" : "BDF2", r.time_step);
  std::printf("%-24s %12s %14s %14s %14s\n", "junctions", "power W", "Tj(0) K", "Tj(end) K", "Zth(end) K/W");
  for (std::size_t j = 0; j < params.junctions.size(); ++j) {
    const TransientPower& p = params.power[j];
    const std::vector<double>& tj = r.junction_temperature[j];
    const bool step = p.power.kind == PowerWaveform::Kind::step && p.power.power != 0;
    std::printf("  %-22s %12.4g %14.6g %14.6g %14.6g\n", region_label(mesh, p.region).c_str(),
                p.power.at(end_time), tj.front(), tj.back(),
                step ? (tj.back() - tj.front()) / p.power.power : NAN);
  }
  // heat_in is the scheme's sum of dt * (heat in at each step's end): for BDF2 it differs from the
  // stored energy by O(dt) end terms (transient.hpp), so only the stored energy is printed as a figure.
  std::printf("energy: stored %.6g J (sum of rho c V dT over the run)\n", r.stored_energy);
  std::printf(
      "solver %s, %zu iterations in all, largest relative residual %.3g; setup %.3f s, steps %.3f s\n",
      r.solver.c_str(), r.iterations, r.relative_residual, r.setup_seconds, r.solve_seconds);

  // CSV, then the .pvd last: its presence means the series is whole.
  {
    std::string csv = "time_s,power_W";
    for (std::size_t j = 0; j < params.junctions.size(); ++j) {
      const std::string n = region_name(mesh, params.junctions[j]);
      csv += ",Tj[" + n + "]_K";
      if (params.power[j].power.kind == PowerWaveform::Kind::step) csv += ",Zth[" + n + "]_K/W";
    }
    csv += '\n';
    for (std::size_t i = 0; i < r.times.size(); ++i) {
      csv += csv_number(r.times[i]) + ',' + csv_number(r.power[i]);
      for (std::size_t j = 0; j < params.junctions.size(); ++j) {
        const std::vector<double>& tj = r.junction_temperature[j];
        csv += ',' + csv_number(tj[i]);
        const PowerWaveform& w = params.power[j].power;
        if (w.kind == PowerWaveform::Kind::step)
          csv += ',' + csv_number(w.power != 0 ? (tj[i] - tj[0]) / w.power : NAN);
      }
      csv += '\n';
    }
    DurableFile f(staging.staged("_junction.csv"));
    f.write(csv);
    f.commit();
  }
  std::vector<JunctionCurve> curves;
  for (std::size_t j = 0; j < params.junctions.size(); ++j) {
    const PowerWaveform& w = params.power[j].power;
    curves.push_back({region_name(mesh, params.junctions[j]),
                      w.kind == PowerWaveform::Kind::step    ? "step"
                      : w.kind == PowerWaveform::Kind::pulse ? "pulse"
                                                             : "table",
                      w.kind == PowerWaveform::Kind::step ? w.power : 0.0, r.junction_temperature[j]});
    if (params.power.size() == 1 && w.kind == PowerWaveform::Kind::step && w.power != 0)
      curves.back().moment = r.capacity_moment / (w.power * w.power);
  }
  write_transient_charts(staging.staged(""), r.times, curves, text, stem);
  {
    std::string pvd =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
    for (const auto& [time, file] : written)
      pvd += "    <DataSet timestep=\"" + csv_number(time) + "\" part=\"0\" file=\"" + io::xml_escape(file) +
             "\"/>\n";
    pvd += "  </Collection>\n</VTKFile>\n";
    staging.commit(pvd);
  }
  std::printf("wrote %s (%zu steps of temperature [K]) and %s_junction.csv\n", out.c_str(), written.size(),
              stem.c_str());

  RunResults res = thermal_results(mesh, r.final);
  res.physics = "transient";
  res.model = files[0];
  res.parameters = run_parameters(sets);
  res.checks = r.checks;
  res.status = all_passed(r.checks) ? RunStatus::ok : RunStatus::unreliable;
  for (std::size_t j = 0; j < params.junctions.size(); ++j) {
    const std::string n = region_name(mesh, params.junctions[j]);
    const std::vector<double>& tj = r.junction_temperature[j];
    res.values.push_back({"Tj_end[" + n + "]", "K", tj.back(), true});
    const PowerWaveform& w = params.power[j].power;
    if (w.kind == PowerWaveform::Kind::step && w.power != 0)
      res.values.push_back({"Zth_end[" + n + "]", "K/W", (tj.back() - tj.front()) / w.power, true});
  }
  res.values.push_back({"stored_energy", "J", r.stored_energy, false});
  res.values.push_back({"heat_in", "J", r.heat_in, false});
  // The last step's temperature: its ZZ indicator, as the steady solve prints it.
  res.error_indicator = error_indicator(mesh, "temperature");
  print_error_indicator(res.error_indicator, "temperature");
  res.mesh_seconds = std::chrono::duration<double>(t1 - t0).count();
  res.solve_seconds = std::chrono::duration<double>(t2 - t1).count();
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int status = print_checks(res.checks);
  write_json(json, results_json(res));
  return status;
}

}  // namespace foxi::cli
