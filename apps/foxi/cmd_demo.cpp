// foxi demo [MODEL.toml]: one example end to end -- model, mesh, Delaunay certificate, steady heat,
// a picture of the inside -- with what each step found.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "mesh_input.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/model_problem.hpp"
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
    "  the solved temperature, graded facets, with a colour-bar legend in degrees Celsius).";

// The folder of the example models: $FOXI_MODELS_DIR if set, else FOXI_MODELS_RELATIVE_DIR next to
// this program (share/foxi/models of an installed foxi; the build tree has a link to models/ there),
// so that no path of the build machine is baked into the program.
std::filesystem::path models_dir() {
  if (const char* env = std::getenv("FOXI_MODELS_DIR"); env != nullptr && *env != '\0') return env;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return (ec ? std::filesystem::path(".") : exe.parent_path()) / FOXI_MODELS_RELATIVE_DIR;
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
  const std::string file = pos.empty() ? (models_dir() / "flip_chip.toml").lexically_normal().string() : pos[0];
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
    std::printf("   part %-14s %-14s %.4g mm^3\n", m.model.parts[i].name.c_str(), m.model.parts[i].material.c_str(),
                m.structure.part_volume[i] * 1e9);
  print_model_conditions(m.model);
  std::printf("2. mesh: PLC %zu points, %zu facets -> %zu nodes, %zu tets, %zu boundary triangles (TetGen %s, %.2f s)\n",
              m.structure.plc.point_count(), m.structure.plc.facet_count(), m.mesh.node_count(),
              m.mesh.tet_count(), m.mesh.bface_count(), m.report.switches.c_str(), seconds_since(t));
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
  std::printf("4. steady heat: max temperature %.2f K (%.2f C); %.4g W in, %.4g W out through the boundaries "
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
  std::printf("6. temperature picture: the far 60 %% coloured by temperature (graded facets, viridis), %.2f to %.2f %s, "
              "legend at the right, %.2f s\n",
              tp.field_lo, tp.field_hi, tp.field_unit.c_str(), seconds_since(t));
  std::printf("wrote %s (temperature, heat flux), %s (inside), %s (parts), %s (temperature)\n", vtu.c_str(), png.c_str(),
              parts.c_str(), temp_png.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
