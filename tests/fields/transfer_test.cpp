// Field transfer by location and by id. Oracles: a linear field, which linear interpolation
// reproduces exactly, between two different meshes of one box (TetGen's and a jittered Kuhn grid);
// a brute-force scan over every source tet for containment (with determinants, not the grid's
// inverse matrices) and for the nearest node; region layers whose expected outside set is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bench_meshes.hpp"
#include "foxi/fields.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

double linear(const double* p) { return 1 + 2 * p[0] - 3 * p[1] + 0.5 * p[2]; }

FieldSource source_of(Mesh m, const std::string& name = "src") {
  FieldSource s;
  s.path = name;
  s.format = "vtu";
  s.mesh = std::move(m);
  return s;
}

TransferParams names(std::vector<std::string> n) {
  TransferParams p;
  p.names = std::move(n);
  return p;
}
TransferParams by_id(std::vector<std::string> n = {}) {
  TransferParams p = names(std::move(n));
  p.by = MatchBy::id;
  return p;
}

// Adds a scalar node field f and a vector node field (f, 2f, -f) over two steps (the second 10 f).
void add_linear_fields(Mesh& m) {
  Field f{"f", FieldLocation::node, 1, "K", {0, 1}, {}};
  Field v{"v", FieldLocation::node, 3, "m", {}, {}};
  for (int s = 0; s < 2; ++s)
    for (std::size_t i = 0; i < m.node_count(); ++i) f.values.push_back((s ? 10 : 1) * linear(&m.xyz[3 * i]));
  for (std::size_t i = 0; i < m.node_count(); ++i)
    for (double k : {1.0, 2.0, -1.0}) v.values.push_back(k * linear(&m.xyz[3 * i]));
  m.fields = {f, v};
}

// Keeps the tets whose centroid passes keep (nodes stay, some unused).
template <class Keep>
Mesh keep_tets(const Mesh& m, Keep keep) {
  Mesh r = m;
  r.tet.clear();
  r.tet_region.clear();
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    double c[3] = {0, 0, 0};
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k) c[k] += m.xyz[3 * std::size_t(m.tet[4 * t + j]) + k] / 4;
    if (!keep(c)) continue;
    r.tet.insert(r.tet.end(), m.tet.begin() + 4 * t, m.tet.begin() + 4 * t + 4);
    if (!m.tet_region.empty()) r.tet_region.push_back(m.tet_region[t]);
  }
  r.bface.clear();
  r.bface_tag.clear();
  r.fields.clear();
  return r;
}

// Brute force: is p in some tet of m (no barycentric coordinate below -tol), by signed volumes.
bool inside_scan(const Mesh& m, const double* p, double tol) {
  auto det = [](const double* a, const double* b, const double* c, const double* d) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
                 w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
  };
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const double* q[4];
    for (int j = 0; j < 4; ++j) q[j] = &m.xyz[3 * std::size_t(m.tet[4 * t + j])];
    const double vol = det(q[0], q[1], q[2], q[3]);
    bool in = true;
    for (int j = 0; j < 4 && in; ++j) {
      const double* r[4] = {q[0], q[1], q[2], q[3]};
      r[j] = p;
      in = det(r[0], r[1], r[2], r[3]) / vol >= -tol;
    }
    if (in) return true;
  }
  return false;
}

