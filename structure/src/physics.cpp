// Material properties and conditions each physics needs (physics.hpp).
#include "foxi/model/physics.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "foxi/model/io_error.hpp"

namespace foxi {

namespace {

std::string format_value(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

}  // namespace

const char* physics_name(Physics physics) {
  switch (physics) {
    case Physics::thermal:
      return "thermal";
    case Physics::electrostatic:
      return "electrostatic";
    case Physics::current:
      return "current";
    case Physics::thermal_stress:
      return "thermoelastic";  // the name foxi solve --physics takes
  }
  return "?";
}

bool condition_applies(ConditionKind c, Physics physics) {
  switch (c) {
    case ConditionKind::temperature:
    case ConditionKind::heat_flux:
    case ConditionKind::convection:
      return physics == Physics::thermal;
    case ConditionKind::voltage:
      return physics == Physics::electrostatic || physics == Physics::current;
    case ConditionKind::current:
      return physics == Physics::current;
    case ConditionKind::displacement:
    case ConditionKind::sliding:
      return physics == Physics::thermal_stress;
  }
  return false;
}

bool condition_applies(const BoundaryCondition& c, Physics physics) {
  return condition_applies(c.kind, physics) && (c.physics.empty() || c.physics == physics_name(physics));
}

void check_physics(const Model& model, Physics physics) {
  struct Need {
    const char* property;
    double Material::*field;
  };
  std::vector<Need> needs;
  switch (physics) {
    case Physics::thermal:
      needs = {{"thermal_conductivity", &Material::thermal_conductivity}};
      break;
    case Physics::electrostatic:
      needs = {{"relative_permittivity", &Material::relative_permittivity}};
      break;
    case Physics::current:
      needs = {{"electrical_conductivity", &Material::electrical_conductivity}};
      break;
    case Physics::thermal_stress:
      needs = {{"youngs_modulus", &Material::youngs_modulus},
               {"poisson_ratio", &Material::poisson_ratio},
               {"thermal_expansion", &Material::thermal_expansion}};
      break;
  }
  for (const Part& part : model.parts)
    for (const Material& m : model.materials)
      if (m.name == part.material)
        for (const Need& n : needs)
          if (std::isnan(m.*n.field) || (physics != Physics::thermal_stress && !(m.*n.field > 0)))
            throw IoError(model.file, part.line, IoError::kNoOffset,
                          "part '" + part.name + "': material '" + m.name + "' has no " + n.property +
                              ", which --physics " + physics_name(physics) + " needs");
  // The elastic constants' ranges (the solve refused them only after meshing, and model check said
  // ready): E > 0, -1 < nu < 0.5 (0.5 is incompressible: lambda infinite), alpha finite.
  if (physics == Physics::thermal_stress)
    for (const Part& part : model.parts)
      for (const Material& m : model.materials) {
        if (m.name != part.material) continue;
        auto refuse = [&](const char* property, double value, const char* range) {
          throw IoError(model.file, part.line, IoError::kNoOffset,
                        "part '" + part.name + "': material '" + m.name + "' has " + property + " " +
                            format_value(value) + "; --physics thermoelastic needs " + range);
        };
        if (!(m.youngs_modulus > 0) || !std::isfinite(m.youngs_modulus))
          refuse("youngs_modulus", m.youngs_modulus, "it positive and finite");
        if (!(m.poisson_ratio > -1 && m.poisson_ratio < 0.5))
          refuse("poisson_ratio", m.poisson_ratio, "it in (-1, 0.5)");
        if (!std::isfinite(m.thermal_expansion))
          refuse("thermal_expansion", m.thermal_expansion, "it finite");
      }
  bool fixes = false;
  for (const BoundaryCondition& c : model.conditions)
    fixes = fixes || (condition_applies(c, physics) && c.kind != ConditionKind::heat_flux &&
                      c.kind != ConditionKind::current &&
                      (c.kind != ConditionKind::sliding || physics == Physics::thermal_stress));
  std::size_t electrodes = 0;
  for (const BoundaryCondition& c : model.conditions)
    electrodes +=
        (physics == Physics::electrostatic || physics == Physics::current) && condition_applies(c, physics);
  if (fixes && electrodes == 1)
    throw IoError(model.file, 0, IoError::kNoOffset,
                  std::string("--physics ") + physics_name(physics) +
                      " needs two electrodes (voltage, ground or current conditions); the model has one");
  if (!fixes)
    throw IoError(model.file, 0, IoError::kNoOffset,
                  std::string("no [[conditions]] fix the ") + physics_name(physics) + " solution (give " +
                      (physics == Physics::thermal          ? "a temperature or a convection"
                       : physics == Physics::thermal_stress ? "a displacement or sliding"
                                                            : "a voltage or ground") +
                      " condition)");
}

}  // namespace foxi
