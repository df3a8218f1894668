// Meshes whose coordinates mix wildly different magnitudes (issue 22: `foxi info --check-delaunay`
// and `foxi order` ran past 60 s on such a 6,000-tet file while plain `info` took 10 ms). The mesh is
// made here: CGAL's Delaunay triangulation (exact predicates) of random points, each scaled by 10^k
// for a random integer k, so the oracle for the certificate is "Delaunay" and for the order "no
// violations". Each step must finish within a generous bound.
#include <gtest/gtest.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::uint32_t, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;

// `n` points u * 10^k, u uniform in [-1, 1]^3, k a uniform integer in [kmin, kmax] (by default
// [-kmax, kmax]), then `far` points u * 10^12, and their Delaunay tetrahedralization (CGAL's cells
// are positively oriented).
Mesh mixed_scale_mesh(int n, int kmax, unsigned seed, int kmin = 1, int far = 0) {
  if (kmin > 0) kmin = -kmax;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> k(kmin, kmax);
  std::vector<std::pair<K::Point_3, std::uint32_t>> pts;
  Mesh m;
  for (int i = 0; i < n + far; ++i) {
    const double s = std::pow(10.0, i < n ? k(rng) : 12);
    const double p[3] = {u(rng) * s, u(rng) * s, u(rng) * s};
    m.xyz.insert(m.xyz.end(), p, p + 3);
    pts.emplace_back(K::Point_3(p[0], p[1], p[2]), static_cast<std::uint32_t>(i));
  }
  Delaunay dt(pts.begin(), pts.end());
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c)
    for (int j = 0; j < 4; ++j) m.tet.push_back(c->vertex(j)->info());
  m.tet_region.assign(m.tet_count(), 1);
  return m;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Generous: a few hundred milliseconds each on a laptop core; the hang was minutes.
constexpr double kBoundSeconds = 20 * test::kTimeScale;

TEST(MixedScales, OverflowingMagnitudesAreRefusedQuickly) {
  // 10^-150 .. 10^150: hull tets' volumes overflow (10^450), so validation must refuse the mesh.
  const Mesh m = mixed_scale_mesh(1000, 150, 7);
  ASSERT_GT(m.tet_count(), 4000u);
  const auto t = std::chrono::steady_clock::now();
  const ValidationReport r = validate(m);
  EXPECT_LT(seconds_since(t), kBoundSeconds);
  EXPECT_FALSE(r.ok());
  EXPECT_GT(r.out_of_range, 0u);
}

TEST(MixedScales, BeyondTheOrdersFloatBoundsIsRefused) {
  // Out to 1e40: finite volumes and spheres, but the visibility order's float error bounds overflow
  // (before validation refused it, this mesh was ordered with about 5,500 violations per view).
  const Mesh m = mixed_scale_mesh(1000, 40, 11);
  const ValidationReport r = validate(m);
  EXPECT_FALSE(r.ok());
  EXPECT_GT(r.out_of_range, 0u);
}

TEST(MixedScales, CertificateAndOrderFinishAndAreRight) {
  for (int kmax : {10, 20}) {
    const Mesh m = mixed_scale_mesh(1000, kmax, 11);
    ASSERT_GT(m.tet_count(), 4000u);
    const ValidationReport r = validate(m);
    ASSERT_TRUE(r.ok()) << "kmax " << kmax << ": " << (r.messages.empty() ? "" : r.messages[0]);
    auto t = std::chrono::steady_clock::now();
    const DelaunayCertificate cert = compute_delaunay_certificate(m);
    const double cert_s = seconds_since(t);
    EXPECT_LT(cert_s, kBoundSeconds) << "kmax " << kmax;
    EXPECT_TRUE(cert.delaunay) << "kmax " << kmax << ": " << cert.violating_tet_count << " violating, "
                               << cert.degenerate_tet_count << " degenerate";
    t = std::chrono::steady_clock::now();
    const SphereTable table = compute_spheres(m);
    const double spheres_s = seconds_since(t);
    EXPECT_LT(spheres_s, kBoundSeconds) << "kmax " << kmax;
    for (const View& v : {View::along(0.3, -0.5, 1), View::at(0.1, 0.2, 0.3), View::at(5, -3, 2)}) {
      t = std::chrono::steady_clock::now();
      const std::vector<std::uint32_t> order = visibility_order(m, table, v);
      const double order_s = seconds_since(t);
      EXPECT_LT(order_s, kBoundSeconds) << "kmax " << kmax;
      EXPECT_EQ(order.size(), m.tet_count());
      EXPECT_EQ(count_violations(m, v, order).violations, 0u) << "kmax " << kmax;
    }
    std::printf("kmax %d: %zu tets; certificate %.3f s, spheres %.3f s\n", kmax, m.tet_count(), cert_s,
                spheres_s);
  }
}

// The certificate on a mixed-scale mesh (its points crowd one grid cell, so it takes the k-d tree)
// against brute force: every tet against every point with CGAL's exact insphere test. Once on the
// Delaunay mesh, once after a 2-3 flip of one interior face, which makes it non-Delaunay.
std::size_t brute_force_violating(const Mesh& m) {
  auto point = [&](std::uint32_t v) { return K::Point_3(m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]); };
  std::size_t violating = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    for (std::uint32_t q = 0; q < m.node_count(); ++q) {
      if (q == v[0] || q == v[1] || q == v[2] || q == v[3]) continue;
      if (CGAL::side_of_oriented_sphere(point(v[0]), point(v[1]), point(v[2]), point(v[3]), point(q)) ==
          CGAL::ON_POSITIVE_SIDE) {
        ++violating;
        break;
      }
    }
  }
  return violating;
}

