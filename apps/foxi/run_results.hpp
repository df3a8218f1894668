// The results record of a foxi solve run (foxi/solver/results.hpp) in the program: --json output,
// the error indicator, and runs of `foxi solve` as child processes for foxi sweep and foxi solve
// --convergence.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "cli.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi::cli {

// --json [FILE.json]: JSON on stdout (the text output silenced) or written durably to FILE, which
// is checked to be writable before the work.
struct JsonOutput {
  bool enabled = false;
  std::string file;    // empty: stdout
  int stdout_fd = -1;  // the real stdout while the text goes to /dev/null
};
JsonOutput json_option(Args& args);
// Sends the text output (stdout) to /dev/null when the JSON goes to stdout; call after the usage
// checks, before the work.
void silence_text_for_json(JsonOutput& json);
// Writes `text` where `json` says (DurableFile for a file).
void write_json(const JsonOutput& json, const std::string& text);

// --set NAME=VALUE as the record's parameters.
std::vector<RunParameter> run_parameters(std::span<const std::string> sets);

// The Zienkiewicz-Zhu relative gradient error of the node field `field` (NaN when absent or with no
// gradient, infinity where the gradient overflows) and its printed line.
double error_indicator(const Mesh& mesh, const char* field);
void print_error_indicator(double relative, const char* field);

// Progress of a long solve on stderr, only when stderr is a terminal (else an empty function): one
// line rewritten in place with the stage, the CG iterations (about: the solver reports every 10th)
// and the relative residual against its goal, at most 5 times a second, cleared when the solve
// ends. The solver reports CG's progress as log(residual) / log(goal), so the residual is goal^f.
// A direct solver (--solver direct; `auto` takes it only for small, fast problems) shows its stage
// and fraction alone.
ProgressFn terminal_progress(const LinearSolverOptions& options);

// This program's executable (/proc/self/exe).
std::string self_executable();

// Runs `foxi solve ARGS --json` as a tracked child process (killed on a stop), its stdout (the
// record) in `json`, its stderr in `log`, and reads the record. A run that wrote none is a record with status
// failed and the child's error line ("foxi solve: error: ..." or its last line) as the error.
// `exit_status`: the child's exit status (2, kExitUsage: its options are wrong, as they are for every run).
RunResults run_solve_child(const std::vector<std::string>& args, const std::filesystem::path& json,
                           const std::filesystem::path& log, int* exit_status = nullptr);

// A folder for child runs' files, STEM-PID-XXXXXX under TMPDIR, removed (with its contents) when the
// program stops or the guard goes (cleanup::TemporaryFolder).
class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& stem) : folder_(stem + "-" + std::to_string(::getpid())) {}
  std::filesystem::path operator/(const std::string& name) const { return folder_.path() / name; }

 private:
  cleanup::TemporaryFolder folder_;
};

}  // namespace foxi::cli
