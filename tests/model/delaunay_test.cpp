// The Delaunay certificate against independent oracles: a brute-force O(tets x vertices) check with
// CGAL's exact predicates over all vertices, TetGen's own output (-O0 meshes are Delaunay), analytic
// cases (cospherical grids, hand-placed weights).
#include "foxi/model/delaunay.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_meshes.hpp"
#include "plc_text.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using WPoint = K::Weighted_point_3;

// --- the brute-force oracle -------------------------------------------------------------------------
struct Brute {
  std::vector<std::uint32_t> violating;  // ascending
  std::size_t on_sphere = 0;             // (tet, other vertex) pairs exactly on the sphere
  std::size_t degenerate = 0;
};

// Every tet against every vertex used by some tet (the tet's own four skipped), exact predicates.
// To keep the Debug+ASan run short, a vertex farther than 1.5 (power) radii from the circum- or
// orthocentre (long double; its error is far below r/2 unless the tet is nearly flat) is skipped;
// nearly flat tets (|6V| < 1e-6 l_max^3) get every vertex. Split over two threads.
Brute brute_force(const Mesh& m) {
  const bool weighted = !m.weight.empty();
  std::vector<std::uint8_t> used(m.node_count(), 0);
  for (auto v : m.tet) used[v] = 1;
  std::vector<std::uint32_t> verts;
  for (std::uint32_t v = 0; v < used.size(); ++v)
    if (used[v]) verts.push_back(v);
  auto pt = [&](std::uint32_t v) { return Point(m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]); };
  auto wpt = [&](std::uint32_t v) { return WPoint(pt(v), weighted ? m.weight[v] : 0.0); };
  const std::size_t n = m.tet_count();
  std::vector<std::uint8_t> bad(n, 0), flat(n, 0);
  std::vector<std::size_t> on(2, 0);
  auto work = [&](unsigned part) {
    for (std::size_t t = part; t < n; t += 2) {
      std::uint32_t v[4] = {m.tet[4 * t], m.tet[4 * t + 1], m.tet[4 * t + 2], m.tet[4 * t + 3]};
      CGAL::Orientation o = CGAL::orientation(pt(v[0]), pt(v[1]), pt(v[2]), pt(v[3]));
      if (o == CGAL::COPLANAR) {
        flat[t] = 1;
        continue;
      }
      if (o == CGAL::NEGATIVE) std::swap(v[2], v[3]);
      // Circumcentre in long double (Cramer's rule relative to v0).
      long double e[3][3], l2[3], lmax = 0;
      auto wt = [&](std::uint32_t i) { return weighted ? static_cast<long double>(m.weight[i]) : 0.0L; };
      for (int i = 0; i < 3; ++i) {
        l2[i] = -(wt(v[i + 1]) - wt(v[0]));
        for (int d = 0; d < 3; ++d) {
          e[i][d] = static_cast<long double>(m.xyz[3 * v[i + 1] + d]) - m.xyz[3 * v[0] + d];
          l2[i] += e[i][d] * e[i][d];
        }
        lmax = std::max(lmax, std::sqrt(l2[i] + wt(v[i + 1]) - wt(v[0])));
      }
      auto det3 = [](long double a[3], long double b[3], long double c[3]) {
        return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
      };
      const long double det = det3(e[0], e[1], e[2]);
      const bool all = std::fabs(det) < 1e-6L * lmax * lmax * lmax;
      long double c[3] = {0, 0, 0}, r2 = 0;
      if (!all) {
        for (int d = 0; d < 3; ++d) {
          long double mcol[3][3];
          for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) mcol[i][k] = k == d ? l2[i] / 2 : e[i][k];
          c[d] = det3(mcol[0], mcol[1], mcol[2]) / det;
          r2 += c[d] * c[d];
        }
        r2 -= wt(v[0]);  // power radius^2 (the orthosphere's; the circumsphere's when unweighted)
      }
      for (std::uint32_t q : verts) {
        if (q == v[0] || q == v[1] || q == v[2] || q == v[3]) continue;
        if (!all) {
          long double d2 = 0;
          for (int d = 0; d < 3; ++d) {
            const long double x = static_cast<long double>(m.xyz[3 * q + d]) - m.xyz[3 * v[0] + d] - c[d];
            d2 += x * x;
          }
          if (d2 > 2.25L * std::max(r2 + wt(q), 0.0L) + 0.01L * lmax * lmax) continue;
        }
        CGAL::Oriented_side s =
            weighted ? K().power_side_of_oriented_power_sphere_3_object()(wpt(v[0]), wpt(v[1]), wpt(v[2]),
                                                                          wpt(v[3]), wpt(q))
                     : CGAL::side_of_oriented_sphere(pt(v[0]), pt(v[1]), pt(v[2]), pt(v[3]), pt(q));
        if (s == CGAL::ON_POSITIVE_SIDE) bad[t] = 1;
        if (s == CGAL::ON_ORIENTED_BOUNDARY) ++on[part];
      }
    }
  };
  std::thread other(work, 1u);
  work(0u);
  other.join();
  Brute b;
  for (std::uint32_t t = 0; t < n; ++t) {
    if (bad[t]) b.violating.push_back(t);
    b.degenerate += flat[t];
  }
  b.on_sphere = on[0] + on[1];
  return b;
}

