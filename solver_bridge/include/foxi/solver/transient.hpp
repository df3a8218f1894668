// Transient heat conduction on P1 tets: rho c dT/dt - div(k grad T) = Q(t), with the boundary
// conditions and steady sources of ThermalParams and per-region powers that vary in time.
//
// Space: the steady solver's P1 stiffness (thermal_setup.hpp) and a *lumped* (row-sum) heat
// capacity, m_i = sum over the tets at node i of rho c V / 4. Lumped rather than consistent because
// the consistent P1 mass makes M/dt + K lose its non-negative inverse for small steps: a step of power
// then gives temperatures below the initial one next to the source in the first steps (undershoot),
// which a Zth curve at short times shows as a dip; lumping keeps the discrete maximum principle on
// meshes where K has it, and the stored energy is sum_i m_i T_i exactly. Both are second order in
// space for the temperature.
//
// Time: implicit, fixed step dt. Backward Euler (order 1, L-stable), or BDF2 (order 2, L-stable; its
// first step is backward Euler). BDF2 rather than Crank-Nicolson: Crank-Nicolson is not L-stable, so
// the stiff modes a power step or the fixed faces excite ring with a factor near -1 per step and show
// as oscillations of the junction temperature at short times, where Zth matters most. The matrix
// (c0 M/dt + K) is the same at every step (c0 = 1 Euler, 3/2 BDF2), so its factorization or AMG
// hierarchy is built once (twice for BDF2: its Euler first step has its own) and reused; each step's
// CG starts from the previous temperature (it solves for the increment) and stops at the relative
// tolerance of the step's whole right-hand side, as a solve from zero would: not of the increment,
// which would ask ever more digits of it as the temperature settles.
//
// Power: sum over TransientPower of P_r(t) W spread uniformly over region r's volume, evaluated at
// the end of each step (implicit), on top of ThermalParams::sources (constant).
//
// Energy check: per step, the heat that enters in the step as the scheme integrates it (dt times
// sources plus boundary heat at the new time) must equal the scheme's change of stored energy
// (Euler: sum m (T^n+1 - T^n); BDF2: sum m (3T^n+1 - 4T^n + T^n-1)/2); summed over the run it is a
// BalanceCheck against the heat that flowed. It checks the solves, reactions and loads (linear-solver
// tolerance), not the time discretization error, which the tests measure against exact solutions.
// The library never prints; errors throw SolverError, cancel SolverCancelled.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi {

// A power against time, W.
struct PowerWaveform {
  enum class Kind : std::uint8_t {
    step,   // `power` from t = 0 on
    pulse,  // `power` during [k period, k period + width) for k = 0 .. count-1 (count 0: no end), else 0
    table,  // linear interpolation of `table` (time s, W), times strictly increasing; held constant
            // before the first and after the last point
  };
  Kind kind = Kind::step;
  double power = 0;              // W
  double width = 0, period = 0;  // s
  std::size_t count = 0;
  std::vector<std::pair<double, double>> table;
  FOXI_API double at(double t) const;
  // The energy from t = 0 to t (J, exact for each kind), and the mean power over [t0, t1] (its value
  // at t1 where t1 <= t0): what a time step of [t0, t1] puts in.
  FOXI_API double energy(double t) const;
  FOXI_API double mean(double t0, double t1) const;
  // Whether the power jumps at some time in (t0, t1] (a step's or a pulse's edge; tables are
  // continuous): BDF2 restarts with Euler steps across a jump.
  FOXI_API bool jumps_in(double t0, double t1) const;
  static PowerWaveform step_of(double watts) {
    PowerWaveform w;
    w.power = watts;
    return w;
  }
};

// Reads a power table: CSV lines "time_s,power_W"; blank lines, lines starting with '#' and one header
// line whose first field is not a number are skipped. Throws foxi::IoError naming the file and line
// for a bad number, a missing field, a non-finite value, a time not above the previous one, or no rows.
FOXI_API std::vector<std::pair<double, double>> read_power_table(const std::string& path);

struct TransientPower {
  std::int32_t region = 0;
  PowerWaveform power;
};
struct RegionHeatCapacity {
  std::int32_t region = 0;
  double rho_c = 0;  // J/(m^3 K), > 0
};

enum class TimeScheme : std::uint8_t { euler, bdf2 };

struct TransientParams {
  // Conductivity, boundary conditions, constant sources, resistances (evaluated at the last step)
  // and the linear solver, as for the steady solve.
  ThermalParams thermal;
  std::vector<TransientPower> power;
  // Overrides the region's material's density * specific_heat; every region needs one of the two.
  std::vector<RegionHeatCapacity> heat_capacity;
  double end_time = 0;    // s, > 0
  std::size_t steps = 0;  // dt = end_time / steps
  TimeScheme scheme = TimeScheme::bdf2;
  // Initial temperature: NaN takes the steady solution with the constant sources only (the device
  // off, in equilibrium with its boundaries: the reference of a JEDEC Zth measurement); a number is a
  // uniform initial temperature (K) on the free nodes.
  double initial_temperature = std::numeric_limits<double>::quiet_NaN();
  // Regions whose maximum temperature (the junction) is recorded at every step.
  std::vector<std::int32_t> junctions;
  // Called after the initial state (step 0) and after each step with the step number, the time and
  // the nodal temperatures (NaN at nodes without tets); the caller writes what it wants. Returning
  // false cancels (SolverCancelled).
  std::function<bool(std::size_t step, double time, std::span<const double> temperature)> on_step;
};

struct TransientReport {
  TimeScheme scheme = TimeScheme::bdf2;
  double time_step = 0;
  std::vector<double> times;  // steps + 1, from 0
  // junction_temperature[j][n]: the max temperature of junctions[j] at times[n], K.
  std::vector<std::vector<double>> junction_temperature;
  std::vector<double> power;  // total power (constant sources + waveforms) at times[n], W
  double stored_energy = 0;   // J, sum m_i (T_i(end) - T_i(0))
  // J K, sum m_i (T_i(end) - T_i(0))^2. For a step of power P from an equilibrium that reaches the
  // steady state, P^2 times the first moment of the thermal impedance, int_0^inf (Zth(inf) - Zth(t))
  // dt (for any RC network: r^T M r with r the transfer resistances), which is sum R tau of a
  // Foster fit of Zth: the structure function's check.
  double capacity_moment = 0;
  // J, the heat that entered over the run as the scheme integrates it: sum of dt * (sources + boundary
  // heat in) at each step's end. Euler: equals stored_energy (to the solver's tolerance); BDF2: differs
  // from it by half the difference of the last and the first steps' energy increments (BDF2's
  // three-level "stored energy" is not sum m T), an O(dt) amount where the temperature still moves.
  double heat_in = 0;
  double heat_flow = 0;  // J, sum over steps of dt * max(what entered, what left): the check's scale
  std::vector<BalanceCheck> checks;
  ThermalReport final;  // the steady solver's report of the last state (regions, boundaries)
  std::string solver;
  std::size_t unknowns = 0;
  std::size_t iterations = 0;    // CG iterations over all steps
  double relative_residual = 0;  // largest over the steps, each against its step's whole right-hand side
  double setup_seconds = 0, solve_seconds = 0;
};

// Solves; stores "temperature" (last step) and "heat_flux" (last step) in mesh.fields like
// solve_thermal. Throws SolverError as solve_thermal does, and when a region has no density or
// specific heat, end_time or steps is not positive, or a waveform is invalid.
FOXI_API TransientReport solve_transient_thermal(Mesh& mesh, const TransientParams& params);

}  // namespace foxi
