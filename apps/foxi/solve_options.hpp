// Command-line pieces shared by the `foxi solve` physics: option values, tags and regions by number
// or name, labels. Each throws UsageError naming the option on a malformed value.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi::cli {

// A finite number.
double parse_number(const std::string& text, const std::string& option);
// "KEY=VALUE" split at the first '='.
std::pair<std::string, std::string> split_assignment(const std::string& text, const std::string& option);
// A boundary tag given by number or by name; a region id by number or name.
std::int32_t boundary_tag(const Mesh& mesh, const std::string& key, const std::string& option);
std::int32_t region_id(const Mesh& mesh, const std::string& key, const std::string& option);
// Every value of a repeatable option, taken out of args.
std::vector<std::string> all_options(Args& args, const char* name);
// "3 (name)" for printing.
std::string boundary_label(const Mesh& mesh, std::int32_t tag);
std::string region_label(const Mesh& mesh, std::int32_t id);
// --solver auto|direct|amg|ichol and --tol REL.
LinearSolverOptions parse_solver_options(Args& args);

int cmd_solve_thermoelastic(Args args);

}  // namespace foxi::cli
