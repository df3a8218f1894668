// foxi-workbench and foxi::qt: the headless loop's view picture against foxi render's picture of the
// same mesh, field and camera (the CLI as the second renderer), its results against foxi solve's
// record, parameter editing with units (refused values keep the state), Cancel keeping the previous
// mesh, and a GUI heartbeat over meshing, solving and drawing (the window never stalls > 100 ms).
#include "workbench.hpp"
#include "history_plot.hpp"
#include "workbench_parts.hpp"

#include <gtest/gtest.h>

#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QEventLoop>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QMouseEvent>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QProgressBar>
#include <QTableWidget>
#include <QThread>
#include <QTimer>
#include <QWheelEvent>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <dirent.h>
#include <regex>
#include <unistd.h>
#include <span>
#include <sstream>
#include <string>

#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/solver/solver.hpp"
#include "foxi/solver/thermal.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/solver/results.hpp"
#include "foxi/viz/field_selection.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/translucent.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
using foxi::workbench::Workbench;

const std::string kModels = foxi::test::models_dir();

// Waits for the running job (at most 120 s); returns its outcome.
bool wait_job(Workbench& w) {
  if (!w.busy()) return false;
  bool ok = false, done = false;
  QEventLoop loop;
  QObject::connect(&w, &Workbench::finished, &loop, [&](bool r) {
    ok = r;
    done = true;
    loop.quit();
  });
  QTimer::singleShot(120000, &loop, &QEventLoop::quit);
  loop.exec();
  EXPECT_TRUE(done) << "the job did not end within 120 s";
  return ok;
}

// A mesh or solve job (`started`: start_mesh's or start_solve's answer) run to its end; a failure
// says which and the workbench's reason.
testing::AssertionResult job_done(Workbench& w, bool started, const char* what) {
  if (!started) return testing::AssertionFailure() << "the " << what << " did not start";
  if (!wait_job(w))
    return testing::AssertionFailure() << "the " << what << " failed: " << w.last_error().toStdString();
  return testing::AssertionSuccess();
}
testing::AssertionResult meshed(Workbench& w) { return job_done(w, w.start_mesh(), "mesh"); }
testing::AssertionResult solved(Workbench& w) { return job_done(w, w.start_solve(), "solve"); }

enum class Shown { yes, no };

// The window most tests start from: the view small (quick pictures), the window shown (or not) and
// the model file opened; a failure says the workbench's reason.
testing::AssertionResult open_window(Workbench& w, const std::string& model, QSize view = {200, 150},
                                     Shown shown = Shown::yes) {
  w.view_widget()->setFixedSize(view);
  if (shown == Shown::yes) w.show();
  QString why;
  if (!w.open_model(QString::fromStdString(model), &why))
    return testing::AssertionFailure() << model << " did not open: " << why.toStdString();
  return testing::AssertionSuccess();
}

// A saved project opened in window `w` (its view small; shown or not) and its picture made (the job
// open_project starts); a failure says the workbench's reason.
testing::AssertionResult reopen(Workbench& w, const QString& folder, QSize view = {200, 150},
                                Shown shown = Shown::no) {
  w.view_widget()->setFixedSize(view);
  if (shown == Shown::yes) w.show();
  QString why;
  if (!w.open_project(folder, &why))
    return testing::AssertionFailure() << folder.toStdString() << " did not open: " << why.toStdString();
  if (!wait_job(w))
    return testing::AssertionFailure()
           << folder.toStdString() << " not shown: " << w.last_error().toStdString();
  return testing::AssertionSuccess();
}

// Parameter `name`'s value (SI) in the window's model; -1 when it has none.
double value_of(const Workbench& w, const std::string& name) {
  for (const foxi::Parameter& p : w.model()->parameters)
    if (p.name == name) return p.value.value;
  return -1.0;
}

std::string line_after(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key);
  if (at == std::string::npos) return {};
  const std::size_t end = text.find('\n', at);
  return text.substr(at + key.size(), end - at - key.size());
}

// Pixels of `a` that differ from `b`'s (of the same size), and those not white (the model drawn).
std::pair<std::size_t, std::size_t> pixel_counts(const foxi::Framebuffer& a, const foxi::Framebuffer& b) {
  std::size_t differ = 0, coloured = 0;
  for (std::size_t i = 0; i < a.rgba.size() && i < b.rgba.size(); ++i) {
    differ += a.rgba[i] != b.rgba[i];
    coloured += a.rgba[i] != foxi::pack_rgba(255, 255, 255);
  }
  return {differ, coloured};
}

// The headless loop on a shipped model: the view's saved picture equals foxi render's picture of
// the mesh the workbench saved, with the camera it printed, pixel for pixel; its key result equals
// foxi solve's record of the same model and --set values.
// `tools`: the field tools' options (--iso, --threshold, --clip), given to both programs alike;
// `physics`: the solve's (foxi solve --physics), whose field the picture shows.
void check_headless(const std::string& model, const std::string& set, const std::string& result,
                    const std::string& shrink = "", const std::string& tools = "",
                    const std::string& physics = "thermal") {
  const std::string field = physics == "thermal"         ? "temperature"
                            : physics == "thermoelastic" ? "von_mises"
                                                         : "potential";
  const std::string shrink_option =
      (shrink.empty() ? "" : " --shrink " + shrink) + (tools.empty() ? "" : " " + tools);
  // --xray: foxi render draws the same from the opacities the workbench prints (its own options).
  const bool xray = tools.find("--xray") != std::string::npos;
  std::string cli_tools = shrink_option;
  if (xray) {
    cli_tools.erase(cli_tools.find(" --xray"), 7);
    // The printed x-ray options hold --regions themselves (pasted alone, they draw the same).
    if (const std::size_t r = cli_tools.find(" --regions "); r != std::string::npos) {
      const std::size_t end = cli_tools.find(' ', r + 11);
      cli_tools.erase(r, end == std::string::npos ? std::string::npos : end - r);
    }
  }
  TempDir dir;
  const auto view = dir.path() / "view.png", mesh = dir.path() / "mesh.vtu", shot = dir.path() / "window.png",
             cli = dir.path() / "cli.png", log = dir.path() / "wb.log";
  const std::string args = "'" + kModels + model + "' --headless --set " + set + " --physics " + physics +
                           " --view-size 320x240" + shrink_option + " --save-picture '" + view.string() +
                           "' --screenshot '" + shot.string() + "' --save-mesh '" + mesh.string() + "'";
  ASSERT_EQ(foxi::test::run("'" + std::string(FOXI_WORKBENCH_PATH) + "' " + args, log), 0)
      << foxi::test::read_text(log);
  const std::string out = foxi::test::read_text(log);
  const std::string camera = line_after(out, "camera: ");
  ASSERT_NE(camera.find("--eye"), std::string::npos) << out;
  EXPECT_TRUE(std::filesystem::file_size(shot) > 0);
  std::string field_option = " --field " + field + " --legend off";
  if (xray) {
    const std::string opacities = line_after(out, "x-ray: ");
    ASSERT_NE(opacities.find("--region-opacity"), std::string::npos) << out;
    EXPECT_NE(out.find("x-ray composited exactly"), std::string::npos) << out;
    cli_tools += " " + opacities;
    // foxi render's translucent regions take their own colours: the field only for isosurfaces.
    if (tools.find("--iso") == std::string::npos) field_option.clear();
  }
  ASSERT_EQ(foxi::test::run_cli("render '" + mesh.string() + "'" + field_option + " --size 320x240" +
                                    cli_tools + " " + camera + " -o '" + cli.string() + "'",
                                dir.path() / "render.log"),
            0)
      << foxi::test::read_text(dir.path() / "render.log");
  const foxi::Framebuffer a = foxi::read_png(view), b = foxi::read_png(cli);
  ASSERT_EQ(a.width, 320);
  ASSERT_EQ(a.height, 240);
  ASSERT_EQ(b.width, a.width);
  ASSERT_EQ(b.height, a.height);
  const auto [differ, coloured] = pixel_counts(a, b);
  EXPECT_EQ(differ, 0u);
  // The tools draw part of the model: a small picture, but not an empty one.
  EXPECT_GT(coloured, a.rgba.size() / (tools.empty() ? 10 : 100)) << "the picture shows the model";
  if (!tools.empty() && !xray) {
    // The same tets drawn as foxi render reports ("drawn N of M tets").
    std::smatch m;
    const std::string render_log = foxi::test::read_text(dir.path() / "render.log");
    const std::regex cli_drawn("drawn +([0-9]+) of ([0-9]+) tets"),
        view_drawn("view: drawn ([0-9]+) / ([0-9]+) tets");
    ASSERT_TRUE(std::regex_search(render_log, m, cli_drawn)) << render_log;
    const std::string cli_n = m[1], cli_total = m[2];
    ASSERT_TRUE(std::regex_search(out, m, view_drawn)) << out;
    EXPECT_EQ(m[1].str(), cli_n);
    EXPECT_EQ(m[2].str(), cli_total);
  }
  if (tools.find("--deform") != std::string::npos) {
    // The order method as foxi render says it: MPVO for a moved mesh that is no longer Delaunay.
    const bool cli_mpvo =
        foxi::test::read_text(dir.path() / "render.log").find("in MPVO order") != std::string::npos;
    EXPECT_EQ(out.find("MPVO order") != std::string::npos, cli_mpvo) << out;
  }

  // The same key result as foxi solve's JSON record of the model with the same --set.
  const auto json = dir.path() / "solve.json";
  ASSERT_EQ(foxi::test::run_cli("solve '" + kModels + model + "' --physics " + physics + " --set " + set +
                                    " --json '" + json.string() + "'",
                                dir.path() / "solve.log"),
            0)
      << foxi::test::read_text(dir.path() / "solve.log");
  const foxi::RunResults r = foxi::parse_results_json(foxi::test::read_text(json));
  const foxi::ResultValue* v = r.find(result);
  ASSERT_NE(v, nullptr);
  const std::string shown = line_after(out, "\n" + result + " ");
  ASSERT_FALSE(shown.empty()) << out;
  EXPECT_NEAR(std::stod(shown), v->value, 1e-5 * std::abs(v->value)) << out;
}

TEST(WorkbenchHeadless, ViewPictureEqualsFoxiRenderDieOnSubstrate) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "T_max");
}

// The flip chip with the tets shrunk (the inside shows between them): foxi render --shrink 0.7.
TEST(WorkbenchHeadless, ViewPictureEqualsFoxiRenderFlipChipShrunk) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "0.7");
}

// The view's field tools against foxi render's options of the same names: the solid above an
// isotherm, the isotherm alone, a threshold, a clip plane, and an isotherm within a clip.
TEST(WorkbenchHeadless, IsoPictureEqualsFoxiRender) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "T_max", "", "--iso 60");
}
TEST(WorkbenchHeadless, IsoOnlyPictureEqualsFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--iso 50 --iso-only");
}
TEST(WorkbenchHeadless, ThresholdPictureEqualsFoxiRender) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "T_max", "", "--threshold 30,50");
}
TEST(WorkbenchHeadless, ClipPictureEqualsFoxiRender) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "T_max", "", "--clip 0.005,0.004,0.0007,1,0.2,0");
}
TEST(WorkbenchHeadless, IsoWithinClipEqualsFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "0.8", "--iso 48 --clip 0.005,0.005,0,0,1,0");
}
// The slice (foxi render --slice): the plane's cut coloured by the field, alone and within a clip.
TEST(WorkbenchHeadless, SlicePictureEqualsFoxiRender) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "T_max", "", "--slice 0.005,0.004,0.0004,0,0.3,1");
}
TEST(WorkbenchHeadless, SliceWithinClipEqualsFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "",
                 "--slice 0.005,0.005,0,0,1,0 --clip 0.005,0.005,0,1,0,0");
}
// The x-ray (issue 23) as foxi render --region-opacity draws it from the opacities the workbench
// prints: of the regions shown (--regions), and with translucent isotherms inside (--iso-opacity 0.5).
TEST(WorkbenchHeadless, XrayOfRegionsShownEqualsFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--regions 1,3 --xray");
}
TEST(WorkbenchHeadless, XrayWithIsothermsEqualsFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--iso 47,50 --xray");
}
// Graded colouring and a user's colour range (foxi render --graded --range), alone and under an isotherm.
TEST(WorkbenchHeadless, SeveralIsovaluesEqualFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--iso 47,50");
}
TEST(WorkbenchHeadless, GradedRangePictureEqualsFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--graded --range 46,52");
}
TEST(WorkbenchHeadless, GradedIsoPictureEqualsFoxiRender) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "T_max", "", "--graded --iso 50");
}
// Regions hidden: the others shown as foxi render --regions shows them (the colour range theirs),
// alone and narrowing an isotherm.
TEST(WorkbenchHeadless, RegionsShownEqualFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--regions 1,3");
}
TEST(WorkbenchHeadless, RegionsShownWithIsoEqualFoxiRender) {
  check_headless("flip_chip.toml", "die_w=7mm", "T_max", "", "--regions 1 --iso 49");
}
// A material's box hides all its regions (multi_chip's two silicon dies): the picture equals foxi
// render --regions of the other regions, pixel for pixel with the same camera, and the region boxes
// follow; a region box unticked leaves its material's box partly ticked, ticked again all ticked.
TEST(Workbench, HidingAMaterialEqualsFoxiRenderOfTheOtherRegions) {
  TempDir dir;
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "multi_chip.toml"));
  ASSERT_TRUE(solved(w));
  ASSERT_TRUE(w.set_field("temperature"));
  if (w.busy()) {
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  }
  auto* materials = w.findChild<QListWidget*>("materials_shown");
  auto* regions = w.findChild<QListWidget*>("regions_shown");
  ASSERT_TRUE(materials && regions);
  const foxi::Mesh& mesh = *w.mesh();
  ASSERT_EQ(regions->count(), int(mesh.regions.size()));
  QListWidgetItem* silicon = nullptr;
  for (int i = 0; i < materials->count(); ++i) {
    EXPECT_EQ(materials->item(i)->checkState(), Qt::Checked);
    if (materials->item(i)->text() == "silicon") silicon = materials->item(i);
  }
  ASSERT_NE(silicon, nullptr);
  const std::uint32_t si = silicon->data(Qt::UserRole).toUInt();
  std::string others;
  int silicon_regions = 0;
  for (const foxi::Region& r : mesh.regions)
    if (r.material == si)
      ++silicon_regions;
    else
      others += (others.empty() ? "" : ",") + std::to_string(r.id);
  ASSERT_EQ(silicon_regions, 2);
  silicon->setCheckState(Qt::Unchecked);  // as a click does
  if (w.busy()) {
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  }
  // the boxes are filled again after each drawing: found by name
  auto silicon_box = [&] {
    const auto found = materials->findItems("silicon", Qt::MatchExactly);
    return found.size() == 1 ? found[0] : nullptr;
  };
  ASSERT_TRUE(silicon_box());
  EXPECT_EQ(silicon_box()->checkState(), Qt::Unchecked);
  for (int i = 0; i < regions->count(); ++i) {
    const std::int32_t id = regions->item(i)->data(Qt::UserRole).toInt();
    const bool of_silicon = std::any_of(mesh.regions.begin(), mesh.regions.end(), [&](const foxi::Region& r) {
      return r.id == id && r.material == si;
    });
    EXPECT_EQ(regions->item(i)->checkState(), of_silicon ? Qt::Unchecked : Qt::Checked) << "region " << id;
  }
  w.view_widget()->finish_now();
  const auto mesh_file = dir.path() / "mesh.vtu", view = dir.path() / "view.png",
             cli = dir.path() / "cli.png";
  foxi::write_mesh(mesh, mesh_file);
  QString why;
  ASSERT_TRUE(w.view_widget()->save_picture(QString::fromStdString(view.string()), &why))
      << why.toStdString();
  const foxi::Framebuffer a = foxi::read_png(view);
  ASSERT_EQ(
      foxi::test::run_cli("render '" + mesh_file.string() + "' --field temperature --legend off --size " +
                              std::to_string(a.width) + "x" + std::to_string(a.height) + " --regions " +
                              others + " " + w.view_widget()->camera_options() + " -o '" + cli.string() + "'",
                          dir.path() / "render.log"),
      0)
      << foxi::test::read_text(dir.path() / "render.log");
  const foxi::Framebuffer b = foxi::read_png(cli);
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  const auto [differ, coloured] = pixel_counts(a, b);
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(coloured, a.rgba.size() / 20) << "the other regions are drawn";
  // the region boxes back to the material's: one silicon region shown, silicon partly ticked
  for (int i = 0; i < regions->count(); ++i)
    if (regions->item(i)->checkState() == Qt::Unchecked) {
      regions->item(i)->setCheckState(Qt::Checked);
      break;
    }
  if (w.busy()) {
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  }
  ASSERT_TRUE(silicon_box());
  EXPECT_EQ(silicon_box()->checkState(), Qt::PartiallyChecked);
  ASSERT_TRUE(w.set_material_shown(si, true));
  if (w.busy()) {
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  }
  EXPECT_EQ(silicon_box()->checkState(), Qt::Checked);
  for (int i = 0; i < regions->count(); ++i) EXPECT_EQ(regions->item(i)->checkState(), Qt::Checked);
}

// The other physics: the potential of an electrostatic solve (its capacitance), the von Mises stress
// of a thermal stress solve (its maximum), as foxi render draws them and foxi solve gives them.
TEST(WorkbenchHeadless, ElectrostaticPictureAndCapacitanceEqualFoxi) {
  check_headless("via_in_dielectric.toml", "via_r=0.25mm", "C[via,via]", "", "", "electrostatic");
}
TEST(WorkbenchHeadless, ThermalStressPictureAndVonMisesEqualFoxi) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "von_mises_max", "", "", "thermoelastic");
}
// The deformed shape (the displacement x 300, no longer Delaunay): foxi render --deform's picture,
// the same order method said.
TEST(WorkbenchHeadless, DeformedShapeEqualsFoxiRender) {
  check_headless("die_on_substrate.toml", "die_w=5mm", "von_mises_max", "", "--deform displacement:300",
                 "thermoelastic");
}

// Save movie: the view's turning camera, frame k equal pixel for pixel to foxi movie --mode rotate's
// frame k with the camera the workbench printed, the same size and options (the CLI as the second
// program): the temperature within a threshold, and the x-ray (foxi movie --region-opacity).
void check_movie(const std::string& tools) {
  TempDir dir;
  const auto mesh = dir.path() / "mesh.vtu", log = dir.path() / "wb.log";
  const bool xray = tools.find("--xray") != std::string::npos;
  const int frames = 4;
  ASSERT_EQ(
      foxi::test::run("'" + std::string(FOXI_WORKBENCH_PATH) + "' '" + kModels +
                          "die_on_substrate.toml' --headless --physics thermal --view-size 160x120 " + tools +
                          " --save-movie '" + (dir.path() / "wb_%02d.png").string() + "' --movie-frames " +
                          std::to_string(frames) + " --save-mesh '" + mesh.string() + "'",
                      log),
      0)
      << foxi::test::read_text(log);
  const std::string out = foxi::test::read_text(log);
  const std::string camera = line_after(out, "camera: ");
  ASSERT_NE(camera.find("--eye"), std::string::npos) << out;
  std::string cli_tools = tools;
  std::string field = " --field temperature --legend off";
  if (xray) {
    cli_tools.erase(cli_tools.find("--xray"), 6);
    cli_tools += " " + line_after(out, "x-ray: ");
    field.clear();
  }
  ASSERT_EQ(foxi::test::run_cli("movie '" + mesh.string() + "'" + field + " --mode rotate --frames " +
                                    std::to_string(frames) + " --size 160x120 " + cli_tools + " " + camera +
                                    " -o '" + (dir.path() / "cli_%02d.png").string() + "'",
                                dir.path() / "movie.log"),
            0)
      << foxi::test::read_text(dir.path() / "movie.log");
  std::vector<std::uint32_t> first;
  for (int k = 0; k < frames; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "%02d.png", k);
    const foxi::Framebuffer a = foxi::read_png(dir.path() / ("wb_" + std::string(name))),
                            b = foxi::read_png(dir.path() / ("cli_" + std::string(name)));
    ASSERT_EQ(a.width, 160);
    ASSERT_EQ(a.height, 120);
    ASSERT_EQ(b.width, a.width);
    ASSERT_EQ(b.height, a.height);
    EXPECT_TRUE(a.rgba == b.rgba) << "frame " << k;
    if (k == 0) {
      first = a.rgba;
      const std::size_t coloured = std::size_t(std::count_if(
          a.rgba.begin(), a.rgba.end(), [](std::uint32_t c) { return c != foxi::pack_rgba(255, 255, 255); }));
      EXPECT_GT(coloured, a.rgba.size() / 20) << "the frame shows the model";
    }
    if (k == 1) {
      EXPECT_FALSE(a.rgba == first) << "the camera turned";
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "wb_04.png")) << "exactly the frames asked for";
}

