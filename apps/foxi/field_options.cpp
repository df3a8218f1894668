#include "field_options.hpp"

#include <algorithm>
#include <cmath>

namespace foxi::cli {

const char* const kFieldOptionsHelp =
    "  --field NAME[:C] colour by a field: C a component (x y z, xx yy zz xy yz xz, or an index), mag\n"
    "                  (a vector's magnitude, the default for vectors), vm (von Mises, the default\n"
    "                  for tensors) or p1 p2 p3 (a tensor's principal values, largest first); flat per\n"
    "                  tet (the value at its centroid) unless --graded\n"
    "  --graded        graded facets: each face's colour interpolated from its corners (a cell field is\n"
    "                  first averaged to the nodes within each region, never across an interface)\n"
    "  --cmap M        viridis (default), cividis, coolwarm (diverging) or rainbow (Turbo)\n"
    "  --range a,b     the colour range in display units (default: the drawn values' range; with\n"
    "                  coolwarm and values of both signs, symmetric about 0 so that white is 0)\n"
    "  --log           logarithmic colour scale (values <= 0 get the no-value grey)\n"
    "  --units U       display unit: degC, mm, um, nm, kPa, MPa, GPa, mV, kV, mW or the SI unit (default:\n"
    "                  degC for K, MPa for Pa, um for m, mV for V below 1 V; the mesh stays SI)\n"
    "  --step k        the field's step k (0-based; default the last)\n"
    "  --markers       (foxi render) a ring at the drawn maximum and minimum with their values, where\n"
    "                  they show in the picture\n"
    "  --legend on|off a colour bar with the field, unit, ticks, range and map (default on), in a panel\n"
    "                  at the right of the picture: the mesh is drawn in what is left of --size\n";

FieldOptions take_field_options(Args& args) {
  FieldOptions o;
  o.spec = args.option("--field");
  const std::string cmap = args.option("--cmap"), range = args.option("--range"),
                    legend = args.option("--legend");
  const std::string step = args.option("--step");
  o.units = args.option("--units");
  o.log = args.flag("--log");
  o.graded = args.flag("--graded");
  o.markers = args.flag("--markers");
  if (o.spec.empty() && (!cmap.empty() || !range.empty() || !legend.empty() || !step.empty() ||
                         !o.units.empty() || o.log || o.graded || o.markers))
    throw UsageError(
        "--cmap, --range, --log, --graded, --units, --step, --markers and --legend colour by a field: give "
        "--field "
        "NAME");
  if (!cmap.empty()) {
    const auto m = parse_color_map(cmap);
    if (!m) throw UsageError("--cmap takes viridis, cividis, coolwarm or rainbow, not '" + cmap + "'");
    o.map = *m;
  }
  if (!range.empty()) {
    const std::vector<double> r = parse_numbers(range, "--range");
    if (r.size() != 2 || !(r[0] < r[1]))
      throw UsageError("--range takes a,b with a < b, not '" + range + "'");
    o.has_range = true;
    o.range[0] = r[0];
    o.range[1] = r[1];
  }
  if (!legend.empty()) {
    if (legend != "on" && legend != "off") throw UsageError("--legend takes on or off, not '" + legend + "'");
    o.legend = legend == "on";
  }
  if (!step.empty()) {
    char* end = nullptr;
    o.step = std::strtol(step.c_str(), &end, 10);
    if (*end != 0 || o.step < 0) throw UsageError("--step takes a step number 0, 1, ..., not '" + step + "'");
  }
  return o;
}

FieldPicture resolve_field(const FieldOptions& o, const Mesh& mesh, std::span<const std::uint32_t> subset,
                           const std::string& path) {
  FieldPicture f;
  try {
    f.choice = choose_field(mesh, o.spec);
    const std::size_t steps = f.choice.field->step_count();
    if (o.step >= 0 && std::size_t(o.step) >= steps)
      throw FieldSelectError("field '" + f.choice.field->name + "' has " + std::to_string(steps) +
                             " step(s): --step takes 0.." + std::to_string(steps - 1));
    f.step = o.step < 0 ? steps - 1 : std::size_t(o.step);
  } catch (const FieldSelectError& e) {
    throw UsageError(path + ": " + e.what());
  }
  const Field& field = *f.choice.field;
  // The values drawn: per tet (flat) or per tet corner (graded), of the selected tets only.
  const std::vector<double> all =
      o.graded ? tet_corner_values(mesh, f.choice, f.step) : tet_centroid_values(mesh, f.choice, f.step);
  const std::size_t per = o.graded ? 4 : 1;
  // The values the range is taken from: those drawn, or the corners' (FieldOptions::corner_range).
  const bool corners = o.corner_range && !o.graded;
  const std::vector<double> corner_values =
      corners ? tet_corner_values(mesh, f.choice, f.step) : std::vector<double>{};
  const std::vector<double>& ranged = corners ? corner_values : all;
  const std::size_t ranged_per = corners ? 4 : per;
  std::vector<double> drawn;
  if (subset.empty()) {
    drawn = ranged;
  } else {
    for (std::uint32_t t : subset)
      drawn.insert(drawn.end(), ranged.begin() + std::ptrdiff_t(ranged_per * t),
                   ranged.begin() + std::ptrdiff_t(ranged_per * t + ranged_per));
  }
  for (double v : drawn) f.no_value += std::isnan(v);
  // The extremes' places: graded, the corner (node) of the largest / smallest value; flat, the tet.
  {
    std::size_t imax = kNone, imin = kNone;
    auto visit = [&](std::size_t i) {
      if (!std::isfinite(all[i])) return;
      if (imax == kNone || all[i] > all[imax]) imax = i;
      if (imin == kNone || all[i] < all[imin]) imin = i;
    };
    if (subset.empty()) {
      for (std::size_t i = 0; i < all.size(); ++i) visit(i);
    } else {
      for (std::uint32_t t : subset)
        for (std::size_t k = 0; k < per; ++k) visit(per * t + k);
    }
    auto place = [&](std::size_t i, double* at, std::vector<std::uint32_t>& tets) {
      if (i == kNone) return;
      const std::size_t t = i / per;
      for (int j = 0; j < 3; ++j) at[j] = 0;
      if (o.graded) {  // the node, and every tet that has it
        const std::uint32_t node = mesh.tet[i];
        for (int j = 0; j < 3; ++j) at[j] = mesh.xyz[3 * std::size_t(node) + std::size_t(j)];
        for (std::size_t u = 0; u < mesh.tet_count(); ++u)
          for (int k = 0; k < 4; ++k)
            if (mesh.tet[4 * u + std::size_t(k)] == node) tets.push_back(std::uint32_t(u));
      } else {
        for (int k = 0; k < 4; ++k)
          for (int j = 0; j < 3; ++j)
            at[j] += 0.25 * mesh.xyz[3 * std::size_t(mesh.tet[4 * t + std::size_t(k)]) + std::size_t(j)];
        tets.push_back(std::uint32_t(t));
      }
    };
    place(imax, f.max_at, f.max_tets);
    place(imin, f.min_at, f.min_tets);
  }
  std::tie(f.data_lo, f.data_hi) = finite_range(drawn, false);
  const double max_abs = std::max(std::abs(f.data_lo), std::abs(f.data_hi));
  if (o.units.empty()) {
    f.legend.unit = default_display_unit(field.unit, std::isfinite(max_abs) ? max_abs : 0);
  } else {
    const auto u = display_unit(field.unit, o.units);
    if (!u)
      throw UsageError("--units " + o.units + " does not apply to field '" + field.name + "' in " +
                       (field.unit.empty() ? std::string("no unit") : field.unit));
    f.legend.unit = *u;
  }
  ColorScale& s = f.legend.scale;
  s.map = o.map;
  s.log = o.log;
  if (o.has_range || o.has_si_range) {
    s.lo = o.has_si_range ? o.si_range[0] : f.legend.unit.to_si(o.range[0]);
    s.hi = o.has_si_range ? o.si_range[1] : f.legend.unit.to_si(o.range[1]);
    if (s.lo > s.hi) std::swap(s.lo, s.hi);
    if (!(s.hi >
          s.lo))  // ends a display unit apart can meet in SI (1e-300 and 2e-300 degC are both 273.15 K)
      throw UsageError("--range " + std::to_string(o.range[0]) + "," + std::to_string(o.range[1]) + " is " +
                       std::to_string(s.lo) + " to " + std::to_string(s.hi) + " " + field.unit +
                       " in SI: no range (give ends further apart)");
    if (o.log && !(s.lo > 0))
      throw UsageError("--log needs a range above 0 in SI (" + field.unit + "), not " + std::to_string(s.lo));
  } else {
    const std::optional<AutoScale> a = automatic_scale(drawn, o.map, o.log);
    if (!a)
      throw UsageError(path + ": field '" + field.name + "' has no " + (o.log ? "positive" : "finite") +
                       " value on the tets drawn" + (o.log ? " (a log scale needs one)" : ""));
    s = a->scale;
    f.range_widened = a->widened;
    f.range_centred = a->centred;
  }
  f.legend.title = f.choice.label;
  f.paint =
      std::make_shared<const FieldPaint>(o.graded ? graded_field_paint(all, s) : flat_field_paint(all, s));
  return f;
}

MarkerReport draw_extreme_markers(Framebuffer& scene, const Camera& camera, const TextRenderer& text,
                                  const FieldPicture& field) {
  MarkerReport report;
  const Projector proj(camera, scene.width, scene.height);
  const DisplayUnit& u = field.legend.unit;
  const double step =
      std::abs(u.to_display(field.legend.scale.hi) - u.to_display(field.legend.scale.lo)) / 100;
  auto mark = [&](const double* at, const std::vector<std::uint32_t>& tets, double value, const char* what) {
    double px[2];
    if (tets.empty() || !proj.project(at, px)) return false;
    const int cx = int(std::floor(px[0])), cy = int(std::floor(px[1]));
    bool shows = false;
    for (int dy = -1; dy <= 1 && !shows; ++dy)
      for (int dx = -1; dx <= 1 && !shows; ++dx) {
        const int x = cx + dx, y = cy + dy;
        if (x < 0 || y < 0 || x >= scene.width || y >= scene.height) continue;
        shows = std::find(tets.begin(), tets.end(), scene.id[scene.index(x, y)]) != tets.end();
      }
    if (!shows) return false;
    // A ring of radius 6 (black inside white, readable on any colour), and the value beside it.
    for (int y = cy - 8; y <= cy + 8; ++y)
      for (int x = cx - 8; x <= cx + 8; ++x) {
        if (x < 0 || y < 0 || x >= scene.width || y >= scene.height) continue;
        const double r = std::hypot(x - cx, y - cy);
        if (r >= 4.5 && r < 6)
          scene.rgba[scene.index(x, y)] = pack_rgba(0, 0, 0);
        else if (r >= 6 && r < 7.5)
          scene.rgba[scene.index(x, y)] = pack_rgba(255, 255, 255);
      }
    const std::string label =
        std::string(what) + " " + tick_label(u.to_display(value), step) + " " + u.symbol;
    const TextExtent e = text.measure(label, 13);
    const int lx = cx + 10 + e.advance < scene.width ? cx + 10 : cx - 10 - e.advance;
    for (int y = cy - e.ascent / 2 - e.ascent - 2; y <= cy + e.ascent / 2 + e.descent + 2;
         ++y)  // a white plate
      for (int x = lx - 2; x <= lx + e.advance + 2; ++x)
        if (x >= 0 && y >= 0 && x < scene.width && y < scene.height)
          scene.rgba[scene.index(x, y)] = pack_rgba(255, 255, 255);
    text.draw(scene, label, lx, cy + e.ascent / 2, 13);
    return true;
  };
  report.max_shown = mark(field.max_at, field.max_tets, field.data_hi, "max");
  report.min_shown = mark(field.min_at, field.min_tets, field.data_lo, "min");
  return report;
}

int legend_panel(const TextRenderer& text, const FieldPicture& field, int width, int height) {
  const int panel = legend_width(text, field.legend);
  if (width - panel < 64 || height < legend_min_height())
    throw UsageError("--size " + std::to_string(width) + "x" + std::to_string(height) +
                     " leaves no room for the legend (" + std::to_string(panel) + " pixels wide, " +
                     std::to_string(legend_min_height()) +
                     " high at least): make it larger or give --legend off");
  return panel;
}

Framebuffer with_legend(const Framebuffer& scene, const TextRenderer& text, const FieldPicture& field,
                        int panel) {
  Framebuffer out(scene.width + panel, scene.height);
  for (int y = 0; y < scene.height; ++y) {
    std::copy_n(scene.rgba.begin() + std::ptrdiff_t(scene.index(0, y)), scene.width,
                out.rgba.begin() + std::ptrdiff_t(out.index(0, y)));
    std::copy_n(scene.id.begin() + std::ptrdiff_t(scene.index(0, y)), scene.width,
                out.id.begin() + std::ptrdiff_t(out.index(0, y)));
  }
  draw_color_legend(out, text, field.legend, PixelRect{scene.width, 0, out.width - 1, out.height - 1});
  return out;
}

}  // namespace foxi::cli
