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

// `n` points u * 10^k, u uniform in [-1, 1]^3, k a uniform integer in [-kmax, kmax], and their
// Delaunay tetrahedralization (CGAL's cells are positively oriented).
Mesh mixed_scale_mesh(int n, int kmax, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> k(-kmax, kmax);
  std::vector<std::pair<K::Point_3, std::uint32_t>> pts;
  Mesh m;
  for (int i = 0; i < n; ++i) {
    const double s = std::pow(10.0, k(rng));
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
constexpr double kBoundSeconds = 20;

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
    std::printf("kmax %d: %zu tets; certificate %.3f s, spheres %.3f s\n", kmax, m.tet_count(), cert_s, spheres_s);
  }
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