TEST(WorkbenchHeadless, MovieFramesEqualFoxiMovie) { check_movie("--threshold 30,50"); }
TEST(WorkbenchHeadless, XrayMovieFramesEqualFoxiMovie) { check_movie("--xray"); }

// Once with a real X server (xvfb-run, Qt's xcb platform): the same view picture as offscreen.
// High-DPI: at a device pixel ratio of 2 (QT_SCALE_FACTOR) a 160 x 120 view draws a 320 x 240
// framebuffer, the same picture as a 320 x 240 view at ratio 1 (not a 160 x 120 one scaled up).
TEST(WorkbenchHeadless, HighDpiViewDrawsDevicePixels) {
  TempDir dir;
  const std::string common = "'" + std::string(FOXI_WORKBENCH_PATH) + "' '" + kModels +
                             "die_on_substrate.toml' --headless --physics thermal --save-picture ";
  const auto one = dir.path() / "one.png", two = dir.path() / "two.png";
  ASSERT_EQ(foxi::test::run("QT_SCALE_FACTOR=1 " + common + "'" + one.string() + "' --view-size 320x240",
                            dir.path() / "one.log"),
            0)
      << foxi::test::read_text(dir.path() / "one.log");
  ASSERT_EQ(foxi::test::run("QT_SCALE_FACTOR=2 " + common + "'" + two.string() + "' --view-size 160x120",
                            dir.path() / "two.log"),
            0)
      << foxi::test::read_text(dir.path() / "two.log");
  const foxi::Framebuffer a = foxi::read_png(one), b = foxi::read_png(two);
  ASSERT_EQ(a.width, 320);
  ASSERT_EQ(b.width, 320);
  ASSERT_EQ(b.height, 240);
  EXPECT_TRUE(a.rgba == b.rgba);
}

TEST(WorkbenchHeadless, UnderXvfbSamePictureAsOffscreen) {
  if (!foxi::test::have_program("xvfb-run")) GTEST_SKIP() << "xvfb-run is not installed (Debian xvfb)";
  TempDir dir;
  const std::string common =
      "'" + std::string(FOXI_WORKBENCH_PATH) + "' '" + kModels +
      "die_on_substrate.toml' --headless --physics thermal --view-size 240x180 --save-picture ";
  const auto off = dir.path() / "off.png", x11 = dir.path() / "x11.png";
  ASSERT_EQ(foxi::test::run("QT_QPA_PLATFORM=offscreen " + common + "'" + off.string() + "'",
                            dir.path() / "off.log"),
            0)
      << foxi::test::read_text(dir.path() / "off.log");
  ASSERT_EQ(
      foxi::test::run("QT_QPA_PLATFORM=xcb timeout 120 xvfb-run -a " + common + "'" + x11.string() + "'",
                      dir.path() / "x11.log"),
      0)
      << foxi::test::read_text(dir.path() / "x11.log");
  const foxi::Framebuffer a = foxi::read_png(off), b = foxi::read_png(x11);
  ASSERT_EQ(a.width, 240);
  ASSERT_EQ(b.width, 240);
  EXPECT_TRUE(a.rgba == b.rgba);
}

TEST(WorkbenchHeadless, BadParameterExitsWithBadInput) {
  TempDir dir;
  const auto log = dir.path() / "wb.log";
  EXPECT_EQ(foxi::test::run("'" + std::string(FOXI_WORKBENCH_PATH) + "' '" + kModels +
                                "die_on_substrate.toml' --headless --set die_w=3kg",
                            log),
            3);
  EXPECT_NE(foxi::test::read_text(log).find("die_w"), std::string::npos) << foxi::test::read_text(log);
  // A model with no thermal conditions: refused as bad input (3), as foxi solve refuses it, naming the file.
  std::string text = foxi::test::read_text(kModels + "die_on_substrate.toml");
  text = text.substr(0, text.find("[[conditions]]"));
  foxi::test::write_text(dir.path() / "nocond.toml", text);
  std::filesystem::copy_file(kModels + "materials.toml", dir.path() / "materials.toml");
  EXPECT_EQ(foxi::test::run("'" + std::string(FOXI_WORKBENCH_PATH) + "' '" +
                                (dir.path() / "nocond.toml").string() + "' --headless --physics thermal",
                            log),
            3);
  EXPECT_NE(foxi::test::read_text(log).find("nocond.toml"), std::string::npos) << foxi::test::read_text(log);
  EXPECT_EQ(
      foxi::test::run_cli("solve '" + (dir.path() / "nocond.toml").string() + "' --physics thermal", log), 3);
}

TEST(Workbench, ParameterEditingWithUnits) {
  Workbench w;
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
  EXPECT_DOUBLE_EQ(value_of(w, "die_w"), 0.004);
  QString error;
  // A mass where a length belongs: refused with the model library's message, nothing changes.
  EXPECT_FALSE(w.set_parameter("die_w", "3 kg", &error));
  EXPECT_TRUE(error.contains("die_w")) << error.toStdString();
  EXPECT_TRUE(error.contains("die_on_substrate.toml")) << error.toStdString();
  EXPECT_TRUE(w.overrides().empty());
  EXPECT_DOUBLE_EQ(value_of(w, "die_w"), 0.004);
  // An unknown parameter and a malformed expression: refused.
  EXPECT_FALSE(w.set_parameter("die_x", "3 mm", &error));
  EXPECT_TRUE(error.contains("die_x")) << error.toStdString();
  EXPECT_FALSE(w.set_parameter("die_w", "3 mm +", &error));
  // Units converted: 0.6 cm is 6 mm; an expression of other parameters evaluated.
  EXPECT_TRUE(w.set_parameter("die_w", "0.6 cm", &error)) << error.toStdString();
  EXPECT_NEAR(value_of(w, "die_w"), 0.006, 1e-15);
  EXPECT_TRUE(w.set_parameter("die_d", "die_w / 2", &error)) << error.toStdString();
  EXPECT_NEAR(value_of(w, "die_d"), 0.003, 1e-15);
  ASSERT_EQ(w.overrides().size(), 2u);
  // A die wider than the substrate is a model the library refuses? Not necessarily; a negative size is.
  EXPECT_FALSE(w.set_parameter("die_h", "-1 mm", &error));
  EXPECT_NEAR(value_of(w, "die_d"), 0.003, 1e-15);
}

// Save model as: the file written holds the edited values (load_model of it gives the parameters
// and parts of the source with the overrides), the workbench goes on with it and no overrides; a
// refused save (a folder that does not exist) writes nothing and keeps the state.
TEST(Workbench, SaveModelAsKeepsTheEditedValues) {
  TempDir dir;
  Workbench w;
  const std::string source = kModels + "die_on_substrate.toml";
  ASSERT_TRUE(w.open_model(QString::fromStdString(source)));
  ASSERT_TRUE(w.set_parameter("die_w", "6 mm"));
  ASSERT_TRUE(w.set_parameter("sub_h", "2 * die_h"));
  const std::vector<foxi::ParameterOverride> values = w.overrides();
  const foxi::Model expected = foxi::load_model(source, values);
  QString error;
  EXPECT_FALSE(w.save_model_file(QString::fromStdString((dir.path() / "no" / "m.toml").string()), &error));
  EXPECT_TRUE(error.contains("m.toml")) << error.toStdString();
  EXPECT_EQ(w.overrides().size(), 2u);
  const auto target = dir.path() / "m.toml";
  ASSERT_TRUE(w.save_model_file(QString::fromStdString(target.string()), &error)) << error.toStdString();
  const foxi::Model saved = foxi::load_model(target, std::span<const foxi::ParameterOverride>{});
  ASSERT_EQ(saved.parameters.size(), expected.parameters.size());
  for (std::size_t i = 0; i < saved.parameters.size(); ++i)
    EXPECT_EQ(saved.parameters[i].value.value, expected.parameters[i].value.value)
        << saved.parameters[i].name;
  ASSERT_EQ(saved.parts.size(), expected.parts.size());
  for (std::size_t i = 0; i < saved.parts.size(); ++i)
    EXPECT_EQ(saved.parts[i].prisms[0].xy, expected.parts[i].prisms[0].xy);
  EXPECT_TRUE(w.overrides().empty());
  ASSERT_TRUE(w.model());
  EXPECT_EQ(w.model()->file, target.string());
  // Save over it: the same text (nothing to change)
  const std::string text = foxi::test::read_text(target);
  EXPECT_TRUE(w.save_model_file({}, &error)) << error.toStdString();
  EXPECT_EQ(foxi::test::read_text(target), text);
}

// The model panel's exploded parts picture equals foxi model show's, pixel for pixel (the CLI as the
// second program drawing it), and follows a parameter edit.
TEST(Workbench, PartsPictureEqualsFoxiModelShow) {
  TempDir dir;
  const std::string model = kModels + "flip_chip.toml";
  const auto png = dir.path() / "show.png", log = dir.path() / "show.log";
  ASSERT_EQ(foxi::test::run_cli(
                "model show '" + model + "' --set die_w=5mm --size 320x240 -o '" + png.string() + "'", log),
            0)
      << foxi::test::read_text(log);
  const foxi::Framebuffer cli = foxi::read_png(png);
  QString error;
  const QImage image =
      Workbench::parts_picture(QString::fromStdString(model), {{"die_w", "5mm"}}, 320, 240, &error);
  ASSERT_FALSE(image.isNull()) << error.toStdString();
  ASSERT_EQ(image.width(), cli.width);
  ASSERT_EQ(image.height(), cli.height);
  const QImage rgba = image.convertToFormat(QImage::Format_RGBA8888);
  std::size_t differ = 0, coloured = 0;
  for (int y = 0; y < cli.height; ++y)
    for (int x = 0; x < cli.width; ++x) {
      std::uint32_t p;
      std::memcpy(&p, rgba.constScanLine(y) + 4 * x, 4);
      differ += p != cli.rgba[std::size_t(y) * cli.width + x];
      coloured += p != foxi::pack_rgba(255, 255, 255);
    }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(coloured, 320u * 240u / 10);  // the parts fill a good part of it
  // the panel: drawn on a worker for the model as opened, again after an edit
  Workbench w;
  ASSERT_TRUE(w.open_model(QString::fromStdString(model)));
  auto wait_pictures = [&](int n) {
    for (int i = 0; i < 600 && w.parts_pictures() < n; ++i) {
      QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
      QThread::msleep(10);
    }
    return w.parts_pictures() >= n;
  };
  ASSERT_TRUE(wait_pictures(1));
  const QImage first = w.shown_parts_picture();
  ASSERT_FALSE(first.isNull());
  ASSERT_TRUE(w.set_parameter("die_w", "5mm"));
  ASSERT_TRUE(wait_pictures(2));
  EXPECT_NE(w.shown_parts_picture(), first);
}

// Editing the table's cell as a user does: a refused value's message shows next to the table (the
// label under it, the row selected) and the cell goes back to the accepted expression.
TEST(Workbench, ParameterTableCellEdit) {
  Workbench w;
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
  QTableWidget* table = w.findChild<QTableWidget*>("parameters");
  QLabel* message = w.findChild<QLabel*>("parameter_error");
  ASSERT_NE(table, nullptr);
  ASSERT_NE(message, nullptr);
  int row = -1;
  for (int r = 0; r < table->rowCount(); ++r)
    if (table->item(r, 0)->text() == "die_w") row = r;
  ASSERT_GE(row, 0);
  table->item(row, 1)->setText("4 s");  // a time for a length
  QApplication::processEvents();        // the edit is checked once the table's signal returns
  EXPECT_TRUE(message->text().contains("die_w")) << message->text().toStdString();
  EXPECT_EQ(table->item(row, 1)->text(), "4 mm");
  EXPECT_TRUE(w.overrides().empty());
  table->item(row, 1)->setText("4.5 mm");
  QApplication::processEvents();
  EXPECT_TRUE(message->text().isEmpty()) << message->text().toStdString();
  ASSERT_EQ(w.overrides().size(), 1u);
  EXPECT_EQ(w.overrides()[0].expression, "4.5 mm");
  for (int r = 0; r < table->rowCount(); ++r)
    if (table->item(r, 0)->text() == "die_w") {
      EXPECT_EQ(table->item(r, 2)->text(), "0.0045 m");
    }
}

TEST(Workbench, UndoRedoOfParameterEdits) {
  Workbench w;
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
  EXPECT_FALSE(w.undo());
  ASSERT_TRUE(w.set_parameter("die_w", "5 mm"));
  ASSERT_TRUE(w.set_parameter("die_d", "2 mm"));
  EXPECT_FALSE(w.set_parameter("die_d", "2 K"));  // refused: not an edit to undo
  EXPECT_TRUE(w.undo());
  EXPECT_NEAR(value_of(w, "die_d"), 0.003, 1e-15);
  EXPECT_NEAR(value_of(w, "die_w"), 0.005, 1e-15);
  EXPECT_TRUE(w.undo());
  EXPECT_NEAR(value_of(w, "die_w"), 0.004, 1e-15);
  EXPECT_TRUE(w.overrides().empty());
  EXPECT_FALSE(w.undo());
  EXPECT_TRUE(w.redo());
  EXPECT_NEAR(value_of(w, "die_w"), 0.005, 1e-15);
  ASSERT_TRUE(w.set_parameter("sub_h", "2 mm"));  // a new edit: nothing left to redo
  EXPECT_FALSE(w.redo());
  EXPECT_NEAR(value_of(w, "sub_h"), 0.002, 1e-15);
}

// Only what changed reruns: Solve after a parameter change remeshes first (the mesh of the new
// parameters, as mesh_model gives it here), Solve again on the same parameters does not.
// The history plot: its points are the history's values (x the parameter as the model evaluates the
// row's overrides, y the row's result), a meshed-only row left out; the chart puts them left to right
// in x order and higher for larger values.
TEST(Workbench, HistoryPlotPointsAreTheHistorysValues) {
  Workbench w;
  const std::string model = kModels + "die_on_substrate.toml";
  ASSERT_TRUE(open_window(w, model, {200, 150}, Shown::no));
  ASSERT_TRUE(w.set_parameter("die_w", "6 mm"));
  ASSERT_TRUE(solved(w));
  ASSERT_TRUE(w.set_parameter("die_w", "die_d"));  // 3 mm, an expression
  ASSERT_TRUE(meshed(w));                          // meshed only: no results, not plotted
  ASSERT_TRUE(w.set_parameter("die_w", "2 mm"));
  ASSERT_TRUE(solved(w));
  ASSERT_EQ(w.history().size(), 3u);
  const std::vector<std::string> names = foxi::workbench::history_results(w.history());
  ASSERT_FALSE(names.empty());
  for (const std::string& name : names) {
    const auto points = foxi::workbench::history_points(model, w.history(), "die_w", name);
    ASSERT_EQ(points.rows, (std::vector<std::size_t>{0, 2})) << name;
    EXPECT_DOUBLE_EQ(points.x[0], 0.006);
    EXPECT_DOUBLE_EQ(points.x[1], 0.002);
    for (std::size_t k = 0; k < 2; ++k)
      for (const foxi::ResultValue& v : w.history()[points.rows[k]].results.values)
        if (v.name == name) {
          EXPECT_EQ(points.y[k], v.value) << name;
        }
  }
  const auto points = foxi::workbench::history_points(model, w.history(), "die_w", names[0]);
  std::vector<std::pair<int, int>> pixels;
  const QImage chart = foxi::workbench::history_chart(points, "die_w", names[0], 480, 320, &pixels);
  ASSERT_FALSE(chart.isNull());
  ASSERT_EQ(pixels.size(), 2u);
  EXPECT_GT(pixels[0].first, pixels[1].first);  // 6 mm right of 2 mm
  if (points.y[0] != points.y[1]) {
    EXPECT_EQ(points.y[0] > points.y[1], pixels[0].second < pixels[1].second);
  }
  const QRgb marker = chart.pixel(pixels[0].first, pixels[0].second);
  EXPECT_NE(marker, qRgb(255, 255, 255));  // a marker is drawn there
}

TEST(Workbench, SolveRemeshesWhenParametersChanged) {
  Workbench w;
  const std::string model = kModels + "die_on_substrate.toml";
  ASSERT_TRUE(open_window(w, model, {200, 150}, Shown::no));
  ASSERT_TRUE(meshed(w));
  const auto first = w.mesh();
  ASSERT_TRUE(w.set_parameter("die_w", "7 mm"));
  ASSERT_TRUE(solved(w));
  const std::vector<foxi::ParameterOverride> ov = {{"die_w", "7 mm"}};
  const foxi::MeshedModel direct = foxi::mesh_model(model, ov);
  EXPECT_EQ(w.mesh()->tet_count(), direct.mesh.tet_count());
  EXPECT_TRUE(w.mesh()->xyz == direct.mesh.xyz);
  ASSERT_NE(w.results(), nullptr);
  ASSERT_EQ(w.history().size(), 2u);
  EXPECT_EQ(w.history()[1].tets, direct.mesh.tet_count());
  const auto second = w.mesh();
  ASSERT_TRUE(solved(w));
  EXPECT_TRUE(w.mesh()->xyz == second->xyz) << "same parameters: solved on the same mesh";
  EXPECT_EQ(w.history().size(), 3u);  // a solve of an already solved mesh: a row of its own
  (void)first;
}

TEST(Workbench, CancelKeepsThePreviousMeshAndPicture) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(meshed(w));
  const std::shared_ptr<const foxi::Mesh> first = w.mesh();
  ASSERT_TRUE(first);
  const std::size_t tets = first->tet_count();
  ASSERT_TRUE(w.set_parameter("die_w", "6 mm"));
  ASSERT_TRUE(w.start_mesh());
  EXPECT_FALSE(w.start_mesh()) << "one job at a time";
  w.cancel();
  EXPECT_FALSE(wait_job(w));
  EXPECT_EQ(w.last_error(), "cancelled");
  EXPECT_EQ(w.mesh(), first);
  EXPECT_EQ(w.mesh()->tet_count(), tets);
  EXPECT_EQ(w.view_widget()->mesh(), first) << "the view still shows the previous mesh";
  // Solving, cancelled: no results, the mesh unchanged.
  ASSERT_TRUE(w.start_solve());
  w.cancel();
  EXPECT_FALSE(wait_job(w));
  EXPECT_EQ(w.results(), nullptr);
  EXPECT_EQ(w.mesh(), first);
  // And the next mesh goes through: a wider die, another mesh.
  ASSERT_TRUE(meshed(w));
  EXPECT_NE(w.mesh(), first);
  ASSERT_TRUE(solved(w));
  ASSERT_NE(w.results(), nullptr);
  ASSERT_EQ(w.history().size(), 2u);  // first mesh (meshed only); second mesh with its solve
  EXPECT_TRUE(w.history()[0].results.values.empty());
  EXPECT_NE(w.history()[1].results.find("T_max"), nullptr);
  ASSERT_EQ(w.history()[1].parameters.size(), 1u);
  EXPECT_EQ(w.history()[1].parameters[0].expression, "6 mm");
}

