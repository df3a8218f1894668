// foxi sweep MODEL --vary NAME=LO:HI:N [--vary ...] --physics P [--jobs N] -o sweep.csv [--plot sweep.png]
// [--json [FILE]]: the model solved at every combination of parameter values, one CSV row per run, and
// the key results drawn against the first varied parameter.
//
// Each run is a `foxi solve MODEL --set NAME=VALUE ... --json` child process (its record on stdout, into
// a scratch file): runs are isolated (a crash or an exhausted memory is that run's failed row, not the
// sweep's end), run in parallel up to --jobs, longest predicted first (RunOrder), and a stop (SIGINT/SIGTERM)
// kills them (signals.hpp) and removes the scratch folder; the table is written once, durably, at the end, so
// an interrupted sweep leaves no partial CSV.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/sweep_values.hpp"
#include "foxi/model/units.hpp"
#include "foxi/viz/chart.hpp"
#include "foxi/viz/png.hpp"
#include "model_run.hpp"
#include "run_order.hpp"
#include "run_results.hpp"
#include "solve_options.hpp"

namespace foxi::cli {

namespace {

const char* kSweepUsage =
    "foxi sweep MODEL.toml --vary NAME=LO:HI:N [--vary ...] [--physics thermal|electrostatic|current|\n"
    "           thermoelastic|transient] [--jobs N] -o SWEEP.csv [--plot SWEEP.png] [--json [FILE.json]]\n"
    "           [--set NAME=VALUE]...\n"
    "           [--theta J:R]... [--solver S] [--tol REL] [--max-tets N] [--threads N]\n"
    "           [-- FOXI SOLVE OPTIONS...]\n"
    "  Solves the model at every combination of the varied parameters (a grid: the product of the\n"
    "  --vary lists) and writes one CSV row per run: the parameters (as given and in SI), status (ok,\n"
    "  unreliable: a balance check failed, failed: no result), mesh size, times, the ZZ error\n"
    "  indicator, the key results (max and mean temperature per part and theta values for thermal,\n"
    "  R and the conductance matrix for current, the capacitance matrix for electrostatic, max von\n"
    "  Mises per part for thermoelastic, the junction temperature at the end and Zth(end) (theta_JA once\n"
    "  the run reaches the steady state) per powered region for transient, whose --time and --steps go\n"
    "  after '--'; a column per result, its unit in the header), the checks\n"
    "  that failed and the error of a failed run. A failed run does not stop the sweep.\n"
    "  --vary NAME=LO:HI:N  N values from LO to HI evenly, in LO's unit (die_w=2mm:8mm:7); or a list\n"
    "                       NAME=V1,V2,... (die_w=2mm,3mm,5mm). NAME is one of the model's [parameters].\n"
    "  --jobs N             runs at once (default: the cores); each run's solver gets cores / N\n"
    "                       threads unless --threads says otherwise\n"
    "  --plot SWEEP.png     one chart per key result (the CSV's result columns, in their order; two\n"
    "                       charts to a row, each 600 x 380 pixels) against the first varied\n"
    "                       parameter, in its unit; with more --vary, one series per combination of\n"
    "                       the others; a failed run's point is left out\n"
    "  --json [FILE.json]   every run's whole record (foxi solve --json) as one JSON array, on stdout\n"
    "                       or in FILE\n"
    "  --set, --theta, --solver, --tol, --max-tets, --threads go to every run as in foxi solve, and\n"
    "  so does everything after '--' (e.g. -- --temperature-from-thermal, -- --k die=150).\n"
    "  A progress line per finished run on stderr. Exit status 0 when every run is ok, 4 when one is\n"
    "  unreliable, 1 when one failed; a stop (Ctrl-C) writes nothing (130/143).";

// A varied parameter: its name and values (foxi/model/sweep_values.hpp).
struct Varied : SweepValues {
  std::string name;
};

Varied parse_vary(const std::string& spec) {
  const auto [name, range] = split_assignment(spec, "--vary");
  Varied v;
  try {
    static_cast<SweepValues&>(v) = parse_sweep_values(range);
  } catch (const ExpressionError& e) {
    throw UsageError("--vary " + name + ": " + e.what());
  }
  v.name = name;
  return v;
}

// A CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
std::string csv(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string number(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

constexpr int kPlotWidth = 600, kPlotHeight = 380;  // one chart (the usage text says so)

// The sweep's charts: one per result column, against the first varied parameter.
void write_sweep_plot(const std::string& path, const TextRenderer& text, const std::vector<Varied>& varied,
                      const std::vector<std::pair<std::string, std::string>>& columns,
                      const std::vector<RunResults>& results,
                      const std::function<std::vector<std::size_t>(std::size_t)>& combination) {
  const std::size_t charts = std::max<std::size_t>(1, columns.size()), across = charts > 1 ? 2 : 1;
  const std::size_t rows = (charts + across - 1) / across;
  Framebuffer fb(int(across) * kPlotWidth, int(rows) * kPlotHeight);
  const Varied& x = varied.front();
  // The other parameters' combinations: one series each (one unnamed series for a single --vary).
  std::size_t others = 1;
  for (std::size_t i = 1; i < varied.size(); ++i) others *= varied[i].texts.size();
  for (std::size_t k = 0; k < charts; ++k) {
    Chart c;
    if (!columns.empty()) {
      c.title = columns[k].first;
      c.y = {columns[k].first, columns[k].second};
    } else {
      c.title = "no results";
    }
    c.x = {x.name, x.unit};
    c.series.resize(others);
    for (std::size_t run = 0; run < results.size(); ++run) {
      const auto idx = combination(run);
      std::size_t series = 0;
      std::string name;
      for (std::size_t i = 1; i < varied.size(); ++i) {
        series = series * varied[i].texts.size() + idx[i];
        name += (i > 1 ? ", " : "") + varied[i].name + "=" + varied[i].texts[idx[i]];
      }
      ChartSeries& s = c.series[series];
      s.name = name;
      s.markers = true;
      s.x.push_back(x.si[idx[0]] / x.unit_si);
      const ResultValue* v = columns.empty() ? nullptr : results[run].find(columns[k].first);
      s.y.push_back(v != nullptr && results[run].status != RunStatus::failed ? v->value : NAN);
    }
    const int x0 = int(k % across) * kPlotWidth, y0 = int(k / across) * kPlotHeight;
    draw_chart(fb, text, c, PixelRect{x0, y0, x0 + kPlotWidth - 1, y0 + kPlotHeight - 1});
  }
  write_png(path, fb);
}

}  // namespace

int cmd_sweep(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kSweepUsage);
    return kExitOk;
  }
  // after "--": options for every run's foxi solve as they are (--temperature-from-thermal, --k ...)
  const std::vector<std::string> solve_options = args.take_after("--");
  for (const std::string& o : solve_options)
    if (o == "-o" || o == "--output" || o == "--json" || o.rfind("--json=", 0) == 0)
      throw UsageError("'" + o +
                       "' after '--': the sweep writes each run's output and record itself (-o "
                       "SWEEP.csv, --json goes before '--')");
  const std::string physics = args.option("--physics", "thermal");
  if (physics != "thermal" && physics != "electrostatic" && physics != "current" &&
      physics != "thermoelastic" && physics != "transient")
    throw UsageError("--physics takes thermal, electrostatic, current, thermoelastic or transient, not '" +
                     physics + "'");
  if (physics == "transient" &&
      std::find(solve_options.begin(), solve_options.end(), "--time") == solve_options.end())
    throw UsageError(
        "--physics transient: give the runs' time stepping after '--' (-- --time 10s --steps 100)");
  std::vector<Varied> varied;
  for (const std::string& s : all_options(args, "--vary")) varied.push_back(parse_vary(s));
  if (varied.empty())
    throw UsageError("foxi sweep needs at least one --vary NAME=LO:HI:N\nusage: " + std::string(kSweepUsage));
  for (std::size_t i = 0; i < varied.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (varied[i].name == varied[j].name) throw UsageError("--vary " + varied[i].name + " is given twice");
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::string jobs_text = args.option("--jobs", std::to_string(cores));
  std::int32_t jobs = 0;
  if (!parse_int(jobs_text, jobs) || jobs < 1 || jobs > 1024)
    throw UsageError("--jobs takes a whole number from 1 to 1024, not '" + jobs_text + "'");
  std::string out = args.option("-o", "");
  if (out.empty()) out = args.option("--output", "");
  if (out.empty()) throw UsageError("foxi sweep needs -o SWEEP.csv");
  const std::string plot = args.option("--plot", "");
  if (!plot.empty() && std::filesystem::path(plot).extension() != ".png")
    throw UsageError("--plot writes a PNG picture: give --plot FILE.png, not '" + plot + "'");
  JsonOutput json = json_option(args);
  // passed to every run as given
  std::vector<std::string> pass;
  const std::vector<std::string> sets = all_options(args, "--set");
  for (const std::string& s : sets) pass.insert(pass.end(), {"--set", s});
  // A varied parameter also --set (before or after '--') overrode every run's value in silence: the
  // rows said a=5mm and a=6mm and were both a=7mm (an outside probe).
  std::vector<std::string> given = pass;
  given.insert(given.end(), solve_options.begin(), solve_options.end());
  for (std::size_t i = 0; i + 1 < given.size(); ++i) {
    if (given[i] != "--set") continue;
    const std::string name = given[i + 1].substr(0, given[i + 1].find('='));
    for (const Varied& v : varied)
      if (v.name == name)
        throw UsageError("--set " + given[i + 1] + ": " + name +
                         " is varied by --vary (a run's --set would override it)");
  }
  const std::vector<std::string> theta = all_options(args, "--theta");
  if (!theta.empty() && physics != "thermal") throw UsageError("--theta is for --physics thermal");
  for (const std::string& s : theta) pass.insert(pass.end(), {"--theta", s});
  for (const char* o : {"--solver", "--tol", "--max-tets", "--threads"})
    if (args.has_option(o)) pass.insert(pass.end(), {o, args.option(o)});
  pass.insert(pass.end(), solve_options.begin(), solve_options.end());
  // Each run's solver threads share the cores with the other runs (unless --threads says otherwise).
  if (std::find(pass.begin(), pass.end(), "--threads") == pass.end())
    pass.insert(pass.end(), {"--threads", std::to_string(std::max(1u, cores / unsigned(jobs)))});
  const auto files = args.positional(1, 1, kSweepUsage);
  const std::string& model = files[0];
  if (!is_model_path(model))
    throw UsageError("foxi sweep takes a model file (MODEL.toml), not '" + model + "'");
  check_output_path(out);
  if (!plot.empty()) check_output_path(plot);
  // Before the runs: a missing font fails at once.
  std::unique_ptr<TextRenderer> text;
  if (!plot.empty()) text = std::make_unique<TextRenderer>(find_font_file());

  // Every combination, the last --vary fastest.
  std::size_t total = 1;
  for (const Varied& v : varied) total *= v.texts.size();
  if (total > 100000) throw UsageError("the sweep has " + std::to_string(total) + " runs; at most 100000");
  auto combination = [&](std::size_t run) {
    std::vector<std::size_t> idx(varied.size());
    for (std::size_t i = varied.size(); i-- > 0;) {
      idx[i] = run % varied[i].texts.size();
      run /= varied[i].texts.size();
    }
    return idx;
  };
  auto run_sets = [&](std::size_t run) {
    std::vector<std::string> s = sets;
    const auto idx = combination(run);
    for (std::size_t i = 0; i < varied.size(); ++i)
      s.push_back(varied[i].name + "=" + varied[i].texts[idx[i]]);
    return s;
  };
  // The parameters and the model are checked once here: a mistyped name or unit, or a broken model,
  // fails before any run (no value of that parameter loads). A value that only some geometry refuses
  // (a die of 1e-30 mm) is that run's failure, a row with its error, and the sweep goes on.
  for (const Varied& v : varied) {
    for (std::size_t i = 0; i < v.texts.size(); ++i) {
      std::vector<std::string> one = sets;
      one.push_back(v.name + "=" + v.texts[i]);
      try {
        (void)load_model(model, one, "--set");
        break;
      } catch (const std::exception&) {
        if (i + 1 == v.texts.size()) {  // none loads: the error of the first value, as it was
          one.back() = v.name + "=" + v.texts.front();
          (void)load_model(model, one, "--set");
          throw;
        }
      }
    }
  }
  silence_text_for_json(json);

  ScratchFolder scratch("foxi-sweep");
  std::vector<RunResults> results(total);
  std::size_t finished = 0;
  std::mutex print;  // guards the progress lines and the scheduler below
  RunOrder order(total, [&](std::size_t run) { return combination(run); });
  const auto t0 = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  std::fprintf(stderr, "foxi sweep: %zu runs of %s --physics %s, %d at a time\n", total, model.c_str(),
               physics.c_str(), std::min<int>(jobs, int(total)));
  // Runs refused for their options (exit 2: --tol 1, an unknown region in --theta, a bad option after
  // '--'): when every run is, the sweep is a usage error with their reason and no CSV (it made a CSV
  // of failed rows, exit 0); when only some are (a --theta interface that only some geometry has),
  // they are failed rows.
  std::size_t refused = 0;
  std::string usage_error;
  auto worker = [&] {
    for (std::size_t run; (run = [&] {
                            std::lock_guard lock(print);
                            return order.next(seconds());
                          }()) < total;) {
      std::vector<std::string> a{model, "--physics", physics};
      for (const std::string& s : run_sets(run)) a.insert(a.end(), {"--set", s});
      // --set of a varied name replaces the sweep's own (the later --set wins in load_model)
      a.insert(a.end(), pass.begin(), pass.end());
      const std::string n = std::to_string(run);
      // A transient run writes its series into the scratch folder: the last step only.
      if (physics == "transient") a.insert(a.end(), {"-o", (scratch / ("run" + n + ".pvd")).string()});
      if (physics == "transient" && std::find(pass.begin(), pass.end(), "--write-every") == pass.end())
        a.insert(a.end(), {"--write-every", "1000000000"});
      const auto start = std::chrono::steady_clock::now();
      int exit_status = 0;
      RunResults r =
          run_solve_child(a, scratch / ("run" + n + ".json"), scratch / ("run" + n + ".log"), &exit_status);
      if (exit_status == kExitUsage) {
        std::lock_guard lock(print);
        if (refused++ == 0) usage_error = r.error;
      }
      if (r.status == RunStatus::failed)
        r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::string label;
      const auto idx = combination(run);
      for (std::size_t i = 0; i < varied.size(); ++i)
        label += (i ? " " : "") + varied[i].name + "=" + varied[i].texts[idx[i]];
      std::string first;
      for (const ResultValue& v : r.values)
        if (v.key) {
          first = ", " + v.name + " " + number(v.value) + " " + v.unit;
          break;
        }
      std::lock_guard lock(print);
      order.finished(run, seconds());
      ++finished;
      if (r.status == RunStatus::failed)
        std::fprintf(stderr, "foxi sweep: [%zu/%zu] %s: FAILED after %.2f s: %s\n", finished, total,
                     label.c_str(), r.wall_seconds, r.error.c_str());
      else
        std::fprintf(stderr, "foxi sweep: [%zu/%zu] %s: %s, %zu tets, %.2f s%s\n", finished, total,
                     label.c_str(), run_status_name(r.status), r.tets, r.wall_seconds, first.c_str());
      results[run] = std::move(r);
    }
  };
  std::vector<std::thread> threads;
  for (int i = 0; i < std::min<int>(jobs, int(total)); ++i) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  if (refused == total) throw UsageError("every run's foxi solve refused its options: " + usage_error);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Columns: the key results of every run, in the order first met.
  std::vector<std::pair<std::string, std::string>> columns;  // name, unit
  for (const RunResults& r : results)
    for (const ResultValue& v : r.values)
      if (v.key &&
          std::none_of(columns.begin(), columns.end(), [&](const auto& c) { return c.first == v.name; }))
        columns.emplace_back(v.name, v.unit);
  std::string table = "run";
  for (const Varied& v : varied)
    table += "," + csv(v.name) + "," + csv(v.name + " (" + (v.si_unit.empty() ? "1" : v.si_unit) + ")");
  table += ",status,nodes,tets,mesh_s,solve_s,wall_s,error_indicator";
  for (const auto& [name, unit] : columns) table += "," + csv(unit.empty() ? name : name + " (" + unit + ")");
  table += ",failed_checks,error\n";
  std::size_t ok = 0, unreliable = 0, failed = 0;
  for (std::size_t run = 0; run < total; ++run) {
    const RunResults& r = results[run];
    (r.status == RunStatus::ok ? ok : r.status == RunStatus::unreliable ? unreliable : failed)++;
    table += std::to_string(run + 1);
    const auto idx = combination(run);
    for (std::size_t i = 0; i < varied.size(); ++i)
      table += "," + csv(varied[i].texts[idx[i]]) + "," + number(varied[i].si[idx[i]]);
    table += std::string(",") + run_status_name(r.status);
    const bool has = r.status != RunStatus::failed;
    table += "," + (has ? std::to_string(r.nodes) : "") + "," + (has ? std::to_string(r.tets) : "");
    table += "," + (has ? number(r.mesh_seconds) : "") + "," + (has ? number(r.solve_seconds) : "") + "," +
             number(r.wall_seconds) + "," + (has ? number(r.error_indicator) : "");
    for (const auto& c : columns) {
      const ResultValue* v = r.find(c.first);
      table += "," + (v ? number(v->value) : "");
    }
    std::string bad;
    for (const BalanceCheck& c : r.checks)
      if (!c.passed)
        bad += (bad.empty() ? "" : "; ") + c.name + " " + number(c.figure) + " > " + number(c.tolerance);
    table += "," + csv(bad) + "," + csv(r.error) + "\n";
  }
  DurableFile file(out);
  file.write(table);
  file.commit();
  std::fprintf(stderr, "foxi sweep: %zu runs in %.2f s (%zu ok, %zu unreliable, %zu failed); wrote %s\n",
               total, wall, ok, unreliable, failed, out.c_str());
  if (text) {
    write_sweep_plot(plot, *text, varied, columns, results, combination);
    std::fprintf(stderr, "foxi sweep: wrote %s (%zu chart%s against %s)\n", plot.c_str(),
                 std::max<std::size_t>(1, columns.size()), columns.size() == 1 ? "" : "s",
                 varied.front().name.c_str());
  }
  if (json.enabled) {
    std::string o = "[\n";
    for (std::size_t run = 0; run < total; ++run) {
      RunResults r = results[run];
      if (r.status == RunStatus::failed) {
        r.model = model;
        r.physics = physics;
        r.parameters = run_parameters(run_sets(run));
      }
      o += (run ? ",\n" : "") + results_json(r);
    }
    o += "]\n";
    write_json(json, o);
  }
  return failed ? kExitFailure : unreliable ? kExitUnreliable : kExitOk;
}

}  // namespace foxi::cli
