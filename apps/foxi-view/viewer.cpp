// foxi-view's script mode and picture saving: see viewer.hpp.
#include "viewer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "foxi/model/durable_file.hpp"
#include "foxi/viz/view_options.hpp"
#include "foxi/viz/png.hpp"

namespace foxi::view {

std::filesystem::path save_next(const Viewer& viewer, const std::string& prefix, bool dump,
                                const ViewField* field) {
  std::string base;
  for (int i = 1;; ++i) {
    char num[16];
    std::snprintf(num, sizeof num, "-%03d", i);
    base = prefix + num;
    if (!std::filesystem::exists(base + ".png")) break;
  }
  const std::filesystem::path png = base + ".png";
  if (field && field->legend)
    write_png(png, presented(viewer, *field));
  else
    viewer.save_png(png);
  if (dump) {
    // Durably, like every output (foxi/model/durable_file.hpp), and the two together: a stop
    // leaves both or neither, never a partial file or a temporary.
    const Framebuffer& fb = viewer.framebuffer();
    std::vector<DurableFile> files;
    files.emplace_back(base + ".ids");
    files.emplace_back(base + ".tets");
    std::string ids;
    ids.reserve(4 * fb.id.size());
    for (std::uint32_t id : fb.id)
      for (int k = 0; k < 4; ++k) ids.push_back(static_cast<char>(id >> (8 * k)));  // little-endian
    files[0].write(ids);
    std::string tets;
    for (std::uint32_t t : viewer.drawn()) tets += std::to_string(t) + '\n';
    files[1].write(tets);
    commit_together(files);
  }
  std::printf("saved %s  %s  (%s)\n", png.c_str(), viewer.status().c_str(), viewer.camera_options().c_str());
  std::fflush(stdout);
  return png;
}

ViewField view_field(const Mesh& mesh, const std::string& spec, bool graded, ColorMapId map) {
  ViewField f;
  f.specs.push_back("");
  for (const Field& field : mesh.fields) f.specs.push_back(field.name);
  f.graded = graded;
  f.map = map;
  if (!spec.empty()) {
    choose_field(mesh, spec);  // throws FieldSelectError for one that is not there
    const auto it = std::find(f.specs.begin(), f.specs.end(), spec);
    if (it == f.specs.end()) f.specs.push_back(spec);
    f.current = std::size_t(std::find(f.specs.begin(), f.specs.end(), spec) - f.specs.begin());
  }
  return f;
}

namespace {

bool scaled_by_corners(const ViewField& f) { return f.graded || f.volume || f.iso_translucent; }

// The scale again where the mode changed which values it is of (apply_field).
void rescale(Viewer& viewer, ViewField& f) {
  if (!f.specs[f.current].empty() && f.scale_of_corners != scaled_by_corners(f)) apply_field(viewer, f);
}

ColorLegend legend_of(const ViewField& f) {
  ColorLegend l;
  l.title = f.choice.label;
  l.unit = f.unit;
  l.scale = f.scale;
  if (f.iso_on) l.marks = {f.iso_value};
  return l;
}

// The scene's width for the legend as it is now: the panel taken from the full width, or all of it.
void fit_legend(Viewer& viewer, ViewField& f) {
  const int height = viewer.framebuffer().height;
  int panel = 0;
  if (f.legend && !f.specs[f.current].empty()) {
    panel = legend_width(*f.text, legend_of(f));
    if (f.full_width - panel < 64 || height < legend_min_height()) panel = 0;  // no room: no legend
  }
  f.legend = panel > 0;
  if (panel != f.panel || viewer.framebuffer().width != f.full_width - panel) {
    f.panel = panel;
    resize_view(viewer, f, f.full_width - panel, height);
  }
}

bool same_camera(const Camera& a, const Camera& b) {
  for (int k = 0; k < 3; ++k)
    if (a.eye[k] != b.eye[k] || a.at[k] != b.at[k] || a.up[k] != b.up[k]) return false;
  return a.perspective == b.perspective && a.fov_deg == b.fov_deg && a.ortho_height == b.ortho_height;
}

}  // namespace

void resize_view(Viewer& viewer, ViewField& f, int width, int height) {
  if (f.fitted && same_camera(viewer.camera(), *f.fitted) && width > 0 && height > 0) {
    f.fitted = camera_for(f.camera_options, f.box_lo, f.box_hi, double(width) / height);
    viewer.resize(width, height);
    viewer.set_camera(*f.fitted);
    return;
  }
  viewer.resize(width, height);
}

bool toggle_legend(Viewer& viewer, ViewField& f) {
  if (f.specs[f.current].empty()) return false;
  if (!f.text) f.text = std::make_shared<const TextRenderer>(find_font_file());
  if (!f.legend) f.full_width = viewer.framebuffer().width;
  f.legend = !f.legend;
  fit_legend(viewer, f);
  return true;
}

Framebuffer presented(const Viewer& viewer, const ViewField& f) {
  const Framebuffer& scene = viewer.framebuffer();
  if (!f.legend || f.panel <= 0) return scene;
  Framebuffer out(scene.width + f.panel, scene.height);
  for (int y = 0; y < scene.height; ++y) {
    std::copy_n(scene.rgba.begin() + std::ptrdiff_t(scene.index(0, y)), scene.width,
                out.rgba.begin() + std::ptrdiff_t(out.index(0, y)));
    std::copy_n(scene.id.begin() + std::ptrdiff_t(scene.index(0, y)), scene.width,
                out.id.begin() + std::ptrdiff_t(out.index(0, y)));
  }
  draw_color_legend(out, *f.text, legend_of(f), PixelRect{scene.width, 0, out.width - 1, out.height - 1});
  return out;
}

void apply_field(Viewer& viewer, ViewField& f) {
  const std::string& spec = f.specs[f.current];
  if (spec.empty()) {
    viewer.set_field(nullptr);
    if (f.legend) fit_legend(viewer, f);  // region colours: no legend
    return;
  }
  const Mesh& mesh = viewer.mesh();
  f.choice = choose_field(mesh, spec);
  f.step = f.choice.field->step_count() - 1;
  const std::vector<double> values =
      f.graded ? tet_corner_values(mesh, f.choice, f.step) : tet_centroid_values(mesh, f.choice, f.step);
  f.scale_of_corners = scaled_by_corners(f);
  const std::vector<double> corner_values =
      f.scale_of_corners && !f.graded ? tet_corner_values(mesh, f.choice, f.step) : std::vector<double>{};
  const std::vector<double>& ranged = f.scale_of_corners && !f.graded ? corner_values : values;
  f.no_value =
      std::size_t(std::count_if(ranged.begin(), ranged.end(), [](double v) { return std::isnan(v); }));
  // foxi render's automatic range (a constant widened, coolwarm centred on 0); no finite value: all
  // drawn in the no-value grey over [0, 1].
  const std::optional<AutoScale> automatic = automatic_scale(ranged, f.map);
  f.scale = ColorScale{};
  f.scale.map = f.map;
  f.scale.lo = 0;
  f.scale.hi = 1;
  if (automatic) f.scale = automatic->scale;
  f.unit = default_display_unit(f.choice.field->unit, std::max(std::abs(f.scale.lo), std::abs(f.scale.hi)));
  viewer.set_field(std::make_shared<const FieldPaint>(f.graded ? graded_field_paint(values, f.scale)
                                                               : flat_field_paint(values, f.scale)));
  if (f.legend) fit_legend(viewer, f);  // another field's labels may need another width
}

void next_field(Viewer& viewer, ViewField& f) {
  if (f.iso_on) {  // the isosurface belongs to the field it was of
    viewer.set_iso(nullptr, {});
    f.iso_on = false;
  }
  // The view borrows the corner values for translucent isosurfaces and the volume: let go first.
  if (f.iso_translucent || f.volume) viewer.set_translucent(nullptr);
  f.corner.clear();
  f.tree.reset();
  f.current = (f.current + 1) % f.specs.size();
  apply_field(viewer, f);
  if (f.xray || f.iso_translucent || f.volume) apply_composite(viewer, f);  // of the new field
}

void apply_composite(Viewer& viewer, ViewField& f) {
  const bool field = !f.specs[f.current].empty();
  if (!field) f.iso_translucent = f.volume = false;
  if (f.iso_on) {  // the opaque isosurface gives way
    f.iso_on = false;
    viewer.set_iso(nullptr, {});
  }
  rescale(viewer, f);
  if ((f.iso_translucent || f.volume) && f.corner.empty()) {
    f.corner = tet_corner_values(viewer.mesh(), f.choice, f.step);
    f.tree = std::make_shared<const TetIntervals>(f.corner);
  }
  if (f.volume) {
    VolumeParams vp = default_volume(viewer.mesh(), f.scale);
    if (!f.curve.empty()) {
      vp.opacity_curve.clear();
      for (const OpacityPoint& p : f.curve) vp.opacity_curve.push_back({f.unit.to_si(p.value), p.opacity});
    }
    f.volume_params = vp;
    viewer.set_volume(f.corner, &f.volume_params);
    return;
  }
  if (f.xray || f.iso_translucent) {
    TranslucentParams tp;
    tp.regions = f.xray;
    tp.region_opacity = f.xray_regions.empty() ? default_xray(viewer.mesh()) : f.xray_regions;
    if (f.iso_translucent) {
      const auto [lo, hi] = finite_range(f.corner);
      if (!(lo < hi))
        std::fprintf(stderr, "foxi-view: note: %s has no two different values: no isosurfaces\n",
                     f.choice.label.c_str());
      tp.corner = f.corner;
      tp.iso.scale = f.scale;
      for (int k = 1; k <= f.iso_count; ++k)  // inside the range, its ends left out
        tp.iso.values.push_back(f.scale.lo + (f.scale.hi - f.scale.lo) * k / (f.iso_count + 1));
      tp.iso_opacity = f.iso_opacity;
    }
    f.translucent = tp;
    viewer.set_translucent(&f.translucent);
    return;
  }
  viewer.set_translucent(nullptr);
}

namespace {

// Translucency and the volume draw whole tets (as foxi render, which refuses --shrink with them).
void check_unshrunk(const Viewer& viewer) {
  if (viewer.shrink() != 1)
    throw std::invalid_argument(
        "the x-ray, translucent isosurfaces and the volume draw whole tets: start without --shrink");
}

}  // namespace

bool toggle_xray(Viewer& viewer, ViewField& f) {
  if (!f.xray) check_unshrunk(viewer);
  f.xray = !f.xray;
  if (f.xray) f.volume = false;
  apply_composite(viewer, f);
  return true;
}

bool toggle_iso_translucent(Viewer& viewer, ViewField& f) {
  if (f.specs[f.current].empty()) return false;
  if (!f.iso_translucent) check_unshrunk(viewer);
  f.iso_translucent = !f.iso_translucent;
  if (f.iso_translucent) f.volume = false;
  apply_composite(viewer, f);
  return true;
}

bool toggle_volume(Viewer& viewer, ViewField& f) {
  if (f.specs[f.current].empty()) return false;
  if (!f.volume) check_unshrunk(viewer);
  f.volume = !f.volume;
  if (f.volume) f.xray = f.iso_translucent = false;
  apply_composite(viewer, f);
  return true;
}

bool set_iso(Viewer& viewer, ViewField& f, double value, bool iso_only) {
  if (f.specs[f.current].empty()) return false;
  if (!f.tree) {
    f.corner = tet_corner_values(viewer.mesh(), f.choice, f.step);
    f.tree = std::make_shared<const TetIntervals>(f.corner);
  }
  f.xray = f.iso_translucent = f.volume = false;  // the opaque isosurface ends compositing (the view's too)
  rescale(viewer, f);
  f.iso_on = true;
  f.iso_only = iso_only;
  f.iso_value = f.unit.to_si(value);
  const auto [lo, hi] = finite_range(f.corner);
  if (!(f.iso_value >= lo && f.iso_value <= hi))  // as foxi render warns
    std::fprintf(
        stderr,
        "foxi-view: note: isovalue %g %s lies outside the field's values (%g to %g %s): no isosurface\n",
        value, f.unit.symbol.c_str(), f.unit.to_display(lo), f.unit.to_display(hi), f.unit.symbol.c_str());
  f.drawing = IsoDrawing{};
  f.drawing.corner = f.corner;
  f.drawing.params.values = {f.iso_value};
  f.drawing.params.scale = f.scale;
  f.drawing.params.cap = !iso_only;
  std::vector<std::uint32_t> tets;  // as foxi render --iso: the crossing tets, or the solid's
  if (iso_only)
    f.tree->crossing(f.iso_value, tets);
  else
    f.tree->reaching(f.iso_value, tets);
  viewer.set_iso(&f.drawing, std::move(tets));
  return true;
}

void toggle_iso(Viewer& viewer, ViewField& f) {
  if (f.iso_on) {
    viewer.set_iso(nullptr, {});
    f.iso_on = false;
    return;
  }
  f.xray = f.iso_translucent = f.volume = false;  // the opaque isosurface ends compositing
  rescale(viewer, f);
  set_iso(viewer, f, f.unit.to_display(0.5 * (f.scale.lo + f.scale.hi)), f.iso_only);
}

void toggle_iso_only(Viewer& viewer, ViewField& f) {
  if (f.iso_on) set_iso(viewer, f, f.unit.to_display(f.iso_value), !f.iso_only);
}

void move_iso(Viewer& viewer, ViewField& f, double steps) {
  if (!f.iso_on) return;
  const double v = std::clamp(f.iso_value + steps * (f.scale.hi - f.scale.lo) / 20, f.scale.lo, f.scale.hi);
  set_iso(viewer, f, f.unit.to_display(v), f.iso_only);
}

void next_map(Viewer& viewer, ViewField& f) {
  const ColorMapId maps[] = {ColorMapId::viridis, ColorMapId::cividis, ColorMapId::coolwarm,
                             ColorMapId::rainbow};
  std::size_t i = 0;
  while (i < 4 && maps[i] != f.map) ++i;
  f.map = maps[(i + 1) % 4];
  if (!f.specs[f.current].empty()) {
    apply_field(viewer, f);
    if (f.iso_translucent || f.volume) apply_composite(viewer, f);  // coloured by the new map
  }
}

std::string value_under(const Viewer& viewer, const ViewField& f, int x, int y, int digits) {
  const std::uint32_t t = viewer.pick(x, y);
  if (t == kNone) return "background";
  const Mesh& mesh = viewer.mesh();
  const Framebuffer& fb = viewer.framebuffer();
  double b[4];
  char buf[256];
  const std::uint32_t region = mesh.tet_region.empty() ? 0 : mesh.tet_region[t];
  if (!pixel_point_in_tet(mesh, viewer.camera(), fb.width, fb.height, t, x, y, b, viewer.shrink())) {
    std::snprintf(buf, sizeof buf, "tet %u, region %u", t, region);
    return buf;
  }
  double p[3] = {0, 0, 0};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      p[k] +=
          b[i] * mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(t) + std::size_t(i)]) + std::size_t(k)];
  std::string value;
  if (!f.specs[f.current].empty()) {
    const double v = field_value_in_tet(mesh, f.choice, t, b, f.step);
    std::snprintf(buf, sizeof buf, "%s %.*g%s%s ", f.choice.label.c_str(), digits, f.unit.to_display(v),
                  f.unit.symbol.empty() ? "" : " ", f.unit.symbol.c_str());
    value = buf;
  }
  std::snprintf(buf, sizeof buf, "at (%.*g, %.*g, %.*g), tet %u, region %u", digits, p[0], digits, p[1],
                digits, p[2], t, region);
  return value + buf;
}

