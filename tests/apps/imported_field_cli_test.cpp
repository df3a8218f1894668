// An imported field (foxi fields import) works where a solved one does: foxi mesh --refine-from gives
// the same mesh from a field imported by id as from the solved file itself, one imported by location
// with points outside its source (NaN) refines by the rest, its NaN tets counted; foxi movie and
// foxi render --field draw it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

class ImportedFieldCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run_cli(args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  std::string p(const std::string& name) const { return "'" + (dir_ / name).string() + "'"; }
  std::string model() const { return "'" + test::models_dir() + "die_on_substrate.toml'"; }
  // The "refine from ..." line of a foxi mesh printout, from "relative gradient error" on.
  static std::string refine_line(const std::string& log) {
    const std::size_t at = log.find("relative gradient error");
    return at == std::string::npos ? std::string() : log.substr(at, log.find('\n', at) - at);
  }
  test::TempDir dir_;
};

TEST_F(ImportedFieldCli, RefineFromAndMovieTakeAnImportedField) {
  std::string log;
  ASSERT_EQ(foxi("mesh " + model() + " -o " + p("c.vtu"), &log), 0) << log;
  ASSERT_EQ(
      foxi("solve " + p("c.vtu") + " --fix substrate.bottom=300K --power die=0.5W -o " + p("s.vtu"), &log), 0)
      << log;
  ASSERT_EQ(
      foxi("fields import " + p("c.vtu") + " " + p("s.vtu") + " --by id --field temperature -o " + p("i.vtu"),
           &log),
      0)
      << log;
  std::string from_solved, from_imported;
  ASSERT_EQ(foxi("mesh " + model() + " --refine-from " + p("s.vtu") +
                     " --field temperature --target-error 0.3 -o " + p("r1.vtu"),
                 &from_solved),
            0)
      << from_solved;
  ASSERT_EQ(foxi("mesh " + model() + " --refine-from " + p("i.vtu") +
                     " --field temperature --target-error 0.3 -o " + p("r2.vtu"),
                 &from_imported),
            0)
      << from_imported;
  EXPECT_FALSE(refine_line(from_solved).empty()) << from_solved;
  EXPECT_EQ(refine_line(from_solved), refine_line(from_imported));
  const Mesh r1 = read_mesh(dir_ / "r1.vtu"), r2 = read_mesh(dir_ / "r2.vtu");
  EXPECT_EQ(r1.node_count(), r2.node_count());
  EXPECT_EQ(r1.tet, r2.tet);

  // From a narrower substrate's solve, by location: the nodes beyond it have no value.
  ASSERT_EQ(foxi("solve " + model() + " --set sub_w=8mm -o " + p("n.vtu"), &log), 0) << log;
  ASSERT_EQ(foxi("fields import " + p("c.vtu") + " " + p("n.vtu") +
                     " --by location --field temperature --outside nan -o " + p("part.vtu"),
                 &log),
            0)
      << log;
  const Mesh part = read_mesh(dir_ / "part.vtu");
  const Field* t = part.find_field("temperature");
  ASSERT_NE(t, nullptr);
  std::size_t nan_tets = 0;
  for (std::size_t e = 0; e < part.tet_count(); ++e) {
    bool nan = false;
    for (int i = 0; i < 4; ++i) nan = nan || std::isnan(t->values[part.tet[4 * e + std::size_t(i)]]);
    nan_tets += nan;
  }
  ASSERT_GT(nan_tets, 0u);
  ASSERT_EQ(foxi("mesh " + model() + " --refine-from " + p("part.vtu") +
                     " --field temperature --target-error 0.3 -o " + p("r3.vtu"),
                 &log),
            0)
      << log;
  EXPECT_NE(log.find(std::to_string(nan_tets) + " of its " + std::to_string(part.tet_count()) +
                     " tets have a node without a value"),
            std::string::npos)
      << log;
  const std::string err = refine_line(log);
  ASSERT_FALSE(err.empty()) << log;
  const double rel = std::strtod(err.c_str() + std::string("relative gradient error ").size(), nullptr);
  EXPECT_GT(rel, 0.05) << err;  // a real figure, not the NaN-poisoned 0 it was
  EXPECT_LT(rel, 2) << err;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "r3.vtu"));

  ASSERT_EQ(foxi("movie " + p("part.vtu") + " --field temperature --frames 2 --size 320x240 -o " + p("m.gif"),
                 &log),
            0)
      << log;
  EXPECT_GT(std::filesystem::file_size(dir_ / "m.gif"), 1000u);
  ASSERT_EQ(
      foxi("render " + p("part.vtu") + " --field temperature --graded --size 320x240 -o " + p("p.png"), &log),
      0)
      << log;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "p.png"));
}

}  // namespace
}  // namespace foxi
