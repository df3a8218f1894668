// foxi-view MESH: a plain libX11 window that draws the inside of a tetrahedral mesh back to front in
// the power-function visibility order, progressively and interruptibly (seed paper, sections 6-7).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "../foxi/exit_codes.hpp"
#include "../foxi/signals.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/viz/view_options.hpp"
#include "viewer.hpp"
#include "x11_window.hpp"

namespace {

const char* kUsage =
    "foxi-view MESH [--size WxH] [--eye x,y,z --at x,y,z --up x,y,z --fov deg | --dir x,y,z]\n"
    "               [--shrink f] [--no-undo] [--field NAME[:C] [--graded] [--cmap M]] [--save PREFIX]\n"
    "               [--region-opacity REGION=a,...] [--iso-opacity a]\n"
    "               [--volume NAME[:C] [--opacity-curve v0:a0,...]] [--script \"COMMANDS\" [--dump-ids]]\n"
    "  Opens a window and draws the mesh back to front in the power-function visibility order,\n"
    "  batch by batch, with a status line (tets drawn / total, %, ms for the draw so far, ms per frame).\n"
    "  Mouse: left-drag orbits, right-drag or wheel zooms, middle-drag pans (each redraws).\n"
    "  Keys: d draw from the back, space stop/continue, n one batch (or one undraw step), u undraw\n"
    "  front to back (1/64 of the set a frame; u again draws on), r region of interest (the tets\n"
    "  drawn so far become the displayed set, re-ordered for each new view), b back up the regions,\n"
    "  f the next field (the mesh's fields in turn, then region colours), m the next colour map\n"
    "  (viridis, cividis, coolwarm, rainbow), l the legend at the right on or off, i the isosurface at the "
    "middle of the range (the solid\n"
    "  above it, as foxi render --iso) on or off, o the surface alone or the solid, [ and ] the\n"
    "  isovalue down or up by 1/20 of the range (only the tets it crosses or reaches are ordered and\n"
    "  drawn), x x-ray on or off (translucent regions: --region-opacity's, by default every region\n"
    "  0.3 but the one with the fewest tets, opaque), t translucent isosurfaces on or off (5 nested\n"
    "  ones across the field's range, opacity --iso-opacity, default 0.35; with x, inside the\n"
    "  translucent regions), v a volume rendering of the field on or off (opacity --opacity-curve\n"
    "  in display units, default a ramp from 0.02 at the low end to 0.5 at the high end, over a tenth\n"
    "  of the mesh box's diagonal), all composited back to front in the power order as foxi render\n"
    "  composites them (a mesh without the certificate: sorted per pixel, or MPVO order for the\n"
    "  volume, NOT exact; the status line says which); u undraws them exactly too (the remaining\n"
    "  far part composited again from the back), s save the picture as PREFIX-NNN.png (default PREFIX\n"
    "  foxi-view), q or Escape quit. The status line shows the field's range and, under the mouse,\n"
    "  the point the pixel shows, its tet and region, and the field's value there.\n"
    "  --field NAME[:C] colour by a field from the start (as foxi render: C a component, mag, vm, p1..p3;\n"
    "  its last step, its automatic range); --graded graded facets; --cmap the colour map.\n"
    "  Camera options as foxi render (same defaults, so the pictures agree); --size default 800x600.\n"
    "  Meshes that fail the Delaunay certificate are drawn with a depth buffer (MPVO order).\n"
    "  Inverted tets are re-oriented (a note says so); an unusable mesh (see foxi info) is refused.\n"
    "  --no-undo draws without recording what undraw needs (faster drawing; u is refused).\n"
    "  --script runs without a window: whitespace-separated commands\n"
    "     d (draw all)  c (restart, draw nothing)  n (one batch)  f (finish, drawing on)\n"
    "     u (undraw all)  u:N (undraw N tets)  r  b  s\n"
    "     orbit:YAW,PITCH (degrees)  zoom:F  pan:DX,DY (fractions of the height)\n"
    "     field  map  legend  i (the keys f, m, l, i)  iso:V  iso-only:V  noiso  xray  isoalpha  volume\n"
    "     (the keys x, t, v) (each restarts without drawing)  status (prints the status line)\n"
    "     probe:X,Y (prints the status line's value under pixel X,Y, 9 digits)\n"
    "  e.g. --script \"d r orbit:30,0 d s\"; --dump-ids also writes PREFIX-NNN.ids (the id buffer,\n"
    "  uint32 little-endian) and PREFIX-NNN.tets (the drawn tets, in drawing order).\n"
    "  Environment: FOXI_VIEW_NO_SHM=1 uses plain XPutImage even where XShm is available.\n"
    "  Exit status as foxi's: 0 ok, 1 failure, 2 usage error, 3 unreadable or unusable mesh.";

struct Usage : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A mesh not fit to view (exit status 3).
struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace

int main(int argc, char** argv) {
  using namespace foxi::cli;
  // SIGINT, SIGTERM, SIGHUP: exit 130/143/129 with a message, a save under way left unfinished and
  // its temporary removed (the durable writers' cleanup list).
  handle_stop_signals("foxi-view");
  try {
    // --name=value as --name value, as foxi reads it.
    const std::vector<std::string> args = foxi::split_option_values({argv + 1, argv + argc});
    std::string mesh_path, size = "800x600", eye, at, up, fov, dir, shrink, save = "foxi-view", script;
    std::string field_spec, cmap, region_opacity, iso_opacity, volume, curve;
    bool script_mode = false, dump = false, no_undo = false, graded = false;
    std::vector<std::string> seen;  // as foxi refuses an option given twice, so does the viewer
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= args.size()) throw Usage(a + " takes a value");
        if (args[i + 1].empty()) throw Usage("option " + a + " takes a value, not an empty one");
        return args[++i];
      };
      if (a.rfind("--", 0) == 0) {
        const std::string name = a == "--batch" ? "--script" : a;
        if (std::find(seen.begin(), seen.end(), name) != seen.end())
          throw Usage("option " + a + " given twice (give it once)");
        seen.push_back(name);
      }
      if (a == "--help" || a == "-h") {
        std::puts(kUsage);
        return kExitOk;
      } else if (a == "--size") {
        size = value();
      } else if (a == "--eye") {
        eye = value();
      } else if (a == "--at") {
        at = value();
      } else if (a == "--up") {
        up = value();
      } else if (a == "--fov") {
        fov = value();
      } else if (a == "--dir") {
        dir = value();
      } else if (a == "--shrink") {
        shrink = value();
      } else if (a == "--save") {
        save = value();
      } else if (a == "--script" || a == "--batch") {
        script = value();
        script_mode = true;
      } else if (a == "--dump-ids") {
        dump = true;
      } else if (a == "--field") {
        field_spec = value();
      } else if (a == "--cmap") {
        cmap = value();
      } else if (a == "--region-opacity") {
        region_opacity = value();
      } else if (a == "--iso-opacity") {
        iso_opacity = value();
      } else if (a == "--volume") {
        volume = value();
      } else if (a == "--opacity-curve") {
        curve = value();
      } else if (a == "--graded") {
        graded = true;
      } else if (a == "--no-undo") {
        no_undo = true;
      } else if (a.rfind("-", 0) == 0) {
        throw Usage("unknown option " + a);
      } else if (mesh_path.empty()) {
        mesh_path = a;
      } else {
        throw Usage("one mesh file only");
      }
    }
    if (mesh_path.empty()) throw Usage("give a mesh file");
    int width = 0, height = 0;
    foxi::RenderParams params;
    params.undoable = !no_undo;
    try {
      const foxi::ImageSize image = foxi::parse_image_size(size);
      width = image.width;
      height = image.height;
      if (!shrink.empty()) params.shrink = foxi::parse_shrink(shrink);
    } catch (const foxi::OptionError& e) {
      throw Usage(e.what());
    }
    foxi::Mesh mesh = foxi::read_mesh(mesh_path);
    {
      // The same gate as foxi's commands (apps/foxi/mesh_input.cpp): repair what can be, refuse the rest.
      const foxi::ValidationReport report = foxi::validate_and_repair(mesh);
      if (!report.ok()) {
        std::string why = mesh_path + " is not a usable mesh:";
        for (const std::string& line : foxi::describe(report)) why += "\n  " + line;
        for (const std::string& m : report.messages) why += "\n  " + m;
        throw BadInput(why);
      }
      if (report.inverted > 0)
        std::fprintf(stderr, "foxi-view: note: %s: %zu inverted tet%s (negative orientation) re-oriented\n",
                     mesh_path.c_str(), report.inverted, report.inverted == 1 ? "" : "s");
    }
    foxi::Camera camera;
    foxi::CameraOptions camera_options;
    double lo[3], hi[3];
    try {
      // The same rules as foxi render (view_options.hpp), so both give the same picture.
      foxi::mesh_bounds(mesh, lo, hi);
      camera_options = foxi::parse_camera_options(eye, at, up, fov, dir);
      camera = foxi::camera_for(camera_options, lo, hi, double(width) / height);
    } catch (const std::invalid_argument& e) {
      throw Usage(e.what());
    }
    if (!volume.empty()) {
      if (!field_spec.empty()) throw Usage("--volume NAME names the field: leave out --field");
      field_spec = volume;
    }
    if (!curve.empty() && volume.empty()) throw Usage("--opacity-curve belongs to --volume NAME");
    if (!iso_opacity.empty() && field_spec.empty())
      throw Usage("--iso-opacity draws translucent isosurfaces of a field: give --field NAME");
    if (!volume.empty() && (!region_opacity.empty() || !iso_opacity.empty()))
      throw Usage("--volume draws the field alone: leave out --region-opacity and --iso-opacity");
    if (!shrink.empty() && (!volume.empty() || !region_opacity.empty() || !iso_opacity.empty()))
      throw Usage("--region-opacity, --iso-opacity and --volume draw whole tets: leave out --shrink");
    if (field_spec.empty() && (graded || !cmap.empty()))
      throw Usage("--graded and --cmap colour by a field: give --field NAME");
    foxi::ColorMapId map = foxi::ColorMapId::viridis;
    if (!cmap.empty()) {
      const auto m = foxi::parse_color_map(cmap);
      if (!m) throw Usage("--cmap takes viridis, cividis, coolwarm or rainbow, not '" + cmap + "'");
      map = *m;
    }
    foxi::view::ViewField field;
    try {
      field = foxi::view::view_field(mesh, field_spec, graded, map);
    } catch (const foxi::FieldSelectError& e) {
      throw Usage(mesh_path + ": " + e.what());
    }
    try {
      if (!region_opacity.empty()) field.xray_regions = foxi::parse_region_opacity(mesh, region_opacity);
      if (!iso_opacity.empty()) {
        field.iso_opacity = foxi::parse_opacity(iso_opacity, "--iso-opacity");
        if (!(field.iso_opacity > 0))
          throw Usage("--iso-opacity 0 draws the isosurfaces invisible: give a > 0");
      }
      if (!curve.empty()) field.curve = foxi::parse_opacity_curve(curve);
    } catch (const foxi::OptionError& e) {
      throw Usage(mesh_path + ": " + e.what());
    }
    field.camera_options = camera_options;
    std::copy_n(lo, 3, field.box_lo);
    std::copy_n(hi, 3, field.box_hi);
    field.fitted = camera;
    field.xray = !region_opacity.empty();
    field.iso_translucent = !iso_opacity.empty();
    field.volume = !volume.empty();
    foxi::view::Viewer viewer(mesh, camera, width, height, params);
    if (!field_spec.empty()) foxi::view::apply_field(viewer, field);
    try {
      if (field.xray || field.iso_translucent || field.volume) foxi::view::apply_composite(viewer, field);
    } catch (const std::invalid_argument& e) {  // an opacity curve the painter refuses
      throw Usage(mesh_path + ": " + e.what());
    }
    if (!viewer.delaunay())
      std::printf(
          "note: %s fails the Delaunay certificate: drawn with the depth buffer (MPVO order); translucency "
          "sorted per pixel, volume in MPVO order, NOT exact\n",
          mesh_path.c_str());
    if (script_mode) {
      foxi::view::run_script(viewer, field, script, save, dump);
      return kExitOk;
    }
    return foxi::view::run_window(viewer, field, save);
  } catch (const Usage& e) {
    std::fprintf(stderr, "foxi-view: %s\nusage: %s\n", e.what(), kUsage);
    return kExitUsage;
  } catch (const BadInput& e) {
    std::fprintf(stderr, "foxi-view: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const foxi::IoError& e) {
    std::fprintf(stderr, "foxi-view: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "foxi-view: %s\n", e.what());
    return kExitFailure;
  }
}
