// foxi mesh PLC.poly -o OUT: a tetrahedral mesh of a piecewise linear complex, through TetGen.
#include <chrono>
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/quality.hpp"

namespace foxi::cli {

namespace {

const char* kMeshUsage =
    "foxi mesh PLC.poly -o OUT [--mesher tetgen|cgal] [--max-volume V] [--radius-edge Q] [--min-dihedral DEG]\n"
    "                   [--optimize] [--perturb] [--check-delaunay]\n"
    "  Meshes a TetGen .poly (points, facets with boundary markers, holes, region seeds) into tets\n"
    "  and writes OUT in any mesh format foxi knows (.vtu .msh .vtk .node .mesh).\n"
    "  --max-volume V    largest tet volume (in the PLC's units cubed); regions may set their own\n"
    "  --radius-edge Q   radius-edge quality bound (default 1.414; 0 turns quality refinement off)\n"
    "  --min-dihedral D  minimum dihedral angle bound in degrees\n"
    "  --optimize        TetGen's flips and smoothing: better angles, but the mesh stops being Delaunay\n"
    "  --check-delaunay  certify the result (exact empty-circumsphere test) and report it\n"
    "  --mesher cgal     CGAL Mesh_3 instead of TetGen: protected facet edges, sliver exudation; the mesh\n"
    "                    is part of a regular triangulation, its vertex weights are written (point data\n"
    "                    'weight' in .vtu) and always certified (orthospheres). --max-volume becomes the\n"
    "                    circumradius of a regular tet of that volume; --radius-edge defaults to 2;\n"
    "                    --perturb adds sliver perturbation; Ctrl-C cancels";

double number(const std::string& s, const char* what) {
  char* end = nullptr;
  double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !(v >= 0)) throw UsageError(std::string(what) + " takes a number >= 0, not '" + s + "'");
  return v;
}

}  // namespace

int mesh_with_cgal(Args& args);  // cmd_mesh_cgal.cpp

int cmd_mesh(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kMeshUsage);
    return 0;
  }
  const std::string mesher = args.option("--mesher", "tetgen");
  if (mesher == "cgal") return mesh_with_cgal(args);
  if (mesher != "tetgen") throw UsageError("--mesher takes tetgen or cgal, not '" + mesher + "'");
  MeshParams params;
  params.max_volume = number(args.option("--max-volume", "0"), "--max-volume");
  params.radius_edge = number(args.option("--radius-edge", "1.414"), "--radius-edge");
  params.min_dihedral = number(args.option("--min-dihedral", "0"), "--min-dihedral");
  params.optimize = args.flag("--optimize");
  const bool check = args.flag("--check-delaunay");
  const std::string out = args.option("-o");
  if (out.empty()) throw UsageError("give the output file with -o OUT\nusage: " + std::string(kMeshUsage));
  const std::string in = args.positional(1, 1, kMeshUsage)[0];
  format_from_path(out);  // an unknown output format fails before any meshing

  const Plc plc = read_poly(in);
  MeshReport report;
  Mesh mesh;
  try {
    mesh = mesh_plc(plc, params, &report);
  } catch (const MesherError& e) {
    std::fprintf(stderr, "foxi mesh: error: %s: %s\n", in.c_str(), e.what());
    return 1;
  }
  write_mesh(mesh, out);
  const QualitySummary q = summarize_quality(mesh);
  std::printf("%s -> %s: %zu nodes (%zu Steiner points), %zu tets, %zu boundary triangles, %zu regions in %.3f s\n",
              in.c_str(), out.c_str(), mesh.node_count(), report.steiner_points, mesh.tet_count(), mesh.bface_count(),
              mesh.regions.size(), report.seconds);
  std::printf("TetGen switches %s; radius-edge max %.4g, min dihedral %.3g deg, %zu slivers below 5 deg\n",
              report.switches.c_str(), q.radius_edge.max, q.min_dihedral_deg.min, q.slivers);
  if (check) {
    const DelaunayCertificate cert = compute_delaunay_certificate(mesh);
    if (cert.delaunay)
      std::printf("delaunay: yes, every circumsphere is empty (%zu tets)\n", cert.tets_checked);
    else
      std::printf("delaunay: NO, %zu of %zu tets have a vertex inside their circumsphere (deepest %.3g of the radius)\n",
                  cert.violating_tet_count, cert.tets_checked, cert.max_relative_depth);
  }
  return 0;
}

}  // namespace foxi::cli