namespace {

std::string composite_status(const ViewField& f) {
  std::string s;
  char buf[128];
  if (f.xray) {
    s += "x-ray ";
    const std::vector<RegionOpacity>& r = f.translucent.region_opacity;
    for (std::size_t i = 0; i < r.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%s%d:%.2g", i ? "," : "", r[i].region, r[i].opacity);
      s += buf;
    }
    s += " (others opaque)";
  }
  if (f.iso_translucent) {
    std::snprintf(buf, sizeof buf, "%s%d translucent isosurfaces, opacity %.2g", s.empty() ? "" : "; ",
                  int(f.translucent.iso.values.size()), f.iso_opacity);
    s += buf;
  }
  if (f.volume) {
    s += "volume, opacity ";
    for (std::size_t i = 0; i < f.volume_params.opacity_curve.size(); ++i) {
      const OpacityPoint& p = f.volume_params.opacity_curve[i];
      std::snprintf(buf, sizeof buf, "%s%.4g:%.2g", i ? "," : "", f.unit.to_display(p.value), p.opacity);
      s += buf;
    }
  }
  if ((f.volume || f.iso_translucent) && f.no_value > 0) {
    std::snprintf(buf, sizeof buf, "; %zu corner values NaN: their tets left out", f.no_value);
    s += buf;
  }
  return s;
}

}  // namespace

