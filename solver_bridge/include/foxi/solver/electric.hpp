// Electrostatics (capacitance) and DC conduction (resistance) on the common mesh database, with the
// P1 machinery of the heat solver (thermal.hpp: SolverError, LinearSolverOptions).
//
// Both solve -div(c grad phi) = 0 with phi fixed on named electrodes (conductors, terminals), each a
// set of boundary tags; other boundaries carry no normal flux (dphi/dn = 0). With one solve per
// electrode (1 V on it, 0 V on the others, one factorization for all) the Maxwell matrix M_ij = charge
// (or current) into electrode i when electrode j is at 1 V: the capacitance matrix for c = eps0 eps_r,
// the conductance matrix for c = sigma. The field at the given potentials is their superposition.
//
// Robust at any contrast (copper 6e7 against FR-4 1e-14 S/m in one package): M_ij is the energy form
// sum over tets of c V grad(u_i) . grad(u_j), not the nodal reactions (K u_j) at electrode i's nodes.
// At a node that touches metal the reaction is a sum of terms of size sigma_metal * h * 1 V that cancel
// down to a current 1e20 times smaller, so it is round-off (the flip chip's 1.5e-11 A in against
// 5.1e-16 A out); in the energy form each tet adds its own, positive-sized share, metal tets whose
// potential is flat to round-off add nothing, and u_i, constant on a metal body, never amplifies the
// metal rows' round-off. Both forms agree for an exact discrete solution (u_i = 1 on electrode i and 0
// on the others, K u_j = 0 at the free nodes). The linear solve measures each row's residual against
// its own diagonal (LinearSolverOptions), so the insulator's rows are solved as well as the metal's.
// M is symmetric by construction. One step more keeps the metal's round-off out: in each unit
// solution, every connected set of tets on which it is flat to 1e-9 V (or 10 x a looser solver
// tolerance; a metal body carrying none of that solve's current) is made exactly constant (1 or 0
// where it touches an electrode) before the energy form, the superposition and the written fields
// use it; else c |grad u|^2 of the metal's round-off (1e-15 V over a tet of copper) would outweigh
// the FR-4's true current (1e-7 of it in a copper-FR-4 series pair). The energy so left out is at
// most c (1e-9 V / h)^2 V per flat tet.
//
// Checks (BalanceCheck, in the reports): Kirchhoff / charge neutrality (each column of M sums to 0,
// relative to its diagonal: the potentials of the separate solves must add up to 1 everywhere a
// coefficient is), the Maxwell sign pattern (M_ii > 0, M_ij <= 0 off the diagonal, relative to
// sqrt(M_ii M_jj)), energy (sum V_i I_i against the Joule heat of the written field; 1/2 sum Q_i V_i
// against its field energy: both come from the same unit fields, so this one guards the
// superposition and the fixed-current terminals' voltages, not the solve) and the linear solve's
// residual, max |r_k| / A_kk per volt applied (recomputed, not CG's recursion), which with Kirchhoff
// guards the solve. Tolerance: max(1e-6, 100 x the solver's relative tolerance).
//
// Electrostatics: metal is part of the conductor it touches. A region is metal when its material's
// electrical_conductivity is at least ElectrostaticParams::metal_conductivity (1e4 S/m: metals, solder,
// doped polysilicon; not intrinsic silicon, 4.3e-4 S/m), or when it is listed in metal_regions; a
// region given a permittivity override is a dielectric. Each connected body of metal tets (through
// shared nodes) that touches a conductor's nodes is at that conductor's potential (the flip chip's
// bumps on the die pad), one that touches none floats: one unknown potential for all its nodes, with
// no net charge. Metal touching two conductors is an error (they are shorted). DC conduction has no
// such rule: a terminal is exactly its boundary tags and metal is a resistor like any other region.
//
// The library never prints; errors throw SolverError.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/solver/thermal.hpp"  // HeatSource: joule_heat_sources feeds the heat solver

