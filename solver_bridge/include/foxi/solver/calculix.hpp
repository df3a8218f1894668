// The bridge to CalculiX (ccx): the same mesh and thermal or thermal-stress problem as a CalculiX input deck,
// and the nodal results of its .frd file read back, so that foxi's solvers can be checked against an
// independent code on the same P1 / C3D4 discretisation.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/solver/solver.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace foxi {

// Writes `mesh` and `params` as a CalculiX steady heat-transfer deck (SI units): *NODE, C3D4
// elements in one ELSET per region (E<id>, ids shifted to be positive), *CONDUCTIVITY per region
// (params first, then the region's material), fixed temperatures as *BOUNDARY (per node, the same
// lumped-area mean that solve_thermal uses where fixed tags meet), heat flux as *DFLUX S<face>,
// convection as *FILM F<face>, sources as *DFLUX BF on the region's elements, and *NODE OUTPUT NT
// (a binary .frd: float32 values).
// Node i of the mesh is CalculiX node i + 1, tet t element t + 1 (tets positively oriented, as
// C3D4 needs). Throws SolverError for the problems solve_thermal rejects (missing conductivity,
// unknown tags and regions, a boundary triangle that is no tet face) and IoError when the file
// cannot be written.
FOXI_API void write_calculix_thermal(const Mesh& mesh, const ThermalParams& params,
                                     const std::filesystem::path& inp);

// Writes `mesh` and `params` as a CalculiX linear static thermal-stress deck (SI units): *NODE, C3D4
// elements per region, *ELASTIC and *EXPANSION per region (params first, then the material), the
// constraints of solve_thermoelastic node by node (components along a coordinate axis as *BOUNDARY,
// sliding normals of other orientations as homogeneous *EQUATION), the reference temperature as
// *INITIAL CONDITIONS and the temperature (reference + delta_t, or the nodal field) as *TEMPERATURE,
// *NODE OUTPUT U and *ELEMENT OUTPUT S. With params.order 2: C3D10 elements whose mid-edge nodes (edge e of
// detail::tet_edges is node node_count + e + 1) get the constraints and the linearly interpolated
// temperature solve_thermoelastic gives them, and *EL PRINT S puts the integration-point stresses in
// the .dat. Throws SolverError for what solve_thermoelastic rejects (except the
// rigid-body check) and for a non-zero displacement along a direction that is no coordinate axis;
// IoError when the file cannot be written.
FOXI_API void write_calculix_thermoelastic(const Mesh& mesh, const ThermoelasticParams& params,
                                           const std::filesystem::path& inp);

// One nodal result block of a CalculiX .frd file ("NDTEMP", "DISP", ...).
struct FrdBlock {
  std::string name;
  std::uint32_t components = 0;
  std::vector<std::uint32_t> node;  // CalculiX node numbers, in file order
  std::vector<double> values;       // components per node
};

// Reads every nodal result block of an ASCII or binary .frd file (the last step's blocks come last), through
// foxi::fields' reader (read_frd_source: the one .frd reader, which also checks the node block and
// the end record). Throws IoError (file and line or byte) on a malformed or truncated file.
FOXI_API std::vector<FrdBlock> read_frd(const std::filesystem::path& frd);

// The decks ask for binary results (*NODE OUTPUT): the .frd holds float32 values, rounded to half a
// unit of their 24-bit mantissa, 2^-24 = 6e-8 relative (an ASCII .frd's E12.5 would be 5e-6).
inline constexpr double kFrdPrecision = 6e-8;

// When a CalculiX run's work folder (the deck, ccx's log, .dat and .frd) outlives the call.
enum class KeepWorkFolder : std::uint8_t {
  never,       // removed on return, on a throw and on cancel
  on_failure,  // kept when ccx fails or its results do not fit the mesh (CalculixError::work_folder)
  always,      // kept whenever the call returns or ccx fails (the result's work_folder); removed on cancel
};

struct CalculixRunOptions {
  std::string program = "ccx";  // looked up in PATH
  // Asked about every 50 ms while ccx runs, as progress("ccx", -1): false kills it (SolverCancelled).
  ProgressFn progress;
  // Given, as they appear in ccx's log (polled every 50 ms while it runs, on the calling thread), the
  // lines that say where it is: its increments, Newton iterations and their convergence, the end.
  std::function<void(const std::string& line)> on_output;
  KeepWorkFolder keep = KeepWorkFolder::never;
  std::size_t log_tail_lines = 15;  // of ccx's output, in a CalculixError
};

