#include "render_options.hpp"

#include <cmath>
#include <cstdlib>

#include "foxi/viz/field_paint.hpp"
#include "mesh_input.hpp"

namespace foxi::cli {

const char* const kPictureOptionsHelp =
    "  --eye/--at/--up/--fov  a perspective camera (the eye may be inside the mesh); missing parts\n"
    "                  are fitted: --at defaults to the centre of the bounding box, the eye to an\n"
    "                  oblique view of the whole mesh, --up to +z, --fov to 30 degrees\n"
    "  --dir x,y,z     an orthographic view along this direction, fitted to the mesh\n"
    "  --size WxH      image size in pixels\n"
    "  --shrink f      scale each tet about its centroid by f in (0, 1] (e.g. 0.8)\n"
    "  --regions a,b   draw only the tets of these region ids\n"
    "  --no-edges      no mesh edges\n";

void parse_size(const std::string& size_s, int& width, int& height) {
  try {
    const ImageSize size = parse_image_size(size_s);
    width = size.width;
    height = size.height;
  } catch (const OptionError& e) {
    throw UsageError(e.what());
  }
}

PictureOptions take_picture_options(Args& args, const char* default_size) {
  PictureOptions o;
  const std::string eye_s = args.option("--eye"), at_s = args.option("--at"), up_s = args.option("--up");
  const std::string fov_s = args.option("--fov"), dir_s = args.option("--dir");
  const std::string size_s = args.option("--size", default_size), shrink_s = args.option("--shrink", "1");
  o.regions = args.option("--regions");
  o.params.edges = !args.flag("--no-edges");
  o.camera = parse_camera_options(eye_s, at_s, up_s, fov_s, dir_s);
  const ImageSize size = parse_image_size(size_s);
  o.width = size.width;
  o.height = size.height;
  o.params.shrink = parse_shrink(shrink_s);
  return o;
}

Picture resolve_picture(const PictureOptions& o, const Mesh& mesh) {
  Picture p;
  if (!o.regions.empty()) {
    p.subset = tets_of_regions(mesh, o.regions, "--regions");
    if (p.subset.empty()) throw UsageError("--regions " + o.regions + " selects no tets");
  }
  // The camera: given parts, the rest fitted to the bounds of what is drawn.
  double lo[3], hi[3];
  tets_bounds(mesh, p.subset, lo, hi);
  const double aspect = double(o.width) / o.height;
  p.camera = camera_for(o.camera, lo, hi, aspect);
  return p;
}

const char* const kDeformOptionHelp =
    "  --deform NAME:SCALE  the deformed shape: every node moved by SCALE times the 3-component node\n"
    "                  field NAME (a displacement, its last step), before the camera is fitted. A\n"
    "                  deformed mesh is certified again: in general it is not Delaunay and is drawn\n"
    "                  in MPVO order with the depth buffer (the 'deformed' line says which)\n";

std::optional<DeformOption> take_deform_option(Args& args) {
  const std::string text = args.option("--deform");
  if (text.empty()) return std::nullopt;
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0)
    throw UsageError("--deform takes NAME:SCALE (a displacement field and a factor), not '" + text + "'");
  DeformOption d;
  d.name = text.substr(0, colon);
  const std::string scale = text.substr(colon + 1);
  char* end = nullptr;
  d.scale = std::strtod(scale.c_str(), &end);
  if (scale.empty() || *end != 0 || !std::isfinite(d.scale))
    throw UsageError("--deform NAME:SCALE: the scale must be a finite number, not '" + scale + "'");
  return d;
}

double apply_deform(Mesh& mesh, const DeformOption& deform, const std::string& path, const char* command) {
  double moved = 0;
  try {
    moved = deform_by_field(mesh, deform.name, deform.scale);
  } catch (const FieldSelectError& e) {
    throw UsageError(path + ": --deform: " + e.what());
  }
  // Large factors fold tets over: re-oriented (a note says so) or, flat, refused.
  require_usable(mesh, path + " deformed by " + deform.name + " x " + std::to_string(deform.scale), command);
  return moved;
}

}  // namespace foxi::cli
