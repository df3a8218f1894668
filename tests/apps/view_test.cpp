// foxi-view, the libX11 viewer: its headless script mode (the same state machine as the window)
// against foxi render, its region of interest through the id buffer, and the real window under Xvfb
// driven by xdotool, its saved PNG and a screenshot of the window compared with the headless picture.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

// foxi-view is built beside the CLI: <build>/apps/foxi/foxi -> <build>/apps/foxi-view/foxi-view.
std::filesystem::path view_path() {
  return std::filesystem::path(test::cli_path()).parent_path().parent_path() / "foxi-view" / "foxi-view";
}

int run_logged(const std::string& cmd, const std::filesystem::path& log, std::string* out = nullptr) {
  int status = test::run(cmd, log);
  if (out) *out = test::read_text(log);
  return status;
}

std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

std::vector<std::uint32_t> read_ids(const std::filesystem::path& path) {
  std::string bytes = test::read_text(path);
  std::vector<std::uint32_t> ids(bytes.size() / 4);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + 4 * i);
    ids[i] = std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
             std::uint32_t(b[3]) << 24;
  }
  return ids;
}

std::vector<std::uint32_t> read_tets(const std::filesystem::path& path) {
  std::istringstream in(test::read_text(path));
  std::vector<std::uint32_t> v;
  std::uint32_t t;
  while (in >> t) v.push_back(t);
  return v;
}

std::size_t differing_pixels(const Framebuffer& a, const Framebuffer& b) {
  if (a.width != b.width || a.height != b.height) return std::size_t(-1);
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.rgba.size(); ++i) n += (a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu);
  return n;
}

// A 6 x 5 x 4 grid of cubes, 6 tets each (cospherical clusters), in two regions: left and right half.
Mesh two_region_grid() {
  Mesh m = test::grid_mesh(6, 5, 4, 1, 1, 1, 6);
  m.tet_region.resize(m.tet_count());
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    double x = 0;
    for (int v = 0; v < 4; ++v) x += m.xyz[3 * std::size_t(m.tet[4 * t + v])];
    m.tet_region[t] = x < 12 ? 1 : 2;
  }
  m.regions = {Region{1, "left", kNone}, Region{2, "right", kNone}};
  return m;
}

// Each "probe X,Y: u V at (x, y, z), tet T" line of a foxi-view script's log against foxi probe of
// `mesh` at that point: the same value (1e-6 relative; the point may lie on a face, where probe may
// name the neighbour). Returns the number of such lines.
int probes_equal_foxi_probe(const std::string& view_log, const std::filesystem::path& mesh,
                            const std::filesystem::path& dir) {
  std::istringstream lines(view_log);
  std::string line, out;
  int probed = 0;
  const std::regex value(
      "^probe ([0-9]+),([0-9]+): u ([-0-9.e+]+) at \\(([-0-9.e+]+), ([-0-9.e+]+), ([-0-9.e+]+)\\), tet "
      "([0-9]+)");
  while (std::getline(lines, line)) {
    std::smatch mm;
    if (!std::regex_search(line, mm, value)) continue;
    ++probed;
    const std::string at = std::string(mm[4]) + "," + std::string(mm[5]) + "," + std::string(mm[6]);
    EXPECT_EQ(run_logged(q(test::cli_path()) + " probe " + q(mesh) + " --field u --at " + at,
                         dir / "probe.log", &out),
              0)
        << out;
    std::smatch pm;
    if (!std::regex_search(out, pm, std::regex("tet ([0-9]+), .*u = ([-0-9.e+]+)"))) {
      ADD_FAILURE() << out;
      continue;
    }
    EXPECT_NEAR(std::stod(pm[2]), std::stod(mm[3]), 1e-6 * std::abs(std::stod(mm[3]))) << line << "\n" << out;
  }
  return probed;
}

class ViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(view_path()))
      GTEST_SKIP() << view_path() << " is not built (FOXI_WITH_X11 off, or no libX11)";
    mesh_path_ = dir_ / "grid.vtu";
    write_mesh(two_region_grid(), mesh_path_);
  }
  test::TempDir dir_;
  std::filesystem::path mesh_path_;
};

const char* kSize = "--size 320x240";

TEST_F(ViewTest, ScriptDrawEqualsFoxiRender) {
  std::string out;
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(mesh_path_) + " " + kSize + " --save " + q(dir_ / "h") +
                           " --script 'd s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_NE(out.find("saved " + (dir_ / "h-001.png").string()), std::string::npos) << out;
  EXPECT_NE(out.find("drawn 720 / 720 tets (100.0%)"), std::string::npos) << out;
  ASSERT_EQ(
      run_logged(q(test::cli_path()) + " render " + q(mesh_path_) + " " + kSize + " -o " + q(dir_ / "r.png"),
                 dir_ / "render.log", &out),
      0)
      << out;
  const Framebuffer view = read_png(dir_ / "h-001.png"), render = read_png(dir_ / "r.png");
  EXPECT_EQ(differing_pixels(view, render), 0u);
  // Not a blank picture: both regions' colours show.
  std::set<std::uint32_t> colours(view.rgba.begin(), view.rgba.end());
  EXPECT_GT(colours.size(), 10u);

  // An orthographic camera gives the same agreement.
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(mesh_path_) + " " + kSize + " --dir 1,2,-3 --save " +
                           q(dir_ / "o") + " --script 'd s'",
                       dir_ / "view2.log", &out),
            0)
      << out;
  ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(mesh_path_) + " " + kSize + " --dir 1,2,-3 -o " +
                           q(dir_ / "ro.png"),
                       dir_ / "render2.log", &out),
            0)
      << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "o-001.png"), read_png(dir_ / "ro.png")), 0u);
}