// The mesh panel: a per-part size typed into its table and CGAL chosen in its combo box reach
// mesh_model's options; the mesh the workbench makes is the one mesh_model makes with those options
// (the library as the second caller), certified by the weighted certificate computed here, and the
// quality report says CGAL. Values mesh_model refuses are refused as set, the settings kept.
TEST(Workbench, MeshPanelPartSizeAndCgal) {
  Workbench w;
  const std::string model = kModels + "die_on_substrate.toml";
  ASSERT_TRUE(open_window(w, model, {200, 150}, Shown::no));
  auto* parts = w.findChild<QTableWidget*>("part_sizes");
  auto* mesher = w.findChild<QComboBox*>("mesher");
  ASSERT_TRUE(parts && mesher);
  int die_row = -1;
  for (int r = 0; r < parts->rowCount(); ++r)
    if (parts->item(r, 0)->text() == "die") die_row = r;
  ASSERT_GE(die_row, 0);
  EXPECT_EQ(parts->item(die_row, 2)->text(), "0.5 mm") << "the model's own part size shown";
  parts->item(die_row, 1)->setText("0.4 mm");
  mesher->setCurrentIndex(1);
  ASSERT_EQ(w.mesh_settings().mesher, foxi::Mesher::cgal);
  ASSERT_EQ(w.mesh_settings().part_sizes.size(), 1u);
  EXPECT_EQ(w.mesh_settings().part_sizes[0].part, "die");
  EXPECT_NEAR(w.mesh_settings().part_sizes[0].max_size, 0.4e-3, 1e-15);
  ASSERT_TRUE(meshed(w));
  foxi::ModelMeshOptions o;
  o.mesher = foxi::Mesher::cgal;
  o.part_sizes = {{.part = "die", .max_size = 0.4e-3}};
  const foxi::MeshedModel direct = foxi::mesh_model(model, {}, o);
  ASSERT_TRUE(w.mesh());
  EXPECT_EQ(w.mesh()->tet_count(), direct.mesh.tet_count());
  EXPECT_TRUE(w.mesh()->xyz == direct.mesh.xyz);
  EXPECT_TRUE(w.mesh()->weight == direct.mesh.weight);
  EXPECT_TRUE(foxi::compute_delaunay_certificate(*w.mesh()).delaunay);
  const std::string report = w.findChild<QPlainTextEdit*>("quality_report")->toPlainText().toStdString();
  EXPECT_NE(report.find("mesher: CGAL Mesh_3"), std::string::npos) << report;
  EXPECT_NE(report.find("delaunay: yes"), std::string::npos) << report;
  EXPECT_NE(report.find("min dihedral histogram"), std::string::npos) << report;

  // A box row with CGAL (through the panel's table, in mm): the mesh is mesh_model's with that box,
  // certified, with more tets than without it.
  auto* add = w.findChild<QPushButton*>("add_box");
  auto* boxes = w.findChild<QTableWidget*>("refine_boxes");
  ASSERT_TRUE(add && boxes);
  add->click();
  ASSERT_EQ(boxes->rowCount(), 1);
  boxes->item(0, 3)->setText("2");  // x1 = 2 mm: the substrate's end, away from the die
  boxes->item(0, 6)->setText("0.3");
  ASSERT_EQ(w.mesh_settings().mesher, foxi::Mesher::cgal);
  ASSERT_EQ(w.mesh_settings().boxes.size(), 1u) << "a box row is taken with CGAL";
  ASSERT_TRUE(meshed(w));
  o.sizes.boxes = w.mesh_settings().boxes;
  EXPECT_NEAR(o.sizes.boxes[0].hi[0], 2e-3, 1e-15);
  EXPECT_NEAR(o.sizes.boxes[0].size, 0.3e-3, 1e-15);
  const foxi::MeshedModel boxed = foxi::mesh_model(model, {}, o);
  EXPECT_EQ(boxed.cgal.boxes, 1u);
  ASSERT_TRUE(w.mesh());
  EXPECT_TRUE(w.mesh()->xyz == boxed.mesh.xyz);
  EXPECT_TRUE(w.mesh()->tet == boxed.mesh.tet);
  EXPECT_GT(w.mesh()->tet_count(), direct.mesh.tet_count() + direct.mesh.tet_count() / 2);
  EXPECT_TRUE(foxi::compute_delaunay_certificate(*w.mesh()).delaunay);
  const std::string boxed_report =
      w.findChild<QPlainTextEdit*>("quality_report")->toPlainText().toStdString();
  EXPECT_NE(boxed_report.find("refinement boxes: 1"), std::string::npos) << boxed_report;

  // Cancel of a CGAL run: the CGAL mesh stays.
  const auto first = w.mesh();
  foxi::workbench::MeshSettings fine = w.mesh_settings();
  fine.max_size = 0.1e-3;
  ASSERT_TRUE(w.set_mesh_settings(fine));
  ASSERT_TRUE(w.start_mesh());
  w.cancel();
  EXPECT_FALSE(wait_job(w));
  EXPECT_EQ(w.last_error(), "cancelled");
  EXPECT_EQ(w.mesh(), first);
  EXPECT_EQ(w.view_widget()->mesh(), first);
}

// Refinement box rows: Add puts the shown mesh's bounds with a tenth of its diagonal, a size typed in
// the model's unit (mm) becomes metres, Remove takes the row away; the mesh made with the box has
// more tets than without.
TEST(Workbench, MeshPanelBoxRowsAddAndRemove) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(meshed(w));
  const std::size_t plain = w.mesh()->tet_count();
  auto* add = w.findChild<QPushButton*>("add_box");
  auto* remove = w.findChild<QPushButton*>("remove_box");
  auto* boxes = w.findChild<QTableWidget*>("refine_boxes");
  ASSERT_TRUE(add && remove && boxes);
  add->click();
  ASSERT_EQ(w.mesh_settings().boxes.size(), 1u);
  ASSERT_EQ(boxes->rowCount(), 1);
  const foxi::RefinementBox& b = w.mesh_settings().boxes[0];
  EXPECT_NEAR(b.hi[0] - b.lo[0], 10e-3, 1e-12) << "the substrate's width";
  EXPECT_NEAR(b.hi[2] - b.lo[2], 1.5e-3, 1e-12) << "substrate and die";
  boxes->item(0, 3)->setText("2");  // x1 = 2 mm: the box's corner by the substrate's edge
  boxes->item(0, 6)->setText("0.25");
  ASSERT_EQ(w.mesh_settings().boxes.size(), 1u);
  EXPECT_NEAR(w.mesh_settings().boxes[0].hi[0], 2e-3, 1e-15);
  EXPECT_NEAR(w.mesh_settings().boxes[0].size, 0.25e-3, 1e-15);
  ASSERT_TRUE(meshed(w));
  EXPECT_GT(w.mesh()->tet_count(), plain);
  boxes->setCurrentCell(0, 0);
  remove->click();
  EXPECT_TRUE(w.mesh_settings().boxes.empty());
  EXPECT_EQ(boxes->rowCount(), 0);
}

// Refine from the current result: after a solve, the next mesh takes its sizes from the solved
// temperature's error; it equals mesh_model's with the same solved mesh, field and target, and has
// more tets than the mesh solved on. Without a result a Mesh fails with the reason, and a Solve
// meshes as the model says.
TEST(Workbench, MeshPanelRefinesFromTheResult) {
  Workbench w;
  const std::string model = kModels + "die_on_substrate.toml";
  ASSERT_TRUE(open_window(w, model, {200, 150}, Shown::no));
  foxi::workbench::MeshSettings s = w.mesh_settings();
  s.refine_from_result = true;
  s.target_error = 0.3;
  ASSERT_TRUE(w.set_mesh_settings(s));
  ASSERT_TRUE(w.start_mesh());
  EXPECT_FALSE(wait_job(w));
  EXPECT_NE(w.last_error().toStdString().find("no solved result"), std::string::npos)
      << w.last_error().toStdString();
  // A solve with no result to refine from meshes from the model's sizes (its mesh_model mesh).
  ASSERT_TRUE(solved(w));
  const std::shared_ptr<const foxi::Mesh> solved = w.mesh();
  EXPECT_TRUE(solved->xyz == foxi::mesh_model(model).mesh.xyz);
  s.refine_from_result = false;
  ASSERT_TRUE(w.set_mesh_settings(s));
  ASSERT_NE(solved->find_field("temperature"), nullptr);
  auto* refine = w.findChild<QCheckBox*>("refine_from_result");
  ASSERT_NE(refine, nullptr);
  refine->setChecked(true);  // through the panel's check box
  ASSERT_TRUE(w.mesh_settings().refine_from_result);
  ASSERT_TRUE(meshed(w));
  foxi::ModelMeshOptions o;
  o.refine_from = {.mesh = solved.get(), .field = "temperature", .target_error = 0.3};
  const foxi::MeshedModel direct = foxi::mesh_model(model, {}, o);
  EXPECT_EQ(w.mesh()->tet_count(), direct.mesh.tet_count());
  EXPECT_TRUE(w.mesh()->xyz == direct.mesh.xyz);
  EXPECT_GT(w.mesh()->tet_count(), solved->tet_count());
  const std::string report = w.findChild<QPlainTextEdit*>("quality_report")->toPlainText().toStdString();
  EXPECT_NE(report.find("refined from the result's 'temperature'"), std::string::npos) << report;
}

// Solve with another physics: every value and check of the results table equals foxi solve --json's
// record of the same model and override (a second program on the same mesh_model mesh); Cancel of
// a later solve keeps those results, the mesh and the history; a saved project keeps the physics.
TEST(Workbench, PhysicsResultsEqualFoxiSolveAndCancelKeepsThem) {
  struct Case {
    const char* model;
    const char* name;
    const char* value;
    foxi::Physics physics;
  };
  for (const Case& c : {Case{"die_on_substrate.toml", "die_w", "7 mm", foxi::Physics::thermal_stress},
                        Case{"via_in_dielectric.toml", "via_r", "0.25 mm", foxi::Physics::electrostatic}}) {
    SCOPED_TRACE(c.model);
    TempDir dir;
    Workbench w;
    ASSERT_TRUE(open_window(w, kModels + c.model, {200, 150}, Shown::no));
    ASSERT_TRUE(w.set_parameter(c.name, c.value));
    ASSERT_TRUE(w.set_physics(c.physics));
    ASSERT_TRUE(w.start_solve());
    EXPECT_FALSE(w.set_physics(foxi::Physics::thermal)) << "not while a job runs";
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
    ASSERT_NE(w.results(), nullptr);
    const foxi::RunResults got = *w.results();
    const auto json = dir.path() / "solve.json";
    ASSERT_EQ(
        foxi::test::run_cli("solve '" + kModels + c.model + "' --physics " + foxi::physics_name(c.physics) +
                                " --set '" + c.name + "=" + c.value + "' --json '" + json.string() + "'",
                            dir.path() / "solve.log"),
        0)
        << foxi::test::read_text(dir.path() / "solve.log");
    const foxi::RunResults cli = foxi::parse_results_json(foxi::test::read_text(json));
    EXPECT_EQ(got.physics, cli.physics);
    EXPECT_EQ(got.tets, cli.tets);
    EXPECT_EQ(got.nodes, cli.nodes);
    ASSERT_EQ(got.values.size(), cli.values.size());
    for (std::size_t i = 0; i < cli.values.size(); ++i) {
      EXPECT_EQ(got.values[i].name, cli.values[i].name);
      EXPECT_NEAR(got.values[i].value, cli.values[i].value, 1e-9 * std::abs(cli.values[i].value))
          << cli.values[i].name;
    }
    ASSERT_EQ(got.checks.size(), cli.checks.size());
    for (std::size_t i = 0; i < cli.checks.size(); ++i) {
      EXPECT_EQ(got.checks[i].name, cli.checks[i].name);
      EXPECT_EQ(got.checks[i].passed, cli.checks[i].passed) << cli.checks[i].name;
    }
    // The picture shows the solve's field.
    const std::string shown = c.physics == foxi::Physics::thermal_stress ? "von_mises" : "potential";
    ASSERT_NE(w.mesh()->find_field(shown), nullptr);
    // The deformed shape: the view shows a moved copy, the solved mesh stays; off again: the mesh itself.
    const auto mesh = w.mesh();
    if (c.physics == foxi::Physics::thermal_stress) {
      ASSERT_TRUE(w.set_deform(foxi::workbench::Deform{"displacement", 100}));
      ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
      EXPECT_EQ(w.mesh(), mesh);
      ASSERT_NE(w.view_widget()->mesh(), mesh);
      EXPECT_EQ(w.view_widget()->mesh()->tet_count(), mesh->tet_count());
      EXPECT_NE(w.view_widget()->mesh()->xyz, mesh->xyz);
      ASSERT_TRUE(w.set_deform(std::nullopt));
      ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
      EXPECT_EQ(w.view_widget()->mesh(), mesh);
      // A scale that folds tets through each other: refused with the reason, the picture stays.
      ASSERT_TRUE(w.set_deform(foxi::workbench::Deform{"displacement", 5000}));
      EXPECT_FALSE(wait_job(w));
      EXPECT_NE(w.last_error().indexOf("not usable"), -1) << w.last_error().toStdString();
      EXPECT_EQ(w.view_widget()->mesh(), mesh);
      EXPECT_FALSE(w.deform().has_value()) << "the shape shown before stays the workbench's";
    } else {
      EXPECT_FALSE(w.set_deform(foxi::workbench::Deform{"displacement", 300}) && wait_job(w))
          << "no displacement field: refused";
    }
    // A thermal solve started and cancelled: the results, mesh and history stay.
    const std::size_t rows = w.history().size();
    ASSERT_TRUE(w.set_physics(foxi::Physics::thermal));
    ASSERT_TRUE(w.start_solve());
    w.cancel();
    EXPECT_FALSE(wait_job(w));
    EXPECT_EQ(w.last_error(), "cancelled");
    ASSERT_NE(w.results(), nullptr);
    EXPECT_EQ(w.results()->physics, cli.physics);
    EXPECT_EQ(w.results()->values.size(), got.values.size());
    EXPECT_EQ(w.mesh(), mesh);
    EXPECT_EQ(w.history().size(), rows);
    // A project keeps the physics chosen and the results.
    const QString folder = QString::fromStdString((dir.path() / "project").string());
    ASSERT_TRUE(w.set_physics(c.physics));
    ASSERT_TRUE(w.save_project(folder));
    Workbench again;
    ASSERT_TRUE(again.open_project(folder));
    EXPECT_EQ(again.physics(), c.physics);
    ASSERT_NE(again.results(), nullptr);
    EXPECT_EQ(again.results()->physics, cli.physics);
    wait_job(again);
  }
}

// The isovalue slider moves the isotherm both ways: each position draws the solid above its value,
// which holds the tets with a corner at or above it (counted here from the mesh's node values), and
// moving back gives the same picture again.
TEST(Workbench, IsoSliderMovesTheIsovalueBothWays) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(solved(w));
  ASSERT_TRUE(w.iso_slider()->isEnabled()) << "the temperature is shown: the tools are on";
  const foxi::Mesh& mesh = *w.mesh();
  const foxi::Field* t = nullptr;
  for (const foxi::Field& f : mesh.fields)
    if (f.name == "temperature") t = &f;
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->location, foxi::FieldLocation::node);
  const std::span<const double> node = t->step(t->step_count() - 1, mesh.node_count());
  double lo = INFINITY, hi = -INFINITY;
  for (double v : node) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_DOUBLE_EQ(w.field_lo(), lo);
  EXPECT_DOUBLE_EQ(w.field_hi(), hi);
  auto reaching = [&](double v) {
    std::size_t n = 0;
    for (std::size_t e = 0; e < mesh.tet_count(); ++e) {
      bool any = false;
      for (int k = 0; k < 4; ++k) any |= node[mesh.tet[4 * e + std::size_t(k)]] >= v;
      n += any;
    }
    return n;
  };
  foxi::FieldSelection s;
  s.iso = {0.5 * (lo + hi)};
  ASSERT_TRUE(w.set_selection(s));
  EXPECT_EQ(w.iso_slider()->value(), 500);
  foxi::qt::ViewWidget* v = w.view_widget();
  auto at = [&](int pos) {
    w.iso_slider()->setValue(pos);
    const double iso = lo + (hi - lo) * pos / 1000.0;
    EXPECT_EQ(v->selection().iso.size(), 1u);
    EXPECT_DOUBLE_EQ(v->selection().iso.at(0), iso);
    EXPECT_EQ(v->selected_tets(), reaching(iso)) << "slider at " << pos;
    v->finish_now();
    EXPECT_EQ(v->view()->drawn().size(), reaching(iso));
    return v->view()->framebuffer().id;
  };
  const auto low = at(200);
  const std::size_t low_count = v->selected_tets();
  at(800);
  EXPECT_LT(v->selected_tets(), low_count) << "a hotter isotherm: a smaller solid";
  EXPECT_GT(v->selected_tets(), 0u);
  EXPECT_TRUE(at(200) == low) << "back down: the same picture";
  // Several isovalues: the box's (display unit, as typed) drawn with the slider's; a word refused.
  const double extra = lo + 0.8 * (hi - lo);
  w.more_isovalues()->setText(QString::number(w.display_unit().to_display(extra), 'g', 17));
  emit w.more_isovalues()->editingFinished();
  ASSERT_EQ(v->selection().iso.size(), 2u);
  EXPECT_NEAR(v->selection().iso[0], lo + 0.2 * (hi - lo), 1e-9 * hi);
  EXPECT_NEAR(v->selection().iso[1], extra, 1e-9 * hi);
  EXPECT_EQ(w.selection().iso, v->selection().iso);
  w.more_isovalues()->setText("hot");
  emit w.more_isovalues()->editingFinished();
  EXPECT_EQ(v->selection().iso.size(), 2u) << "refused: the selection stays";
  // Off again: all tets.
  ASSERT_TRUE(w.set_selection({}));
  v->finish_now();
  EXPECT_EQ(v->view()->drawn().size(), mesh.tet_count());
  // Refused: a zero clip normal; the selection stays as it was.
  foxi::FieldSelection bad;
  bad.clip = foxi::Plane{{0, 0, 0}, {0, 0, 0}};
  QString why;
  EXPECT_FALSE(w.set_selection(bad, &why));
  EXPECT_FALSE(why.isEmpty());
  EXPECT_FALSE(v->selection().any());
}

// The view's X-ray and volume (issue 23 item 3): the x-ray equals draw_translucent_picture with the
// same default opacities (default_xray) and the same camera, pixel for pixel; undrawing part of it
// and drawing on gives the same picture again; the volume needs the field shown and says it is exact.
TEST(Workbench, XrayAndVolumeInTheView) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(solved(w));
  foxi::qt::ViewWidget* v = w.view_widget();
  const foxi::Mesh& mesh = *w.mesh();
  ASSERT_TRUE(v->set_xray(true));
  v->finish_now();
  EXPECT_TRUE(v->view()->translucent());
  EXPECT_NE(v->view()->status().find("x-ray composited exactly"), std::string::npos) << v->view()->status();
  const foxi::Framebuffer xray = v->view()->framebuffer();
  foxi::TranslucentParams tp;
  tp.region_opacity = foxi::default_xray(mesh);
  ASSERT_GE(tp.region_opacity.size(), 1u);
  foxi::Framebuffer ref(xray.width, xray.height);
  const foxi::SphereTable table = foxi::compute_spheres(mesh);
  ASSERT_TRUE(foxi::draw_translucent_picture(mesh, table, v->view()->camera(), ref, {}, tp).exact_order);
  EXPECT_TRUE(ref.rgba == xray.rgba) << "the x-ray is the one-call picture";
  ASSERT_TRUE(v->view()->set_undrawing(true));
  const std::size_t n = v->view()->drawn().size();
  EXPECT_EQ(v->view()->undraw(n / 2), n / 2);
  EXPECT_FALSE(v->view()->framebuffer().rgba == xray.rgba);
  v->view()->set_undrawing(false);
  v->finish_now();
  EXPECT_TRUE(v->view()->framebuffer().rgba == xray.rgba) << "drawn on again";
  ASSERT_TRUE(v->set_volume(true));
  v->finish_now();
  EXPECT_TRUE(v->view()->volume());
  EXPECT_NE(v->view()->status().find("volume composited exactly"), std::string::npos) << v->view()->status();
  ASSERT_TRUE(v->set_volume(false));
  EXPECT_FALSE(v->view()->volume());
}

