// The power-function visibility order against independent oracles: brute-force rays through pairs
// of tets, TetGen's Delaunay meshes of random points, structured grids with cospherical cells, exactly
// and nearly cospherical point sets, and the centroid-depth baseline that fails where it succeeds.
#include "foxi/viz/visibility_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "mesh_factory.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

std::vector<View> random_views(const Mesh& m, int n, unsigned seed) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < m.node_count(); ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], m.xyz[3 * i + k]);
      hi[k] = std::max(hi[k], m.xyz[3 * i + k]);
    }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g(0, 1);
  std::vector<View> views;
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0) {  // eye inside the bounding box
      views.push_back(View::at(lo[0] + u(rng) * (hi[0] - lo[0]), lo[1] + u(rng) * (hi[1] - lo[1]),
                               lo[2] + u(rng) * (hi[2] - lo[2])));
    } else if (i % 3 == 1) {  // eye outside, up to three box sizes away
      double p[3];
      for (int k = 0; k < 3; ++k) p[k] = lo[k] + (hi[k] - lo[k]) * (-3 + 7 * u(rng));
      views.push_back(View::at(p[0], p[1], p[2]));
    } else {
      views.push_back(View::along(g(rng), g(rng), g(rng)));
    }
  }
  return views;
}

std::size_t violations(const Mesh& m, const SphereTable& t, const View& v,
                       std::span<const std::uint32_t> subset = {}) {
  auto order = visibility_order(m, t, v, subset);
  EXPECT_EQ(order.size(), subset.empty() ? m.tet_count() : subset.size());
  return count_violations(m, v, order).violations;
}

// Parameter interval [t0, t1] of the ray o + t d inside tet `tet` (t >= tmin); empty if t1 <= t0.
std::pair<double, double> ray_interval(const Mesh& m, std::uint32_t tet, const double* o, const double* d,
                                       double tmin) {
  static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  double t0 = tmin, t1 = 1e300;
  const std::uint32_t* v = &m.tet[4 * std::size_t(tet)];
  for (int f = 0; f < 4; ++f) {
    const double* a = &m.xyz[3 * v[face[f][0]]];
    const double* b = &m.xyz[3 * v[face[f][1]]];
    const double* c = &m.xyz[3 * v[face[f][2]]];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    // Inside the tet: n.(x - a) < 0 (the tet's vertex f is on the negative side).
    double num = -(n[0] * (o[0] - a[0]) + n[1] * (o[1] - a[1]) + n[2] * (o[2] - a[2]));
    double den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    if (den == 0) {
      if (num <= 0) return {1, 0};
    } else if (den > 0) {
      t1 = std::min(t1, num / den);
    } else {
      t0 = std::max(t0, num / den);
    }
  }
  return {t0, t1};
}

// For every pair of tets and rays from the eye through random interior points of the first, the
// tet the ray enters first must come later in the back-to-front order. Returns contradictions.
std::size_t brute_force_contradictions(const Mesh& m, const View& view, std::span<const std::uint32_t> order,
                                       std::mt19937& rng, std::size_t* compared) {
  std::vector<std::uint32_t> pos(m.tet_count(), kNone);
  for (std::size_t i = 0; i < order.size(); ++i) pos[order[i]] = static_cast<std::uint32_t>(i);
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t bad = 0;
  for (std::uint32_t a : order) {
    for (int sample = 0; sample < 6; ++sample) {
      double w[4], sum = 0;
      for (double& x : w) sum += (x = -std::log(u(rng) + 1e-300));
      double x[3] = {0, 0, 0};
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j) x[j] += w[k] / sum * m.xyz[3 * m.tet[4 * std::size_t(a) + k] + j];
      double o[3], d[3], tmin;
      if (view.perspective) {
        for (int j = 0; j < 3; ++j) {
          o[j] = view.eye[j];
          d[j] = x[j] - view.eye[j];
        }
        tmin = 0;
      } else {
        for (int j = 0; j < 3; ++j) {
          d[j] = view.dir[j];
          o[j] = x[j] - 1e3 * view.dir[j];
        }
        tmin = -1e300;
      }
      auto ia = ray_interval(m, a, o, d, tmin);
      if (ia.second - ia.first < 1e-9) continue;
      for (std::uint32_t b : order) {
        if (b == a) continue;
        auto ib = ray_interval(m, b, o, d, tmin);
        if (ib.second - ib.first < 1e-9) continue;
        ++*compared;
        // Entered first = in front = must be drawn later.
        bool b_in_front = ib.first < ia.first;
        if (b_in_front != (pos[b] > pos[a])) ++bad;
      }
    }
  }
  return bad;
}

