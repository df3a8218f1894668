// grid_png: a host that makes its own tetrahedral mesh and has foxi draw it.
//
//   grid_png OUT.png [N]
//
// The host builds an N x N x N grid of cubes, each cut into the 6 Kuhn tets (its own arrays:
// coordinates, tets, a region per tet), hands the arrays to foxi, checks the mesh
// (foxi::validate), certifies it Delaunay (foxi::delaunay_certificate: exact empty-circumsphere
// test), orders the tets of the cut-open block back to front for an eye point (foxi::visibility_order,
// the power order) and draws them with the painter (foxi::TetRasterizer) into a PNG. It checks what
// it prints: the order has no face-adjacent pair in the wrong order (foxi::count_violations), and
// the picture has both regions' colours in it.
//
// Copies: foxi::Mesh owns its arrays (std::vector), so the host's arrays are moved in here (the
// host built them for foxi); a host that must keep its own arrays copies them once. The order,
// the painter and the certificate then read the mesh in place; the subset and the order are spans.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "foxi/model.hpp"
#include "foxi/viz.hpp"

namespace {

// The host's own mesh: plain arrays, as a host's solver would keep them.
struct HostMesh {
  std::vector<double> xyz;           // 3 per node
  std::vector<std::uint32_t> tet;    // 4 per tet
  std::vector<std::int32_t> region;  // 1 per tet
};

// An n^3 grid of unit cubes scaled to [0, 1]^3; each cube cut into the 6 tets of the Kuhn (Freudenthal)
// subdivision, the paths 000 -> 111 along the three axes in each order, so neighbouring cubes
// share their face diagonals and the mesh is conforming. Region 1 below z = 1/2, region 2 above.
HostMesh kuhn_grid(int n) {
  HostMesh m;
  const auto node = [n](int i, int j, int k) {
    return static_cast<std::uint32_t>((k * (n + 1) + j) * (n + 1) + i);
  };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.xyz.insert(m.xyz.end(), {double(i) / n, double(j) / n, double(k) / n});
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          std::uint32_t v[4];
          v[0] = node(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            v[s + 1] = node(c[0], c[1], c[2]);
          }
          // foxi wants positively oriented tets (det[p1-p0, p2-p0, p3-p0] > 0); an odd permutation
          // of the axes gives a negative one, fixed by swapping two vertices.
          const bool odd = (p[0] == 0 && p[1] == 2) || (p[0] == 1 && p[1] == 0) || (p[0] == 2 && p[1] == 1);
          if (odd) std::swap(v[2], v[3]);
          m.tet.insert(m.tet.end(), v, v + 4);
          m.region.push_back(2 * k < n ? 1 : 2);
        }
  return m;
}

int run(const std::string& out, int n) {
  HostMesh host = kuhn_grid(n);

  foxi::Mesh mesh;  // owns its arrays: the host's are moved in (no copy)
  mesh.xyz = std::move(host.xyz);
  mesh.tet = std::move(host.tet);
  mesh.tet_region = std::move(host.region);
  mesh.regions = {{1, "lower", foxi::kNone}, {2, "upper", foxi::kNone}};

  const foxi::ValidationReport check = foxi::validate(mesh);
  if (!check.ok()) {
    for (const std::string& line : foxi::describe(check))
      std::fprintf(stderr, "grid_png: %s\n", line.c_str());
    return 1;
  }
  // The painter's order is a visibility order only for a Delaunay mesh: certify before trusting it.
  const foxi::DelaunayCertificate& cert = foxi::delaunay_certificate(mesh);
  if (!cert.delaunay) {
    std::fprintf(stderr, "grid_png: the mesh is not Delaunay (%zu violating tets)\n",
                 cert.violating_tet_count);
    return 1;
  }

  // Cut the block open: leave out the tets whose centroid lies in the front quarter (x > 1/2, y < 1/2).
  std::vector<std::uint32_t> subset;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    double cx = 0, cy = 0;
    for (int v = 0; v < 4; ++v) {
      cx += mesh.xyz[3 * std::size_t{mesh.tet[4 * t + v]}] / 4;
      cy += mesh.xyz[3 * std::size_t{mesh.tet[4 * t + v]} + 1] / 4;
    }
    if (!(cx > 0.5 && cy < 0.5)) subset.push_back(static_cast<std::uint32_t>(t));
  }

  const int width = 640, height = 480;
  double lo[3], hi[3];
  foxi::mesh_bounds(mesh, lo, hi);
  const double dir[3] = {-1, 1.3, -0.8}, up[3] = {0, 0, 1};
  const foxi::Camera camera = foxi::fit_camera(lo, hi, dir, up, true, 30, double(width) / height);

  const foxi::SphereTable spheres = foxi::compute_spheres(mesh);
  const foxi::View view = foxi::view_of(camera);
  const std::vector<std::uint32_t> order = foxi::visibility_order(mesh, spheres, view, subset);
  const foxi::ViolationReport violations = foxi::count_violations(mesh, view, order);
  if (order.size() != subset.size() || violations.violations != 0) {
    std::fprintf(stderr, "grid_png: bad order: %zu of %zu tets, %zu pairs in the wrong order\n", order.size(),
                 subset.size(), violations.violations);
    return 1;
  }

  foxi::RenderParams params;
  params.region_colors = {0, foxi::pack_rgba(200, 117, 51), foxi::pack_rgba(96, 110, 160)};
  foxi::Framebuffer fb(width, height);
  foxi::TetRasterizer painter(mesh, camera, width, height, params);
  painter.draw(fb, order);
  foxi::write_png(out, fb);

  // The picture shows both regions (each tet drawn is a region's colour, shaded and edge-darkened).
  std::set<std::int32_t> regions_seen;
  std::size_t covered = 0;
  for (std::size_t p = 0; p < fb.id.size(); ++p)
    if (fb.id[p] != foxi::kNone) {
      ++covered;
      regions_seen.insert(mesh.region_of(fb.id[p]));
    }
  std::printf(
      "grid_png: %zu tets (Delaunay, %zu checked), %zu drawn, %zu face pairs in order, %zu pixels "
      "covered, %zu regions seen -> %s\n",
      mesh.tet_count(), cert.tets_checked, order.size(), violations.pairs_checked, covered,
      regions_seen.size(), out.c_str());
  return regions_seen.size() == 2 && covered > std::size_t(width) * height / 10 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: grid_png OUT.png [N (cubes per side, 1..200, default 12)]\n");
    return 2;
  }
  const int n = argc == 3 ? std::atoi(argv[2]) : 12;
  if (n < 1 || n > 200) {
    std::fprintf(stderr, "grid_png: N must be 1..200, not '%s'\n", argv[2]);
    return 2;
  }
  try {
    return run(argv[1], n);
  } catch (const std::exception& e) {  // foxi reports failures as exceptions with the reason
    std::fprintf(stderr, "grid_png: %s\n", e.what());
    return 1;
  }
}
