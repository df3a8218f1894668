// foxi movie --sweep end to end, each frame against the single-picture path as the second algorithm:
// frame k of an iso sweep equals foxi render --iso v_k (v_k = a + (b - a) k / (N - 1)), of a threshold
// sweep foxi render --threshold a,v_k, of a steps sweep foxi render --step k with the range fixed to the
// union over the steps (computed here from the library's tet values); the printed isovalues and the
// crossing counts equal a brute-force scan (crossing_scan); a .pvd collection's steps are the frames;
// bad combinations exit 2 with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <regex>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/legend.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

class MovieSweepCli : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh = test::grid_mesh(8, 4, 3, 1, 1, 1, 6);
    // Temperature 300 + 10 x + 4 y z K (curved isotherms); u: three steps, k (x + y) + z / 3, no unit.
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    Field u{"u", FieldLocation::node, 1, "", {0, 0.5, 1}, {}};
    for (std::size_t n = 0; n < mesh.node_count(); ++n) {
      const double x = mesh.xyz[3 * n], y = mesh.xyz[3 * n + 1], z = mesh.xyz[3 * n + 2];
      t.values.push_back(300 + 10 * x + 4 * y * z);
    }
    for (int k = 0; k < 3; ++k)
      for (std::size_t n = 0; n < mesh.node_count(); ++n)
        u.values.push_back(k * (mesh.xyz[3 * n] + mesh.xyz[3 * n + 1]) + mesh.xyz[3 * n + 2] / 3);
    mesh.fields = {t, u};
    write_mesh(mesh, dir_ / "grid.vtu");
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run("'" + test::cli_path() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  std::string p(const std::string& name) const { return "'" + (dir_ / name).string() + "'"; }
  Framebuffer frame(const std::string& dir, int k) const {
    return read_png(dir_ / dir / ("f_" + std::to_string(k) + ".png"));
  }
  static std::string exact(double v) {
    char b[64];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
  }
  Mesh mesh;
  test::TempDir dir_;
};

bool same_rgb(const Framebuffer& a, const Framebuffer& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (std::size_t i = 0; i < a.rgba.size(); ++i)
    if ((a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu)) return false;
  return true;
}

// A sweep frame's caption (issue 17 item 1: the step's time or the swept value at the top left), drawn
// on foxi render's picture of the same choice: what the frame must then equal, pixel for pixel. The
// expected text comes from the test's own values (the steps' times, the frame's isovalue), so a frame
// labelled with another step's time or value differs.
Framebuffer captioned(Framebuffer fb, const std::string& label) {
  static const TextRenderer text(find_font_file());
  const PixelRect ink = draw_caption(fb, text, label);
  if (!label.empty()) {
    EXPECT_LE(ink.x0, ink.x1) << "the caption '" << label << "' draws nothing";
  }
  return fb;
}

std::string caption(const char* fmt, double v) {
  char b[128];
  std::snprintf(b, sizeof b, fmt, v);
  return b;
}

// The mesh part (left of the legend) all white but for the caption.
bool blank(const Framebuffer& fb, int width, const std::string& label) {
  Framebuffer white(fb.width, fb.height);
  std::fill(white.rgba.begin(), white.rgba.end(), pack_rgba(255, 255, 255));
  const Framebuffer expected = captioned(white, label);
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < width; ++x)
      if ((fb.rgba[fb.index(x, y)] & 0xFFFFFFu) != (expected.rgba[fb.index(x, y)] & 0xFFFFFFu)) return false;
  return true;
}

