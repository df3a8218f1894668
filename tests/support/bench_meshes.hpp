// Meshes for the tests and the benchmarks, made in the run (never committed): the target
// foxi_test_support (tests/support/CMakeLists.txt).
#pragma once

#include <cmath>
#include <stdexcept>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi::bench {

// An n x n x n grid of unit cubes, each split into 6 tets around its main diagonal (Kuhn
// triangulation, positively oriented, conforming), nodes jittered by up to `jitter` (fraction of a
// cell) so that keys and coordinates are not all round numbers. 6 n^3 tets, (n+1)^3 nodes:
// n = 57 gives 1.11M tets and 195k nodes. Regions: lower and upper half (ids 1, 2); boundary
// triangles of the outer faces tagged 1..6 (x-, x+, y-, y+, z-, z+).
inline Mesh kuhn_grid_mesh(std::uint32_t n, double jitter = 0.1, std::uint32_t seed = 1) {
  Mesh m;
  const std::uint32_t s = n + 1;
  auto id = [s](std::uint32_t i, std::uint32_t j, std::uint32_t k) { return (k * s + j) * s + i; };
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  m.xyz.reserve(3ull * s * s * s);
  for (std::uint32_t k = 0; k < s; ++k)
    for (std::uint32_t j = 0; j < s; ++j)
      for (std::uint32_t i = 0; i < s; ++i) {
        bool bi = i == 0 || i == n, bj = j == 0 || j == n, bk = k == 0 || k == n;
        m.xyz.push_back((i + (bi ? 0 : u(rng))) / n);
        m.xyz.push_back((j + (bj ? 0 : u(rng))) / n);
        m.xyz.push_back((k + (bk ? 0 : u(rng))) / n);
      }
  // The 6 paths from corner 0 to corner 7 of a cube (bit 0 = x, 1 = y, 2 = z).
  static const int paths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
  m.tet.reserve(24ull * n * n * n);
  m.tet_region.reserve(6ull * n * n * n);
  for (std::uint32_t k = 0; k < n; ++k)
    for (std::uint32_t j = 0; j < n; ++j)
      for (std::uint32_t i = 0; i < n; ++i) {
        auto corner = [&](int c) { return id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)); };
        for (auto& p : paths) {
          std::uint32_t a = corner(0), b = corner(p[0]), c = corner(p[1]), d = corner(7);
          // Orientation of (0, e_a, e_a + e_b, 1,1,1): positive for even permutations of axes.
          int ax0 = p[0] == 1 ? 0 : p[0] == 2 ? 1 : 2;
          int ax1 = (p[1] ^ p[0]) == 1 ? 0 : (p[1] ^ p[0]) == 2 ? 1 : 2;
          bool even = (ax1 - ax0 + 3) % 3 == 1;
          if (even)
            m.tet.insert(m.tet.end(), {a, b, c, d});
          else
            m.tet.insert(m.tet.end(), {a, c, b, d});
          m.tet_region.push_back(k < n / 2 ? 1 : 2);
        }
      }
  m.regions = {{1, "lower", kNone}, {2, "upper", kNone}};
  // Outer faces: each cube face is split along the diagonal from its lowest to its highest corner,
  // as the Kuhn tets split it.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const std::int32_t tag = 2 * axis + side + 1;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      for (std::uint32_t v = 0; v < n; ++v)
        for (std::uint32_t w = 0; w < n; ++w) {
          auto node = [&](std::uint32_t dv, std::uint32_t dw) {
            std::uint32_t c[3];
            c[axis] = side ? n : 0;
            c[a1] = v + dv;
            c[a2] = w + dw;
            return id(c[0], c[1], c[2]);
          };
          m.bface.insert(m.bface.end(), {node(0, 0), node(1, 0), node(1, 1)});
          m.bface.insert(m.bface.end(), {node(0, 0), node(1, 1), node(0, 1)});
          m.bface_tag.push_back(tag);
          m.bface_tag.push_back(tag);
        }
      m.boundaries.push_back({tag, std::string("xyz"[axis] == 'x' ? "x"
                                               : axis == 1        ? "y"
                                                                  : "z") +
                                       (side ? "max" : "min")});
    }
  return m;
}

// TetGen's mesh of a sx x sy x sz box with `tetgen -pq1.414a<max_volume>O0` (no flips or smoothing,
// so the mesh is Delaunay). The TetGen files are cached in the temp folder under a name made of the
// parameters, so that repeated runs do not remesh; throws if tetgen fails.
inline Mesh tetgen_box_mesh(double sx, double sy, double sz, double max_volume) {
  namespace fs = std::filesystem;
  char tag[128];
  std::snprintf(tag, sizeof tag, "foxi-bench-box-%g-%g-%g-%g", sx, sy, sz, max_volume);
  const fs::path dir = fs::temp_directory_path() / tag;
  const fs::path base = dir / "box.1";
  if (!fs::exists(dir / "box.1.ele")) {
    fs::create_directories(dir);
    std::string poly = "8 3 0 0\n";
    for (int i = 0; i < 8; ++i)
      poly += std::to_string(i + 1) + " " + std::to_string(i & 1 ? sx : 0.0) + " " +
              std::to_string(i & 2 ? sy : 0.0) + " " + std::to_string(i & 4 ? sz : 0.0) + "\n";
    poly += "6 0\n1\n4 1 3 7 5\n1\n4 2 4 8 6\n1\n4 1 2 6 5\n1\n4 3 4 8 7\n1\n4 1 2 4 3\n1\n4 5 6 8 7\n0\n0\n";
    std::FILE* f = std::fopen((dir / "box.poly").c_str(), "w");
    if (f == nullptr) throw std::runtime_error("cannot write " + (dir / "box.poly").string());
    std::fputs(poly.c_str(), f);
    std::fclose(f);
    char a[64];
    std::snprintf(a, sizeof a, "%g", max_volume);
    const std::string cmd =
        "tetgen -pq1.414a" + std::string(a) + "O0Q '" + (dir / "box.poly").string() + "' > /dev/null 2>&1";
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("tetgen failed: " + cmd);
  }
  return read_tetgen(base);
}

// A structured grid of n x n x n unit cubes, each split into 6 tets (the paper's Table 2 meshes):
// exactly Delaunay, every cube one cospherical cluster.
inline Mesh cube_grid_mesh(std::uint32_t n) { return kuhn_grid_mesh(n, 0.0); }

}  // namespace foxi::bench