TEST(VisibilityOrder, TwoTetsSharingAFaceFromEverySide) {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1, 0.3, 0.3, -1};
  test::push_tet(m, 0, 1, 2, 3);
  test::push_tet(m, 0, 1, 2, 4);
  SphereTable t = compute_spheres(m);
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  std::size_t compared = 0;
  for (int i = 0; i < 200; ++i) {
    View v = i % 2 ? View::at(3 * g(rng), 3 * g(rng), 3 * g(rng)) : View::along(g(rng), g(rng), g(rng));
    auto order = visibility_order(m, t, v);
    ASSERT_EQ(order.size(), 2u);
    EXPECT_EQ(count_violations(m, v, order).violations, 0u);
    // Independent check: the tet on the eye's side of the plane z = 0 is in front, so it comes last.
    double side = v.perspective ? v.eye[2] : -v.dir[2];
    if (side != 0) {
      EXPECT_EQ(order[1], side > 0 ? 0u : 1u) << "view " << i;
    }
    EXPECT_EQ(brute_force_contradictions(m, v, order, rng, &compared), 0u);
  }
  EXPECT_GT(compared, 100u);
}

TEST(VisibilityOrder, RandomDelaunayMeshesHaveNoViolationsFromAnyView) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  // 10^3 to 10^5 tets; 100 eye points (inside and around the bounding box) and 100 directions.
  for (int n : {200, 3000, 16000}) {
    Mesh m = test::random_delaunay(dir, n, 11 + n, 2, 1, 1);
    ASSERT_GT(m.tet_count(), std::size_t(n));
    ASSERT_TRUE(compute_delaunay_certificate(m).delaunay);
    SphereTable t = compute_spheres(m);
    std::size_t eyes = 0, dirs = 0;
    for (const View& v : random_views(m, 150, 5)) {
      if (v.perspective ? eyes++ >= 100 : dirs++ >= 100) continue;
      ASSERT_EQ(violations(m, t, v), 0u);
    }
    for (int i = 0; i < 50; ++i) {  // random views give 2 eyes per direction: top the directions up
      std::mt19937 rng(700 + i);
      std::normal_distribution<double> g(0, 1);
      ASSERT_EQ(violations(m, t, View::along(g(rng), g(rng), g(rng))), 0u);
    }
  }
}

TEST(VisibilityOrder, FixedPointKeysStayWithinTheirBound) {
  // The whole-mesh key pass reads the table's fixed-point keys; its near-tie window relies on the
  // bound (bound_a + fixed_a) + (bound_b + fixed_b) |p|_1. Oracle: each item's key from its tet's
  // circumcentre computed again from the nodes in long double. A grid (clusters as items) and a
  // random mesh moved far from the coordinate origin.
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  std::vector<Mesh> meshes;
  meshes.push_back(test::random_delaunay(dir, 4000, 41, 2, 1, 1));
  for (std::size_t i = 0; i < meshes[0].xyz.size(); i += 3) meshes[0].xyz[i] += 1000;
  meshes.push_back(test::grid_mesh(9, 8, 7, 1, 0.5, 0.2, 6));
  for (const Mesh& m : meshes) {
    SphereTable t = compute_spheres(m);
    ASSERT_EQ(t.fixed_keys.size(), t.all_items.size());
    const double a = t.bound_a + t.fixed_a, b = t.bound_b + t.fixed_b;
    for (const View& v : random_views(m, 30, 17)) {
      if (!v.perspective) continue;
      long double p[3];
      for (int k = 0; k < 3; ++k) p[k] = static_cast<long double>(v.eye[k]) - t.origin[k];
      const double p1 = static_cast<double>(std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]));
      double worst = 0;
      for (std::size_t i = 0; i < t.all_items.size(); ++i) {
        const SphereTable::FixedKey& f = t.fixed_keys[i];
        const long double key_fixed =
            f.s * static_cast<long double>(t.s_unit) -
            2 * static_cast<long double>(t.c_unit) * (f.c[0] * p[0] + f.c[1] * p[1] + f.c[2] * p[2]);
        const std::uint32_t* q = &m.tet[4 * std::size_t(t.all_rep[i])];
        long double x[4][3];
        for (int j = 0; j < 4; ++j)
          for (int k = 0; k < 3; ++k) x[j][k] = static_cast<long double>(m.xyz[3 * q[j] + k]) - t.origin[k];
        long double e[3][3], l[3];
        for (int j = 0; j < 3; ++j) {
          for (int k = 0; k < 3; ++k) e[j][k] = x[j + 1][k] - x[0][k];
          l[j] = e[j][0] * e[j][0] + e[j][1] * e[j][1] + e[j][2] * e[j][2];
        }
        auto cross = [](const long double* u, const long double* w, long double* r) {
          r[0] = u[1] * w[2] - u[2] * w[1];
          r[1] = u[2] * w[0] - u[0] * w[2];
          r[2] = u[0] * w[1] - u[1] * w[0];
        };
        long double cd[3], db[3], bc[3];
        cross(e[1], e[2], cd);
        cross(e[2], e[0], db);
        cross(e[0], e[1], bc);
        const long double det = e[0][0] * cd[0] + e[0][1] * cd[1] + e[0][2] * cd[2];
        long double o[3], c[3];
        for (int k = 0; k < 3; ++k) {
          o[k] = (l[0] * cd[k] + l[1] * db[k] + l[2] * bc[k]) / (2 * det);
          c[k] = x[0][k] + o[k];
        }
        // s = |c|^2 - r^2 = |x0|^2 + 2 x0.o
        const long double s_exact = x[0][0] * x[0][0] + x[0][1] * x[0][1] + x[0][2] * x[0][2] +
                                    2 * (x[0][0] * o[0] + x[0][1] * o[1] + x[0][2] * o[2]);
        const long double key_exact = s_exact - 2 * (c[0] * p[0] + c[1] * p[1] + c[2] * p[2]);
        worst = std::max(worst, static_cast<double>(std::abs(key_fixed - key_exact)) / (a + b * p1));
      }
      EXPECT_LE(worst, 1.0);
      // The bound is tight (it sets the near-tie window): the rounding to fixed point is most of it.
      EXPECT_GT(worst, 0.05);
    }
  }
}