TEST(FieldTransfer, LinearFieldBetweenTwoMeshesOfABoxIsExact) {
  if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  Mesh src = bench::tetgen_box_mesh(1, 1, 1, 0.002);
  add_linear_fields(src);
  const Mesh target = bench::kuhn_grid_mesh(9, 0.3, 7);
  ASSERT_GT(src.tet_count(), 500u);
  const TransferReport rep = transfer_fields(source_of(src), target);
  EXPECT_EQ(rep.nodes_outside, 0u);  // the same box: its boundary nodes too are inside, on faces
  EXPECT_EQ(rep.nan_values, 0u);
  ASSERT_EQ(rep.fields.size(), 2u);
  const Field& f = rep.fields[0];
  ASSERT_EQ(f.step_count(), 2u);
  EXPECT_EQ(f.step_values, (std::vector<double>{0, 1}));
  EXPECT_EQ(f.unit, "K");
  double worst = 0;
  const std::size_t n = target.node_count();
  for (std::size_t i = 0; i < n; ++i) {
    const double want = linear(&target.xyz[3 * i]);
    worst = std::max(worst, std::abs(f.values[i] - want));
    worst = std::max(worst, std::abs(f.values[n + i] - 10 * want) / 10);
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(rep.fields[1].values[3 * i + k] - (k == 0   ? 1
                                                                          : k == 1 ? 2
                                                                                   : -1) *
                                                                             want) /
                                  2);
  }
  EXPECT_LT(worst, 1e-13) << "linear interpolation of a linear field must be exact to rounding";
}

// Outside counts on non-convex meshes against the brute-force scan: an L-shaped source under a full
// box target, and an L-shaped target sticking out of a box source.
TEST(FieldTransfer, OutsideCountsOnNonConvexMeshesMatchABruteForceScan) {
  const double tol = 1e-9;
  Mesh box = bench::kuhn_grid_mesh(6, 0.25, 3);
  box.tet_region.clear();
  Mesh ell = keep_tets(bench::kuhn_grid_mesh(7, 0.2, 5),
                       [](const double* c) { return !(c[0] > 0.5 && c[1] > 0.5); });
  ell.tet_region.clear();
  for (int shifted = 0; shifted < 2; ++shifted) {
    Mesh src = shifted ? box : ell;
    Mesh target = shifted ? ell : box;
    if (shifted)  // the L moved so that part of it lies beyond the box
      for (std::size_t i = 0; i < target.xyz.size(); i += 3) target.xyz[i] += 0.37, target.xyz[i + 2] -= 0.21;
    add_linear_fields(src);
    TransferParams p;
    p.names = {"f"};
    const TransferReport rep = transfer_fields(source_of(src), target, p);
    std::size_t scan_outside = 0;
    double worst = 0;
    for (std::size_t i = 0; i < target.node_count(); ++i) {
      const bool in = inside_scan(src, &target.xyz[3 * i], tol);
      scan_outside += !in;
      const double got = rep.fields[0].values[i];
      EXPECT_EQ(std::isnan(got), !in) << "node " << i;
      if (in) worst = std::max(worst, std::abs(got - linear(&target.xyz[3 * i])));
    }
    EXPECT_GT(scan_outside, 10u);
    EXPECT_LT(scan_outside, target.node_count() - 10);
    EXPECT_EQ(rep.nodes_outside, scan_outside) << (shifted ? "shifted L target" : "L source");
    EXPECT_EQ(rep.nan_values, 2 * scan_outside);  // two steps
    EXPECT_LT(worst, 1e-13);
  }
}

TEST(FieldTransfer, NearestOutsideTakesTheNearestSourceNode) {
  Mesh src = bench::kuhn_grid_mesh(5, 0.2, 9);
  src.tet_region.clear();
  add_linear_fields(src);
  Mesh target = bench::kuhn_grid_mesh(4, 0.2, 2);
  target.tet_region.clear();
  for (double& x : target.xyz) x = 1.5 * x - 0.25;  // sticks out on every side
  TransferParams p;
  p.outside = Outside::nearest;
  p.names = {"f"};
  const TransferReport rep = transfer_fields(source_of(src), target, p);
  ASSERT_GT(rep.nodes_outside, 0u);
  EXPECT_EQ(rep.nan_values, 0u);
  for (std::size_t i = 0; i < target.node_count(); ++i) {
    if (inside_scan(src, &target.xyz[3 * i], 1e-9)) continue;
    double best = std::numeric_limits<double>::infinity();
    std::size_t arg = 0;
    for (std::size_t s = 0; s < src.node_count(); ++s) {
      double d = 0;
      for (int k = 0; k < 3; ++k) d += std::pow(src.xyz[3 * s + k] - target.xyz[3 * i + k], 2);
      if (d < best) best = d, arg = s;
    }
    EXPECT_EQ(rep.fields[0].values[i], src.fields[0].values[arg]) << "node " << i;
  }
}

