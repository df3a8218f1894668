// foxi render MESH: a picture of the mesh's interior by the software painter (tets back to front in
// the power-function visibility order, front faces only, no depth buffer), written as a PNG.
#include <cctype>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "composite_options.hpp"
#include "exit_codes.hpp"
#include "field_options.hpp"
#include "iso_options.hpp"
#include "mesh_input.hpp"
#include "render_options.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/depth_stop.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/view_options.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi::cli {

namespace {

// Whether every pixel is the background colour: a blank picture is said, not only written (a curve
// of opacity 0 where the field's values are, every region at opacity 0, a camera that sees no tet;
// an outside probe found such pictures written without a word).
bool blank(const Framebuffer& fb, std::uint32_t background) {
  return std::all_of(fb.rgba.begin(), fb.rgba.end(), [&](std::uint32_t c) { return c == background; });
}

}  // namespace

namespace {

const std::string kRenderUsage =
    std::string(
        "foxi render MESH [--eye x,y,z --at x,y,z --up x,y,z --fov deg | --dir x,y,z] [--size WxH]\n"
        "                 [--stop P%] [--depth d] [--zbuffer] [--shrink f] [--regions a,b] [--no-edges]\n"
        "                 [--field NAME[:C] [--graded] [--cmap M] [--range a,b] [--log] [--units U] [--step "
        "k]\n"
        "                 [--legend on|off] [--markers] [--iso v1,v2,... [--iso-only]] [--threshold a,b]\n"
        "                 [--clip px,py,pz,nx,ny,nz] [--slice px,py,pz,nx,ny,nz]] [--deform NAME:SCALE]\n"
        "                 [--region-opacity REGION=a,... ] [--iso-opacity a]\n"
        "                 [--volume NAME[:C] [--cmap M] [--range a,b] --opacity-curve v0:a0,v1:a1,...\n"
        "                 [--opacity-length L]] -o OUT.png\n"
        "  Draws the tets back to front in the power-function visibility order, each showing its front\n"
        "  faces flat-shaded in its region's colour (or a field's) with the mesh edges darkened (no depth\n"
        "  buffer).\n") +
    kPictureOptionsHelp + kFieldOptionsHelp + kIsoOptionsHelp +
    "  (--size defaults to 1280x960)\n"
    "  --stop P%       draw only the first P percent of the back-to-front order (the far part)\n"
    "  --depth d       stop at the first tet whose power distance from the eye, sqrt(|eye-c|^2-r^2)\n"
    "                  for its circumsphere (c, r), is below d (world units; the order decreases in\n"
    "                  it); orthographic: the circumcentre's distance in front of the plane through\n"
    "                  --at across the view. With --stop, whichever stops first\n"
    "  --zbuffer       draw with a depth buffer instead (the oracle; order irrelevant)\n"
    "  Meshes that fail the Delaunay certificate have no guaranteed order: their picture is drawn\n"
    "  with the depth buffer (in MPVO order, so --stop still takes the far part) and a note says so.\n" +
    kDeformOptionHelp + kCompositeOptionsHelp +
    "  (--region-opacity, --iso-opacity and --volume not with --stop, --depth, --zbuffer)\n"
    "  Inverted tets are re-oriented (a note says so); an unusable mesh (see foxi info) is refused\n"
    "  with exit status 3, and no picture is written.";

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int cmd_render(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kRenderUsage.c_str());
    return kExitOk;
  }
  // First: --volume NAME is the field to draw (the field options apply to it).
  const CompositeOptions composite = take_composite_options(args);
  const std::string stop_s = args.option("--stop"), depth_s = args.option("--depth");
  std::string out = args.option("-o");
  if (out.empty()) out = args.option("--output");
  const bool zbuffer = args.flag("--zbuffer");
  PictureOptions options = take_picture_options(args, "1280x960");
  FieldOptions field_options = take_field_options(args);
  // A volume and translucent isosurfaces show the field between the nodes: the range is theirs.
  field_options.corner_range = composite.volume_on() || composite.has_iso_opacity;
  const IsoOptions iso_options = take_iso_options(args, field_options);
  const std::optional<DeformOption> deform = take_deform_option(args);
  const bool translucent = composite.translucent(), volume = composite.volume_on();
  if ((translucent || volume) && (!stop_s.empty() || !depth_s.empty() || zbuffer))
    throw UsageError(std::string(volume ? "--volume" : "--region-opacity and --iso-opacity") +
                     " composite the whole picture: leave out --stop, --depth and --zbuffer");
  check_composite_options(composite, field_options, iso_options, options.params.shrink);
  const std::string path = args.positional(1, 1, kRenderUsage)[0];
  if (out.empty()) throw UsageError("give the output file with -o OUT.png\nusage: " + kRenderUsage);
  {
    // It writes PNG: another image extension would hold PNG bytes under a name that says otherwise.
    std::string ext = std::filesystem::path(out).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".gif" || ext == ".bmp" || ext == ".tif" ||
        ext == ".tiff" || ext == ".ppm" || ext == ".webp")
      throw UsageError("-o " + out + ": foxi render writes PNG pictures: give a .png name");
  }
  check_output_path(out);
  int width = options.width, height = options.height;
  double stop = 1;
  if (!stop_s.empty()) {
    std::string s = stop_s;
    if (!s.empty() && s.back() == '%') s.pop_back();
    char* end = nullptr;
    double p = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != 0 || !(p >= 0 && p <= 100))
      throw UsageError("--stop takes a percentage 0..100, e.g. 40%");
    stop = p / 100;
  }
  double depth_stop = -std::numeric_limits<double>::infinity();
  if (!depth_s.empty()) {
    char* end = nullptr;
    depth_stop = std::strtod(depth_s.c_str(), &end);
    if (*end != 0 || !std::isfinite(depth_stop)) throw UsageError("--depth takes a distance, e.g. 0.5");
  }
  RenderParams params = options.params;

  Mesh read = read_usable_mesh(path, "render");
  const double moved = deform ? apply_deform(read, *deform, path, "render") : 0;
  const Mesh& mesh = read;
  Picture picture = resolve_picture(options, mesh);
  // Colour by a field: the legend's panel is taken from the picture's width, the camera fitted to the rest.
  FieldPicture field;
  std::unique_ptr<TextRenderer> text;
  int panel = 0;
  if (!field_options.spec.empty()) {
    field = resolve_field(field_options, mesh, picture.subset, path);
    params.field = field.paint;
    if (field_options.legend) {
      text = std::make_unique<TextRenderer>(find_font_file());
      panel = legend_panel(*text, field, options.width, options.height);
      options.width -= panel;
      picture = resolve_picture(options, mesh);
    }
  }
  // Isosurfaces, slices and subsets by the field: the tets to order instead of the picture's subset.
  IsoPicture iso;
  if (iso_options.any()) {
    iso = resolve_iso(iso_options, mesh, field, picture.subset);
    field.legend.marks = iso.iso_si;
    warn_iso_outside(iso, field);
  }
  const std::vector<std::uint32_t>& subset = iso_options.any() ? iso.subset : picture.subset;
  const IsoDrawing iso_drawing = iso.drawing();
  const Camera& camera = picture.camera;

  auto t0 = std::chrono::steady_clock::now();
  const SphereTable table = compute_spheres(mesh);
  const double spheres_ms = ms_since(t0);
  if (volume) {
    const VolumeParams vp = volume_params(composite, mesh, field, picture.subset);
    const std::vector<double> corner = tet_corner_values(mesh, field.choice, field.step);
    Framebuffer fb(options.width, height);
    const VolumeReport report = draw_volume_picture(mesh, table, camera, fb, picture.subset, corner, vp);
    write_png(out, field_options.legend ? with_legend(fb, *text, field, panel) : fb);
    std::printf("mesh        %s: %zu tets, %zu drawn\n", path.c_str(), mesh.tet_count(), report.tets);
    std::printf("certificate %s (%.1f ms); spheres %.1f ms\n", report.delaunay ? "Delaunay" : "NOT Delaunay",
                report.certificate_ms, spheres_ms);
    std::printf("volume      %s, %s, colours %.6g to %.6g %s; opacity over %g world units\n",
                field.legend.title.c_str(), color_map_name(vp.scale.map),
                field.legend.unit.to_display(vp.scale.lo), field.legend.unit.to_display(vp.scale.hi),
                field.legend.unit.symbol.c_str(), vp.unit_length);
    if (field.no_value > 0)
      std::printf(
          "warning     %zu corner values are NaN or infinite: the tets with one are left out (transparent)\n",
          field.no_value);
    // A curve wholly beside the values (given in another unit, say) is one opacity everywhere.
    if (!vp.opacity_curve.empty() && std::isfinite(field.data_lo) &&
        (vp.opacity_curve.back().value < field.data_lo || vp.opacity_curve.front().value > field.data_hi)) {
      const DisplayUnit& u = field.legend.unit;
      std::printf(
          "warning     the opacity curve (%g to %g %s) lies wholly %s the field's values (%g to %g %s): one "
          "opacity throughout\n",
          u.to_display(vp.opacity_curve.front().value), u.to_display(vp.opacity_curve.back().value),
          u.symbol.c_str(), vp.opacity_curve.back().value < field.data_lo ? "below" : "above",
          u.to_display(field.data_lo), u.to_display(field.data_hi), u.symbol.c_str());
    }
    if (report.exact_order)
      std::printf(
          "composited back to front in the power order (exact for this Delaunay mesh), order %.1f ms, "
          "integration %.1f ms: %zu pixel segments, %dx%d\n",
          report.order_ms, report.draw_ms, report.samples, options.width, height);
    else
      std::printf(
          "composited in MPVO order, NOT exact (no visibility order without the certificate; %zu cycles "
          "broken), order %.1f ms, integration %.1f ms: %zu pixel segments, %dx%d\n",
          report.cycles_broken, report.order_ms, report.draw_ms, report.samples, options.width, height);
    if (blank(fb, vp.background))
      std::printf(
          "warning     the picture is blank: no segment left a colour (the opacity curve is 0 where the "
          "field's values are, or the camera sees no tet)\n");
    std::printf("wrote       %s\n", out.c_str());
    return kExitOk;
  }
  if (translucent) {
    const TranslucentParams tp = translucent_params(composite, mesh, params, iso);
    Framebuffer fb(options.width, height);
    const TranslucentReport report = draw_translucent_picture(mesh, table, camera, fb, picture.subset, tp);
    write_png(out, field.paint && field_options.legend ? with_legend(fb, *text, field, panel) : fb);
    std::size_t covered = 0;
    for (std::uint32_t id : fb.id) covered += id != kNone;
    std::printf("mesh        %s: %zu tets\n", path.c_str(), mesh.tet_count());
    std::printf("certificate %s (%.1f ms); spheres %.1f ms\n", report.delaunay ? "Delaunay" : "NOT Delaunay",
                report.certificate_ms, spheres_ms);
    std::printf("translucent ");
    for (std::size_t i = 0; i < tp.region_opacity.size(); ++i)
      std::printf("%sregion %d opacity %g", i ? ", " : "", tp.region_opacity[i].region,
                  tp.region_opacity[i].opacity);
    if (!tp.region_opacity.empty()) std::printf(" (others opaque); ");
    if (!iso_options.iso.empty()) std::printf("isosurfaces opacity %g; ", tp.iso_opacity);
    std::printf("%zu tets own a surface (%.1f ms)\n", report.tets_ordered, report.surfaces_ms);
    if (!iso_options.iso.empty() && field.no_value > 0)
      std::printf(
          "warning     %zu corner values are NaN or infinite: no isosurface crosses the tets with one\n",
          field.no_value);
    std::printf(
        "composited %s, order %.1f ms, blending %.1f ms: %zu fragments, %dx%d, %.1f%% of pixels covered\n",
        report.exact_order ? "back to front in the power order (exact for this Delaunay mesh)"
                           : "by sorting each pixel's fragments by depth (no exact order without the "
                             "certificate)",
        report.order_ms, report.draw_ms, report.fragments, options.width, height,
        100.0 * double(covered) / double(fb.id.size()));
    if (blank(fb, tp.background))
      std::printf(
          "warning     the picture is blank: every pixel is the background (every surface drawn has "
          "opacity 0, or the camera sees no tet)\n");
    std::printf("wrote       %s\n", out.c_str());
    return kExitOk;
  }
  PictureParams pp;
  pp.render = params;
  pp.render.depth_buffer = zbuffer;
  pp.subset = subset;
  pp.subset_exact = iso_options.any();
  if (iso.polygons) pp.iso = &iso_drawing;
  pp.stop_fraction = stop;
  pp.stop_depth = depth_stop;
  width = options.width;
  Framebuffer fb(width, height);
  const PictureReport report = draw_picture(mesh, table, camera, fb, pp);
  const bool delaunay = report.delaunay;
  const std::size_t count = report.tets_drawn;
  MarkerReport markers;
  if (field.paint && field_options.markers) {
    if (!text) text = std::make_unique<TextRenderer>(find_font_file());
    markers = draw_extreme_markers(fb, camera, *text, field);
  }
  write_png(out, field.paint && field_options.legend ? with_legend(fb, *text, field, panel) : fb);

  std::size_t covered = 0;
  for (std::uint32_t id : fb.id) covered += id != kNone;
  std::printf("mesh        %s: %zu tets, %zu selected\n", path.c_str(), mesh.tet_count(),
              report.tets_ordered);
  std::printf("certificate %s (%.1f ms); spheres %.1f ms\n",
              delaunay ? "Delaunay" : "NOT Delaunay: picture drawn with the depth buffer",
              report.certificate_ms, spheres_ms);
  if (camera.perspective)
    std::printf("camera      perspective eye (%g, %g, %g) at (%g, %g, %g) up (%g, %g, %g) fov %g\n",
                camera.eye[0], camera.eye[1], camera.eye[2], camera.at[0], camera.at[1], camera.at[2],
                camera.up[0], camera.up[1], camera.up[2], camera.fov_deg);
  else
    std::printf("camera      orthographic along (%g, %g, %g), height %g\n", camera.at[0] - camera.eye[0],
                camera.at[1] - camera.eye[1], camera.at[2] - camera.eye[2], camera.ortho_height);
  const bool mpvo = report.method == OrderMethod::mpvo;
  if (deform)
    std::printf("deformed    by %s x %g: nodes moved up to %g; drawn %s\n", deform->name.c_str(),
                deform->scale, moved,
                mpvo ? "in MPVO order with the depth buffer (the deformed mesh is not Delaunay)"
                     : "by the painter in the power order (the deformed mesh is still Delaunay)");
  std::printf("order       %s, %.1f ms%s\n", mpvo ? "MPVO" : "power (visibility order)", report.order_ms,
              mpvo ? (", " + std::to_string(report.cycles_broken) + " cycles broken").c_str() : "");
  std::printf("drawn       %zu of %zu tets (%.0f%%) in %s mode, %.1f ms, %dx%d, %.1f%% of pixels covered",
              count, report.tets_ordered,
              report.tets_ordered == 0 ? 0.0 : 100.0 * double(count) / double(report.tets_ordered),
              report.depth_buffer ? "depth-buffer" : "painter", report.draw_ms, width, height,
              100.0 * double(covered) / double(fb.id.size()));
  if (!depth_s.empty() && count > 0)
    std::printf(", stopped at depth %g (last tet drawn at %g)", depth_stop,
                tet_depth(table, camera, report.last_drawn));
  if (report.raster.tets_behind > 0) std::printf(", %zu tets behind the eye", report.raster.tets_behind);
  if (covered == 0) std::printf(" (a blank picture: the camera sees no tet of the selection)");
  if (field.paint) {
    const DisplayUnit& u = field.legend.unit;
    const ColorScale& sc = field.legend.scale;
    auto shown = [&](double si) {  // a value in the display unit, with the unit if it has one
      char b[64];
      std::snprintf(b, sizeof b, "%.6g", u.to_display(si));
      return u.symbol.empty() ? std::string(b) : std::string(b) + " " + u.symbol;
    };
    std::printf("\nfield       %s, step %zu of %zu, %s, %s%s: values %.6g to %s, colours %.6g to %s%s",
                field.legend.title.c_str(), field.step, field.choice.field->step_count(),
                field_options.graded ? "graded facets" : "flat per tet (centroid value)",
                color_map_name(sc.map), sc.log ? " log" : "", u.to_display(field.data_lo),
                shown(field.data_hi).c_str(), u.to_display(sc.lo), shown(sc.hi).c_str(),
                field.range_widened   ? " (a constant: range widened around it)"
                : field.range_centred ? " (symmetric about 0 for the diverging map)"
                                      : "");
    if (field.no_value > 0) std::printf(", %zu values NaN (grey)", field.no_value);
    if (!iso_options.iso.empty()) {
      std::printf("\niso         ");
      for (std::size_t i = 0; i < iso.iso_si.size(); ++i)
        std::printf("%s%s", i ? ", " : "", shown(iso.iso_si[i]).c_str());
      std::printf(": %zu tets crossed (interval tree %.1f ms, query %.2f ms), %s", iso.crossing, iso.build_ms,
                  iso.query_ms,
                  iso.params.cap ? "drawn as the solid above the lowest value, cut at its isosurface"
                                 : "isosurfaces alone, the side toward higher values brighter");
    }
    if (iso_options.has_threshold)
      std::printf("\nthreshold   values in [%g, %g] %s", iso_options.threshold[0], iso_options.threshold[1],
                  u.symbol.c_str());
    if (iso_options.clip)
      std::printf("\nclip        whole tets behind the plane through (%g, %g, %g), normal (%g, %g, %g)",
                  iso_options.clip->p[0], iso_options.clip->p[1], iso_options.clip->p[2],
                  iso_options.clip->n[0], iso_options.clip->n[1], iso_options.clip->n[2]);
    if (iso_options.slice)
      std::printf("\nslice       plane through (%g, %g, %g), normal (%g, %g, %g): %zu tets cut",
                  iso_options.slice->p[0], iso_options.slice->p[1], iso_options.slice->p[2],
                  iso_options.slice->n[0], iso_options.slice->n[1], iso_options.slice->n[2], iso.crossing);
    if (field_options.legend)
      std::printf("\nlegend      %d pixels at the right, font %s", panel, text->font_file().c_str());
    if (field_options.markers)
      std::printf("\nmarkers     max %s at (%g, %g, %g) %s; min %s at (%g, %g, %g) %s",
                  shown(field.data_hi).c_str(), field.max_at[0], field.max_at[1], field.max_at[2],
                  markers.max_shown ? "marked" : "hidden in this view", shown(field.data_lo).c_str(),
                  field.min_at[0], field.min_at[1], field.min_at[2],
                  markers.min_shown ? "marked" : "hidden in this view");
  }
  std::printf("\nwrote       %s\n", out.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
