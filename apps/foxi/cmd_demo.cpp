// foxi demo [MODEL.toml]: one example end to end -- model, mesh, Delaunay certificate, steady heat,
// a picture of the inside -- with what each step found.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <span>
#include <stdexcept>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "mesh_input.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/model_problem.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "model_picture.hpp"
#include "model_run.hpp"

namespace foxi::cli {

namespace {

const char* kDemoUsage =
    "foxi demo [MODEL.toml] [--set NAME=VALUE]... [-o DIR]\n"
    "  Runs a model end to end (default: the flip chip of the models/ folder): loads and checks it,\n"
    "  meshes it with TetGen (its [mesh] controls), certifies the mesh (exact empty-circumsphere test),\n"
    "  solves its steady heat conduction with its [[conditions]] and [[loads]], and writes to DIR\n"
    "  (default out/demo): MODEL.vtu (mesh, temperature, heat flux; for ParaView), MODEL.png (the far\n"
    "  60 % of the visibility order drawn by the painter, parts in their materials' colours),\n"
    "  MODEL_parts.png (the parts, exploded) and MODEL_temperature.png (the same far 60 % coloured by\n"
    "  the solved temperature, graded facets, with a colour-bar legend in degrees Celsius). Then, through\n"
    "  the commands themselves: MODEL_isotherm.png (foxi render --iso at the middle of the range: the\n"
    "  solid hotter than it, cut at the isotherm), MODEL_isotherms.gif (foxi movie --sweep iso: the\n"
    "  isotherm swept from the coolest to the hottest), MODEL_stress.vtu (foxi solve --physics\n"
    "  thermoelastic) and MODEL_von_mises.png (von Mises stress on the deformed shape, the displacement\n"
    "  scaled so that it reaches 2 % of the model's size, drawn as the solid where it is at least a\n"
    "  quarter of the way up its range: where the stress concentrates).";

// The folder of the example models: $FOXI_MODELS_DIR if set, else FOXI_MODELS_RELATIVE_DIR next to
// this program (share/foxi/models of an installed foxi; the build tree has a link to models/ there),
// so that no path of the build machine is baked into the program.
std::filesystem::path models_dir() {
  if (const char* env = std::getenv("FOXI_MODELS_DIR"); env != nullptr && *env != '\0') return env;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return (ec ? std::filesystem::path(".") : exe.parent_path()) / FOXI_MODELS_RELATIVE_DIR;
}

// A 1-2-5 factor that moves the nodes of `mesh` by `field` (a displacement) by at most `fraction` of
// the diagonal of its bounding box (1 when the field is zero).
double deform_scale_for(const Mesh& mesh, const std::string& field, double fraction) {
  const Field* f = nullptr;
  for (const Field& g : mesh.fields)
    if (g.name == field && g.location == FieldLocation::node && g.components == 3) f = &g;
  if (f == nullptr)
    throw std::runtime_error("the thermoelastic result has no 3-component node field '" + field + "'");
  double lo[3], hi[3];
  mesh_bounds(mesh, lo, hi);
  const double diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const std::span<const double> u = f->step(f->step_count() - 1, mesh.node_count());
  double umax = 0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n)
    umax = std::max(umax, std::hypot(u[3 * n], u[3 * n + 1], u[3 * n + 2]));
  if (!(umax > 0) || !std::isfinite(umax)) return 1;
  const double want = fraction * diag / umax;
  const double decade = std::pow(10.0, std::floor(std::log10(want)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * decade <= want) return m * decade;
  return decade;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int cmd_demo(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kDemoUsage);
    return kExitOk;
  }
  std::vector<std::string> sets;
  while (args.has_option("--set")) sets.push_back(args.option("--set"));
  const std::filesystem::path dir = args.option("-o", "out/demo");
  const auto pos = args.positional(0, 1, kDemoUsage);
  const std::string file =
      pos.empty() ? (models_dir() / "flip_chip.toml").lexically_normal().string() : pos[0];
  if (!is_model_path(file)) throw UsageError("foxi demo takes a model file (.toml), not '" + file + "'");
  const std::string stem = std::filesystem::path(file).stem().string();
  std::filesystem::create_directories(dir);
  check_output_path(dir / (stem + ".vtu"));