// Regions: a target node looks only in source tets of its own regions. Source layers: region 1
// below z = 1/4, region 2 above; target: region 1 below z = 1/2. Target nodes strictly between
// 1/4 and 1/2 touch only region-1 target tets, and no region-1 source tet holds them: outside.
TEST(FieldTransfer, ValuesStayInTheirRegion) {
  Mesh src = bench::cube_grid_mesh(4);
  for (std::size_t t = 0; t < src.tet_count(); ++t) {
    double z = 0;
    for (int j = 0; j < 4; ++j) z += src.xyz[3 * std::size_t(src.tet[4 * t + j]) + 2] / 4;
    src.tet_region[t] = z < 0.25 ? 1 : 2;
  }
  add_linear_fields(src);
  Field c{"c", FieldLocation::cell, 1, "", {}, {}};
  for (std::size_t t = 0; t < src.tet_count(); ++t) c.values.push_back(src.tet_region[t]);
  src.fields.push_back(c);
  const Mesh target = bench::cube_grid_mesh(6);  // regions 1 (z < 1/2) and 2
  TransferParams p;
  const TransferReport rep = transfer_fields(source_of(src), target, p);
  std::size_t expect_nodes = 0;
  for (std::size_t i = 0; i < target.node_count(); ++i) {
    const double z = target.xyz[3 * i + 2];
    const bool out = z > 0.25 + 1e-12 && z < 0.5 - 1e-12;
    expect_nodes += out;
    EXPECT_EQ(std::isnan(rep.fields[0].values[i]), out) << "z " << z;
  }
  EXPECT_EQ(expect_nodes, 7u * 7u);
  EXPECT_EQ(rep.nodes_outside, expect_nodes);
  // Cells: a region-1 target tet whose centroid lies above 1/4 has no region-1 source tet there;
  // every other target tet gets its own region's value, never the other's.
  // Centroids on the source's interface plane (z = 1/4 up to rounding) may go either way.
  std::size_t expect_cells = 0, ties = 0;
  for (std::size_t t = 0; t < target.tet_count(); ++t) {
    double z = 0;
    for (int j = 0; j < 4; ++j) z += target.xyz[3 * std::size_t(target.tet[4 * t + j]) + 2] / 4;
    const double got = rep.fields[2].values[t];
    if (target.tet_region[t] == 1 && std::abs(z - 0.25) < 1e-9) {
      ++ties;
      EXPECT_TRUE(std::isnan(got) || got == 1) << "tet " << t;
    } else if (target.tet_region[t] == 1 && z > 0.25) {
      ++expect_cells;
      EXPECT_TRUE(std::isnan(got));
    } else {
      EXPECT_EQ(got, target.tet_region[t]) << "tet " << t;
    }
  }
  EXPECT_GT(expect_cells, 0u);
  EXPECT_GE(rep.cells_outside, expect_cells);
  EXPECT_LE(rep.cells_outside, expect_cells + ties);
  // A node of no target tet keeps to no region: located wherever it lies.
  Mesh loose = target;
  loose.xyz.insert(loose.xyz.end(), {0.5, 0.5, 0.4});
  const TransferReport lr = transfer_fields(source_of(src), loose, p);
  EXPECT_EQ(lr.nodes_outside, expect_nodes);
  EXPECT_NEAR(lr.fields[0].values[loose.node_count() - 1], linear(&loose.xyz[loose.xyz.size() - 3]), 1e-13);
  // Without the region rule every node is inside (one box).
  p.match_regions = false;
  EXPECT_EQ(transfer_fields(source_of(src), target, p).nodes_outside, 0u);
  // A target region the source lacks is refused rather than left all outside.
  Mesh other = target;
  other.tet_region[0] = 7;
  p.match_regions = true;
  EXPECT_THROW(transfer_fields(source_of(src), other, p), FieldError);
}

