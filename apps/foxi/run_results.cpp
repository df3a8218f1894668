// The results record in the program (run_results.hpp).
#include "run_results.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "foxi/mesher/size_field.hpp"
#include "foxi/model/durable_file.hpp"
#include "signals.hpp"

namespace foxi::cli {

JsonOutput json_option(Args& args) {
  JsonOutput j;
  j.enabled = args.flag_with_file("--json", ".json", j.file);
  if (!j.file.empty()) check_output_path(j.file);
  return j;
}

void silence_text_for_json(JsonOutput& json) {
  if (!json.enabled || !json.file.empty()) return;
  std::fflush(stdout);
  json.stdout_fd = ::dup(1);
  const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (json.stdout_fd < 0 || null < 0) throw std::runtime_error("cannot redirect stdout for --json");
  ::dup2(null, 1);
  ::close(null);
}

void write_json(const JsonOutput& json, const std::string& text) {
  if (!json.enabled) return;
  if (!json.file.empty()) {
    DurableFile f(json.file);
    f.write(text);
    f.commit();
    return;
  }
  std::fflush(stdout);
  const int fd = json.stdout_fd >= 0 ? json.stdout_fd : 1;
  for (std::size_t at = 0; at < text.size();) {
    const ssize_t n = ::write(fd, text.data() + at, text.size() - at);
    if (n <= 0) throw std::runtime_error("cannot write the JSON to stdout");
    at += std::size_t(n);
  }
}

std::vector<RunParameter> run_parameters(std::span<const std::string> sets) {
  std::vector<RunParameter> p;
  for (const std::string& s : sets) {
    const auto eq = s.find('=');
    p.push_back({s.substr(0, eq), eq == std::string::npos ? "" : s.substr(eq + 1)});
  }
  return p;
}

double error_indicator(const Mesh& mesh, const char* field) {
  const Field* f = mesh.find_field(field);
  if (!f || f->location != FieldLocation::node || mesh.tet_count() == 0) return NAN;
  const ErrorIndicator e = zz_error_indicator(mesh, *f);
  if (!std::isfinite(e.gradient_norm)) return INFINITY;  // overflowed (an absurd load): no indicator
  return e.gradient_norm > 0 ? e.relative_error() : NAN;
}

void print_error_indicator(double relative, const char* field) {
  if (std::isnan(relative))
    std::printf("error indicator: none (the %s has no gradient)\n", field);
  else if (std::isinf(relative))
    std::printf("error indicator: none (the %s's gradient is not a finite number)\n", field);
  else
    std::printf(
        "error indicator (Zienkiewicz-Zhu, recovered against element gradient of the %s): %.3g relative "
        "(foxi mesh --refine-from refines where it is large)\n",
        field, relative);
}

ProgressFn terminal_progress(const LinearSolverOptions& options) {
  if (!::isatty(2)) return {};
  struct State {
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now(), last{};
    std::size_t reports = 0;
    bool shown = false;
    std::string line;  // what the shown line says: a stage's name, or "cg" for the iterations
  };
  auto state = std::make_shared<State>();
  const double relative_tolerance = options.relative_tolerance;
  const bool cg = options.kind != LinearSolverKind::direct;
  return [state, relative_tolerance, cg](std::string_view stage, double fraction) {
    const auto now = std::chrono::steady_clock::now();
    if (stage == "solve" && fraction > 0 && fraction < 1) ++state->reports;  // CG, every 10th iteration
    const bool done = stage == "solve" && fraction >= 1;
    if (done) {
      if (state->shown) std::fprintf(stderr, "\r\033[K");
      state->shown = false;
      return true;
    }
    // Quiet for the first second (a small solve shows nothing), then at most 5 times a second; a line
    // of another kind (a new stage, the first CG iterations) shows at once, so that a stage shorter
    // than 200 ms still says what it was.
    const bool iterations = cg && stage == "solve" && state->reports > 0;
    const std::string line = iterations ? std::string("cg") : std::string(stage);
    if (now - state->start < std::chrono::seconds(1) ||
        (line == state->line && now - state->last < std::chrono::milliseconds(200)))
      return true;
    state->last = now;
    state->line = line;
    const double seconds = std::chrono::duration<double>(now - state->start).count();
    if (iterations)
      std::fprintf(stderr,
                   "\r\033[Ksolve: about %zu CG iterations, relative residual %.2g (goal %.2g), %.1f s",
                   10 * state->reports, std::pow(relative_tolerance, fraction), relative_tolerance, seconds);
    else
      std::fprintf(stderr, "\r\033[K%.*s %.0f%%, %.1f s", int(stage.size()), stage.data(), 100 * fraction,
                   seconds);
    state->shown = true;
    return true;
  };
}

std::string self_executable() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("foxi") : p.string();
}

RunResults run_solve_child(const std::vector<std::string>& args, const std::filesystem::path& json,
                           const std::filesystem::path& log, int* exit_status) {
  std::vector<std::string> argv{self_executable(), "solve"};
  argv.insert(argv.end(), args.begin(), args.end());
  // The record comes on the child's stdout (its text then goes nowhere, its stderr to the log), into
  // a plain scratch file: `--json FILE` would write it durably, two fsyncs per run (about 20 ms here,
  // more on a busy disk) that the run's caller does not need.
  argv.push_back("--json");
  const int rc = run_program(argv, log.string(), json.string());
  if (exit_status) *exit_status = rc;
  std::error_code ec;
  if (std::filesystem::file_size(json, ec) > 0 && !ec) {
    std::string text;
    if (FILE* f = std::fopen(json.c_str(), "rb")) {
      char buf[65536];
      std::size_t n = 0;
      while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
      std::fclose(f);
    }
    try {
      return parse_results_json(text);
    } catch (const std::exception& e) {
      RunResults r;
      r.status = RunStatus::failed;
      r.error = e.what();
      return r;
    }
  }
  // No record: the run failed before its results. Its error line says why.
  RunResults r;
  r.status = RunStatus::failed;
  std::string last, error;
  if (FILE* f = std::fopen(log.c_str(), "rb")) {
    char line[4096];
    while (std::fgets(line, sizeof line, f)) {
      std::string s(line);
      while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
      if (s.empty()) continue;
      last = s;
      if (s.rfind("foxi solve: ", 0) == 0 && s.find("warning:") == std::string::npos) error = s.substr(12);
    }
    std::fclose(f);
  }
  r.error = !error.empty() ? error : !last.empty() ? last : "exit status " + std::to_string(rc);
  if (r.error.rfind("error: ", 0) == 0) r.error = r.error.substr(7);
  return r;
}

}  // namespace foxi::cli