TEST(VisibilityOrder, NonConvexRandomSubsetsAndFrontToBack) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 2000, 7);
  SphereTable t = compute_spheres(m);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  for (const View& v : random_views(m, 60, 21)) {
    std::vector<std::uint32_t> subset;
    for (std::uint32_t i = 0; i < m.tet_count(); ++i)
      if (u(rng) < 0.3) subset.push_back(i);
    EXPECT_EQ(violations(m, t, v, subset), 0u);
    auto ftb = visibility_order(m, t, v, subset, true);
    std::reverse(ftb.begin(), ftb.end());
    EXPECT_EQ(count_violations(m, v, ftb).violations, 0u);
  }
}

TEST(VisibilityOrder, AgreesWithBruteForceRays) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 40, 3);
  SphereTable t = compute_spheres(m);
  std::mt19937 rng(4);
  std::size_t compared = 0;
  std::uniform_real_distribution<double> u(0, 1);
  for (const View& v : random_views(m, 24, 8)) {
    std::vector<std::uint32_t> subset;  // non-convex, maybe disconnected
    for (std::uint32_t i = 0; i < m.tet_count(); ++i)
      if (u(rng) < 0.6) subset.push_back(i);
    EXPECT_EQ(brute_force_contradictions(m, v, visibility_order(m, t, v, subset), rng, &compared), 0u);
  }
  EXPECT_GT(compared, 1000u);
}

// Cospherical cells cut by a subset or by the mesh's own boundary (a grid with tets left out: the
// fuzz finding undraw_kuhn_cube_missing_tet): two tets of one cube that share no face may face each
// other across a left-out tet, so the cube's faces alone no longer order it. Oracle: rays.
TEST(VisibilityOrder, GridCubesCutBySubsetsOrByTheMeshBoundaryAgreeWithRays) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  std::size_t compared = 0;
  for (int per_cell : {5, 6}) {
    const Mesh grid = test::grid_mesh(3, 3, 2, 1, 1, 1, per_cell);
    const SphereTable t = compute_spheres(grid);
    Mesh cut;  // the grid with about a third of its tets left out of the mesh itself
    cut.xyz = grid.xyz;
    for (std::uint32_t i = 0; i < grid.tet_count(); ++i)
      if (u(rng) < 0.65) cut.tet.insert(cut.tet.end(), &grid.tet[4 * i], &grid.tet[4 * i] + 4);
    ASSERT_TRUE(compute_delaunay_certificate(cut).delaunay);
    const SphereTable tc = compute_spheres(cut);
    EXPECT_GT(tc.separating_planes, 0u);
    for (const View& v : random_views(grid, 30, 17 + per_cell)) {
      std::vector<std::uint32_t> subset;
      for (std::uint32_t i = 0; i < grid.tet_count(); ++i)
        if (u(rng) < 0.5) subset.push_back(i);
      EXPECT_EQ(brute_force_contradictions(grid, v, visibility_order(grid, t, v, subset), rng, &compared), 0u)
          << "subset, " << per_cell << " tets a cube";
      EXPECT_EQ(brute_force_contradictions(cut, v, visibility_order(cut, tc, v), rng, &compared), 0u)
          << "cut mesh, " << per_cell << " tets a cube";
    }
  }
  EXPECT_GT(compared, 1000u);
}

