// foxi model check|plc: exit statuses, the PLC file it writes (read back and meshed by the tetgen
// program), --set, and errors that name the file and the entity.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include "foxi/model/delaunay.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
namespace test = foxi::test;

const std::string kModels = std::string(FOXI_TEST_DATA_DIR) + "/../../models/";
constexpr int kBadInput = 3;  // kExitBadInput (apps/foxi/exit_codes.hpp)

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
  ASSERT_EQ(
      foxi_cli("solve '" + kModels + "flip_chip.toml' --physics thermal --set die_h=0.6mm", dir / "out.txt"),
      0)
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

// Two bars in series (copper 10 mm, then a weaker conductor 5 mm, both 1 mm square), 1 A from the
// top to the grounded bottom: the resistance is L1 / (s1 A) + L2 / (s2 A) exactly (the potential
// is linear in each bar, which P1 elements hold). A current of 1e300 A overflows the Joule heat:
// the energy check fails, the run says UNRELIABLE with exit status 4, and the error indicator says
// the gradient is not a finite number (it said "has no gradient").
TEST(ModelCli, SeriesBarsResistanceAndAnOverflowingCurrentIsFlagged) {
  TempDir dir;
  auto model = [&](const std::string& current) {
    return "units.length = \"mm\"\n"
           "[materials.cu]\nthermal_conductivity = 400.0\nelectrical_conductivity = 6e7\n"
           "[materials.alloy]\nthermal_conductivity = 50.0\nelectrical_conductivity = 8e6\n"
           "[[parts]]\nname = \"bar\"\nmaterial = \"cu\"\nshape = \"box\"\norigin = [0, 0, 0]\n"
           "size = [1, 1, 10]\n"
           "[[parts]]\nname = \"cap\"\nmaterial = \"alloy\"\nshape = \"box\"\norigin = [0, 0, 10]\n"
           "size = [1, 1, 5]\n"
           "[[conditions]]\ntype = \"ground\"\nsurface = \"bar.bottom\"\nname = \"gnd\"\n"
           "[[conditions]]\ntype = \"current\"\nsurface = \"cap.top\"\nname = \"load\"\nvalue = \"" +
           current + "\"\n[mesh]\nmax_size = \"0.5 mm\"\n";
  };
  test::write_text(dir / "bars.toml", model("1 A"));
  ASSERT_EQ(foxi_cli("solve '" + (dir / "bars.toml").string() + "' --physics current -o '" +
                         (dir / "bars.vtu").string() + "'",
                     dir / "bars.txt"),
            0)
      << test::read_text(dir / "bars.txt");
  const std::string out = test::read_text(dir / "bars.txt");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("resistance (\\S+) ohm"))) << out;
  const double analytic = 0.010 / (6e7 * 1e-6) + 0.005 / (8e6 * 1e-6);
  EXPECT_NEAR(std::stod(m[1]), analytic, 1e-6 * analytic) << out;
  test::write_text(dir / "huge.toml", model("1e300 A"));
  EXPECT_EQ(foxi_cli("solve '" + (dir / "huge.toml").string() + "' --physics current -o '" +
                         (dir / "huge.vtu").string() + "'",
                     dir / "huge.txt"),
            4);
  const std::string huge = test::read_text(dir / "huge.txt");
  EXPECT_NE(huge.find("UNRELIABLE"), std::string::npos) << huge;
  EXPECT_NE(huge.find("gradient is not a finite number"), std::string::npos) << huge;
  EXPECT_EQ(huge.find("has no gradient"), std::string::npos) << huge;
}

