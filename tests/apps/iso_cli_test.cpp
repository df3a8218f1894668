// foxi render --iso / --iso-only / --threshold / --clip / --slice end to end, on a grid whose temperature
// is linear in x (300 + 10 x K): the isotherms are the planes x = const, so seen along x the nearest one
// fills the view in its value's colour, the hot side (brighter) from +x and the cold side (darker) from
// -x; the printed counts equal the library's selections computed here (crossing_scan, threshold_tets,
// clip_tets); malformed options exit 2 with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <regex>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/field_subset.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

class IsoCli : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh = test::grid_mesh(8, 4, 3, 1, 1, 1, 6);
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    for (std::size_t n = 0; n < mesh.node_count(); ++n)
      t.values.push_back(300 + 10 * mesh.xyz[3 * n]);  // 300..380 K
    mesh.fields = {t};
    path_ = dir_ / "grid.vtu";
    write_mesh(mesh, path_);
    for (std::size_t i = 0; i < mesh.tet.size(); ++i) corner.push_back(300 + 10 * mesh.xyz[3 * mesh.tet[i]]);
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status =
        test::run("'" + test::cli_path() + "' render '" + path_.string() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  // "drawn N of M tets": N.
  static std::size_t drawn(const std::string& log) {
    std::smatch m;
    if (!std::regex_search(log, m, std::regex("drawn +([0-9]+) of"))) return std::size_t(-1);
    return std::stoul(m[1]);
  }
  // Whether pixel p is colour c scaled by some factor in [lo, hi], each channel rounded.
  static bool scaled_from(std::uint32_t p, std::uint32_t c, double lo, double hi) {
    for (int k = 0; k < 3; ++k) {
      const double pc = double((p >> (8 * k)) & 255u), cc = double((c >> (8 * k)) & 255u);
      if (cc == 0) {
        if (pc != 0) return false;
        continue;
      }
      lo = std::max(lo, (pc - 0.5001) / cc);
      hi = std::min(hi, (pc + 0.5001) / cc);
    }
    return lo <= hi;
  }
  Mesh mesh;
  std::vector<double> corner;
  test::TempDir dir_;
  std::filesystem::path path_;
};

TEST_F(IsoCli, IsothermsSeenAlongTheGradientShowTheNearestValueHotOrCold) {
  ColorScale scale;  // --range 20,110 (°C)
  scale.lo = 293.15;
  scale.hi = 383.15;
  for (int from_hot = 0; from_hot < 2; ++from_hot) {
    const auto png = dir_ / "iso.png";
    std::string log;
    // 50 and 80 °C: the planes x = 2.315 and x = 5.315.
    ASSERT_EQ(
        foxi("--field temperature --iso 50,80 --iso-only --range 20,110 --legend off --size 200x160 --dir " +
                 std::string(from_hot ? "-1,0,0" : "1,0,0") + " -o '" + png.string() + "'",
             &log),
        0)
        << log;
    std::size_t want = 0;  // tets crossed by either value
    {
      std::vector<std::uint32_t> any;
      TetIntervals(corner).crossing_any(std::vector<double>{323.15, 353.15}, any);
      want = crossing_scan(corner, 323.15).size() + crossing_scan(corner, 353.15).size();
      EXPECT_EQ(any.size(), want);  // the planes are a grid cell apart: no tet crosses both
    }
    EXPECT_NE(log.find(std::to_string(want) + " tets crossed"), std::string::npos) << log;
    EXPECT_EQ(drawn(log), want) << log;
    const Framebuffer fb = read_png(png);
    // Seen from +x (looking along -x) the nearest plane is 80 °C, its hot side; from -x, 50 °C, cold.
    const std::uint32_t colour = scale.color(from_hot ? 353.15 : 323.15);
    std::size_t covered = 0, right = 0;
    for (std::uint32_t p : fb.rgba) {
      if (p == pack_rgba(255, 255, 255)) continue;
      ++covered;
      right += from_hot ? scaled_from(p, colour, 0.75, 1) : scaled_from(p, colour, 0.55 * 0.75, 0.55);
    }
    EXPECT_GT(covered, 5000u);
    EXPECT_EQ(right, covered) << (from_hot ? "hot side" : "cold side") << log << " pixel " << std::hex
                              << fb.rgba[fb.index(100, 80)] << " colour " << colour;
  }
}