// Translucency and selections together (issue 23): the X-ray and volume check boxes always show what
// the view draws. An isotherm with the x-ray on stays translucent (the x-ray's isosurfaces); what
// foxi render does not combine with it (a threshold, clip or slice; any selection with the volume; a
// region of interest taken from the x-ray's surface tets) is refused with a reason and changes
// nothing; volume and x-ray exclude each other; a recolour keeps the volume, colouring by regions
// ends it. A region of interest pushed with the x-ray off is what the x-ray then shows: the one-call
// picture of that subset (draw_translucent_picture, the same camera), pixel for pixel.
TEST(Workbench, XrayVolumeAndSelectionsStayInSync) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(solved(w));
  foxi::qt::ViewWidget* v = w.view_widget();
  auto* xray_box = w.findChild<QCheckBox*>("xray");
  auto* volume_box = w.findChild<QCheckBox*>("volume");
  ASSERT_NE(xray_box, nullptr);
  ASSERT_NE(volume_box, nullptr);
  auto in_sync = [&](const char* when) {
    EXPECT_EQ(xray_box->isChecked(), v->view()->translucent()) << when;
    EXPECT_EQ(volume_box->isChecked(), v->view()->volume()) << when;
    EXPECT_EQ(v->xray(), v->view()->translucent()) << when;
    EXPECT_EQ(v->volume(), v->view()->volume()) << when;
  };
  xray_box->click();
  EXPECT_TRUE(v->view()->translucent());
  in_sync("x-ray on");
  foxi::FieldSelection iso;
  iso.iso = {0.5 * (w.field_lo() + w.field_hi())};
  QString why;
  ASSERT_TRUE(w.set_selection(iso, &why)) << why.toStdString();
  EXPECT_TRUE(v->view()->translucent()) << "the isotherm drawn translucent inside the x-ray";
  ASSERT_NE(v->xray_params(), nullptr);
  EXPECT_EQ(v->xray_params()->iso.values, iso.iso);
  in_sync("isotherm with the x-ray");
  foxi::FieldSelection threshold;
  threshold.threshold = {w.field_lo(), w.field_hi()};
  why.clear();
  EXPECT_FALSE(w.set_selection(threshold, &why));
  EXPECT_NE(why.indexOf("x-ray"), -1) << why.toStdString();
  EXPECT_EQ(v->selection().iso, iso.iso) << "refused: the isotherm stays";
  foxi::FieldSelection slice;
  slice.slice = foxi::Plane{{0.005, 0.004, 0.0004}, {0, 0, 1}};
  EXPECT_FALSE(w.set_selection(slice));
  in_sync("threshold and slice refused");
  v->finish_now();
  why.clear();
  EXPECT_FALSE(v->push_region(&why));
  EXPECT_NE(why.indexOf("x-ray off"), -1) << why.toStdString();
  EXPECT_EQ(v->view()->region_depth(), 0u);
  volume_box->click();  // refused: the isotherm is on
  EXPECT_FALSE(v->view()->volume());
  in_sync("volume refused with a selection");
  ASSERT_TRUE(w.set_selection({}));
  EXPECT_TRUE(v->view()->translucent()) << "the selection off: the x-ray stays";
  volume_box->click();
  EXPECT_TRUE(v->view()->volume());
  EXPECT_FALSE(xray_box->isChecked()) << "one at a time";
  in_sync("volume replaces the x-ray");
  EXPECT_FALSE(w.set_selection(iso));
  in_sync("a selection refused with the volume");
  ASSERT_TRUE(w.set_field("temperature", "coolwarm"));  // a new view (recolour): the volume follows
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  EXPECT_TRUE(v->view()->volume());
  in_sync("recoloured");
  ASSERT_TRUE(w.set_field("", "viridis"));  // coloured by region: no field for the volume
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  EXPECT_FALSE(v->view()->volume());
  in_sync("by region");
  EXPECT_FALSE(volume_box->isEnabled()) << "no field shown: nothing to render";
  EXPECT_TRUE(xray_box->isEnabled());
  // A region of interest first, then the x-ray of it.
  v->finish_now();
  v->set_fraction(0.3);
  for (int i = 0; i < 100000 && v->busy(); ++i) QApplication::processEvents();
  std::vector<std::uint32_t> region = v->view()->drawn();
  ASSERT_FALSE(region.empty());
  ASSERT_TRUE(v->push_region(&why)) << why.toStdString();
  xray_box->click();
  ASSERT_TRUE(v->view()->translucent());
  v->finish_now();
  std::sort(region.begin(), region.end());
  foxi::TranslucentParams tp;
  tp.region_opacity = foxi::default_xray(*w.mesh());
  const foxi::Framebuffer& got = v->view()->framebuffer();
  foxi::Framebuffer ref(got.width, got.height);
  ASSERT_TRUE(foxi::draw_translucent_picture(*w.mesh(), foxi::compute_spheres(*w.mesh()), *v->camera(), ref,
                                             region, tp)
                  .exact_order);
  EXPECT_TRUE(ref.rgba == got.rgba) << "the x-ray of the region of interest";
  ASSERT_TRUE(v->pop_region());
  EXPECT_TRUE(v->view()->translucent()) << "back to all tets: still the x-ray";
  in_sync("region popped");
}

// A 1366 x 768 laptop screen: the window fits it (the view's rows of controls, about 800 pixels
// wide, set the window's least width at 1670 pixels with the side panels), the rows scroll sideways,
// and every one of their buttons can be scrolled into sight. At the default size (1680 wide) the rows
// need no scrolling. Screenshots into $FOXI_WALKTHROUGH_DIR when set.
TEST(Workbench, FitsALaptopScreenWithItsControlsScrolled) {
  Workbench w;
  w.show();
  QString why;
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml"), &why))
      << why.toStdString();
  ASSERT_TRUE(meshed(w));
  QApplication::processEvents();
  auto* controls = w.findChild<QScrollArea*>("view_controls");
  ASSERT_NE(controls, nullptr);
  EXPECT_EQ(controls->horizontalScrollBar()->maximum(), 0) << "scrolled at the default width " << w.width();
  w.resize(1366, 740);
  for (int i = 0; i < 20; ++i) QApplication::processEvents();
  EXPECT_LE(w.minimumSizeHint().width(), 1366);
  EXPECT_LE(w.width(), 1366);
  EXPECT_GT(controls->horizontalScrollBar()->maximum(), 0) << "nothing to scroll at " << w.width();
  // The rows keep their whole height: the scroll bar below them, not over them.
  EXPECT_GE(controls->viewport()->height(), controls->widget()->minimumSizeHint().height());
  const QList<QPushButton*> buttons = controls->widget()->findChildren<QPushButton*>();
  EXPECT_GE(buttons.size(), 9);
  for (QPushButton* b : buttons) {
    if (!b->isVisibleTo(controls->widget())) continue;
    controls->ensureWidgetVisible(b, 0, 0);
    QApplication::processEvents();
    const QRect in_viewport(b->mapTo(controls->viewport(), QPoint(0, 0)), b->size());
    EXPECT_TRUE(controls->viewport()->rect().contains(in_viewport)) << b->text().toStdString();
  }
  if (const char* keep = std::getenv("FOXI_WALKTHROUGH_DIR"); keep && *keep)
    w.grab().save(QString::fromStdString((std::filesystem::path(keep) / "laptop-1366.png").string()));
}

// Issue 21's "Done when", step by step as a new user does it, without the command line: open the flip
// chip, change the die size, remesh, solve the thermal problem, look inside (draw, stop, undraw, a
// region of interest, an isotherm), compare two runs in the history, save the picture. Each step is
// asserted on what the window shows, and a screenshot of the whole window is taken after it (into
// $FOXI_WALKTHROUGH_DIR when set, to look at; else a temporary folder).
TEST(Workbench, DoneWhenWalkThrough) {
  TempDir tmp;
  const char* keep = std::getenv("FOXI_WALKTHROUGH_DIR");
  const std::filesystem::path dir = keep && *keep ? std::filesystem::path(keep) : tmp.path();
  std::filesystem::create_directories(dir);
  Workbench w;
  w.resize(1280, 860);
  w.show();
  QApplication::processEvents();
  int shot_number = 0;
  auto shot = [&](const std::string& name) {
    QApplication::processEvents();
    char prefix[16];
    std::snprintf(prefix, sizeof prefix, "%02d-", ++shot_number);
    const auto path = dir / (prefix + name + ".png");
    ASSERT_TRUE(w.grab().save(QString::fromStdString(path.string()))) << path;
    EXPECT_GT(std::filesystem::file_size(path), 1000u) << path;
  };
  auto settle = [&](foxi::qt::ViewWidget* v) {
    for (int i = 0; i < 100000 && v->busy(); ++i) QApplication::processEvents();
  };
  auto* params = w.findChild<QTableWidget*>("parameters");
  ASSERT_NE(params, nullptr);
  // 1. Open the example: its parameters listed, die_w among them.
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "flip_chip.toml")));
  bool listed = false;
  for (int r = 0; r < params->rowCount(); ++r)
    listed |= params->item(r, 0) && params->item(r, 0)->text() == "die_w";
  EXPECT_TRUE(listed) << "die_w in the parameter table";
  shot("opened");
  // 2. The die size changed (a unit the model checks).
  ASSERT_TRUE(w.set_parameter("die_w", "7 mm"));
  ASSERT_EQ(w.overrides().size(), 1u);
  EXPECT_EQ(w.overrides()[0].expression, "7 mm");
  shot("die-size-changed");
  // 3. Remesh: the mesh of those parameters shown.
  ASSERT_TRUE(meshed(w));
  ASSERT_TRUE(w.mesh());
  foxi::qt::ViewWidget* v = w.view_widget();
  EXPECT_EQ(v->mesh(), w.mesh());
  shot("remeshed");
  // 4. Solve the thermal problem: results and the temperature shown with its legend.
  ASSERT_TRUE(w.set_physics(foxi::Physics::thermal));
  ASSERT_TRUE(solved(w));
  ASSERT_NE(w.results(), nullptr);
  const foxi::ResultValue* t_first = w.results()->find("T_max");
  ASSERT_NE(t_first, nullptr);
  const double t_max_first = t_first->value;
  EXPECT_TRUE(v->view()->field()) << "coloured by the temperature";
  v->finish_now();
  EXPECT_EQ(v->view()->drawn().size(), w.mesh()->tet_count());
  shot("solved");
  // 5. Draw from the back, stop part way: the far part drawn, nothing more while stopped.
  v->draw();
  for (int i = 0; i < 3 && v->busy(); ++i) v->step_once();
  v->stop();
  const std::size_t stopped = v->view()->drawn().size();
  EXPECT_GT(stopped, 0u);
  EXPECT_LT(stopped, v->view()->total());
  for (int i = 0; i < 20; ++i) QApplication::processEvents();
  EXPECT_EQ(v->view()->drawn().size(), stopped) << "stopped: nothing drawn";
  EXPECT_FALSE(v->busy());
  v->finish_now();
  v->set_fraction(0.6);
  settle(v);
  shot("drawn-60-percent");
  // 6. Undraw: front to back, the picture of fewer tets.
  const std::size_t before = v->view()->drawn().size();
  v->set_fraction(0.35);
  settle(v);
  EXPECT_LT(v->view()->drawn().size(), before);
  EXPECT_EQ(v->view()->drawn().size(), std::size_t(std::llround(0.35 * double(v->view()->total()))));
  shot("undrawn-35-percent");
  // 7. A region of interest: what is drawn becomes the displayed set, the camera framed on it.
  const std::size_t region = v->view()->drawn().size();
  QString why;
  ASSERT_TRUE(v->push_region(&why)) << why.toStdString();
  EXPECT_EQ(v->view()->total(), region);
  v->finish_now();
  EXPECT_EQ(v->view()->drawn().size(), region);
  shot("region-of-interest");
  // 8. An isotherm inside it: the solid above the middle temperature, within the region.
  foxi::FieldSelection iso;
  iso.iso = {0.5 * (w.field_lo() + w.field_hi())};
  ASSERT_TRUE(w.set_selection(iso, &why)) << why.toStdString();
  v->finish_now();
  EXPECT_GT(v->view()->drawn().size(), 0u);
  EXPECT_LT(v->view()->drawn().size(), region);
  EXPECT_EQ(w.iso_slider()->value(), 500);
  shot("isotherm-in-region");
  // The x-ray with the isotherm inside, translucent.
  auto* xray_box = w.findChild<QCheckBox*>("xray");
  ASSERT_NE(xray_box, nullptr);
  xray_box->click();
  EXPECT_TRUE(v->view()->translucent());
  v->finish_now();
  shot("xray-isotherm");
  xray_box->click();
  EXPECT_FALSE(v->view()->translucent());
  ASSERT_TRUE(v->pop_region());
  // 9. A second run: another die size, solved; the history compares them.
  ASSERT_TRUE(w.set_parameter("die_w", "5 mm"));
  ASSERT_TRUE(w.start_solve());  // remeshes first: the parameters changed
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  ASSERT_EQ(w.history().size(), 2u);
  const foxi::ResultValue* a = w.history()[0].results.find("T_max");
  const foxi::ResultValue* b = w.history()[1].results.find("T_max");
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->value, t_max_first);
  EXPECT_NE(a->value, b->value) << "two die sizes, two maximum temperatures";
  EXPECT_NE(w.history()[0].tets, w.history()[1].tets);
  EXPECT_EQ(w.selection().iso.size(), 1u) << "the isotherm stays across the re-solve";
  v->finish_now();
  shot("second-run-history");
  // 10. Save the picture: the view's framebuffer as a PNG.
  const auto picture = dir / "view.png";
  ASSERT_TRUE(v->save_picture(QString::fromStdString(picture.string()), &why)) << why.toStdString();
  const foxi::Framebuffer saved = foxi::read_png(picture);
  EXPECT_TRUE(saved.rgba == v->view()->framebuffer().rgba);
  shot("picture-saved");
}

// The slice control: ticking it draws the plane across z through the middle of the mesh's box (the
// slider's middle), the tets it cuts; with the isosurface on it is refused (a slice and isovalues are
// both the polygons drawn) and the box unticks itself: the controls show what is drawn.
TEST(Workbench, SliceControlDrawsAndRefusesWithIsovalues) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(solved(w));
  auto* slice = w.findChild<QCheckBox*>("slice");
  ASSERT_NE(slice, nullptr);
  ASSERT_TRUE(slice->isEnabled());
  slice->click();
  foxi::qt::ViewWidget* v = w.view_widget();
  ASSERT_TRUE(v->selection().slice.has_value());
  double lo[3], hi[3];
  foxi::mesh_bounds(*w.mesh(), lo, hi);
  EXPECT_DOUBLE_EQ(v->selection().slice->p[2], lo[2] + (hi[2] - lo[2]) * 500 / 1000.0);
  EXPECT_EQ(v->selection().slice->n[2], 1.0);
  // The tets drawn are those the plane cuts (a corner below it, one on or above it), counted here;
  // the middle of this box is a layer of nodes, so the rule at a corner on the plane matters.
  const foxi::Mesh& m = *w.mesh();
  const double z = v->selection().slice->p[2];
  std::size_t cut = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    double zlo = INFINITY, zhi = -INFINITY;
    for (int k = 0; k < 4; ++k) {
      const double c = m.xyz[3 * std::size_t(m.tet[4 * t + std::size_t(k)]) + 2] - z;
      zlo = std::min(zlo, c), zhi = std::max(zhi, c);
    }
    cut += zlo < 0 && zhi >= 0;  // crossing's half-open rule (isosurface.hpp): min < v <= max
  }
  v->finish_now();
  EXPECT_GT(v->view()->drawn().size(), 0u);
  EXPECT_EQ(v->view()->drawn().size(), cut);
  EXPECT_TRUE(v->view()->iso()) << "drawn as polygons";
  // The isosurface too: refused, the slice stays and the isosurface box unticks.
  auto* iso = w.findChild<QCheckBox*>("isosurface");
  ASSERT_NE(iso, nullptr);
  iso->click();
  EXPECT_FALSE(iso->isChecked());
  EXPECT_TRUE(v->selection().iso.empty());
  EXPECT_TRUE(v->selection().slice.has_value());
  slice->click();
  EXPECT_FALSE(v->selection().any());
}

// Save movie runs on a worker: the window goes on (the GUI thread is not held), Cancel stops it and no
// file is left; a name of no known kind, a second movie while one runs and a movie of an isosurface
// are refused with the reason; an APNG is written whole.
TEST(Workbench, MovieOnAWorkerCancelsAndRefuses) {
  TempDir dir;
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {160, 120}));
  ASSERT_TRUE(solved(w));
  auto wait_movie = [&](bool* ok, QString* message) {
    QEventLoop loop;
    QObject::connect(&w, &Workbench::movie_finished, &loop, [&](bool r, const QString& m) {
      *ok = r;
      *message = m;
      loop.quit();
    });
    QTimer::singleShot(120000, &loop, &QEventLoop::quit);
    loop.exec();
  };
  QString why;
  EXPECT_FALSE(w.save_movie(QString::fromStdString((dir.path() / "m.mp3").string()), 8, &why));
  EXPECT_NE(why.indexOf(".gif"), -1) << why.toStdString();
  const auto long_one = dir.path() / "long.apng";
  ASSERT_TRUE(w.save_movie(QString::fromStdString(long_one.string()), 2000, &why)) << why.toStdString();
  EXPECT_TRUE(w.movie_running());
  EXPECT_FALSE(w.save_movie(QString::fromStdString((dir.path() / "b.gif").string()), 8, &why));
  w.cancel_movie();
  bool ok = true;
  QString message;
  wait_movie(&ok, &message);
  EXPECT_FALSE(ok);
  EXPECT_EQ(message, "cancelled");
  EXPECT_FALSE(w.movie_running());
  EXPECT_FALSE(std::filesystem::exists(long_one));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "no temporary left";
  const auto apng = dir.path() / "turn.apng";
  ASSERT_TRUE(w.save_movie(QString::fromStdString(apng.string()), 6, &why)) << why.toStdString();
  wait_movie(&ok, &message);
  EXPECT_TRUE(ok) << message.toStdString();
  ASSERT_TRUE(std::filesystem::exists(apng));
  const foxi::Framebuffer first = foxi::read_png(apng);  // an APNG's first frame, to a PNG reader
  EXPECT_EQ(first.width, 160);
  EXPECT_EQ(first.height, 120);
  foxi::FieldSelection iso;
  iso.iso = {0.5 * (w.field_lo() + w.field_hi())};
  ASSERT_TRUE(w.set_selection(iso));
  why.clear();
  EXPECT_FALSE(w.save_movie(QString::fromStdString((dir.path() / "iso.gif").string()), 6, &why));
  EXPECT_NE(why.indexOf("isosurface"), -1) << why.toStdString();
}

