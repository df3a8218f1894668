// foxi model check|plc: exit statuses, the PLC file it writes (read back and meshed by the tetgen
// program), --set, and errors that name the file and the entity.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <string>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
namespace test = foxi::test;

const std::string kModels = std::string(FOXI_TEST_DATA_DIR) + "/../../models/";

int foxi_cli(const std::string& args, const std::filesystem::path& log) {
  return test::run("'" + test::cli_path() + "' " + args, log);
}

TEST(ModelCli, CheckReportsPartsBoundariesAndParameters) {
  TempDir dir;
  ASSERT_EQ(foxi_cli("model check '" + kModels + "flip_chip.toml' --set die_w=7mm", dir / "out.txt"), 0);
  const std::string out = test::read_text(dir / "out.txt");
  for (const char* s :
       {"substrate", "underfill", "bumps", "die", "sac305", "bumps/die", "die.top", "from --set",
        "physics thermal: ready", "physics thermoelastic: ready (foxi solve MODEL --physics thermoelastic)"})
    EXPECT_NE(out.find(s), std::string::npos) << s << " missing in:\n" << out;
  // the die is 7 x 7 x 0.5 mm with --set die_w=7mm
  EXPECT_NE(out.find("24.5 mm^3"), std::string::npos) << out;
}

TEST(ModelCli, PlcIsWrittenAndTetgenMeshesIt) {
  if (!test::have_program("tetgen")) GTEST_SKIP() << "no tetgen program";
  TempDir dir;
  ASSERT_EQ(
      foxi_cli("model plc '" + kModels + "via_in_dielectric.toml' -o '" + (dir / "v.poly").string() + "'",
               dir / "out.txt"),
      0)
      << test::read_text(dir / "out.txt");
  const foxi::Plc plc = foxi::read_poly(dir / "v.poly");
  EXPECT_EQ(plc.regions.size(), 3u);
  ASSERT_EQ(
      test::run("cd '" + dir.path().string() + "' && tetgen -pq1.414a1e-11AQ v.poly", dir / "tetgen.log"), 0)
      << test::read_text(dir / "tetgen.log");
}

TEST(ModelCli, ErrorsAndUsage) {
  TempDir dir;
  EXPECT_EQ(foxi_cli("model check '" + kModels + "die_on_substrate.toml' --set nothing=1mm", dir / "e1.txt"),
            3);
  EXPECT_NE(test::read_text(dir / "e1.txt").find("'nothing'"), std::string::npos)
      << test::read_text(dir / "e1.txt");
  EXPECT_EQ(foxi_cli("model plc '" + kModels + "die_on_substrate.toml'", dir / "e2.txt"), 2);  // no -o
  EXPECT_EQ(foxi_cli("model frobnicate x.toml", dir / "e3.txt"), 2);
  EXPECT_EQ(foxi_cli("model check '" + (dir / "missing.toml").string() + "'", dir / "e4.txt"), 3);
  EXPECT_NE(test::read_text(dir / "e4.txt").find("missing.toml"), std::string::npos)
      << test::read_text(dir / "e4.txt");
}

// foxi solve MODEL.toml: the model's conditions and loads drive the solve; the heat put into the
// die leaves through the boundaries, the fixed board temperature is what the model says (45 degC).
TEST(ModelCli, SolveModelUsesItsConditionsAndLoads) {
  TempDir dir;
  ASSERT_EQ(foxi_cli("solve '" + kModels + "flip_chip.toml' --physics thermal --set die_h=0.6mm", dir / "out.txt"), 0)
      << test::read_text(dir / "out.txt");
  const std::string out = test::read_text(dir / "out.txt");
  for (const char* s : {"substrate.bottom", "fixed", "die.top", "convection", "sources 3 W"})
    EXPECT_NE(out.find(s), std::string::npos) << s << " missing in:\n" << out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("energy balance: .* = (\\S+) W"))) << out;
  EXPECT_LT(std::abs(std::stod(m[1])), 1e-6 * 3) << out;
  // the hottest point is above the board's 318.15 K
  ASSERT_TRUE(std::regex_search(out, m, std::regex("max temperature (\\S+) K"))) << out;
  EXPECT_GT(std::stod(m[1]), 318.15);
  ASSERT_EQ(foxi_cli("solve '" + kModels + "via_in_dielectric.toml' --physics current", dir / "cur.txt"), 0)
      << test::read_text(dir / "cur.txt");
  EXPECT_NE(test::read_text(dir / "cur.txt").find("resistance"), std::string::npos);
}

