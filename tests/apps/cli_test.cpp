// The foxi command line, run as a user runs it, checked against what gmsh, tetgen and Python's own
// JSON parser say.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "test_util.hpp"

namespace foxi {
namespace {

struct Result {
  int status;
  std::string out;
};

Result foxi_cli(const std::string& args, const test::TempDir& dir) {
  const auto log = dir / "cli.log";
  int status = test::run("'" + test::cli_path() + "' " + args, log);
  return {status, test::read_text(log)};
}

// Counts of a gmsh-made mesh as gmsh itself reports them: the msh22 file gmsh writes lists its nodes
// and elements; we count tets (type 4) and triangles (type 2) in it with a few lines of parsing.
struct GmshCounts {
  long nodes = 0, tets = 0, triangles = 0;
};
GmshCounts count_msh22(const std::string& text) {
  GmshCounts c;
  auto nodes = text.find("$Nodes");
  c.nodes = std::stol(text.substr(nodes + 7, text.find('\n', nodes + 7) - nodes - 7));
  auto el = text.find("$Elements");
  std::size_t pos = text.find('\n', el + 10) + 1;
  long n = std::stol(text.substr(el + 10, pos - el - 10));
  for (long i = 0; i < n; ++i) {
    std::size_t end = text.find('\n', pos);
    std::string line = text.substr(pos, end - pos);
    int id = 0, type = 0;
    std::sscanf(line.c_str(), "%d %d", &id, &type);
    if (type == 4) ++c.tets;
    if (type == 2) ++c.triangles;
    pos = end + 1;
  }
  return c;
}

const char* kTwoBoxes = R"(SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {1, 0, 0, 1, 1, 1};
Coherence;
Physical Volume("left", 11) = {1};
Physical Volume("right", 12) = {2};
Physical Surface("bottom", 5) = {Surface{:}};
Mesh.CharacteristicLengthMax = 0.25;
)";

TEST(Cli, InfoCountsMatchGmsh) {
  if (!test::have_program("gmsh")) GTEST_SKIP();
  test::TempDir dir;
  test::write_text(dir / "b.geo", kTwoBoxes);
  ASSERT_EQ(test::run("gmsh -3 '" + (dir / "b.geo").string() + "' -format msh41 -bin -o '" +
                          (dir / "b.msh").string() + "'",
                      dir / "gmsh.log"),
            0);
  // gmsh re-saves its own mesh as ASCII 2.2: the independent count.
  ASSERT_EQ(test::run("gmsh -nopopup '" + (dir / "b.msh").string() + "' -save -format msh22 -o '" +
                          (dir / "g.msh").string() + "'",
                      dir / "gmsh2.log"),
            0);
  GmshCounts want = count_msh22(test::read_text(dir / "g.msh"));
  ASSERT_GT(want.tets, 100);
  Result r = foxi_cli("info --json '" + (dir / "b.msh").string() + "'", dir);
  ASSERT_EQ(r.status, 0) << r.out;
  // Python's JSON parser reads the output and prints the counts.
  test::write_text(dir / "info.json", r.out);
  const auto py = dir / "py.log";
  ASSERT_EQ(
      test::run("/usr/bin/python3 -c \"import json; d = json.load(open('" + (dir / "info.json").string() +
                    "')); print(d['nodes'], d['tets'], d['boundary_triangles'], round(d['volume'], 9), "
                    "sorted(r['name'] for r in d['regions']))\"",
                py),
      0);
  std::string got = test::read_text(py);
  EXPECT_EQ(got, std::to_string(want.nodes) + " " + std::to_string(want.tets) + " " +
                     std::to_string(want.triangles) + " 2.0 ['left', 'right']\n");
}

TEST(Cli, InfoCountsMatchTetgen) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  std::filesystem::copy(std::string(FOXI_TEST_DATA_DIR) + "/../../examples/die_on_substrate.poly",
                        dir / "d.poly");
  ASSERT_EQ(
      test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a2e-9AO0 d.poly", dir / "tetgen.log"), 0);
  // TetGen prints its own statistics.
  std::string log = test::read_text(dir / "tetgen.log");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(log, m, std::regex("Mesh points: (\\d+)")));
  long points = std::stol(m[1]);
  ASSERT_TRUE(std::regex_search(log, m, std::regex("Mesh tetrahedra: (\\d+)")));
  long tets = std::stol(m[1]);
  Result r = foxi_cli("info --check-delaunay '" + (dir / "d.1.ele").string() + "'", dir);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("nodes               " + std::to_string(points) + "\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tets                " + std::to_string(tets) + "\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("delaunay            yes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("regions             2"), std::string::npos) << r.out;
}

