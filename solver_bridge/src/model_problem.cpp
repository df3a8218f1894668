// Model conditions and loads -> solver parameters (model_problem.hpp).
#include "foxi/solver/model_problem.hpp"

#include <cmath>

#include "foxi/model/physics.hpp"

namespace foxi {

std::vector<std::int32_t> surface_tags(const BoundaryCondition& c, const Mesh& mesh) {
  std::vector<std::int32_t> tags;
  for (const std::string& s : c.surfaces) {
    const Boundary* found = nullptr;
    for (const Boundary& b : mesh.boundaries)
      if (b.name == s) found = &b;
    if (found == nullptr)
      throw SolverInputError(std::string(condition_kind_name(c.kind)) + " condition (line " +
                             std::to_string(c.line) + "): the mesh has no boundary named '" + s + "'");
    tags.push_back(found->tag);
  }
  return tags;
}

ThermalParams thermal_params_from_model(const Model& model, const Mesh& mesh) {
  ThermalParams p;
  for (const BoundaryCondition& c : model.conditions) {
    if (c.kind != ConditionKind::temperature && c.kind != ConditionKind::heat_flux &&
        c.kind != ConditionKind::convection)
      continue;
    for (std::int32_t tag : surface_tags(c, mesh)) {
      if (c.kind == ConditionKind::temperature) p.fixed.push_back({tag, c.value});
      if (c.kind == ConditionKind::heat_flux) p.flux.push_back({tag, c.value});
      if (c.kind == ConditionKind::convection) p.convection.push_back({tag, c.h, c.ambient});
    }
  }
  for (const Load& l : model.loads) {
    if (l.kind != LoadKind::power) continue;
    for (std::size_t i = 0; i < model.parts.size(); ++i)
      if (model.parts[i].name == l.part)
        p.sources.push_back({static_cast<std::int32_t>(i + 1), l.value, l.total});
  }
  return p;
}

namespace {

std::vector<Electrode> electrodes(const Model& model, const Mesh& mesh, Physics physics) {
  std::vector<Electrode> out;
  for (const BoundaryCondition& c : model.conditions) {
    if ((c.kind != ConditionKind::voltage && c.kind != ConditionKind::current) ||
        !condition_applies(c, physics))
      continue;
    Electrode e;
    e.name = c.name;
    e.tags = surface_tags(c, mesh);
    e.fixed_current = c.kind == ConditionKind::current;
    (e.fixed_current ? e.current : e.voltage) = c.value;
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace

ElectrostaticParams electrostatic_params_from_model(const Model& model, const Mesh& mesh) {
  ElectrostaticParams p;
  p.conductors = electrodes(model, mesh, Physics::electrostatic);
  return p;
}

CurrentParams current_params_from_model(const Model& model, const Mesh& mesh) {
  CurrentParams p;
  p.terminals = electrodes(model, mesh, Physics::current);
  return p;
}

ThermoelasticParams thermoelastic_params_from_model(const Model& model, const Mesh& mesh) {
  ThermoelasticParams p;
  for (const BoundaryCondition& c : model.conditions) {
    if (c.kind != ConditionKind::displacement && c.kind != ConditionKind::sliding) continue;
    for (std::int32_t tag : surface_tags(c, mesh)) {
      if (c.kind == ConditionKind::sliding) {
        p.sliding.push_back({tag});
        continue;
      }
      FixedDisplacement f;
      f.tag = tag;
      for (int i = 0; i < 3; ++i) f.value[i] = c.displacement[i];
      p.fixed.push_back(f);
    }
  }
  for (std::size_t i = 0; i < model.parts.size(); ++i)
    for (const Material& m : model.materials)
      if (m.name == model.parts[i].material)
        p.materials.push_back(
            {static_cast<std::int32_t>(i + 1), m.youngs_modulus, m.poisson_ratio, m.thermal_expansion});
  // dT per part: NaN where no load names it
  std::vector<double> part_dt(model.parts.size(), std::nan(""));
  std::uint64_t first_line = 0;
  for (const Load& l : model.loads) {
    if (l.kind != LoadKind::temperature_change) continue;
    if (first_line == 0) first_line = l.line;
    for (std::size_t i = 0; i < model.parts.size(); ++i) {
      if (!l.part.empty() && model.parts[i].name != l.part) continue;
      if (!std::isnan(part_dt[i]) && part_dt[i] != l.value)
        throw SolverInputError("temperature_change load (line " + std::to_string(l.line) + "): part '" +
                               model.parts[i].name + "' already has a temperature change of " +
                               std::to_string(part_dt[i]) + " K");
      part_dt[i] = l.value;
    }
  }
  if (first_line == 0) return p;
  for (std::size_t i = 0; i < model.parts.size(); ++i)
    if (std::isnan(part_dt[i]) || part_dt[i] != part_dt[0])
      throw SolverInputError(
          "temperature_change load (line " + std::to_string(first_line) +
          "): the thermal stress solver takes one uniform temperature change; part '" + model.parts[i].name +
          "' has " + (std::isnan(part_dt[i]) ? std::string("none") : std::to_string(part_dt[i]) + " K") +
          ", part '" + model.parts[0].name + "' " + std::to_string(part_dt[0]) + " K");
  p.delta_t = part_dt[0];
  return p;
}

}  // namespace foxi