std::string field_status(const ViewField& f) {
  const std::string composite = composite_status(f);
  if (f.specs[f.current].empty()) return composite;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s, %s%s, %.4g to %.4g%s%s", f.choice.label.c_str(), color_map_name(f.map),
                f.graded ? ", graded" : "", f.unit.to_display(f.scale.lo), f.unit.to_display(f.scale.hi),
                f.unit.symbol.empty() ? "" : " ", f.unit.symbol.c_str());
  std::string s = buf;
  if (f.iso_on) {
    std::snprintf(buf, sizeof buf, ", %s %.4g%s%s", f.iso_only ? "isosurface" : "solid above",
                  f.unit.to_display(f.iso_value), f.unit.symbol.empty() ? "" : " ", f.unit.symbol.c_str());
    s += buf;
  }
  if (!composite.empty()) s += "; " + composite;
  return s;
}

void run_script(Viewer& viewer, ViewField& field, const std::string& script, const std::string& prefix,
                bool dump) {
  std::istringstream in(script);
  std::string cmd;
  while (in >> cmd) {
    const std::size_t colon = cmd.find(':');
    const std::string name = cmd.substr(0, colon),
                      arg = colon == std::string::npos ? "" : cmd.substr(colon + 1);
    auto args = [&](std::size_t count) {
      auto v = parse_number_list(arg, name);
      if (v.size() != count)
        throw std::invalid_argument("script command '" + cmd + "' takes " + std::to_string(count) +
                                    " numbers");
      return v;
    };
    if (cmd == "d") {
      viewer.restart();
      viewer.finish();
    } else if (cmd == "c") {
      viewer.restart();
    } else if (cmd == "n") {
      viewer.step();
    } else if (cmd == "f") {
      viewer.set_undrawing(false);
      viewer.finish();
    } else if (name == "u") {
      if (!viewer.set_undrawing(true))
        throw std::invalid_argument(
            "script: 'u' needs the painter (a Delaunay mesh) and no --no-undo (compositing: a Delaunay "
            "mesh)");
      if (arg.empty()) {
        while (viewer.step()) {
        }
      } else {
        const double k = args(1)[0];
        if (!(k >= 0 && k == std::floor(k))) throw std::invalid_argument("u:N takes a whole number of tets");
        viewer.undraw(std::size_t(k));
      }
    } else if (cmd == "r") {
      if (viewer.translucent())
        throw std::invalid_argument(
            "script: 'r' (a region of interest) is refused while the x-ray or translucent isosurfaces are "
            "on: turn them off first");
      if (!viewer.push_region()) throw std::invalid_argument("script: 'r' with no tets drawn");
    } else if (cmd == "b") {
      viewer.pop_region();
    } else if (cmd == "s") {
      save_next(viewer, prefix, dump, &field);
    } else if (name == "orbit") {
      auto v = args(2);
      viewer.orbit(v[0], v[1]);
    } else if (name == "zoom") {
      auto v = args(1);
      if (!(v[0] > 0)) throw std::invalid_argument("zoom takes a factor > 0");
      viewer.zoom(v[0]);
    } else if (name == "probe") {
      auto v = args(2);
      std::printf("probe %g,%g: %s\n", v[0], v[1],
                  value_under(viewer, field, int(v[0]), int(v[1]), 9).c_str());
      std::fflush(stdout);
    } else if (name == "iso" || name == "iso-only") {
      if (!set_iso(viewer, field, args(1)[0], name == "iso-only"))
        throw std::invalid_argument("script: '" + cmd +
                                    "' draws a field's isosurface: give --field or 'field' first");
    } else if (cmd == "legend") {
      const bool was = field.legend;
      if (!toggle_legend(viewer, field))
        throw std::invalid_argument("script: 'legend' needs a field: give --field");
      if (field.legend)
        std::printf("legend on, %d pixels at the right\n", field.panel);
      else if (!was)  // as foxi render refuses a --size that leaves no room for it
        std::printf("legend off: no room in a %dx%d picture\n", viewer.framebuffer().width,
                    viewer.framebuffer().height);
      else
        std::printf("legend off\n");
      std::fflush(stdout);
    } else if (cmd == "i") {  // the key: on at the middle of the range, or off
      if (field.specs[field.current].empty())
        throw std::invalid_argument("script: 'i' needs a field: give --field");
      toggle_iso(viewer, field);
    } else if (cmd == "noiso") {
      if (field.iso_on) toggle_iso(viewer, field);
    } else if (cmd == "xray") {
      toggle_xray(viewer, field);
    } else if (cmd == "isoalpha" || cmd == "volume") {
      if (!(cmd == "volume" ? toggle_volume(viewer, field) : toggle_iso_translucent(viewer, field)))
        throw std::invalid_argument("script: '" + cmd + "' needs a field: give --field");
    } else if (cmd == "status") {
      std::printf("status %s%s%s\n", viewer.status().c_str(), field_status(field).empty() ? "" : "  |  ",
                  field_status(field).c_str());
      std::fflush(stdout);
    } else if (cmd == "field") {
      next_field(viewer, field);
    } else if (cmd == "map") {
      next_map(viewer, field);
    } else if (name == "pan") {
      auto v = args(2);
      viewer.pan(v[0], v[1]);
    } else {
      throw std::invalid_argument("unknown script command '" + cmd +
                                  "' (d c n f u u:N r b s orbit:Y,P zoom:F pan:X,Y probe:X,Y field map i "
                                  "iso:V iso-only:V noiso legend xray isoalpha volume status)");
    }
  }
}

}  // namespace foxi::view