  std::printf("1. model %s\n", file.c_str());
  auto t = std::chrono::steady_clock::now();
  ModelMeshOptions options;
  options.physics = Physics::thermal;
  MeshedModel m = mesh_model_from_sets(file, sets, options);
  for (std::size_t i = 0; i < m.model.parts.size(); ++i)
    std::printf("   part %-14s %-14s %.4g mm^3\n", m.model.parts[i].name.c_str(),
                m.model.parts[i].material.c_str(), m.structure.part_volume[i] * 1e9);
  print_model_conditions(m.model);
  std::printf(
      "2. mesh: PLC %zu points, %zu facets -> %zu nodes, %zu tets, %zu boundary triangles (TetGen %s, %.2f "
      "s)\n",
      m.structure.plc.point_count(), m.structure.plc.facet_count(), m.mesh.node_count(), m.mesh.tet_count(),
      m.mesh.bface_count(), m.report.switches.c_str(), seconds_since(t));
  const QualitySummary q = summarize_quality(m.mesh);
  std::printf("   radius-edge max %.3g, min dihedral %.3g deg, %zu slivers below 5 deg\n", q.radius_edge.max,
              q.min_dihedral_deg.min, q.slivers);
  const ValidationReport v = require_usable(m.mesh, file + " (its mesh)", "demo");
  std::printf("   validation: %s\n", v.clean() ? "ok" : "usable, with warnings");

  t = std::chrono::steady_clock::now();
  const DelaunayCertificate cert = compute_delaunay_certificate(m.mesh);
  std::printf("3. certificate: %s (%zu tets, %.2f s)\n",
              cert.delaunay ? "Delaunay, every circumsphere empty" : "NOT Delaunay", cert.tets_checked,
              seconds_since(t));

  const ThermalReport r = solve_thermal(m.mesh, thermal_params_from_model(m.model, m.mesh));
  double out = 0;
  for (const BoundaryHeat& b : r.boundaries) out -= b.heat_in;
  std::printf(
      "4. steady heat: max temperature %.2f K (%.2f C); %.4g W in, %.4g W out through the boundaries "
      "(balance %.2g W); solver %s, %.2f s\n",
      r.max_temperature, r.max_temperature - 273.15, r.total_power, out, r.total_power - out,
      r.solver.c_str(), r.assembly_seconds + r.solve_seconds);
  for (const RegionTemperature& rt : r.regions) {
    const Region* reg = m.mesh.find_region(rt.region);
    std::printf("   %-14s max %.2f K, mean %.2f K\n", reg ? reg->name.c_str() : "?", rt.max_temperature,
                rt.mean_temperature);
  }
  const std::string vtu = (dir / (stem + ".vtu")).string();
  write_mesh(m.mesh, vtu);

  const std::string png = (dir / (stem + ".png")).string(), parts = (dir / (stem + "_parts.png")).string();
  t = std::chrono::steady_clock::now();
  ModelPictureParams pp;
  pp.view = ModelView::interior;
  const ModelPicture pic = render_model_picture(m, png, pp);
  std::printf("5. picture: %zu tets drawn back to front (%s), %.2f s\n", pic.tets_drawn,
              pic.delaunay ? "painter, power order" : "MPVO order, depth buffer", seconds_since(t));
  pp.view = ModelView::exploded;
  render_model_picture(m, parts, pp);
  print_legend(m, pic);
  const std::string temp_png = (dir / (stem + "_temperature.png")).string();
  t = std::chrono::steady_clock::now();
  pp.view = ModelView::interior;
  pp.field = "temperature";
  const ModelPicture tp = render_model_picture(m, temp_png, pp);
  std::printf(
      "6. temperature picture: the far 60 %% coloured by temperature (graded facets, viridis), %.2f to %.2f "
      "%s, "
      "legend at the right, %.2f s\n",
      tp.field_lo, tp.field_hi, tp.field_unit.c_str(), seconds_since(t));