TEST(MixedScales, CertificateMatchesBruteForce) {
  // 400 points within 1 of the origin (scales 1e-20 .. 1) and 20 out to 1e12: the grid's cells are
  // about 1e11 wide, so the 400 share one cell (a boundary within 1 of the origin is a 1e-11
  // chance), more than the 256 that switch the certificate to its k-d tree.
  const Mesh base = mixed_scale_mesh(400, 0, 5, -20, 20);
  auto point = [&](std::uint32_t v) {
    return K::Point_3(base.xyz[3 * v], base.xyz[3 * v + 1], base.xyz[3 * v + 2]);
  };
  // Two tets sharing a face whose opposite vertices a, b see the segment ab cross the face's
  // interior: replaced by the three tets around ab.
  Mesh flipped;
  flipped.xyz = base.xyz;
  const FaceAdjacency& adj = face_adjacency(base);
  bool done = false;
  std::size_t skip0 = kNone, skip1 = kNone;
  for (std::size_t t = 0; t < base.tet_count() && !done; ++t)
    for (int i = 0; i < 4 && !done; ++i) {
      const std::uint32_t nb = adj.neighbour[4 * t + i];  // 4 u + g
      if (nb == kNone || nb / 4 < t) continue;
      const std::uint32_t n = nb / 4;
      const std::uint32_t* vt = &base.tet[4 * t];
      const std::uint32_t* vn = &base.tet[4 * std::size_t(n)];
      const std::uint32_t a = vt[i];
      std::uint32_t b = kNone;
      for (int j = 0; j < 4; ++j)
        if (vn[j] != vt[0] && vn[j] != vt[1] && vn[j] != vt[2] && vn[j] != vt[3]) b = vn[j];
      std::uint32_t f[3];
      for (int j = 0, k = 0; j < 4; ++j)
        if (j != i) f[k++] = vt[j];
      const auto o0 = CGAL::orientation(point(a), point(b), point(f[0]), point(f[1]));
      const auto o1 = CGAL::orientation(point(a), point(b), point(f[1]), point(f[2]));
      const auto o2 = CGAL::orientation(point(a), point(b), point(f[2]), point(f[0]));
      if (o0 == CGAL::COPLANAR || o0 != o1 || o1 != o2) continue;
      for (int j = 0; j < 3; ++j) {
        std::uint32_t c = f[j], d = f[(j + 1) % 3];
        if (CGAL::orientation(point(a), point(b), point(c), point(d)) == CGAL::NEGATIVE) std::swap(c, d);
        flipped.tet.insert(flipped.tet.end(), {a, b, c, d});
      }
      skip0 = t;
      skip1 = n;
      done = true;
    }
  ASSERT_TRUE(done);
  for (std::size_t t = 0; t < base.tet_count(); ++t)
    if (t != skip0 && t != skip1)
      flipped.tet.insert(flipped.tet.end(), &base.tet[4 * t], &base.tet[4 * t + 4]);
  flipped.tet_region.assign(flipped.tet_count(), 1);
  const ValidationReport r = validate(flipped);
  ASSERT_TRUE(r.ok()) << (r.messages.empty() ? "" : r.messages[0]);

  const DelaunayCertificate c0 = compute_delaunay_certificate(base);
  EXPECT_TRUE(c0.delaunay);
  EXPECT_EQ(c0.violating_tet_count, brute_force_violating(base));
  const DelaunayCertificate c1 = compute_delaunay_certificate(flipped);
  const std::size_t want = brute_force_violating(flipped);
  EXPECT_GT(want, 0u);  // the flip made it non-Delaunay
  EXPECT_FALSE(c1.delaunay);
  EXPECT_EQ(c1.violating_tet_count, want);
}

// The command line on the same kind of file: both must end (refusing, or answering) well within
// the bound, the refusal with exit status 3 (bad input).
TEST(MixedScales, CommandLineEndsQuickly) {
  test::TempDir dir;
  const std::string wide = (dir / "wide.vtu").string(), narrow = (dir / "narrow.vtu").string();
  write_mesh(mixed_scale_mesh(1000, 150, 7), wide);
  write_mesh(mixed_scale_mesh(1000, 20, 11), narrow);
  auto run = [&](const std::string& args) {
    const auto t = std::chrono::steady_clock::now();
    const int status = test::run("timeout 120 '" + test::cli_path() + "' " + args, dir / "cli.log");
    EXPECT_LT(seconds_since(t), kBoundSeconds) << args;
    return status;
  };
  EXPECT_EQ(run("info --check-delaunay '" + wide + "'"), 3) << test::read_text(dir / "cli.log");
  EXPECT_NE(test::read_text(dir / "cli.log").find("beyond the range"), std::string::npos);
  EXPECT_EQ(run("order --views 4 --check '" + wide + "'"), 3) << test::read_text(dir / "cli.log");
  EXPECT_EQ(run("info --check-delaunay '" + narrow + "'"), 0) << test::read_text(dir / "cli.log");
  EXPECT_NE(test::read_text(dir / "cli.log").find("delaunay            yes"), std::string::npos)
      << test::read_text(dir / "cli.log");
  EXPECT_EQ(run("order --views 4 --check '" + narrow + "'"), 0) << test::read_text(dir / "cli.log");
}

}  // namespace
}  // namespace foxi
