// A model's boundary conditions and loads (foxi/model/conditions.hpp) as solver parameters for a
// mesh of its structure, named by name_mesh (structure.hpp): surfaces are found by boundary name,
// parts by region id (part index + 1).
#pragma once

#include "foxi/api.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/solver/electric.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/solver/thermoelastic.hpp"

namespace foxi {

// Temperatures, heat fluxes and convections on every tag of their surfaces; power loads as total
// heat (W) or density (W/m^3) sources of their part's region. Conductivities stay the materials'.
FOXI_API ThermalParams thermal_params_from_model(const Model& model, const Mesh& mesh);

// Each voltage (or ground) condition is one conductor at its voltage, named by the condition.
FOXI_API ElectrostaticParams electrostatic_params_from_model(const Model& model, const Mesh& mesh);

// Each voltage condition a voltage terminal, each current condition a fixed-current terminal.
FOXI_API CurrentParams current_params_from_model(const Model& model, const Mesh& mesh);

// Displacement conditions fix all three components of their surfaces' nodes at the condition's
// vector, sliding conditions hold their (planar) surfaces' normal displacement at 0; each part's
// region takes its material's E, nu and alpha. The temperature_change loads give delta_t: one load on
// every part (no `part`), or loads that give every part the same value. Throws SolverError when parts
// get different temperature changes (a per-part dT would tear the shared interface nodes) or some parts
// get none while others do. No temperature_change load leaves delta_t 0 (a temperature field, e.g. of
// the model's thermal solve, is then the caller's to give).
FOXI_API ThermoelasticParams thermoelastic_params_from_model(const Model& model, const Mesh& mesh);

// Throws SolverError when a condition's surface names no boundary of `mesh`.
FOXI_API std::vector<std::int32_t> surface_tags(const BoundaryCondition& condition, const Mesh& mesh);

}  // namespace foxi
