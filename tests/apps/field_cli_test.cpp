// foxi render / movie --field and foxi info's field ranges, end to end: a linear field seen from
// above reads back, pixel by pixel, as entries growing with x from the map's first to its last; the
// legend panel holds the whole map; usage errors exit 2 with the reason; foxi info prints the range.
#include <gtest/gtest.h>

#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

class FieldCli : public ::testing::Test {
 protected:
  void SetUp() override {
    Mesh m = test::grid_mesh(8, 4, 2, 1, 1, 1, 6);
    test::regions_along_x(m, 3, 6);
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    for (std::size_t n = 0; n < m.node_count(); ++n)
      t.values.push_back(300 + 10 * m.xyz[3 * n]);  // 300..380 K
    Field s{"stress", FieldLocation::cell, 6, "Pa", {}, {}};
    for (std::size_t e = 0; e < m.tet_count(); ++e)
      for (double v : {-1e6, 0.0, 0.0, 0.0, 0.0, 0.0}) s.values.push_back(v);
    Field u{"u", FieldLocation::node, 1, "m", {}, {}};
    for (std::size_t n = 0; n < m.node_count(); ++n)
      u.values.push_back((m.xyz[3 * n] - 2) * 1e-6);   // -2..6 um
    Field q{"q", FieldLocation::node, 1, "", {}, {}};  // largest on the top face's x = 8 edge
    for (std::size_t n = 0; n < m.node_count(); ++n)
      q.values.push_back(m.xyz[3 * n] + 0.1 * m.xyz[3 * n + 2]);
    m.fields = {t, s, u, q};
    mesh_ = dir_ / "grid.vtu";
    write_mesh(m, mesh_);
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run("'" + test::cli_path() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  // The entries of viridis pixel p could show, shaded in [0.75, 1].
  static std::vector<int> decode(std::uint32_t p) {
    std::vector<int> out;
    for (int i = 0; i < 256; ++i) {
      const std::uint32_t c = color_map_entry(ColorMapId::viridis, i);
      double lo = 0.75, hi = 1;
      for (int k = 0; k < 3; ++k) {
        const double pc = double((p >> (8 * k)) & 255u), cc = double((c >> (8 * k)) & 255u);
        lo = std::max(lo, (pc - 0.5001) / cc);
        hi = std::min(hi, (pc + 0.5001) / cc);
      }
      if (lo <= hi) out.push_back(i);
    }
    return out;
  }
  test::TempDir dir_;
  std::filesystem::path mesh_;
};

TEST_F(FieldCli, GradedLinearFieldReadsBackAlongTheRow) {
  const auto png = dir_ / "t.png";
  std::string log;
  ASSERT_EQ(foxi("render '" + mesh_.string() +
                     "' --field temperature --graded --no-edges --dir 0,0,-1 --up 0,1,0 "
                     "--size 640x320 -o '" +
                     png.string() + "'",
                 &log),
            0)
      << log;
  EXPECT_NE(log.find("graded facets"), std::string::npos) << log;
  EXPECT_NE(log.find("26.85 to 106.85 °C"), std::string::npos) << log;  // 300..380 K in °C
  const Framebuffer fb = read_png(png);
  ASSERT_EQ(fb.width, 640);
  ASSERT_EQ(fb.height, 320);
  // The middle row: from the mesh's left end to its right end the entries grow from 0 to 255.
  const int y = fb.height / 2;
  const std::uint32_t white = pack_rgba(255, 255, 255);
  int first = -1, last = -1, previous = -1;
  for (int x = 0; x < fb.width; ++x) {
    const std::uint32_t p = fb.rgba[fb.index(x, y)];
    if (p == white) {
      if (first >= 0) break;  // past the mesh: the gap before the legend
      continue;
    }
    const std::vector<int> can = decode(p);
    ASSERT_FALSE(can.empty()) << "pixel " << x << " is not a shaded viridis colour";
    if (first < 0) first = can.front();
    EXPECT_GE(can.back(), previous - 2) << "pixel " << x;  // never back down (8-bit ties allowed)
    previous = can.front();
    last = can.back();
  }
  EXPECT_LE(first, 3);
  EXPECT_GE(last, 252);
}

TEST_F(FieldCli, DivergingMapCentresSignedValuesOnZero) {
  const auto png = dir_ / "u.png";
  std::string log;
  ASSERT_EQ(
      foxi("render '" + mesh_.string() + "' --field u --graded --cmap coolwarm -o '" + png.string() + "'",
           &log),
      0);
  EXPECT_NE(log.find("values -2 to 6 µm, colours -6 to 6 µm (symmetric about 0"), std::string::npos) << log;
  ASSERT_EQ(foxi("render '" + mesh_.string() + "' --field u --graded -o '" + png.string() + "'", &log), 0);
  EXPECT_NE(log.find("colours -2 to 6 µm\n"), std::string::npos) << log;  // viridis: the values' range
}

// --markers: seen from above, the maximum (on the top face) is marked near the right end of the mesh,
// the minimum (on the bottom face) is hidden and said to be.
TEST_F(FieldCli, MarkersShowTheVisibleExtremes) {
  const auto png = dir_ / "q.png";
  std::string log;
  ASSERT_EQ(foxi("render '" + mesh_.string() +
                     "' --field q --graded --markers --no-edges --legend off --dir 0,0,-1 "
                     "--up 0,1,0 --size 640x320 -o '" +
                     png.string() + "'",
                 &log),
            0)
      << log;
  EXPECT_NE(log.find("markers     max 8.2 at (8, "), std::string::npos) << log;
  EXPECT_NE(log.find(", 2) marked; min 0 at (0, "), std::string::npos) << log;
  EXPECT_NE(log.find(", 0) hidden in this view"), std::string::npos) << log;
  // Black pixels (the ring and its label; no edges, no legend) only in the right part of the picture.
  const Framebuffer fb = read_png(png);
  int black = 0, left = 0;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if (fb.rgba[fb.index(x, y)] == pack_rgba(0, 0, 0)) {
        ++black;
        left += x < fb.width / 2;
      }
  EXPECT_GT(black, 20);
  EXPECT_EQ(left, 0);
  EXPECT_EQ(
      foxi("movie '" + mesh_.string() + "' --field q --markers -o '" + (dir_ / "m.gif").string() + "'", &log),
      2);
}

TEST_F(FieldCli, LegendPanelHoldsTheWholeMap) {
  const auto png = dir_ / "t.png";
  ASSERT_EQ(foxi("render '" + mesh_.string() + "' --field temperature --cmap coolwarm --size 640x400 -o '" +
                 png.string() + "'"),
            0);
  const Framebuffer fb = read_png(png);
  // Some column on the right holds the first and the last entry of the map (the bar's ends).
  bool found = false;
  for (int x = fb.width - 1; x > fb.width / 2 && !found; --x) {
    bool low = false, high = false;
    for (int y = 0; y < fb.height; ++y) {
      low = low || fb.rgba[fb.index(x, y)] == color_map_entry(ColorMapId::coolwarm, 0);
      high = high || fb.rgba[fb.index(x, y)] == color_map_entry(ColorMapId::coolwarm, 255);
    }
    found = low && high;
  }
  EXPECT_TRUE(found);
  // --legend off: no bar.
  ASSERT_EQ(
      foxi("render '" + mesh_.string() +
           "' --field temperature --cmap coolwarm --legend off --size 640x400 -o '" + png.string() + "'"),
      0);
  const Framebuffer plain = read_png(png);
  int bar = 0;
  for (std::uint32_t p : plain.rgba) bar += p == color_map_entry(ColorMapId::coolwarm, 255);
  EXPECT_EQ(bar, 0);
}

TEST_F(FieldCli, UsageErrorsSayWhatIsWrong) {
  const std::string m = "'" + mesh_.string() + "'", o = " -o '" + (dir_ / "x.png").string() + "'";
  std::string log;
  EXPECT_EQ(foxi("render " + m + " --field pressure" + o, &log), 2);
  EXPECT_NE(log.find("it has: temperature, u, q, stress"), std::string::npos)
      << log;  // the .vtu lists node fields first
  EXPECT_EQ(foxi("render " + m + " --field temperature --cmap jet" + o, &log), 2);
  EXPECT_NE(log.find("viridis, cividis, coolwarm or rainbow"), std::string::npos) << log;
  EXPECT_EQ(foxi("render " + m + " --graded" + o, &log), 2);
  EXPECT_EQ(foxi("render " + m + " --field temperature --range 5,1" + o, &log), 2);
  EXPECT_EQ(foxi("render " + m + " --field temperature --units MPa" + o, &log), 2);
  EXPECT_NE(log.find("does not apply"), std::string::npos) << log;
  EXPECT_EQ(foxi("render " + m + " --field stress:xx --log" + o, &log), 2);  // all -1 MPa
  EXPECT_NE(log.find("positive"), std::string::npos) << log;
  EXPECT_EQ(foxi("render " + m + " --field temperature --step 3" + o, &log), 2);
  EXPECT_EQ(foxi("render " + m + " --field temperature --size 100x100" + o, &log), 2);
  EXPECT_NE(log.find("legend"), std::string::npos) << log;
  EXPECT_EQ(foxi("render " + m + " --field temperature --size 600x60" + o, &log), 2);  // too low for a bar
  EXPECT_NE(log.find("legend"), std::string::npos) << log;
  EXPECT_EQ(foxi("render " + m + " --field temperature --legend off --size 600x60" + o, &log), 0) << log;
  std::filesystem::remove(dir_ / "x.png");
  EXPECT_EQ(
      foxi("movie " + m + " --field temperature --graded --range 1 -o '" + (dir_ / "m.gif").string() + "'",
           &log),
      2);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.png"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "m.gif"));
}

TEST_F(FieldCli, InfoPrintsEachFieldsRange) {
  std::string log;
  ASSERT_EQ(foxi("info '" + mesh_.string() + "'", &log), 0);
  EXPECT_NE(log.find("value 300 to 380 K (26.85 to 106.85 °C)"), std::string::npos) << log;
  EXPECT_NE(log.find("von Mises 1e+06 to 1e+06 Pa (1 to 1 MPa)"), std::string::npos) << log;
  ASSERT_EQ(foxi("info --json '" + mesh_.string() + "'", &log), 0);
  EXPECT_NE(log.find("\"scalar\": \"value\", \"min\": 300, \"max\": 380"), std::string::npos) << log;
  // A cell field with a node field's name shows its own range (it showed the node field's; an outside
  // probe).
  Mesh m = read_mesh(mesh_);
  Field cell{"temperature", FieldLocation::cell, 1, "K", {}, std::vector<double>(m.tet_count(), 500.0)};
  cell.values[0] = 450;
  m.fields.push_back(cell);
  write_mesh(m, dir_ / "twin.vtu");
  ASSERT_EQ(foxi("info '" + (dir_ / "twin.vtu").string() + "'", &log), 0);
  EXPECT_NE(log.find("value 300 to 380 K"), std::string::npos) << log;
  EXPECT_NE(log.find("value 450 to 500 K"), std::string::npos) << log;
}

TEST_F(FieldCli, MovieWithAFieldKeepsOneRange) {
  const auto out = dir_ / "f_%02d.png";
  std::string log;
  ASSERT_EQ(foxi("movie '" + mesh_.string() + "' --field temperature --frames 4 --size 400x240 -o '" +
                     out.string() + "'",
                 &log),
            0)
      << log;
  // Flat: the tets' centroid values, x from 0.25 to 7.75: 302.5 to 377.5 K.
  EXPECT_NE(log.find("colours 29.35 to 104.35 °C in every frame"), std::string::npos) << log;
  for (int k = 0; k < 4; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "f_%02d.png", k);
    const Framebuffer fb = read_png(dir_ / name);
    EXPECT_EQ(fb.width, 400);
    EXPECT_EQ(fb.height, 240);
  }
  ASSERT_EQ(foxi("movie '" + mesh_.string() +
                     "' --field temperature --graded --mode rotate --frames 3 --size 400x240 -o '" +
                     (dir_ / "r.gif").string() + "'",
                 &log),
            0)
      << log;
  ASSERT_EQ(
      foxi("movie '" + mesh_.string() + "' --field temperature --graded --frames 4 --size 400x240 -o '" +
               (dir_ / "g_%02d.png").string() + "'",
           &log),
      0)
      << log;
  // Back and forth: the frame at the high point (all tets) is foxi render's graded picture.
  ASSERT_EQ(foxi("render '" + mesh_.string() + "' --field temperature --graded --size 400x240 -o '" +
                     (dir_ / "all.png").string() + "'",
                 &log),
            0)
      << log;
  EXPECT_EQ(read_png(dir_ / "g_02.png").rgba, read_png(dir_ / "all.png").rgba);
}

// The von Mises stress foxi colours by (from the stress tensor) against the one the thermoelastic
// solver writes itself (another code path: the solver's own von_mises field), tet by tet, and the
// principal values against the solver's principal_stress.
TEST_F(FieldCli, VonMisesAndPrincipalValuesEqualTheSolversOwn) {
  const auto vtu = dir_ / "te.vtu";
  std::string log;
  ASSERT_EQ(foxi("solve '" + test::models_dir() + "die_on_substrate.toml' --physics thermoelastic -o '" +
                     vtu.string() + "'",
                 &log),
            0)
      << log;
  const Mesh m = read_mesh(vtu);
  const std::vector<double> ours = field_scalar_values(m, choose_field(m, "stress"));
  const std::vector<double> solver = field_scalar_values(m, choose_field(m, "von_mises"));
  ASSERT_EQ(ours.size(), solver.size());
  ASSERT_GT(ours.size(), 1000u);
  for (std::size_t t = 0; t < ours.size(); ++t)
    EXPECT_NEAR(ours[t], solver[t], 1e-9 * solver[t] + 1e-6) << "tet " << t;
  // The principal values (Smith's closed form here, Eigen's eigensolver in the solver), largest first.
  const Field* principal = m.find_field("principal_stress");
  ASSERT_NE(principal, nullptr);
  for (int k = 0; k < 3; ++k) {
    const std::vector<double> p =
        field_scalar_values(m, choose_field(m, std::string("stress:p") + char('1' + k)));
    for (std::size_t t = 0; t < p.size(); ++t)
      EXPECT_NEAR(p[t], principal->values[3 * t + std::size_t(k)], 1e-7 * solver[t] + 1e-3)
          << "tet " << t << " p" << k + 1;
  }
}

}  // namespace
}  // namespace foxi
