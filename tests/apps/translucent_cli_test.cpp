// foxi render --region-opacity / --iso-opacity end to end. A slab of three regions along x seen from
// above (orthographic): over a region of opacity a, a pixel shows its bottom face blended over the
// white background and its top face over that (both flat, facing the eye, the same Lambert factor),
// computed here by hand; an opaque region its shaded colour; a region of opacity 0 nothing. The
// options take region ids or names; malformed ones and combinations it does not draw exit 2. --volume
// of a field linear in x seen along z, with a constant opacity that accumulates 0.5 through the slab:
// every pixel is half the colour map's colour of its x over white.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

class TranslucentCli : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh = test::grid_mesh(9, 4, 2, 1, 1, 0.5, 6);
    test::regions_along_x(mesh, 3, 6);
    mesh.regions = {{1, "mould", kNone}, {2, "die", kNone}, {3, "substrate", kNone}};
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    for (std::size_t n = 0; n < mesh.node_count(); ++n) t.values.push_back(300 + 10 * mesh.xyz[3 * n]);
    mesh.fields = {t};
    path_ = dir_ / "slab.vtu";
    write_mesh(mesh, path_);
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status =
        test::run("'" + test::cli_path() + "' render '" + path_.string() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  Mesh mesh;
  test::TempDir dir_;
  std::filesystem::path path_;
};

// The painter's Lambert factor of a face whose normal points straight at an orthographic eye.
double facing_shade() {
  const double l[3] = {-0.3, 0.45, -1};
  const double s = 1 / std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  return 0.3 + 0.7 * s;
}

std::size_t count_near(const Framebuffer& fb, const double want[3]) {
  std::size_t n = 0;
  for (std::uint32_t p : fb.rgba) {
    bool ok = true;
    for (int k = 0; k < 3; ++k) ok &= std::abs(double((p >> (8 * k)) & 255u) - want[k]) <= 1.0;
    n += ok;
  }
  return n;
}

TEST_F(TranslucentCli, TopViewShowsHandBlendedLayers) {
  const auto png = dir_ / "x.png";
  std::string log;
  ASSERT_EQ(
      foxi("--region-opacity mould=0.4,3=0 --dir 0,0,-1 --up 0,1,0 --size 180x120 -o '" + png.string() + "'",
           &log),
      0)
      << log;
  EXPECT_NE(log.find("composited back to front in the power order"), std::string::npos) << log;
  const Framebuffer fb = read_png(png);
  const double shade = facing_shade();
  double mould[3], die[3], white[3] = {255, 255, 255};
  for (int k = 0; k < 3; ++k) {
    const double c = double((region_color(1) >> (8 * k)) & 255u) * shade;
    double x = 255;
    x = c * 0.4 + x * 0.6;  // the bottom face
    x = c * 0.4 + x * 0.6;  // the top face
    mould[k] = x;
    die[k] = double((region_color(2) >> (8 * k)) & 255u) * shade;
  }
  // The slab is 9 x 4 seen from above, fitted to 180x120: each third of it covers a block of pixels.
  const std::size_t n_mould = count_near(fb, mould), n_die = count_near(fb, die),
                    n_white = count_near(fb, white);
  EXPECT_GT(n_mould, 1500u);
  EXPECT_GT(n_die, 1500u);
  EXPECT_GT(n_white, 1500u) << "the substrate is left out (opacity 0), the background shows";
  // Nothing else but the edges between the blocks (a pixel column or two).
  EXPECT_GT(n_mould + n_die + n_white, fb.rgba.size() - 3 * 120u);
}

TEST_F(TranslucentCli, TranslucentIsosurfacesAreDrawn) {
  const auto png = dir_ / "iso.png";
  std::string log;
  ASSERT_EQ(foxi("--field temperature --iso 40,70 --iso-opacity 0.5 --legend off --size 160x120 -o '" +
                     png.string() + "'",
                 &log),
            0)
      << log;
  EXPECT_NE(log.find("isosurfaces opacity 0.5"), std::string::npos) << log;  // (display units: °C)
  const Framebuffer fb = read_png(png);
  std::size_t drawn = 0;
  for (std::uint32_t p : fb.rgba) drawn += (p & 0xffffffu) != 0xffffffu;
  EXPECT_GT(drawn, 500u);
}

