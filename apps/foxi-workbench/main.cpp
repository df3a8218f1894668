// foxi-workbench [MODEL.toml] [--headless ...]: the Qt5 workbench (workbench.hpp). With --headless it
// runs the loop once without a user -- load, --set, mesh, solve, show, save -- for tests and scripts
// (QT_QPA_PLATFORM=offscreen: no display needed).
#include <QApplication>
#include <QEventLoop>
#include <QPixmap>
#include <QStandardPaths>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "../foxi/exit_codes.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/view_options.hpp"
#include "workbench.hpp"
#include "workbench_parts.hpp"

namespace {

const char* kUsage =
    "foxi-workbench [MODEL.toml]\n"
    "foxi-workbench MODEL.toml --headless [--set NAME=VALUE]... [--physics NAME] [--field NAME]\n"
    "               [--solver auto|direct|amg|ichol|ccx] [--units engineering|si]\n"
    "               [--cmap viridis|cividis|coolwarm|rainbow] [--shrink F] [--view-size WxH]\n"
    "               [--regions ID,...] [--graded] [--range a,b] [--iso v [--iso-only]] [--threshold a,b] "
    "[--clip px,py,pz,nx,ny,nz] [--slice px,py,pz,nx,ny,nz] [--deform NAME:SCALE]\n"
    "               [--xray] [--save-movie OUT.gif|OUT.apng|DIR/frame_%04d.png [--movie-frames N]]\n"
    "               [--save-project FOLDER] [--screenshot WINDOW.png] [--save-picture VIEW.png] [--save-mesh "
    "MESH.vtu]\n"
    "  The window: open a model, edit its parameters (with units, checked as the model file would\n"
    "  be), mesh and solve on worker threads (Cancel keeps the previous mesh), look inside with the\n"
    "  painter (draw, stop, step, undraw, the drawn-fraction slider, regions of interest), colour by a\n"
    "  field with a legend, and compare runs in the history.\n"
    "  --headless runs the loop once without a user: loads MODEL, applies the --set values, meshes,\n"
    "  solves (--physics thermal|electrostatic|current|thermoelastic: the model's conditions and loads\n"
    "  of it, as foxi solve MODEL --physics NAME), shows --field (default the solve's temperature,\n"
    "  potential or von_mises), draws the view\n"
    "  completely and saves the window (--screenshot), the view's own picture (--save-picture: what\n"
    "  foxi render draws for the same mesh, field and camera) and the mesh with its fields\n"
    "  (--save-mesh). Prints the tets, the key results, the solver used and the camera as foxi render\n"
    "  options.\n"
    "  --save-project writes the project folder (Save project in the window).\n"
    "  --solver picks the solve panel's solver: foxi's linear solver (auto, direct, amg: CG + AMG,\n"
    "  ichol: CG + IC, as foxi solve --solver) or ccx, CalculiX (thermal only, as foxi solve --with ccx).\n"
    "  --units sets the panel's units box: engineering (°C, MPa, µm, mV; the default) or si (K, Pa, m,\n"
    "  V) for the legend, the results table and the history; the printed results are SI either way.\n"
    "  --regions, --graded, --range, --iso, --iso-only, --threshold and --clip set the view's field tools as "
    "foxi render's options\n"
    "  of the same names draw them (values in the field's display unit, as the legend shows it).\n"
    "  --slice draws the plane's cut as foxi render --slice. --xray: every region translucent but the\n"
    "  smallest (printed as foxi render's --region-opacity), isotherms of --iso translucent inside\n"
    "  (--iso-opacity 0.5). --save-movie: the view's camera turned once around in --movie-frames N\n"
    "  frames (default 48), as foxi movie --mode rotate --frames N draws them.\n"
    "  --deform NAME:SCALE draws the deformed shape as foxi render --deform does (the status line says\n"
    "  the order: MPVO with the depth buffer where the moved mesh is not Delaunay).\n"
    "  Run it with QT_QPA_PLATFORM=offscreen where there is no display.\n"
    "  Exit status: 0 ok, 1 failure, 2 usage, 3 bad model or parameter, 4 a result failed its checks.";

struct Usage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Waits (serving events) for the workbench's running job; returns its outcome.
bool wait_job(foxi::workbench::Workbench& w) {
  if (!w.busy()) return false;
  bool ok = false;
  QEventLoop loop;
  QObject::connect(&w, &foxi::workbench::Workbench::finished, &loop, [&](bool r) {
    ok = r;
    loop.quit();
  });
  loop.exec();
  return ok;
}

// "a,b,c": finite numbers, exactly `count` of them (0: any number, at least one).
std::vector<double> parse_list(const std::string& s, const char* what, std::size_t count) {
  std::vector<double> v;
  std::size_t at = 0;
  while (at <= s.size()) {
    const std::size_t comma = std::min(s.find(',', at), s.size());
    const std::string item = s.substr(at, comma - at);
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != 0 || !std::isfinite(x))
      throw Usage(std::string(what) + " takes finite numbers separated by commas, not '" + s + "'");
    v.push_back(x);
    at = comma + 1;
  }
  if (count ? v.size() != count : v.empty())
    throw Usage(std::string(what) + " takes " + std::to_string(count) + " numbers, not '" + s + "'");
  return v;
}

