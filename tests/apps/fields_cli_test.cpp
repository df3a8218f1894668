// foxi fields list|import end to end: a linear field carried between two meshes of one box comes out
// exact in OUT and draws with foxi render --field; mismatches and broken files exit 3 naming the file
// (and line), leaving no output; command-line mistakes exit 2.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/mesh_io.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

double linear(const double* p) { return 250 + 20 * p[0] - 30 * p[1] + 5 * p[2]; }

class FieldsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    Mesh target = bench::kuhn_grid_mesh(5, 0.2, 3);
    write_mesh(target, dir_ / "target.vtu");
    Mesh src = bench::kuhn_grid_mesh(7, 0.25, 8);
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    for (std::size_t i = 0; i < src.node_count(); ++i) t.values.push_back(linear(&src.xyz[3 * i]));
    src.fields = {t};
    write_mesh(src, dir_ / "source.vtu");
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run_cli(args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  std::string p(const std::string& name) const { return "'" + (dir_ / name).string() + "'"; }
  test::TempDir dir_;
};

TEST_F(FieldsCli, ListNamesLocationComponentsStepsUnitsAndRanges) {
  std::string log;
  ASSERT_EQ(foxi("fields list " + p("source.vtu"), &log), 0) << log;
  EXPECT_NE(log.find("temperature"), std::string::npos) << log;
  EXPECT_NE(log.find("node, 1 component, 1 step, unit K"), std::string::npos) << log;
  ASSERT_EQ(foxi("fields list '" + test::data_dir() + "/fields/ccx_two_steps.frd'", &log), 0) << log;
  EXPECT_NE(log.find("DISP             node, 3 components, 2 steps (1 .. 2)"), std::string::npos) << log;
  EXPECT_NE(log.find("STRESS           node, 6 components"), std::string::npos) << log;
  EXPECT_NE(
      log.find("NDTEMP           node, 1 component, 2 steps (1 .. 2), unit -, values 310 .. 330, 0 NaN"),
      std::string::npos)
      << log;
  // A binary .frd written by ccx 2.21 (tests/data/fields/README.md).
  ASSERT_EQ(foxi("fields list '" + test::data_dir() + "/fields/ccx221_beam10psmooth_binary.frd'", &log), 0)
      << log;
  EXPECT_NE(log.find("90 nodes, 31 tets, 3 fields"), std::string::npos) << log;
  EXPECT_NE(log.find("STRESS           node, 6 components, 1 step"), std::string::npos) << log;
}

TEST_F(FieldsCli, ImportByLocationIsExactAndRenders) {
  std::string log;
  ASSERT_EQ(foxi("fields import " + p("target.vtu") + " " + p("source.vtu") + " -o " + p("out.vtu"), &log), 0)
      << log;
  EXPECT_NE(log.find("by location"), std::string::npos) << log;
  EXPECT_NE(log.find("outside the source mesh: 0 nodes"), std::string::npos) << log;
  const Mesh out = read_mesh(dir_ / "out.vtu");
  const Field* t = out.find_field("temperature");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->unit, "K");
  for (std::size_t i = 0; i < out.node_count(); ++i)
    EXPECT_NEAR(t->values[i], linear(&out.xyz[3 * i]), 1e-11);
  ASSERT_EQ(foxi("render " + p("out.vtu") + " --field temperature --size 480x320 -o " + p("t.png"), &log), 0)
      << log;
  EXPECT_TRUE(std::filesystem::file_size(dir_ / "t.png") > 1000);
  // The same mesh again: by id (the default when counts agree), bit for bit.
  ASSERT_EQ(foxi("fields import " + p("out.vtu") + " " + p("out.vtu") + " -o " + p("again.vtu"), &log), 0)
      << log;
  EXPECT_NE(log.find("by id"), std::string::npos) << log;
  EXPECT_EQ(read_mesh(dir_ / "again.vtu").find_field("temperature")->values, t->values);
  // Another mesh with the target's counts (other jitter): the default goes by location and says so.
  Mesh twin = bench::kuhn_grid_mesh(5, 0.2, 99);
  Field tt{"temperature", FieldLocation::node, 1, "K", {}, {}};
  for (std::size_t i = 0; i < twin.node_count(); ++i) tt.values.push_back(linear(&twin.xyz[3 * i]));
  twin.fields = {tt};
  write_mesh(twin, dir_ / "twin.vtu");
  ASSERT_EQ(foxi("fields import " + p("target.vtu") + " " + p("twin.vtu") + " -o " + p("t2.vtu"), &log), 0)
      << log;
  EXPECT_NE(log.find("matching by location"), std::string::npos) << log;
  const Mesh t2 = read_mesh(dir_ / "t2.vtu");
  for (std::size_t i = 0; i < t2.node_count(); ++i)
    EXPECT_NEAR(t2.find_field("temperature")->values[i], linear(&t2.xyz[3 * i]), 1e-11);
  // Formats that hold no fields: the import is refused before any work (it wrote the mesh without
  // them, exit 0; an outside probe), convert says what it leaves out.
  for (const char* fieldless : {"out.mesh", "out.node"}) {
    EXPECT_EQ(foxi("fields import " + p("target.vtu") + " " + p("source.vtu") + " -o " + p(fieldless), &log),
              2)
        << log;
    EXPECT_NE(log.find("format holds no fields"), std::string::npos) << log;
    EXPECT_FALSE(std::filesystem::exists(dir_ / fieldless));
  }
  ASSERT_EQ(foxi("convert " + p("out.vtu") + " " + p("plain.mesh"), &log), 0) << log;
  EXPECT_NE(log.find("warning: the Medit .mesh format holds no fields: the 1 fields"), std::string::npos)
      << log;
}

