// A model's boundary conditions and loads (foxi/model/conditions.hpp) as solver parameters for a
// mesh of its structure, named by name_mesh (structure.hpp): surfaces are found by boundary name,
// parts by region id (part index + 1).
#pragma once

#include "foxi/model/model_file.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/thermal.hpp"

namespace foxi {

// Temperatures, heat fluxes and convections on every tag of their surfaces; power loads as total
// heat (W) or density (W/m^3) sources of their part's region. Conductivities stay the materials'.
ThermalParams thermal_params_from_model(const Model& model, const Mesh& mesh);

// Each voltage (or ground) condition is one conductor at its voltage, named by the condition.
ElectrostaticParams electrostatic_params_from_model(const Model& model, const Mesh& mesh);

// Each voltage condition a voltage terminal, each current condition a fixed-current terminal.
CurrentParams current_params_from_model(const Model& model, const Mesh& mesh);

// Throws SolverError when a condition's surface names no boundary of `mesh`.
std::vector<std::int32_t> surface_tags(const BoundaryCondition& condition, const Mesh& mesh);

}  // namespace foxi