void expect_matches_brute(const Mesh& m, const DelaunayCertificate& c, const Brute& b) {
  EXPECT_EQ(c.violating_tet_count, b.violating.size());
  // Each listed violation confirmed, none missed (the list holds the first max_listed).
  const std::size_t listed = std::min(b.violating.size(), CertificateOptions{}.max_listed);
  ASSERT_EQ(c.violating_tets.size(), listed);
  EXPECT_TRUE(std::equal(c.violating_tets.begin(), c.violating_tets.end(), b.violating.begin()));
  EXPECT_EQ(c.degenerate_tet_count, b.degenerate);
  EXPECT_EQ(c.tets_checked, m.tet_count());
  EXPECT_EQ(c.delaunay, b.violating.empty() && b.degenerate == 0);
}

// --- TetGen meshes ----------------------------------------------------------------------------------

Mesh read_node_ele(const std::filesystem::path& base) {
  Mesh m;
  std::vector<double> node = test::read_numbers(base.string() + ".node");
  const auto nn = static_cast<std::size_t>(node[0]);
  const std::size_t stride = 1 + static_cast<std::size_t>(node[1] + node[2] + node[3]);
  const long node_base = static_cast<long>(node[4]);
  for (std::size_t i = 0; i < nn; ++i)
    for (std::size_t d = 0; d < 3; ++d) m.xyz.push_back(node[4 + i * stride + 1 + d]);
  std::vector<double> ele = test::read_numbers(base.string() + ".ele");
  const auto ne = static_cast<std::size_t>(ele[0]);
  const std::size_t estride = 1 + static_cast<std::size_t>(ele[1] + ele[2]);
  for (std::size_t t = 0; t < ne; ++t)
    for (std::size_t j = 0; j < 4; ++j)
      m.tet.push_back(
          static_cast<std::uint32_t>(static_cast<long>(ele[3 + t * estride + 1 + j]) - node_base));
  return m;
}

// Runs tetgen on a PLC; returns false (and the test skips) when tetgen is not installed.
bool tetgen_mesh(const std::string& poly, const std::string& switches, Mesh& out) {
  if (!test::have_program("tetgen")) return false;
  test::TempDir dir;
  test::write_text(dir / "m.poly", poly);
  EXPECT_EQ(test::run("tetgen " + switches + " '" + (dir / "m.poly").string() + "'", dir / "log"), 0)
      << test::read_text(dir / "log");
  out = read_node_ele(dir / "m.1");
  return true;
}

TEST(DelaunayCertificate, TetgenBoxWithoutOptimisationIsDelaunay) {
  Mesh m;
  if (!tetgen_mesh(test::box_poly(2, 1, 1), "-pq1.414a0.0004O0Q", m)) GTEST_SKIP() << "no tetgen";
  ASSERT_GT(m.tet_count(), 5000u);
  DelaunayCertificate c = compute_delaunay_certificate(m);
  EXPECT_TRUE(c.delaunay);
  EXPECT_FALSE(c.weighted);
  EXPECT_EQ(c.violating_tet_count, 0u);
  EXPECT_EQ(c.degenerate_tet_count, 0u);
  EXPECT_EQ(c.tets_checked, m.tet_count());
}

