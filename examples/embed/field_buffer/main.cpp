// field_buffer: a host that has its own per-node field and its own pixel buffer, and has foxi draw
// the field into that buffer.
//
//   field_buffer [OUT.ppm]
//
// The host's mesh is a Kuhn-subdivided box, its field an analytic temperature it computes itself
// (as its own solver would), T(x, y, z) = sin(pi x) sin(pi y) (1 + z) at every node, and its picture
// buffer has rows `stride` pixels apart (wider than the image, as a window system's would be).
//
// The host hands foxi its per-tet values as a span (foxi::flat_field_paint: no copy into the mesh,
// no foxi::Field): each tet's value is the mean of its 4 nodal values, and each tet is painted in
// the colour of that value on a viridis scale over the field's range. Shading and edges are off
// (shade_min 1), so every pixel is exactly its tet's colour, which the host checks through the
// framebuffer's id buffer.
//
// Copies: the host's nodes and tets are copied into a foxi::Mesh (foxi::Mesh owns std::vectors;
// there is no mesh view over host arrays yet), and foxi::Framebuffer owns its pixels, so the
// picture is copied row by row into the host's buffer (width * height * 4 bytes). The field goes
// in as a span; the order and the painter read the mesh in place and take the tet order as a span.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <memory>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "foxi/model.hpp"
#include "foxi/viz.hpp"

namespace {

// The host's picture buffer: RGBA8 (R first in memory), `stride` pixels per row, padding included.
struct HostImage {
  int width = 0, height = 0, stride = 0;
  std::vector<std::uint32_t> pixels;
};

int run(const char* out) {
  // The host's mesh: an nx x ny x nz box of cubes, 6 Kuhn tets each, over [0,1] x [0,1] x [0,0.5].
  const int nx = 16, ny = 16, nz = 8;
  std::vector<double> xyz;
  std::vector<std::uint32_t> tets;
  const auto node = [&](int i, int j, int k) { return std::uint32_t((k * (ny + 1) + j) * (nx + 1) + i); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) xyz.insert(xyz.end(), {double(i) / nx, double(j) / ny, 0.5 * k / nz});
  const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                           {0, 2, 1}, {1, 0, 2}, {2, 1, 0}};  // even, then odd
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int p = 0; p < 6; ++p) {
          int c[3] = {i, j, k};
          std::uint32_t v[4] = {node(i, j, k), 0, 0, 0};
          for (int s = 0; s < 3; ++s) {
            ++c[perms[p][s]];
            v[s + 1] = node(c[0], c[1], c[2]);
          }
          if (p >= 3) std::swap(v[2], v[3]);  // odd permutation: negative orientation otherwise
          tets.insert(tets.end(), v, v + 4);
        }

  // The host's own field, computed by the host at its nodes.
  std::vector<double> temperature(xyz.size() / 3);
  for (std::size_t v = 0; v < temperature.size(); ++v)
    temperature[v] = std::sin(std::numbers::pi * xyz[3 * v]) * std::sin(std::numbers::pi * xyz[3 * v + 1]) *
                     (1 + xyz[3 * v + 2]);

  foxi::Mesh mesh;  // copies of the host's arrays (see the top)
  mesh.xyz = xyz;
  mesh.tet = tets;

  // The host's per-tet values, handed to foxi as a span.
  std::vector<double> tet_value(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    for (int v = 0; v < 4; ++v) tet_value[t] += temperature[mesh.tet[4 * t + v]] / 4;
  foxi::ColorScale scale;
  scale.map = foxi::ColorMapId::viridis;
  std::tie(scale.lo, scale.hi) = foxi::finite_range(tet_value);
  auto paint = std::make_shared<foxi::FieldPaint>(foxi::flat_field_paint(tet_value, scale));
  paint->shade_min = 1;  // no shading: each pixel is its tet's colour exactly
  foxi::RenderParams params;
  params.edges = false;
  params.field = paint;

  if (!foxi::validate(mesh).ok()) throw std::runtime_error("the host's mesh is not valid");
  if (!foxi::delaunay_certificate(mesh).delaunay) throw std::runtime_error("the host's mesh is not Delaunay");

  HostImage image;
  image.width = 480;
  image.height = 360;
  image.stride = 512;
  const std::uint32_t kPadding = 0xdeadbeef;  // the host's padding must stay untouched
  image.pixels.assign(std::size_t(image.stride) * image.height, kPadding);

  double lo[3], hi[3];
  foxi::mesh_bounds(mesh, lo, hi);
  const double dir[3] = {-0.6, 1, -0.9}, up[3] = {0, 0, 1};
  const foxi::Camera camera = foxi::fit_camera(lo, hi, dir, up, true, 30, double(image.width) / image.height);
  const foxi::SphereTable spheres = foxi::compute_spheres(mesh);
  const std::vector<std::uint32_t> order = foxi::visibility_order(mesh, spheres, foxi::view_of(camera));

  foxi::Framebuffer fb(image.width, image.height, false, foxi::pack_rgba(0, 0, 0, 0));
  foxi::TetRasterizer painter(mesh, camera, image.width, image.height, params);
  painter.draw(fb, order);
  for (int y = 0; y < image.height; ++y)  // the copy out of foxi's framebuffer (see the top)
    std::memcpy(&image.pixels[std::size_t(y) * image.stride], &fb.rgba[fb.index(0, y)],
                std::size_t(image.width) * sizeof(std::uint32_t));

  // Checks: every covered pixel has the map colour of the field at the tet it shows, the background
  // stays transparent, the padding untouched, and the picture spans the field's range.
  std::size_t covered = 0, wrong = 0, padding_changed = 0;
  std::set<std::uint32_t> colours;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.stride; ++x) {
      const std::uint32_t px = image.pixels[std::size_t(y) * image.stride + x];
      if (x >= image.width) {
        padding_changed += px != kPadding;
        continue;
      }
      const std::uint32_t t = fb.id[fb.index(x, y)];
      if (t == foxi::kNone) {
        wrong += px != foxi::pack_rgba(0, 0, 0, 0);
        continue;
      }
      ++covered;
      colours.insert(px);
      wrong += px != scale.color(tet_value[t]);  // the colour of the host's value, on the host's scale
    }
  std::printf(
      "field_buffer: %zu tets, values %.3g..%.3g, %zu pixels covered, %zu colours shown, %zu wrong "
      "pixels, %zu padding pixels changed\n",
      mesh.tet_count(), scale.lo, scale.hi, covered, colours.size(), wrong, padding_changed);

  if (out != nullptr) {  // the host's own writer: binary PPM of its buffer, alpha dropped
    std::ofstream f(out, std::ios::binary);
    f << "P6\n" << image.width << ' ' << image.height << "\n255\n";
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const std::uint32_t px = image.pixels[std::size_t(y) * image.stride + x];
        const char rgb[3] = {char(px & 255u), char(px >> 8 & 255u), char(px >> 16 & 255u)};
        f.write(rgb, 3);
      }
    if (!f.flush()) throw std::runtime_error(std::string("cannot write ") + out);
  }
  return wrong == 0 && padding_changed == 0 && colours.size() > 50 &&
                 covered > std::size_t(image.width) * image.height / 10
             ? 0
             : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 2) {
    std::fprintf(stderr, "usage: field_buffer [OUT.ppm]\n");
    return 2;
  }
  try {
    return run(argc == 2 ? argv[1] : nullptr);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "field_buffer: %s\n", e.what());
    return 1;
  }
}