// A [[mesh.refine]] box in the model: `foxi solve` meshes with it as `foxi mesh` does. The nodes in
// the box (counted on the solved mesh read back) against the same model without the box.
TEST(ModelCli, SolveAppliesTheModelsRefinementBoxes) {
  TempDir dir;
  std::filesystem::copy(kModels + "materials.toml", dir / "materials.toml");
  const std::string model = test::read_text(kModels + "die_on_substrate.toml");
  auto write = [&](const std::string& name, const std::string& text) {
    std::FILE* f = std::fopen((dir / name).c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(text.c_str(), f);
    std::fclose(f);
  };
  write("plain.toml", model);
  write("boxed.toml", model + "\n[[mesh.refine]]\nmin = [0, 0, 0]\nmax = [2, 2, 1]\nmax_size = \"0.25 mm\"\n");
  auto nodes_in_box = [&](const std::string& name, const std::string& command = "solve", const std::string& args = " --physics thermal") {
    const auto out = dir / (name + command + ".vtu");
    EXPECT_EQ(foxi_cli(command + " '" + (dir / (name + ".toml")).string() + "'" + args + " -o '" + out.string() + "'",
                       dir / "log.txt"),
              0)
        << test::read_text(dir / "log.txt");
    const foxi::Mesh m = foxi::read_mesh(out);
    EXPECT_TRUE(foxi::compute_delaunay_certificate(m).delaunay);
    std::size_t n = 0;
    for (std::size_t i = 0; i < m.node_count(); ++i)
      n += m.xyz[3 * i] <= 2e-3 && m.xyz[3 * i + 1] <= 2e-3 && m.xyz[3 * i + 2] <= 1e-3;
    return n;
  };
  const std::size_t plain = nodes_in_box("plain"), boxed = nodes_in_box("boxed");
  EXPECT_GT(boxed, 3 * plain) << plain << " nodes in the box without it";
  EXPECT_EQ(boxed, nodes_in_box("boxed", "mesh", ""));  // the mesh `foxi mesh` makes
}

TEST(ModelCli, SolveModelErrorsBeforeMeshing) {
  TempDir dir;
  // die_on_substrate has no electrodes
  EXPECT_EQ(foxi_cli("solve '" + kModels + "die_on_substrate.toml' --physics current", dir / "e1.txt"), 3);
  EXPECT_NE(test::read_text(dir / "e1.txt").find("no [[conditions]] fix the current solution"), std::string::npos)
      << test::read_text(dir / "e1.txt");
  std::filesystem::copy(kModels + "materials.toml", dir / "materials.toml");
  test::write_text(dir / "bad.toml", test::read_text(kModels + "die_on_substrate.toml") +
                                          "\n[[conditions]]\ntype = \"heat_flux\"\nsurface = \"die.bottom\"\n"
                                          "value = \"1 W/m^2\"\n");
  EXPECT_EQ(foxi_cli("solve '" + (dir / "bad.toml").string() + "' --physics thermal", dir / "e2.txt"), 3);
  const std::string e2 = test::read_text(dir / "e2.txt");
  EXPECT_NE(e2.find("bad.toml:"), std::string::npos) << e2;
  EXPECT_NE(e2.find("surface 'die.bottom' does not exist"), std::string::npos) << e2;
  EXPECT_EQ(e2.find("nodes"), std::string::npos) << "meshed before the error:\n" << e2;
  EXPECT_EQ(foxi_cli("solve '" + kModels + "die_on_substrate.toml' --set nothing=1", dir / "e3.txt"), 3);
}

// Every part of the exploded picture shows: some pixel has the part's colour (up to shading).
TEST(ModelCli, ShowDrawsEveryPartInItsColour) {
  TempDir dir;
  ASSERT_EQ(foxi_cli("model show '" + kModels + "flip_chip.toml' --size 640x480 -o '" + (dir / "f.png").string() + "'",
                     dir / "out.txt"),
            0)
      << test::read_text(dir / "out.txt");
  const std::string out = test::read_text(dir / "out.txt");
  const foxi::Framebuffer fb = foxi::read_png(dir / "f.png");
  ASSERT_EQ(fb.width, 640);
  ASSERT_EQ(fb.height, 480);
  std::size_t parts = 0;
  const std::regex legend("\\n  (\\S+) +(\\S+) +#([0-9a-f]{6})");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), legend); it != std::sregex_iterator(); ++it) {
    ++parts;
    const unsigned c = static_cast<unsigned>(std::stoul((*it)[3].str(), nullptr, 16));
    const double want[3] = {double(c >> 16), double((c >> 8) & 255u), double(c & 255u)};
    std::size_t hits = 0;
    for (std::uint32_t px : fb.rgba) {
      const double got[3] = {double(px & 255u), double((px >> 8) & 255u), double((px >> 16) & 255u)};
      const double k = (got[0] + got[1] + got[2]) / (want[0] + want[1] + want[2]);
      bool same = k > 0.25;
      for (int i = 0; i < 3; ++i) same = same && std::abs(got[i] - k * want[i]) <= 2.5;
      hits += same;
    }
    EXPECT_GT(hits, 50u) << (*it)[1] << " (" << (*it)[2] << ") not in the picture";
  }
  EXPECT_EQ(parts, 4u) << out;
  EXPECT_EQ(foxi_cli("model show '" + kModels + "flip_chip.toml'", dir / "e.txt"), 2);  // no -o
}

TEST(ModelCli, DemoRunsAModelEndToEnd) {
  TempDir dir;
  ASSERT_EQ(foxi_cli("demo '" + kModels + "trench.toml' -o '" + (dir / "d").string() + "'", dir / "out.txt"), 0)
      << test::read_text(dir / "out.txt");
  const std::string out = test::read_text(dir / "out.txt");
  for (const char* s : {"1. model", "2. mesh", "3. certificate", "4. steady heat", "5. picture"})
    EXPECT_NE(out.find(s), std::string::npos) << s << " missing in:\n" << out;
  for (const char* f : {"trench.vtu", "trench.png", "trench_parts.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "d" / f)) << f;
}

}  // namespace
