// Tet quality against analytic values.
#include "foxi/model/quality.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr double kDeg = 180 / std::numbers::pi;

TEST(TetQuality, RegularTet) {
  // Alternate corners of a cube: edge sqrt(2), volume 1/3; R/l = sqrt(6)/4, dihedral acos(1/3).
  const double a[3] = {0, 0, 0}, b[3] = {1, 1, 0}, c[3] = {1, 0, 1}, d[3] = {0, 1, 1};
  TetQuality q = tet_quality(a, b, c, d);
  EXPECT_NEAR(std::abs(q.volume), 1.0 / 3.0, 1e-14);
  EXPECT_NEAR(q.radius_edge, std::sqrt(6.0) / 4, 1e-12);
  EXPECT_NEAR(q.radius_edge, 0.612, 5e-4);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1.0 / 3.0) * kDeg, 1e-10);
  EXPECT_NEAR(q.min_dihedral_deg, 70.53, 5e-3);
  // Orientation flips the volume's sign, nothing else.
  TetQuality r = tet_quality(a, b, d, c);
  EXPECT_NEAR(r.volume, -q.volume, 1e-15);
  EXPECT_NEAR(r.radius_edge, q.radius_edge, 1e-14);
  EXPECT_NEAR(r.min_dihedral_deg, q.min_dihedral_deg, 1e-10);
}

TEST(TetQuality, RightCornerTet) {
  // (0,0,0), (s,0,0), (0,s,0), (0,0,s): volume s^3/6, circumcentre (s/2)(1,1,1), R = s sqrt(3)/2,
  // shortest edge s; dihedral angles 90 deg at the axes, acos(1/sqrt 3) = 54.74 deg at the slanted face.
  const double s = 2.5;
  const double a[3] = {0, 0, 0}, b[3] = {s, 0, 0}, c[3] = {0, s, 0}, d[3] = {0, 0, s};
  TetQuality q = tet_quality(a, b, c, d);
  EXPECT_NEAR(q.volume, s * s * s / 6, 1e-13);
  EXPECT_GT(q.volume, 0);
  EXPECT_NEAR(q.radius_edge, std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(q.min_dihedral_deg, std::acos(1 / std::sqrt(3.0)) * kDeg, 1e-10);
}

TEST(TetQuality, FlatTet) {
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, d[3] = {1, 1, 0};
  TetQuality q = tet_quality(a, b, c, d);
  EXPECT_EQ(q.volume, 0);
  EXPECT_TRUE(std::isinf(q.radius_edge));
  EXPECT_EQ(q.min_dihedral_deg, 0);
}

TEST(TetQuality, NearlyFlatSliverHasSmallAngle) {
  // A square with one diagonal pair lifted by h: the classic sliver; the dihedral angle at the two
  // diagonals is 2 atan(h sqrt2 / ...) -> small. Bound: well below 5 degrees for h = 0.01.
  const double h = 0.01;
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, h}, c[3] = {1, 1, 0}, d[3] = {0, 1, h};
  TetQuality q = tet_quality(a, b, c, d);
  EXPECT_LT(q.min_dihedral_deg, 5);
  EXPECT_GT(q.min_dihedral_deg, 0);
  EXPECT_NEAR(std::abs(q.volume), h / 3, 1e-14);  // |det| = 2h for this sliver
}

