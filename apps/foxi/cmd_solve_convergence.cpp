// foxi solve MODEL --convergence K [--ratio R] ...: the same solve on K meshes, each with the model's
// mesh sizes divided by R once more, and per key result the observed order and the Richardson
// extrapolation (foxi/solver/results.hpp). Each level is a `foxi solve --size-scale S` child process,
// so that a level is exactly what a user's `foxi solve` gives, and a stop kills it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "exit_codes.hpp"
#include "model_run.hpp"
#include "run_results.hpp"
#include "solve_options.hpp"

namespace foxi::cli {

int cmd_solve_convergence(Args args, const std::string& physics) {
  const std::string k_text = args.option("--convergence");
  std::int32_t levels = 0;
  if (!parse_int(k_text, levels) || levels < 2 || levels > 8)
    throw UsageError("--convergence takes a number of meshes from 2 to 8, not '" + k_text + "'");
  const std::string ratio_text = args.option("--ratio", "1.5");
  const double ratio = parse_number(ratio_text, "--ratio");
  if (!(ratio >= 1.1 && ratio <= 4))
    throw UsageError("--ratio takes a number from 1.1 to 4, not '" + ratio_text + "'");
  if (args.has_option("-o") || args.has_option("--output"))
    throw UsageError("-o is not for --convergence (it solves several meshes); solve one level without it");
  if (args.has_option("--size-scale"))
    throw UsageError("--size-scale is set by --convergence for each level");
  JsonOutput json = json_option(args);
  // What is left goes to each level as it is (the model, --set, conditions, solver options).
  std::vector<std::string> pass = args.remaining();
  std::string model;
  for (const std::string& a : pass)
    if (is_model_path(a)) model = a;
  if (model.empty())
    throw UsageError("--convergence is for model files (MODEL.toml): it meshes the model K times");
  pass.insert(pass.begin(), {"--physics", physics});
  silence_text_for_json(json);

  ScratchFolder scratch("foxi-convergence");
  std::vector<RunResults> runs;
  std::vector<double> h;
  int status = kExitOk;
  std::printf("convergence study of %s, --physics %s: %d meshes, sizes divided by %g each\n", model.c_str(),
              physics.c_str(), levels, ratio);
  for (int k = 0; k < levels; ++k) {
    std::vector<std::string> a = pass;
    char scale[32];
    std::snprintf(scale, sizeof scale, "%.17g", std::pow(ratio, -k));
    a.insert(a.end(), {"--size-scale", scale});
    const std::string n = std::to_string(k);
    // A transient level writes its series into the scratch folder: the last step only.
    if (physics == "transient") a.insert(a.end(), {"-o", (scratch / ("level" + n + ".pvd")).string()});
    if (physics == "transient" && std::find(pass.begin(), pass.end(), "--write-every") == pass.end())
      a.insert(a.end(), {"--write-every", "1000000000"});
    int exit_status = 0;
    RunResults r =
        run_solve_child(a, scratch / ("level" + n + ".json"), scratch / ("level" + n + ".log"), &exit_status);
    if (exit_status == kExitUsage) throw UsageError(r.error);
    if (r.status == RunStatus::failed) {
      std::fprintf(stderr, "foxi solve: error: level %d (size scale %s) failed: %s\n", k, scale,
                   r.error.c_str());
      return kExitFailure;
    }
    if (r.status == RunStatus::unreliable) status = kExitUnreliable;
    std::printf("  level %d: size scale %-8.4g %9zu nodes %10zu tets  %8.3f s  error indicator %.3g%s\n", k,
                std::pow(ratio, -k), r.nodes, r.tets, r.wall_seconds, r.error_indicator,
                r.status == RunStatus::unreliable ? "  UNRELIABLE (a check failed)" : "");
    std::fflush(stdout);
    h.push_back(std::cbrt(1.0 / double(r.tets)));  // a typical edge, up to the volume's factor
    runs.push_back(std::move(r));
  }
  const std::vector<ConvergenceRow> rows = convergence_table(runs, h);
  std::printf("h measured as tets^(-1/3) relative to level 0:");
  for (double x : h) std::printf(" %.4g", x / h[0]);
  std::printf("\n");
  std::printf("%-34s %-6s", "result", "unit");
  for (int k = 0; k < levels; ++k) std::printf(" %14s", ("level " + std::to_string(k)).c_str());
  std::printf(" %7s %14s %10s\n", "order", "extrapolated", "error est");
  for (const ConvergenceRow& row : rows) {
    std::printf("%-34s %-6s", row.name.c_str(), row.unit.c_str());
    for (double v : row.level_values) std::printf(" %14.7g", v);
    if (std::isfinite(row.order))
      std::printf(" %7.3g %14.7g %10.3g\n", row.order, row.extrapolated, row.error_estimate);
    else
      std::printf(" %7s %14s %10s\n", "-", "-", "-");
  }
  std::printf(
      "order: observed p of f(h) = f* + C h^p through the levels (3 levels: exactly; more: least squares;\n"
      "'-': no asymptotic range, e.g. differences that change sign, or fewer than 3 levels); extrapolated:\n"
      "Richardson's f*; error est: |finest - f*|\n");
  if (json.enabled) {
    std::string o = "{\"foxi_convergence\": 1, \"ratio\": " + json_number(ratio) + ",\n \"levels\": [\n";
    for (std::size_t k = 0; k < runs.size(); ++k) o += (k ? ",\n" : "") + results_json(runs[k]);
    o += "],\n \"h\": [";
    for (std::size_t k = 0; k < h.size(); ++k) o += (k ? ", " : "") + json_number(h[k]);
    o += "],\n \"rows\": [";
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const ConvergenceRow& row = rows[i];
      o += std::string(i ? ",\n  " : "\n  ") + "{\"name\": " + json_quoted(row.name) +
           ", \"unit\": " + json_quoted(row.unit) + ", \"values\": [";
      for (std::size_t k = 0; k < row.level_values.size(); ++k)
        o += (k ? ", " : "") + json_number(row.level_values[k]);
      o += "], \"order\": " + json_number(row.order) +
           ", \"extrapolated\": " + json_number(row.extrapolated) +
           ", \"error_estimate\": " + json_number(row.error_estimate) + "}";
    }
    o += "]}\n";
    write_json(json, o);
  }
  return status;
}

}  // namespace foxi::cli