TEST(VisibilityOrder, GridMeshesOfThePapersTable2) {
  // Nodes at cuboid corners with aspect ratios 1:1:1, 5:5:2, 10:5:1, each cuboid split into 5 or 6
  // tets: every cuboid is one cospherical cluster, where plain float keys tie.
  const double aspects[3][3] = {{1, 1, 1}, {5, 5, 2}, {10, 5, 1}};
  for (auto& a : aspects)
    for (int per_cell : {5, 6}) {
      Mesh m = test::grid_mesh(7, 6, 5, a[0], a[1], a[2], per_cell);
      ASSERT_TRUE(compute_delaunay_certificate(m).delaunay);
      SphereTable t = compute_spheres(m);
      EXPECT_EQ(t.cluster_count(), 7u * 6u * 5u);
      EXPECT_EQ(t.cluster_tets.size(), m.tet_count());
      std::size_t naive_violations = 0;
      for (const View& v : random_views(m, 60, 13)) {
        EXPECT_EQ(violations(m, t, v), 0u) << a[0] << ":" << a[1] << ":" << a[2] << " x" << per_cell;
        // Naive double keys with no tie handling: the baseline that the clusters fix.
        std::vector<std::pair<double, std::uint32_t>> keyed;
        for (std::uint32_t i = 0; i < m.tet_count(); ++i) {
          const double* c = &t.c[3 * i];
          double k = v.perspective ? t.s[i] - 2 * (c[0] * v.eye[0] + c[1] * v.eye[1] + c[2] * v.eye[2])
                                   : c[0] * v.dir[0] + c[1] * v.dir[1] + c[2] * v.dir[2];
          keyed.emplace_back(k, i);
        }
        std::sort(keyed.begin(), keyed.end(), [](auto& x, auto& y) { return x.first > y.first; });
        std::vector<std::uint32_t> naive;
        for (auto& k : keyed) naive.push_back(k.second);
        naive_violations += count_violations(m, v, naive).violations;
      }
      EXPECT_GT(naive_violations, 0u);
    }
}

TEST(VisibilityOrder, LargeGridSubsetsSplitAcrossThreadsAndBatches) {
  // Over 100,000 items (cells): the whole order is written by two threads straight to the tets'
  // places, counted per bucket; a subset cuts clusters (only some of a cell's tets), so a cluster
  // item stands for fewer tets. Oracles: the subset's tets exactly once, no violation (exact
  // orientation tests), and the progressive batches (first bucket ahead of the scatter) agree.
  Mesh m = test::grid_mesh(48, 46, 46, 1, 1, 1, 5);
  SphereTable t = compute_spheres(m);
  ASSERT_EQ(t.cluster_count(), 48u * 46u * 46u);
  ASSERT_GE(t.cluster_count(), 100000u);
  std::mt19937 rng(5);
  std::vector<std::uint32_t> subset;
  for (std::uint32_t i = 0; i < m.tet_count(); ++i)
    if (rng() % 8 != 0) subset.push_back(i);  // 7 in 8 tets: most cells lose one or two
  std::vector<std::uint32_t> order;
  for (const View& v : random_views(m, 3, 21)) {
    for (bool use_subset : {false, true}) {
      std::span<const std::uint32_t> s =
          use_subset ? std::span<const std::uint32_t>(subset) : std::span<const std::uint32_t>();
      visibility_order_into(order, m, t, v, s);
      std::vector<std::uint32_t> sorted_order = order,
                                 expected = use_subset ? subset : std::vector<std::uint32_t>();
      if (!use_subset)
        for (std::uint32_t i = 0; i < m.tet_count(); ++i) expected.push_back(i);
      std::sort(sorted_order.begin(), sorted_order.end());
      ASSERT_EQ(sorted_order, expected);
      EXPECT_EQ(count_violations(m, v, order).violations, 0u);
      ProgressiveOrder progressive(m, t, v, s);
      std::vector<std::uint32_t> all;
      for (auto b = progressive.next(); !b.empty(); b = progressive.next())
        all.insert(all.end(), b.begin(), b.end());
      EXPECT_EQ(all, order);
    }
  }
}