// Fields in the viewer: --field colours as foxi render --field --legend off does (pixel for pixel, the
// same automatic range); the value the status line reads under the mouse (script probe:X,Y) equals
// foxi probe's at the point it names; the key f cycles to the next field; the isosurface keys draw
// what foxi render --iso draws.
TEST_F(ViewTest, FieldColoursAndTheValueUnderTheMouseEqualRenderAndProbe) {
  Mesh m = two_region_grid();
  Field u{"u", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n)
    u.values.push_back(1 + m.xyz[3 * n] * m.xyz[3 * n + 1] + std::sin(m.xyz[3 * n + 2]));
  Field w{"w", FieldLocation::node, 1, "", {}, {}};
  w.values.assign(m.node_count(), 2.0);
  m.fields = {u, w};
  write_mesh(m, dir_ / "f.vtu");
  std::string out;
  const int px[][2] = {{160, 120}, {100, 90}, {200, 150}, {140, 170}, {230, 100}, {5, 5}};
  std::string script = "d s";
  for (const auto& p : px) script += " probe:" + std::to_string(p[0]) + "," + std::to_string(p[1]);
  script += " field d probe:160,120";
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(dir_ / "f.vtu") + " " + kSize +
                           " --field u --graded --save " + q(dir_ / "fv") + " --script '" + script + "'",
                       dir_ / "view.log", &out),
            0)
      << out;
  const std::string view_log = out;
  ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(dir_ / "f.vtu") + " " + kSize +
                           " --field u --graded --legend off -o " + q(dir_ / "fr.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "fv-001.png"), read_png(dir_ / "fr.png")), 0u);
  EXPECT_NE(view_log.find("probe 5,5: background"), std::string::npos) << view_log;
  EXPECT_EQ(probes_equal_foxi_probe(view_log, dir_ / "f.vtu", dir_.path()), 5) << view_log;
  // After f: the next field (w, a constant 2).
  EXPECT_NE(view_log.find("probe 160,120: w 2 at"), std::string::npos) << view_log;

  // The isosurface keys' script forms: the solid above u = 6 and the surface alone equal foxi render
  // --iso 6 [--iso-only], pixel for pixel; 'noiso' gives the whole tets back.
  ASSERT_EQ(
      run_logged(q(view_path()) + " " + q(dir_ / "f.vtu") + " " + kSize + " --field u --graded --save " +
                     q(dir_ / "iv") + " --script 'iso:6 d s iso-only:6 d s noiso d s'",
                 dir_ / "view.log", &out),
      0)
      << out;
  for (const char* only : {"", " --iso-only"}) {
    ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(dir_ / "f.vtu") + " " + kSize +
                             " --field u --graded --legend off --iso 6" + only + " -o " + q(dir_ / "ir.png"),
                         dir_ / "render.log", &out),
              0)
        << out;
    EXPECT_EQ(
        differing_pixels(read_png(dir_ / (*only ? "iv-002.png" : "iv-001.png")), read_png(dir_ / "ir.png")),
        0u)
        << (*only ? "surface" : "solid");
  }
  EXPECT_NE(differing_pixels(read_png(dir_ / "iv-001.png"), read_png(dir_ / "iv-002.png")), 0u);
  EXPECT_EQ(differing_pixels(read_png(dir_ / "iv-003.png"), read_png(dir_ / "fr.png")), 0u);

  // The legend key's script form: the scene narrowed by the panel, the legend beside it with the
  // isovalue marked, as foxi render --iso 6 with the legend draws it given the viewer's camera.
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(dir_ / "f.vtu") + " " + kSize +
                           " --field u --graded --save " + q(dir_ / "lv") + " --script 'legend iso:6 d s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  std::smatch cm;
  ASSERT_TRUE(std::regex_search(out, cm, std::regex("legend on, ([0-9]+) pixels at the right"))) << out;
  ASSERT_TRUE(std::regex_search(out, cm, std::regex("\\((--eye [^)]*)\\)"))) << out;
  ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(dir_ / "f.vtu") + " " + kSize + " " +
                           std::string(cm[1]) + " --field u --graded --iso 6 -o " + q(dir_ / "lr.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  const Framebuffer lv = read_png(dir_ / "lv-001.png");
  EXPECT_EQ(lv.width, 320);
  EXPECT_EQ(differing_pixels(lv, read_png(dir_ / "lr.png")), 0u);
}

