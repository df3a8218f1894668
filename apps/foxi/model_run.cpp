// A model file to a named mesh, and the report of its conditions (model_run.hpp).
#include "model_run.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "foxi/model/diagnostics.hpp"
#include "foxi/model/io_error.hpp"

namespace foxi::cli {

double max_tets_option(Args& args) {
  const std::string s = args.option("--max-tets");
  if (s.empty()) return kDefaultMaxTets;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !(v >= 1) || !std::isfinite(v) || v != std::floor(v))
    throw UsageError("--max-tets takes a whole number >= 1, not '" + s + "'");
  return v;
}

std::string tet_limit_message(const TetLimitError& e) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "the mesh would have about %.3g tets (from the volumes and the size bounds), over the limit "
                "of %.0f; use a larger size, or --max-tets to raise the limit",
                e.estimate(), e.limit());
  return IoError(e.file(), e.line(), IoError::kNoOffset, buf).what();
}

std::vector<ParameterOverride> set_overrides(const std::string& file, std::span<const std::string> sets) {
  return split_overrides(file, sets, "--set");
}

bool is_model_path(const std::string& path) {
  return path.size() > 5 && path.compare(path.size() - 5, 5, ".toml") == 0;
}

MeshedModel mesh_model_from_sets(const std::string& file, std::span<const std::string> sets,
                                 ModelMeshOptions options) {
  options.override_origin = "--set";
  return foxi::mesh_model(file, set_overrides(file, sets), options);
}

MeshedModel mesh_model_for_solve(const std::string& file, std::span<const std::string> sets,
                                 const std::string& physics, double size_scale, double max_tets) {
  std::optional<Physics> ph;
  for (Physics p : {Physics::thermal, Physics::electrostatic, Physics::current, Physics::thermal_stress})
    if (physics == physics_name(p)) ph = p;
  ModelMeshOptions options;
  options.physics = ph;
  options.max_tets = max_tets;
  options.size_scale = size_scale;
  MeshedModel m = mesh_model_from_sets(file, sets, options);
  // the model's warnings before the work (foxi model check prints the same)
  if (ph)
    for (const ModelWarning& w : warnings_for(diagnose_model(m.model, m.structure), *ph))
      std::fprintf(stderr, "foxi solve: warning: %s: %s\n", file.c_str(), describe(w, m.model).c_str());
  std::printf(
      "model %s: %zu parts, %zu conditions, %zu loads -> PLC %zu points, %zu facets -> %zu nodes, %zu tets "
      "(TetGen %s, %.3f s; Delaunay %s%s)\n",
      file.c_str(), m.model.parts.size(), m.model.conditions.size(), m.model.loads.size(),
      m.structure.plc.point_count(), m.structure.plc.facet_count(), m.mesh.node_count(), m.mesh.tet_count(),
      m.report.switches.c_str(), m.conforming.seconds, m.conforming.delaunay ? "certified" : "NOT certified",
      m.conforming.thin_layers.empty() ? "" : ", thin layers meshed flat");
  return m;
}

void print_model_conditions(const Model& model) {
  const double s = model.length_scale;
  const char* u = model.length_unit.c_str();
  if (!model.surfaces.empty()) std::printf("surfaces (own boundary markers):\n");
  for (const SurfaceSelector& sel : model.surfaces) {
    if (sel.plane)
      std::printf("  %-16s plane through (%g, %g, %g) %s, normal (%g, %g, %g)\n", sel.name.c_str(),
                  sel.point[0] / s, sel.point[1] / s, sel.point[2] / s, u, sel.normal[0], sel.normal[1],
                  sel.normal[2]);
    else
      std::printf("  %-16s box (%g, %g, %g) .. (%g, %g, %g) %s\n", sel.name.c_str(), sel.lo[0] / s,
                  sel.lo[1] / s, sel.lo[2] / s, sel.hi[0] / s, sel.hi[1] / s, sel.hi[2] / s, u);
  }
  if (!model.conditions.empty()) std::printf("conditions:\n");
  for (const BoundaryCondition& c : model.conditions) {
    std::printf("  %-12s on %-28s ", condition_kind_name(c.kind), c.name.c_str());
    switch (c.kind) {
      case ConditionKind::temperature:
        std::printf("%g K (%g C)", c.value, c.value - 273.15);
        break;
      case ConditionKind::heat_flux:
        std::printf("%g W/m^2 into the body", c.value);
        break;
      case ConditionKind::convection:
        std::printf("h %g W/(m^2 K), ambient %g K (%g C)", c.h, c.ambient, c.ambient - 273.15);
        break;
      case ConditionKind::voltage:
        std::printf("%g V%s%s", c.value, c.physics.empty() ? "" : ", --physics ", c.physics.c_str());
        break;
      case ConditionKind::current:
        std::printf("%g A into the body", c.value);
        break;
      case ConditionKind::displacement:
        std::printf("(%g, %g, %g) %s", c.displacement[0] / s, c.displacement[1] / s, c.displacement[2] / s,
                    u);
        break;
      case ConditionKind::sliding:
        std::printf("normal displacement 0");
        break;
    }
    std::printf("\n");
  }
  if (!model.loads.empty()) std::printf("loads:\n");
  for (const Load& l : model.loads) {
    if (l.kind == LoadKind::power)
      std::printf("  power        in %-28s %g %s\n", l.part.c_str(), l.value, l.total ? "W" : "W/m^3");
    else
      std::printf("  temperature change in %-22s %g K\n", l.part.empty() ? "every part" : l.part.c_str(),
                  l.value);
  }
  const ModelMeshControls& mc = model.mesh;
  std::printf("mesh controls: max size %s", mc.max_size > 0 ? "" : "none");
  if (mc.max_size > 0) std::printf("%g %s", mc.max_size / s, u);
  if (mc.quality >= 0)
    std::printf(", radius-edge bound %g", mc.quality);
  else
    std::printf(", radius-edge bound the mesher's default");
  if (mc.min_dihedral > 0) std::printf(", min dihedral %g deg", mc.min_dihedral);
  std::printf("\n");
  for (const PartSize& p : mc.part_sizes)
    std::printf("  part %-16s max size %g %s\n", p.part.c_str(), p.max_size / s, u);
  for (const RefineBox& b : mc.refine)
    std::printf("  refine box (%g, %g, %g) .. (%g, %g, %g) %s: max size %g %s\n", b.lo[0] / s, b.lo[1] / s,
                b.lo[2] / s, b.hi[0] / s, b.hi[1] / s, b.hi[2] / s, u, b.max_size / s, u);
}

}  // namespace foxi::cli
