// foxi mesh MODEL.toml|PLC.poly -o OUT: a conforming Delaunay tetrahedral mesh of a model or a PLC,
// through TetGen and the conforming refinement (or CGAL Mesh_3), with size controls and a quality
// report. A thin user of mesh_model's options (model_mesh.hpp): the options are read here, the
// meshing is the library's; the CGAL report is printed by cmd_mesh_cgal.cpp.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "model_run.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/mesher/quality_report.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/units.hpp"

namespace foxi::cli {

namespace {

const char* kMeshUsage =
    "foxi mesh MODEL.toml|PLC.poly -o OUT [--set NAME=VALUE]... [--max-size H] [--quality Q]\n"
    "          [--min-dihedral DEG] [--max-volume V] [--region-size REGION=H]... [--refine-box "
    "X0,Y0,Z0,X1,Y1,Z1=H]...\n"
    "          [--refine-from RESULT.vtu [--field NAME] --target-error E] [--no-conform] [--optimize]\n"
    "          [--mesher tetgen|cgal] [--perturb] [--resample [--feature-angle DEG]] [--time-limit S]\n"
    "          [--max-tets N]\n"
    "  Meshes a model (parts -> PLC) or a TetGen .poly into tets with TetGen (no optimisation), then\n"
    "  splits encroached boundary/interface triangles until every tet is Delaunay (exact certificate),\n"
    "  and prints a quality report. OUT in any mesh format foxi knows (.vtu .msh .vtk .node .mesh).\n"
    "  Lengths H take a unit (\"0.2 mm\"); a bare number is in the model's length unit (metres for .poly).\n"
    "  --set NAME=VALUE   overrides a model parameter\n"
    "  --max-size H       target edge length everywhere (TetGen -a with the regular tet's volume)\n"
    "  --quality Q        radius-edge bound (default and least 1.414; 0: no quality refinement)\n"
    "  --min-dihedral D   TetGen's dihedral bound in degrees (not guaranteed without optimisation)\n"
    "  --max-volume V     largest tet volume in m^3 (or the .poly's units cubed)\n"
    "  --region-size R=H  target edge length in region R (its id; a model's part i has id i+1)\n"
    "  --refine-box B=H   target edge length H inside the box X0,Y0,Z0,X1,Y1,Z1 (lengths as above)\n"
    "  --refine-from F    remesh from a solved mesh F: elements shrink where the Zienkiewicz-Zhu\n"
    "                     error of its field (--field, default the first node field) is large, for a\n"
    "                     relative gradient error --target-error E (e.g. 0.05)\n"
    "  --max-tets N       refuse a mesh estimated (before meshing, from the volumes and the sizes) to\n"
    "                     have more than N tets (default 4000000)\n"
    "  --no-conform       TetGen's mesh as it is (may not be Delaunay)\n"
    "  --optimize         TetGen's flips and smoothing (implies --no-conform: the mesh stops being "
    "Delaunay)\n"
    "  --mesher cgal      CGAL Mesh_3 instead of TetGen (a model, with --set and its max_size and part\n"
    "                     sizes, or a PLC.poly): every facet edge of the PLC protected (region volumes\n"
    "                     are the PLC's, checked to 0.1%), sliver exudation; the mesh is part of a\n"
    "                     regular triangulation, its vertex weights are written (point data 'weight' in\n"
    "                     .vtu) and always certified (orthospheres); a mesh failing a check exits 4.\n"
    "                     --max-size, --region-size, --refine-box and a model's refinement boxes act\n"
    "                     as for TetGen (as circumradius bounds of the regular tet of that edge, on\n"
    "                     the cells, the boundary triangles and the protected edges in a box);\n"
    "                     --refine-from, --no-conform need TetGen.\n"
    "                     --max-volume becomes the circumradius of a regular tet of that volume;\n"
    "                     --radius-edge (or --quality) defaults to 2; --perturb adds sliver perturbation;\n"
    "                     --resample: only edges turning by more than --feature-angle (default 60)\n"
    "                     and patch borders are protected, a faceted cylinder's wall is resampled\n"
    "                     (each region's volume change is printed); --time-limit S stops CGAL after\n"
    "                     S seconds (default 300; 0: none) with an error\n"
    "  Ctrl-C (SIGINT) or SIGTERM stops it: TetGen or CGAL is killed, nothing is written, exit status\n"
    "  130 or 143.";

double number(const std::string& s, const char* what) {
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !(v >= 0))
    throw UsageError(std::string(what) + " takes a number >= 0, not '" + s + "'");
  return v;
}

// A length: "0.2 mm", or a bare number in `unit_scale` metres.
double length(const std::string& s, double unit_scale, const char* what) {
  Quantity q;
  try {
    q = evaluate_expression(s, [](std::string_view) { return std::optional<Quantity>(); });
  } catch (const ExpressionError& e) {
    throw UsageError(std::string(what) + ": " + e.what());
  }
  if (q.dims == kDimensionless)
    q.value *= unit_scale;
  else if (q.dims != kLength)
    throw UsageError(std::string(what) + " takes a length, not '" + s + "'");
  if (!(q.value > 0) || !std::isfinite(q.value))
    throw UsageError(std::string(what) + " must be > 0, not '" + s + "'");
  return q.value;
}

// "LHS=RHS" split at the last '='.
std::pair<std::string, std::string> split_eq(const std::string& s, const char* what) {
  const auto eq = s.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == s.size())
    throw UsageError(std::string(what) + " takes A=B, not '" + s + "'");
  return {s.substr(0, eq), s.substr(eq + 1)};
}

}  // namespace