TEST(FieldTransfer, LocatePointsAgreesWithTheScan) {
  const Mesh m = bench::kuhn_grid_mesh(5, 0.3, 11);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  std::vector<double> pts(3 * 3000);
  for (double& x : pts) x = u(rng);
  const PointLocation loc = locate_points(m, pts);
  for (std::size_t i = 0; i < pts.size() / 3; ++i) {
    ASSERT_EQ(loc.tet[i] != kNone, inside_scan(m, &pts[3 * i], 1e-9)) << i;
    if (loc.tet[i] == kNone) continue;
    double q[3] = {0, 0, 0}, s = 0;  // the barycentric coordinates give the point back
    for (int j = 0; j < 4; ++j) {
      s += loc.bary[4 * i + j];
      for (int k = 0; k < 3; ++k)
        q[k] += loc.bary[4 * i + j] * m.xyz[3 * std::size_t(m.tet[4 * loc.tet[i] + j]) + k];
    }
    EXPECT_NEAR(s, 1, 1e-14);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(q[k], pts[3 * i + k], 1e-14);
  }
}

TEST(FieldTransfer, ByIdChecksTheMesh) {
  Mesh m = bench::kuhn_grid_mesh(3, 0.2, 1);
  add_linear_fields(m);
  Mesh target = m;
  target.fields.clear();
  const TransferReport rep = transfer_fields(source_of(m), target, by_id());
  ASSERT_EQ(rep.fields.size(), 2u);
  EXPECT_EQ(rep.fields[0].values, m.fields[0].values);
  EXPECT_EQ(rep.nodes_missing, 0u);
  // Another mesh (a node moved, a node fewer, other tets): refused, never a silent mismatch.
  Mesh moved = target;
  moved.xyz[3 * 20] += 0.01;
  EXPECT_THROW(transfer_fields(source_of(m), moved, by_id()), FieldError);
  Mesh other = bench::kuhn_grid_mesh(4, 0.2, 1);
  EXPECT_THROW(transfer_fields(source_of(m), other, by_id()), FieldError);
  Mesh swapped = target;
  std::swap(swapped.tet[0], swapped.tet[swapped.tet.size() - 1]);  // tets of two far cubes
  EXPECT_THROW(transfer_fields(source_of(m), swapped, by_id()), FieldError);
  // A field that is not there, and a unit that differs from the target's field of that name.
  EXPECT_THROW(transfer_fields(source_of(m), target, by_id({"nope"})), FieldError);
  Mesh with_unit = target;
  with_unit.fields.push_back(
      Field{"f", FieldLocation::node, 1, "degC", {}, std::vector<double>(m.node_count(), 0)});
  EXPECT_THROW(transfer_fields(source_of(m), with_unit, by_id()), FieldError);
}

TEST(FieldTransfer, NanValuesAreKeptAndCounted) {
  Mesh m = bench::kuhn_grid_mesh(3, 0.0, 1);
  add_linear_fields(m);
  m.fields[0].values[5] = std::numeric_limits<double>::quiet_NaN();
  Mesh target = m;
  target.fields.clear();
  const TransferReport rep = transfer_fields(source_of(m), target, by_id({"f"}));
  EXPECT_TRUE(std::isnan(rep.fields[0].values[5]));
  EXPECT_EQ(rep.nan_values, 1u);
  // By location the NaN spreads to what is interpolated from that node, and is counted there too.
  const TransferReport loc = transfer_fields(source_of(m), target, names({"f"}));
  EXPECT_TRUE(std::isnan(loc.fields[0].values[5]));
  EXPECT_GE(loc.nan_values, 1u);
  EXPECT_EQ(loc.nan_values,
            std::size_t(std::count_if(loc.fields[0].values.begin(), loc.fields[0].values.end(),
                                      [](double v) { return std::isnan(v); })));
}

}  // namespace
}  // namespace foxi
