// Meshes for the ordering and rendering tests, made in the test (never stored): structured grids of
// cuboids split into 5 or 6 tets (every cuboid's corners are cospherical: the paper's Table 2 meshes),
// and TetGen's Delaunay tetrahedralizations of random points.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/mesh.hpp"
#include "test_util.hpp"

namespace foxi::test {

inline double orient(const Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  const double* p = &m.xyz[3 * a];
  const double* q = &m.xyz[3 * b];
  const double* r = &m.xyz[3 * c];
  const double* s = &m.xyz[3 * d];
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = q[k] - p[k];
    v[k] = r[k] - p[k];
    w[k] = s[k] - p[k];
  }
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

inline void push_tet(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
  if (orient(m, a, b, c, d) < 0) std::swap(c, d);
  m.tet.insert(m.tet.end(), {a, b, c, d});
}

// nx x ny x nz cuboids of size hx x hy x hz; tets_per_cell 5 or 6. Region 1 everywhere.
inline Mesh grid_mesh(int nx, int ny, int nz, double hx, double hy, double hz, int tets_per_cell) {
  Mesh m;
  auto id = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>((k * (ny + 1) + j) * (nx + 1) + i);
  };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.xyz.insert(m.xyz.end(), {i * hx, j * hy, k * hz});
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        std::uint32_t c[8];
        for (int b = 0; b < 8; ++b) c[b] = id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
        if (tets_per_cell == 6) {
          static const int paths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
          for (auto& p : paths) push_tet(m, c[0], c[p[0]], c[p[1]], c[7]);
        } else {
          // 5 tets: a central tet and 4 corners, mirrored in alternate cells so faces match.
          bool even = (i + j + k) % 2 == 0;
          int a = even ? 0 : 1, b = even ? 3 : 2, cc = even ? 5 : 4, d = even ? 6 : 7;
          int o[4] = {even ? 1 : 0, even ? 2 : 3, even ? 4 : 5, even ? 7 : 6};
          push_tet(m, c[a], c[b], c[cc], c[d]);
          // Each other corner with its three neighbours among the central tet's vertices.
          for (int x : o) {
            int nbr[3], q = 0;
            for (int y : {a, b, cc, d})
              if (__builtin_popcount(unsigned(x ^ y)) == 1) nbr[q++] = y;
            push_tet(m, c[x], c[nbr[0]], c[nbr[1]], c[nbr[2]]);
          }
        }
      }
  m.tet_region.assign(m.tet_count(), 1);
  m.regions = {{1, "grid", kNone}};
  return m;
}

// Three regions (materials 1, 2, 3) by the x of each tet's centroid: below x1, below x2, beyond.
inline void regions_along_x(Mesh& m, double x1, double x2) {
  m.tet_region.assign(m.tet_count(), 0);
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    double cx = 0;
    for (int k = 0; k < 4; ++k) cx += 0.25 * m.xyz[3 * std::size_t(m.tet[4 * t + k])];
    m.tet_region[t] = cx < x1 ? 1 : cx < x2 ? 2 : 3;
  }
}

// TetGen's Delaunay tetrahedralization of `n` random points in the box [0,sx]x[0,sy]x[0,sz]
// (`tetgen` on a .node file, no PLC: the convex hull is meshed).
inline Mesh random_delaunay(const TempDir& dir, int n, unsigned seed, double sx = 1, double sy = 1,
                            double sz = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::string text = std::to_string(n) + " 3 0 0\n";
  char line[128];
  for (int i = 0; i < n; ++i) {
    std::snprintf(line, sizeof line, "%d %.17g %.17g %.17g\n", i + 1, sx * u(rng), sy * u(rng), sz * u(rng));
    text += line;
  }
  const std::string base = "pts" + std::to_string(seed);
  write_text(dir / (base + ".node"), text);
  run("cd '" + dir.path().string() + "' && tetgen -Q " + base + ".node", dir / "tetgen.log");
  return read_tetgen(dir / (base + ".1"));
}

// Points on a unit sphere (all cospherical), tetrahedralized by TetGen.
inline Mesh sphere_points_delaunay(const TempDir& dir, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  std::string text = std::to_string(n) + " 3 0 0\n";
  char line[128];
  for (int i = 0; i < n; ++i) {
    double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
    std::snprintf(line, sizeof line, "%d %.17g %.17g %.17g\n", i + 1, x / r, y / r, z / r);
    text += line;
  }
  write_text(dir / "sph.node", text);
  run("cd '" + dir.path().string() + "' && tetgen -Q sph.node", dir / "tetgen.log");
  return read_tetgen(dir / "sph.1");
}

// All integer points with x^2 + y^2 + z^2 = r2: exactly cospherical, so the whole Delaunay
// triangulation is one cluster with a single circumsphere (the paper's section 3.3 case).
inline Mesh integer_sphere_delaunay(const TempDir& dir, int r2) {
  std::string body;
  int n = 0, r = static_cast<int>(std::sqrt(double(r2))) + 1;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y)
      for (int z = -r; z <= r; ++z)
        if (x * x + y * y + z * z == r2) {
          ++n;
          body += std::to_string(n) + " " + std::to_string(x) + " " + std::to_string(y) + " " +
                  std::to_string(z) + "\n";
        }
  write_text(dir / "isph.node", std::to_string(n) + " 3 0 0\n" + body);
  run("cd '" + dir.path().string() + "' && tetgen -Q isph.node", dir / "tetgen.log");
  return read_tetgen(dir / "isph.1");
}

}  // namespace foxi::test
