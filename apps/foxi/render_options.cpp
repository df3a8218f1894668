#include "render_options.hpp"

#include <algorithm>
#include <cstdlib>

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

namespace {

void triple(const std::string& s, const char* what, double out[3]) {
  auto v = parse_numbers(s, what);
  if (v.size() != 3) throw UsageError(std::string(what) + " takes x,y,z");
  for (int k = 0; k < 3; ++k) out[k] = v[k];
}

}  // namespace

void parse_size(const std::string& size_s, int& width, int& height) {
  std::size_t x = size_s.find('x');
  char* e1 = nullptr;
  char* e2 = nullptr;
  std::string w = size_s.substr(0, x), h = x == std::string::npos ? "" : size_s.substr(x + 1);
  long lw = std::strtol(w.c_str(), &e1, 10), lh = std::strtol(h.c_str(), &e2, 10);
  if (x == std::string::npos || w.empty() || h.empty() || *e1 != 0 || *e2 != 0 || lw < 1 || lh < 1 ||
      lw > 16384 || lh > 16384)
    throw UsageError("--size takes WxH with 1 <= W, H <= 16384, not '" + size_s + "'");
  width = int(lw);
  height = int(lh);
}

PictureOptions take_picture_options(Args& args, const char* default_size) {
  PictureOptions o;
  const std::string eye_s = args.option("--eye"), at_s = args.option("--at"), up_s = args.option("--up");
  const std::string fov_s = args.option("--fov"), dir_s = args.option("--dir");
  const std::string size_s = args.option("--size", default_size), shrink_s = args.option("--shrink", "1");
  o.regions = args.option("--regions");
  o.params.edges = !args.flag("--no-edges");
  if (!dir_s.empty() && (!eye_s.empty() || !fov_s.empty()))
    throw UsageError("--dir (orthographic) cannot be combined with --eye or --fov");
  parse_size(size_s, o.width, o.height);
  {
    char* end = nullptr;
    o.params.shrink = std::strtod(shrink_s.c_str(), &end);
    if (*end != 0 || !(o.params.shrink > 0 && o.params.shrink <= 1))
      throw UsageError("--shrink takes a factor in (0, 1]");
  }
  if ((o.has_up = !up_s.empty())) triple(up_s, "--up", o.up);
  if ((o.has_at = !at_s.empty())) triple(at_s, "--at", o.at);
  if ((o.has_eye = !eye_s.empty())) triple(eye_s, "--eye", o.eye);
  if ((o.has_dir = !dir_s.empty())) {
    triple(dir_s, "--dir", o.dir);
    if (o.dir[0] == 0 && o.dir[1] == 0 && o.dir[2] == 0) throw UsageError("--dir takes a nonzero x,y,z");
  }
  if (!fov_s.empty()) {
    char* end = nullptr;
    o.fov = std::strtod(fov_s.c_str(), &end);
    if (*end != 0 || !(o.fov > 0 && o.fov < 180)) throw UsageError("--fov takes degrees in (0, 180)");
  }
  return o;
}

Picture resolve_picture(const PictureOptions& o, const Mesh& mesh) {
  Picture p;
  if (!o.regions.empty()) {
    auto ids = parse_numbers(o.regions, "--regions");
    for (std::size_t t = 0; t < mesh.tet_count(); ++t)
      for (double id : ids)
        if (mesh.region_of(t) == static_cast<std::int32_t>(id)) {
          p.subset.push_back(static_cast<std::uint32_t>(t));
          break;
        }
    if (p.subset.empty()) throw UsageError("--regions " + o.regions + " selects no tets");
  }
  // The camera: given parts, the rest fitted to the bounds of what is drawn.
  double lo[3], hi[3];
  if (p.subset.empty()) {
    mesh_bounds(mesh, lo, hi);
  } else {
    for (int k = 0; k < 3; ++k) {
      lo[k] = 1e300;
      hi[k] = -1e300;
    }
    for (std::uint32_t t : p.subset)
      for (int v = 0; v < 4; ++v)
        for (int k = 0; k < 3; ++k) {
          double x = mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(t) + v]) + k];
          lo[k] = std::min(lo[k], x);
          hi[k] = std::max(hi[k], x);
        }
  }
  const double aspect = double(o.width) / o.height;
  p.camera = camera_from_options(lo, hi, aspect, o.has_eye ? o.eye : nullptr, o.has_at ? o.at : nullptr,
                                 o.has_up ? o.up : nullptr, o.fov, o.has_dir ? o.dir : nullptr);
  return p;
}

}  // namespace foxi::cli