TEST_F(TranslucentCli, VolumeOfALinearFieldIsHalfItsColourOverWhite) {
  const auto png = dir_ / "vol.png";
  std::string log;
  // The slab is 1 thick in z; opacity 0.5 per 1 world unit at every value: each ray gains exactly 0.5.
  ASSERT_EQ(foxi("--volume temperature --opacity-curve 0:0.5 --opacity-length 1 --legend off --dir 0,0,-1 "
                 "--up 0,1,0 "
                 "--size 180x120 -o '" +
                     png.string() + "'",
                 &log),
            0)
      << log;
  EXPECT_NE(log.find("composited back to front in the power order"), std::string::npos) << log;
  const Framebuffer fb = read_png(png);
  // The GNU spelling --name=value is the same options (it once read as none of them).
  const auto eq = dir_ / "eq.png";
  ASSERT_EQ(foxi("--volume=temperature --opacity-curve=0:0.5 --opacity-length=1 --legend=off --dir=0,0,-1 "
                 "--up=0,1,0 --size=180x120 -o '" +
                     eq.string() + "'",
                 &log),
            0)
      << log;
  EXPECT_EQ(read_png(eq).rgba, fb.rgba);
  // Unblended: u = 2 p - 255 must be an entry of viridis (to rounding); the image centre (x = 4.5,
  // 345 K on the data range 300..390 K) entry 128.
  auto distance_to_entry = [](const double u[3], int e) {
    const std::uint32_t c = color_map_entry(ColorMapId::viridis, e);
    double d = 0;
    for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(u[k] - double((c >> (8 * k)) & 255u)));
    return d;
  };
  std::size_t covered = 0, off_map = 0;
  for (std::size_t p = 0; p < fb.rgba.size(); ++p) {
    if ((fb.rgba[p] & 0xffffffu) == 0xffffffu) continue;
    ++covered;
    double u[3];
    for (int k = 0; k < 3; ++k) u[k] = 2.0 * double((fb.rgba[p] >> (8 * k)) & 255u) - 255;
    double best = 1e9;
    for (int e = 0; e < 256; ++e) best = std::min(best, distance_to_entry(u, e));
    off_map += best > 3;
  }
  EXPECT_GT(covered, 180u * 120u / 3);
  EXPECT_LE(off_map, covered / 100) << "pixels not half a viridis colour over white (the slab's edges)";
  const std::uint32_t centre = fb.rgba[fb.index(90, 60)];
  double u[3];
  for (int k = 0; k < 3; ++k) u[k] = 2.0 * double((centre >> (8 * k)) & 255u) - 255;
  double best = 1e9;
  for (int e = 124; e <= 132; ++e) best = std::min(best, distance_to_entry(u, e));
  EXPECT_LE(best, 3.0);
}