TEST(Cli, ConvertRoundTripsThroughEveryFormat) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  std::filesystem::copy(std::string(FOXI_TEST_DATA_DIR) + "/../../examples/trench.poly", dir / "t.poly");
  ASSERT_EQ(
      test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a0.01O0 t.poly", dir / "tetgen.log"), 0);
  Result base = foxi_cli("info --json '" + (dir / "t.1.ele").string() + "'", dir);
  ASSERT_EQ(base.status, 0) << base.out;
  auto counts = [](const std::string& json) {
    std::smatch m;
    std::regex_search(
        json, m, std::regex("\"nodes\": (\\d+),\\s*\"tets\": (\\d+),\\s*\"boundary_triangles\": (\\d+)"));
    return m.str(0);
  };
  std::string want = counts(base.out);
  ASSERT_FALSE(want.empty());
  for (std::string out : {"a.msh", "b.vtu", "c.vtk", "d.mesh", "e.node"}) {
    std::string extra = out == "a.msh" ? "--msh-version 2.2 --ascii" : "";
    Result c =
        foxi_cli("convert '" + (dir / "t.1.ele").string() + "' '" + (dir / out).string() + "' " + extra, dir);
    ASSERT_EQ(c.status, 0) << out << ": " << c.out;
    Result i = foxi_cli("info --json '" + (dir / out).string() + "'", dir);
    ASSERT_EQ(i.status, 0) << out << ": " << i.out;
    EXPECT_EQ(counts(i.out), want) << out;
  }
}

TEST(Cli, BadInputNamesFileAndLineAndLeavesNoOutput) {
  test::TempDir dir;
  test::write_text(dir / "bad.msh",
                   "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n3 1 0 2\n1\n2\n0 0 zero\n");
  Result r =
      foxi_cli("convert '" + (dir / "bad.msh").string() + "' '" + (dir / "out.vtu").string() + "'", dir);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.out.find("bad.msh:"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.vtu"));
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find("out.vtu"), std::string::npos) << e.path();
  Result missing = foxi_cli("info '" + (dir / "nope.msh").string() + "'", dir);
  EXPECT_EQ(missing.status, 3);
  EXPECT_NE(missing.out.find("nope.msh"), std::string::npos);
  Result usage = foxi_cli("convert onlyone.msh", dir);
  EXPECT_EQ(usage.status, 2);
  Result unknown = foxi_cli("info x.xyz", dir);
  EXPECT_EQ(unknown.status, 3);
  EXPECT_NE(unknown.out.find("unknown mesh format"), std::string::npos) << unknown.out;
}

// An option given twice was reported as "unknown" (the first was taken, the second left over), and
// a user who meant the second value was told the option does not exist. Options that may repeat
// (--set) still take every value.
TEST(Cli, AnOptionGivenTwiceIsNamedSoAndNothingIsWritten) {
  test::TempDir dir;
  const std::string png = (dir / "o.png").string();
  Result twice = foxi_cli("render nope.vtu --size 320x240 --size 64x48 -o '" + png + "'", dir);
  EXPECT_EQ(twice.status, 2);
  EXPECT_NE(twice.out.find("option --size given twice"), std::string::npos) << twice.out;
  EXPECT_FALSE(std::filesystem::exists(png));
  Result flag = foxi_cli("info nope.vtu --json --json", dir);
  EXPECT_EQ(flag.status, 2);
  EXPECT_NE(flag.out.find("option --json given twice"), std::string::npos) << flag.out;
  Result unknown = foxi_cli("render nope.vtu --sise 320x240 -o '" + png + "'", dir);
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.out.find("unknown option --sise"), std::string::npos) << unknown.out;
  Result sets = foxi_cli(
      "model check '" + test::models_dir() + "die_on_substrate.toml" + "' --set die_w=5mm --set die_d=4mm",
      dir);
  EXPECT_EQ(sets.status, 0) << sets.out;
}

TEST(Cli, HelpForEveryCommand) {
  test::TempDir dir;
  for (std::string cmd : {"--help", "info --help", "convert --help", "order --help"}) {
    Result r = foxi_cli(cmd, dir);
    EXPECT_EQ(r.status, 0) << cmd;
    EXPECT_NE(r.out.find("foxi"), std::string::npos) << cmd;
  }
}

TEST(Cli, OrderReportsZeroViolationsOnDelaunayMesh) {
  if (!test::have_program("tetgen")) GTEST_SKIP();
  test::TempDir dir;
  std::filesystem::copy(std::string(FOXI_TEST_DATA_DIR) + "/../../examples/trench.poly", dir / "t.poly");
  ASSERT_EQ(
      test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a0.002O0 t.poly", dir / "tetgen.log"), 0);
  Result r = foxi_cli("order '" + (dir / "t.1.ele").string() + "' --views 12 --check", dir);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("total       0 violations over 12 views"), std::string::npos) << r.out;
  Result s = foxi_cli(
      "order '" + (dir / "t.1.ele").string() + "' --views 6 --subset box:0,0,0,1,1,0.6 --check", dir);
  EXPECT_EQ(s.status, 0) << s.out;
  // The centroid baseline gets some wrong on the same mesh.
  Result c = foxi_cli("order '" + (dir / "t.1.ele").string() + "' --views 12 --method centroid --check", dir);
  EXPECT_EQ(c.status, 4) << c.out;
  // Counts and seeds that are not whole numbers are usage errors naming the option (std::stoi said
  // "stoi" with exit 1, and read 1e3 as 1; an outside probe).
  for (const char* bad : {"--views abc", "--views 1e3", "--views 99999999999", "--views 12 --seed 1e5"}) {
    Result u = foxi_cli("order '" + (dir / "t.1.ele").string() + "' " + bad, dir);
    EXPECT_EQ(u.status, 2) << bad << "\n" << u.out;
    EXPECT_NE(
        u.out.find(std::string(bad).find("seed") != std::string::npos ? "--seed takes" : "--views takes"),
        std::string::npos)
        << u.out;
  }
}

}  // namespace
}  // namespace foxi