  // The rest through the commands themselves (their reports printed as they are), so that the demo
  // shows what a user's command line gives: an isotherm, its sweep as a movie, the stress.
  // 7. The isotherm half way up the temperature range, as the cut face of the solid hotter than it.
  const double iso = std::round(5 * (tp.field_lo + tp.field_hi)) / 10;  // to 0.1 degree
  char iso_s[32];
  std::snprintf(iso_s, sizeof iso_s, "%g", iso);
  const std::string iso_png = (dir / (stem + "_isotherm.png")).string();
  const std::string gif = (dir / (stem + "_isotherms.gif")).string();
  std::printf("7. isotherm at %s %s: foxi render %s --field temperature --graded --iso %s -o %s\n", iso_s,
              tp.field_unit.c_str(), vtu.c_str(), iso_s, iso_png.c_str());
  std::fflush(stdout);
  int status = cmd_render(Args({vtu, "--field", "temperature", "--graded", "--iso", iso_s, "-o", iso_png}));
  if (status != kExitOk) return status;
  char sweep[96];
  std::snprintf(sweep, sizeof sweep, "iso:%.6g,%.6g", tp.field_lo, tp.field_hi);
  std::printf(
      "\n8. the isotherm swept from the coolest to the hottest: foxi movie %s --field temperature --graded "
      "--sweep %s --frames 24 -o %s\n",
      vtu.c_str(), sweep, gif.c_str());
  std::fflush(stdout);
  status = cmd_movie(
      Args({vtu, "--field", "temperature", "--graded", "--sweep", sweep, "--frames", "24", "-o", gif}));
  if (status != kExitOk) return status;
  // 9. Thermal stress (the same model, thermoelastic), von Mises on the shape deformed by a factor that
  // moves the nodes by at most 2 % of the model's size: the warpage visible, the tets not folded.
  // A model without mechanical supports or properties has no stress to show: said, and the rest skipped.
  try {
    check_physics(m.model, Physics::thermal_stress);
  } catch (const IoError& e) {
    std::printf("\n9. thermal stress: skipped, the model is not ready for it: %s\n", e.what());
    std::printf(
        "\nwrote %s (temperature, heat flux), %s (inside), %s (parts), %s (temperature), %s (isotherm), %s "
        "(isotherm movie)\n",
        vtu.c_str(), png.c_str(), parts.c_str(), temp_png.c_str(), iso_png.c_str(), gif.c_str());
    return kExitOk;
  }
  const std::string te_vtu = (dir / (stem + "_stress.vtu")).string();
  const std::string vm_png = (dir / (stem + "_von_mises.png")).string();
  std::vector<std::string> solve = {file, "--physics", "thermoelastic", "-o", te_vtu};
  for (const std::string& set : sets) solve.insert(solve.end(), {"--set", set});
  std::printf("\n9. thermal stress: foxi solve %s --physics thermoelastic -o %s\n", file.c_str(),
              te_vtu.c_str());
  std::fflush(stdout);
  status = cmd_solve(Args(solve));
  if (status != kExitOk) return status;
  const Mesh te = read_mesh(te_vtu);
  const double scale = deform_scale_for(te, "displacement", 0.02);
  char scale_s[32];
  std::snprintf(scale_s, sizeof scale_s, "displacement:%g", scale);
  // The solid where von Mises is at least a quarter of the way up its range, cut at that level: the
  // places the stress concentrates (a flip chip's bumps) seen whole, not one hot spot among the far
  // 60 % of the tets. The level in MPa (the display unit of a stress in Pa), two significant digits.
  char level_s[32];
  {
    const std::vector<double> corner = tet_corner_values(te, choose_field(te, "von_mises"));
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double x : corner)
      if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
    double level = 1e-6 * (lo + 0.25 * (hi - lo));
    if (level > 0) {  // two significant digits, written out ("140", not "1.4e+02")
      const double unit = std::pow(10.0, std::floor(std::log10(level)) - 1);
      level = std::round(level / unit) * unit;
    }
    std::snprintf(level_s, sizeof level_s, "%.6g", level);
  }
  std::printf(
      "\n10. von Mises on the deformed shape, the solid above a quarter of its range: foxi render %s --field "
      "von_mises --graded --deform %s --iso %s -o %s\n",
      te_vtu.c_str(), scale_s, level_s, vm_png.c_str());
  std::fflush(stdout);
  status = cmd_render(Args(
      {te_vtu, "--field", "von_mises", "--graded", "--deform", scale_s, "--iso", level_s, "-o", vm_png}));
  if (status != kExitOk) return status;
  std::printf(
      "\nwrote %s (temperature, heat flux), %s (inside), %s (parts), %s (temperature), %s (isotherm), %s "
      "(isotherm movie), %s (stress), %s (von Mises, deformed)\n",
      vtu.c_str(), png.c_str(), parts.c_str(), temp_png.c_str(), iso_png.c_str(), gif.c_str(), te_vtu.c_str(),
      vm_png.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
