// foxi movie with translucency and volume rendering (issue 23 item 3), end to end, each frame against
// foxi render as the second path: a rotating x-ray movie's frame k equals foxi render with the camera
// turned by turn k / N (the turned camera computed here by the library's orbit and given to render as
// --eye/--at/--up, %.17g), a rotating volume movie likewise; --sweep opacity:a,b's frame k equals foxi
// render with every opacity multiplied by s_k (the products written out here, %.17g); a back-and-forth
// x-ray movie reaches foxi render's picture at its high point, and its frames coming down (the far
// part composited again from the back) equal the frames going up (composited incrementally) pixel for
// pixel; bad combinations exit 2 with the reason, a back-and-forth of an uncertified mesh 3.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

class MovieTranslucentCli : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh = test::grid_mesh(6, 4, 3, 1, 1, 1, 6);
    test::regions_along_x(mesh, 2, 4);
    mesh.regions = {{1, "mould", kNone}, {2, "die", kNone}, {3, "substrate", kNone}};
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    for (std::size_t n = 0; n < mesh.node_count(); ++n) {
      const double x = mesh.xyz[3 * n], y = mesh.xyz[3 * n + 1], z = mesh.xyz[3 * n + 2];
      t.values.push_back(300 + 6 * x + 4 * y * z);
    }
    mesh.fields = {t};
    write_mesh(mesh, dir_ / "pkg.vtu");
    camera.perspective = true;
    const double eye[3] = {-4, 9, 7}, at[3] = {3, 2, 1.5}, up[3] = {0, 0, 1};
    for (int k = 0; k < 3; ++k) camera.eye[k] = eye[k], camera.at[k] = at[k], camera.up[k] = up[k];
    camera.fov_deg = 40;
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
  static std::string camera_options(const Camera& c) {
    auto v = [](const double* x) { return exact(x[0]) + "," + exact(x[1]) + "," + exact(x[2]); };
    return " --eye " + v(c.eye) + " --at " + v(c.at) + " --up " + v(c.up) + " --fov " + exact(c.fov_deg);
  }
  Mesh mesh;
  Camera camera;
  test::TempDir dir_;
};

bool same_rgb(const Framebuffer& a, const Framebuffer& b) {
  if (a.width != b.width || a.height != b.height) return false;
  for (std::size_t i = 0; i < a.rgba.size(); ++i)
    if ((a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu)) return false;
  return true;
}

TEST_F(MovieTranslucentCli, RotatingFramesEqualRenderWithTheTurnedCamera) {
  const int n = 4;
  const double turn = 120;
  for (const std::string& what :
       {std::string(" --region-opacity mould=0.3,substrate=0.5 --field temperature --iso 25,29,33 "
                    "--iso-opacity 0.4 --units degC"),
        std::string(" --volume temperature --opacity-curve 27:0.1,40:0.6 --cmap coolwarm --legend off")}) {
    SCOPED_TRACE(what);
    const std::string common = p("pkg.vtu") + " --size 240x150" + what;
    std::string out;
    ASSERT_EQ(foxi("movie " + common + camera_options(camera) + " --mode rotate --turn 120 --frames 4 -o " +
                       p("rot/f_%d.png"),
                   &out),
              0)
        << out;
    EXPECT_NE(out.find("composited back to front in the power order (exact for this Delaunay mesh) in every "
                       "frame"),
              std::string::npos)
        << out;
    for (int k = 0; k < n; ++k) {
      const Camera c = orbit(camera, turn * k / n, 0);
      std::string rlog;
      ASSERT_EQ(foxi("render " + common + camera_options(c) + " -o " + p("r.png"), &rlog), 0) << rlog;
      EXPECT_TRUE(same_rgb(frame("rot", k), read_png(dir_ / "r.png"))) << "frame " << k;
    }
    EXPECT_FALSE(same_rgb(frame("rot", 0), frame("rot", 1))) << "the camera turns";
  }
}

TEST_F(MovieTranslucentCli, OpacitySweepFramesEqualRenderWithScaledOpacities) {
  const double a = 0.5, b = 1.5;
  const int n = 3;
  auto scaled = [&](int k, double opacity) {
    const double s = k == n - 1 ? b : a + (b - a) * double(k) / double(n - 1);
    return exact(opacity * s);
  };
  const std::string base = p("pkg.vtu") + " --size 240x150" + camera_options(camera);
  std::string out;
  // X-ray with translucent isotherms.
  const std::string xray = base + " --field temperature --iso 27,31 --units degC";
  ASSERT_EQ(
      foxi("movie " + xray + " --region-opacity mould=0.3,die=0.6 --iso-opacity 0.4 --sweep opacity:0.5,1.5" +
               " --frames 3 -o " + p("xo/f_%d.png"),
           &out),
      0)
      << out;
  EXPECT_NE(out.find("every opacity scaled by s = 0.5 to 1.5 over 3 frames (0.5, 1, 1.5)"), std::string::npos)
      << out;
  for (int k = 0; k < n; ++k) {
    std::string rlog;
    ASSERT_EQ(foxi("render " + xray + " --region-opacity mould=" + scaled(k, 0.3) + ",die=" + scaled(k, 0.6) +
                       " --iso-opacity " + scaled(k, 0.4) + " -o " + p("r.png"),
                   &rlog),
              0)
        << rlog;
    EXPECT_TRUE(same_rgb(frame("xo", k), read_png(dir_ / "r.png"))) << "x-ray frame " << k;
  }
  EXPECT_FALSE(same_rgb(frame("xo", 0), frame("xo", 2)));
  // The volume's transfer function: the opacity curve scaled.
  const std::string vol = base + " --volume temperature --range 26,40 --legend off";
  ASSERT_EQ(
      foxi("movie " + vol + " --opacity-curve 26:0.05,33:0.2,40:0.6 --sweep opacity:0.5,1.5 --frames 3 -o " +
               p("vo/f_%d.png"),
           &out),
      0)
      << out;
  for (int k = 0; k < n; ++k) {
    std::string rlog;
    ASSERT_EQ(foxi("render " + vol + " --opacity-curve 26:" + scaled(k, 0.05) + ",33:" + scaled(k, 0.2) +
                       ",40:" + scaled(k, 0.6) + " -o " + p("r.png"),
                   &rlog),
              0)
        << rlog;
    EXPECT_TRUE(same_rgb(frame("vo", k), read_png(dir_ / "r.png"))) << "volume frame " << k;
  }
  EXPECT_FALSE(same_rgb(frame("vo", 0), frame("vo", 2)));
  // An opacity pushed past its range is refused before any frame.
  EXPECT_EQ(foxi("movie " + vol + " --opacity-curve 26:0.05,40:0.7 --sweep opacity:0.5,1.5 --frames 3 -o " +
                     p("bad/f_%d.png"),
                 &out),
            2);
  EXPECT_NE(out.find("above 0.999999"), std::string::npos) << out;
}

