// foxi mesh --mesher cgal end to end: a model's PLC meshed by CGAL, certified by the program, ordered
// without violations by `foxi order --check`, and its weights read back by meshio (another reader).
#include <gtest/gtest.h>

#include "foxi/model/mesh_io.hpp"
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

TEST(MeshCgalCli, UnknownMesherIsAUsageError) {
  test::TempDir dir;
  EXPECT_EQ(test::run(test::cli_path() + " mesh x.poly --mesher gmsh -o " + (dir / "x.vtu").string(), dir / "log"), 2);
  EXPECT_NE(test::read_text(dir / "log").find("--mesher takes tetgen or cgal"), std::string::npos);
}

}  // namespace
}  // namespace foxi
