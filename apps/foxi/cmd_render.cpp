// foxi render MESH: a picture of the mesh's interior by the software painter (tets back to front in
// the power-function visibility order, front faces only, no depth buffer), written as a PNG.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "cli.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/depth_stop.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi::cli {

namespace {

const char* kRenderUsage =
    "foxi render MESH [--eye x,y,z --at x,y,z --up x,y,z --fov deg | --dir x,y,z] [--size WxH]\n"
    "                 [--stop P%] [--depth d] [--zbuffer] [--shrink f] [--regions a,b] [--no-edges] -o OUT.png\n"
    "  Draws the tets back to front in the power-function visibility order, each showing its front\n"
    "  faces flat-shaded in its region's colour with the mesh edges darkened (no depth buffer).\n"
    "  --eye/--at/--up/--fov  a perspective camera (the eye may be inside the mesh); missing parts\n"
    "                  are fitted: --at defaults to the centre of the bounding box, the eye to an\n"
    "                  oblique view of the whole mesh, --up to +z, --fov to 30 degrees\n"
    "  --dir x,y,z     an orthographic view along this direction, fitted to the mesh\n"
    "  --size WxH      image size in pixels (default 1280x960)\n"
    "  --stop P%       draw only the first P percent of the back-to-front order (the far part)\n"
    "  --depth d       stop at the first tet whose power distance from the eye, sqrt(|eye-c|^2-r^2)\n"
    "                  for its circumsphere (c, r), is below d (world units; the order decreases in\n"
    "                  it); orthographic: the circumcentre's distance in front of the plane through\n"
    "                  --at across the view. With --stop, whichever stops first\n"
    "  --zbuffer       draw with a depth buffer instead (the oracle; order irrelevant)\n"
    "  --shrink f      scale each tet about its centroid by f in (0, 1] (e.g. 0.8)\n"
    "  --regions a,b   draw only the tets of these region ids\n"
    "  --no-edges      no mesh edges\n"
    "  Meshes that fail the Delaunay certificate have no guaranteed order: their picture is drawn\n"
    "  with the depth buffer (in MPVO order, so --stop still takes the far part) and a note says so.";


void triple(const std::string& s, const char* what, double out[3]) {
  auto v = parse_numbers(s, what);
  if (v.size() != 3) throw UsageError(std::string(what) + " takes x,y,z");
  for (int k = 0; k < 3; ++k) out[k] = v[k];
}

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int cmd_render(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kRenderUsage);
    return 0;
  }
  const std::string eye_s = args.option("--eye"), at_s = args.option("--at"), up_s = args.option("--up");
  const std::string fov_s = args.option("--fov"), dir_s = args.option("--dir");
  const std::string size_s = args.option("--size", "1280x960"), stop_s = args.option("--stop");
  const std::string depth_s = args.option("--depth");
  const std::string shrink_s = args.option("--shrink", "1"), regions_s = args.option("--regions");
  std::string out = args.option("-o");
  if (out.empty()) out = args.option("--output");
  const bool zbuffer = args.flag("--zbuffer"), no_edges = args.flag("--no-edges");
  const std::string path = args.positional(1, 1, kRenderUsage)[0];
  if (out.empty())
    throw UsageError("give the output file with -o OUT.png\nusage: " + std::string(kRenderUsage));
  if (!dir_s.empty() && (!eye_s.empty() || !fov_s.empty()))
    throw UsageError("--dir (orthographic) cannot be combined with --eye or --fov");

  int width = 0, height = 0;
  {
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
  RenderParams params;
  params.edges = !no_edges;
  {
    char* end = nullptr;
    params.shrink = std::strtod(shrink_s.c_str(), &end);
    if (*end != 0 || !(params.shrink > 0 && params.shrink <= 1))
      throw UsageError("--shrink takes a factor in (0, 1]");
  }

  const Mesh mesh = read_mesh(path);
  if (mesh.tet_count() == 0) throw UsageError(path + " has no tets");
  std::vector<std::uint32_t> subset;
  if (!regions_s.empty()) {
    auto ids = parse_numbers(regions_s, "--regions");
    for (std::size_t t = 0; t < mesh.tet_count(); ++t)
      for (double id : ids)
        if (mesh.region_of(t) == static_cast<std::int32_t>(id)) {
          subset.push_back(static_cast<std::uint32_t>(t));
          break;
        }
    if (subset.empty()) throw UsageError("--regions " + regions_s + " selects no tets");
  }

  // The camera: given parts, the rest fitted to the bounds of what is drawn.
  double lo[3], hi[3];
  if (subset.empty()) {
    mesh_bounds(mesh, lo, hi);
  } else {
    for (int k = 0; k < 3; ++k) {
      lo[k] = 1e300;
      hi[k] = -1e300;
    }
    for (std::uint32_t t : subset)
      for (int v = 0; v < 4; ++v)
        for (int k = 0; k < 3; ++k) {
          double x = mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(t) + v]) + k];
          lo[k] = std::min(lo[k], x);
          hi[k] = std::max(hi[k], x);
        }
  }
  const double aspect = double(width) / height;
  double up[3], at[3], eye[3], dir[3];
  if (!up_s.empty()) triple(up_s, "--up", up);
  if (!at_s.empty()) triple(at_s, "--at", at);
  if (!eye_s.empty()) triple(eye_s, "--eye", eye);
  if (!dir_s.empty()) {
    triple(dir_s, "--dir", dir);
    if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0) throw UsageError("--dir takes a nonzero x,y,z");
  }
  double fov = 0;
  if (!fov_s.empty()) {
    char* end = nullptr;
    fov = std::strtod(fov_s.c_str(), &end);
    if (*end != 0 || !(fov > 0 && fov < 180)) throw UsageError("--fov takes degrees in (0, 180)");
  }
  const Camera camera = camera_from_options(lo, hi, aspect, eye_s.empty() ? nullptr : eye, at_s.empty() ? nullptr : at,
                                            up_s.empty() ? nullptr : up, fov, dir_s.empty() ? nullptr : dir);

  auto t0 = std::chrono::steady_clock::now();
  const DelaunayCertificate& cert = delaunay_certificate(mesh);
  const double cert_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  const SphereTable table = compute_spheres(mesh);
  const double spheres_ms = ms_since(t0);
  const View view = view_of(camera);
  t0 = std::chrono::steady_clock::now();
  std::vector<std::uint32_t> order;
  std::size_t cycles = 0;
  if (cert.delaunay)
    order = visibility_order(mesh, table, view, subset);
  else
    order = mpvo_order(mesh, table, view, subset, &cycles);
  const double order_ms = ms_since(t0);
  std::size_t count = std::min(order.size(), std::size_t(std::floor(stop * double(order.size()) + 1e-9)));
  if (!depth_s.empty()) count = std::min(count, count_deeper(table, camera, order, depth_stop));

  params.depth_buffer = zbuffer || !cert.delaunay;
  t0 = std::chrono::steady_clock::now();
  Framebuffer fb(width, height, params.depth_buffer);
  TetRasterizer raster(mesh, camera, width, height, params);
  raster.draw(fb, std::span<const std::uint32_t>(order).first(count));
  const double draw_ms = ms_since(t0);
  write_png(out, fb);

  std::size_t covered = 0;
  for (std::uint32_t id : fb.id) covered += id != kNone;
  std::printf("mesh        %s: %zu tets, %zu selected\n", path.c_str(), mesh.tet_count(), order.size());
  std::printf("certificate %s (%.1f ms); spheres %.1f ms\n",
              cert.delaunay ? "Delaunay" : "NOT Delaunay: picture drawn with the depth buffer", cert_ms,
              spheres_ms);
  if (camera.perspective)
    std::printf("camera      perspective eye (%g, %g, %g) at (%g, %g, %g) up (%g, %g, %g) fov %g\n",
                camera.eye[0], camera.eye[1], camera.eye[2], camera.at[0], camera.at[1], camera.at[2],
                camera.up[0], camera.up[1], camera.up[2], camera.fov_deg);
  else
    std::printf("camera      orthographic along (%g, %g, %g), height %g\n", camera.at[0] - camera.eye[0],
                camera.at[1] - camera.eye[1], camera.at[2] - camera.eye[2], camera.ortho_height);
  std::printf("order       %s, %.1f ms%s\n", cert.delaunay ? "power (visibility order)" : "MPVO", order_ms,
              cert.delaunay ? "" : (", " + std::to_string(cycles) + " cycles broken").c_str());
  std::printf("drawn       %zu of %zu tets (%.0f%%) in %s mode, %.1f ms, %dx%d, %.1f%% of pixels covered",
              count, order.size(), order.empty() ? 0.0 : 100.0 * double(count) / double(order.size()),
              params.depth_buffer ? "depth-buffer" : "painter", draw_ms, width, height,
              100.0 * double(covered) / double(fb.id.size()));
  if (!depth_s.empty() && count > 0)
    std::printf(", stopped at depth %g (last tet drawn at %g)", depth_stop, tet_depth(table, camera, order[count - 1]));
  if (raster.stats().tets_behind > 0) std::printf(", %zu tets behind the eye", raster.stats().tets_behind);
  std::printf("\nwrote       %s\n", out.c_str());
  return 0;
}

}  // namespace foxi::cli