// Square copper bars 0.2 to 1.2 mm wide, 10 mm long, meshed at 0.3, 0.5 and 0.77 mm: TetGen puts
// Steiner points at the midpoints of the four sides at one height, four of them nearly coplanar
// and cocircular, and its Delaunay mesh held the flat tet across them (6V 1e-17 of its edges
// cubed): the solve refused the mesh ("nearly flat"), found the matrix singular, or failed the
// Kirchhoff check (an outside probe: 0.4 to 0.9 mm at 0.5 mm). The mesher now removes them, and
// every bar conducts L / (sigma w^2) (the potential is linear along the bar, which P1 holds exactly).
TEST(ModelCli, BarsWhoseMeshHadFlatTetsConductAsTheFormulaSays) {
  TempDir dir;
  const std::pair<const char*, const char*> cases[] = {{"0.5", "0.4"}, {"0.5", "0.5"}, {"0.5", "0.6"},
                                                       {"0.5", "0.7"}, {"0.5", "0.9"}, {"0.3", "0.2"},
                                                       {"0.77", "1.2"}};
  for (const auto& [size, width] : cases) {
    const std::string name = std::string("bar_") + size + "_" + width;
    test::write_text(dir / (name + ".toml"),
                     std::string("units.length = \"mm\"\n[materials.cu]\nelectrical_conductivity = 5.96e7\n"
                                 "[[parts]]\nname = \"bar\"\nmaterial = \"cu\"\nshape = \"box\"\n"
                                 "origin = [0, 0, 0]\nsize = [") +
                         width + ", " + width + ", 10]\n" +
                         "[[conditions]]\ntype = \"voltage\"\nsurface = \"bar.top\"\nname = \"top\"\n"
                         "value = \"1 V\"\n[[conditions]]\ntype = \"ground\"\nsurface = \"bar.bottom\"\n"
                         "name = \"bot\"\n[mesh]\nmax_size = \"" +
                         size + " mm\"\n");
    const int rc = foxi_cli("solve '" + (dir / (name + ".toml")).string() + "' --physics current",
                            dir / (name + ".txt"));
    const std::string out = test::read_text(dir / (name + ".txt"));
    ASSERT_EQ(rc, 0) << name << "\n" << out;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(out, m, std::regex("resistance (\\S+) ohm"))) << out;
    const double w = std::stod(width) * 1e-3, analytic = 0.010 / (5.96e7 * w * w);
    EXPECT_NEAR(std::stod(m[1]), analytic, 1e-6 * analytic) << name << "\n" << out;
  }
}