TEST(VisibilityOrder, OrdersBeyondTheCacheAreSortedPermutations) {
  // Over 2^21 items (a jittered grid: no cospherical cells, 2.24M tets): the key pass and the
  // scatter write around the cache (non-temporal stores, write-combining lines per bucket).
  // Oracles: the order is a permutation of the tets whose keys, recomputed in double from the
  // table, never rise by more than the two tets' rounding bounds; the progressive order, which
  // places its buckets by the plain scatter, hands out the same order.
  const int n = 72;
  Mesh m = test::grid_mesh(n, n, n, 1, 1, 1, 6);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  for (std::size_t v = 0; v < m.node_count(); ++v)
    for (int k = 0; k < 3; ++k) {
      double& x = m.xyz[3 * v + k];
      if (x > 0 && x < n) x += jitter(rng);
    }
  SphereTable t = compute_spheres(m);
  ASSERT_GT(t.all_items.size() + t.wide_items.size(), std::size_t(1) << 21);
  std::vector<std::uint32_t> order, expected(m.tet_count());
  for (std::uint32_t i = 0; i < m.tet_count(); ++i) expected[i] = i;
  const View views[3] = {View::at(-30, 20, 150), View::at(36, 37, 35), View::along(0.3, -0.5, 0.8)};
  for (const View& v : views)
    for (bool front_to_back : {false, true}) {
      if (front_to_back && !v.perspective) continue;
      visibility_order_into(order, m, t, v, {}, front_to_back);
      std::vector<std::uint32_t> sorted_order = order;
      std::sort(sorted_order.begin(), sorted_order.end());
      ASSERT_EQ(sorted_order, expected);
      double p[3];
      for (int k = 0; k < 3; ++k) p[k] = v.perspective ? v.eye[k] - t.origin[k] : v.dir[k];
      const double np = std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]);
      auto key = [&](std::uint32_t tet) {  // drawn in decreasing key, back to front
        const double* c = &t.c[3 * std::size_t(tet)];
        const double k = v.perspective ? t.s[tet] - 2 * (c[0] * p[0] + c[1] * p[1] + c[2] * p[2])
                                       : c[0] * p[0] + c[1] * p[1] + c[2] * p[2];
        return front_to_back ? -k : k;
      };
      auto err = [&](std::uint32_t tet) { return (v.perspective ? t.key_a[tet] : 0.f) + t.key_b[tet] * np; };
      std::size_t rises = 0;
      for (std::size_t i = 0; i + 1 < order.size(); ++i)
        if (key(order[i + 1]) > key(order[i]) + err(order[i]) + err(order[i + 1])) ++rises;
      EXPECT_EQ(rises, 0u);
      ProgressiveOrder progressive(m, t, v, {}, front_to_back);
      std::size_t at = 0, mismatches = 0;
      for (auto b = progressive.next(); !b.empty(); b = progressive.next())
        for (std::uint32_t tet : b) mismatches += at < order.size() && order[at++] == tet ? 0 : 1;
      EXPECT_EQ(at, order.size());
      EXPECT_EQ(mismatches, 0u);
    }
}

TEST(VisibilityOrder, ExactlyCosphericalPointsFormOneCluster) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::integer_sphere_delaunay(dir, 425);  // 336 integer points on one sphere
  ASSERT_GT(m.tet_count(), 300u);
  ASSERT_TRUE(compute_delaunay_certificate(m).delaunay);
  SphereTable t = compute_spheres(m);
  EXPECT_EQ(t.cluster_count(), 1u);
  EXPECT_EQ(t.cluster_tets.size(), m.tet_count());
  std::mt19937 rng(1);
  std::size_t compared = 0;
  for (const View& v : random_views(m, 60, 17)) {
    OrderStats stats;
    auto order = visibility_order(m, t, v, {}, false, &stats);
    EXPECT_EQ(count_violations(m, v, order).violations, 0u);
    EXPECT_EQ(stats.cluster_cycles, 0u);
  }
  for (const View& v : random_views(m, 3, 19))
    EXPECT_EQ(brute_force_contradictions(m, v, visibility_order(m, t, v), rng, &compared), 0u);
}