// A project saved and reopened in a new window: the same parameters, mesh (counts, coordinates),
// results, history, camera and picture; a save killed half way (its temporaries left behind: a
// partial project.json temporary, a mesh file project.json does not name) leaves the saved project
// readable and the same.
TEST(Workbench, ProjectSaveReopenAndKilledSave) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "proj").string());
  std::vector<std::uint32_t> ids;
  std::vector<double> xyz;
  std::size_t tets = 0;
  double t_max = 0;
  std::string camera;
  {
    Workbench w;
    ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
    ASSERT_TRUE(w.set_parameter("die_w", "6 mm"));
    ASSERT_TRUE(solved(w));
    w.view_widget()->view()->orbit(20, 10);  // a camera of the user's, not the default
    foxi::FieldSelection sel;                // and an isotherm in the middle of the range
    sel.iso = {0.5 * (w.field_lo() + w.field_hi())};
    ASSERT_TRUE(w.set_selection(sel));
    w.view_widget()->finish_now();
    QString why;
    ASSERT_TRUE(w.save_project(folder, &why)) << why.toStdString();
    ids = w.view_widget()->view()->framebuffer().id;
    xyz = w.mesh()->xyz;
    tets = w.mesh()->tet_count();
    t_max = w.results()->find("T_max")->value;
    camera = w.view_widget()->camera_options();
  }
  auto reopen = [&](const char* when) {
    Workbench w;
    w.view_widget()->setFixedSize(200, 150);
    w.show();
    QString why;
    ASSERT_TRUE(w.open_project(folder, &why)) << when << ": " << why.toStdString();
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
    ASSERT_EQ(w.overrides().size(), 1u) << when;
    EXPECT_EQ(w.overrides()[0].name, "die_w");
    EXPECT_EQ(w.overrides()[0].expression, "6 mm");
    ASSERT_TRUE(w.mesh());
    EXPECT_EQ(w.mesh()->tet_count(), tets);
    EXPECT_TRUE(w.mesh()->xyz == xyz) << when << ": the coordinates as saved";
    ASSERT_NE(w.results(), nullptr);
    EXPECT_EQ(w.results()->find("T_max")->value, t_max);
    ASSERT_EQ(w.history().size(), 1u);
    EXPECT_EQ(w.history()[0].tets, tets);
    EXPECT_EQ(w.view_widget()->camera_options(), camera) << when;
    ASSERT_EQ(w.view_widget()->selection().iso.size(), 1u) << when << ": the isotherm as saved";
    w.view_widget()->finish_now();
    EXPECT_TRUE(w.view_widget()->view()->framebuffer().id == ids) << when << ": the same picture";
  };
  reopen("after the save");
  // What a save killed while writing leaves: a temporary of project.json cut short (its writer's
  // process gone) and the next mesh file written but not yet named by project.json.
  const auto p = dir.path() / "proj";
  {
    std::ofstream(p / "project.json.foxi-tmp-999999999-killed") << "{\"format\": \"foxi-workbench proj";
    std::ofstream(p / "mesh-9.vtu") << "<?xml version=\"1.0\"?><VTKFile";
  }
  reopen("after a killed save");
}

// The project folder holds its model: a copy with the edited values, the material library (outside
// the model's folder here) and the STL file copied beside it, named relatively. The folder renamed and
// the original model's folder and library removed, it reopens: the same parameters, materials and
// STL surface, the saved mesh, and a remesh (of the copies) equal to the mesh of the original files.
// A project of the previous version (the model file's absolute path) still opens where it is.
TEST(Workbench, ProjectFolderHoldsItsModel) {
  TempDir dir;
  const auto src = dir.path() / "src";
  std::filesystem::create_directories(src / "model" / "shapes");
  std::filesystem::create_directories(src / "lib");
  std::string stl = "solid t\n";
  const char* const facets[4][3] = {{"1 1 2", "1 2 2", "2 1 2"},
                                    {"1 1 2", "2 1 2", "1 1 3"},
                                    {"1 1 2", "1 1 3", "1 2 2"},
                                    {"2 1 2", "1 2 2", "1 1 3"}};
  for (const auto& f : facets)
    stl += std::string(" facet normal 0 0 0\n  outer loop\n   vertex ") + f[0] + "\n   vertex " + f[1] +
           "\n   vertex " + f[2] + "\n  endloop\n endfacet\n";
  foxi::test::write_text(src / "model" / "shapes" / "t.stl", stl + "endsolid t\n");
  foxi::test::write_text(
      src / "lib" / "materials.toml",
      "[materials.a]\nthermal_conductivity = 3\n[materials.b]\nthermal_conductivity = 30\n");
  const auto model = src / "model" / "m.toml";
  foxi::test::write_text(
      model,
      "units.length = \"mm\"\nlibrary = \"../lib/materials.toml\"\n"
      "[parameters]\nw = \"3 mm\"\nh = \"1 mm\"\n"
      "[[parts]]\nname = \"base\"\nmaterial = \"a\"\nshape = \"box\"\n"
      "origin = [0, 0, 0]\nsize = [\"w\", 3, \"h\"]\n"
      "[[parts]]\nname = \"tip\"\nmaterial = \"b\"\nshape = \"stl\"\nfile = \"shapes/t.stl\"\n");
  const auto proj = dir.path() / "proj";
  foxi::Mesh before;
  {
    Workbench w;
    ASSERT_TRUE(w.open_model(QString::fromStdString(model.string())));
    ASSERT_TRUE(w.set_parameter("w", "4 mm"));
    ASSERT_TRUE(meshed(w));
    QString why;
    ASSERT_TRUE(w.save_project(QString::fromStdString(proj.string()), &why)) << why.toStdString();
    before = *w.mesh();
  }
  const std::string json = foxi::test::read_text(proj / "project.json");
  EXPECT_NE(json.find("\"model\": \"model/m.toml\""), std::string::npos) << json;
  const std::string copy = foxi::test::read_text(proj / "model" / "m.toml");
  EXPECT_NE(copy.find("library = \"materials.toml\""), std::string::npos) << copy;
  EXPECT_NE(copy.find("file = \"t.stl\""), std::string::npos) << copy;
  EXPECT_NE(copy.find("w = \"4 mm\""), std::string::npos) << copy;
  EXPECT_EQ(foxi::test::read_text(proj / "model" / "t.stl"), stl + "endsolid t\n");

  auto check_open = [&](const std::filesystem::path& folder, const std::filesystem::path& model_file) {
    Workbench w;
    QString why;
    ASSERT_TRUE(w.open_project(QString::fromStdString(folder.string()), &why)) << why.toStdString();
    EXPECT_EQ(std::filesystem::weakly_canonical(w.model()->file),
              std::filesystem::weakly_canonical(model_file));
    ASSERT_EQ(w.overrides().size(), 1u);
    EXPECT_EQ(w.overrides()[0].name, "w");
    EXPECT_EQ(w.overrides()[0].expression, "4 mm");
    ASSERT_EQ(w.model()->materials.size(), 2u);
    EXPECT_EQ(w.model()->materials[1].thermal_conductivity, 30);  // the library's
    ASSERT_EQ(w.model()->parts.size(), 2u);
    EXPECT_EQ(w.model()->parts[1].surface.tri.size(), 12u);  // the STL's 4 triangles
    EXPECT_EQ(w.model()->parts[0].prisms[0].xy[2], 4e-3);    // the base's width, 4 mm
    ASSERT_TRUE(w.mesh());
    EXPECT_TRUE(w.mesh()->xyz == before.xyz) << "the saved mesh";
    if (w.busy()) {  // the reopened view's drawing
      ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
    }
    ASSERT_TRUE(meshed(w));
    EXPECT_TRUE(w.mesh()->xyz == before.xyz) << "the next mesh, of " << model_file;
    EXPECT_TRUE(w.mesh()->tet_region == before.tet_region);
    EXPECT_TRUE(w.mesh()->tet == before.tet);
  };
  // The previous version's project: project.json naming the original model absolutely
  const auto old = dir.path() / "old";
  std::filesystem::create_directories(old);
  QJsonObject o = QJsonDocument::fromJson(QByteArray::fromStdString(json)).object();
  o["model"] = QString::fromStdString(model.string());
  foxi::test::write_text(old / "project.json", QJsonDocument(o).toJson().toStdString());
  const std::string mesh_name = o["mesh"].toString().toStdString();
  std::filesystem::copy_file(proj / mesh_name, old / mesh_name);
  check_open(old, model);

  const auto moved = dir.path() / "moved";
  std::filesystem::rename(proj, moved);
  std::filesystem::remove_all(src);
  check_open(moved, moved / "model" / "m.toml");
}

// A save killed while it writes (SIGKILL at staggered moments of a headless run that saves a
// project over an existing one): the folder always opens, as the old project or the new one whole.
TEST(WorkbenchHeadless, KilledSaveLeavesAProjectThatOpens) {
  TempDir dir;
  const auto folder = dir.path() / "proj";
  const std::string base =
      "'" + std::string(FOXI_WORKBENCH_PATH) + "' '" + kModels +
      "die_on_substrate.toml' --headless --physics thermal --view-size 160x120 --save-project '" +
      folder.string() + "' --set ";
  ASSERT_EQ(foxi::test::run(base + "die_w=5mm", dir.path() / "first.log"), 0)
      << foxi::test::read_text(dir.path() / "first.log");
  const auto run_time = std::chrono::steady_clock::now();
  ASSERT_EQ(foxi::test::run(base + "die_w=6mm", dir.path() / "second.log"), 0);
  const double full = std::chrono::duration<double>(std::chrono::steady_clock::now() - run_time).count();
  for (int i = 1; i <= 6; ++i) {
    // Killed at i/6 of a whole run's time (the save is at its end), alternating the two states.
    const std::string set = i % 2 ? "die_w=5mm" : "die_w=6mm";
    const std::string cmd = "timeout -s KILL " + std::to_string(full * i / 6.0) + " " + base + set;
    foxi::test::run(cmd, dir.path() / "killed.log");
    Workbench w;
    w.view_widget()->setFixedSize(160, 120);
    QString why;
    ASSERT_TRUE(w.open_project(QString::fromStdString(folder.string()), &why))
        << "kill " << i << ": " << why.toStdString();
    if (w.busy()) {
      ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
    }
    ASSERT_EQ(w.overrides().size(), 1u);
    const std::string v = w.overrides()[0].expression;
    EXPECT_TRUE(v == "5mm" || v == "6mm") << v;
    ASSERT_TRUE(w.mesh());
    // The mesh is the one of those parameters (die_w = 5 mm and 6 mm mesh to different counts).
    const std::vector<foxi::ParameterOverride> ov = {{"die_w", v}};
    const foxi::MeshedModel direct = foxi::mesh_model(kModels + "die_on_substrate.toml", ov);
    EXPECT_EQ(w.mesh()->tet_count(), direct.mesh.tet_count()) << "kill " << i;
  }
}

// Autosave: within 5 s of a parameter change the autosave folder holds a project with it (written on
// a worker), which reopens with that value.
// Autosave writes the mesh (with the results' fields) only when it changed: a view change rewrites
// project.json and keeps the mesh file as it was (same name, size and modification time); a remesh
// writes a new one.
TEST(Workbench, AutosaveWritesOnlyWhatChanged) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "auto").string());
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(meshed(w));
  w.set_autosave_folder(folder);
  w.set_autosave_delay(50);  // the rule tested is what is written, not when: no 2 s waits
  const auto json = dir.path() / "auto" / "project.json";
  auto autosave_after = [&](int n) {  // waits for autosave number n to be written
    const auto t0 = std::chrono::steady_clock::now();
    while (w.autosaves() < n && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(8))
      QApplication::processEvents(QEventLoop::AllEvents, 50);
    w.wait_autosave();
    return w.autosaves() >= n;
  };
  auto mesh_file = [&] {
    const std::string text = foxi::test::read_text(json);
    return line_after(text, "\"mesh\": \"").substr(0, line_after(text, "\"mesh\": \"").find('"'));
  };
  ASSERT_TRUE(w.set_shrink(0.9));
  ASSERT_TRUE(wait_job(w));
  ASSERT_TRUE(autosave_after(1));
  const std::string first = mesh_file();
  ASSERT_FALSE(first.empty()) << foxi::test::read_text(json);
  const auto mesh_path = dir.path() / "auto" / first;
  const auto time0 = std::filesystem::last_write_time(mesh_path);
  const auto size0 = std::filesystem::file_size(mesh_path);
  EXPECT_EQ(w.autosaves_without_mesh(), 0);
  const auto model_copy = dir.path() / "auto" / "model" / "die_on_substrate.toml";
  ASSERT_TRUE(std::filesystem::exists(model_copy));
  const auto model_time0 = std::filesystem::last_write_time(model_copy);
  EXPECT_EQ(w.autosaves_without_model(), 0);
  // a view change: project.json again, the mesh file untouched
  ASSERT_TRUE(w.set_shrink(0.8));
  ASSERT_TRUE(wait_job(w));
  ASSERT_TRUE(autosave_after(2));
  EXPECT_NE(foxi::test::read_text(json).find("0.8"), std::string::npos);
  EXPECT_EQ(mesh_file(), first);
  EXPECT_EQ(std::filesystem::last_write_time(mesh_path), time0);
  EXPECT_EQ(std::filesystem::file_size(mesh_path), size0);
  EXPECT_EQ(w.autosaves_without_mesh(), 1);
  EXPECT_EQ(std::filesystem::last_write_time(model_copy), model_time0) << "the model copy kept";
  EXPECT_EQ(w.autosaves_without_model(), 1);
  // a new mesh: a new file, the old one gone
  ASSERT_TRUE(w.set_parameter("die_w", "5 mm"));
  ASSERT_TRUE(meshed(w));
  ASSERT_TRUE(autosave_after(3));
  EXPECT_NE(mesh_file(), first);
  EXPECT_FALSE(std::filesystem::exists(mesh_path));
  EXPECT_EQ(w.autosaves_without_mesh(), 1);
  // and the model copy with the new value
  EXPECT_EQ(w.autosaves_without_model(), 1);
  EXPECT_NE(foxi::test::read_text(model_copy).find("die_w = \"5 mm\""), std::string::npos)
      << foxi::test::read_text(model_copy);
  Workbench again;
  QString why;
  ASSERT_TRUE(again.open_project(folder, &why)) << why.toStdString();
  EXPECT_EQ(again.mesh()->tet_count(), w.mesh()->tet_count());
  if (again.busy()) {
    ASSERT_TRUE(wait_job(again)) << again.last_error().toStdString();
  }
  // The reopened project works on its copy, autosaved over itself: written once, then kept
  w.set_autosave_folder({});
  again.set_autosave_folder(folder);
  again.set_autosave_delay(50);
  for (int n = 1; n <= 2; ++n) {
    ASSERT_TRUE(again.set_shrink(n == 1 ? 0.7 : 0.6));
    ASSERT_TRUE(wait_job(again));
    const auto t0 = std::chrono::steady_clock::now();
    while (again.autosaves() < n && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(8))
      QApplication::processEvents(QEventLoop::AllEvents, 50);
    again.wait_autosave();
    ASSERT_EQ(again.autosaves(), n);
  }
  EXPECT_EQ(again.autosaves_without_model(), 1);
}

// An autosave a session left is found and restored on start (the window asks first; here without
// asking): the parameters as they were; no autosave, nothing restored.
TEST(Workbench, RestoreOfferedForAnAutosave) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "auto").string());
  EXPECT_FALSE(Workbench::autosave_found(folder));
  {
    Workbench w;
    EXPECT_FALSE(w.restore_autosave(folder, false));
    ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
    ASSERT_TRUE(w.set_parameter("die_w", "5 mm"));
    QString why;
    ASSERT_TRUE(w.save_project(folder, &why)) << why.toStdString();
  }
  EXPECT_TRUE(Workbench::autosave_found(folder));
  Workbench again;
  QString why;
  ASSERT_TRUE(again.restore_autosave(folder, false, &why)) << why.toStdString();
  ASSERT_EQ(again.overrides().size(), 1u);
  EXPECT_EQ(again.overrides()[0].expression, "5 mm");
}

TEST(Workbench, AutosaveWithinFiveSeconds) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "auto").string());
  Workbench w;
  w.view_widget()->setFixedSize(200, 150);
  w.set_autosave_folder(folder);
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(w.set_parameter("die_w", "4 mm"));
  const auto json = dir.path() / "auto" / "project.json";
  auto has_value = [&] {
    return std::filesystem::exists(json) && foxi::test::read_text(json).find("4 mm") != std::string::npos;
  };
  while (!has_value() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(6)) {
    QApplication::processEvents(QEventLoop::AllEvents, 50);
    w.wait_autosave();
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(has_value()) << "no autosave within 6 s";
  EXPECT_LT(s, 5.0);
  EXPECT_GE(w.autosaves(), 1);
  Workbench again;
  QString why;
  ASSERT_TRUE(again.open_project(folder, &why)) << why.toStdString();
  ASSERT_EQ(again.overrides().size(), 1u);
  EXPECT_EQ(again.overrides()[0].expression, "4 mm");
}

// The value and unit the results table shows for `name` (its row "name *" for a key result).
std::pair<double, std::string> table_value(Workbench& w, const std::string& name) {
  auto* t = w.findChild<QTableWidget*>("results");
  if (!t) return {NAN, ""};
  for (int r = 0; r < t->rowCount(); ++r) {
    const std::string n = t->item(r, 0)->text().toStdString();
    if (n == name || n == name + " *")
      return {t->item(r, 1)->text().toDouble(), t->item(r, 2)->text().toStdString()};
  }
  return {NAN, ""};
}

// One unit everywhere: the results table shows temperatures in the legend's unit (°C by default,
// the SI value less 273.15), and in K, as the legend then does, when the user picks SI units; the
// history's key results follow.
TEST(Workbench, ResultsTableInTheLegendsUnit) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(solved(w));
  const foxi::ResultValue* t = w.results()->find("T_max");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->unit, "K");
  EXPECT_EQ(w.display_unit().symbol, "°C");
  auto [shown, unit] = table_value(w, "T_max");
  EXPECT_EQ(unit, "°C");
  EXPECT_NEAR(shown, t->value - 273.15, 1e-3);
  ASSERT_TRUE(w.set_si_units(true));
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  EXPECT_EQ(w.display_unit().symbol, "K");
  std::tie(shown, unit) = table_value(w, "T_max");
  EXPECT_EQ(unit, "K");
  EXPECT_NEAR(shown, t->value, 1e-3 * t->value);
  ASSERT_TRUE(w.set_si_units(false));
  ASSERT_TRUE(wait_job(w));
  EXPECT_EQ(w.display_unit().symbol, "°C");
}

// After Save model (the edited values written into the file, the overrides gone) the shown mesh is
// still the model's: the next Solve solves it without remeshing (no new mesh, the mesh's history row
// completed), and so does a save of the same values again.
TEST(Workbench, SaveModelThenSolveDoesNotRemesh) {
  TempDir dir;
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(w.set_parameter("die_w", "6 mm"));
  ASSERT_TRUE(meshed(w));
  const auto meshed = w.mesh();
  ASSERT_EQ(w.history().size(), 1u);
  QString error;
  ASSERT_TRUE(w.save_model_file(QString::fromStdString((dir.path() / "m.toml").string()), &error))
      << error.toStdString();
  EXPECT_TRUE(w.overrides().empty());
  ASSERT_TRUE(solved(w));
  ASSERT_EQ(w.history().size(), 1u) << "the solve completed the mesh's row: no remesh";
  EXPECT_EQ(w.history()[0].mesh, 1u);
  EXPECT_NE(w.history()[0].results.find("T_max"), nullptr);
  EXPECT_TRUE(w.mesh()->xyz == meshed->xyz);
  // A parameter edited after the mesh and then saved: the file changed, the next Solve remeshes.
  ASSERT_TRUE(w.set_parameter("die_w", "5 mm"));
  ASSERT_TRUE(w.save_model_file({}, &error)) << error.toStdString();
  ASSERT_TRUE(solved(w));
  ASSERT_EQ(w.history().size(), 2u);
  EXPECT_EQ(w.history()[1].mesh, 2u);
  const std::vector<foxi::ParameterOverride> ov = {{"die_w", "5 mm"}};
  EXPECT_EQ(w.mesh()->tet_count(), foxi::mesh_model(kModels + "die_on_substrate.toml", ov).mesh.tet_count());
}

// A project keeps the deformed shape and its scale: reopened, the view shows the same moved mesh.
TEST(Workbench, ProjectKeepsTheDeformedShape) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "proj").string());
  std::vector<double> moved;
  {
    Workbench w;
    ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
    ASSERT_TRUE(w.set_physics(foxi::Physics::thermal_stress));
    ASSERT_TRUE(solved(w));
    ASSERT_TRUE(w.set_deform(foxi::workbench::Deform{"displacement", 150}));
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
    moved = w.view_widget()->mesh()->xyz;
    ASSERT_NE(moved, w.mesh()->xyz);
    QString why;
    ASSERT_TRUE(w.save_project(folder, &why)) << why.toStdString();
  }
  Workbench again;
  ASSERT_TRUE(reopen(again, folder));
  ASSERT_TRUE(again.deform().has_value());
  EXPECT_EQ(again.deform()->field, "displacement");
  EXPECT_EQ(again.deform()->scale, 150);
  ASSERT_NE(again.view_widget()->mesh(), again.mesh());
  EXPECT_TRUE(again.view_widget()->mesh()->xyz == moved) << "the same moved mesh as saved";
}

