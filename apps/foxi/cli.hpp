// Shared pieces of the foxi command-line program: argument lists, usage errors, JSON text.
#pragma once

#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace foxi::cli {

// A mistake in the command line (exit status 2); the message says what was wrong.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An input that is not fit for the command (exit status 3, kExitBadInput): a mesh that validation
// refuses, a file with no tets, ...; the message names the file and says why.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The arguments of one subcommand, with flags taken out as they are asked for.
class Args {
 public:
  // --name=value is read as --name value (GNU style), up to a bare "--" (what follows it is
  // another program's, taken whole by take_after).
  explicit Args(std::vector<std::string> args);
  // True (and removed) if `flag` is present.
  bool flag(std::string_view name);
  // The value after `name` (removed with it), or `fallback` if absent; UsageError if it has none or
  // an empty one.
  std::string option(std::string_view name, std::string fallback = {});
  bool has_option(std::string_view name) const;
  // A flag that may take a file: true (and removed) if `name` is present; the argument after it is
  // taken (removed) into `file` when it ends with `suffix` (e.g. "--json out.json"), else `file` is
  // cleared ("--json" alone, the model file after it left alone).
  bool flag_with_file(std::string_view name, std::string_view suffix, std::string& file);
  // The remaining arguments; UsageError if any still starts with "--" (an unknown option, or one
  // given again after it was taken: "given twice") or their count is not between min and max.
  std::vector<std::string> positional(std::size_t min, std::size_t max, std::string_view usage);
  // Everything after `marker` ("--"), taken out with it; empty when it is absent.
  std::vector<std::string> take_after(std::string_view marker);
  // The arguments not taken out yet, in order.
  const std::vector<std::string>& remaining() const { return args_; }

 private:
  std::vector<std::string> args_;
  std::vector<std::string> taken_;  // the options and flags taken out so far
};

// Comma-separated finite numbers ("1,2.5,-3"); UsageError naming the option `what` otherwise.
std::vector<double> parse_numbers(const std::string& s, const char* what);

// A JSON number for `v` (null for NaN and infinities, which JSON lacks).
std::string json_number(double v);

int cmd_info(Args args);
int cmd_convert(Args args);
int cmd_order(Args args);
int cmd_mesh(Args args);
int cmd_render(Args args);
int cmd_movie(Args args);
int cmd_solve(Args args);
int cmd_model(Args args);
int cmd_demo(Args args);
int cmd_sweep(Args args);
int cmd_fields(Args args);
int cmd_probe(Args args);
int cmd_plot(Args args);
int cmd_export_ccx(Args args);
// foxi solve ... --with ccx (cmd_ccx.cpp), from cmd_solve.
int cmd_solve_with(Args args, const std::string& physics);

}  // namespace foxi::cli