TEST_F(MovieSweepCli, IsoSweepFramesEqualRenderAtEachValue) {
  // Isovalues 20..80 °C in 6 frames: 293.15..353.15 K, the first below every node (300 + ... >= 300 K,
  // so it crosses nothing and its solid is everything), the last inside.
  const double a = 20, b = 80;
  const int n = 6;
  std::vector<double> corner;
  for (std::uint32_t node : mesh.tet) corner.push_back(mesh.fields[0].values[node]);
  for (const char* extra : {"", " --iso-only", " --graded --cmap coolwarm"}) {
    SCOPED_TRACE(extra);
    const std::string common = p("grid.vtu") + " --field temperature --size 240x160" + std::string(extra);
    std::string out;
    ASSERT_EQ(foxi("movie " + common + " --sweep iso:20,80 --frames 6 -o " + p("iso/f_%d.png"), &out), 0)
        << out;
    EXPECT_NE(out.find("6 frames: 20, 32, 44, 56, 68, 80 °C"), std::string::npos) << out;
    std::size_t cmin = std::size_t(-1), cmax = 0;
    for (int k = 0; k < n; ++k) {
      const double v = k == n - 1 ? b : a + (b - a) * double(k) / double(n - 1);
      const std::size_t c = crossing_scan(corner, v + 273.15).size();
      cmin = std::min(cmin, c);
      cmax = std::max(cmax, c);
      std::string rlog;
      ASSERT_EQ(foxi("render " + common + " --iso " + exact(v) + " -o " + p("r.png"), &rlog), 0) << rlog;
      EXPECT_TRUE(same_rgb(frame("iso", k), captioned(read_png(dir_ / "r.png"), caption("iso %.6g °C", v))))
          << "frame " << k << " at " << v << " °C";
    }
    EXPECT_EQ(cmin, 0u) << "20 °C lies below every node";
    EXPECT_GT(cmax, 20u);
    EXPECT_NE(
        out.find("pruned      " + std::to_string(cmin) + " to " + std::to_string(cmax) + " tets crossed"),
        std::string::npos)
        << out;
    EXPECT_FALSE(same_rgb(frame("iso", 2), frame("iso", 3))) << "the isosurface moves";
  }
}

TEST_F(MovieSweepCli, ThresholdSweepFramesEqualRenderOfTheGrowingRange) {
  const std::string common = p("grid.vtu") + " --field temperature --size 200x150 --legend off";
  std::string out;
  ASSERT_EQ(foxi("movie " + common + " --sweep threshold:30,110 --frames 5 -o " + p("thr/f_%d.png"), &out), 0)
      << out;
  EXPECT_NE(out.find("threshold [30, v] of temperature, 5 frames, v = 30, 50, 70, 90, 110 °C"),
            std::string::npos)
      << out;
  for (int k = 0; k < 5; ++k) {
    ASSERT_EQ(
        foxi("render " + common + " --threshold 30," + std::to_string(30 + 20 * k) + " -o " + p("r.png"),
             &out),
        0)
        << out;
    EXPECT_TRUE(same_rgb(frame("thr", k), captioned(read_png(dir_ / "r.png"),
                                                    caption("threshold 30 to %.6g °C", 30 + 20 * k))))
        << "frame " << k;
  }
  EXPECT_TRUE(blank(frame("thr", 0), 200, "threshold 30 to 30 °C")) << "[30, 30] °C holds no tet's value";
  EXPECT_FALSE(blank(frame("thr", 1), 200, "threshold 30 to 50 °C"));
  // With --slice: the plane's section through each frame's threshold subset (issue 17 item 4).
  const std::string slice = " --slice 4,2,1.5,1,0.3,0.2";
  ASSERT_EQ(
      foxi("movie " + common + slice + " --sweep threshold:30,110 --frames 3 -o " + p("ths/f_%d.png"), &out),
      0)
      << out;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(foxi("render " + common + slice + " --threshold 30," + std::to_string(30 + 40 * k) + " -o " +
                       p("r.png"),
                   &out),
              0)
        << out;
    EXPECT_TRUE(same_rgb(frame("ths", k), captioned(read_png(dir_ / "r.png"),
                                                    caption("threshold 30 to %.6g °C", 30 + 40 * k))))
        << "frame " << k;
  }
  EXPECT_FALSE(same_rgb(frame("ths", 1), frame("thr", 2))) << "the slice, not the tets";
}

