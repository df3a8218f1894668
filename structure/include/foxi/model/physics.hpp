// What a solve of a model needs: material properties per physics and at least one condition that
// makes the problem well posed, checked before any meshing.
#pragma once

#include "foxi/api.hpp"
#include "foxi/model/model_file.hpp"

namespace foxi {

enum class Physics : std::uint8_t { thermal, electrostatic, current, thermal_stress };

// "thermal", "electrostatic", "current", "thermoelastic" (as foxi solve --physics names them).
FOXI_API const char* physics_name(Physics physics);

// True if `c` belongs to `physics` (temperature/heat_flux/convection: thermal; voltage: electrostatic
// and current; current: current; displacement/sliding: thermal_stress).
FOXI_API bool condition_applies(ConditionKind c, Physics physics);
// The same for one condition, which may be restricted to one physics (BoundaryCondition::physics).
FOXI_API bool condition_applies(const BoundaryCondition& c, Physics physics);

// Throws IoError (the model file, the line of the part, naming the part, its material and the
// property) when a part's material lacks a property `physics` needs (thermal_conductivity;
// relative_permittivity; electrical_conductivity; youngs_modulus, poisson_ratio and
// thermal_expansion), and (line 0) when the model has no condition that fixes the solution (a
// temperature or convection; a voltage; a voltage; a displacement or sliding) or, for electrostatic
// and current, fewer than two electrodes.
FOXI_API void check_physics(const Model& model, Physics physics);

}  // namespace foxi
