// [surfaces] selectors -> boundary markers, and the condition checks against the built structure.
#include "foxi/model/surfaces.hpp"

#include <algorithm>
#include <cmath>

#include "foxi/model/io_error.hpp"
#include "foxi/model/physics.hpp"
#include "plc_geometry.hpp"

namespace foxi {

namespace {

// Area of polygon p of `plc` (Newell's normal; any planar polygon).
double polygon_area(const Plc& plc, std::uint32_t p) {
  double n[3];
  polygon_normal(plc, p, n);
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

// The structure builder's facets: the first polygon is the outline, the others are holes in it.
double facet_area(const Plc& plc, std::size_t f) {
  double a = 0;
  for (std::uint32_t p = plc.facet_polygon_begin[f]; p < plc.facet_polygon_begin[f + 1]; ++p)
    a += (p == plc.facet_polygon_begin[f] ? 1 : -1) * polygon_area(plc, p);
  return a;
}

bool picks(const SurfaceSelector& s, const double* x, double tol) {
  if (s.plane)
    return std::abs((x[0] - s.point[0]) * s.normal[0] + (x[1] - s.point[1]) * s.normal[1] +
                    (x[2] - s.point[2]) * s.normal[2]) <= tol;
  for (int i = 0; i < 3; ++i)
    if (x[i] < s.lo[i] - tol || x[i] > s.hi[i] + tol) return false;
  return true;
}

bool is_outer(const std::string& name) { return name.find('/') == std::string::npos; }

}  // namespace

void tag_selected_surfaces(const Model& model, Structure& s) {
  if (model.surfaces.empty()) return;
  Plc& plc = s.plc;
  double span = 0;
  for (double c : plc.points) span = std::max(span, std::abs(c));
  const double tol = 1e-9 * std::max(span, 1e-300);
  const std::size_t first_selector = s.boundary_names.size();
  for (const SurfaceSelector& sel : model.surfaces) {
    s.boundary_names.push_back(sel.name);
    s.boundary_area.push_back(0);
    const auto marker = static_cast<std::int32_t>(s.boundary_names.size());
    std::size_t taken = 0;
    for (std::size_t f = 0; f < plc.facet_count(); ++f) {
      const auto old = static_cast<std::size_t>(plc.facet_marker[f] - 1);
      if (plc.facet_marker[f] <= 0 || !is_outer(s.boundary_names[old])) continue;
      bool all = true;
      for (std::uint32_t p = plc.facet_polygon_begin[f]; p < plc.facet_polygon_begin[f + 1] && all; ++p)
        for (std::uint32_t i = plc.polygon_vertex_begin[p]; i < plc.polygon_vertex_begin[p + 1] && all; ++i)
          all = picks(sel, &plc.points[3 * std::size_t{plc.polygon_vertices[i]}], tol);
      if (!all) continue;
      if (old >= first_selector)
        throw IoError(model.file, sel.line, IoError::kNoOffset,
                      "surface '" + sel.name + "' picks facets that surface '" + s.boundary_names[old] +
                          "' already took (selectors must not overlap)");
      const double a = facet_area(plc, f);
      s.boundary_area[old] -= a;
      s.boundary_area.back() += a;
      plc.facet_marker[f] = marker;
      ++taken;
    }
    if (taken == 0)
      throw IoError(
          model.file, sel.line, IoError::kNoOffset,
          "surface '" + sel.name + "' picks no outer boundary facet (facets are taken whole: the " +
              (sel.plane ? "plane must hold whole part faces" : "box must contain whole part faces") + ")");
  }
  // a boundary whose facets all went to selectors keeps its marker with no area
  for (double& a : s.boundary_area)
    if (std::abs(a) < 1e-12 * std::max(1.0, a)) a = std::max(a, 0.0);
}

void check_conditions(const Model& model, const Structure& s) {
  auto area_of = [&](const std::string& name) {
    for (std::size_t b = 0; b < s.boundary_names.size(); ++b)
      if (s.boundary_names[b] == name) return s.boundary_area[b];
    return -1.0;
  };
  constexpr Physics kGroups[] = {Physics::thermal, Physics::current, Physics::thermal_stress};
  for (std::size_t i = 0; i < model.conditions.size(); ++i) {
    const BoundaryCondition& c = model.conditions[i];
    const std::string who = std::string("condition '") + condition_kind_name(c.kind) + "'";
    for (const std::string& name : c.surfaces) {
      const double a = area_of(name);
      if (a < 0)
        throw IoError(model.file, c.line, IoError::kNoOffset,
                      who + ": surface '" + name +
                          "' does not exist in the built structure (parts that do not touch have no "
                          "interface; a face covered entirely by other parts has no outer boundary)");
      if (!(a > 0))
        throw IoError(
            model.file, c.line, IoError::kNoOffset,
            who + ": surface '" + name + "' has no facets left (a [surfaces] selector took them all)");
      for (std::size_t j = 0; j < i; ++j) {
        const BoundaryCondition& d = model.conditions[j];
        const bool same_physics = std::any_of(std::begin(kGroups), std::end(kGroups), [&](Physics p) {
          return condition_applies(c, p) && condition_applies(d, p);
        });
        if (same_physics && std::find(d.surfaces.begin(), d.surfaces.end(), name) != d.surfaces.end())
          throw IoError(model.file, c.line, IoError::kNoOffset,
                        who + ": surface '" + name + "' already has a '" + condition_kind_name(d.kind) +
                            "' condition (line " + std::to_string(d.line) + ")");
      }
    }
  }
}

}  // namespace foxi