namespace foxi {

inline constexpr double kVacuumPermittivity = 8.8541878128e-12;  // F/m

// A conductor or terminal: the boundary tags it covers, all at one potential.
struct Electrode {
  std::string name;
  std::vector<std::int32_t> tags;
  double voltage = 0;  // V (the operating potential; for a current terminal, unused)
  // DC conduction only: the terminal's total current into the body (A) is given and its voltage
  // is found. At least one terminal must have a fixed voltage.
  bool fixed_current = false;
  double current = 0;
};

struct RegionCoefficient {
  std::int32_t region = 0;
  double value = 0;  // relative permittivity (1) or electrical conductivity (S/m), > 0
};

struct ElectrostaticParams {
  // Overrides the region's material's relative_permittivity (and makes the region a dielectric);
  // every dielectric region with tets needs one of the two.
  std::vector<RegionCoefficient> permittivity;
  // Metal (equipotential) regions: those listed, and those whose material's electrical_conductivity
  // is at least metal_conductivity (S/m; infinity: only the listed ones).
  double metal_conductivity = 1e4;
  std::vector<std::int32_t> metal_regions;
  std::vector<Electrode> conductors;
  LinearSolverOptions solver;
};

struct ElectrodeResult {
  std::string name;
  double area = 0;     // m^2 of its boundary triangles
  double voltage = 0;  // V at the operating point
  double charge = 0;   // C (electrostatics) or current into the body, A (conduction), at that point
  std::vector<std::int32_t> metal_regions;  // electrostatics: the metal regions that are part of it
};

// Electrostatics: a metal body that touches no conductor, at the potential that leaves it uncharged.
struct FloatingMetal {
  std::vector<std::int32_t> regions;
  std::size_t nodes = 0;
  double voltage = 0;  // V at the operating point
};

struct ElectrostaticReport {
  std::vector<ElectrodeResult> conductors;  // in the order given
  std::vector<FloatingMetal> floating;
  // capacitance[i][j] = charge on conductor i with 1 V on j and 0 V on the others (F), energy form.
  std::vector<std::vector<double>> capacitance;
  double energy = 0;        // J, 1/2 sum Q_i V_i at the operating potentials
  double field_energy = 0;  // J, 1/2 int eps |E|^2 of the written field
  double residual = 0;      // max |r_k| / A_kk per volt over the solves (see above)
  std::vector<BalanceCheck> checks;
  std::string solver;
  std::size_t unknowns = 0, iterations = 0;
  double relative_residual = 0;
  double assembly_seconds = 0, solve_seconds = 0;
};

// Stores "potential" (V, nodes) at the conductors' voltages and "electric_field" (V/m, cells). Throws
// SolverError when a region has no permittivity, there is no conductor, a tag is unknown or on two
// conductors, two conductors share a node, or a connected part touches no conductor.
FOXI_API ElectrostaticReport solve_electrostatic(Mesh& mesh, const ElectrostaticParams& params);

struct CurrentParams {
  // Overrides the region's material's electrical_conductivity; every region with tets needs one.
  std::vector<RegionCoefficient> conductivity;
  std::vector<Electrode> terminals;
  LinearSolverOptions solver;
};

struct RegionJoule {
  std::int32_t region = 0;
  double conductivity = 0;  // S/m
  double volume = 0;        // m^3
  double power = 0;         // W dissipated, int sigma |grad phi|^2
};

struct CurrentReport {
  std::vector<ElectrodeResult> terminals;        // in the order given; charge = current into the body (A)
  std::vector<std::vector<double>> conductance;  // S, G[i][j] = current into i with 1 V on j
  // With exactly two terminals: (V_0 - V_1) / I_0 at the operating point, else 1 / G[0][0] (ohm).
  double resistance = 0;
  std::vector<RegionJoule> regions;  // by region id
  double total_power = 0;            // W, the Joule heat of the written field (the regions' sum)
  double terminal_power = 0;         // W, sum V_i I_i
  double residual = 0;               // max |r_k| / A_kk per volt over the solves (see above)
  std::vector<BalanceCheck> checks;
  std::string solver;
  std::size_t unknowns = 0, iterations = 0;
  double relative_residual = 0;
  double assembly_seconds = 0, solve_seconds = 0;
};

// Stores "potential" (V, nodes), "current_density" (A/m^2, cells) and "joule_heat" (W/m^3, cells).
// Errors as solve_electrostatic, plus: no terminal with a fixed voltage.
FOXI_API CurrentReport solve_current(Mesh& mesh, const CurrentParams& params);

// The checks of a Maxwell matrix M (capacitance or conductance) and of the solves behind it (see
// above): "Kirchhoff" (columns sum to 0 relative to their largest entry; with more than one
// electrode), "Maxwell signs" and "residual" (the given figure), each against `tolerance`. `flow`
// names what M carries ("the currents") in the checks' text.
FOXI_API std::vector<BalanceCheck> maxwell_matrix_checks(const std::vector<std::vector<double>>& m,
                                                         double residual, double tolerance,
                                                         const std::string& flow);

// The Joule heat of each region as total heat sources of a thermal run.
FOXI_API std::vector<HeatSource> joule_heat_sources(const CurrentReport& report);

}  // namespace foxi
