// The bridge to CalculiX (ccx): the same mesh and thermal or thermal-stress problem as a CalculiX input deck,
// and the nodal results of its .frd file read back, so that foxi's solvers can be checked against an
// independent code on the same P1 / C3D4 discretisation.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
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

struct CalculixRunOptions {
  std::string program = "ccx";  // looked up in PATH
  // Asked about every 50 ms while ccx runs, as progress("ccx", -1): false kills it (SolverCancelled).
  ProgressFn progress;
};

// Solves `params` on `mesh` by CalculiX, as foxi solve --with ccx does: the deck (write_calculix_thermal)
// in a fresh work folder under the temporary directory, `ccx -i heat` run there as a child process
// (foxi/model/run_program.hpp; OMP_NUM_THREADS 1 unless set), its NDTEMP read back onto the mesh by
// node number (coordinates checked, every node given a value) and reported by thermal_report at the
// .frd's precision with the convection centroid rule of ccx's *FILM (the balance checks of ccx's own
// solution), `solver` "ccx". The temperature and heat flux are stored on the mesh as solve_thermal
// stores them. The work folder is removed on return, a throw or cleanup::interrupt(). Throws
// SolverError for what write_calculix_thermal rejects and for a ccx that fails (its last output in
// the message) or is not installed, SolverCancelled when progress says stop.
FOXI_API ThermalReport solve_thermal_calculix(Mesh& mesh, ThermalParams params,
                                              const CalculixRunOptions& options = {});

}  // namespace foxi
