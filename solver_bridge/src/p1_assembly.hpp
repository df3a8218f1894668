// Internal pieces shared by foxi's P1 solvers: the node-adjacency CSR pattern of a
// tet mesh and the gradients of the P1 shape functions.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <thread>
#include <vector>

#include "foxi/model/mesh.hpp"
#include "foxi/model/parallel.hpp"  // thread_count, parallel_for

namespace foxi::detail {

// Compressed sparse rows with sorted column indices in each row.
struct CsrPattern {
  std::vector<std::size_t> row_start;  // rows + 1
  std::vector<std::uint32_t> col;
  std::size_t rows() const { return row_start.size() - 1; }
  // Position of (r, c) in col, or kNone-like SIZE_MAX when absent.
  std::size_t find(std::uint32_t r, std::uint32_t c) const {
    auto b = col.begin() + static_cast<std::ptrdiff_t>(row_start[r]);
    auto e = col.begin() + static_cast<std::ptrdiff_t>(row_start[r + 1]);
    auto it = std::lower_bound(b, e, c);
    return (it != e && *it == c) ? static_cast<std::size_t>(it - col.begin()) : SIZE_MAX;
  }
};

// Tets around each node: node_tet[node_start[v] .. node_start[v+1]) holds 4 * tet + local index.
struct NodeTets {
  std::vector<std::size_t> node_start;
  std::vector<std::uint32_t> item;
};

NodeTets node_tets(const Mesh& mesh);
// Node adjacency through tets (every node is its own neighbour when it has a tet).
CsrPattern node_pattern(const Mesh& mesh, const NodeTets& nt, unsigned threads);

// Gradients of the 4 barycentric functions of tet t (g[a] for vertex a) and its signed volume.
inline double p1_gradients(const Mesh& mesh, std::size_t t, std::array<std::array<double, 3>, 4>& g) {
  const std::uint32_t* v = &mesh.tet[4 * t];
  const double* p0 = &mesh.xyz[3 * std::size_t{v[0]}];
  double e[3][3];
  for (int i = 0; i < 3; ++i) {
    const double* p = &mesh.xyz[3 * std::size_t{v[i + 1]}];
    for (int c = 0; c < 3; ++c) e[i][c] = p[c] - p0[c];
  }
  // Rows of the inverse of J = [e0 e1 e2] (columns) are the cross products over det.
  double c0[3] = {e[1][1] * e[2][2] - e[1][2] * e[2][1], e[1][2] * e[2][0] - e[1][0] * e[2][2],
                  e[1][0] * e[2][1] - e[1][1] * e[2][0]};
  double c1[3] = {e[2][1] * e[0][2] - e[2][2] * e[0][1], e[2][2] * e[0][0] - e[2][0] * e[0][2],
                  e[2][0] * e[0][1] - e[2][1] * e[0][0]};
  double c2[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                  e[0][0] * e[1][1] - e[0][1] * e[1][0]};
  const double det = e[0][0] * c0[0] + e[0][1] * c0[1] + e[0][2] * c0[2];
  const double inv = det != 0 ? 1.0 / det : 0.0;
  for (int c = 0; c < 3; ++c) {
    g[1][c] = c0[c] * inv;
    g[2][c] = c1[c] * inv;
    g[3][c] = c2[c] * inv;
    g[0][c] = -(g[1][c] + g[2][c] + g[3][c]);
  }
  return det / 6.0;
}

inline double triangle_area(const Mesh& mesh, std::size_t f) {
  const std::uint32_t* v = &mesh.bface[3 * f];
  const double* a = &mesh.xyz[3 * std::size_t{v[0]}];
  const double* b = &mesh.xyz[3 * std::size_t{v[1]}];
  const double* c = &mesh.xyz[3 * std::size_t{v[2]}];
  double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

}  // namespace foxi::detail
