// foxi/solver.hpp: FEM solvers on the mesh database and the bridge to CalculiX (foxi::solver), in one
// include. The entry points, one a line (declared in the topic headers below, which say more):
//
//   solve_thermal(mesh, params)                steady heat conduction, P1 tets (thermal.hpp)
//   solve_electrostatic(mesh, params)          potentials and capacitance matrix (electric.hpp)
//   solve_current(mesh, params)                DC conduction: potentials and resistances (electric.hpp)
//   joule_heat_sources(report)                 the Joule heat of a current solve, for thermal (electric.hpp)
//   solve_transient_thermal(mesh, params)      transient heat: BDF2/Euler steps, junction T(t)
//   (transient.hpp) read_power_table(path)                     a CSV power waveform (time, W) (transient.hpp)
//   structure_function(t, zth)                 Zth(t) -> Foster fit -> Cauer ladder, cumulative R, C
//   (structure_function.hpp) solve_thermoelastic(mesh, params)          thermal stress: displacements,
//   stresses (thermoelastic.hpp) thermal_params_from_model(model, mesh)     a model's conditions as solver
//   parameters; also
//     electrostatic_, current_, thermoelastic_params_from_model (model_problem.hpp)
//   SolverError, SolverCancelled, LinearSolverOptions   why a solve failed; the linear solver (solver.hpp)
//   write_calculix_thermal, read_frd           the same problem as a CalculiX deck, its results
//   (calculix.hpp)
//   solve_thermal_calculix, solve_thermoelastic_calculix  the problem solved by ccx, its results on the
//   mesh (calculix.hpp)
//   thermal_results(mesh, report), results_json  a run's key values as a record, JSON
//   (results.hpp) convergence_table, observed_order          convergence over refinement levels (results.hpp)
#pragma once

#include "foxi/solver/calculix.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/solver/solver.hpp"
#include "foxi/solver/structure_function.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"
#include "foxi/solver/transient.hpp"
