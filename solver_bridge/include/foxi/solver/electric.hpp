// Electrostatics (capacitance) and DC conduction (resistance) on the common mesh database, with the
// P1 machinery of the heat solver (thermal.hpp: SolverError, LinearSolverOptions).
//
// Both solve -div(c grad phi) = 0 with phi fixed on named electrodes (conductors, terminals), each a
// set of boundary tags; other boundaries carry no normal flux (dphi/dn = 0). With one solve per
// electrode (1 V on it, 0 V on the others, one factorization for all) the reactions at the fixed
// nodes give the Maxwell matrix M_ij = charge (or current) into electrode i when electrode j is at 1 V:
// the capacitance matrix for c = eps0 eps_r, the conductance matrix for c = sigma. The field at the
// given potentials is their superposition. The library never prints; errors throw SolverError.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/solver/thermal.hpp"

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
  // Overrides the region's material's relative_permittivity; every region with tets needs one.
  std::vector<RegionCoefficient> permittivity;
  std::vector<Electrode> conductors;
  LinearSolverOptions solver;
};

struct ElectrodeResult {
  std::string name;
  double area = 0;     // m^2 of its boundary triangles
  double voltage = 0;  // V at the operating point
  double charge = 0;   // C (electrostatics) or current into the body, A (conduction), at that point
};

struct ElectrostaticReport {
  std::vector<ElectrodeResult> conductors;  // in the order given
  // capacitance[i][j] = charge on conductor i with 1 V on j and 0 V on the others (F), symmetrized;
  // asymmetry is the largest |C_ij - C_ji| / max |C| before that.
  std::vector<std::vector<double>> capacitance;
  double asymmetry = 0;
  // 2 W_i / (1 V)^2 from the field energy of solve i; equals capacitance[i][i] up to the solver's tolerance.
  std::vector<double> energy_capacitance;
  double energy = 0;  // J stored at the operating potentials
  std::string solver;
  std::size_t unknowns = 0, iterations = 0;
  double relative_residual = 0;
  double assembly_seconds = 0, solve_seconds = 0;
};

// Stores "potential" (V, nodes) at the conductors' voltages and "electric_field" (V/m, cells). Throws
// SolverError when a region has no permittivity, there is no conductor, a tag is unknown or on two
// conductors, two conductors share a node, or a connected part touches no conductor.
ElectrostaticReport solve_electrostatic(Mesh& mesh, const ElectrostaticParams& params);

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
  double total_power = 0;            // W, = sum V_i I_i
  std::string solver;
  std::size_t unknowns = 0, iterations = 0;
  double relative_residual = 0;
  double assembly_seconds = 0, solve_seconds = 0;
};

// Stores "potential" (V, nodes), "current_density" (A/m^2, cells) and "joule_heat" (W/m^3, cells).
// Errors as solve_electrostatic, plus: no terminal with a fixed voltage.
CurrentReport solve_current(Mesh& mesh, const CurrentParams& params);

// The Joule heat of each region as total heat sources of a thermal run.
std::vector<HeatSource> joule_heat_sources(const CurrentReport& report);

}  // namespace foxi