TEST(DelaunayCertificate, OptimisedTrenchViolationsMatchBruteForce) {
  Mesh m;
  if (!tetgen_mesh(test::trench_poly(), "-pq1.414a0.0005Q", m)) GTEST_SKIP() << "no tetgen";
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  std::printf("trench a0.0005: %zu tets, %zu nodes, %zu violating (brute force %zu)\n", m.tet_count(),
              m.node_count(), c.violating_tet_count, b.violating.size());
  EXPECT_GT(b.violating.size(), 0u);  // TetGen's mesh optimisation breaks the Delaunay property
  EXPECT_FALSE(c.delaunay);
  expect_matches_brute(m, c, b);
  EXPECT_GT(c.max_relative_depth, 0.0);
  EXPECT_LT(c.max_relative_depth, 1.0);
}

TEST(DelaunayCertificate, TrenchWithoutOptimisationMatchesBruteForce) {
  Mesh m;
  if (!tetgen_mesh(test::trench_poly(), "-pq1.414a0.002O0Q", m)) GTEST_SKIP() << "no tetgen";
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  EXPECT_TRUE(b.violating.empty());
  expect_matches_brute(m, c, b);
}

TEST(DelaunayCertificate, CosphericalGridIsDelaunayWithPointsOnSpheres) {
  // Unjittered Kuhn grid: each cube's 8 corners lie on one sphere shared by its 6 tets.
  Mesh m = bench::kuhn_grid_mesh(4, 0.0);
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  EXPECT_GT(b.on_sphere, 6u * 64u);  // at least the 4 other corners of its cube for each tet
  EXPECT_TRUE(b.violating.empty());
  EXPECT_TRUE(c.delaunay);
  expect_matches_brute(m, c, b);
}

TEST(DelaunayCertificate, MovedVertexMakesTetsNonDelaunay) {
  Mesh m = bench::kuhn_grid_mesh(4, 0.0);
  // Move the interior node (2,2,2) by a fifth of a cell: spheres of neighbouring cubes now hold it.
  const std::uint32_t v = (2 * 5 + 2) * 5 + 2;
  m.xyz[3 * v] += 0.05;
  m.xyz[3 * v + 1] += 0.03;
  m.xyz[3 * v + 2] -= 0.02;
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  EXPECT_GT(b.violating.size(), 0u);
  EXPECT_FALSE(c.delaunay);
  expect_matches_brute(m, c, b);
}

TEST(DelaunayCertificate, JitteredGridMatchesBruteForce) {
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    Mesh m = bench::kuhn_grid_mesh(6, 0.25, seed);
    expect_matches_brute(m, compute_delaunay_certificate(m), brute_force(m));
  }
}

TEST(DelaunayCertificate, DisconnectedPiecesCheckedGlobally) {
  // Tet 0 is the corner tet with circumcentre (.5,.5,.5), radius 0.866. Tet 1 shares no face (no
  // vertex) with it, but its vertex (.6,.6,.6) lies inside tet 0's sphere: a face-local test misses it.
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.6, 0.6, 0.6, 4, 0.6, 0.6, 0.6, 4, 0.6, 0.6, 0.6, 4};
  m.tet = {0, 1, 2, 3, 4, 5, 6, 7};
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  ASSERT_FALSE(b.violating.empty());
  EXPECT_EQ(b.violating.front(), 0u);
  expect_matches_brute(m, c, b);
  EXPECT_FALSE(c.delaunay);
}

TEST(DelaunayCertificate, DuplicatePointsAreOnSpheresNotInside) {
  // Two copies of the same Delaunay mesh with their own nodes at identical coordinates: every tet has
  // its twin's four vertices on its sphere and nothing inside.
  Mesh m;
  if (!tetgen_mesh(test::box_poly(1, 1, 1), "-pq1.414a0.002O0Q", m)) GTEST_SKIP() << "no tetgen";
  const auto nn = static_cast<std::uint32_t>(m.node_count());
  const std::size_t nt = m.tet.size();
  m.xyz.insert(m.xyz.end(), m.xyz.begin(), m.xyz.end());
  for (std::size_t i = 0; i < nt; ++i) m.tet.push_back(m.tet[i] + nn);
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  EXPECT_GE(b.on_sphere, 4 * nt / 4 * 2);
  EXPECT_TRUE(c.delaunay);
  expect_matches_brute(m, c, b);
}