TEST(VisibilityOrder, NearlyCosphericalPointsNeedExactTieBreaks) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  // Points normalized to the unit sphere in double: off the sphere by rounding only, so the
  // circumspheres differ by a few ulps and the float keys of neighbours nearly tie.
  Mesh m = test::sphere_points_delaunay(dir, 400, 5);
  ASSERT_TRUE(compute_delaunay_certificate(m).delaunay);
  SphereTable t = compute_spheres(m);
  std::size_t runs = 0;
  for (const View& v : random_views(m, 60, 23)) {
    OrderStats stats;
    auto order = visibility_order(m, t, v, {}, false, &stats);
    EXPECT_EQ(count_violations(m, v, order).violations, 0u);
    runs += stats.near_tie_runs;
  }
  EXPECT_GT(runs + t.cluster_count(), 0u);  // the ties were met, not dodged
}

TEST(VisibilityOrder, CentroidDepthOrderFailsWherePowerOrderDoesNot) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 2000, 31);
  SphereTable t = compute_spheres(m);
  std::size_t centroid_bad = 0;
  for (const View& v : random_views(m, 30, 2)) {
    EXPECT_EQ(violations(m, t, v), 0u);
    centroid_bad += count_violations(m, v, centroid_order(m, v)).violations;
  }
  EXPECT_GT(centroid_bad, 30u);
}

TEST(VisibilityOrder, ProgressiveBatchesConcatenateToTheWholeOrder) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 3000, 41);
  SphereTable t = compute_spheres(m);
  View v = View::at(0.3, -2, 0.7);
  ProgressiveOrder progressive(m, t, v);
  std::vector<std::uint32_t> all;
  std::size_t batches = 0;
  for (auto b = progressive.next(); !b.empty(); b = progressive.next()) {
    all.insert(all.end(), b.begin(), b.end());
    ++batches;
  }
  EXPECT_GT(batches, 10u);
  EXPECT_EQ(all, visibility_order(m, t, v));
  std::vector<std::uint32_t> sorted = all;
  std::sort(sorted.begin(), sorted.end());
  for (std::uint32_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);
}

TEST(VisibilityOrder, ProgressiveSortingAheadOnASecondThread) {
  // 50,000 tets and more: buckets are sorted ahead on a worker thread while batches are taken.
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 9000, 43);
  ASSERT_GE(m.tet_count(), 50000u);
  SphereTable t = compute_spheres(m);
  for (const View& v : random_views(m, 6, 77)) {
    ProgressiveOrder progressive(m, t, v);
    std::vector<std::uint32_t> all;
    for (auto b = progressive.next(); !b.empty(); b = progressive.next())
      all.insert(all.end(), b.begin(), b.end());
    EXPECT_EQ(progressive.handed_out(), m.tet_count());
    EXPECT_EQ(all, visibility_order(m, t, v));
    EXPECT_EQ(count_violations(m, v, all).violations, 0u);
  }
  // Stopping early (a user's stop button): destroying the order stops the worker.
  for (int k = 0; k < 5; ++k) {
    ProgressiveOrder progressive(m, t, View::at(0.5, -3, 0.5 + k));
    auto first = progressive.next();
    EXPECT_FALSE(first.empty());
  }
}

TEST(VisibilityOrder, FirstBatchFromKeyBlocksIsThePrefixOfTheWholeOrder) {
  // A whole-mesh progressive order finds its first batch from the blocks of keys whose bounds may
  // reach it (SphereTable::key_blocks), before any other key is computed: it must be exactly the
  // start of the whole order (a second algorithm: every key, all buckets), from eyes inside and
  // outside, along directions, back to front and front to back, whatever the tets' numbering (here
  // shuffled, so that the mesh's order gives the blocks nothing).
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh tetgen_mesh = test::random_delaunay(dir, 9000, 47);
  Mesh m;
  m.xyz = tetgen_mesh.xyz;
  const std::size_t n = tetgen_mesh.tet_count();
  ASSERT_GE(n, 50000u);
  std::vector<std::uint32_t> shuffle(n);
  for (std::uint32_t i = 0; i < n; ++i) shuffle[i] = i;
  std::shuffle(shuffle.begin(), shuffle.end(), std::mt19937(5));
  for (std::uint32_t t : shuffle)
    m.tet.insert(m.tet.end(), tetgen_mesh.tet.begin() + 4 * std::ptrdiff_t(t),
                 tetgen_mesh.tet.begin() + 4 * std::ptrdiff_t(t + 1));
  SphereTable t = compute_spheres(m);
  ASSERT_EQ(t.key_order.size(), t.fixed_keys.size());
  std::size_t compared = 0, keys_read = 0;
  for (const View& v : random_views(m, 24, 91)) {
    for (bool ftb : {false, true}) {
      ProgressiveOrder progressive(m, t, v, {}, ftb);
      const auto batch = progressive.next();
      const std::vector<std::uint32_t> first(batch.begin(), batch.end());
      ASSERT_FALSE(first.empty());
      const std::vector<std::uint32_t> whole = visibility_order(m, t, v, {}, ftb);
      ASSERT_TRUE(std::equal(first.begin(), first.end(), whole.begin()));
      // (Hull slivers' huge spheres can stretch the quantisation so that the head is most of the
      // mesh: then the blocks cannot save much.)
      EXPECT_GT(progressive.stats().first_batch_keys, 0u);
      if (first.size() < n / 100) {
        ++compared;
        keys_read += progressive.stats().first_batch_keys;
      }
    }
  }
  // A small first batch came from a small part of the keys (about 64 a block read).
  ASSERT_GE(compared, 30u);
  EXPECT_LT(keys_read / compared, n / 5);
}