TEST_F(IsoCli, CountsEqualTheLibrarysSelections) {
  const std::string o = " -o '" + (dir_ / "o.png").string() + "'";
  std::string log;
  // Cap: the tets reaching 50 °C.
  ASSERT_EQ(foxi("--field temperature --graded --iso 50" + o, &log), 0) << log;
  std::vector<std::uint32_t> reach;
  TetIntervals(corner).reaching(323.15, reach);
  EXPECT_EQ(drawn(log), reach.size()) << log;
  EXPECT_NE(log.find("solid above the lowest value"), std::string::npos) << log;
  // Threshold on the centroid values, in °C.
  ASSERT_EQ(foxi("--field temperature --threshold 50,80" + o, &log), 0) << log;
  std::vector<double> centroid(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    centroid[t] = 0.25 * (corner[4 * t] + corner[4 * t + 1] + corner[4 * t + 2] + corner[4 * t + 3]);
  EXPECT_EQ(drawn(log), threshold_tets(centroid, 323.15, 353.15).size()) << log;
  // Clip and slice.
  Plane pl;
  pl.p[0] = 3.3, pl.p[1] = 2, pl.p[2] = 1;
  pl.n[0] = 1, pl.n[1] = 0.5, pl.n[2] = 0.2;
  ASSERT_EQ(foxi("--field temperature --clip 3.3,2,1,1,0.5,0.2" + o, &log), 0) << log;
  EXPECT_EQ(drawn(log), clip_tets(mesh, pl).size()) << log;
  ASSERT_EQ(foxi("--field temperature --slice 3.3,2,1,1,0.5,0.2" + o, &log), 0) << log;
  EXPECT_EQ(drawn(log), crossing_scan(plane_corner_values(mesh, pl), 0).size()) << log;
  // Clip and threshold together: both.
  ASSERT_EQ(foxi("--field temperature --clip 3.3,2,1,1,0.5,0.2 --threshold 50,80" + o, &log), 0) << log;
  const std::vector<std::uint32_t> th = threshold_tets(centroid, 323.15, 353.15);
  EXPECT_EQ(drawn(log), clip_tets(mesh, pl, th).size()) << log;
  // A slice combines with a threshold and a clip (issue 17 item 4): the plane's cut through the tets
  // both keep, and the painter's picture is the depth buffer's.
  Plane pl2;
  pl2.p[0] = 5, pl2.p[1] = 2, pl2.p[2] = 1.5;
  pl2.n[0] = 0.3, pl2.n[1] = 1, pl2.n[2] = -0.2;
  const std::string slice2 = " --size 320x240 --legend off --slice 5,2,1.5,0.3,1,-0.2";
  const std::vector<std::uint32_t> cut2 = crossing_scan(plane_corner_values(mesh, pl2), 0);
  const std::vector<std::uint32_t> both = clip_tets(mesh, pl, th);
  for (const auto& [opts, keep] :
       {std::pair{std::string(" --threshold 50,80"), th},
        std::pair{std::string(" --clip 3.3,2,1,1,0.5,0.2"), clip_tets(mesh, pl)},
        std::pair{std::string(" --clip 3.3,2,1,1,0.5,0.2 --threshold 50,80"), both}}) {
    SCOPED_TRACE(opts);
    std::vector<std::uint32_t> expected;
    std::vector<std::uint32_t> k = keep;
    std::sort(k.begin(), k.end());
    for (std::uint32_t t : cut2)
      if (std::binary_search(k.begin(), k.end(), t)) expected.push_back(t);
    ASSERT_GT(expected.size(), 5u);
    ASSERT_LT(expected.size(), cut2.size());
    const std::string po = " -o '" + (dir_ / "p.png").string() + "'",
                      zo = " -o '" + (dir_ / "z.png").string() + "'";
    ASSERT_EQ(foxi("--field temperature --no-edges" + slice2 + opts + po, &log), 0) << log;
    EXPECT_EQ(drawn(log), expected.size()) << log;
    EXPECT_NE(log.find(std::to_string(expected.size()) + " tets cut"), std::string::npos) << log;
    ASSERT_EQ(foxi("--field temperature --no-edges --zbuffer" + slice2 + opts + zo, &log), 0) << log;
    const Framebuffer a = read_png(dir_ / "p.png"), b = read_png(dir_ / "z.png");
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    std::size_t differ = 0, coloured = 0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i) {
      differ += (a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu);
      coloured += (a.rgba[i] & 0xFFFFFFu) != 0xFFFFFFu;
    }
    EXPECT_EQ(differ, 0u) << "painter == depth buffer";
    EXPECT_GT(coloured, 300u);
  }
  // An isovalue outside the data crosses nothing: an empty picture, not the whole mesh, and a warning
  // with the field's range (300..380 K) says why (issue 17 item 6).
  ASSERT_EQ(foxi("--field temperature --iso 500 --iso-only" + o, &log), 0) << log;
  EXPECT_EQ(drawn(log), 0u) << log;
  EXPECT_NE(log.find("warning     --iso 500 °C lies outside the field's values 26.85 to 106.85 °C"),
            std::string::npos)
      << log;
  ASSERT_EQ(foxi("--field temperature --iso 20,50,120" + o, &log), 0) << log;
  EXPECT_NE(log.find("warning     --iso 20, 120 °C lies outside"), std::string::npos) << log;
  ASSERT_EQ(foxi("--field temperature --iso 50" + o, &log), 0) << log;
  EXPECT_EQ(log.find("warning"), std::string::npos) << log;
}

TEST_F(IsoCli, MalformedOptionsExit2WithTheReason) {
  const std::string o = " -o '" + (dir_ / "o.png").string() + "'";
  std::string log;
  EXPECT_EQ(foxi("--iso 50" + o, &log), 2);
  EXPECT_NE(log.find("give --field"), std::string::npos) << log;
  EXPECT_EQ(foxi("--field temperature --iso-only" + o, &log), 2);
  EXPECT_NE(log.find("give --iso"), std::string::npos) << log;
  EXPECT_EQ(foxi("--field temperature --iso 50,x" + o, &log), 2);
  EXPECT_EQ(foxi("--field temperature --clip 1,2,3,4,5" + o, &log), 2);
  EXPECT_NE(log.find("px,py,pz,nx,ny,nz"), std::string::npos) << log;
  EXPECT_EQ(foxi("--field temperature --slice 1,2,3,0,0,0" + o, &log), 2);
  EXPECT_NE(log.find("normal must not be zero"), std::string::npos) << log;
  EXPECT_EQ(foxi("--field temperature --threshold 80,50" + o, &log), 2);
  EXPECT_EQ(foxi("--field temperature --slice 1,2,3,0,0,1 --iso 50" + o, &log), 2);
  EXPECT_NE(log.find("both draw polygons"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "o.png"));
}

}  // namespace
}  // namespace foxi