// The field tools of the headless options, in the field's display unit.
struct ToolOptions {
  std::vector<double> iso;
  bool iso_only = false;
  std::vector<double> threshold, clip, slice;
  bool any() const { return !iso.empty() || !threshold.empty() || !clip.empty() || !slice.empty(); }
  bool xray = false;  // --xray
  std::string movie;  // --save-movie
  int movie_frames = 48;
  bool graded = false;
  std::vector<double> range, regions;
  std::string project;                                  // --save-project
  std::optional<foxi::workbench::Deform> deform;        // --deform NAME:SCALE
  std::optional<foxi::workbench::SolverChoice> solver;  // --solver (the solve panel's)
  std::optional<bool> si_units;                         // --units si (true) or engineering
};

int headless(foxi::workbench::Workbench& w, const ToolOptions& tools, const std::string& model,
             const std::vector<std::string>& sets, const std::string& physics, std::string field,
             const std::string& cmap, double shrink, const std::string& screenshot,
             const std::string& picture, const std::string& mesh_out) {
  using namespace foxi::cli;
  QString error;
  if (!w.open_model(QString::fromStdString(model), &error)) {
    std::fprintf(stderr, "foxi-workbench: error: %s\n", error.toUtf8().constData());
    return kExitBadInput;
  }
  for (const std::string& s : sets) {
    const std::size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw Usage("--set takes NAME=VALUE, not '" + s + "'");
    if (!w.set_parameter(QString::fromStdString(s.substr(0, eq)), QString::fromStdString(s.substr(eq + 1)),
                         &error)) {
      std::fprintf(stderr, "foxi-workbench: error: %s\n", error.toUtf8().constData());
      return kExitBadInput;
    }
  }
  w.set_shrink(shrink);
  if (tools.si_units) w.set_si_units(*tools.si_units);
  if (tools.graded || !tools.range.empty()) {
    std::optional<std::pair<double, double>> r;
    if (!tools.range.empty()) r = std::pair(tools.range[0], tools.range[1]);
    w.set_colouring(tools.graded, r);
  }
  QApplication::processEvents();  // the window laid out: the view has its size before the picture is made
  if (!w.start_mesh() || !wait_job(w)) {
    std::fprintf(stderr, "foxi-workbench: error: meshing: %s\n", w.last_error().toUtf8().constData());
    return w.last_error_bad_input() ? kExitBadInput : kExitFailure;
  }
  if (!physics.empty()) {
    w.set_physics(*foxi::workbench::physics_of(physics));
    // main() refused the choices set_solver refuses (CalculiX for a physics other than thermal)
    if (tools.solver) w.set_solver(*tools.solver);
    if (!w.start_solve() || !wait_job(w)) {
      std::fprintf(stderr, "foxi-workbench: error: solving: %s\n", w.last_error().toUtf8().constData());
      return w.last_error_bad_input() ? kExitBadInput : kExitFailure;
    }
    if (field.empty()) field = foxi::workbench::solved_field(w.physics());
  }
  if (!field.empty() || cmap != "viridis") {
    if (!w.set_field(QString::fromStdString(field), QString::fromStdString(cmap)) || !wait_job(w)) {
      std::fprintf(stderr, "foxi-workbench: error: --field %s: %s\n", field.c_str(),
                   w.last_error().toUtf8().constData());
      return kExitBadInput;
    }
  }
  if (!tools.regions.empty()) {
    for (double id : tools.regions) {  // an id no region has would hide everything in silence
      bool known = false;
      for (const foxi::Region& r : w.mesh()->regions) known = known || double(r.id) == id;
      if (!known) {
        std::string there;
        for (const foxi::Region& r : w.mesh()->regions)
          there += (there.empty() ? "" : ", ") + std::to_string(r.id) +
                   (r.name.empty() ? "" : " (" + r.name + ")");
        std::fprintf(stderr, "foxi-workbench: error: --regions: the mesh has no region %g (it has %s)\n", id,
                     there.c_str());
        return kExitUsage;
      }
    }
    std::vector<std::int32_t> hidden;
    for (const foxi::Region& r : w.mesh()->regions)
      if (std::find(tools.regions.begin(), tools.regions.end(), double(r.id)) == tools.regions.end())
        hidden.push_back(r.id);
    if (!w.set_hidden_regions(hidden) || !wait_job(w)) {
      std::fprintf(stderr, "foxi-workbench: error: --regions: %s\n", w.last_error().toUtf8().constData());
      return kExitBadInput;
    }
  }
  if (tools.deform) {
    if (!w.set_deform(tools.deform) || !wait_job(w)) {
      std::fprintf(stderr, "foxi-workbench: error: --deform: %s\n", w.last_error().toUtf8().constData());
      return kExitBadInput;
    }
  }
  if (tools.any()) {
    const foxi::DisplayUnit& u = w.display_unit();
    foxi::FieldSelection s;
    for (double v : tools.iso) s.iso.push_back(u.to_si(v));
    s.iso_only = tools.iso_only;
    if (!tools.threshold.empty()) s.threshold = {u.to_si(tools.threshold[0]), u.to_si(tools.threshold[1])};
    if (!tools.clip.empty()) {
      foxi::Plane p;
      for (int k = 0; k < 3; ++k)
        p.p[k] = tools.clip[std::size_t(k)], p.n[k] = tools.clip[std::size_t(k) + 3];
      s.clip = p;
    }
    if (!tools.slice.empty()) {
      foxi::Plane p;
      for (int k = 0; k < 3; ++k)
        p.p[k] = tools.slice[std::size_t(k)], p.n[k] = tools.slice[std::size_t(k) + 3];
      s.slice = p;
    }
    if (!w.set_selection(s, &error)) {
      std::fprintf(stderr, "foxi-workbench: error: --iso/--threshold/--clip/--slice: %s\n",
                   error.toUtf8().constData());
      return kExitUsage;
    }
    for (double v : tools.iso)  // as foxi render warns: no isosurface at a value the field never takes
      if (!(u.to_si(v) >= w.field_lo() && u.to_si(v) <= w.field_hi()))
        std::fprintf(
            stderr,
            "foxi-workbench: warning: --iso %g %s lies outside the field's values (%.6g to %.6g %s): no "
            "isosurface there\n",
            v, u.symbol.c_str(), u.to_display(w.field_lo()), u.to_display(w.field_hi()), u.symbol.c_str());
  }
  foxi::qt::ViewWidget* view = w.view_widget();
  if (tools.xray) {
    if (!view->set_xray(true, &error)) {
      std::fprintf(stderr, "foxi-workbench: error: --xray: %s\n", error.toUtf8().constData());
      return kExitUsage;
    }
    // The opacities as foxi render's option (region ids), so that a script can draw the same.
    std::string spec;
    for (const foxi::RegionOpacity& r : view->xray_params()->region_opacity)
      spec += (spec.empty() ? "" : ",") + std::to_string(r.region) + "=" + std::to_string(r.opacity);
    // The regions shown (--regions) are foxi render's --regions: the others are not drawn at all.
    std::string shown;
    for (double r : tools.regions) shown += (shown.empty() ? "--regions " : ",") + std::to_string(long(r));
    std::printf("x-ray: %s%s--region-opacity %s%s\n", shown.c_str(), shown.empty() ? "" : " ", spec.c_str(),
                view->xray_params()->iso.values.empty() ? "" : " --iso-opacity 0.5");
  }
  view->finish_now();
  QApplication::processEvents();
  std::printf("mesh: %zu tets\n", w.mesh()->tet_count());
  int status = kExitOk;
  if (const foxi::RunResults* r = w.results()) {
    for (const foxi::ResultValue& v : r->values)
      if (v.key) std::printf("%s %.6g %s\n", v.name.c_str(), v.value, v.unit.c_str());
    for (const foxi::BalanceCheck& c : r->checks)
      std::printf("check %s %s %.3g (tolerance %.3g)\n", c.name.c_str(), c.passed ? "ok" : "FAILED", c.figure,
                  c.tolerance);
    if (r->status != foxi::RunStatus::ok) status = kExitUnreliable;
    if (!r->solver.empty()) std::printf("solver: %s\n", r->solver.c_str());
  }
  std::printf("view: %s\n", view->status_text().toUtf8().constData());
  std::printf("camera: %s\n", view->camera_options().c_str());
  if (!picture.empty()) {
    if (!view->save_picture(QString::fromStdString(picture), &error)) {
      std::fprintf(stderr, "foxi-workbench: error: %s: %s\n", picture.c_str(), error.toUtf8().constData());
      return kExitFailure;
    }
    std::printf("wrote %s (%dx%d)\n", picture.c_str(), view->width(), view->height());
  }
  if (!screenshot.empty()) {
    if (!w.grab().save(QString::fromStdString(screenshot))) {
      std::fprintf(stderr, "foxi-workbench: error: cannot write %s\n", screenshot.c_str());
      return kExitFailure;
    }
    std::printf("wrote %s\n", screenshot.c_str());
  }
  if (!tools.movie.empty()) {
    if (!w.save_movie(QString::fromStdString(tools.movie), tools.movie_frames, &error)) {
      std::fprintf(stderr, "foxi-workbench: error: --save-movie: %s\n", error.toUtf8().constData());
      return kExitUsage;
    }
    bool ok = false;
    QString message;
    QEventLoop loop;
    QObject::connect(&w, &foxi::workbench::Workbench::movie_finished, &loop, [&](bool r, const QString& m) {
      ok = r;
      message = m;
      loop.quit();
    });
    loop.exec();
    if (!ok) {
      std::fprintf(stderr, "foxi-workbench: error: %s: %s\n", tools.movie.c_str(),
                   message.toUtf8().constData());
      return kExitFailure;
    }
    std::printf("wrote %s (%d frames)\n", tools.movie.c_str(), tools.movie_frames);
  }
  if (!tools.project.empty()) {
    if (!w.save_project(QString::fromStdString(tools.project), &error)) {
      std::fprintf(stderr, "foxi-workbench: error: %s: %s\n", tools.project.c_str(),
                   error.toUtf8().constData());
      return kExitFailure;
    }
    std::printf("wrote project %s\n", tools.project.c_str());
  }
  if (!mesh_out.empty()) {
    foxi::write_mesh(*w.mesh(), mesh_out);
    std::printf("wrote %s\n", mesh_out.c_str());
  }
  std::fflush(stdout);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace foxi::cli;
  try {
    // --name=value as --name value, as foxi reads it.
    const std::vector<std::string> args = foxi::split_option_values({argv + 1, argv + argc});
    std::string model, physics, field, cmap = "viridis", screenshot, picture, mesh_out, view_size;
    std::vector<std::string> sets;
    bool is_headless = false;
    ToolOptions tools;
    double shrink = 1;
    std::vector<std::string> seen;  // as foxi refuses an option given twice (but --set), so does this
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= args.size()) throw Usage(a + " takes a value");
        if (args[i + 1].empty()) throw Usage("option " + a + " takes a value, not an empty one");
        return args[++i];
      };
      if (a.rfind("--", 0) == 0 && a != "--set") {
        if (std::find(seen.begin(), seen.end(), a) != seen.end())
          throw Usage("option " + a + " given twice (give it once)");
        seen.push_back(a);
      }
      if (a == "--help" || a == "-h") {
        std::puts(kUsage);
        return kExitOk;
      } else if (a == "--headless") {
        is_headless = true;
      } else if (a == "--set") {
        sets.push_back(value());
      } else if (a == "--physics") {
        physics = value();
        if (!foxi::workbench::physics_of(physics))
          throw Usage("--physics takes thermal, electrostatic, current or thermoelastic, not '" + physics +
                      "'");
      } else if (a == "--solver") {
        const std::string name = value();
        tools.solver = foxi::workbench::solver_of(name);
        if (!tools.solver)
          throw Usage("--solver takes auto, direct, amg, ichol or ccx (CalculiX), not '" + name + "'");
      } else if (a == "--units") {
        const std::string units = value();
        if (units != "si" && units != "engineering")
          throw Usage("--units takes engineering (°C, MPa, µm, mV) or si (K, Pa, m, V), not '" + units + "'");
        tools.si_units = units == "si";
      } else if (a == "--field") {
        field = value();
      } else if (a == "--cmap") {
        cmap = value();
      } else if (a == "--screenshot") {
        screenshot = value();
      } else if (a == "--save-picture") {
        picture = value();
      } else if (a == "--save-mesh") {
        mesh_out = value();
      } else if (a == "--shrink") {
        try {
          shrink = foxi::parse_shrink(value());
        } catch (const std::exception& e) {
          throw Usage(std::string("--shrink: ") + e.what());
        }
      } else if (a == "--iso") {
        tools.iso = parse_list(value(), "--iso", 0);
      } else if (a == "--save-project") {
        tools.project = value();
      } else if (a == "--regions") {
        tools.regions = parse_list(value(), "--regions", 0);
      } else if (a == "--deform") {
        const std::string d = value();
        const std::size_t colon = d.rfind(':');
        char* end = nullptr;
        const double scale = colon == std::string::npos ? NAN : std::strtod(d.c_str() + colon + 1, &end);
        if (colon == 0 || !std::isfinite(scale) || (end && *end))
          throw Usage("--deform takes NAME:SCALE (a displacement field and a finite factor), not '" + d +
                      "'");
        tools.deform = foxi::workbench::Deform{d.substr(0, colon), scale};
      } else if (a == "--graded") {
        tools.graded = true;
      } else if (a == "--range") {
        tools.range = parse_list(value(), "--range", 2);
        if (!(tools.range[0] < tools.range[1])) throw Usage("--range takes a,b with a < b");
      } else if (a == "--iso-only") {
        tools.iso_only = true;
      } else if (a == "--threshold") {
        tools.threshold = parse_list(value(), "--threshold", 2);
        if (!(tools.threshold[0] <= tools.threshold[1])) throw Usage("--threshold takes a,b with a <= b");
      } else if (a == "--clip") {
        tools.clip = parse_list(value(), "--clip", 6);
      } else if (a == "--slice") {
        tools.slice = parse_list(value(), "--slice", 6);
      } else if (a == "--xray") {
        tools.xray = true;
      } else if (a == "--save-movie") {
        tools.movie = value();
      } else if (a == "--movie-frames") {
        const std::vector<double> n = parse_list(value(), "--movie-frames", 1);
        if (!(n[0] >= 2 && n[0] <= 10000 && n[0] == std::floor(n[0])))
          throw Usage("--movie-frames takes a whole number 2..10000");
        tools.movie_frames = int(n[0]);
      } else if (a == "--view-size") {
        view_size = value();
      } else if (a.rfind("-", 0) == 0 && a.size() > 1 && a.rfind("-platform", 0) != 0) {
        throw Usage("unknown option " + a);
      } else if (model.empty()) {
        model = a;
      } else {
        throw Usage("one model file only");
      }
    }
    if (is_headless && model.empty()) throw Usage("--headless needs a model file");
    if (tools.solver && physics.empty()) throw Usage("--solver picks the solve's solver: give --physics");
    if (tools.solver && tools.solver->calculix && physics != "thermal")
      throw Usage("--solver ccx solves the thermal problem only (--physics thermal), not " + physics);
    if (tools.xray && (shrink != 1 || tools.graded))
      throw Usage("--xray draws whole tets in their regions' colours: leave out --shrink and --graded");
    if (tools.iso_only && tools.iso.empty())
      throw Usage("--iso-only draws the isosurface of --iso: give --iso");
    if (!is_headless && (tools.any() || tools.graded || tools.deform || tools.xray || !tools.movie.empty() ||
                         !tools.range.empty() || !tools.regions.empty() || !tools.project.empty() ||
                         tools.solver || tools.si_units || !sets.empty() || !physics.empty() ||
                         !field.empty() || !screenshot.empty() || !picture.empty() || !mesh_out.empty()))
      throw Usage(
          "--set, --physics, --solver, --units, --field, --screenshot, --save-picture and --save-mesh "
          "are for --headless");
    if (cmap != "viridis" && cmap != "cividis" && cmap != "coolwarm" && cmap != "rainbow")
      throw Usage("--cmap takes viridis, cividis, coolwarm or rainbow, not '" + cmap + "'");
    foxi::ImageSize size{0, 0};
    if (!view_size.empty()) {
      try {
        size = foxi::parse_image_size(view_size);
      } catch (const std::exception& e) {
        throw Usage(std::string("--view-size: ") + e.what());
      }
    }
    // High-DPI screens: Qt scales the widgets; the view's framebuffer and the parts picture have the
    // widgets' device pixels (foxi::qt::ViewWidget), drawn 1:1, not scaled up.
    QApplication::setAttribute(Qt::AA_EnableHighDpiScaling);
    QApplication::setAttribute(Qt::AA_UseHighDpiPixmaps);
    QApplication app(argc, argv);
    QApplication::setApplicationName("foxi-workbench");
    QApplication::setOrganizationName("foxi");
    foxi::workbench::Workbench w;
    if (size.width > 0) w.view_widget()->setFixedSize(size.width, size.height);
    w.show();
    if (is_headless)
      return headless(w, tools, model, sets, physics, field, cmap, shrink, screenshot, picture, mesh_out);
    w.restore_settings();
    // Until a project is saved or opened, the session autosaves here (reopen it with Open project).
    const QString autosave = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave";
    // A session's work left there (the program was killed, or closed before a project save): offered
    // back before this session autosaves over it
    if (model.empty()) w.restore_autosave(autosave, true);
    w.set_autosave_folder(autosave);
    if (!model.empty()) w.open_model(QString::fromStdString(model));
    return app.exec();
  } catch (const Usage& e) {
    std::fprintf(stderr, "foxi-workbench: %s\nusage: %s\n", e.what(), kUsage);
    return kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "foxi-workbench: error: %s\n", e.what());
    return kExitFailure;
  }
}