// The mesh panel's settings, field by field (lengths exactly: the project keeps them in metres).
void expect_same_settings(const foxi::workbench::MeshSettings& a, const foxi::workbench::MeshSettings& b,
                          const char* when) {
  EXPECT_EQ(a.mesher, b.mesher) << when;
  EXPECT_EQ(a.max_size, b.max_size) << when;
  EXPECT_EQ(a.quality, b.quality) << when;
  ASSERT_EQ(a.part_sizes.size(), b.part_sizes.size()) << when;
  for (std::size_t i = 0; i < a.part_sizes.size(); ++i) {
    EXPECT_EQ(a.part_sizes[i].part, b.part_sizes[i].part) << when;
    EXPECT_EQ(a.part_sizes[i].max_size, b.part_sizes[i].max_size) << when;
  }
  ASSERT_EQ(a.boxes.size(), b.boxes.size()) << when;
  for (std::size_t i = 0; i < a.boxes.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a.boxes[i].lo[k], b.boxes[i].lo[k]) << when;
      EXPECT_EQ(a.boxes[i].hi[k], b.boxes[i].hi[k]) << when;
    }
    EXPECT_EQ(a.boxes[i].size, b.boxes[i].size) << when;
  }
  EXPECT_EQ(a.refine_from_result, b.refine_from_result) << when;
  EXPECT_EQ(a.refine_field, b.refine_field) << when;
  EXPECT_EQ(a.target_error, b.target_error) << when;
}

// A refinement box from the origin to (x, y, z) with edge length `size` inside (m).
foxi::RefinementBox box_from_origin(double x, double y, double z, double size) {
  foxi::RefinementBox b;
  b.hi[0] = x, b.hi[1] = y, b.hi[2] = z;
  b.size = size;
  return b;
}

// Waits (serving events) until the workbench has started `n` autosaves and the last is written.
bool autosaved(Workbench& w, int n) {
  const auto t0 = std::chrono::steady_clock::now();
  while (w.autosaves() < n && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(8))
    QApplication::processEvents(QEventLoop::AllEvents, 50);
  w.wait_autosave();
  return w.autosaves() >= n;
}

// A project keeps the mesh panel's settings (TetGen: global and part size, quality bound, a
// refinement box, refine from the result with its field and target): a change of one is autosaved,
// and the autosaved project reopened in a new window has them field by field, in the panel's
// controls too; a Solve there does not remesh (the shown mesh was made with them), and the next Mesh
// is mesh_model's with those options, refined from the reopened result.
TEST(Workbench, ProjectKeepsTheMeshSettings) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "auto").string());
  const std::string model = kModels + "die_on_substrate.toml";
  foxi::workbench::MeshSettings s;
  s.max_size = 1.5e-3;
  s.part_sizes = {{.part = "die", .max_size = 0.4e-3}};
  s.quality = 1.8;
  const foxi::RefinementBox box = box_from_origin(2e-3, 10e-3, 1.5e-3, 0.3e-3);
  s.boxes = {box};
  s.refine_from_result = true;
  s.refine_field = "temperature";
  s.target_error = 0.25;
  {
    Workbench w;
    ASSERT_TRUE(open_window(w, model, {160, 120}, Shown::no));
    QString why;
    ASSERT_TRUE(w.set_mesh_settings(s, &why)) << why.toStdString();
    ASSERT_TRUE(w.start_solve());  // no result to refine from yet: meshed with the sizes, solved
    ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
    w.set_autosave_folder(folder);
    w.set_autosave_delay(50);
    const int before = w.autosaves();
    s.target_error = 0.3;  // a mesh setting changed: an autosave follows
    ASSERT_TRUE(w.set_mesh_settings(s, &why)) << why.toStdString();
    ASSERT_TRUE(autosaved(w, before + 1)) << "no autosave after a mesh setting changed";
    EXPECT_NE(foxi::test::read_text(dir.path() / "auto" / "project.json").find("\"target_error\": 0.3"),
              std::string::npos);
    // The same settings again (the panel's editingFinished without an edit) is no change.
    ASSERT_TRUE(w.set_mesh_settings(s));
    for (int i = 0; i < 5; ++i) QApplication::processEvents(QEventLoop::AllEvents, 50);
    EXPECT_EQ(w.autosaves(), before + 1);
    // the shown mesh made with these settings again (a Solve reopened must not remesh)
    s.target_error = 0.25;
    ASSERT_TRUE(w.set_mesh_settings(s, &why));
    ASSERT_TRUE(autosaved(w, before + 2));
  }
  Workbench again;
  ASSERT_TRUE(reopen(again, folder, {160, 120}));
  expect_same_settings(again.mesh_settings(), s, "reopened");
  // The panel's controls show them (lengths in the model's mm).
  EXPECT_EQ(again.findChild<QComboBox*>("mesher")->currentIndex(), 0);
  EXPECT_EQ(again.findChild<QLineEdit*>("mesh_size")->text(), "1.5 mm");
  EXPECT_EQ(again.findChild<QLineEdit*>("mesh_quality")->text(), "1.8");
  EXPECT_EQ(again.findChild<QLineEdit*>("target_error")->text(), "0.25");
  EXPECT_TRUE(again.findChild<QCheckBox*>("refine_from_result")->isChecked());
  auto* parts = again.findChild<QTableWidget*>("part_sizes");
  bool die_shown = false;
  for (int r = 0; r < parts->rowCount(); ++r)
    if (parts->item(r, 0)->text() == "die") die_shown = parts->item(r, 1)->text() == "0.4 mm";
  EXPECT_TRUE(die_shown);
  auto* boxes = again.findChild<QTableWidget*>("refine_boxes");
  ASSERT_EQ(boxes->rowCount(), 1);
  EXPECT_EQ(boxes->item(0, 3)->text(), "2");
  EXPECT_EQ(boxes->item(0, 6)->text(), "0.3");
  // A Solve on the reopened mesh solves it (made with the settings shown: no remesh).
  const std::shared_ptr<const foxi::Mesh> before = again.mesh();
  ASSERT_TRUE(before && again.results());
  ASSERT_FALSE(again.history().empty());
  const std::size_t mesh_number = again.history().back().mesh;
  ASSERT_TRUE(solved(again));
  EXPECT_EQ(again.history().back().mesh, mesh_number)
      << "the reopened mesh's settings are the panel's: no remesh";
  EXPECT_TRUE(again.mesh()->xyz == before->xyz);
  // The next Mesh: mesh_model's with the options written out here, refined from the reopened result.
  const std::shared_ptr<const foxi::Mesh> result = again.mesh();
  ASSERT_TRUE(meshed(again));
  foxi::ModelMeshOptions o;
  o.max_size = 1.5e-3;
  o.part_sizes = {{.part = "die", .max_size = 0.4e-3}};
  o.quality = 1.8;
  o.sizes.boxes = {box};
  o.refine_from = {.mesh = result.get(), .field = "temperature", .target_error = 0.25};
  const foxi::MeshedModel direct = foxi::mesh_model(model, {}, o);
  EXPECT_EQ(again.mesh()->tet_count(), direct.mesh.tet_count());
  EXPECT_TRUE(again.mesh()->xyz == direct.mesh.xyz);
  EXPECT_TRUE(again.mesh()->tet == direct.mesh.tet);
  EXPECT_GT(again.mesh()->tet_count(), result->tet_count()) << "refined";
}

// CGAL with a part size, a quality bound and a box, saved in a project (no mesh yet) and reopened in a
// new window: the same settings, the mesher box on CGAL, and the next mesh mesh_model's with them.
TEST(Workbench, ProjectKeepsCgalMeshSettings) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "proj").string());
  const std::string model = kModels + "die_on_substrate.toml";
  foxi::workbench::MeshSettings s;
  s.mesher = foxi::Mesher::cgal;
  s.part_sizes = {{.part = "die", .max_size = 0.4e-3}};
  s.quality = 2.5;
  const foxi::RefinementBox box = box_from_origin(2e-3, 10e-3, 1e-3, 0.4e-3);
  s.boxes = {box};
  {
    Workbench w;
    ASSERT_TRUE(w.open_model(QString::fromStdString(model)));
    QString why;
    ASSERT_TRUE(w.set_mesh_settings(s, &why)) << why.toStdString();
    ASSERT_TRUE(w.save_project(folder, &why)) << why.toStdString();
  }
  Workbench again;
  again.view_widget()->setFixedSize(160, 120);
  QString why;
  ASSERT_TRUE(again.open_project(folder, &why)) << why.toStdString();
  expect_same_settings(again.mesh_settings(), s, "reopened");
  EXPECT_EQ(again.findChild<QComboBox*>("mesher")->currentIndex(), 1);
  EXPECT_EQ(again.findChild<QLineEdit*>("mesh_quality")->text(), "2.5");
  ASSERT_TRUE(meshed(again));
  foxi::ModelMeshOptions o;
  o.mesher = foxi::Mesher::cgal;
  o.part_sizes = {{.part = "die", .max_size = 0.4e-3}};
  o.quality = 2.5;
  o.sizes.boxes = {box};
  const foxi::MeshedModel direct = foxi::mesh_model(model, {}, o);
  EXPECT_EQ(direct.cgal.boxes, 1u);
  EXPECT_TRUE(again.mesh()->xyz == direct.mesh.xyz);
  EXPECT_TRUE(again.mesh()->tet == direct.mesh.tet);
  EXPECT_TRUE(again.mesh()->weight == direct.mesh.weight);
}

// A project saved before the mesh settings were kept opens with the defaults (also in a window whose
// settings for the same model were others); a malformed entry is refused naming project.json and
// the reason, the window's settings as they were.
TEST(Workbench, ProjectMeshSettingsOldAndMalformed) {
  TempDir dir;
  const auto proj = dir.path() / "proj";
  QJsonObject saved;
  {
    Workbench w;
    ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
    QString why;
    ASSERT_TRUE(w.save_project(QString::fromStdString(proj.string()), &why)) << why.toStdString();
    saved = QJsonDocument::fromJson(QByteArray::fromStdString(foxi::test::read_text(proj / "project.json")))
                .object();
  }
  ASSERT_TRUE(saved.contains("mesh_settings"));
  auto write = [&](const QJsonObject& p) {
    foxi::test::write_text(proj / "project.json", QJsonDocument(p).toJson().toStdString());
  };
  // A window on the project's model (the same path: the folder's copy) with settings of its own.
  Workbench x;
  ASSERT_TRUE(
      x.open_model(QString::fromStdString((proj / saved["model"].toString().toStdString()).string())));
  foxi::workbench::MeshSettings mine;
  mine.mesher = foxi::Mesher::cgal;
  mine.max_size = 2e-3;
  mine.boxes = {foxi::RefinementBox{{0, 0, 0}, {1e-3, 1e-3, 1e-3}, 0.5e-3}};
  QString why;
  ASSERT_TRUE(x.set_mesh_settings(mine, &why)) << why.toStdString();

  // Malformed entries: refused with the file and the reason; the settings stay.
  const std::string file = (proj / "project.json").string();
  struct Case {
    const char* key;
    QJsonValue value;
    const char* reason;
  };
  const QJsonObject settings = saved["mesh_settings"].toObject();
  auto with = [&](const char* key, const QJsonValue& v) {
    QJsonObject o = settings;
    o[key] = v;
    return o;
  };
  const QJsonObject bad_box{{"lo", QJsonArray{0, 0}}, {"hi", QJsonArray{1e-3, 1e-3, 1e-3}}, {"size", 1e-4}};
  const Case cases[] = {
      {"mesher", "gmsh", "the mesher is tetgen or cgal, not 'gmsh'"},
      {"max_size", "1 mm", "max_size is not a number"},
      {"boxes", QJsonArray{bad_box}, "refinement box 1's lo is not 3 numbers"},
      {"refine_from_result", 1, "refine_from_result is not true or false"},
      {"max-size", 1e-3, "unknown entry 'max-size'"},
  };
  for (const Case& c : cases) {
    QJsonObject p = saved;
    p["mesh_settings"] = with(c.key, c.value);
    write(p);
    why.clear();
    EXPECT_FALSE(x.open_project(QString::fromStdString(proj.string()), &why)) << c.key;
    EXPECT_NE(why.toStdString().find(file + ": mesh_settings: " + c.reason), std::string::npos)
        << why.toStdString();
    expect_same_settings(x.mesh_settings(), mine, c.key);
  }
  // Values the panel refuses, with its reason (mesh_model's check, the model's parts).
  const std::pair<QJsonObject, const char*> refused[] = {
      {with("part_sizes", QJsonArray{QJsonObject{{"part", "chip"}, {"max_size", 1e-3}}}),
       "no part named 'chip' in the model"},
      {with("quality", 1.0), "the radius-edge bound must be 0 (no quality refinement) or at least 1.414"},
      {with("max_size", -1e-3), "the global mesh size must be > 0"},
  };
  for (const auto& [entry, reason] : refused) {
    QJsonObject p = saved;
    p["mesh_settings"] = entry;
    write(p);
    why.clear();
    EXPECT_FALSE(x.open_project(QString::fromStdString(proj.string()), &why)) << reason;
    EXPECT_NE(why.toStdString().find(file + ": mesh_settings: "), std::string::npos) << why.toStdString();
    EXPECT_NE(why.toStdString().find(reason), std::string::npos) << why.toStdString();
  }

  // An old project (no entry): the defaults, in the panel too.
  ASSERT_TRUE(x.set_mesh_settings(mine, &why)) << why.toStdString();
  QJsonObject old = saved;
  old.remove("mesh_settings");
  write(old);
  ASSERT_TRUE(x.open_project(QString::fromStdString(proj.string()), &why)) << why.toStdString();
  expect_same_settings(x.mesh_settings(), foxi::workbench::MeshSettings{}, "an old project");
  EXPECT_EQ(x.findChild<QComboBox*>("mesher")->currentIndex(), 0);
  EXPECT_EQ(x.findChild<QTableWidget*>("refine_boxes")->rowCount(), 0);
  EXPECT_TRUE(x.findChild<QLineEdit*>("mesh_size")->text().isEmpty());
}

// The slice plane is kept in a project like the clip plane: reopened, the view draws the same slice
// within the same clip (the same tets, the same picture with the saved camera) and its check box is
// ticked; a project saved before the slice was kept (no "slice" in its selection) opens with the
// clip alone.
TEST(Workbench, ProjectKeepsTheSlicePlane) {
  TempDir dir;
  const QString folder = QString::fromStdString((dir.path() / "proj").string());
  std::size_t drawn = 0;
  std::vector<std::uint32_t> ids;
  foxi::FieldSelection s;
  {
    Workbench w;
    ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
    ASSERT_TRUE(solved(w));
    double lo[3], hi[3];
    foxi::mesh_bounds(*w.mesh(), lo, hi);
    s.clip = foxi::Plane{{0.5 * (lo[0] + hi[0]), 0, 0}, {-1, 0, 0}};
    s.slice = foxi::Plane{{0, lo[1] + 0.3 * (hi[1] - lo[1]), 0}, {0, 1, 0}};
    QString why;
    ASSERT_TRUE(w.set_selection(s, &why)) << why.toStdString();
    w.view_widget()->finish_now();
    drawn = w.view_widget()->view()->drawn().size();
    ids = w.view_widget()->view()->framebuffer().id;
    ASSERT_GT(drawn, 0u);
    ASSERT_TRUE(w.save_project(folder, &why)) << why.toStdString();
  }
  {
    Workbench again;
    ASSERT_TRUE(reopen(again, folder, {200, 150}, Shown::yes));
    again.view_widget()->finish_now();
    const foxi::FieldSelection& got = again.view_widget()->selection();
    ASSERT_TRUE(got.slice.has_value());
    ASSERT_TRUE(got.clip.has_value());
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(got.slice->p[k], s.slice->p[k]);
      EXPECT_EQ(got.slice->n[k], s.slice->n[k]);
      EXPECT_EQ(got.clip->p[k], s.clip->p[k]);
      EXPECT_EQ(got.clip->n[k], s.clip->n[k]);
    }
    EXPECT_EQ(again.view_widget()->view()->drawn().size(), drawn);
    EXPECT_TRUE(again.view_widget()->view()->framebuffer().id == ids) << "the same picture";
    auto* slice = again.findChild<QCheckBox*>("slice");
    ASSERT_NE(slice, nullptr);
    EXPECT_TRUE(slice->isChecked());
  }
  const auto file = dir.path() / "proj" / "project.json";
  QJsonObject p = QJsonDocument::fromJson(QByteArray::fromStdString(foxi::test::read_text(file))).object();
  QJsonObject sel = p["selection"].toObject();
  ASSERT_TRUE(sel.contains("slice"));
  sel.remove("slice");
  p["selection"] = sel;
  foxi::test::write_text(file, QJsonDocument(p).toJson().toStdString());
  Workbench old;
  ASSERT_TRUE(reopen(old, folder, {200, 150}, Shown::yes));
  old.view_widget()->finish_now();
  EXPECT_FALSE(old.view_widget()->selection().slice.has_value());
  EXPECT_TRUE(old.view_widget()->selection().clip.has_value());
  EXPECT_GT(old.view_widget()->view()->drawn().size(), drawn) << "the clip's half, whole tets";
}

// Each history row keeps the mesh settings that made its mesh: in the row's tooltip (lengths in the
// model's mm), in a saved project and reopened with it. Row 2's mesh is mesh_model's with those
// settings (the library as the second caller). A project saved before rows kept them opens, its rows
// saying so; a malformed row's settings are refused with the file, the row and the reason.
TEST(Workbench, HistoryRowsKeepTheirMeshSettings) {
  TempDir dir;
  const std::string model = kModels + "die_on_substrate.toml";
  const QString folder = QString::fromStdString((dir.path() / "proj").string());
  foxi::workbench::MeshSettings second;
  second.max_size = 1.5e-3;
  second.part_sizes = {{.part = "die", .max_size = 0.4e-3}};
  second.quality = 1.6;
  second.boxes = {box_from_origin(2e-3, 10e-3, 1e-3, 0.5e-3)};
  const QStringList first_text = {"mesher: TetGen", "global size: the model's", "part sizes: the model's",
                                  "refinement boxes: none", "quality bound: the default"};
  const QStringList second_text = {"mesher: TetGen", "global size: 1.5 mm", "part sizes: die 0.4 mm",
                                   "refinement box 1: (0, 0, 0) to (2, 10, 1) mm, size 0.5 mm",
                                   "quality bound: 1.6"};
  auto tooltips = [](Workbench& w, int row, const QStringList& lines) {
    auto* table = w.findChild<QTableWidget*>("history_table");
    ASSERT_NE(table, nullptr);
    ASSERT_LT(row, table->rowCount());
    for (int c = 0; c < table->columnCount(); ++c) {
      const QString tip = table->item(row, c)->toolTip();
      for (const QString& line : lines) EXPECT_TRUE(tip.contains(line)) << tip.toStdString();
    }
  };
  {
    Workbench w;
    ASSERT_TRUE(open_window(w, model, {160, 120}, Shown::no));
    ASSERT_TRUE(meshed(w));
    QString why;
    ASSERT_TRUE(w.set_mesh_settings(second, &why)) << why.toStdString();
    ASSERT_TRUE(solved(w));  // remeshed first: the settings changed
    ASSERT_EQ(w.history().size(), 2u);
    ASSERT_TRUE(w.history()[0].mesh_settings.has_value());
    expect_same_settings(*w.history()[0].mesh_settings, {}, "row 1");
    ASSERT_TRUE(w.history()[1].mesh_settings.has_value());
    expect_same_settings(*w.history()[1].mesh_settings, second, "row 2");
    foxi::ModelMeshOptions o;
    o.max_size = second.max_size;
    o.part_sizes = second.part_sizes;
    o.quality = second.quality;
    o.sizes.boxes = second.boxes;
    EXPECT_EQ(w.history()[1].tets, foxi::mesh_model(model, {}, o).mesh.tet_count());
    EXPECT_NE(w.history()[1].tets, w.history()[0].tets);
    tooltips(w, 0, first_text);
    tooltips(w, 1, second_text);
    ASSERT_TRUE(w.save_project(folder, &why)) << why.toStdString();
  }
  {
    Workbench again;
    ASSERT_TRUE(reopen(again, folder, {160, 120}));
    ASSERT_EQ(again.history().size(), 2u);
    ASSERT_TRUE(again.history()[0].mesh_settings.has_value());
    ASSERT_TRUE(again.history()[1].mesh_settings.has_value());
    expect_same_settings(*again.history()[0].mesh_settings, {}, "reopened row 1");
    expect_same_settings(*again.history()[1].mesh_settings, second, "reopened row 2");
    tooltips(again, 0, first_text);
    tooltips(again, 1, second_text);
  }
  const auto file = dir.path() / "proj" / "project.json";
  const QJsonObject saved =
      QJsonDocument::fromJson(QByteArray::fromStdString(foxi::test::read_text(file))).object();
  auto with_rows = [&](auto edit) {
    QJsonObject p = saved;
    QJsonArray rows = p["history"].toArray();
    for (int i = 0; i < rows.size(); ++i) {
      QJsonObject row = rows[i].toObject();
      edit(i, row);
      rows[i] = row;
    }
    p["history"] = rows;
    foxi::test::write_text(file, QJsonDocument(p).toJson().toStdString());
  };
  with_rows([](int, QJsonObject& row) { row.remove("mesh_settings"); });
  {
    Workbench old;
    ASSERT_TRUE(reopen(old, folder, {160, 120}));
    ASSERT_EQ(old.history().size(), 2u);
    EXPECT_FALSE(old.history()[0].mesh_settings.has_value());
    EXPECT_FALSE(old.history()[1].mesh_settings.has_value());
    tooltips(old, 1, {"mesh settings not recorded"});
  }
  with_rows([](int i, QJsonObject& row) {
    if (i == 1) row["mesh_settings"] = QJsonObject{{"mesher", "gmsh"}};
  });
  Workbench bad;
  QString why;
  EXPECT_FALSE(bad.open_project(folder, &why));
  EXPECT_NE(why.toStdString().find(
                file.string() + ": history row 2: mesh_settings: the mesher is tetgen or cgal, not 'gmsh'"),
            std::string::npos)
      << why.toStdString();
  EXPECT_EQ(bad.model(), nullptr) << "refused before anything changed";
}

