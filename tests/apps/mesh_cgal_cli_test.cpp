// foxi mesh --mesher cgal end to end: a model's PLC meshed by CGAL, certified by the program, ordered
// without violations by `foxi order --check`, and its weights read back by meshio (another reader).
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "foxi/model/mesh_io.hpp"
#include "foxi/model/quality.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

TEST(MeshCgalCli, ModelMeshedCertifiedOrderedAndWeightsReadByMeshio) {
  test::TempDir dir;
  const std::string foxi = test::cli_path(), models = test::data_dir() + "/../../models/";
  ASSERT_EQ(test::run(foxi + " model plc " + models + "die_on_substrate.toml -o " + (dir / "d.poly").string(), dir / "plc.log"), 0);
  ASSERT_EQ(test::run(foxi + " mesh " + (dir / "d.poly").string() + " --mesher cgal -o " + (dir / "d.vtu").string(), dir / "mesh.log"), 0)
      << test::read_text(dir / "mesh.log");
  const std::string log = test::read_text(dir / "mesh.log");
  EXPECT_NE(log.find("regular (weighted Delaunay): yes"), std::string::npos) << log;
  EXPECT_NE(log.find("dihedral min"), std::string::npos) << log;

  ASSERT_EQ(test::run(foxi + " order " + (dir / "d.vtu").string() + " --views 12 --check", dir / "order.log"), 0);
  const std::string order = test::read_text(dir / "order.log");
  EXPECT_NE(order.find(" 0 violations over 12 views"), std::string::npos) << order;

  const Mesh m = read_mesh(dir / "d.vtu");
  ASSERT_EQ(m.weight.size(), m.node_count());
  if (test::have_program("/usr/bin/python3") &&
      test::run("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") == 0) {
    ASSERT_EQ(test::run("/usr/bin/python3 -c \"import meshio; m = meshio.read('" + (dir / "d.vtu").string() +
                            "'); w = m.point_data['weight']; print(len(w), repr(float(w.max())))\"",
                        dir / "meshio.log"),
              0);
    double max_weight = 0;
    for (double w : m.weight) max_weight = std::max(max_weight, w);
    std::size_t count = 0;
    double read_max = 0;
    ASSERT_EQ(std::sscanf(test::read_text(dir / "meshio.log").c_str(), "%zu %lf", &count, &read_max), 2);
    EXPECT_EQ(count, m.node_count());
    EXPECT_EQ(read_max, max_weight);
    EXPECT_GT(max_weight, 0);
  }
}

// A model file straight to CGAL, with --set: the parts' volumes (boxes: protected edges, exact) and
// names, and the model's max_size as the cell size bound.
TEST(MeshCgalCli, ModelFileWithSetKeepsPartVolumesAndNames) {
  test::TempDir dir;
  const std::string models = test::data_dir() + "/../../models/";
  ASSERT_EQ(test::run(test::cli_path() + " mesh " + models + "die_on_substrate.toml --set die_w=3mm --mesher cgal -o " +
                          (dir / "d.vtu").string(),
                      dir / "mesh.log"),
            0)
      << test::read_text(dir / "mesh.log");
  EXPECT_NE(test::read_text(dir / "mesh.log").find("regular (weighted Delaunay): yes"), std::string::npos);
  const Mesh m = read_mesh(dir / "d.vtu");
  std::map<std::string, double> volume;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    const double* p[4] = {&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]};
    const double a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double c[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
    const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    for (const Region& r : m.regions)
      if (r.id == m.region_of(t)) volume[r.name] += std::abs(det) / 6;
  }
  // The model: a 10 x 8 x 1 mm substrate under a 4 x 3 x 0.5 mm die, here 3 x 3.
  ASSERT_EQ(volume.size(), 2u);
  EXPECT_NEAR(volume["die"], 3e-3 * 3e-3 * 0.5e-3, 1e-9 * 4.5e-9);
  EXPECT_NEAR(volume["substrate"], 10e-3 * 8e-3 * 1e-3, 1e-9 * 8e-8);
  // A model's [mesh] max_size of 1 mm bounds the cells: no tet is larger than the regular tet's 0.118 mm^3.
  double largest = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) largest = std::max(largest, std::abs(tet_quality(&m.xyz[3 * m.tet[4 * t]],
      &m.xyz[3 * m.tet[4 * t + 1]], &m.xyz[3 * m.tet[4 * t + 2]], &m.xyz[3 * m.tet[4 * t + 3]]).volume));
  EXPECT_LT(largest, 1e-9 / (6 * std::sqrt(2.0)) * 1.5);
}

TEST(MeshCgalCli, UnknownMesherIsAUsageError) {
  test::TempDir dir;
  EXPECT_EQ(test::run(test::cli_path() + " mesh x.poly --mesher gmsh -o " + (dir / "x.vtu").string(), dir / "log"), 2);
  EXPECT_NE(test::read_text(dir / "log").find("--mesher takes tetgen or cgal"), std::string::npos);
}

}  // namespace
}  // namespace foxi
