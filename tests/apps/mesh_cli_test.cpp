// foxi mesh MODEL.toml: the model goes through the PLC to a certified mesh, the report is printed,
// --set and --max-size act (checked on the mesh read back: the die's volume, the largest tet),
// usage errors exit 2, and Ctrl-C (SIGINT) stops a long run with status 130 and no output file
// (signals_cli_test.cpp signals every command at random moments).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/quality.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
namespace test = foxi::test;

const std::string kModels = test::models_dir();
int foxi_cli(const std::string& args, const std::filesystem::path& log) { return test::run_cli(args, log); }

TEST(MeshCli, ModelToCertifiedMeshWithReport) {
  TempDir dir;
  const auto out = dir / "d.vtu";
  ASSERT_EQ(foxi_cli("mesh '" + kModels +
                         "die_on_substrate.toml' --set die_w=3mm --max-size 1mm --quality 1.5 -o '" +
                         out.string() + "'",
                     dir / "log.txt"),
            0)
      << test::read_text(dir / "log.txt");
  const std::string log = test::read_text(dir / "log.txt");
  for (const char* s : {"radius-edge ratio", "min dihedral histogram", "slivers below 5 deg",
                        "Steiner points", "delaunay: yes", "region 2 die", "q1.5"})
    EXPECT_NE(log.find(s), std::string::npos) << s << " missing in:\n" << log;
  const foxi::Mesh m = foxi::read_mesh(out);
  EXPECT_TRUE(foxi::compute_delaunay_certificate(m).delaunay);
  double die = 0, vmax = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    const double vol = std::abs(
        foxi::tet_quality(&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]).volume);
    if (m.region_of(t) == 2) die += vol;
    vmax = std::max(vmax, vol);
  }
  EXPECT_NEAR(die, 3e-3 * 3e-3 * 0.5e-3, 1e-15);              // --set die_w=3mm
  EXPECT_LE(vmax, 1e-9 / (6 * std::sqrt(2.0)) * (1 + 1e-9));  // --max-size 1mm: the regular tet's volume
  bool named = false;
  for (const foxi::Region& r : m.regions) named = named || r.name == "die";
  EXPECT_TRUE(named);
  // The materials travel with the mesh: it solves without restating them, and the substrate's k is
  // the library's FR-4 value.
  ASSERT_EQ(
      foxi_cli("solve '" + out.string() + "' --physics thermal --fix substrate.bottom=300 --power die=1",
               dir / "solve.txt"),
      0)
      << test::read_text(dir / "solve.txt");
  const std::string solved = test::read_text(dir / "solve.txt");
  EXPECT_NE(solved.find("(substrate)                   0.4"), std::string::npos) << solved;
}

TEST(MeshCli, UsageErrors) {
  TempDir dir;
  EXPECT_EQ(
      foxi_cli("mesh '" + kModels + "flip_chip.toml' --max-size 3K -o '" + (dir / "a.vtu").string() + "'",
               dir / "log.txt"),
      2);
  EXPECT_NE(test::read_text(dir / "log.txt").find("--max-size"), std::string::npos);
  EXPECT_EQ(foxi_cli("mesh '" + kModels + "flip_chip.toml' --refine-from x.vtu -o '" +
                         (dir / "a.vtu").string() + "'",
                     dir / "log.txt"),
            2);
  EXPECT_NE(test::read_text(dir / "log.txt").find("--target-error"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "a.vtu"));
}

TEST(MeshCli, SigintCancelsWithoutOutput) {
  TempDir dir;
  const auto out = dir / "big.vtu";
  // A run of minutes, interrupted after 1.5 s (`timeout` passes SIGINT on, and kills a run that
  // ignores it after 60 s so that a failing test ends).
  const std::string cmd = "timeout -s KILL 60 '" + test::cli_path() + "' mesh '" + kModels +
                          "flip_chip.toml' --max-size 0.03mm --max-tets 100000000 -o '" + out.string() +
                          "' > '" + (dir / "log.txt").string() + "' 2>&1 & echo $! > '" +
                          (dir / "pid").string() + "'; wait";
  std::thread runner([&] { test::run(cmd); });
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const std::string pid = test::read_text(dir / "pid");
  ASSERT_FALSE(pid.empty());
  test::run("kill -INT " + pid);
  runner.join();
  EXPECT_NE(test::read_text(dir / "log.txt").find("stopped by SIGINT"), std::string::npos)
      << test::read_text(dir / "log.txt");
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