// A job's duration on the progress bar: seconds, under 0.1 s milliseconds (a recolour's picture takes
// a few). After a recolour the bar says a duration above zero and at most the wall time measured
// here around the job (it read "0.00 s": the recolour's time was not taken).
TEST(Workbench, RecolourSaysItsDuration) {
  EXPECT_EQ(foxi::workbench::duration_text(1.234), "1.23 s");
  EXPECT_EQ(foxi::workbench::duration_text(12.34), "12.3 s");
  EXPECT_EQ(foxi::workbench::duration_text(0.0031415), "3.14 ms");
  EXPECT_EQ(foxi::workbench::duration_text(0.0000123), "0.0123 ms");
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(solved(w));
  const std::regex done("^([a-z ]+): done in ([0-9.]+) (s|ms)$");
  std::smatch m;
  std::string text = w.progress_bar()->format().toStdString();
  ASSERT_TRUE(std::regex_match(text, m, done)) << text;
  EXPECT_EQ(m[1].str(), "meshing and solving");
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(w.set_field("temperature", "coolwarm"));
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  text = w.progress_bar()->format().toStdString();
  ASSERT_TRUE(std::regex_match(text, m, done)) << text;
  EXPECT_EQ(m[1].str(), "colouring");
  const double said = std::stod(m[2].str()) * (m[3].str() == "ms" ? 1e-3 : 1);
  EXPECT_GT(said, 0) << text;
  EXPECT_LE(said, wall * 1.01) << text;  // 3 digits: rounded up by 0.5% at most
}

// At the default 860 px height the right side's two panels share the height: the results table shows
// at least 7 rows (it showed one: the mesh panel took the height, and the window grew to 1019 px),
// the mesh panel scrolls instead and keeps its part sizes in sight.
TEST(Workbench, SidePanelsShareTheHeightAt860) {
  Workbench w;
  w.show();
  ASSERT_TRUE(w.open_model(QString::fromStdString(kModels + "die_on_substrate.toml")));
  ASSERT_TRUE(solved(w));
  QApplication::processEvents();
  EXPECT_EQ(w.height(), 860);
  auto* results = w.findChild<QTableWidget*>("results");
  ASSERT_NE(results, nullptr);
  ASSERT_GE(results->rowCount(), 8);
  EXPECT_GE(results->viewport()->height(), 7 * results->rowHeight(0))
      << "results viewport " << results->viewport()->height() << " px, rows of " << results->rowHeight(0);
  auto* parts = w.findChild<QTableWidget*>("part_sizes");
  auto* scroll = w.findChild<QWidget*>("mesh_scroll");
  ASSERT_TRUE(parts && scroll);
  EXPECT_TRUE(parts->isVisible());
  const QPoint top = parts->mapTo(scroll, QPoint(0, 0));
  EXPECT_GE(top.y(), 0);
  EXPECT_LE(top.y() + parts->height(), scroll->height()) << "the part sizes in sight";
}

// Headless --solver ichol --units si: the printed results and solver are foxi solve --solver ichol
// --json's and the solve panel's (the same choices set in a window); the saved project has them (the
// units box on SI: the results table in K). Bad values: exit 2 with the usage.
TEST(WorkbenchHeadless, SolverAndUnitsAsTheSolvePanel) {
  TempDir dir;
  const std::string model = kModels + "die_on_substrate.toml";
  const auto proj = dir.path() / "proj", log = dir.path() / "wb.log";
  const std::string wb = "'" + std::string(FOXI_WORKBENCH_PATH) + "' '" + model + "' --headless ";
  ASSERT_EQ(foxi::test::run(wb +
                                "--physics thermal --solver ichol --units si --view-size 160x120 "
                                "--save-project '" +
                                proj.string() + "'",
                            log),
            0)
      << foxi::test::read_text(log);
  const std::string out = foxi::test::read_text(log);
  const auto json = dir.path() / "solve.json";
  ASSERT_EQ(foxi::test::run_cli("solve '" + model + "' --solver ichol --json '" + json.string() + "'",
                                dir.path() / "solve.log"),
            0)
      << foxi::test::read_text(dir.path() / "solve.log");
  const foxi::RunResults cli = foxi::parse_results_json(foxi::test::read_text(json));
  auto line = [](const std::string& text, const std::string& key) {  // the rest of key's line
    const std::string rest = line_after(text, key);
    return rest.substr(0, rest.find('\n'));
  };
  EXPECT_EQ(line(out, "solver: "), cli.solver) << out;
  // The window's solve panel with the same choices.
  Workbench w;
  ASSERT_TRUE(open_window(w, model, {160, 120}, Shown::no));
  ASSERT_TRUE(w.set_solver({false, foxi::LinearSolverKind::cg_ichol}));
  ASSERT_TRUE(w.set_si_units(true));
  ASSERT_TRUE(solved(w));
  EXPECT_EQ(w.results()->solver, cli.solver);
  std::size_t keys = 0;
  for (const foxi::ResultValue& v : cli.values) {
    if (!v.key) continue;
    ++keys;
    const std::string shown = line(out, "\n" + v.name + " ");
    ASSERT_FALSE(shown.empty()) << v.name << "\n" << out;
    EXPECT_NEAR(std::stod(shown), v.value, 1e-5 * std::abs(v.value)) << v.name;
    EXPECT_NE(shown.find(" " + v.unit), std::string::npos) << "SI: " << shown;
    ASSERT_NE(w.results()->find(v.name), nullptr) << v.name;
    EXPECT_NEAR(w.results()->find(v.name)->value, v.value, 1e-9 * std::abs(v.value)) << v.name;
  }
  EXPECT_GE(keys, 1u);
  // The headless run's project: the solver and the units box as given.
  Workbench again;
  ASSERT_TRUE(reopen(again, QString::fromStdString(proj.string()), {160, 120}));
  EXPECT_FALSE(again.solver().calculix);
  EXPECT_EQ(again.solver().linear, foxi::LinearSolverKind::cg_ichol);
  EXPECT_TRUE(again.si_units());
  EXPECT_EQ(again.display_unit().symbol, "K");
  EXPECT_EQ(again.results()->solver, cli.solver);
  const foxi::ResultValue* t = cli.find("T_max");
  ASSERT_NE(t, nullptr);
  const auto [value, unit] = table_value(again, "T_max");
  EXPECT_EQ(unit, "K");
  EXPECT_NEAR(value, t->value, 1e-5 * t->value);
  // Without --units the engineer's units (°C) and the automatic solver: another solver name.
  ASSERT_EQ(foxi::test::run(wb + "--physics thermal --view-size 160x120", log), 0)
      << foxi::test::read_text(log);
  const std::string automatic = line(foxi::test::read_text(log), "solver: ");
  EXPECT_FALSE(automatic.empty());
  EXPECT_NE(automatic, cli.solver);
  // Bad values and combinations: usage (2), naming the option.
  const std::pair<const char*, const char*> bad[] = {
      {"--physics thermal --solver gauss", "--solver takes auto, direct, amg, ichol or ccx"},
      {"--physics thermal --units kelvin", "--units takes engineering"},
      {"--physics current --solver ccx", "--solver ccx solves the thermal problem only"},
      {"--solver ichol", "--solver picks the solve's solver: give --physics"},
      // As foxi render: an option given twice is refused (the last one once won in silence), and
      // the x-ray draws whole tets in their regions' colours.
      {"--physics thermal --range 0,1 --range 2,3", "--range given twice"},
      {"--physics thermal --physics current", "--physics given twice"},
      {"--physics thermal --xray --shrink 0.5", "--xray draws whole tets"},
  };
  for (const auto& [args, reason] : bad) {
    EXPECT_EQ(foxi::test::run(wb + args, log), 2) << args;
    const std::string text = foxi::test::read_text(log);
    EXPECT_NE(text.find(reason), std::string::npos) << text;
    EXPECT_NE(text.find("usage: "), std::string::npos) << text;
  }
}

// The solve's iterations: a CG solve's callbacks counted 1, 2, ..., N (N as foxi solve --solver ichol
// prints it for the same model), the progress never going back within a stage and the stages in
// order; a Cancel at iteration 5 stops the solve there. The workbench shows the iterations and the
// residual on its progress bar.
TEST(Workbench, SolveProgressIterationsAndCancelMidSolve) {
  const std::string model = kModels + "die_on_substrate.toml";
  foxi::MeshedModel mm = foxi::mesh_model(model, std::span<const foxi::ParameterOverride>{});
  auto cancel = std::make_shared<std::atomic<bool>>(false);
  auto permille = std::make_shared<std::atomic<int>>(0);
  auto solve = std::make_shared<foxi::workbench::SolveProgress>();
  foxi::LinearSolverOptions o =
      foxi::workbench::job_solver_options(foxi::LinearSolverKind::cg_ichol, cancel, permille, solve);
  std::vector<long> iterations;
  std::vector<int> shown;
  const auto inner_it = o.iterations;
  const auto inner_progress = o.progress;
  o.iterations = [&](const foxi::IterationReport& r) {
    const bool go = inner_it(r);
    iterations.push_back(solve->iteration.load());
    EXPECT_TRUE(std::isfinite(r.relative_residual));
    return go;
  };
  o.progress = [&](std::string_view stage, double f) {
    const bool go = inner_progress(stage, f);
    shown.push_back(permille->load());
    return go;
  };
  foxi::Mesh mesh = mm.mesh;
  const foxi::RunResults r =
      foxi::workbench::solve_model_physics(model, mm.model, mesh, foxi::Physics::thermal, o);
  ASSERT_FALSE(iterations.empty());
  for (std::size_t i = 0; i < iterations.size(); ++i) EXPECT_EQ(iterations[i], long(i + 1));
  EXPECT_LE(solve->residual.load(), 1e-10);
  for (std::size_t i = 1; i < shown.size(); ++i) EXPECT_GE(shown[i], shown[i - 1]) << "report " << i;
  // foxi solve's count of the same solve
  TempDir dir;
  ASSERT_EQ(foxi::test::run_cli("solve '" + model + "' --solver ichol", dir.path() / "solve.log"), 0);
  std::smatch m;
  const std::string log = foxi::test::read_text(dir.path() / "solve.log");
  ASSERT_TRUE(std::regex_search(log, m, std::regex("([0-9]+) iterations"))) << log;
  EXPECT_EQ(iterations.back(), std::stol(m[1]));
  // Cancelled at iteration 5: the solve stops there, the mesh gets no field.
  iterations.clear();
  o.iterations = [&](const foxi::IterationReport& rep) {
    if (rep.iteration == 5) cancel->store(true);
    iterations.push_back(long(rep.iteration));
    return inner_it(rep);
  };
  foxi::Mesh again = mm.mesh;
  bool stopped = false;
  try {
    foxi::workbench::solve_model_physics(model, mm.model, again, foxi::Physics::thermal, o);
  } catch (const foxi::Cancelled&) {
    stopped = true;
  }
  EXPECT_TRUE(stopped);
  EXPECT_EQ(iterations.back(), 5);
  EXPECT_EQ(again.find_field("temperature"), nullptr);
  // The label: the stage, the iteration and the residual.
  solve->iteration.store(12);
  solve->residual.store(3.5e-7);
  const QString label = foxi::workbench::progress_format("solving", 5 * 10000 + 400, solve.get());
  EXPECT_TRUE(label.contains("(solve)")) << label.toStdString();
  EXPECT_TRUE(label.contains("iteration 12, residual 3.5e-07")) << label.toStdString();
  solve->points.store(3);  // a sweep's point
  solve->point.store(2);
  const QString sweep = foxi::workbench::progress_format("sweep of die_w", 1 * 10000 + 300, solve.get());
  EXPECT_TRUE(sweep.startsWith("sweep of die_w, point 2 of 3 (meshing)")) << sweep.toStdString();
  EXPECT_FALSE(sweep.contains("iteration")) << "no iteration while meshing";
  // The workbench with CG: the iterations of its solve as foxi solve counts them, and a Cancel keeps
  // the previous results.
  Workbench w;
  ASSERT_TRUE(open_window(w, model, {200, 150}, Shown::no));
  ASSERT_TRUE(w.set_solver({false, foxi::LinearSolverKind::cg_ichol}));
  ASSERT_TRUE(solved(w));
  EXPECT_EQ(w.solve_iterations(), std::stol(m[1]));
  EXPECT_EQ(w.results()->solver, "CG+IncompleteCholesky");
  const double t_max = w.results()->find("T_max")->value;
  ASSERT_TRUE(w.start_solve());
  w.cancel();
  EXPECT_FALSE(wait_job(w));
  EXPECT_EQ(w.last_error(), "cancelled");
  ASSERT_NE(w.results(), nullptr);
  EXPECT_EQ(w.results()->find("T_max")->value, t_max);
  // Cancel once CG has begun (the GUI thread watching the count): the solve stops, the results stay.
  ASSERT_TRUE(w.start_solve());
  const auto t0 = std::chrono::steady_clock::now();
  while (w.busy() && w.solve_iterations() == 0 &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60))
    QApplication::processEvents(QEventLoop::AllEvents);
  w.cancel();
  // (on a machine that gives this thread no core for the few ms CG takes, the solve ends first)
  const bool running = w.busy();
  if (running) {
    EXPECT_FALSE(wait_job(w));
    EXPECT_EQ(w.last_error(), "cancelled");
    EXPECT_GT(w.solve_iterations(), 0);
    EXPECT_LE(w.solve_iterations(), std::stol(m[1]));
  }
  std::printf("Cancel %s, at CG iteration %ld of %ld\n",
              running ? "while the job ran" : "after the job had ended", w.solve_iterations(),
              std::stol(m[1]));
  ASSERT_NE(w.results(), nullptr);
  EXPECT_EQ(w.results()->find("T_max")->value, t_max);
}

// The work folders and child processes a CalculiX run leaves (none, when it is done or cancelled).
std::size_t ccx_folders() {
  std::size_t n = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::temp_directory_path()))
    n += e.path().filename().string().rfind("foxi-ccx-", 0) == 0;
  return n;
}
std::size_t child_processes() {
  std::size_t n = 0;
  const std::string me = std::to_string(::getpid());
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string stat = foxi::test::read_text(e.path() / "stat");
    // pid (comm) state ppid ...
    const std::size_t close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(stat.substr(close + 1));
    std::string state, ppid;
    rest >> state >> ppid;
    n += ppid == me;
  }
  return n;
}

// The test's own TMPDIR for its lifetime: the CalculiX runs' work folders go there, so that counting
// them sees no other test's (ctest -j runs the other CalculiX tests beside this one).
struct PrivateTmpdir {
  PrivateTmpdir() : old(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "") {
    ::setenv("TMPDIR", dir.path().c_str(), 1);
  }
  ~PrivateTmpdir() {
    if (old.empty())
      ::unsetenv("TMPDIR");
    else
      ::setenv("TMPDIR", old.c_str(), 1);
  }
  foxi::test::TempDir dir;
  std::string old;
};

// A solve by ccx cancelled while ccx runs: the previous results (their value `key`) stay, no work
// folder beyond the `folders` there were and no child process is left behind.
void cancel_while_ccx_runs(Workbench& w, const char* key, std::size_t folders) {
  ASSERT_NE(w.results(), nullptr);
  const double before = w.results()->find(key)->value;
  ASSERT_TRUE(w.start_solve());
  while (w.busy() && !w.progress_bar()->format().contains("(ccx)"))
    QApplication::processEvents(QEventLoop::AllEvents, 5);
  w.cancel();
  // (on a machine where ccx ends before the progress poll shows it, the solve ends before the Cancel)
  std::printf("Cancel %s\n", w.busy() ? "while ccx ran" : "after ccx had ended");
  if (w.busy()) {
    EXPECT_FALSE(wait_job(w));
    EXPECT_EQ(w.last_error(), "cancelled");
  }
  ASSERT_NE(w.results(), nullptr);
  EXPECT_EQ(w.results()->find(key)->value, before);
  EXPECT_EQ(ccx_folders(), folders);
  EXPECT_EQ(child_processes(), 0u) << "ccx killed and reaped";
}

// CalculiX from the solve panel: ccx's temperature on the same mesh equals the built-in solver's with
// ccx's convection rule to ccx's output precision (foxi solve --with ccx --compare's bound, 1e-5 of
// the largest), and the workbench's own solve (the exact convection integral) within 1e-3
// (calculix_test's bound across the rules); its balance checks pass; a ccx run cancelled keeps the
// previous results and leaves no work folder and no child process.
TEST(Workbench, CalculixTemperatureEqualsBuiltIn) {
  if (foxi::test::run("command -v ccx > /dev/null") != 0) GTEST_SKIP() << "ccx is not installed";
  const PrivateTmpdir tmpdir;
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(solved(w));
  const std::vector<double> own = w.mesh()->find_field("temperature")->values;
  const double own_t_max = w.results()->find("T_max")->value;
  const std::size_t folders = ccx_folders();
  ASSERT_TRUE(w.set_physics(foxi::Physics::current));
  EXPECT_FALSE(w.set_solver({true, foxi::LinearSolverKind::automatic}))
      << "CalculiX is for the thermal problem";
  ASSERT_TRUE(w.set_physics(foxi::Physics::thermal));
  ASSERT_TRUE(w.set_solver({true, foxi::LinearSolverKind::automatic}));
  ASSERT_TRUE(solved(w));
  ASSERT_NE(w.results(), nullptr);
  EXPECT_EQ(w.results()->solver, "ccx");
  ASSERT_EQ(w.history().size(), 2u);
  EXPECT_EQ(w.history()[1].mesh, w.history()[0].mesh) << "the same mesh: solved again, not remeshed";
  const std::vector<double> ccx = w.mesh()->find_field("temperature")->values;
  ASSERT_EQ(ccx.size(), own.size());
  // foxi's solve of the same mesh with ccx's *FILM rule (the convection integral at face centroids)
  foxi::Mesh same_rule = *w.mesh();
  foxi::ThermalParams params = foxi::thermal_params_from_model(*w.model(), same_rule);
  params.convection_centroid_rule = true;
  const foxi::ThermalReport rep = foxi::solve_thermal(same_rule, params);
  const std::vector<double>& centroid = same_rule.find_field("temperature")->values;
  auto largest = [&](const std::vector<double>& a) {
    double diff = 0, scale = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      diff = std::max(diff, std::abs(ccx[i] - a[i]));
      scale = std::max(scale, std::abs(ccx[i]));
    }
    return diff / scale;
  };
  EXPECT_LE(largest(centroid), 1e-5);
  EXPECT_LE(largest(own), 1e-3);
  EXPECT_NEAR(w.results()->find("T_max")->value, rep.max_temperature, 1e-5 * rep.max_temperature);
  EXPECT_NEAR(w.results()->find("T_max")->value, own_t_max, 1e-3 * own_t_max);
  ASSERT_FALSE(w.results()->checks.empty());
  for (const foxi::BalanceCheck& c : w.results()->checks) EXPECT_TRUE(c.passed) << c.name;
  EXPECT_EQ(ccx_folders(), folders) << "the work folder removed";
  cancel_while_ccx_runs(w, "T_max", folders);
}