TEST_F(MovieSweepCli, StepsSweepKeepsOneRangeOverTheSteps) {
  // The range the movie must fix: the union of every step's values as drawn (flat: the tets' centroid
  // values).
  double lo = 1e300, hi = -1e300;
  const FieldChoice choice = choose_field(mesh, "u");
  for (std::size_t s = 0; s < 3; ++s)
    for (double v : tet_centroid_values(mesh, choice, s)) lo = std::min(lo, v), hi = std::max(hi, v);
  const std::string common = p("grid.vtu") + " --field u --size 240x160";
  std::string out;
  ASSERT_EQ(foxi("movie " + common + " --sweep steps -o " + p("st/f_%d.png"), &out), 0) << out;
  EXPECT_NE(out.find("steps of u, 3 frames, step values 0 to 1"), std::string::npos) << out;
  char range[128];
  std::snprintf(range, sizeof range, "colours %.6g to %.6g in every frame", lo, hi);
  EXPECT_NE(out.find(range), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "st/f_3.png"));
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(foxi("render " + common + " --step " + std::to_string(k) + " --range " + exact(lo) + "," +
                       exact(hi) + " -o " + p("r.png"),
                   &out),
              0)
        << out;
    // u's steps are at times 0, 0.5 and 1.
    EXPECT_TRUE(same_rgb(frame("st", k), captioned(read_png(dir_ / "r.png"), caption("t = %g s", 0.5 * k))))
        << "step " << k;
  }
  // The fixed range is the point: step 0 alone spans only z, so its own range colours it otherwise.
  ASSERT_EQ(foxi("render " + common + " --step 0 -o " + p("own.png"), &out), 0) << out;
  EXPECT_FALSE(same_rgb(frame("st", 0), read_png(dir_ / "own.png")));

  // With an isovalue every step: foxi render --step k --iso v; graded, the range is the nodes' values'.
  lo = 1e300, hi = -1e300;
  for (std::size_t s = 0; s < 3; ++s)
    for (double v : tet_corner_values(mesh, choice, s)) lo = std::min(lo, v), hi = std::max(hi, v);
  ASSERT_EQ(foxi("movie " + common + " --graded --iso 1.5 --sweep steps -o " + p("sti/f_%d.png"), &out), 0)
      << out;
  for (int k = 1; k < 3; ++k) {
    ASSERT_EQ(foxi("render " + common + " --graded --iso 1.5 --step " + std::to_string(k) + " --range " +
                       exact(lo) + "," + exact(hi) + " -o " + p("r.png"),
                   &out),
              0)
        << out;
    EXPECT_TRUE(same_rgb(frame("sti", k), captioned(read_png(dir_ / "r.png"), caption("t = %g s", 0.5 * k))))
        << "step " << k;
  }
  EXPECT_TRUE(blank(frame("sti", 0), 80, "t = 0 s")) << "step 0 (u = z / 3 <= 1) never reaches 1.5";
}

TEST_F(MovieSweepCli, PvdCollectionStepsAreTheFrames) {
  // The same three steps as a ParaView collection of one .vtu per step (as the transient writes them).
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (int k = 0; k < 3; ++k) {
    Mesh m = mesh;
    Field u = m.fields[1];
    u.step_values = {};
    u.values.assign(mesh.fields[1].values.begin() + std::ptrdiff_t(k * mesh.node_count()),
                    mesh.fields[1].values.begin() + std::ptrdiff_t((k + 1) * mesh.node_count()));
    m.fields = {u};
    write_mesh(m, dir_ / ("s_" + std::to_string(k) + ".vtu"));
    pvd += "<DataSet timestep=\"" + std::to_string(0.5 * k) + "\" part=\"0\" file=\"s_" + std::to_string(k) +
           ".vtu\"/>\n";
  }
  test::write_text(dir_ / "run.pvd", pvd + "</Collection>\n</VTKFile>\n");
  std::string out;
  ASSERT_EQ(
      foxi("movie " + p("run.pvd") + " --field u --size 240x160 --sweep steps -o " + p("pvd/f_%d.png"), &out),
      0)
      << out;
  ASSERT_EQ(foxi("movie " + p("grid.vtu") + " --field u --size 240x160 --sweep steps -o " + p("vtu/f_%d.png"),
                 &out),
            0)
      << out;
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(same_rgb(frame("pvd", k), frame("vtu", k))) << "step " << k;
}