// TetGen's Delaunay mesh of random points in the unit cube with a few small cubes' corners added,
// each cube inscribed in a ball kept free of the random points, so that each cube is meshed by
// 5 or 6 tets with one circumsphere: a few cospherical clusters (with those of 2 tets that each
// square face makes with an outside apex) in a mesh otherwise without any.
Mesh few_cubes_delaunay(const test::TempDir& dir, int points, int cubes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double radius = 0.03, half = radius / std::sqrt(3.0);
  std::vector<std::array<double, 3>> centres;
  for (int k = 0; k < cubes; ++k)
    centres.push_back({0.15 + 0.7 * u(rng), 0.15 + 0.7 * u(rng), 0.15 + 0.7 * u(rng)});
  std::vector<std::array<double, 3>> xyz;
  while (xyz.size() < std::size_t(points)) {
    const std::array<double, 3> p = {u(rng), u(rng), u(rng)};
    bool free = true;
    for (const auto& c : centres) {
      const double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
      free = free && d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 1.5 * 1.5 * radius * radius;
    }
    if (free) xyz.push_back(p);
  }
  for (const auto& c : centres)
    for (int corner = 0; corner < 8; ++corner)
      xyz.push_back({c[0] + (corner & 1 ? half : -half), c[1] + (corner & 2 ? half : -half),
                     c[2] + (corner & 4 ? half : -half)});
  std::string text = std::to_string(xyz.size()) + " 3 0 0\n";
  char line[128];
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    std::snprintf(line, sizeof line, "%zu %.17g %.17g %.17g\n", i + 1, xyz[i][0], xyz[i][1], xyz[i][2]);
    text += line;
  }
  test::write_text(dir / "cubes.node", text);
  test::run("cd '" + dir.path().string() + "' && tetgen -Q cubes.node", dir / "tetgen.log");
  return read_tetgen(dir / "cubes.1");
}

TEST(VisibilityOrder, AFewSplitClustersAreDrawnAsUnits) {
  // A mesh with a few clusters keeps them split in its whole-mesh items (SphereTable::
  // clusters_split): each cluster must still come out as one unit, in its local order. Oracles: the
  // violation count, each cluster's tets adjacent in the order, and the order with clusters as
  // items (a subset of every tet takes that path) giving the same order; the progressive order
  // (first batch from key blocks, the rest on a worker) concatenating to it too.
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = few_cubes_delaunay(dir, 17000, 4, 5);
  const std::size_t n = m.tet_count();
  ASSERT_GE(n, 100000u);  // both cores sort (two halves)
  ASSERT_TRUE(compute_delaunay_certificate(m).delaunay);
  SphereTable t = compute_spheres(m);
  // Each cube (6 tets here), and on each of its faces the two tets outside it that share the
  // face's square and an apex (2 tets on one sphere).
  std::size_t cubes = 0;
  for (std::size_t k = 0; k < t.cluster_count(); ++k)
    cubes += t.cluster_begin[k + 1] - t.cluster_begin[k] >= 5;
  ASSERT_EQ(cubes, 4u);
  ASSERT_TRUE(t.clusters_split);
  ASSERT_EQ(t.all_items.size() + t.wide_items.size(), n);
  std::vector<std::uint32_t> every(n);
  for (std::uint32_t i = 0; i < n; ++i) every[i] = i;
  for (const View& v : random_views(m, 18, 23)) {
    for (bool ftb : {false, true}) {
      const std::vector<std::uint32_t> whole = visibility_order(m, t, v, {}, ftb);
      ASSERT_EQ(whole.size(), n);
      if (!ftb) {
        EXPECT_EQ(count_violations(m, v, whole).violations, 0u);
      }
      std::vector<std::uint32_t> pos(n);
      for (std::uint32_t i = 0; i < n; ++i) pos[whole[i]] = i;
      for (std::size_t k = 0; k < t.cluster_count(); ++k) {
        std::uint32_t lo = kNone, hi = 0;
        for (std::uint32_t i = t.cluster_begin[k]; i < t.cluster_begin[k + 1]; ++i) {
          lo = std::min(lo, pos[t.cluster_tets[i]]);
          hi = std::max(hi, pos[t.cluster_tets[i]]);
        }
        EXPECT_EQ(hi - lo + 1, t.cluster_begin[k + 1] - t.cluster_begin[k]);
      }
      EXPECT_EQ(whole, visibility_order(m, t, v, every, ftb));
      ProgressiveOrder progressive(m, t, v, {}, ftb);
      std::vector<std::uint32_t> all;
      for (auto b = progressive.next(); !b.empty(); b = progressive.next())
        all.insert(all.end(), b.begin(), b.end());
      EXPECT_EQ(all, whole);
    }
  }
}

