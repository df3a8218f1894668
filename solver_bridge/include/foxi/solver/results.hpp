// The results of one solve as one plain record: what `foxi solve --json` writes, one row of `foxi
// sweep`, one level of `foxi solve --convergence`, and what a workbench's run history keeps.
//
// Every figure a physics reports is a named value with its unit; the key ones (the figures an
// engineer compares between runs: max and mean temperature per region, theta values, R, the
// conductance and capacitance matrices, max von Mises per region) are marked `key` and become the
// sweep table's columns. Names are stable between runs of one model (regions and boundaries by
// name, else by number), so the same name in two records is the same quantity:
//   thermal        T_max, T_max[REGION], T_mean[REGION], theta[JUNCTION:REFERENCE]   (key)
//   electrostatic  C[A,B]                                                           (key)
//   current        R, G[A,B]                                                        (key)
//   thermoelastic  von_mises_max, von_mises_max[REGION]                             (key)
// and the rest of each report (boundary heat, areas, charges, solver work, ...) unmarked.
// The checks (BalanceCheck) go along whole. The library never prints; JSON text is returned.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace foxi {

struct ResultValue {
  std::string name;  // see above
  std::string unit;  // SI: "K", "K/W", "ohm", "S", "F", "Pa", "W", "m^2", ... ("" for counts)
  double value = 0;  // NaN where undefined (a theta with no power)
  bool key = false;  // a figure the sweep table and the convergence study carry
};

// A printed fact that is not a number: a boundary's condition kind, a terminal's kind, the metal
// regions a conductor takes in.
struct ResultText {
  std::string name;  // "condition[substrate.bottom]", "terminal[via]", "metal[via]", "T_max_region"
  std::string text;  // "fixed", "voltage", "bump+pad", "die"
};

// A model parameter as the run was given it (foxi solve --set NAME=TEXT).
struct RunParameter {
  std::string name;
  std::string text;  // "4mm"
};

enum class RunStatus : std::uint8_t { ok, unreliable, failed };
FOXI_API const char* run_status_name(RunStatus s);  // "ok", "unreliable", "failed"

struct FOXI_API RunResults {
  std::string model;    // file the run came from (model or mesh)
  std::string physics;  // "thermal", "electrostatic", "current", "thermoelastic"
  std::vector<RunParameter> parameters;
  RunStatus status = RunStatus::ok;  // unreliable: a check failed; failed: no result (see error)
  std::string error;                 // why it failed, in words
  std::size_t nodes = 0, tets = 0;
  double mesh_seconds = 0;   // model to mesh (0 for a mesh file)
  double solve_seconds = 0;  // assembly and solve
  double wall_seconds = 0;   // the whole run
  // Zienkiewicz-Zhu a-posteriori estimate of the primary field's relative gradient error (||e||/||grad
  // u||, foxi/mesher/size_field.hpp); NaN when not computed.
  double error_indicator = NAN;
  std::string solver;  // the linear solver used
  std::vector<ResultValue> values;
  std::vector<ResultText> texts;
  std::vector<BalanceCheck> checks;

  // The value named `name`, or nullptr.
  const ResultValue* find(std::string_view name) const;
};

// "die" for a named region or boundary, else its number.
FOXI_API std::string region_name(const Mesh& mesh, std::int32_t id);
FOXI_API std::string boundary_name(const Mesh& mesh, std::int32_t tag);

// The record of a physics' report on the mesh it solved (names from the mesh): values, checks,
// solver, counts, solve time; status unreliable when a check failed. The caller adds the model,
// parameters, mesh and wall times and the error indicator.
FOXI_API RunResults thermal_results(const Mesh& mesh, const ThermalReport& report);
FOXI_API RunResults electrostatic_results(const Mesh& mesh, const ElectrostaticReport& report);
FOXI_API RunResults current_results(const Mesh& mesh, const CurrentReport& report);
FOXI_API RunResults thermoelastic_results(const Mesh& mesh, const ThermoelasticReport& report);

// One JSON object (UTF-8, one line per value), NaN and infinities as null:
//   {"foxi_results": 1, "model": ..., "physics": ..., "parameters": [{"name", "text"}], "status",
//    "error", "nodes", "tets", "mesh_seconds", "solve_seconds", "wall_seconds", "error_indicator",
//    "solver", "values": [{"name", "unit", "value", "key"}], "texts": [{"name", "text"}],
//    "checks": [{"name", "what", "figure", "tolerance", "passed"}]}
FOXI_API std::string results_json(const RunResults& results);
// `s` as a JSON string literal, quotes included (\" \\ \n \r \t, other control characters as \u00XX):
// what results_json writes names with, and what the CLI's --json records use.
FOXI_API std::string json_quoted(std::string_view s);

// Reads what results_json wrote (null as NaN; members it does not know are skipped). Throws
// std::runtime_error naming the byte offset on text that is not such an object.
FOXI_API RunResults parse_results_json(std::string_view text);

// A convergence study (foxi solve --convergence): one record per mesh level, coarse to fine, and
// for each key value the observed order and the Richardson extrapolation. The levels' sizes h_k are
// the caller's (foxi: tets_k^(-1/3): the meshes are not nested, so the measured ratios, not the
// requested one, enter; any common factor cancels). f(h) = f* + C h^p is put through the levels:
// with three, exactly (observed_order); with more, in the least-squares sense (p on [0.05, 8]),
// which is much steadier on unstructured meshes, whose levels scatter. The error estimate is
// |finest - f*|. Fewer than three levels, or no p (differences that change sign or vanish, a fit at
// the ends of the range): order, f* and the estimate are NaN.
struct ConvergenceRow {
  std::string name, unit;
  std::vector<double> level_values;  // one per level
  double order = NAN;                // observed p
  double extrapolated = NAN;         // Richardson f*
  double error_estimate = NAN;       // |finest - f*|
};
// `h`: one size per level (m). Throws std::invalid_argument if sizes and levels differ in number.
FOXI_API std::vector<ConvergenceRow> convergence_table(const std::vector<RunResults>& levels,
                                                       const std::vector<double>& h);

// The observed order p of three values at sizes h0 > h1 > h2: p solves (f2 - f1) / (f1 - f0) =
// (h2^p - h1^p) / (h1^p - h0^p) (bisection on [0.05, 8]); NaN when there is none.
FOXI_API double observed_order(double f0, double f1, double f2, double h0, double h1, double h2);

}  // namespace foxi