// A part touching the rest only along an edge or at a corner: no area of contact, nothing passes
// (foxi model check says so), but the mesh shares nodes there and a solve passed a mesh-dependent
// heat and current through them (8e-5 ohm through an edge, every check passed; an outside probe).
// Refused before solving, naming the part's line; the same part moved to share a face solves.
TEST(ModelCli, ContactAlongAnEdgeOrAtACornerIsRefusedBySolve) {
  TempDir dir;
  auto model = [&](const std::string& origin) {
    return "units.length = \"mm\"\n[materials.cu]\nthermal_conductivity = 400.0\n"
           "electrical_conductivity = 6e7\n"
           "[[parts]]\nname = \"a\"\nmaterial = \"cu\"\nshape = \"box\"\norigin = [0, 0, 0]\n"
           "size = [1, 1, 1]\n"
           "[[parts]]\nname = \"b\"\nmaterial = \"cu\"\nshape = \"box\"\norigin = [" +
           origin +
           "]\nsize = [1, 1, 1]\n"
           "[[conditions]]\ntype = \"voltage\"\nsurface = \"a.bottom\"\nname = \"t1\"\nvalue = \"1 V\"\n"
           "[[conditions]]\ntype = \"ground\"\nsurface = \"b.top\"\nname = \"t2\"\n"
           "[[conditions]]\ntype = \"temperature\"\nsurface = \"a.bottom\"\nvalue = \"300 K\"\n"
           "[[conditions]]\ntype = \"temperature\"\nsurface = \"b.top\"\nvalue = \"310 K\"\n"
           "[mesh]\nmax_size = \"0.4 mm\"\n";
  };
  for (const char* origin : {"1, 0, 1", "1, 1, 1"}) {
    test::write_text(dir / "m.toml", model(origin));
    for (const char* physics : {"current", "thermal"}) {
      const int rc =
          foxi_cli("solve '" + (dir / "m.toml").string() + "' --physics " + physics, dir / "out.txt");
      const std::string out = test::read_text(dir / "out.txt");
      EXPECT_EQ(rc, kBadInput) << origin << " " << physics << "\n" << out;
      EXPECT_NE(
          out.find("m.toml:11: part 'b' touches the rest of the model only along an edge or at a point"),
          std::string::npos)
          << out;
      EXPECT_EQ(out.find("resistance"), std::string::npos) << out;
    }
  }
  test::write_text(dir / "m.toml", model("0, 0, 1"));  // b on a's top face: a 2 mm bar
  ASSERT_EQ(foxi_cli("solve '" + (dir / "m.toml").string() + "' --physics current", dir / "out.txt"), 0)
      << test::read_text(dir / "out.txt");
  const std::string out = test::read_text(dir / "out.txt");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("resistance (\\S+) ohm"))) << out;
  EXPECT_NEAR(std::stod(m[1]), 0.002 / (6e7 * 1e-6), 1e-6 * 0.002 / (6e7 * 1e-6)) << out;
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
  write("boxed.toml",
        model + "\n[[mesh.refine]]\nmin = [0, 0, 0]\nmax = [2, 2, 1]\nmax_size = \"0.25 mm\"\n");
  auto nodes_in_box = [&](const std::string& name, const std::string& command = "solve",
                          const std::string& args = " --physics thermal") {
    const auto out = dir / (name + command + ".vtu");
    EXPECT_EQ(foxi_cli(command + " '" + (dir / (name + ".toml")).string() + "'" + args + " -o '" +
                           out.string() + "'",
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
  EXPECT_NE(test::read_text(dir / "e1.txt").find("no [[conditions]] fix the current solution"),
            std::string::npos)
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
  ASSERT_EQ(foxi_cli("model show '" + kModels + "flip_chip.toml' --size 640x480 -o '" +
                         (dir / "f.png").string() + "'",
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
  ASSERT_EQ(foxi_cli("demo '" + kModels + "trench.toml' -o '" + (dir / "d").string() + "'", dir / "out.txt"),
            0)
      << test::read_text(dir / "out.txt");
  const std::string out = test::read_text(dir / "out.txt");
  for (const char* s : {"1. model", "2. mesh", "3. certificate", "4. steady heat", "5. picture"})
    EXPECT_NE(out.find(s), std::string::npos) << s << " missing in:\n" << out;
  for (const char* f :
       {"trench.vtu", "trench.png", "trench_parts.png", "trench_isotherm.png", "trench_isotherms.gif"})
    EXPECT_TRUE(std::filesystem::exists(dir / "d" / f)) << f;
  // The trench has no mechanical supports: the stress steps are skipped with the reason, not failed.
  EXPECT_NE(out.find("9. thermal stress: skipped, the model is not ready for it"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "d" / "trench_von_mises.png"));
}

// The flip chip has supports: the demo shows the isotherm at the middle of the temperature range (its
// render's isovalue is that middle), the sweep as a movie, and von Mises on the deformed shape, the
// displacement scaled (1-2-5) so that the nodes move by 0.8 % to 2 % of the model's diagonal.
TEST(ModelCli, DemoShowsIsothermAndStressOnTheDeformedShape) {
  TempDir dir;
  ASSERT_EQ(
      foxi_cli("demo '" + kModels + "flip_chip.toml' -o '" + (dir / "d").string() + "'", dir / "out.txt"), 0)
      << test::read_text(dir / "out.txt");
  const std::string out = test::read_text(dir / "out.txt");
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(out, m, std::regex("\\(graded facets, viridis\\), ([0-9.]+) to ([0-9.]+) °C")))
      << out;
  const double lo = std::stod(m[1]), hi = std::stod(m[2]);
  ASSERT_TRUE(std::regex_search(out, m, std::regex("iso         ([0-9.]+) °C: ([0-9]+) tets crossed")))
      << out;
  EXPECT_NEAR(std::stod(m[1]), (lo + hi) / 2, 0.051);
  EXPECT_GT(std::stoul(m[2]), 0u);
  EXPECT_NE(out.find("sweep       isovalue of temperature, 24 frames"), std::string::npos) << out;
  const foxi::Mesh te = foxi::read_mesh(dir / "d" / "flip_chip_stress.vtu");
  double lo3[3] = {1e300, 1e300, 1e300}, hi3[3] = {-1e300, -1e300, -1e300};
  for (std::size_t n = 0; n < te.node_count(); ++n)
    for (int k = 0; k < 3; ++k)
      lo3[k] = std::min(lo3[k], te.xyz[3 * n + std::size_t(k)]),
      hi3[k] = std::max(hi3[k], te.xyz[3 * n + std::size_t(k)]);
  const double diag = std::hypot(hi3[0] - lo3[0], hi3[1] - lo3[1], hi3[2] - lo3[2]);
  ASSERT_TRUE(std::regex_search(
      out, m, std::regex("deformed    by displacement x ([0-9.e+-]+): nodes moved up to ([0-9.e+-]+)")))
      << out;
  const double moved = std::stod(m[2]);
  EXPECT_LE(moved, 0.02 * diag * (1 + 1e-5));
  EXPECT_GE(moved, 0.008 * diag);
  EXPECT_NE(out.find("field       von_mises"), std::string::npos) << out;
  // The von Mises picture is the solid above a quarter of the way up its range (two digits, MPa).
  ASSERT_TRUE(std::regex_search(out, m, std::regex("iso         ([0-9.e+-]+) MPa: ([0-9]+) tets crossed")))
      << out;
  {
    const std::vector<double> c = foxi::tet_corner_values(te, foxi::choose_field(te, "von_mises"));
    const auto [vlo, vhi] = std::minmax_element(c.begin(), c.end());
    const double want = 1e-6 * (*vlo + 0.25 * (*vhi - *vlo));
    EXPECT_NEAR(std::stod(m[1]), want, 0.051 * want) << out;
    EXPECT_GT(std::stoul(m[2]), 0u);
  }
  for (const char* f : {"flip_chip_isotherm.png", "flip_chip_isotherms.gif", "flip_chip_von_mises.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "d" / f)) << f;
}

// --- issue 22: model inputs that crashed or hung foxi; each is refused quickly with exit status 3 ---

struct Outcome {
  int status;
  double seconds;
  std::string text;
};

Outcome timed(const std::string& args, const std::filesystem::path& log) {
  const auto t0 = std::chrono::steady_clock::now();
  const int status = foxi_cli(args, log);
  return {status, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
          test::read_text(log)};
}

// The crashes (SIGSEGV in CGAL, SIGFPE in GMP and on nan, stack overflows in toml11 and in foxi's
// expression parser) and the hangs (counts without a bound): exit 3, the file named, in seconds.
TEST(ModelCli, CrashesAndHangsOfIssue22AreRefused) {
  TempDir dir;
  std::filesystem::copy(kModels + "materials.toml", dir / "materials.toml");
  const std::string die = kModels + "die_on_substrate.toml", bga = kModels + "bga.toml";
  auto model = [&](const std::string& name, const std::string& text) {
    test::write_text(dir / name, "units.length = \"mm\"\nlibrary = \"materials.toml\"\n" + text);
    return "'" + (dir / name).string() + "'";
  };
  const std::string board =
      "[[parts]]\nname = \"board\"\nmaterial = \"fr4\"\nshape = \"box\"\norigin = [0, 0, 0]\nsize = [10, 10, "
      "1]\n";
  std::string outline;
  for (int i = 0; i < 20000; ++i) {
    const double a = 2 * 3.141592653589793 * i / 20000;
    outline += (i ? ",\n [" : "[") + std::to_string(5 + 2 * std::cos(a)) + ", " +
               std::to_string(5 + 2 * std::sin(a)) + "]";
  }
  std::string deep;  // 100,000 levels in 200 KB, a thousand brackets a line
  for (int k = 0; k < 100; ++k) deep = std::string(1000, '[') + "\n" + deep + std::string(1000, ']') + "\n";
  std::string one_line = outline;  // all on one line: toml11 took a minute over it
  std::replace(one_line.begin(), one_line.end(), '\n', ' ');
  struct Case {
    std::string args, file, want;
  } cases[] = {
      {"'" + die + "' --set 'die_w=1e-30 mm'", "die_on_substrate.toml", "degenerate geometry"},
      {"'" + bga + "' --set 'die_w=1e300 mm'", "bga.toml", "beyond the limit of 1000 m"},
      {model("nan.toml", board + "[[parts]]\nname = \"e\"\nmaterial = \"fr4\"\nshape = \"extrusion\"\n"
                                 "points = [[0, 0], [nan, 0], [1, 1]]\nz = 1\nheight = 1\n"),
       "nan.toml", "part 'e' points[1][0] is not a finite number"},
      {model("inf.toml", board + "[[parts]]\nname = \"e\"\nmaterial = \"fr4\"\nshape = \"extrusion\"\n"
                                 "points = [[0, 0], [1, inf], [1, 1]]\nz = 1\nheight = 1\n"),
       "inf.toml", "not a finite number"},
      {model("deep.toml", "x = " + deep + board), "deep.toml", "nest deeper than 32"},
      {"'" + die + "' --set 'die_w=" + std::string(20000, '(') + "4 mm" + std::string(20000, ')') + "'",
       "die_on_substrate.toml", "parameter 'die_w' (from --set)"},
      {"'" + die + "' --set 'die_w=" + std::string(100, '(') + "4 mm" + std::string(100, ')') + "'",
       "die_on_substrate.toml", "nests deeper than 64"},
      {model("array.toml", board + "[[parts]]\nname = \"pins\"\nmaterial = \"copper\"\nshape = \"array\"\n"
                                   "count = [100000, 1]\npitch = [0.1, 0.1]\nitem = { shape = \"box\", "
                                   "origin = [0, 0, 1], size = [0.05, 0.05, 1] }\n"),
       "array.toml", "must be an integer from 1 to 10000"},
      {model("cyl.toml", board + "[[parts]]\nname = \"c\"\nmaterial = \"copper\"\nshape = \"cylinder\"\n"
                                 "center = [5, 5, 1]\nradius = 1\nheight = 1\nsegments = 1e6\n"),
       "cyl.toml", "must be an integer from 3 to 1000"},
      {"'" + bga + "' --set 'ball_tol=1e-6 mm'", "bga.toml", "below the limit of 0.001 times the radius"},
      {model("outline.toml", board +
                                 "[[parts]]\nname = \"e\"\nmaterial = \"fr4\"\nshape = \"extrusion\"\n"
                                 "points = [" +
                                 outline + "]\nz = 1\nheight = 1\n"),
       "outline.toml", "20000 points, more than the limit of 2000"},
      {model("line.toml", board +
                              "[[parts]]\nname = \"e\"\nmaterial = \"fr4\"\nshape = \"extrusion\"\n"
                              "points = [" +
                              one_line + "]\nz = 1\nheight = 1\n"),
       "line.toml", "more than the limit of 65536 (break long arrays over several lines)"},
  };
  for (const Case& c : cases) {
    const Outcome o = timed("model check " + c.args, dir / "log.txt");
    EXPECT_EQ(o.status, kBadInput) << c.want << "\n" << o.text;
    EXPECT_LT(o.seconds, 5 * test::kTimeScale) << c.want;
    EXPECT_NE(o.text.find(c.file + ":"), std::string::npos) << o.text;
    EXPECT_NE(o.text.find(c.want), std::string::npos) << c.want << "\n" << o.text;
  }
}

// Referenced files (library, STL): a directory, an empty name, an absolute path, a file of the wrong
// kind; the error never quotes the file it opened.
TEST(ModelCli, ReferencedFilesAreCheckedAndNeverQuoted) {
  TempDir dir;
  std::filesystem::create_directory(dir / "sub");
  test::write_text(dir / "secret.txt", "root:x:0:0:SECRET:/root:/bin/bash\n");
  const std::string part =
      "[materials.a]\nthermal_conductivity = 1\n[[parts]]\nname = \"b\"\nmaterial = \"a\"\nshape = \"box\"\n"
      "origin = [0, 0, 0]\nsize = [1, 1, 1]\n";
  const std::string stl = "[[parts]]\nname = \"s\"\nmaterial = \"a\"\nshape = \"stl\"\nfile = ";
  struct Case {
    std::string text, want;
  } cases[] = {
      {"library = \"sub\"\n" + part, "library 'sub' is a directory, not a file"},
      {"library = \"\"\n" + part, "library: the file name is empty"},
      {"library = \"/etc/passwd\"\n" + part, "is an absolute path"},
      {"library = \"secret.txt\"\n" + part, "not a TOML materials library"},
      {part + stl + "\"sub\"\n", "part 's' file 'sub' is a directory, not a file"},
      {part + stl + "\"\"\n", "part 's' file: the file name is empty"},
      {part + stl + "\"secret.txt\"\n", "not an STL file"},
  };
  for (const Case& c : cases) {
    test::write_text(dir / "m.toml", c.text);
    const Outcome o = timed("model check '" + (dir / "m.toml").string() + "'", dir / "log.txt");
    EXPECT_EQ(o.status, kBadInput) << o.text;
    EXPECT_NE(o.text.find(c.want), std::string::npos) << c.want << "\n" << o.text;
    EXPECT_EQ(o.text.find("SECRET"), std::string::npos) << o.text;
    EXPECT_EQ(o.text.find("out of memory"), std::string::npos) << o.text;
  }
}

// The tet-count estimate: a size far too small for the model is refused before meshing (in well
// under the time TetGen would take), --max-tets raises or lowers the limit, and the estimate is
// within a factor of 3 of the tets TetGen then makes.
TEST(ModelCli, MeshRefusesAnEstimatePastMaxTets) {
  TempDir dir;
  const std::string die = "'" + kModels + "die_on_substrate.toml'",
                    out = "'" + (dir / "m.vtu").string() + "'";
  Outcome o = timed("mesh " + die + " --max-size 0.01mm -o " + out, dir / "log.txt");
  EXPECT_EQ(o.status, kBadInput) << o.text;
  EXPECT_LT(o.seconds, 5 * test::kTimeScale);
  EXPECT_NE(o.text.find("over the limit of 4000000"), std::string::npos) << o.text;
  EXPECT_NE(o.text.find("--max-tets"), std::string::npos) << o.text;
  EXPECT_FALSE(std::filesystem::exists(dir / "m.vtu"));
  // 0.4 mm: about 2 * 112 mm^3 / (0.4^3 / 8.49 mm^3) = 30k tets
  o = timed("mesh " + die + " --max-size 0.4mm --max-tets 5000 -o " + out, dir / "log.txt");
  EXPECT_EQ(o.status, kBadInput) << o.text;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.text, m, std::regex("about (\\S+) tets"))) << o.text;
  const double estimate = std::stod(m[1]);
  ASSERT_EQ(foxi_cli("mesh " + die + " --max-size 0.4mm -o " + out, dir / "log.txt"), 0)
      << test::read_text(dir / "log.txt");
  const double tets = static_cast<double>(foxi::read_mesh(dir / "m.vtu").tet_count());
  EXPECT_GT(tets, estimate / 3) << estimate;
  EXPECT_LT(tets, estimate * 3) << estimate;
  EXPECT_EQ(foxi_cli("mesh " + die + " --max-tets 0 -o " + out, dir / "log.txt"), 2);
  EXPECT_EQ(foxi_cli("mesh " + die + " --max-tets lots -o " + out, dir / "log.txt"), 2);
  // A size for a region the model does not have is the input's fault (it was exit 1, a failure).
  EXPECT_EQ(foxi_cli("mesh " + die + " --region-size 99=0.1mm -o " + out, dir / "log.txt"), kBadInput);
  EXPECT_NE(test::read_text(dir / "log.txt").find("no region 99"), std::string::npos);
  // A refinement box over the whole model at 0.01 mm (an outside probe: meshed until killed, in the
  // passes that make the boxes' size field, before their estimate): refused as promptly.
  o = timed("mesh " + die + " --refine-box -10,-10,-10,10,10,10=0.01mm -o " + out, dir / "log.txt");
  EXPECT_EQ(o.status, kBadInput) << o.text;
  EXPECT_LT(o.seconds, 5 * test::kTimeScale);
  EXPECT_NE(o.text.find("over the limit of 4000000"), std::string::npos) << o.text;
}

// --refine-from with a small target error shrinks every size by up to 4 (64 times the tets) each
// round, without end: the estimate (the size field integrated over the solved mesh) bounds it, and
// is within a factor of 3 of what TetGen makes where it is allowed.
TEST(ModelCli, RefineFromIsBoundedByTheEstimate) {
  TempDir dir;
  const std::string die = "'" + kModels + "die_on_substrate.toml'",
                    solved = "'" + (dir / "s.vtu").string() + "'";
  ASSERT_EQ(foxi_cli("solve " + die + " --physics thermal -o " + solved, dir / "log.txt"), 0)
      << test::read_text(dir / "log.txt");
  const double first = static_cast<double>(foxi::read_mesh(dir / "s.vtu").tet_count());
  const std::string refine =
      "mesh " + die + " --refine-from " + solved + " -o '" + (dir / "r.vtu").string() + "'";
  Outcome o =
      timed(refine + " --target-error 1e-9 --max-tets " + std::to_string(static_cast<long>(10 * first)),
            dir / "log.txt");
  EXPECT_EQ(o.status, kBadInput) << o.text;
  EXPECT_LT(o.seconds, 10 * test::kTimeScale);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.text, m, std::regex("about (\\S+) tets"))) << o.text;
  EXPECT_GT(std::stod(m[1]), 10 * first) << o.text;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.vtu"));
  // a moderate target: the estimate against the mesh made
  o = timed(refine + " --target-error 0.3 --max-tets 1", dir / "log.txt");
  ASSERT_TRUE(std::regex_search(o.text, m, std::regex("about (\\S+) tets"))) << o.text;
  const double estimate = std::stod(m[1]);
  ASSERT_EQ(foxi_cli(refine + " --target-error 0.3", dir / "log.txt"), 0) << test::read_text(dir / "log.txt");
  const double tets = static_cast<double>(foxi::read_mesh(dir / "r.vtu").tet_count());
  EXPECT_GT(tets, estimate / 3) << estimate;
  EXPECT_LT(tets, estimate * 3) << estimate;
}

// model show meshes coarsely: power_module's thin solders once made a "coarse" mesh of 612,775 tets
// (44 s); now the tets follow the PLC's points, and every part still shows (its legend line).
TEST(ModelCli, ShowMeshIsCoarse) {
  TempDir dir;
  const Outcome o = timed(
      "model show '" + kModels + "power_module.toml' --size 320x240 -o '" + (dir / "p.png").string() + "'",
      dir / "log.txt");
  ASSERT_EQ(o.status, 0) << o.text;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(o.text, m, std::regex("coarse mesh (\\d+) nodes, (\\d+) tets"))) << o.text;
  EXPECT_LT(std::stod(m[2]), 5000) << o.text;
  EXPECT_NE(o.text.find("baseplate"), std::string::npos) << o.text;
  EXPECT_EQ(foxi::read_png(dir / "p.png").width, 320);
  EXPECT_EQ(foxi_cli("model show '" + kModels + "power_module.toml' --max-tets 10 -o '" +
                         (dir / "q.png").string() + "'",
                     dir / "log2.txt"),
            kBadInput)
      << test::read_text(dir / "log2.txt");
  EXPECT_NE(test::read_text(dir / "log2.txt").find("over the limit of 10;"), std::string::npos)
      << test::read_text(dir / "log2.txt");
}

}  // namespace
