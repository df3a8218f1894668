// field_buffer: a host that has its own mesh arrays, its own per-node field (as its own solver would
// leave it) and its own pixel buffer, and has foxi draw the field into that buffer.
//
//   field_buffer [OUT.ppm]
//
// The host's mesh is a Kuhn-subdivided box, its field an analytic temperature it computes itself,
// T(x, y, z) = sin(pi x) sin(pi y) (1 + z) at every node, and its picture buffer has rows `stride`
// bytes apart (wider than 4 x the width, as a window system's would be).
//
// No copy of the host's arrays: foxi reads them through a foxi::MeshView (std::span over the host's
// coordinates and tets), and keeps the view's derived data (face adjacency, Delaunay certificate) in a
// foxi::DerivedCache the host owns; the sphere table is a value the host keeps. The field goes in as
// spans: per-tet values for a flat colouring (foxi::flat_field_paint), corner values
// (foxi::node_corner_values) for two isosurfaces. foxi::draw_picture with a foxi::RgbaImage draws into
// the host's buffer: the tet painter in place, the isosurfaces into foxi's own framebuffer whose rows
// are then copied; that framebuffer (`scratch`, with the id buffer) is the host's to reuse.
//
// Checks: (1) flat colouring, shading and edges off: every pixel is exactly the colour of its tet's
// value on the host's scale (the tet a pixel shows from the scratch framebuffer's id buffer);
// (2) the isosurfaces drawn from the view into the strided buffer equal, byte for byte, the same drawn
// from a foxi::Mesh holding copies of the arrays (the CLI's path); the host's padding stays untouched.
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

// The host's picture buffer: RGBA8 (R first in memory), rows `stride` bytes apart, padding included.
struct HostImage {
  int width = 0, height = 0;
  std::size_t stride = 0;
  std::vector<std::uint8_t> bytes;
  foxi::RgbaImage target() { return {bytes.data(), width, height, stride}; }
  std::uint32_t pixel(int x, int y) const {
    std::uint32_t p;
    std::memcpy(&p, &bytes[std::size_t(y) * stride + 4 * std::size_t(x)], 4);
    return p;  // little-endian: pack_rgba's layout
  }
};

constexpr std::uint8_t kPadding = 0xA5;  // the host's padding must stay untouched