// With --shrink (issue 17 item 2) the status line's point is the true point the shrunk tet's pixel
// shows (the point of the tet's face that its shrunk face shows there; pixel_point_test checks that
// it lies on the pixel's ray once shrunk): foxi probe at that point gives the same value.
TEST_F(ViewTest, ValueUnderTheMouseOfShrunkTetsEqualsProbe) {
  Mesh m = two_region_grid();
  Field u{"u", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n)
    u.values.push_back(1 + m.xyz[3 * n] * m.xyz[3 * n + 1] + std::sin(m.xyz[3 * n + 2]));
  m.fields = {u};
  write_mesh(m, dir_ / "f.vtu");
  std::string script = "d";
  for (int y = 60; y < 200; y += 23)
    for (int x = 70; x < 260; x += 31) script += " probe:" + std::to_string(x) + "," + std::to_string(y);
  std::string out;
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(dir_ / "f.vtu") + " " + kSize +
                           " --shrink 0.5 --field u --graded --script '" + script + "'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_GE(probes_equal_foxi_probe(out, dir_ / "f.vtu", dir_.path()), 10) << out;
}

// Undraw in the viewer's state machine: draw all, undraw 360 of the 720 tets, and the picture (and
// the tets left) equal foxi render --stop 50% (another program, drawing them afresh); undraw all is
// blank; drawing on after the undraw gives the whole picture again; a region taken after an undraw
// is exactly the tets left.
// Translucency and volume rendering in the viewer (issue 23 item 3): --region-opacity's x-ray and
// --volume's picture equal foxi render's with the same options pixel for pixel; undrawing part of the
// x-ray changes the picture and drawing on restores it exactly; the status line says what is
// composited and that it is exact; the keys x, t, v (script xray, isoalpha, volume) switch.
TEST_F(ViewTest, XrayAndVolumeEqualRenderAndUndrawExactly) {
  Mesh m = two_region_grid();
  Field u{"u", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n)
    u.values.push_back(1 + 0.3 * m.xyz[3 * n] + 0.2 * m.xyz[3 * n + 1] * m.xyz[3 * n + 2]);
  m.fields = {u};
  write_mesh(m, dir_ / "x.vtu");
  const std::string view = q(view_path()) + " " + q(dir_ / "x.vtu") + " " + kSize;
  const std::string render = q(test::cli_path()) + " render " + q(dir_ / "x.vtu") + " " + kSize;
  std::string out;
  ASSERT_EQ(run_logged(view + " --region-opacity left=0.3,right=0.6 --save " + q(dir_ / "xv") +
                           " --script 'd s status u:100 s f s xray d s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_NE(out.find("x-ray composited exactly (power order)"), std::string::npos) << out;
  EXPECT_NE(out.find("x-ray 1:0.3,2:0.6"), std::string::npos) << out;
  ASSERT_EQ(run_logged(render + " --region-opacity left=0.3,right=0.6 -o " + q(dir_ / "xr.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  const Framebuffer xray = read_png(dir_ / "xv-001.png");
  EXPECT_EQ(differing_pixels(xray, read_png(dir_ / "xr.png")), 0u) << "the x-ray is foxi render's";
  EXPECT_GT(differing_pixels(xray, read_png(dir_ / "xv-002.png")), 0u) << "undrawn 100 surface tets";
  EXPECT_EQ(differing_pixels(xray, read_png(dir_ / "xv-003.png")), 0u) << "drawn on again";
  ASSERT_EQ(run_logged(render + " -o " + q(dir_ / "opaque.png"), dir_ / "render.log", &out), 0) << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "xv-004.png"), read_png(dir_ / "opaque.png")), 0u)
      << "x: the x-ray off";
  // The volume, with the viewer's automatic range as foxi render's.
  const std::string curve = " --opacity-curve 1:0.05,3:0.3,5:0.6";
  ASSERT_EQ(run_logged(view + " --volume u" + curve + " --save " + q(dir_ / "vv") + " --script 'd s status'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_NE(out.find("volume composited exactly (power order)"), std::string::npos) << out;
  ASSERT_EQ(run_logged(render + " --volume u" + curve + " --legend off -o " + q(dir_ / "vr.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "vv-001.png"), read_png(dir_ / "vr.png")), 0u);
  // Translucent isosurfaces need a field; the volume and --region-opacity do not go together.
  EXPECT_EQ(run_logged(view + " --script 'isoalpha'", dir_ / "view.log", &out), 1) << out;
  EXPECT_NE(out.find("needs a field"), std::string::npos) << out;
  EXPECT_EQ(run_logged(view + " --volume u --region-opacity left=0.5 --script d", dir_ / "view.log", &out),
            2);
  ASSERT_EQ(run_logged(view + " --field u --save " + q(dir_ / "iv") + " --script 'isoalpha d status'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_NE(out.find("5 translucent isosurfaces, opacity 0.35"), std::string::npos) << out;
  // Isosurfaces alone are not an x-ray.
  EXPECT_NE(out.find("translucent isosurfaces composited exactly"), std::string::npos) << out;
  EXPECT_EQ(out.find("x-ray"), std::string::npos) << out;
}

// The legend's panel at the start with the camera as fitted: the camera is fitted again to what the
// panel leaves, as foxi render fits it, so the picture is foxi render's with its legend, pixel for
// pixel (the viewer once kept the camera of the whole width, cutting off both ends of the mesh). A
// volume's colours and legend span the corner values (foxi render's range), and an 'iso:V' that ends
// the volume says so in the status line and gives the opaque picture's range back.
TEST_F(ViewTest, LegendAtTheStartAndTheVolumesRangeEqualFoxiRender) {
  Mesh m = two_region_grid();
  Field u{"u", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) u.values.push_back(m.xyz[3 * n] + 0.5 * m.xyz[3 * n + 2]);
  m.fields = {u};
  write_mesh(m, dir_ / "l.vtu");
  const std::string view = q(view_path()) + " " + q(dir_ / "l.vtu") + " --size 400x300";
  const std::string render = q(test::cli_path()) + " render " + q(dir_ / "l.vtu") + " --size 400x300";
  std::string out;
  ASSERT_EQ(run_logged(view + " --field u --save " + q(dir_ / "lv") + " --script 'legend d s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  ASSERT_EQ(run_logged(render + " --field u -o " + q(dir_ / "lr.png"), dir_ / "render.log", &out), 0) << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "lv-001.png"), read_png(dir_ / "lr.png")), 0u);
  const std::string curve = " --opacity-curve 0:0.05,8:0.4";
  ASSERT_EQ(run_logged(view + " --volume u" + curve + " --save " + q(dir_ / "vl") +
                           " --script 'legend d s status iso:3 status'",
                       dir_ / "view.log", &out),
            0)
      << out;
  const std::string view_log = out;
  ASSERT_EQ(
      run_logged(render + " --volume u" + curve + " -o " + q(dir_ / "vr.png"), dir_ / "render.log", &out), 0)
      << out;
  EXPECT_NE(out.find("colours 0 to 8"), std::string::npos) << out;  // the corners': x + z / 2 on [0,6]x[0,4]
  EXPECT_EQ(differing_pixels(read_png(dir_ / "vl-001.png"), read_png(dir_ / "vr.png")), 0u);
  EXPECT_NE(view_log.find("u, viridis, 0 to 8; volume"), std::string::npos) << view_log;
  const std::size_t after = view_log.rfind("status ");
  EXPECT_NE(view_log.find("solid above 3", after), std::string::npos) << view_log;
  EXPECT_EQ(view_log.find("volume", after), std::string::npos) << view_log;
}

// As foxi render: an option given twice, or an empty value, is refused; --shrink does not go with
// what draws whole tets; 'r' under the x-ray says why it is refused.
TEST_F(ViewTest, RepeatedOptionsAndWholeTetModesAreRefused) {
  std::string out;
  const std::string view = q(view_path()) + " " + q(mesh_path_);
  EXPECT_EQ(run_logged(view + " --size 100x100 --size 200x200 --script d", dir_ / "v.log", &out), 2) << out;
  EXPECT_NE(out.find("--size given twice"), std::string::npos) << out;
  EXPECT_EQ(run_logged(view + " --size=100x100 --size 200x200 --script d", dir_ / "v.log", &out), 2) << out;
  EXPECT_NE(out.find("--size given twice"), std::string::npos) << out;  // --name=value is --name value
  EXPECT_EQ(run_logged(view + " --region-opacity left=0.2 --region-opacity right=0.5 --script d",
                       dir_ / "v.log", &out),
            2)
      << out;
  EXPECT_EQ(run_logged(view + " --region-opacity '' --script d", dir_ / "v.log", &out), 2) << out;
  EXPECT_NE(out.find("not an empty one"), std::string::npos) << out;
  EXPECT_EQ(run_logged(view + " --shrink 0.5 --region-opacity left=0.2 --script d", dir_ / "v.log", &out), 2)
      << out;
  EXPECT_EQ(run_logged(view + " --shrink 0.5 --script 'xray'", dir_ / "v.log", &out), 1) << out;
  EXPECT_NE(out.find("without --shrink"), std::string::npos) << out;
  EXPECT_EQ(run_logged(view + " --script 'xray d r'", dir_ / "v.log", &out), 1) << out;
  EXPECT_NE(out.find("refused while the x-ray"), std::string::npos) << out;
}

TEST_F(ViewTest, UndrawEqualsRenderingFewerTets) {
  std::string out;
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(mesh_path_) + " " + kSize + " --dump-ids --save " +
                           q(dir_ / "u") + " --script 'd s u:360 s u s f s u:100 r s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_NE(out.find("undrawing 360 / 720 tets (50.0%)"), std::string::npos) << out;
  EXPECT_NE(out.find("undrawn 0 / 720 tets"), std::string::npos) << out;
  ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(mesh_path_) + " " + kSize + " --stop 50% -o " +
                           q(dir_ / "half.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  const auto all = read_tets(dir_ / "u-001.tets");
  ASSERT_EQ(all.size(), 720u);
  const auto half = read_tets(dir_ / "u-002.tets");
  EXPECT_EQ(half, std::vector<std::uint32_t>(all.begin(), all.begin() + 360));
  EXPECT_EQ(differing_pixels(read_png(dir_ / "u-002.png"), read_png(dir_ / "half.png")), 0u);
  const auto blank_ids = read_ids(dir_ / "u-003.ids");
  EXPECT_TRUE(std::all_of(blank_ids.begin(), blank_ids.end(), [](std::uint32_t id) { return id == kNone; }));
  EXPECT_EQ(differing_pixels(read_png(dir_ / "u-003.png"), Framebuffer(320, 240)), 0u);
  EXPECT_EQ(read_tets(dir_ / "u-004.tets"), all);
  EXPECT_EQ(differing_pixels(read_png(dir_ / "u-004.png"), read_png(dir_ / "u-001.png")), 0u);
  EXPECT_EQ(read_ids(dir_ / "u-004.ids"), read_ids(dir_ / "u-001.ids"));
  // The dumps are written durably (DurableFile, committed together): no temporary is left beside them.
  for (const auto& e : std::filesystem::directory_iterator(dir_.path()))
    EXPECT_EQ(e.path().filename().string().find(".foxi-tmp-"), std::string::npos) << e.path();
  // The region after undrawing 100: the first 620 tets of the order, nothing drawn yet.
  const std::string log = test::read_text(dir_ / "view.log");
  EXPECT_NE(log.find("drawing 0 / 620 tets"), std::string::npos) << log;
  EXPECT_NE(log.find("region 1"), std::string::npos) << log;
  EXPECT_NE(run_logged(q(view_path()) + " " + q(mesh_path_) + " --script 'u:x'", dir_ / "bad.log", &out), 0);
}

// --no-undo: the same picture as foxi render (drawing without recording for undraw changes no
// pixel), and an undraw is refused with a message.
TEST_F(ViewTest, NoUndoDrawsTheSamePictureAndRefusesUndraw) {
  std::string out;
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(mesh_path_) + " " + kSize + " --no-undo --save " +
                           q(dir_ / "n") + " --script 'd s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  ASSERT_EQ(
      run_logged(q(test::cli_path()) + " render " + q(mesh_path_) + " " + kSize + " -o " + q(dir_ / "r.png"),
                 dir_ / "render.log", &out),
      0)
      << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "n-001.png"), read_png(dir_ / "r.png")), 0u);
  EXPECT_NE(run_logged(q(view_path()) + " " + q(mesh_path_) + " " + kSize + " --no-undo --script 'd u'",
                       dir_ / "undo.log", &out),
            0);
  EXPECT_NE(out.find("no --no-undo"), std::string::npos) << out;
}

TEST_F(ViewTest, RegionOfInterestDrawsExactlyTheSubsetAndBackRestores) {
  std::string out;
  // Draw two batches, save, take them as the region, turn, draw the region, save; back up, draw, save.
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(mesh_path_) + " " + kSize + " --dump-ids --save " +
                           q(dir_ / "h") + " --script 'c n n s r orbit:40,10 d s b d s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  const auto roi = read_tets(dir_ / "h-001.tets");
  ASSERT_GT(roi.size(), 0u);
  ASSERT_LT(roi.size(), 720u) << "two batches should not be the whole mesh";
  const std::set<std::uint32_t> subset(roi.begin(), roi.end());
  ASSERT_EQ(subset.size(), roi.size());

  // The region drawn from the new view: every subset tet once, nothing else, in the id buffer too.
  auto drawn = read_tets(dir_ / "h-002.tets");
  std::sort(drawn.begin(), drawn.end());
  EXPECT_EQ(drawn, std::vector<std::uint32_t>(subset.begin(), subset.end()));
  std::size_t covered = 0;
  for (std::uint32_t id : read_ids(dir_ / "h-002.ids")) {
    if (id == kNone) continue;
    ++covered;
    EXPECT_TRUE(subset.count(id)) << "pixel shows tet " << id << " outside the region";
    if (!subset.count(id)) break;
  }
  EXPECT_GT(covered, 0u);
  EXPECT_NE(out.find("drawn " + std::to_string(roi.size()) + " / " + std::to_string(roi.size()) + " tets"),
            std::string::npos)
      << out;

  // Back up: the whole mesh again, from the turned view; equal to foxi render of that camera.
  auto all = read_tets(dir_ / "h-003.tets");
  EXPECT_EQ(all.size(), 720u);
  std::set<std::uint32_t> shown;
  for (std::uint32_t id : read_ids(dir_ / "h-003.ids"))
    if (id != kNone) shown.insert(id);
  EXPECT_TRUE(std::any_of(shown.begin(), shown.end(), [&](std::uint32_t t) { return !subset.count(t); }));
  const std::string marker = "saved " + (dir_ / "h-003.png").string();
  const auto at = out.find(marker);
  ASSERT_NE(at, std::string::npos) << out;
  const auto open = out.find("(--", at), close = out.find(')', open);
  const std::string camera = out.substr(open + 1, close - open - 1);
  ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(mesh_path_) + " " + kSize + " " + camera +
                           " -o " + q(dir_ / "r.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "h-003.png"), read_png(dir_ / "r.png")), 0u) << camera;
}

TEST_F(ViewTest, NonDelaunayMeshIsDrawnWithTheDepthBuffer) {
  // Two tets on one triangle, each apex inside the other's circumsphere: not Delaunay.
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 0.1, 0.3, 0.3, -0.1};
  test::push_tet(m, 0, 1, 2, 3);
  test::push_tet(m, 0, 1, 2, 4);
  write_mesh(m, dir_ / "nd.vtu");
  std::string out;
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(dir_ / "nd.vtu") + " " + kSize + " --dir 0.2,0.3,-1 --save " +
                           q(dir_ / "h") + " --script 'd s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  EXPECT_NE(out.find("NOT Delaunay: depth-buffer drawing"), std::string::npos) << out;
  ASSERT_EQ(run_logged(q(test::cli_path()) + " render " + q(dir_ / "nd.vtu") + " " + kSize +
                           " --dir 0.2,0.3,-1 -o " + q(dir_ / "r.png"),
                       dir_ / "render.log", &out),
            0)
      << out;
  EXPECT_EQ(differing_pixels(read_png(dir_ / "h-001.png"), read_png(dir_ / "r.png")), 0u);
}

TEST_F(ViewTest, BadScriptIsAnError) {
  EXPECT_EQ(test::run(q(view_path()) + " " + q(mesh_path_) + " --script 'd wobble'", dir_ / "bad.log"), 1);
  EXPECT_NE(test::read_text(dir_ / "bad.log").find("unknown script command 'wobble'"), std::string::npos);
  EXPECT_EQ(test::run(q(view_path()) + " " + q(mesh_path_) + " --size 0x3", dir_ / "bad2.log"), 2);
}

// An XWD screenshot (xwd -id WINDOW) as RGB pixels, for 24/32-bit TrueColor ZPixmap images.
bool read_xwd(const std::filesystem::path& path, Framebuffer& fb) {
  const std::string s = test::read_text(path);
  auto be32 = [&](std::size_t off) {
    const auto* b = reinterpret_cast<const unsigned char*>(s.data() + off);
    return std::uint32_t(b[0]) << 24 | std::uint32_t(b[1]) << 16 | std::uint32_t(b[2]) << 8 | b[3];
  };
  if (s.size() < 100) return false;
  const std::uint32_t header = be32(0), format = be32(8), w = be32(16), h = be32(20), order = be32(28);
  const std::uint32_t bpp = be32(44), bpl = be32(48), rmask = be32(56), gmask = be32(60), bmask = be32(64);
  const std::uint32_t ncolors = be32(76);
  if (format != 2 || bpp != 32 || w == 0 || h == 0) return false;
  const std::size_t data = header + 12 * std::size_t(ncolors);
  if (s.size() < data + std::size_t(bpl) * h) return false;
  auto shift = [](std::uint32_t m) {
    int k = 0;
    while (m && !(m & 1)) m >>= 1, ++k;
    return k;
  };
  fb.resize(int(w), int(h), false);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) {
      const auto* b = reinterpret_cast<const unsigned char*>(s.data() + data + std::size_t(y) * bpl + 4 * x);
      std::uint32_t p =
          order == 0
              ? (std::uint32_t(b[3]) << 24 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[1]) << 8 | b[0])
              : (std::uint32_t(b[0]) << 24 | std::uint32_t(b[1]) << 16 | std::uint32_t(b[2]) << 8 | b[3]);
      fb.rgba[std::size_t(y) * w + x] =
          pack_rgba((p & rmask) >> shift(rmask), (p & gmask) >> shift(gmask), (p & bmask) >> shift(bmask));
    }
  return true;
}

// The real window under Xvfb: keys sent with xdotool (d, wait for the draw, s, u undraw all, s,
// u draw on, s, q). The PNG it saves
// equals the headless one, and so does a screenshot of the window above its status line (the window
// is updated with each frame's changed rectangle only, so a missed change would show there).
TEST_F(ViewTest, WindowUnderXvfbDrivenByXdotool) {
  if (!test::have_program("xvfb-run") || !test::have_program("xdotool"))
    GTEST_SKIP() << "xvfb-run or xdotool is missing (scripts/install-deps.sh installs them)";
  const bool have_xwd = test::have_program("xwd");
  const std::string driver = R"SH(set -u
V=$1; M=$2; D=$3
"$V" "$M" --size 320x240 --save "$D/x" > "$D/window.log" 2>&1 &
pid=$!
trap 'kill -9 $pid 2>/dev/null' EXIT
wait_for() { i=0; while [ $i -lt 100 ]; do [ "$(grep -c "$1" "$D/window.log")" -ge "$2" ] && return 0; kill -0 $pid 2>/dev/null || return 1; sleep 0.1; i=$((i+1)); done; echo "timeout waiting for $1"; return 1; }
wid=$(timeout 10 xdotool search --sync --name '^foxi-view$' | head -1)
[ -n "$wid" ] || { echo "no window"; exit 3; }
wait_for '^done' 1 || exit 4
xdotool key --window "$wid" d
wait_for '^done' 2 || exit 5
xdotool key --window "$wid" s
wait_for '^saved' 1 || exit 6
xdotool key --window "$wid" u
wait_for '^undrawn' 1 || exit 10
xdotool key --window "$wid" s
wait_for '^saved' 2 || exit 11
xdotool key --window "$wid" u
wait_for '^done' 3 || exit 12
xdotool key --window "$wid" s
wait_for '^saved' 3 || exit 13
if command -v xwd > /dev/null; then xwd -silent -id "$wid" > "$D/shot.xwd" || exit 8; fi
xdotool key --window "$wid" q 2>/dev/null
i=0; while kill -0 $pid 2>/dev/null && [ $i -lt 50 ]; do sleep 0.1; i=$((i+1)); done
kill -0 $pid 2>/dev/null && { echo "viewer did not quit"; exit 7; }
wait $pid; rc=$?
[ $rc -eq 0 ] || { echo "viewer exit status $rc"; cat "$D/window.log"; exit 9; }
trap - EXIT
exit 0
)SH";
  test::write_text(dir_ / "drive.sh", driver);
  std::string out;
  ASSERT_EQ(run_logged(q(view_path()) + " " + q(mesh_path_) + " --size 320x240 --save " + q(dir_ / "h") +
                           " --script 'd s'",
                       dir_ / "view.log", &out),
            0)
      << out;
  const Framebuffer headless = read_png(dir_ / "h-001.png");

  // Once with XShm (Xvfb has it), once with plain XPutImage.
  for (const std::string env : {"", "FOXI_VIEW_NO_SHM=1 "}) {
    SCOPED_TRACE(env.empty() ? "XShm" : "XPutImage");
    for (const char* name : {"x-001.png", "x-002.png", "x-003.png"}) std::filesystem::remove(dir_ / name);
    std::filesystem::remove(dir_ / "shot.xwd");
    const int status =
        run_logged(env + "timeout -k 5 40 xvfb-run -a -s '-screen 0 640x480x24' sh " + q(dir_ / "drive.sh") +
                       " " + q(view_path()) + " " + q(mesh_path_) + " " + q(dir_.path()),
                   dir_ / "xvfb.log", &out);
    ASSERT_EQ(status, 0) << out << test::read_text(dir_ / "window.log");
    const std::string log = test::read_text(dir_ / "window.log");
    EXPECT_NE(log.find(env.empty() ? "XShm;" : "XPutImage;"), std::string::npos) << log;
    EXPECT_NE(log.find("done drawn 720 / 720 tets (100.0%)"), std::string::npos) << log;
    ASSERT_TRUE(std::filesystem::exists(dir_ / "x-001.png")) << log;
    EXPECT_EQ(differing_pixels(read_png(dir_ / "x-001.png"), headless), 0u);
    // Key u undrew everything (blank), u again drew it all on.
    EXPECT_NE(log.find("undrawn 0 / 720 tets"), std::string::npos) << log;
    EXPECT_EQ(differing_pixels(read_png(dir_ / "x-002.png"), Framebuffer(320, 240)), 0u);
    EXPECT_EQ(differing_pixels(read_png(dir_ / "x-003.png"), headless), 0u);

    if (!have_xwd) {
      std::printf("xwd is missing: the screenshot comparison is skipped\n");
      continue;
    }
    Framebuffer shot;
    ASSERT_TRUE(read_xwd(dir_ / "shot.xwd", shot)) << "cannot read the xwd screenshot";
    ASSERT_EQ(shot.width, 320);
    ASSERT_GE(shot.height, 240);
    Framebuffer top(320, 240);
    for (int y = 0; y < 240; ++y)
      std::copy_n(shot.rgba.begin() + std::ptrdiff_t(y) * 320, 320,
                  top.rgba.begin() + std::ptrdiff_t(y) * 320);
    EXPECT_EQ(differing_pixels(top, headless), 0u);
  }
}

// SIGTERM and SIGHUP to the window (a job scheduler, a closed terminal): the viewer stops with exit
// 143 / 129 and says so, as the foxi commands do, leaving nothing in its save folder.
// The field keys in the real window: l (legend), i (isosurface at the middle of the range), m (next
// colour map), x (x-ray, ending the opaque isosurface), t (translucent isosurfaces), s; the saved
// picture and the window's screenshot equal the headless script's 'legend i map xray isoalpha d s'.
TEST_F(ViewTest, FieldKeysInTheWindowUnderXvfb) {
  if (!test::have_program("xvfb-run") || !test::have_program("xdotool"))
    GTEST_SKIP() << "xvfb-run or xdotool is missing (scripts/install-deps.sh installs them)";
  Mesh m = two_region_grid();
  Field u{"u", FieldLocation::node, 1, "", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) u.values.push_back(m.xyz[3 * n] + 0.5 * m.xyz[3 * n + 2]);
  m.fields = {u};
  write_mesh(m, dir_ / "f.vtu");
  const std::string driver = R"SH(set -u
V=$1; M=$2; D=$3
"$V" "$M" --size 320x240 --field u --graded --save "$D/k" > "$D/window.log" 2>&1 &
pid=$!
trap 'kill -9 $pid 2>/dev/null' EXIT
wait_for() { i=0; while [ $i -lt 100 ]; do [ "$(grep -c "$1" "$D/window.log")" -ge "$2" ] && return 0; kill -0 $pid 2>/dev/null || return 1; sleep 0.1; i=$((i+1)); done; echo "timeout waiting for $1"; return 1; }
wid=$(timeout 10 xdotool search --sync --name '^foxi-view$' | head -1)
[ -n "$wid" ] || { echo "no window"; exit 3; }
wait_for '^done' 1 || exit 4
xdotool key --window "$wid" l
wait_for '^done' 2 || exit 5
xdotool key --window "$wid" i
wait_for '^done' 3 || exit 5
xdotool key --window "$wid" m
wait_for '^done' 4 || exit 5
xdotool key --window "$wid" x
wait_for '^done' 5 || exit 5
xdotool key --window "$wid" t
wait_for '^done' 6 || exit 5
xdotool key --window "$wid" s
wait_for '^saved' 1 || exit 6
if command -v xwd > /dev/null; then xwd -silent -id "$wid" > "$D/kshot.xwd" || exit 8; fi
xdotool key --window "$wid" q 2>/dev/null
i=0; while kill -0 $pid 2>/dev/null && [ $i -lt 50 ]; do sleep 0.1; i=$((i+1)); done
kill -0 $pid 2>/dev/null && { echo "viewer did not quit"; exit 7; }
wait $pid; rc=$?
[ $rc -eq 0 ] || { echo "viewer exit status $rc"; cat "$D/window.log"; exit 9; }
trap - EXIT
exit 0
)SH";
  test::write_text(dir_ / "drive.sh", driver);
  std::string out;
  ASSERT_EQ(
      run_logged(q(view_path()) + " " + q(dir_ / "f.vtu") + " --size 320x240 --field u --graded --save " +
                     q(dir_ / "h") + " --script 'legend i map xray isoalpha d s'",
                 dir_ / "view.log", &out),
      0)
      << out;
  const Framebuffer headless = read_png(dir_ / "h-001.png");
  const int status =
      run_logged("timeout -k 5 40 xvfb-run -a -s '-screen 0 640x480x24' sh " + q(dir_ / "drive.sh") + " " +
                     q(view_path()) + " " + q(dir_ / "f.vtu") + " " + q(dir_.path()),
                 dir_ / "xvfb.log", &out);
  ASSERT_EQ(status, 0) << out << test::read_text(dir_ / "window.log");
  ASSERT_TRUE(std::filesystem::exists(dir_ / "k-001.png")) << test::read_text(dir_ / "window.log");
  EXPECT_EQ(differing_pixels(read_png(dir_ / "k-001.png"), headless), 0u);
  EXPECT_EQ(headless.width, 320);
  if (!test::have_program("xwd")) GTEST_SKIP() << "xwd is missing: the screenshot comparison is skipped";
  Framebuffer shot;
  ASSERT_TRUE(read_xwd(dir_ / "kshot.xwd", shot)) << "cannot read the xwd screenshot";
  ASSERT_EQ(shot.width, 320);
  Framebuffer top(320, 240);
  for (int y = 0; y < 240; ++y)
    std::copy_n(shot.rgba.begin() + std::ptrdiff_t(y) * 320, 320, top.rgba.begin() + std::ptrdiff_t(y) * 320);
  EXPECT_EQ(differing_pixels(top, headless), 0u) << "the window shows the scene beside the legend";
}

TEST_F(ViewTest, WindowStopsCleanlyOnSigtermAndSighup) {
  if (!test::have_program("xvfb-run"))
    GTEST_SKIP() << "xvfb-run is missing (scripts/install-deps.sh installs it)";
  const std::string driver = R"SH(set -u
V=$1; M=$2; D=$3; S=$4
"$V" "$M" --size 320x240 --save "$D/x" > "$D/stop.log" 2>&1 &
pid=$!
i=0; while [ $i -lt 200 ] && ! grep -q '^done' "$D/stop.log"; do kill -0 $pid 2>/dev/null || exit 4; sleep 0.1; i=$((i+1)); done
grep -q '^done' "$D/stop.log" || { kill -9 $pid; exit 5; }
kill -s "$S" $pid
wait $pid
exit $?
)SH";
  test::write_text(dir_ / "stop.sh", driver);
  for (const auto& [sig, status] :
       {std::pair<std::string, int>{"TERM", 143}, std::pair<std::string, int>{"HUP", 129}}) {
    SCOPED_TRACE("SIG" + sig);
    const std::filesystem::path d = dir_ / ("stop-" + sig);
    std::filesystem::create_directories(d);
    std::string out;
    EXPECT_EQ(run_logged("xvfb-run -a sh " + q(dir_ / "stop.sh") + " " + q(view_path()) + " " +
                             q(mesh_path_) + " " + q(d) + " " + sig,
                         dir_ / "stop-run.log", &out),
              status)
        << out << test::read_text(d / "stop.log");
    EXPECT_NE(test::read_text(d / "stop.log").find("foxi-view: stopped by SIG" + sig), std::string::npos)
        << test::read_text(d / "stop.log");
    std::vector<std::string> left;
    for (const auto& e : std::filesystem::directory_iterator(d))
      if (e.path().filename() != "stop.log") left.push_back(e.path().filename().string());
    EXPECT_TRUE(left.empty()) << left.front();
  }
}

}  // namespace
}  // namespace foxi
