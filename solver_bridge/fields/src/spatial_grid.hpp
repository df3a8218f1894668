// Uniform grids for the transfer (internal): tets by their bounding boxes for point location, and
// points for nearest-point queries. A grid of about one cell per tet (per two points) keeps each
// query to a handful of candidates on meshes of even size, at a fraction of the memory of a tree.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "foxi/model/mesh.hpp"

namespace foxi {

// The cells of a box, cubes of side h, at most ~`cells` of them.
struct GridFrame {
  double lo[3] = {0, 0, 0};
  double inv_h = 1, h = 1;
  std::int64_t dim[3] = {1, 1, 1};

  void fit(const std::vector<double>& xyz, std::size_t cells) {
    double hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = -lo[k];
    }
    for (std::size_t i = 0; i + 2 < xyz.size(); i += 3)
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(xyz[i + k])) continue;
        lo[k] = std::min(lo[k], xyz[i + k]);
        hi[k] = std::max(hi[k], xyz[i + k]);
      }
    double ext[3], largest = 0;
    for (int k = 0; k < 3; ++k) {
      if (!(lo[k] <= hi[k])) lo[k] = hi[k] = 0;
      ext[k] = hi[k] - lo[k];
      largest = std::max(largest, ext[k]);
    }
    if (largest <= 0) largest = 1;
    // Flat directions count as one cell; the cell side from the volume of the others.
    double vol = 1;
    int dims = 0;
    for (int k = 0; k < 3; ++k)
      if (ext[k] > largest * 1e-9) {
        vol *= ext[k];
        ++dims;
      }
    cells = std::max<std::size_t>(cells, 1);
    h = dims == 0 ? largest : std::pow(vol / double(cells), 1.0 / dims);
    h = std::max(h, largest / 1024);  // at most 1024 cells along an axis
    inv_h = 1 / h;
    for (int k = 0; k < 3; ++k) dim[k] = std::max<std::int64_t>(1, std::int64_t(std::ceil(ext[k] * inv_h)));
  }
  std::int64_t coord(double x, int k) const {
    const double c = std::floor((x - lo[k]) * inv_h);
    if (!(c >= 0)) return 0;
    return std::min<std::int64_t>(std::int64_t(std::min(c, 1e15)), dim[k] - 1);
  }
  bool inside(const double* p) const {
    for (int k = 0; k < 3; ++k)
      if (!(p[k] >= lo[k] - h * 1e-9 && p[k] <= lo[k] + double(dim[k]) * h + h * 1e-9)) return false;
    return true;
  }
  std::size_t index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return std::size_t((k * dim[1] + j) * dim[0] + i);
  }
  std::size_t cell_count() const { return std::size_t(dim[0] * dim[1] * dim[2]); }
};

// Lists of items per cell (CSR), filled from each item's range of cells.
struct CellLists {
  std::vector<std::uint32_t> start, items;
  template <class Range>  // range(item, lo[3], hi[3])
  void build(const GridFrame& g, std::size_t n, Range range) {
    start.assign(g.cell_count() + 1, 0);
    std::int64_t a[3], b[3];
    for (std::size_t t = 0; t < n; ++t) {
      range(t, a, b);
      for (std::int64_t z = a[2]; z <= b[2]; ++z)
        for (std::int64_t y = a[1]; y <= b[1]; ++y)
          for (std::int64_t x = a[0]; x <= b[0]; ++x) ++start[g.index(x, y, z) + 1];
    }
    for (std::size_t c = 0; c + 1 < start.size(); ++c) start[c + 1] += start[c];
    items.resize(start.back());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t t = 0; t < n; ++t) {
      range(t, a, b);
      for (std::int64_t z = a[2]; z <= b[2]; ++z)
        for (std::int64_t y = a[1]; y <= b[1]; ++y)
          for (std::int64_t x = a[0]; x <= b[0]; ++x) items[fill[g.index(x, y, z)]++] = std::uint32_t(t);
    }
  }
};