TEST(DelaunayCertificate, NearlyFlatTetDecidedExactly) {
  // Tet 0 = (0,0,0) (1,0,0) (0,1,0) (1,1,eps): its volume is below the double rounding bound of the
  // orientation, yet positive; its sphere is centred at (.5,.5,eps/2) with radius ~0.707. A vertex of
  // a second tet at (.5,.5,.3) lies inside it; with z = .8 instead, outside.
  for (double z : {0.3, 0.8}) {
    Mesh m;
    m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 1e-17, 0.5, 0.5, z, 3, 0.5, z, 0.5, 3, z, 0.5, 0.5, z + 3};
    m.tet = {0, 1, 2, 3, 4, 5, 6, 7};
    DelaunayCertificate c = compute_delaunay_certificate(m);
    Brute b = brute_force(m);
    EXPECT_EQ(c.degenerate_tet_count, 0u);
    const bool tet0 = !c.violating_tets.empty() && c.violating_tets.front() == 0;
    EXPECT_EQ(tet0, z < 0.5) << "z = " << z;
    expect_matches_brute(m, c, b);
  }
}

TEST(DelaunayCertificate, NearlyFlatSkewTetMatchesBruteForce) {
  // A parallelogram in a skew plane, its fourth corner lifted by about 1e-15: the double orientation
  // cannot be trusted (cancellation), the sphere is huge. Whatever the exact predicates say about the
  // stored doubles (flat or not, which points are inside), the certificate must say the same.
  for (double lift : {0.0, 1e-15, -1e-15, 1e-13}) {
    Mesh m;
    m.xyz = {0.1, 0.2, 0.3, 1.3, 0.4, 0.7, 0.2, 1.1, 0.9, 1.4, 1.3, 1.3 + lift};
    for (double x : {0.7, 0.5, 0.4, 2.0, 0.6, 0.5, 0.7, 2.1, 0.4, 0.7, 0.5, 2.5}) m.xyz.push_back(x);
    m.tet = {0, 1, 2, 3, 4, 5, 6, 7};
    // Positive orientation for both, by the exact predicate.
    for (std::uint32_t t = 0; t < 2; ++t) {
      auto p = [&](std::uint32_t j) {
        const std::uint32_t v = m.tet[4 * t + j];
        return Point(m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]);
      };
      if (CGAL::orientation(p(0), p(1), p(2), p(3)) == CGAL::NEGATIVE)
        std::swap(m.tet[4 * t + 2], m.tet[4 * t + 3]);
    }
    SCOPED_TRACE(lift);
    expect_matches_brute(m, compute_delaunay_certificate(m), brute_force(m));
  }
}

TEST(DelaunayCertificate, DegenerateTetCounted) {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 0, 1};
  m.tet = {0, 1, 2, 3, 0, 1, 2, 4};  // tet 0 is flat (all z = 0)
  DelaunayCertificate c = compute_delaunay_certificate(m);
  EXPECT_EQ(c.degenerate_tet_count, 1u);
  EXPECT_FALSE(c.delaunay);
  expect_matches_brute(m, c, brute_force(m));
}

TEST(DelaunayCertificate, EqualWeightsGiveTheUnweightedResult) {
  // Equal weights shift every power distance by the same amount: regular = Delaunay.
  Mesh m;
  if (!tetgen_mesh(test::trench_poly(), "-pq1.414a0.002Q", m)) GTEST_SKIP() << "no tetgen";
  DelaunayCertificate plain = compute_delaunay_certificate(m);
  m.weight.assign(m.node_count(), 0.013);
  DelaunayCertificate w = compute_delaunay_certificate(m);
  EXPECT_TRUE(w.weighted);
  EXPECT_EQ(w.violating_tets, plain.violating_tets);
  EXPECT_EQ(w.violating_tet_count, plain.violating_tet_count);
  expect_matches_brute(m, w, brute_force(m));
}