// The CGAL path's report (cmd_mesh_cgal.cpp): prints it and returns the exit status (4 for a mesh
// that fails its checks).
int report_cgal_mesh(const std::string& in, const std::string& out, const MeshedModel& m,
                     double volume_tolerance);
// The exit status of a mesher failure, TetGen or CGAL (cmd_mesh_cgal.cpp).
int mesher_exit_code(MesherFailure f);

int cmd_mesh(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kMeshUsage);
    return kExitOk;
  }
  const std::string mesher = args.option("--mesher", "tetgen");
  if (mesher != "tetgen" && mesher != "cgal")
    throw UsageError("--mesher takes tetgen or cgal, not '" + mesher + "'");
  const bool cgal = mesher == "cgal";
  ModelMeshOptions options;
  options.mesher = cgal ? Mesher::cgal : Mesher::tetgen;
  // The options of one mesher only: named as the other's (not "unknown option").
  auto only = [&](const char* name, bool for_cgal) {
    if (cgal != for_cgal && args.has_option(name))
      throw UsageError(std::string(name) + " needs --mesher " + (for_cgal ? "cgal" : "tetgen"));
  };
  for (const char* o : {"--min-dihedral", "--refine-from", "--field", "--target-error"}) only(o, false);
  for (const char* o : {"--time-limit", "--feature-angle"}) only(o, true);
  for (const char* f : {"--no-conform", "--optimize"})
    if (cgal && std::find(args.remaining().begin(), args.remaining().end(), f) != args.remaining().end())
      throw UsageError(std::string(f) + " needs --mesher tetgen");
  for (const char* f : {"--perturb", "--resample"})
    if (!cgal && std::find(args.remaining().begin(), args.remaining().end(), f) != args.remaining().end())
      throw UsageError(std::string(f) + " needs --mesher cgal");
  std::vector<std::string> sets, region_sizes, boxes;
  while (args.has_option("--set")) sets.push_back(args.option("--set"));
  while (args.has_option("--region-size")) region_sizes.push_back(args.option("--region-size"));
  while (args.has_option("--refine-box")) boxes.push_back(args.option("--refine-box"));
  const std::string max_size = args.option("--max-size");
  options.max_volume = number(args.option("--max-volume", "0"), "--max-volume");
  // --radius-edge is --quality's other name (CGAL's default 2, TetGen's 1.414 or the model's).
  const std::string quality = args.option("--quality", args.option("--radius-edge", ""));
  const std::string min_dihedral = args.option("--min-dihedral", "");
  if (!quality.empty()) options.quality = number(quality, "--quality");
  if (!min_dihedral.empty()) options.min_dihedral = number(min_dihedral, "--min-dihedral");
  if (!cgal && options.quality && !(*options.quality == 0 || *options.quality >= kMinRadiusEdgeBound))
    throw UsageError(
        "--quality takes 0 (no quality refinement) or a radius-edge bound of at least 1.414, not '" +
        quality + "' (TetGen's refinement does not finish below it on thin layers)");
  if (options.min_dihedral && !(*options.min_dihedral >= 0 && *options.min_dihedral < 30))
    throw UsageError("--min-dihedral takes 0 to 30 degrees (larger bounds do not terminate), not '" +
                     min_dihedral + "'");
  options.optimize = args.flag("--optimize");
  options.conform = !args.flag("--no-conform") && !options.optimize;
  CgalMeshParams& cp = options.cgal;
  cp.perturb = args.flag("--perturb");
  cp.resample = args.flag("--resample");
  if (args.has_option("--feature-angle")) {
    cp.feature_angle = number(args.option("--feature-angle"), "--feature-angle");
    if (cp.feature_angle > 180) throw UsageError("--feature-angle takes degrees in [0, 180]");
    if (!cp.resample)
      throw UsageError("--feature-angle needs --resample (without it every facet edge is protected)");
  }
  cp.time_limit = number(args.option("--time-limit", "300"), "--time-limit");
  if (!std::isfinite(cp.time_limit)) throw UsageError("--time-limit takes a number >= 0");
  args.flag("--check-delaunay");  // the certificate is always part of the report now
  const std::string refine_from = args.option("--refine-from");
  const std::string field_name = args.option("--field");
  const std::string target_error = args.option("--target-error");
  const std::string out = args.option("-o");
  options.max_tets = max_tets_option(args);
  if (out.empty()) throw UsageError("give the output file with -o OUT\nusage: " + std::string(kMeshUsage));
  const std::string in = args.positional(1, 1, kMeshUsage)[0];
  if (!refine_from.empty() && target_error.empty()) throw UsageError("--refine-from needs --target-error E");
  format_from_path(out);  // an unknown output format or an unwritable path fails before any meshing
  check_output_path(out);

  // A model (its length unit read first: the sizes given bare are in it) or a .poly.
  const bool is_model = is_model_path(in);
  Model model;
  Plc plc;
  double unit_scale = 1;
  if (is_model) {
    model = load_model(in, sets, "--set");
    unit_scale = model.length_scale;
  } else {
    if (!sets.empty()) throw UsageError("--set needs a model file (.toml), not a .poly");
    plc = read_poly(in);
  }
  // The model's [mesh] table first; the command line replaces its global size and bounds and adds to
  // its part sizes and boxes (mesh_model's options).
  if (!max_size.empty()) options.max_size = length(max_size, unit_scale, "--max-size");
  for (const std::string& r : region_sizes) {
    const auto [id, h] = split_eq(r, "--region-size");
    options.sizes.region_ids.push_back(static_cast<std::int32_t>(number(id, "--region-size")));
    options.sizes.region_sizes.push_back(length(h, unit_scale, "--region-size"));
  }
  for (const std::string& b : boxes) {
    const auto [corners, h] = split_eq(b, "--refine-box");
    const std::vector<double> c = parse_numbers(corners, "--refine-box");
    if (c.size() != 6) throw UsageError("--refine-box takes X0,Y0,Z0,X1,Y1,Z1=H, not '" + b + "'");
    RefinementBox box;
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = std::min(c[std::size_t(k)], c[std::size_t(k) + 3]) * unit_scale;
      box.hi[k] = std::max(c[std::size_t(k)], c[std::size_t(k) + 3]) * unit_scale;
    }
    box.size = length(h, unit_scale, "--refine-box");
    options.sizes.boxes.push_back(box);
  }
  Mesh solved;
  if (!refine_from.empty()) {
    solved = read_mesh(refine_from);
    if (!refine_field(solved, field_name))
      throw UsageError(refine_from + " has no node field" +
                       (field_name.empty() ? "" : " named '" + field_name + "'"));
    options.refine_from = {.mesh = &solved,
                           .field = field_name,
                           .target_error = number(target_error, "--target-error"),
                           .origin = refine_from};
  }

  // Progress on stderr for long runs (SIGINT and SIGTERM are handled by signals.hpp: they end the
  // process, so the callback never cancels).
  const auto t0 = std::chrono::steady_clock::now();
  double last_print = 0;
  const bool tty = ::isatty(2);
  options.progress = [&](std::string_view stage, double fraction) {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (tty && s - last_print >= 1) {
      last_print = s;
      if (fraction >= 0)
        std::fprintf(stderr, "\r%.*s %3.0f%% %5.0f s   ", int(stage.size()), stage.data(), 100 * fraction, s);
      else
        std::fprintf(stderr, "\r%.*s %5.0f s   ", int(stage.size()), stage.data(), s);
    }
    return true;
  };

  MeshedModel m;
  int status = kExitOk;
  try {
    m = is_model ? mesh_loaded_model(std::move(model), options)
                 : mesh_plc_with_options(std::move(plc), options, in);
  } catch (const MesherError& e) {
    if (cgal) {
      std::fprintf(stderr, "%sfoxi mesh: error: %s: %s: %s\n", tty && last_print > 0 ? "\n" : "", in.c_str(),
                   failure_name(e.failure()), e.what());
      status = mesher_exit_code(e.failure());
    } else {
      std::fprintf(stderr, "%sfoxi mesh: error: %s: %s\n", tty ? "\n" : "", in.c_str(), e.what());
      // The input's fault (a PLC TetGen refuses, a --region-size for no region) is exit 3, as with
      // CGAL; it was 1, the work's failure.
      status = mesher_exit_code(e.failure());
    }
  }
  if (tty && last_print > 0) std::fputc('\n', stderr);
  if (status != 0) return status;
  write_mesh(m.mesh, out);
  if (cgal) return report_cgal_mesh(in, out, m, cp.volume_tolerance);
  if (m.refined) {
    const RefinedFrom& r = *m.refined;
    std::printf("refine from %s: field '%s', relative gradient error %.3g (Zienkiewicz-Zhu), target %s\n",
                refine_from.c_str(), r.field.c_str(), r.relative_error, target_error.c_str());
    if (r.tets_without_value > 0)
      std::printf(
          "  %zu of its %zu tets have a node without a value (NaN): left out of the error, they keep their "
          "size\n",
          r.tets_without_value, r.tets);
  }
  std::printf("%s -> %s (TetGen switches %s)\n", in.c_str(), out.c_str(), m.report.switches.c_str());
  std::printf("%s\n", format_quality_report(mesh_quality_report(m.mesh, m.conforming)).c_str());
  return kExitOk;
}

}  // namespace foxi::cli
