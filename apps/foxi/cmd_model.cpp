// foxi model check|plc MODEL [--set k=v]...: load a parametrized structure model, report it, write
// its PLC.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "model_picture.hpp"
#include "model_run.hpp"
#include "foxi/model/diagnostics.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/structure.hpp"
#include "foxi/solver/electric.hpp"

namespace foxi::cli {

namespace {

const char* kModelUsage =
    "foxi model check MODEL.toml [--set NAME=VALUE]...\n"
    "foxi model plc MODEL.toml [--set NAME=VALUE]... -o OUT.poly\n"
    "foxi model show MODEL.toml [--set NAME=VALUE]... [--size WxH] [--view exploded|cut|whole]\n"
    "                [--max-tets N] -o OUT.png\n"
    "  check: loads the model, builds its PLC and prints parameters, materials, parts with volumes,\n"
    "         boundary names, conditions, loads and mesh controls (or the errors, with file and line);\n"
    "         warns about parts that touch no other part and parts that overhang what they sit on, and\n"
    "         says for each physics whether the model is ready for it or why not (a missing material\n"
    "         property, no condition, a group of parts with no path to a fixed value)\n"
    "  plc:   writes the PLC (metres, region id = part number, boundary markers) as a TetGen .poly\n"
    "  show:  meshes the model coarsely (TetGen, no sizes, no quality refinement, not made Delaunay:\n"
    "         the tets of the PLC's points) and draws it with the\n"
    "         painter, each part in its material's colour, seen from the front, above, right; --view\n"
    "         exploded (default: part i lifted by i gaps, so every part shows whole), cut (the back\n"
    "         half, tets beyond the middle of y) or whole; prints the colour legend\n"
    "  --set NAME=VALUE  overrides a parameter, e.g. --set die_w=8mm\n"
    "  --max-tets N      show: refuse a mesh estimated to have more than N tets (default 4000000)";

// Lengths in the model's unit, everything else in SI.
void print_quantity(const Quantity& q, const Model& model) {
  if (q.dims == kLength)
    std::printf("%.6g %s", q.value / model.length_scale, model.length_unit.c_str());
  else
    std::printf("%.6g %s", q.value, q.dims == kDimensionless ? "" : dims_to_string(q.dims).c_str());
}

}  // namespace

namespace {

// Electrostatics: each conductor with the metal parts that become part of it (electric.hpp: metal is
// a material of electrical_conductivity >= ElectrostaticParams::metal_conductivity, joined through
// shared points: the PLC's, which the mesh keeps), and the metal that floats.
void print_conductors(const Model& model, const Structure& s) {
  const double threshold = ElectrostaticParams{}.metal_conductivity;
  const std::size_t np = model.parts.size();
  std::vector<char> metal(np, 0);
  for (std::size_t i = 0; i < np; ++i)
    for (const Material& m : model.materials)
      if (m.name == model.parts[i].material) metal[i] = m.electrical_conductivity >= threshold;
  if (std::find(metal.begin(), metal.end(), 1) == metal.end()) return;
  auto part_index = [&](const std::string& name) {
    for (std::size_t i = 0; i < np; ++i)
      if (model.parts[i].name == name) return i;
    return np;
  };
  // The PLC points of each marker's facets, and of each part's facets (markers "P.face", "A/B").
  std::vector<std::set<std::uint32_t>> marker_points(s.boundary_names.size()), part_points(np);
  for (std::size_t f = 0; f < s.plc.facet_count(); ++f) {
    const std::int32_t m = s.plc.facet_marker[f];
    if (m < 1 || static_cast<std::size_t>(m) > s.boundary_names.size()) continue;
    const std::string& name = s.boundary_names[static_cast<std::size_t>(m) - 1];
    std::vector<std::size_t> parts;
    if (const auto slash = name.find('/'); slash != std::string::npos) {
      parts = {part_index(name.substr(0, slash)), part_index(name.substr(slash + 1))};
    } else if (const auto dot = name.rfind('.'); dot != std::string::npos) {
      parts = {part_index(name.substr(0, dot))};
    }
    for (std::uint32_t p = s.plc.facet_polygon_begin[f]; p < s.plc.facet_polygon_begin[f + 1]; ++p)
      for (std::uint32_t v = s.plc.polygon_vertex_begin[p]; v < s.plc.polygon_vertex_begin[p + 1]; ++v) {
        marker_points[static_cast<std::size_t>(m) - 1].insert(s.plc.polygon_vertices[v]);
        for (std::size_t part : parts)
          if (part < np) part_points[part].insert(s.plc.polygon_vertices[v]);
      }
  }
  std::vector<int> owner(np, -1);
  int index = 0;
  for (const BoundaryCondition& c : model.conditions) {
    if (c.kind != ConditionKind::voltage || !condition_applies(c, Physics::electrostatic)) continue;
    std::set<std::uint32_t> points;
    for (const std::string& surface : c.surfaces)
      for (std::size_t b = 0; b < s.boundary_names.size(); ++b)
        if (s.boundary_names[b] == surface) points.insert(marker_points[b].begin(), marker_points[b].end());
    std::vector<std::size_t> joined;
    for (bool grew = true; grew;) {
      grew = false;
      for (std::size_t i = 0; i < np; ++i) {
        if (!metal[i] || std::find(joined.begin(), joined.end(), i) != joined.end()) continue;
        if (std::none_of(part_points[i].begin(), part_points[i].end(),
                         [&](std::uint32_t v) { return points.count(v) > 0; }))
          continue;
        joined.push_back(i);
        points.insert(part_points[i].begin(), part_points[i].end());
        grew = true;
      }
    }
    std::printf("  conductor %-16s", ("'" + c.name + "'").c_str());
    if (joined.empty()) std::printf(" no metal part touches it\n");
    for (std::size_t k = 0; k < joined.size(); ++k) {
      const std::size_t i = joined[k];
      std::printf("%s%s", k ? ", " : " with the metal parts ", model.parts[i].name.c_str());
      if (owner[i] >= 0)
        std::printf(" (also on an earlier conductor: they are shorted, foxi solve refuses it)");
      owner[i] = index;
    }
    if (!joined.empty()) std::printf("\n");
    ++index;
  }
  for (std::size_t i = 0; i < np; ++i)
    if (metal[i] && owner[i] < 0)
      std::printf("  floating metal   %s: one unknown potential, no net charge\n",
                  model.parts[i].name.c_str());
}

}  // namespace

int cmd_model(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kModelUsage);
    return kExitOk;
  }
  std::vector<std::string> sets;
  while (args.has_option("--set")) sets.push_back(args.option("--set"));
  const std::string out = args.option("-o");
  const std::string size = args.option("--size", "1280x960");
  const std::string view = args.option("--view", "exploded");
  const double max_tets = max_tets_option(args);
  const auto pos = args.positional(2, 2, kModelUsage);
  const std::string& action = pos[0];
  const std::string& file = pos[1];
  if (action != "check" && action != "plc" && action != "show")
    throw UsageError("unknown action '" + action + "'\nusage: " + kModelUsage);
  if (action == "plc" && out.empty()) throw UsageError("give the output file with -o OUT.poly");
  if (!out.empty()) check_output_path(out);
  if (action == "show") {
    if (out.empty()) throw UsageError("give the output file with -o OUT.png");
    ModelPictureParams pp;
    if (view == "cut")
      pp.view = ModelView::cut;
    else if (view == "whole")
      pp.view = ModelView::whole;
    else if (view != "exploded")
      throw UsageError("--view takes exploded, cut or whole, not '" + view + "'");
    const auto wh =
        parse_numbers(size.substr(0, size.find('x')) + "," + size.substr(size.find('x') + 1), "--size");
    if (size.find('x') == std::string::npos || wh.size() != 2 || !(wh[0] >= 16 && wh[0] <= 8192) ||
        !(wh[1] >= 16 && wh[1] <= 8192) || wh[0] != std::floor(wh[0]) || wh[1] != std::floor(wh[1]))
      throw UsageError("--size takes WxH, 16 to 8192 pixels each, not '" + size + "'");
    pp.width = static_cast<int>(wh[0]);
    pp.height = static_cast<int>(wh[1]);
    ModelMeshOptions options;
    options.coarse = true;
    options.max_tets = max_tets;
    const MeshedModel m = mesh_model_from_sets(file, sets, options);
    const ModelPicture pic = render_model_picture(m, out, pp);
    std::printf("%s: %zu parts, coarse mesh %zu nodes, %zu tets (TetGen %s); drew %zu tets (%s) -> %s\n",
                file.c_str(), m.model.parts.size(), m.mesh.node_count(), m.mesh.tet_count(),
                m.report.switches.c_str(), pic.tets_drawn,
                pic.delaunay ? "painter, power order" : "not Delaunay: MPVO order, depth buffer",
                out.c_str());
    std::printf("colours (part, material, RGB):\n");
    print_legend(m, pic);
    return kExitOk;
  }

  const Model model = load_model(file, sets, "--set");
  const Structure s = build_structure(model);
  if (action == "plc") {
    write_poly(s.plc, out);
    std::printf("%s -> %s: %zu points, %zu facets, %zu parts, %zu boundaries\n", file.c_str(), out.c_str(),
                s.plc.point_count(), s.plc.facet_count(), model.parts.size(), s.boundary_names.size());
    return kExitOk;
  }
  std::printf("model %s (length unit %s)\n", file.c_str(), model.length_unit.c_str());
  std::printf("parameters:\n");
  for (const Parameter& p : model.parameters) {
    std::printf("  %-16s = ", p.name.c_str());
    print_quantity(p.value, model);
    std::printf("   (%s%s)\n", p.expression.c_str(), p.overridden ? ", from --set" : "");
  }
  std::printf("materials:\n");
  for (const Material& m : model.materials)
    std::printf("  %-16s k %g W/(m K), sigma %g S/m, eps_r %g, E %g Pa, nu %g, alpha %g 1/K\n",
                m.name.c_str(), m.thermal_conductivity, m.electrical_conductivity, m.relative_permittivity,
                m.youngs_modulus, m.poisson_ratio, m.thermal_expansion);
  std::printf("parts (region id, name, shape, material, volume after carving):\n");
  for (std::size_t i = 0; i < model.parts.size(); ++i) {
    const Part& p = model.parts[i];
    std::printf("  %2zu %-16s %-9s %-16s %.6g m^3 (%.6g %s^3)", i + 1, p.name.c_str(), p.shape.c_str(),
                p.material.c_str(), s.part_volume[i],
                s.part_volume[i] / (model.length_scale * model.length_scale * model.length_scale),
                model.length_unit.c_str());
    if (p.prisms.size() > 1) std::printf(", %zu items", p.prisms.size());
    std::printf("\n");
  }
  std::printf("boundaries (marker, name, area):\n");
  for (std::size_t b = 0; b < s.boundary_names.size(); ++b)
    std::printf("  %2zu %-28s %.6g m^2\n", b + 1, s.boundary_names[b].c_str(), s.boundary_area[b]);
  print_model_conditions(model);
  // what the geometry and the conditions leave unsound (diagnostics.hpp)
  const ModelDiagnostics diag = diagnose_model(model, s);
  for (const ModelWarning& w : diag.warnings)
    if (w.kind != ModelWarningKind::no_fixed_value) std::printf("warning: %s\n", describe(w, model).c_str());
  // which solves the model is ready for (foxi solve MODEL --physics NAME), or why not
  for (Physics ph : {Physics::thermal, Physics::electrostatic, Physics::current, Physics::thermal_stress}) {
    try {
      check_physics(model, ph);
    } catch (const IoError& e) {
      std::printf("physics %s: not ready: %s\n", physics_name(ph), e.what());
      continue;
    }
    std::size_t unfixed = 0;
    for (const ModelWarning& w : diag.warnings)
      if (w.kind == ModelWarningKind::no_fixed_value && w.physics == ph) {
        std::printf("physics %s: not ready: %s\n", physics_name(ph), describe(w, model).c_str());
        ++unfixed;
      }
    if (unfixed > 0) continue;
    if (ph != Physics::thermal_stress) {
      std::printf("physics %s: ready (foxi solve MODEL --physics %s)\n", physics_name(ph), physics_name(ph));
      if (ph == Physics::electrostatic) print_conductors(model, s);
      continue;
    }
    // the stress solve also needs a temperature: the model's load, or its own thermal run
    bool load = false, thermal = true;
    for (const Load& l : model.loads) load = load || l.kind == LoadKind::temperature_change;
    try {
      check_physics(model, Physics::thermal);
    } catch (const IoError&) {
      thermal = false;
    }
    std::printf("physics %s: ready (foxi solve MODEL --physics thermoelastic%s)%s\n", physics_name(ph),
                load      ? ""
                : thermal ? " --temperature-from-thermal, or --dT K"
                          : " --dT K",
                load ? (thermal ? "; or with the thermal run's temperatures: --temperature-from-thermal" : "")
                     : "; the model has no temperature_change load");
  }
  std::printf("PLC: %zu points, %zu facets, %zu region seeds\n", s.plc.point_count(), s.plc.facet_count(),
              s.plc.regions.size());
  return kExitOk;
}

}  // namespace foxi::cli