TEST(VisibilityOrder, NonDelaunayMeshIsReportedAndMpvoOrdersIt) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  // TetGen with its mesh optimisation (flips, smoothing): not Delaunay, as measured in issue 6.
  test::write_text(dir / "t.poly",
                   test::read_text(std::string(FOXI_TEST_DATA_DIR) + "/../../examples/trench.poly"));
  ASSERT_EQ(test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a0.0005Q t.poly"), 0);
  Mesh m = read_tetgen(dir / "t.1");
  DelaunayCertificate cert = compute_delaunay_certificate(m);
  ASSERT_FALSE(cert.delaunay);
  SphereTable t = compute_spheres(m);
  std::size_t power_bad = 0, mpvo_bad = 0;
  for (const View& v : random_views(m, 30, 6)) {
    power_bad += count_violations(m, v, visibility_order(m, t, v)).violations;
    std::size_t cycles = 0;
    auto order = mpvo_order(m, t, v, {}, &cycles);
    ASSERT_EQ(order.size(), m.tet_count());
    std::size_t bad = count_violations(m, v, order).violations;
    // MPVO violates only where it had to break a cycle.
    EXPECT_LE(bad, 8 * cycles);
    mpvo_bad += bad;
  }
  EXPECT_LE(mpvo_bad, power_bad);
}

TEST(VisibilityOrder, EqualWeightsGiveTheUnweightedOrder) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 500, 51);
  Mesh w = m;
  w.weight.assign(w.node_count(), 0.25);
  SphereTable tm = compute_spheres(m), tw = compute_spheres(w);
  EXPECT_TRUE(tw.weighted);
  for (const View& v : random_views(m, 20, 3)) {
    EXPECT_EQ(count_violations(w, v, visibility_order(w, tw, v)).violations, 0u);
    EXPECT_EQ(visibility_order(w, tw, v), visibility_order(m, tm, v));
  }
}

// Found by fuzzing (tests/data/bad/fuzz/mesh_pipeline/infinite_weight): a weight of infinity or NaN
// (a .vtu's 'weight' array may hold one; validation now refuses it, foxi render does not validate)
// reached the exact recomputation of the orthocentre, where GMP raised SIGFPE. Such a tet has no
// sphere: it is ordered as a flat tet, like the certificate's degenerate ones.
TEST(VisibilityOrder, NonFiniteWeightsGiveFlatTetsNotACrash) {
  for (double bad : {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    Mesh m;
    m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1, 0.3, 0.3, -1};
    test::push_tet(m, 0, 1, 2, 3);
    test::push_tet(m, 0, 1, 2, 4);
    m.weight = {0, bad, 0, 0, 0};
    const SphereTable t = compute_spheres(m);
    EXPECT_EQ(t.flat[0], 1);
    EXPECT_EQ(t.flat[1], 1);
    auto order = visibility_order(m, t, View::at(0.2, 0.2, 5));
    std::sort(order.begin(), order.end());
    EXPECT_EQ(order, (std::vector<std::uint32_t>{0, 1}));
  }
}

}  // namespace
}  // namespace foxi
