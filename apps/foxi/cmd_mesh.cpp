// foxi mesh MODEL.toml|PLC.poly -o OUT: a conforming Delaunay tetrahedral mesh of a model or a PLC,
// through TetGen and the conforming refinement, with size controls and a quality report.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "model_run.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/quality_report.hpp"
#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/size_field.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/structure.hpp"
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
    "  --mesher cgal      CGAL Mesh_3 instead of TetGen (a model, with --set and its max_size and part "
    "sizes,\n"
    "                     or a PLC.poly): every facet edge of the PLC protected (region volumes are the\n"
    "                     PLC's, checked to 0.1%), sliver exudation; the mesh is part of a regular\n"
    "                     triangulation, its vertex weights are written (point data 'weight' in .vtu)\n"
    "                     and always certified (orthospheres); a mesh failing a check exits 4.\n"
    "                     --max-volume becomes the circumradius of a regular tet of that volume;\n"
    "                     --radius-edge defaults to 2; --perturb adds sliver perturbation;\n"
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

int mesh_with_cgal(Args& args);  // cmd_mesh_cgal.cpp

int cmd_mesh(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kMeshUsage);
    return kExitOk;
  }
  const std::string mesher = args.option("--mesher", "tetgen");
  if (mesher == "cgal") return mesh_with_cgal(args);
  if (mesher != "tetgen") throw UsageError("--mesher takes tetgen or cgal, not '" + mesher + "'");
  std::vector<std::string> sets, region_sizes, boxes;
  while (args.has_option("--set")) sets.push_back(args.option("--set"));
  while (args.has_option("--region-size")) region_sizes.push_back(args.option("--region-size"));
  while (args.has_option("--refine-box")) boxes.push_back(args.option("--refine-box"));
  const std::string max_size = args.option("--max-size");
  MeshParams params;
  params.max_volume = number(args.option("--max-volume", "0"), "--max-volume");
  const std::string quality = args.option("--quality", args.option("--radius-edge", ""));
  const std::string min_dihedral = args.option("--min-dihedral", "");
  params.radius_edge = quality.empty() ? 1.414 : number(quality, "--quality");
  params.min_dihedral = min_dihedral.empty() ? 0 : number(min_dihedral, "--min-dihedral");
  if (!(params.radius_edge == 0 || params.radius_edge >= kMinRadiusEdgeBound))
    throw UsageError(
        "--quality takes 0 (no quality refinement) or a radius-edge bound of at least 1.414, not '" +
        quality + "' (TetGen's refinement does not finish below it on thin layers)");
  if (!(params.min_dihedral >= 0 && params.min_dihedral < 30))
    throw UsageError("--min-dihedral takes 0 to 30 degrees (larger bounds do not terminate), not '" +
                     min_dihedral + "'");
  params.optimize = args.flag("--optimize");
  const bool conform = !args.flag("--no-conform") && !params.optimize;
  args.flag("--check-delaunay");  // the certificate is always part of the report now
  const std::string refine_from = args.option("--refine-from");
  const std::string field_name = args.option("--field");
  const std::string target_error = args.option("--target-error");
  const std::string out = args.option("-o");
  const double max_tets = max_tets_option(args);
  if (out.empty()) throw UsageError("give the output file with -o OUT\nusage: " + std::string(kMeshUsage));
  const std::string in = args.positional(1, 1, kMeshUsage)[0];
  if (!refine_from.empty() && target_error.empty()) throw UsageError("--refine-from needs --target-error E");
  format_from_path(out);  // an unknown output format or an unwritable path fails before any meshing
  check_output_path(out);

  // The PLC, from a model or a .poly.
  const bool is_model = is_model_path(in);
  Model model;
  Structure structure;
  Plc plc;
  double unit_scale = 1;
  if (is_model) {
    model = load_model(in, sets, "--set");
    structure = build_structure(model);
    plc = structure.plc;
    unit_scale = model.length_scale;
  } else {
    if (!sets.empty()) throw UsageError("--set needs a model file (.toml), not a .poly");
    plc = read_poly(in);
  }

  // A model's [mesh] table first; the command line overrides its global size and bounds and adds to
  // its part sizes and boxes.
  SizeControls controls;
  if (is_model) {
    controls = size_controls_from_model(model);
    if (controls.max_size > 0 && max_size.empty()) {
      const double v = regular_tet_volume(controls.max_size);
      params.max_volume = params.max_volume > 0 ? std::min(params.max_volume, v) : v;
    }
    if (quality.empty() && model.mesh.quality >= 0) params.radius_edge = model.mesh.quality;
    if (min_dihedral.empty()) params.min_dihedral = model.mesh.min_dihedral;
  }
  if (!max_size.empty()) {
    controls.max_size = length(max_size, unit_scale, "--max-size");
    const double v = regular_tet_volume(controls.max_size);
    params.max_volume = params.max_volume > 0 ? std::min(params.max_volume, v) : v;
  }
  for (const std::string& r : region_sizes) {
    const auto [id, h] = split_eq(r, "--region-size");
    controls.region_ids.push_back(static_cast<std::int32_t>(number(id, "--region-size")));
    controls.region_sizes.push_back(length(h, unit_scale, "--region-size"));
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
    controls.boxes.push_back(box);
  }

  // Progress on stderr for long runs (SIGINT and SIGTERM are handled by signals.hpp: they end the
  // process, so the callback never cancels).
  const auto t0 = std::chrono::steady_clock::now();
  double last_print = 0;
  const bool tty = ::isatty(2);
  params.progress = [&](std::string_view stage, double fraction) {
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

  Mesh mesh;
  ConformingReport report;
  SizeField field;
  int status = kExitOk;
  try {
    plc = with_region_sizes(plc, controls);
    const std::span<const double> volumes =
        is_model ? std::span<const double>(structure.part_volume) : std::span<const double>();
    if (!refine_from.empty()) {
      const Mesh solved = read_mesh(refine_from);
      const Field* f = nullptr;
      for (const Field& cand : solved.fields)
        if (cand.location == FieldLocation::node && (field_name.empty() ? true : cand.name == field_name)) {
          f = &cand;
          break;
        }
      if (!f)
        throw UsageError(refine_from + " has no node field" +
                         (field_name.empty() ? "" : " named '" + field_name + "'"));
      const ErrorIndicator e = zz_error_indicator(solved, *f);
      field = size_field_from_error(solved, *f, number(target_error, "--target-error"), 0, controls.max_size);
      std::printf("refine from %s: field '%s', relative gradient error %.3g (Zienkiewicz-Zhu), target %s\n",
                  refine_from.c_str(), f->name.c_str(), e.relative_error(), target_error.c_str());
      if (e.tets_without_value > 0)
        std::printf(
            "  %zu of its %zu tets have a node without a value (NaN): left out of the error, they keep their "
            "size\n",
            e.tets_without_value, solved.tet_count());
    } else if (!controls.boxes.empty()) {
      check_tet_estimate(in, plc, params, volumes, max_tets);  // box_size_field meshes with params first
      field = box_size_field(plc, params, controls);
    }
    if (!field.empty()) params.size_field = &field;
    check_tet_estimate(in, plc, params, volumes, max_tets);
    if (conform) {
      mesh = mesh_conforming(plc, params, {}, &report);
    } else {
      mesh = mesh_plc(plc, params, &report.tetgen);
      report.first_mesh_points = mesh.node_count();
      report.seconds = report.tetgen.seconds;
      const DelaunayCertificate cert = compute_delaunay_certificate(mesh);
      report.delaunay = cert.delaunay;
      report.first_mesh_violations = cert.violating_tet_count;
      report.violations.push_back(cert.violating_tet_count);
    }
    if (is_model) name_mesh(model, structure, mesh);
  } catch (const MesherError& e) {
    std::fprintf(stderr, "%sfoxi mesh: error: %s: %s\n", tty ? "\n" : "", in.c_str(), e.what());
    status = kExitFailure;
  }
  if (tty && last_print > 0) std::fputc('\n', stderr);
  if (status != 0) return status;
  write_mesh(mesh, out);
  std::printf("%s -> %s (TetGen switches %s)\n", in.c_str(), out.c_str(), report.tetgen.switches.c_str());
  std::printf("%s\n", format_quality_report(mesh_quality_report(mesh, report)).c_str());
  return kExitOk;
}

}  // namespace foxi::cli