TEST_F(FieldsCli, CsvAndOutsidePoints) {
  // Node ids 1..3 of the target, one unknown column layout; then the same table with an id beyond it.
  test::write_text(dir_ / "t.csv", "id,heat [W]\n1,5\n2,6\n3,7\n");
  std::string log;
  ASSERT_EQ(foxi("fields import " + p("target.vtu") + " " + p("t.csv") + " -o " + p("o.vtu"), &log), 0)
      << log;
  const Mesh o = read_mesh(dir_ / "o.vtu");
  EXPECT_EQ(o.find_field("heat")->values[2], 7);
  const std::size_t missing = o.node_count() - 3;
  EXPECT_NE(log.find("without a source value: " + std::to_string(missing) + " nodes"), std::string::npos)
      << log;
  EXPECT_NE(log.find("NaN values: " + std::to_string(missing)), std::string::npos) << log;
  // Nearest outside: a target reaching beyond the source box gets no NaN.
  Mesh big = bench::kuhn_grid_mesh(3, 0.0, 1);
  for (double& x : big.xyz) x = 1.4 * x - 0.2;
  write_mesh(big, dir_ / "big.vtu");
  ASSERT_EQ(
      foxi("fields import " + p("big.vtu") + " " + p("source.vtu") + " --outside nearest -o " + p("n.vtu"),
           &log),
      0)
      << log;
  EXPECT_NE(log.find("NaN values: 0"), std::string::npos) << log;
  EXPECT_EQ(log.find("outside the source mesh: 0 nodes"), std::string::npos) << log;
}

TEST_F(FieldsCli, MismatchesAndBrokenFilesExitThreeAndWriteNothing) {
  std::string log;
  // A field over another mesh with --by id.
  EXPECT_EQ(
      foxi("fields import " + p("target.vtu") + " " + p("source.vtu") + " --by id -o " + p("x.vtu"), &log),
      3);
  EXPECT_NE(log.find("different mesh"), std::string::npos) << log;
  // An id the mesh lacks; a non-numeric cell; a truncated .frd.
  test::write_text(dir_ / "far.csv", "id,t\n1,2\n100000,3\n");
  EXPECT_EQ(foxi("fields import " + p("target.vtu") + " " + p("far.csv") + " -o " + p("x.vtu"), &log), 3);
  EXPECT_NE(log.find("100000 does not exist"), std::string::npos) << log;
  test::write_text(dir_ / "nan.csv", "id,t\n1,2\n2,two\n");
  EXPECT_EQ(foxi("fields import " + p("target.vtu") + " " + p("nan.csv") + " -o " + p("x.vtu"), &log), 3);
  EXPECT_NE(log.find("nan.csv:3: column 2: 'two' is not a number"), std::string::npos) << log;
  const std::string frd = test::read_text(test::data_dir() + "/fields/ccx_two_steps.frd");
  test::write_text(dir_ / "cut.frd", frd.substr(0, frd.size() / 2));
  EXPECT_EQ(foxi("fields list " + p("cut.frd"), &log), 3);
  EXPECT_NE(log.find("cut.frd:"), std::string::npos) << log;
  // A truncated binary .frd: the byte where it ends.
  const std::string bin = test::read_text(test::data_dir() + "/fields/ccx221_beam10psmooth_binary.frd");
  test::write_text(dir_ / "cut_binary.frd", bin.substr(0, 5000));
  EXPECT_EQ(foxi("fields list " + p("cut_binary.frd"), &log), 3);
  EXPECT_NE(log.find("cut_binary.frd: byte 4985: the file ends inside the binary element block"),
            std::string::npos)
      << log;
  // A field that is not there.
  EXPECT_EQ(
      foxi("fields import " + p("target.vtu") + " " + p("source.vtu") + " --field nope -o " + p("x.vtu"),
           &log),
      3);
  EXPECT_NE(log.find("no field 'nope'"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.vtu"));
  // Usage mistakes.
  EXPECT_EQ(
      foxi("fields import " + p("target.vtu") + " " + p("source.vtu") + " --outside far -o " + p("x.vtu")),
      2);
  EXPECT_EQ(foxi("fields import " + p("target.vtu") + " " + p("source.vtu")), 2);
  EXPECT_EQ(foxi("fields frobnicate"), 2);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.vtu"));
}

}  // namespace
}  // namespace foxi
