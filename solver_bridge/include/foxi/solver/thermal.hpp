// Steady heat conduction on the common mesh database: linear (P1) tetrahedra, conductivity per
// region, boundary conditions per boundary tag, volumetric heat per region.
//
//   -div(k grad T) = Q in each region,   T = T_fix, -k dT/dn = -q (q into the body),
//   -k dT/dn = h (T - T_inf) on the tagged boundary triangles; untagged boundaries are insulated.
//
// The result goes into Mesh::fields ("temperature" on nodes in K, "heat_flux" = -k grad T on cells
// in W/m^2, 3 components), replacing fields of those names; the derived quantities an engineer reads
// first come back in a ThermalReport. The library never prints; errors throw foxi::SolverError.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/solver/solver.hpp"  // SolverError, SolverCancelled, BalanceCheck, LinearSolverOptions

namespace foxi {

struct FixedTemperature {
  std::int32_t tag = 0;
  double temperature = 0;  // K
};
struct HeatFlux {
  std::int32_t tag = 0;
  double flux = 0;  // W/m^2, positive into the body
};
struct Convection {
  std::int32_t tag = 0;
  double h = 0;        // W/(m^2 K), > 0
  double ambient = 0;  // K
};
struct HeatSource {
  std::int32_t region = 0;
  double value = 0;  // W/m^3, or W for the whole region when `total`
  bool total = false;
};
struct RegionConductivity {
  std::int32_t region = 0;
  double k = 0;  // W/(m K), > 0
};

// One side of a thermal resistance: a temperature read off the solution.
enum class ThermalProbeKind : std::uint8_t {
  region_max,     // the largest nodal temperature of a region (JEDEC's junction: the hottest point)
  region_mean,    // the volume mean of a region
  boundary_mean,  // the area mean of a boundary tag's surface temperature (a case or board temperature)
  ambient,        // T_inf of a convection boundary tag (JEDEC's theta_JA reference)
};
struct ThermalProbe {
  ThermalProbeKind kind = ThermalProbeKind::region_max;
  std::int32_t id = 0;  // region id for region_*, boundary tag otherwise
};

// A thermal resistance to report, e.g. theta_JC = junction {region_max, die} to reference
// {boundary_mean, case}, or theta_JA = ... to {ambient, convective tag}.
struct ThermalResistanceSpec {
  ThermalProbe junction;
  ThermalProbe reference{ThermalProbeKind::boundary_mean, 0};
};

struct ThermalParams {
  // Overrides the region's material's thermal_conductivity; every region with tets needs one of the two.
  std::vector<RegionConductivity> conductivity;
  std::vector<FixedTemperature> fixed;
  std::vector<HeatFlux> flux;
  std::vector<Convection> convection;
  std::vector<HeatSource> sources;
  // Convection integrates h T over each triangle exactly (consistent "mass" h A/12 (1 + delta_ij));
  // true takes h T at the centroid instead (h A/9 for every pair), which is what CalculiX does for
  // *FILM on C3D4 faces: less accurate, but it reproduces ccx to its output precision.
  bool convection_centroid_rule = false;
  // Thermal resistances to evaluate after the solve (ThermalReport::resistances, same order).
  std::vector<ThermalResistanceSpec> resistances;
  LinearSolverOptions solver;
};

// Heat entering the body through one boundary tag (W): for fixed-temperature tags from the nodal
// reactions (a node shared by two fixed tags splits its reaction by its lumped area on each), for
// flux tags q * area, for convection tags the integral of h (T_inf - T).
struct BoundaryHeat {
  std::int32_t tag = 0;
  std::string kind;             // "fixed", "flux", "convection"
  double area = 0;              // m^2
  double heat_in = 0;           // W
  double heat_bound = 0;        // W, the round-off bound of heat_in (the resolution check's)
  double mean_temperature = 0;  // K, area mean of the surface temperature (a case temperature)
};

struct RegionTemperature {
  std::int32_t region = 0;
  double volume = 0;           // m^3
  double conductivity = 0;     // W/(m K)
  double power = 0;            // W generated in the region
  double max_temperature = 0;  // K, over the region's nodes
  std::uint32_t max_node = kNone;
  double mean_temperature = 0;  // K, volume average of the P1 field
};

// theta = (T_junction - T_reference) / P with P the total power put into the body (sources plus the
// heat entering through heat-flux boundaries), as JEDEC JESD51 defines theta_JX. `path_theta` divides
// by the heat leaving through the reference boundary instead: the resistance of that path alone, which
// equals theta when all the heat leaves there, and is the one defined between two fixed-temperature
// boundaries with no power at all. A quantity whose divisor is zero is NaN.
struct ThermalResistance {
  ThermalResistanceSpec spec;
  double junction_temperature = 0;   // K
  double reference_temperature = 0;  // K
  double delta_t = 0;                // K, junction - reference
  double power = 0;                  // W, P above
  double theta = 0;                  // K/W, delta_t / power
  double reference_heat_out = 0;     // W leaving through the reference boundary
  double path_theta = 0;             // K/W, delta_t / reference_heat_out
};

struct ThermalReport {
  std::vector<BoundaryHeat> boundaries;    // one per tag given a boundary condition, by tag
  std::vector<RegionTemperature> regions;  // one per region with tets, by id
  double max_temperature = 0;              // K
  std::uint32_t max_node = kNone;
  double total_power = 0;  // W from the sources
  double imbalance = 0;    // W, sources + heat in through all boundaries (~0)
  double heat_flow = 0;    // W through the body: the larger of what enters and what leaves
  // "energy": |imbalance| / heat_flow (or / 1e-9 of the fixed nodes' sum |K_vv T_v| where that is
  // larger: with nothing flowing, the reactions are round-off of those terms)
  std::vector<BalanceCheck> checks;
  std::vector<ThermalResistance> resistances;  // one per ThermalParams::resistances
  std::string solver;            // "SimplicialLDLT", "CG+IncompleteCholesky", "CG+SmoothedAggregationAMG"
  std::size_t unknowns = 0;      // free nodes
  std::size_t nonzeros = 0;      // of the free-free matrix (both triangles)
  std::size_t iterations = 0;    // CG iterations (0 for the direct solver)
  double relative_residual = 0;  // |W (b - A x)| / |W b| of the free system (LinearSolverOptions)
  double assembly_seconds = 0, solve_seconds = 0;
};

// Solves steady heat conduction on `mesh` (tets positively oriented, see validate.hpp) and stores the
// fields "temperature" and "heat_flux" in it. Nodes used by no tet get NaN. Throws SolverError when a
// region has no conductivity, a tag or region in `params` (resistances included; an ambient probe
// needs a convection tag) is not in the mesh, a tag has two conditions,
// no tag fixes a temperature or convects (the temperature would be undetermined), the factorization
// fails or CG does not converge; SolverCancelled when the progress callback returns false.
FOXI_API ThermalReport solve_thermal(Mesh& mesh, const ThermalParams& params);

// The report of solve_thermal for nodal temperatures solved elsewhere (CalculiX): the same boundary
// heat (the P1 reactions of `temperature` at the fixed nodes), region maxima and means, resistances
// and energy check, and the same fields stored. `precision` > 0: the temperatures are rounded to
// that relative precision (ccx's binary .frd: float32, 6e-8; an ASCII one: 5e-6), and the energy check's
// tolerance takes in the imbalance that rounding can make. The solver figures stay 0, `solver` is "given".
// Throws SolverError as solve_thermal does for `params`, and when `temperature` has the wrong size or no
// finite value at a node of a tet.
FOXI_API ThermalReport thermal_report(Mesh& mesh, const ThermalParams& params,
                                      std::vector<double> temperature, double precision = 0);

}  // namespace foxi