TEST(QualitySummary, KuhnCube) {
  // The 6 Kuhn tets of the unit cube: volume 1/6 each, edges 1, sqrt2, sqrt3, circumradius sqrt3/2
  // (the cube's), dihedral angles 45, 60 and 90 degrees.
  Mesh m = bench::kuhn_grid_mesh(1, 0.0);
  QualitySummary s = summarize_quality(m);
  EXPECT_EQ(s.tets, 6u);
  EXPECT_NEAR(s.total_volume, 1.0, 1e-14);
  EXPECT_NEAR(s.volume.min, 1.0 / 6, 1e-14);
  EXPECT_NEAR(s.volume.max, 1.0 / 6, 1e-14);
  EXPECT_NEAR(s.radius_edge.mean, std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(s.min_dihedral_deg.min, 45, 1e-10);
  EXPECT_NEAR(s.min_dihedral_deg.max, 45, 1e-10);
  EXPECT_EQ(s.slivers, 0u);
}

TEST(QualitySummary, GridVolumeAndSlivers) {
  // Jittered grid keeps the unit cube's volume exactly (boundary nodes not jittered).
  Mesh m = bench::kuhn_grid_mesh(5, 0.2);
  // Add one sliver as a sixth... a separate tet on new nodes.
  const double h = 0.001;
  const std::uint32_t base = static_cast<std::uint32_t>(m.node_count());
  m.xyz.insert(m.xyz.end(), {5, 5, 5, 6, 5, 5 + h, 6, 6, 5, 5, 6, 5 + h});
  m.tet.insert(m.tet.end(), {base, base + 1, base + 2, base + 3});
  m.tet_region.push_back(1);
  QualitySummary s = summarize_quality(m);
  EXPECT_EQ(s.tets, m.tet_count());
  EXPECT_NEAR(s.total_volume, 1.0 + h / 3, 1e-12);
  EXPECT_EQ(s.slivers, 1u);
  EXPECT_LE(s.min_dihedral_deg.min, s.min_dihedral_deg.mean);
  EXPECT_LE(s.min_dihedral_deg.mean, s.min_dihedral_deg.max);
  EXPECT_GE(s.radius_edge.min, std::sqrt(6.0) / 4 - 1e-12);  // no tet beats the regular one
}

// Coordinates and tets of a TetGen .node/.ele pair (a tiny local parser: the oracle stays independent).
Mesh read_node_ele(const std::filesystem::path& base) {
  auto numbers = [](const std::filesystem::path& path) {
    std::ifstream in(path);
    std::vector<double> out;
    std::string line;
    while (std::getline(in, line)) {
      line = line.substr(0, line.find('#'));
      std::istringstream ls(line);
      double x;
      while (ls >> x) out.push_back(x);
    }
    return out;
  };
  Mesh m;
  std::vector<double> node = numbers(base.string() + ".node");
  const auto nn = static_cast<std::size_t>(node[0]);
  const std::size_t stride = 1 + static_cast<std::size_t>(node[1] + node[2] + node[3]);
  const auto first = static_cast<long>(node[4]);
  for (std::size_t i = 0; i < nn; ++i)
    for (std::size_t d = 0; d < 3; ++d) m.xyz.push_back(node[4 + i * stride + 1 + d]);
  std::vector<double> ele = numbers(base.string() + ".ele");
  const std::size_t estride = 1 + static_cast<std::size_t>(ele[1] + ele[2]);
  for (std::size_t t = 0; t < static_cast<std::size_t>(ele[0]); ++t)
    for (std::size_t j = 0; j < 4; ++j)
      m.tet.push_back(static_cast<std::uint32_t>(static_cast<long>(ele[3 + t * estride + 1 + j]) - first));
  return m;
}

TEST(QualitySummary, TetgenRadiusEdgeBoundAndVolume) {
  // TetGen's -q1.414 promises radius-edge ratios of at most 1.414; the 2 x 1 x 1 box has volume 2.
  if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  test::TempDir dir;
  test::write_text(
      dir / "b.poly",
      "8 3 0 0\n1 0 0 0\n2 2 0 0\n3 0 1 0\n4 2 1 0\n5 0 0 1\n6 2 0 1\n7 0 1 1\n8 2 1 1\n6 0\n"
      "1\n4 1 3 7 5\n1\n4 2 4 8 6\n1\n4 1 2 6 5\n1\n4 3 4 8 7\n1\n4 1 2 4 3\n1\n4 5 6 8 7\n0\n0\n");
  ASSERT_EQ(test::run("tetgen -pq1.414a0.001O0Q '" + (dir / "b.poly").string() + "'", dir / "log"), 0);
  Mesh m = read_node_ele(dir / "b.1");
  QualitySummary s = summarize_quality(m);
  EXPECT_EQ(s.tets, m.tet_count());
  EXPECT_NEAR(s.total_volume, 2.0, 1e-9);
  EXPECT_LE(s.radius_edge.max, 1.414 * (1 + 1e-6));
  EXPECT_GE(s.radius_edge.min, std::sqrt(6.0) / 4 - 1e-12);
  EXPECT_GT(s.volume.min, 0);  // all positively oriented, none flat
  EXPECT_GT(s.min_dihedral_deg.max, s.min_dihedral_deg.min);
}

TEST(QualitySummary, EmptyMesh) {
  QualitySummary s = summarize_quality(Mesh{});
  EXPECT_EQ(s.tets, 0u);
  EXPECT_EQ(s.total_volume, 0);
}

}  // namespace
}  // namespace foxi