class TetGrid {
 public:
  explicit TetGrid(const Mesh& m) {
    const std::size_t nt = m.tet_count();
    frame_.fit(m.xyz, nt);
    // Per tet: its first corner and the inverse of [b-a, c-a, d-a] (barycentric coordinates 1..3 =
    // inverse * (p - a)), whatever its orientation; a flat tet gets no cells.
    inv_.resize(12 * nt);
    std::vector<char> flat(nt, 0);
    for (std::size_t t = 0; t < nt; ++t) {
      const double* a = &m.xyz[3 * std::size_t(m.tet[4 * t])];
      double e[3][3];
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) e[j][k] = m.xyz[3 * std::size_t(m.tet[4 * t + 1 + j]) + k] - a[k];
      // Rows of the inverse of the matrix with columns e0, e1, e2: cross products over the determinant.
      const double c0[3] = {e[1][1] * e[2][2] - e[1][2] * e[2][1], e[1][2] * e[2][0] - e[1][0] * e[2][2],
                            e[1][0] * e[2][1] - e[1][1] * e[2][0]};
      const double c1[3] = {e[2][1] * e[0][2] - e[2][2] * e[0][1], e[2][2] * e[0][0] - e[2][0] * e[0][2],
                            e[2][0] * e[0][1] - e[2][1] * e[0][0]};
      const double c2[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                            e[0][0] * e[1][1] - e[0][1] * e[1][0]};
      const double det = e[0][0] * c0[0] + e[0][1] * c0[1] + e[0][2] * c0[2];
      double* r = &inv_[12 * t];
      std::copy(a, a + 3, r);
      if (!(std::abs(det) > 0) || !std::isfinite(det)) {
        flat[t] = 1;
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        r[3 + k] = c0[k] / det;
        r[6 + k] = c1[k] / det;
        r[9 + k] = c2[k] / det;
      }
    }
    cells_.build(frame_, nt, [&](std::size_t t, std::int64_t* lo, std::int64_t* hi) {
      if (flat[t]) {
        for (int k = 0; k < 3; ++k) lo[k] = 1, hi[k] = 0;  // an empty range
        return;
      }
      for (int k = 0; k < 3; ++k) {
        double a = std::numeric_limits<double>::infinity(), b = -a;
        for (int j = 0; j < 4; ++j) {
          const double x = m.xyz[3 * std::size_t(m.tet[4 * t + j]) + k];
          a = std::min(a, x);
          b = std::max(b, x);
        }
        lo[k] = frame_.coord(a - frame_.h * 1e-9, k);
        hi[k] = frame_.coord(b + frame_.h * 1e-9, k);
      }
    });
  }

  // The tet (accepted by ok) holding p, with no barycentric coordinate below -tol (the most inside
  // one where several are), its barycentric coordinates in bary; kNone if there is none.
  template <class Ok>
  std::uint32_t locate(const double* p, double tol, Ok ok, double* bary) const {
    if (!frame_.inside(p)) return kNone;
    const std::size_t c = frame_.index(frame_.coord(p[0], 0), frame_.coord(p[1], 1), frame_.coord(p[2], 2));
    std::uint32_t best = kNone;
    double best_min = -tol;
    for (std::uint32_t i = cells_.start[c]; i < cells_.start[c + 1]; ++i) {
      const std::uint32_t t = cells_.items[i];
      const double* r = &inv_[12 * std::size_t(t)];
      const double d[3] = {p[0] - r[0], p[1] - r[1], p[2] - r[2]};
      const double l1 = r[3] * d[0] + r[4] * d[1] + r[5] * d[2];
      const double l2 = r[6] * d[0] + r[7] * d[1] + r[8] * d[2];
      const double l3 = r[9] * d[0] + r[10] * d[1] + r[11] * d[2];
      const double l0 = 1 - l1 - l2 - l3;
      const double lmin = std::min(std::min(l0, l1), std::min(l2, l3));
      if (lmin < best_min || !ok(t)) continue;
      best = t;
      best_min = lmin;
      bary[0] = l0, bary[1] = l1, bary[2] = l2, bary[3] = l3;
      if (lmin > 0) break;  // strictly inside: no other tet holds it
    }
    return best;
  }

 private:
  GridFrame frame_;
  CellLists cells_;
  std::vector<double> inv_;
};

class PointGrid {
 public:
  explicit PointGrid(const std::vector<double>& xyz) : xyz_(xyz) {
    const std::size_t n = xyz.size() / 3;
    frame_.fit(xyz, n / 2 + 1);
    cells_.build(frame_, n, [&](std::size_t i, std::int64_t* lo, std::int64_t* hi) {
      for (int k = 0; k < 3; ++k) lo[k] = hi[k] = frame_.coord(xyz[3 * i + k], k);
    });
  }

  // The nearest point accepted by ok, kNone if none is: rings of cells around p's cell, until the
  // best distance found is below the nearest a further ring can hold.
  template <class Ok>
  std::uint32_t nearest(const double* p, Ok ok) const {
    const std::int64_t c[3] = {frame_.coord(p[0], 0), frame_.coord(p[1], 1), frame_.coord(p[2], 2)};
    const std::int64_t max_r = std::max({frame_.dim[0], frame_.dim[1], frame_.dim[2]});
    std::uint32_t best = kNone;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (std::int64_t r = 0; r <= max_r; ++r) {
      for (std::int64_t z = c[2] - r; z <= c[2] + r; ++z)
        for (std::int64_t y = c[1] - r; y <= c[1] + r; ++y)
          for (std::int64_t x = c[0] - r; x <= c[0] + r; ++x) {
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r)
              continue;  // the shell only
            if (x < 0 || y < 0 || z < 0 || x >= frame_.dim[0] || y >= frame_.dim[1] || z >= frame_.dim[2])
              continue;
            const std::size_t cell = frame_.index(x, y, z);
            for (std::uint32_t i = cells_.start[cell]; i < cells_.start[cell + 1]; ++i) {
              const std::uint32_t s = cells_.items[i];
              double d2 = 0;
              for (int k = 0; k < 3; ++k)
                d2 += (xyz_[3 * std::size_t(s) + k] - p[k]) * (xyz_[3 * std::size_t(s) + k] - p[k]);
              if (d2 < best_d2 && ok(s)) {
                best_d2 = d2;
                best = s;
              }
            }
          }
      const double reach = double(r) * frame_.h;
      if (best != kNone && best_d2 <= reach * reach) break;
    }
    return best;
  }

 private:
  const std::vector<double>& xyz_;
  GridFrame frame_;
  CellLists cells_;
};

}  // namespace foxi