TEST_F(TranslucentCli, BadOptionsExitWithUsage) {
  const std::string out = " -o '" + (dir_ / "bad.png").string() + "'";
  std::string log;
  EXPECT_EQ(foxi("--region-opacity nosuch=0.5" + out, &log), 2);
  EXPECT_NE(log.find("no region 'nosuch'"), std::string::npos) << log;
  EXPECT_EQ(foxi("--region-opacity die=1.5" + out, &log), 2);
  EXPECT_NE(log.find("opacity from 0"), std::string::npos) << log;
  EXPECT_EQ(foxi("--region-opacity die" + out, &log), 2);
  EXPECT_EQ(foxi("--region-opacity die=0.5,die=0.2" + out, &log), 2);
  EXPECT_EQ(foxi("--iso-opacity 0.5" + out, &log), 2);
  EXPECT_NE(log.find("give --iso"), std::string::npos) << log;
  EXPECT_EQ(foxi("--region-opacity die=0.5 --stop 50%" + out, &log), 2);
  EXPECT_EQ(foxi("--region-opacity die=0.5 --shrink 0.8" + out, &log), 2);
  EXPECT_EQ(foxi("--region-opacity die=0.5 --field temperature" + out, &log), 2);
  EXPECT_NE(log.find("--field serves only --iso"), std::string::npos) << log;
  EXPECT_EQ(foxi("--volume temperature" + out, &log), 2);
  EXPECT_EQ(foxi("--volume temperature --opacity-curve 1:0.5,0:0.2" + out, &log), 2);
  EXPECT_EQ(foxi("--volume temperature --opacity-curve 0:1" + out, &log), 2);
  EXPECT_EQ(foxi("--volume temperature --opacity-curve 0:0.5 --iso 40" + out, &log), 2);
  EXPECT_EQ(foxi("--volume temperature --field temperature --opacity-curve 0:0.5" + out, &log), 2);
  // Given twice, empty, or naming what is not there: each refused with its reason (a second
  // --volume once read as an unknown option, an empty value as the option left out, and region
  // 4294967297 as region 1 after a cast).
  EXPECT_EQ(foxi("--volume temperature --volume temperature --opacity-curve 0:0.5" + out, &log), 2);
  EXPECT_NE(log.find("--volume given twice"), std::string::npos) << log;
  EXPECT_EQ(foxi("--volume '' --opacity-curve 0:0.5" + out, &log), 2);
  EXPECT_NE(log.find("--volume takes a value, not an empty one"), std::string::npos) << log;
  EXPECT_EQ(foxi("--volume temperature --opacity-curve ''" + out, &log), 2);
  EXPECT_NE(log.find("--opacity-curve takes a value"), std::string::npos) << log;
  EXPECT_EQ(foxi("--volume temperature: --opacity-curve 0:0.5" + out, &log), 2);
  EXPECT_NE(log.find("no component after the colon"), std::string::npos) << log;
  EXPECT_EQ(foxi("--region-opacity 4294967297=0.5" + out, &log), 2);
  EXPECT_NE(log.find("no region '4294967297'"), std::string::npos) << log;
  EXPECT_EQ(foxi("--region-opacity 7=0.5" + out, &log), 2);
  EXPECT_NE(log.find("its tets' regions: 1 (mould), 2 (die), 3 (substrate)"), std::string::npos) << log;
  EXPECT_EQ(foxi("--field temperature --iso 304 --iso-opacity 0" + out, &log), 2);
  EXPECT_NE(log.find("invisible"), std::string::npos) << log;
  // Values that meet in SI, or span more than a double: said so, exit 2 (once a crash, exit 139).
  EXPECT_EQ(foxi("--volume temperature --opacity-curve 30:0,30.00000000000001:0.5" + out, &log), 2);
  EXPECT_NE(log.find("the same in SI"), std::string::npos) << log;
  EXPECT_EQ(foxi("--volume temperature --opacity-curve -1e308:0.1,1e308:0.5" + out, &log), 2);
  EXPECT_NE(log.find("give a span between"), std::string::npos) << log;
  EXPECT_EQ(foxi("--volume temperature --units K --opacity-curve 0:0,3e-310:0.5" + out, &log), 2);
  EXPECT_EQ(foxi("--field temperature --range 1e-300,2e-300" + out, &log), 2);
  EXPECT_NE(log.find("no range"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bad.png"));
}

// A volume's automatic colour range is its corner values' (what it shows between the nodes), not
// the tets' centroid values': a single tet with 0, 1, 2 and 3 at its corners is coloured 0 to 3
// (its centroid's 1.5 was widened to 1.485 to 1.515, a hard split of two colours). Its NaN and
// infinite corner values are counted and said.
TEST(VolumeCli, AutomaticRangeIsTheCornersAndNoValuesAreSaid) {
  test::TempDir dir;
  Mesh one;
  one.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  one.tet = {0, 1, 2, 3};
  one.tet_region = {1};
  one.fields = {Field{"T", FieldLocation::node, 1, "", {}, {0, 1, 2, 3}}};
  write_mesh(one, dir / "one.vtu");
  std::string log;
  const std::string run = "'" + test::cli_path() + "' render '" + (dir / "one.vtu").string() + "' ";
  ASSERT_EQ(test::run(run + "--volume T --opacity-curve 0:0.1,3:0.5 -o '" + (dir / "v.png").string() + "'",
                      dir / "log.txt"),
            0);
  log = test::read_text(dir / "log.txt");
  EXPECT_NE(log.find("colours 0 to 3"), std::string::npos) << log;
  EXPECT_EQ(log.find("NaN"), std::string::npos) << log;
  EXPECT_EQ(log.find("wholly"), std::string::npos) << log;
  // A curve beside the values (another unit's numbers): said.
  ASSERT_EQ(
      test::run(run + "--volume T --opacity-curve 300:0.1,400:0.5 -o '" + (dir / "w.png").string() + "'",
                dir / "log.txt"),
      0);
  log = test::read_text(dir / "log.txt");
  EXPECT_NE(log.find("lies wholly above the field's values (0 to 3"), std::string::npos) << log;
  EXPECT_EQ(log.find("blank"), std::string::npos) << log;
  // A curve of opacity 0, every region at opacity 0: blank pictures are said (an outside probe).
  ASSERT_EQ(test::run(run + "--volume T --opacity-curve 0:0,3:0 -o '" + (dir / "z.png").string() + "'",
                      dir / "log.txt"),
            0);
  EXPECT_NE(test::read_text(dir / "log.txt").find("warning     the picture is blank"), std::string::npos);
  ASSERT_EQ(test::run(run + "--region-opacity 1=0 -o '" + (dir / "z.png").string() + "'", dir / "log.txt"),
            0);
  EXPECT_NE(test::read_text(dir / "log.txt").find("warning     the picture is blank"), std::string::npos);
  // Translucent isosurfaces too: their colours and the legend reach the corners' values.
  ASSERT_EQ(test::run(run + "--region-opacity 1=0.2 --field T --iso 0.5,2.5 --iso-opacity 0.5 -o '" +
                          (dir / "i.png").string() + "'",
                      dir / "log.txt"),
            0);
  Mesh holes = one;
  holes.fields[0].values = {0, std::nan(""), 2, std::numeric_limits<double>::infinity()};
  write_mesh(holes, dir / "holes.vtu");
  ASSERT_EQ(test::run("'" + test::cli_path() + "' render '" + (dir / "holes.vtu").string() +
                          "' --volume T --opacity-curve 0:0.1,3:0.5 -o '" + (dir / "h.png").string() + "'",
                      dir / "log.txt"),
            0);
  log = test::read_text(dir / "log.txt");
  EXPECT_NE(log.find("2 corner values are NaN or infinite"), std::string::npos) << log;
}

}  // namespace
}  // namespace foxi