TEST_F(MovieTranslucentCli, BackAndForthComesDownThroughTheSamePictures) {
  const std::string common = p("pkg.vtu") + " --size 140x100" + camera_options(camera) +
                             " --region-opacity mould=0.25,die=0.7,substrate=0.4";
  std::string out;
  ASSERT_EQ(foxi("movie " + common + " --frames 6 -o " + p("bf/f_%d.png"), &out), 0) << out;
  EXPECT_NE(out.find("of them again to go back: exact undraw"), std::string::npos) << out;
  ASSERT_EQ(foxi("render " + common + " -o " + p("full.png"), &out), 0) << out;
  EXPECT_TRUE(same_rgb(frame("bf", 3), read_png(dir_ / "full.png"))) << "the high point is render's picture";
  EXPECT_TRUE(same_rgb(frame("bf", 0), Framebuffer(140, 100))) << "from 0%: nothing composited";
  EXPECT_FALSE(same_rgb(frame("bf", 1), frame("bf", 0)));
  EXPECT_FALSE(same_rgb(frame("bf", 1), frame("bf", 2)));
  EXPECT_FALSE(same_rgb(frame("bf", 2), frame("bf", 3)));
  // Up by compositing more, down by compositing the far part again: the same pictures.
  EXPECT_TRUE(same_rgb(frame("bf", 1), frame("bf", 5)));
  EXPECT_TRUE(same_rgb(frame("bf", 2), frame("bf", 4)));
}

TEST_F(MovieTranslucentCli, BadCombinationsAreRefused) {
  const std::string common = p("pkg.vtu") + " --size 80x60 --frames 3 -o " + p("x/f_%d.png");
  std::string out;
  EXPECT_EQ(foxi("movie " + common + " --sweep opacity:0.5,1", &out), 2);
  EXPECT_NE(out.find("give one of them"), std::string::npos) << out;
  EXPECT_EQ(foxi("movie " + common + " --region-opacity 1=0.5 --field temperature --sweep iso:20,30", &out),
            2);
  EXPECT_NE(out.find("not --sweep iso"), std::string::npos) << out;
  EXPECT_EQ(foxi("movie " + common + " --region-opacity 1=0.5 --mode rotate --to 50%", &out), 2);
  EXPECT_NE(out.find("leave out --from and --to"), std::string::npos) << out;
  EXPECT_EQ(foxi("movie " + common + " --region-opacity 1=0.5 --sweep opacity:1,3", &out), 2);
  EXPECT_NE(out.find("more than 1"), std::string::npos) << out;
  EXPECT_EQ(foxi("movie " + common + " --region-opacity 1=0.5 --sweep opacity:-1,1", &out), 2);
  EXPECT_EQ(foxi("movie " + common + " --volume temperature --opacity-curve 30:0.2 --threshold 20,30", &out),
            2);
  EXPECT_NE(out.find("--volume draws the field alone"), std::string::npos) << out;
  // Without the certificate there is no far part to grow: refused (3), though rotate composites it.
  Mesh bent = mesh;
  for (std::size_t i = 0; i < bent.xyz.size(); i += 3)
    bent.xyz[i + 2] += 0.3 * std::sin(3 * bent.xyz[i] + bent.xyz[i + 1]);
  write_mesh(bent, dir_ / "bent.vtu");
  const std::string bent_common = p("bent.vtu") + " --size 80x60 --frames 3 --region-opacity 1=0.5";
  ASSERT_EQ(foxi("movie " + bent_common + " --mode rotate -o " + p("b/f_%d.png"), &out), 0) << out;
  if (out.find("sorting each pixel's fragments by depth") == std::string::npos)
    GTEST_SKIP() << "the bent grid stayed Delaunay: " << out;
  EXPECT_EQ(foxi("movie " + bent_common + " -o " + p("b/f_%d.png"), &out), 3);
  EXPECT_NE(out.find("fails the Delaunay certificate"), std::string::npos) << out;
}

}  // namespace
}  // namespace foxi
