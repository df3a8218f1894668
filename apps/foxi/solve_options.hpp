// Command-line pieces shared by the `foxi solve` physics: option values, tags and regions by number
// or name, labels. Each throws UsageError naming the option on a malformed value.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/units.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace foxi::cli {

// A whole number (decimal); false when `s` is not one.
bool parse_int(const std::string& s, std::int32_t& out);
// A finite number.
double parse_number(const std::string& text, const std::string& option);
// A value with units as model files write them ("3 W", "3W", "3000 mW"; a bare number is SI), of the
// dimension of `unit` ("W", "W/(m*K)", "V"); UsageError naming the option and the expected unit.
double parse_value(const std::string& text, const std::string& option, const char* unit);
// A temperature: "300", "300 K", "25 degC", "25degC", "25 °C". Absolute: degC adds 273.15 K and a
// value not above 0 K is refused; a difference (--dT): 5 degC = 5 K.
double parse_temperature(const std::string& text, const std::string& option, TemperatureKind kind);
// "A,B" split at the last comma outside parentheses (values may be "max(1, 2) W"); UsageError
// naming the option and `form` when there is none.
std::pair<std::string, std::string> split_pair(const std::string& text, const std::string& option,
                                               const char* form);
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
// --solver auto|direct|amg|ichol, --tol REL and --threads N (the solver's threads; default the cores).
LinearSolverOptions parse_solver_options(Args& args);

// --size-scale S: a number > 0 multiplying the model's mesh sizes (model_run.hpp), default 1.
double size_scale_option(Args& args);

// One line per check; a failed one is a loud UNRELIABLE line (on stdout with the figures, and on
// stderr). Returns the exit status: kExitUnreliable when a check failed.
int print_checks(const std::vector<BalanceCheck>& checks);

// The thermal conditions of `foxi solve MESH --physics thermal` (--fix, --flux, --convect, --power,
// --power-density, --k, --theta), taken out of args with their values checked (before the meshing:
// tags and regions need the mesh, so add_thermal_options looks them up and appends to `params`; a
// --power or --power-density replaces a load already in `params` on its region, with a line saying so).
struct ThermalOptions {
  std::vector<std::string> fix, flux, convect, power, density, cond, theta;
  bool empty() const {
    return fix.empty() && flux.empty() && convect.empty() && power.empty() && density.empty() &&
           cond.empty() && theta.empty();
  }
};
ThermalOptions thermal_options(Args& args);
void add_thermal_options(const Mesh& mesh, const ThermalOptions& options, ThermalParams& params);
// The thermal report's lines: max temperature and where, the region and boundary tables, the energy
// balance, the thermal resistances (foxi solve and foxi solve --with ccx print the same).
void print_thermal_report(const Mesh& mesh, const ThermalReport& report);

// The thermoelastic report's lines: the largest von Mises stress and displacement and where, per
// region and per material interface (foxi solve and foxi solve --with ccx print the same).
void print_thermoelastic_report(const Mesh& mesh, const ThermoelasticReport& report);

int cmd_solve_thermoelastic(Args args);
// foxi solve MODEL --physics transient ...: transient heat conduction, a .pvd series and Zth(t).
int cmd_solve_transient(Args args);
// foxi solve MODEL --convergence K ...: the same solve on K meshes, finer by --ratio each.
int cmd_solve_convergence(Args args, const std::string& physics);

}  // namespace foxi::cli