// CalculiX for the thermal stress from the solve panel (solve_thermoelastic_calculix): on the same
// mesh, ccx's displacement equals the built-in solver's to 1e-5 of the largest (foxi solve --with ccx
// --compare's bound, ccx_cli's ThermoelasticWithCcxAgreesWithFoxiAndRenders), and the von Mises
// results, derived by foxi from ccx's displacements, to 1e-6 of the largest von Mises stress (the
// bound of ccx_cli's record comparison); the per-tet von Mises field to 1e-5 of its largest (the
// displacement's bound: a derivative of the same float32 rounding). The results show as the
// built-in ones (the von Mises field, the deformed shape); its checks (the built-in's) pass; ccx's nodal
// stress comes along as stress_nodal. Cancel while ccx runs keeps the previous results and leaves no work
// folder and no child process.
TEST(Workbench, CalculixThermalStressEqualsBuiltIn) {
  if (foxi::test::run("command -v ccx > /dev/null") != 0) GTEST_SKIP() << "ccx is not installed";
  const PrivateTmpdir tmpdir;
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml", {200, 150}, Shown::no));
  ASSERT_TRUE(w.set_physics(foxi::Physics::thermal_stress));
  ASSERT_TRUE(solved(w));
  const std::vector<double> own_u = w.mesh()->find_field("displacement")->values;
  const std::vector<double> own_vm = w.mesh()->find_field("von_mises")->values;
  const foxi::RunResults own = *w.results();
  const std::size_t folders = ccx_folders();
  ASSERT_TRUE(w.set_solver({true, foxi::LinearSolverKind::automatic}));
  ASSERT_TRUE(solved(w));
  ASSERT_NE(w.results(), nullptr);
  EXPECT_EQ(w.results()->solver, "ccx");
  ASSERT_EQ(w.history().size(), 2u);
  EXPECT_EQ(w.history()[1].mesh, w.history()[0].mesh) << "the same mesh: solved again, not remeshed";
  const foxi::Field* u = w.mesh()->find_field("displacement");
  const foxi::Field* vm = w.mesh()->find_field("von_mises");
  const foxi::Field* nodal = w.mesh()->find_field("stress_nodal");
  ASSERT_TRUE(u && vm && nodal);
  ASSERT_EQ(u->values.size(), own_u.size());
  ASSERT_EQ(vm->values.size(), own_vm.size());
  EXPECT_EQ(nodal->components, 6u);
  auto largest = [](const std::vector<double>& a, const std::vector<double>& b) {
    double diff = 0, scale = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      diff = std::max(diff, std::abs(a[i] - b[i]));
      scale = std::max(scale, std::abs(b[i]));
    }
    return diff / scale;
  };
  const double du = largest(u->values, own_u), dvm = largest(vm->values, own_vm);
  std::printf("ccx against built-in: displacement %.3g, von Mises field %.3g of the largest\n", du, dvm);
  EXPECT_GT(*std::max_element(own_u.begin(), own_u.end()), 1e-8) << "the die and substrate do move";
  EXPECT_LE(du, 1e-5);
  EXPECT_LE(dvm, 1e-5);
  const double vm_max = own.find("von_mises_max")->value;
  EXPECT_GT(vm_max, 1e6);
  std::size_t compared = 0;
  for (const foxi::ResultValue& v : own.values) {
    if (v.unit != "Pa") continue;
    const foxi::ResultValue* c = w.results()->find(v.name);
    ASSERT_NE(c, nullptr) << v.name;
    EXPECT_NEAR(c->value, v.value, 1e-6 * vm_max) << v.name;
    ++compared;
  }
  EXPECT_GE(compared, 4u) << "the maximum, per region and per interface";
  ASSERT_EQ(w.results()->checks.size(), own.checks.size()) << "the built-in solve's checks";
  for (const foxi::BalanceCheck& c : w.results()->checks) EXPECT_TRUE(c.passed) << c.name;
  EXPECT_EQ(ccx_folders(), folders) << "the work folder removed";
  // The deformed shape of ccx's displacement, as of the built-in one.
  ASSERT_TRUE(w.set_deform(foxi::workbench::Deform{"displacement", 150}));
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  ASSERT_NE(w.view_widget()->mesh(), nullptr);
  const std::vector<double>& moved = w.view_widget()->mesh()->xyz;
  ASSERT_EQ(moved.size(), w.mesh()->xyz.size());
  double moved_most = 0;
  for (std::size_t i = 0; i < moved.size(); ++i)
    moved_most = std::max(moved_most, std::abs(moved[i] - w.mesh()->xyz[i] - 150 * u->values[i]));
  EXPECT_LE(moved_most, 1e-12) << "each node moved by 150 x ccx's displacement";
  cancel_while_ccx_runs(w, "von_mises_max", folders);
}

// A sweep started from the history: each point's row equals foxi sweep's CSV row for the same model,
// parameter and values (tets, every key result); a value the geometry refuses is a failed row with
// its error and the sweep goes on; a cancelled sweep adds no row.
TEST(Workbench, SweepFromTheHistoryEqualsFoxiSweep) {
  TempDir dir;
  const std::string model = kModels + "die_on_substrate.toml";
  Workbench w;
  ASSERT_TRUE(open_window(w, model, {200, 150}, Shown::no));
  QString error;
  const QStringList values = Workbench::sweep_values("2mm", "6mm", 3, &error);
  ASSERT_EQ(values, (QStringList{"2mm", "4mm", "6mm"})) << error.toStdString();
  EXPECT_TRUE(Workbench::sweep_values("2mm", "6 W", 3, &error).isEmpty());
  EXPECT_TRUE(error.contains("dimension")) << error.toStdString();
  EXPECT_FALSE(w.start_sweep("no_such", values, &error));
  ASSERT_TRUE(w.start_sweep("die_w", values, &error)) << error.toStdString();
  EXPECT_FALSE(w.start_solve()) << "one job at a time";
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  ASSERT_EQ(w.history().size(), 3u);
  EXPECT_EQ(w.mesh(), nullptr) << "a sweep shows nothing new";
  const auto csv = dir.path() / "sweep.csv";
  ASSERT_EQ(
      foxi::test::run_cli("sweep '" + model + "' --vary die_w=2mm:6mm:3 --jobs 1 -o '" + csv.string() + "'",
                          dir.path() / "sweep.log"),
      0)
      << foxi::test::read_text(dir.path() / "sweep.log");
  std::istringstream lines(foxi::test::read_text(csv));
  std::string header, line;
  std::getline(lines, header);
  auto split = [](const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string f; std::getline(ss, f, ',');) out.push_back(f);
    if (!s.empty() && s.back() == ',') out.emplace_back();  // (getline drops a last empty field)
    return out;
  };
  const std::vector<std::string> names = split(header);
  for (std::size_t k = 0; k < 3; ++k) {
    ASSERT_TRUE(std::getline(lines, line));
    const std::vector<std::string> f = split(line);
    ASSERT_EQ(f.size(), names.size()) << line;
    const foxi::workbench::HistoryRow& row = w.history()[k];
    ASSERT_EQ(row.parameters.size(), 1u);
    EXPECT_EQ(row.parameters[0].expression, values[int(k)].toStdString());
    // The mesh settings of the point's mesh: the panel's defaults, as foxi sweep meshes (same tets below).
    ASSERT_TRUE(row.mesh_settings.has_value());
    expect_same_settings(*row.mesh_settings, {}, "sweep row");
    std::size_t compared = 0;
    for (std::size_t c = 0; c < names.size(); ++c) {
      if (names[c] == "die_w") {
        EXPECT_EQ(f[c], values[int(k)].toStdString());
      }
      if (names[c] == "tets") {
        EXPECT_EQ(std::stoul(f[c]), row.tets);
      }
      if (names[c] == "status") {
        EXPECT_EQ(f[c], "ok");
      }
      const std::size_t paren = names[c].find(" (");
      const foxi::ResultValue* v = row.results.find(names[c].substr(0, paren));
      if (v == nullptr || !v->key || f[c].empty()) continue;
      EXPECT_NEAR(v->value, std::stod(f[c]), 1e-9 * std::abs(v->value) + 1e-300) << names[c] << " row " << k;
      ++compared;
    }
    EXPECT_GT(compared, 0u) << "the rows share key results";
  }
  // A value the geometry refuses is that point's failed row; the sweep goes on.
  ASSERT_TRUE(w.start_sweep("die_w", {"-1mm", "3mm"}, &error)) << error.toStdString();
  ASSERT_TRUE(wait_job(w)) << w.last_error().toStdString();
  ASSERT_EQ(w.history().size(), 5u);
  EXPECT_EQ(w.history()[3].results.status, foxi::RunStatus::failed);
  EXPECT_FALSE(w.history()[3].results.error.empty());
  EXPECT_NE(w.history()[4].results.find("T_max"), nullptr);
  // The plot of a result against the parameter shows the sweep's points.
  const auto points = foxi::workbench::history_points(model, w.history(), "die_w", "T_max");
  EXPECT_EQ(points.rows, (std::vector<std::size_t>{0, 1, 2, 4}));
  // Cancelled: no row added.
  ASSERT_TRUE(w.start_sweep("die_w", values, &error));
  w.cancel();
  EXPECT_FALSE(wait_job(w));
  EXPECT_EQ(w.last_error(), "cancelled");
  EXPECT_EQ(w.history().size(), 5u);
}

// The view follows the fraction slider both ways: drawing on to it and undrawing back to it; a
// fraction's picture equals a draw of that many tets from scratch (InteractiveView's undraw rule).
TEST(ViewWidget, FractionDrawsAndUndraws) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(meshed(w));
  foxi::qt::ViewWidget* v = w.view_widget();
  v->finish_now();
  const std::size_t total = v->view()->total();
  auto settle = [&] {
    for (int i = 0; i < 100000 && v->busy(); ++i) QApplication::processEvents();
  };
  v->set_fraction(0.25);
  settle();
  EXPECT_EQ(v->view()->drawn().size(), std::size_t(std::llround(0.25 * double(total))));
  const std::vector<std::uint32_t> quarter_ids = v->view()->framebuffer().id;
  v->set_fraction(0.75);
  settle();
  EXPECT_EQ(v->view()->drawn().size(), std::size_t(std::llround(0.75 * double(total))));
  v->set_fraction(0.25);
  settle();
  EXPECT_EQ(v->view()->drawn().size(), std::size_t(std::llround(0.25 * double(total))));
  EXPECT_TRUE(v->view()->framebuffer().id == quarter_ids) << "undrawn back to the same picture";
}

// A region of interest: the tets drawn become the displayed set and the camera is re-framed on them
// (looking at the centre of their bounds, computed here from their corners); Back restores all.
TEST(ViewWidget, RegionOfInterestReframes) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(meshed(w));
  foxi::qt::ViewWidget* v = w.view_widget();
  v->finish_now();
  v->set_fraction(0.2);
  for (int i = 0; i < 100000 && v->busy(); ++i) QApplication::processEvents();
  const std::vector<std::uint32_t> region = v->view()->drawn();
  ASSERT_FALSE(region.empty());
  const foxi::Mesh& m = *w.mesh();
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::uint32_t t : region)
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) {
        const double x = m.xyz[3 * std::size_t(m.tet[4 * std::size_t(t) + std::size_t(k)]) + std::size_t(j)];
        lo[j] = std::min(lo[j], x);
        hi[j] = std::max(hi[j], x);
      }
  ASSERT_TRUE(v->push_region());
  EXPECT_EQ(v->view()->total(), region.size());
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(v->camera()->at[j], 0.5 * (lo[j] + hi[j]), 1e-12);
  v->finish_now();
  EXPECT_EQ(v->view()->drawn().size(), region.size());
  ASSERT_TRUE(v->pop_region());
  EXPECT_EQ(v->view()->total(), m.tet_count());
  EXPECT_FALSE(v->pop_region());
}

// The mouse, as Qt delivers it: left-drag orbits (the eye turns about `at` at the same distance),
// middle-drag pans (eye and `at` move together), the wheel and right-drag zoom (wheel forward and
// right-drag up bring the eye closer); each restarts the draw.
TEST(ViewWidget, MouseOrbitsPansZooms) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(meshed(w));
  foxi::qt::ViewWidget* v = w.view_widget();
  auto dist = [](const foxi::Camera& c) {
    return std::hypot(c.eye[0] - c.at[0], c.eye[1] - c.at[1], c.eye[2] - c.at[2]);
  };
  auto drag = [&](Qt::MouseButton button, QPoint from, QPoint to) {
    QMouseEvent press(QEvent::MouseButtonPress, from, button, button, Qt::NoModifier);
    QApplication::sendEvent(v, &press);
    QMouseEvent move(QEvent::MouseMove, to, Qt::NoButton, button, Qt::NoModifier);
    QApplication::sendEvent(v, &move);
    QMouseEvent release(QEvent::MouseButtonRelease, to, button, Qt::NoButton, Qt::NoModifier);
    QApplication::sendEvent(v, &release);
  };
  foxi::Camera c0 = *v->camera();
  drag(Qt::LeftButton, {100, 75}, {130, 75});
  foxi::Camera c1 = *v->camera();
  EXPECT_GT(std::hypot(c1.eye[0] - c0.eye[0], c1.eye[1] - c0.eye[1], c1.eye[2] - c0.eye[2]), 1e-3 * dist(c0));
  EXPECT_NEAR(dist(c1), dist(c0), 1e-12 * dist(c0));
  for (int j = 0; j < 3; ++j) EXPECT_DOUBLE_EQ(c1.at[j], c0.at[j]);
  EXPECT_TRUE(v->busy()) << "the move restarted the draw";

  drag(Qt::MiddleButton, {100, 75}, {110, 90});
  foxi::Camera c2 = *v->camera();
  double moved = 0;
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(c2.eye[j] - c2.at[j], c1.eye[j] - c1.at[j], 1e-12 * dist(c1));
    moved += std::abs(c2.at[j] - c1.at[j]);
  }
  EXPECT_GT(moved, 1e-4 * dist(c1));

  QWheelEvent wheel(QPointF(100, 75), v->mapToGlobal(QPoint(100, 75)), QPoint(), QPoint(0, 120), Qt::NoButton,
                    Qt::NoModifier, Qt::NoScrollPhase, false);
  QApplication::sendEvent(v, &wheel);
  foxi::Camera c3 = *v->camera();
  EXPECT_NEAR(dist(c3), dist(c2) / 1.1, 1e-9 * dist(c2));
  drag(Qt::RightButton, {100, 75}, {100, 55});  // up: closer
  EXPECT_LT(dist(*v->camera()), dist(c3));
  v->finish_now();
  EXPECT_EQ(v->view()->drawn().size(), w.mesh()->tet_count());
}

// The value under the mouse: the tet at the pixel (the id buffer) and its temperature in °C, against
// the mean of its 4 nodes' temperatures computed here from the node field (flat paint: the tet's
// colour shows its centroid value); the status names the order method and the certificate.
TEST(ViewWidget, ValueUnderTheMouseAndStatus) {
  Workbench w;
  ASSERT_TRUE(open_window(w, kModels + "die_on_substrate.toml"));
  ASSERT_TRUE(meshed(w));
  ASSERT_TRUE(solved(w));
  foxi::qt::ViewWidget* v = w.view_widget();
  v->finish_now();
  EXPECT_NE(v->status_text().indexOf("power order, Delaunay certified"), -1)
      << v->status_text().toStdString();
  const foxi::Mesh& m = *w.mesh();
  const foxi::Field* temp = nullptr;
  for (const foxi::Field& f : m.fields)
    if (f.name == "temperature") temp = &f;
  ASSERT_NE(temp, nullptr);
  const foxi::Framebuffer& fb = v->view()->framebuffer();
  int checked = 0;
  for (int y = 10; y < fb.height; y += 23)
    for (int x = 10; x < fb.width; x += 29) {
      const std::uint32_t t = fb.id[std::size_t(y) * std::size_t(fb.width) + std::size_t(x)];
      const QString text = v->probe_text(x, y);
      if (t == foxi::kNone) {
        EXPECT_TRUE(text.isEmpty());
        continue;
      }
      double mean = 0;
      for (int k = 0; k < 4; ++k) mean += 0.25 * temp->values[m.tet[4 * std::size_t(t) + std::size_t(k)]];
      const std::regex re("^tet ([0-9]+), region [a-z]+, ([-0-9.e+]+) °C$");
      std::smatch match;
      const std::string s = text.toStdString();
      ASSERT_TRUE(std::regex_match(s, match, re)) << s;
      EXPECT_EQ(std::stoul(match[1]), t);
      EXPECT_NEAR(std::stod(match[2]), mean - 273.15, 1e-3) << s;
      ++checked;
    }
  EXPECT_GT(checked, 5);
}

// The GUI thread never stalls: a 10 ms timer's longest gap while the flip chip is meshed, solved
// and drawn progressively (the widget's own time slices, no finish_now) stays within 100 ms. The
// machine is shared (CI and here: 2 cores, other processes): a gap also counts the time the OS gave
// the GUI thread no core, so the loop runs up to 3 times and the best run must pass; a stall of the
// program's own (work on the GUI thread) is in every run and fails all three.
double longest_gap_ms() {
  Workbench w;
  w.view_widget()->setFixedSize(480, 360);
  w.show();
  QApplication::processEvents();
  using Clock = std::chrono::steady_clock;
  Clock::time_point last = Clock::now();
  double longest = 0;
  QTimer beat;
  beat.setInterval(10);
  QObject::connect(&beat, &QTimer::timeout, [&] {
    const Clock::time_point now = Clock::now();
    longest = std::max(longest, std::chrono::duration<double, std::milli>(now - last).count());
    last = now;
  });
  EXPECT_TRUE(w.open_model(QString::fromStdString(kModels + "flip_chip.toml")));
  last = Clock::now();
  beat.start();
  EXPECT_TRUE(w.start_mesh());
  EXPECT_TRUE(wait_job(w)) << w.last_error().toStdString();
  EXPECT_TRUE(w.start_solve());
  EXPECT_TRUE(wait_job(w)) << w.last_error().toStdString();
  foxi::qt::ViewWidget* v = w.view_widget();
  QEventLoop loop;
  QObject::connect(v, &foxi::qt::ViewWidget::draw_finished, &loop, &QEventLoop::quit);
  QTimer::singleShot(60000, &loop, &QEventLoop::quit);
  if (v->busy()) loop.exec();
  beat.stop();
  EXPECT_FALSE(v->busy());
  EXPECT_EQ(v->view()->drawn().size(), w.mesh()->tet_count());
  std::printf("longest GUI-thread gap %.1f ms over mesh + solve + draw of %zu tets\n", longest,
              w.mesh()->tet_count());
  return longest;
}

TEST(Workbench, HeartbeatDuringMeshSolveDraw) {
  double best = 1e300;
  for (int run = 0; run < 3 && best > 100.0; ++run) best = std::min(best, longest_gap_ms());
  EXPECT_LE(best, 100.0) << "longest GUI-thread gap in the best of 3 runs";
  RecordProperty("longest_gap_ms", std::to_string(best));
}

}  // namespace

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // No display needed (CTest sets it too; this covers a direct run and the test discovery).
  setenv("QT_QPA_PLATFORM", "offscreen", 0);
  QApplication app(argc, argv);
  return RUN_ALL_TESTS();
}