std::size_t padding_changed(const HostImage& image) {
  std::size_t n = 0;
  for (int y = 0; y < image.height; ++y)
    for (std::size_t b = 4 * std::size_t(image.width); b < image.stride; ++b)
      n += image.bytes[std::size_t(y) * image.stride + b] != kPadding;
  return n;
}

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

  // The view over the host's arrays (no copy) and the cache the host keeps for it.
  foxi::DerivedCache derived;
  const foxi::MeshView mesh(xyz, tets, {}, {}, {}, &derived);
  if (!foxi::validate(mesh).ok()) throw std::runtime_error("the host's mesh is not valid");
  if (!foxi::delaunay_certificate(mesh).delaunay) throw std::runtime_error("the host's mesh is not Delaunay");
  const foxi::SphereTable spheres = foxi::compute_spheres(mesh);

  HostImage image;
  image.width = 480;
  image.height = 360;
  image.stride = 4 * 512 + 8;
  image.bytes.assign(image.stride * std::size_t(image.height), kPadding);
  double lo[3], hi[3];
  foxi::mesh_bounds(mesh, lo, hi);
  const double dir[3] = {-0.6, 1, -0.9}, up[3] = {0, 0, 1};
  const foxi::Camera camera = foxi::fit_camera(lo, hi, dir, up, true, 30, double(image.width) / image.height);
  foxi::Framebuffer scratch;  // foxi's framebuffer, kept by the host from one picture to the next

  // (1) Flat colouring by the host's per-tet values (the mean of each tet's 4 nodal values).
  std::vector<double> tet_value(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    for (int v = 0; v < 4; ++v) tet_value[t] += temperature[mesh.tet[4 * t + v]] / 4;
  foxi::ColorScale scale;
  scale.map = foxi::ColorMapId::viridis;
  std::tie(scale.lo, scale.hi) = foxi::finite_range(tet_value);
  auto paint = std::make_shared<foxi::FieldPaint>(foxi::flat_field_paint(tet_value, scale));
  paint->shade_min = 1;  // no shading: each pixel is its tet's colour exactly
  foxi::PictureParams flat;
  flat.render.edges = false;
  flat.render.field = paint;
  foxi::draw_picture(mesh, spheres, camera, image.target(), scratch, flat);
  std::size_t covered = 0, wrong = 0;
  std::set<std::uint32_t> colours;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint32_t px = image.pixel(x, y), t = scratch.id[scratch.index(x, y)];
      if (t == foxi::kNone) {
        wrong += px != foxi::pack_rgba(255, 255, 255);  // draw_picture's white background
        continue;
      }
      ++covered;
      colours.insert(px);
      wrong += px != scale.color(tet_value[t]);  // the colour of the host's value, on the host's scale
    }
  const std::size_t flat_padding = padding_changed(image);

  // (2) Two isosurfaces of the host's node field, only the tets they cross ordered and drawn.
  foxi::IsoDrawing iso;
  const std::vector<double> corners = foxi::node_corner_values(mesh, temperature);
  iso.corner = corners;
  iso.params.values = {0.35, 0.8};
  iso.params.scale = scale;
  std::vector<std::uint32_t> crossing;
  foxi::TetIntervals(corners).crossing_any(iso.params.values, crossing);
  foxi::PictureParams iso_params;
  iso_params.iso = &iso;
  iso_params.subset = crossing;
  iso_params.subset_exact = true;
  const foxi::PictureReport report =
      foxi::draw_picture(mesh, spheres, camera, image.target(), scratch, iso_params);

  // The same through a foxi::Mesh holding copies of the host's arrays.
  foxi::Mesh copy;
  copy.xyz = xyz;
  copy.tet = tets;
  foxi::Framebuffer fb(image.width, image.height);
  foxi::draw_picture(copy, foxi::compute_spheres(copy), camera, fb, iso_params);
  std::size_t iso_wrong = 0, iso_covered = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      iso_wrong += image.pixel(x, y) != fb.rgba[fb.index(x, y)];
      iso_covered += fb.id[fb.index(x, y)] != foxi::kNone;
    }
  const std::size_t iso_padding = padding_changed(image);

  std::printf(
      "field_buffer: %zu tets (a view of the host's arrays), values %.3g..%.3g\n"
      "  flat colours: %zu pixels covered, %zu colours shown, %zu wrong pixels, %zu padding bytes changed\n"
      "  isosurfaces %.3g and %.3g: %zu tets crossed, %s order, %zu pixels covered, %zu pixels unlike the "
      "Mesh path's, %zu padding bytes changed\n",
      mesh.tet_count(), scale.lo, scale.hi, covered, colours.size(), wrong, flat_padding,
      iso.params.values[0], iso.params.values[1], crossing.size(),
      report.method == foxi::OrderMethod::power ? "power" : "MPVO", iso_covered, iso_wrong, iso_padding);

  if (out != nullptr) {  // the host's own writer: binary PPM of its buffer (the isosurfaces), alpha dropped
    std::ofstream f(out, std::ios::binary);
    f << "P6\n" << image.width << ' ' << image.height << "\n255\n";
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        f.write(
            reinterpret_cast<const char*>(&image.bytes[std::size_t(y) * image.stride + 4 * std::size_t(x)]),
            3);
    if (!f.flush()) throw std::runtime_error(std::string("cannot write ") + out);
  }
  const bool ok = wrong == 0 && flat_padding == 0 && colours.size() > 50 &&
                  covered > std::size_t(image.width) * image.height / 10 && iso_wrong == 0 &&
                  iso_padding == 0 && iso_covered > std::size_t(image.width) * image.height / 20 &&
                  report.delaunay;
  return ok ? 0 : 1;
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