// A CalculiX run that gave no result to use. The work folder is kept when the options asked for it
// (then work_folder names it; empty when it was removed).
struct FOXI_API CalculixError : SolverError {
  enum class Kind : std::uint8_t {
    not_installed,  // no `program` in PATH (the shell's status 127)
    failed,         // a non-zero exit status, *ERROR in its output, or no .frd: log_tail says why
    bad_results,    // the .frd does not fit the mesh (nodes, coordinates) or leaves nodes without a value
  };
  CalculixError(Kind k, const std::string& message, int status = 0, std::string tail = {})
      : SolverError(message), kind(k), exit_status(status), log_tail(std::move(tail)) {}
  Kind kind;
  int exit_status;       // ccx's (failed)
  std::string log_tail;  // ccx's last output lines (failed)
  std::filesystem::path work_folder;
};

struct CalculixThermal {
  // thermal_report of ccx's temperatures; solver "ccx", solve_seconds the deck written, ccx run and
  // its .frd read.
  ThermalReport report;
  std::filesystem::path work_folder;  // kept (KeepWorkFolder::always), else empty
};

// Solves `params` on `mesh` by CalculiX, as foxi solve --with ccx does: the deck (write_calculix_thermal)
// in a fresh work folder under the temporary directory (cleanup::TemporaryFolder, "foxi-ccx-XXXXXX"),
// `ccx -i heat` run there as a child process (foxi/model/run_program.hpp; OMP_NUM_THREADS 1 unless
// set), its NDTEMP read back onto the mesh by node number (coordinates checked, every node given a
// value) and reported by thermal_report at the .frd's precision with the convection centroid rule of
// ccx's *FILM (the balance checks of ccx's own solution). The temperature and heat flux are stored on
// the mesh as solve_thermal stores them. The work folder goes as options.keep says, and always on
// cleanup::interrupt(). Throws SolverError for what write_calculix_thermal rejects, CalculixError when
// ccx is not installed, fails or gives results that do not fit, SolverCancelled when progress says
// stop (ccx killed and reaped first).
FOXI_API CalculixThermal solve_thermal_calculix(Mesh& mesh, ThermalParams params,
                                                const CalculixRunOptions& options = {});

struct CalculixThermoelastic {
  // ccx's steady temperatures of `temperature_from` (as solve_thermal_calculix reports them), when given.
  std::optional<ThermalReport> thermal;
  // thermoelastic_report of ccx's displacements (with C3D10 the mid-edge nodes' too); solver "ccx",
  // solve_seconds the stress deck written, ccx run and its .frd read.
  ThermoelasticReport report;
  // The largest von Mises stress of ccx's own nodal stress (its element values averaged at the nodes).
  double max_nodal_von_mises = 0;     // Pa
  std::filesystem::path work_folder;  // kept (KeepWorkFolder::always), else empty
};

// Solves `params` on `mesh` by CalculiX, as foxi solve --physics thermoelastic --with ccx does: the
// deck (write_calculix_thermoelastic, C3D4 or with params.order 2 C3D10) run by `ccx -i stress` as
// solve_thermal_calculix runs its deck; DISP read back onto the mesh's nodes (and the C3D10 mid-edge
// nodes) and reported by thermoelastic_report, which stores "displacement", "stress", "von_mises"
// and "principal_stress" as solve_thermoelastic does; ccx's nodal STRESS is stored as "stress_nodal"
// (Pa, node, xx yy zz xy yz xz). With `temperature_from`: its steady heat problem is first solved by
// ccx in the same work folder (`ccx -i heat`, as solve_thermal_calculix: "temperature" and
// "heat_flux" stored) and ccx's temperatures are the load (params.temperature, delta_t 0). Throws as
// solve_thermal_calculix does, and SolverError for what write_calculix_thermoelastic and
// thermoelastic_report reject.
FOXI_API CalculixThermoelastic solve_thermoelastic_calculix(Mesh& mesh, ThermoelasticParams params,
                                                            const CalculixRunOptions& options = {},
                                                            const ThermalParams* temperature_from = nullptr);

}  // namespace foxi