TEST(DelaunayCertificate, LargeWeightOnOneVertexMatchesBruteForce) {
  Mesh m;
  if (!tetgen_mesh(test::box_poly(1, 1, 1), "-pq1.414a0.001O0Q", m)) GTEST_SKIP() << "no tetgen";
  m.weight.assign(m.node_count(), 0.0);
  // The node nearest the centre gets a power radius of about two mean edge lengths.
  std::uint32_t best = 0;
  double bd = 1e9;
  for (std::uint32_t v = 0; v < m.node_count(); ++v) {
    double d = std::hypot(m.xyz[3 * v] - 0.5, m.xyz[3 * v + 1] - 0.5, m.xyz[3 * v + 2] - 0.5);
    if (d < bd) bd = d, best = v;
  }
  m.weight[best] = 0.04;
  DelaunayCertificate c = compute_delaunay_certificate(m);
  Brute b = brute_force(m);
  EXPECT_GT(b.violating.size(), 0u);
  expect_matches_brute(m, c, b);
}

TEST(DelaunayCertificate, WeightSignConventionAnalytic) {
  // Tet 0: the corner tet, weights 0, circumcentre c = (.5,.5,.5), r^2 = 0.75. Vertex q = (2,2,2) of
  // a far tet has |q - c|^2 = 6.75, so its power distance 6.75 - w_q - 0.75 is negative iff w_q > 6.
  for (double wq : {5.9, 6.1}) {
    Mesh m;
    m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 2, 2, 2, 9, 2, 2, 2, 9, 2, 2, 2, 9};
    m.tet = {0, 1, 2, 3, 4, 5, 6, 7};
    m.weight = {0, 0, 0, 0, wq, 0, 0, 0};
    DelaunayCertificate c = compute_delaunay_certificate(m);
    const bool tet0 = !c.violating_tets.empty() && c.violating_tets.front() == 0;
    EXPECT_EQ(tet0, wq > 6) << "w_q = " << wq;
  }
}

TEST(DelaunayCertificate, ListTruncatedCountKept) {
  Mesh m;
  if (!tetgen_mesh(test::trench_poly(), "-pq1.414a0.002Q", m)) GTEST_SKIP() << "no tetgen";
  CertificateOptions opt;
  opt.max_listed = 3;
  DelaunayCertificate all = compute_delaunay_certificate(m);
  DelaunayCertificate few = compute_delaunay_certificate(m, opt);
  ASSERT_GT(all.violating_tet_count, 3u);
  EXPECT_EQ(few.violating_tet_count, all.violating_tet_count);
  ASSERT_EQ(few.violating_tets.size(), 3u);
  EXPECT_TRUE(std::equal(few.violating_tets.begin(), few.violating_tets.end(), all.violating_tets.begin()));
}

TEST(DelaunayCertificate, ProgressReachesOneAndCancelStops) {
  Mesh m = bench::kuhn_grid_mesh(16);  // 24,576 tets: the threaded path
  std::vector<double> seen;
  CertificateOptions opt;
  opt.progress = [&](std::string_view, double f) {
    seen.push_back(f);
    return true;
  };
  DelaunayCertificate c = compute_delaunay_certificate(m, opt);
  EXPECT_FALSE(c.cancelled);
  ASSERT_GE(seen.size(), 2u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), 1.0);

  int calls = 0;
  opt.progress = [&](std::string_view, double) { return ++calls < 2; };
  DelaunayCertificate x = compute_delaunay_certificate(m, opt);
  EXPECT_TRUE(x.cancelled);
  EXPECT_FALSE(x.delaunay);  // a cancelled certificate never claims Delaunay
  // The other thread may finish its half before it sees the cancel: not more than all were checked.
  EXPECT_LE(x.tets_checked, m.tet_count());
}

TEST(DelaunayCertificate, CachedOnMesh) {
  Mesh m = bench::kuhn_grid_mesh(3, 0.0);
  const DelaunayCertificate& a = delaunay_certificate(m);
  EXPECT_EQ(&a, &delaunay_certificate(m));
  EXPECT_TRUE(a.delaunay);
  m.xyz[3 * ((1 * 4 + 1) * 4 + 1)] += 0.08;  // move an interior node, then say so
  invalidate_derived(m);
  EXPECT_FALSE(delaunay_certificate(m).delaunay);
}

}  // namespace
}  // namespace foxi