// --threshold narrows the back-and-forth movie too: its high point is foxi render --threshold's picture;
// --deform with a sweep: each frame foxi render --deform --iso's (the deformed mesh drawn with the
// depth buffer), while the back-and-forth movie, which needs the visibility order, refuses it.
TEST_F(MovieSweepCli, ThresholdInBackAndForthAndDeformInSweeps) {
  const std::string common = p("grid.vtu") + " --field temperature --size 200x150 --legend off";
  std::string out;
  ASSERT_EQ(foxi("movie " + common + " --threshold 40,70 --frames 6 -o " + p("bf/f_%d.png"), &out), 0) << out;
  ASSERT_EQ(foxi("render " + common + " --threshold 40,70 -o " + p("r.png"), &out), 0) << out;
  EXPECT_TRUE(same_rgb(frame("bf", 3), read_png(dir_ / "r.png"))) << "no caption out of a sweep";
  EXPECT_TRUE(blank(frame("bf", 0), 200, ""));

  Mesh m = mesh;  // a shear: u = (0.05 z, 0, 0)
  Field d{"displacement", FieldLocation::node, 3, "m", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n)
    d.values.insert(d.values.end(), {0.05 * m.xyz[3 * n + 2], 0, 0});
  m.fields.push_back(d);
  write_mesh(m, dir_ / "d.vtu");
  const std::string dcommon =
      p("d.vtu") + " --field temperature --size 200x150 --legend off --deform displacement:2";
  ASSERT_EQ(foxi("movie " + dcommon + " --sweep iso:40,90 --frames 3 -o " + p("dv/f_%d.png"), &out), 0)
      << out;
  EXPECT_NE(out.find("with the depth buffer"), std::string::npos) << out;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(foxi("render " + dcommon + " --iso " + std::to_string(40 + 25 * k) + " -o " + p("r.png"), &out),
              0)
        << out;
    EXPECT_TRUE(
        same_rgb(frame("dv", k), captioned(read_png(dir_ / "r.png"), caption("iso %g °C", 40 + 25 * k))))
        << "frame " << k;
  }
  EXPECT_EQ(foxi("movie " + dcommon + " -o " + p("bfd.gif"), &out), 3) << out;
  EXPECT_NE(out.find("fails the Delaunay certificate"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bfd.gif"));
}

// The transient solver's own output: one frame per data set of its .pvd, each foxi render --step k
// of the same collection with the same --range.
TEST_F(MovieSweepCli, TransientPvdOutputSteps) {
  std::string out;
  ASSERT_EQ(foxi("solve '" + test::models_dir() +
                     "die_on_substrate.toml' --physics transient --time 1 --steps 4 -o " + p("run.pvd"),
                 &out),
            0)
      << out;
  const std::string common = p("run.pvd") + " --field temperature --graded --range 25,90 --size 240x160";
  ASSERT_EQ(foxi("movie " + common + " --sweep steps -o " + p("tr/f_%d.png"), &out), 0) << out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("steps of temperature, ([0-9]+) frames"))) << out;
  const int n = std::stoi(m[1]);
  EXPECT_EQ(n, 5) << "the start and 4 steps";
  for (int k = 0; k < n; ++k) {
    ASSERT_EQ(foxi("render " + common + " --step " + std::to_string(k) + " -o " + p("r.png"), &out), 0)
        << out;
    // --time 1 --steps 4: the start and four steps of 0.25 s.
    EXPECT_TRUE(same_rgb(frame("tr", k), captioned(read_png(dir_ / "r.png"), caption("t = %g s", 0.25 * k))))
        << "step " << k;
  }
  EXPECT_FALSE(same_rgb(frame("tr", 0), frame("tr", n - 1))) << "the die heats up";
}

TEST_F(MovieSweepCli, BadSweepsAreUsageErrors) {
  const std::string g = p("grid.vtu") + " ";
  const std::string o = " -o " + p("m.gif");
  std::string out;
  auto refused = [&](const std::string& args, const std::string& reason) {
    EXPECT_EQ(foxi("movie " + g + args + o, &out), 2) << args << "\n" << out;
    EXPECT_NE(out.find(reason), std::string::npos) << args << "\n" << out;
  };
  refused("--sweep iso:1,2", "give --field");
  refused("--field temperature --sweep spin", "--sweep takes iso:a,b");
  refused("--field temperature --sweep iso:1", "two different values");
  refused("--field temperature --sweep threshold:5,1", "a < b");
  refused("--field temperature --sweep iso:1,2 --iso 3", "leave out --iso");
  refused("--field temperature --sweep threshold:1,2 --threshold 0,3", "leave out --threshold");
  refused("--field temperature --sweep iso:1,2 --mode rotate", "in place of --mode");
  refused("--field u --sweep steps --frames 4", "leave out --frames");
  refused("--field u --sweep steps --step 1", "leave out --step");
  refused("--field temperature --sweep steps", "has one step");
  refused("--field temperature --iso 50", "--sweep iso:a,b");
  refused("--field temperature --sweep iso:1,2 --cycles 2", "belong to --mode");
  refused("--field temperature --threshold 500,600", "select no tets");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "m.gif"));
}

}  // namespace
}  // namespace foxi
