// foxi mesh MODEL.toml|PLC.poly --mesher cgal -o OUT: the report of the CGAL Mesh_3 path of `foxi mesh`
// (options in cmd_mesh.cpp, meshing by mesh_model): counts, time, dihedral angles, each region's volume
// against the PLC's and the weighted certificate. A mesh that fails either check is written but refused
// (exit 4).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "exit_codes.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/quality.hpp"

namespace foxi::cli {

namespace {

// The largest dihedral angle of a tet (degrees), from its face normals.
double max_dihedral_deg(const Mesh& m, std::size_t t) {
  static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  double n[4][3];
  for (int f = 0; f < 4; ++f) {
    const double* a = &m.xyz[3 * m.tet[4 * t + face[f][0]]];
    const double* b = &m.xyz[3 * m.tet[4 * t + face[f][1]]];
    const double* c = &m.xyz[3 * m.tet[4 * t + face[f][2]]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[f][0] = u[1] * w[2] - u[2] * w[1];
    n[f][1] = u[2] * w[0] - u[0] * w[2];
    n[f][2] = u[0] * w[1] - u[1] * w[0];
    const double len = std::sqrt(n[f][0] * n[f][0] + n[f][1] * n[f][1] + n[f][2] * n[f][2]);
    for (double& x : n[f]) x /= len;
  }
  double worst =
      0;  // the dihedral angle at the edge of faces f and g is pi minus the angle of their outward normals
  for (int f = 0; f < 4; ++f)
    for (int g = f + 1; g < 4; ++g) {
      const double d = n[f][0] * n[g][0] + n[f][1] * n[g][1] + n[f][2] * n[g][2];
      worst = std::max(worst, 180.0 - std::acos(std::clamp(d, -1.0, 1.0)) * 180.0 / M_PI);
    }
  return worst;
}

}  // namespace

// The exit status of a mesher failure: the input's fault, a stop asked for, or the mesher's.
int mesher_exit_code(MesherFailure f) {
  switch (f) {
    case MesherFailure::bad_input:
    case MesherFailure::self_intersection:
    case MesherFailure::feature_too_small:
    case MesherFailure::facets_too_close:
      return kExitBadInput;
    case MesherFailure::cancelled:
      return kExitInterrupted;
    default:
      return kExitFailure;
  }
}

int report_cgal_mesh(const std::string& in, const std::string& out, const MeshedModel& m,
                     double volume_tolerance) {
  const Mesh& mesh = m.mesh;
  const CgalMeshReport& report = m.cgal;
  const QualitySummary q = summarize_quality(mesh);
  double max_dihedral = 0;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    max_dihedral = std::max(max_dihedral, max_dihedral_deg(mesh, t));
  std::printf("%s -> %s: %zu nodes, %zu tets, %zu boundary triangles, %zu regions in %.3f s (CGAL Mesh_3)\n",
              in.c_str(), out.c_str(), mesh.node_count(), mesh.tet_count(), mesh.bface_count(),
              mesh.regions.size(), report.seconds);
  std::printf(
      "sizes: cell %.4g, facet %.4g, edge %.4g%s; radius-edge max %.4g, dihedral min %.3g max %.4g deg, %zu "
      "slivers below 5 deg\n",
      report.max_size, report.facet_size, report.edge_size,
      report.boxes > 0
          ? (" (smaller inside the refinement boxes: " + std::to_string(report.boxes) + ")").c_str()
          : "",
      q.radius_edge.max, q.min_dihedral_deg.min, max_dihedral, q.slivers);
  // Each region's volume against the PLC's (the divergence theorem over its facets).
  auto region_name = [&](std::int32_t id) {
    for (const Region& r : mesh.regions)
      if (r.id == id && !r.name.empty()) return " (" + r.name + ")";
    return std::string();
  };
  std::printf(
      "PLC: %zu coordinates snapped and %zu points welded (rounding), %zu facet triangles in %zu patches "
      "(%zu coplanar "
      "facets joined a neighbour's), %zu facets without area left out; %zu tets labelled by centroid, not "
      "circumcentre\n",
      report.coordinates_snapped, report.points_welded, report.facet_triangles, report.patches,
      report.facets_joined, report.facets_without_area, report.tets_relabelled);
  std::printf("region volumes against the PLC (%s):\n",
              report.resampled ? "facets resampled" : "every facet edge protected");
  for (const CgalRegionVolume& v : report.volumes)
    std::printf("  region %d%s: PLC %.6g, mesh %.6g, change %+.3g%%\n", v.region,
                region_name(v.region).c_str(), v.plc, v.mesh, 100 * v.relative_change());
  const DelaunayCertificate& cert = delaunay_certificate(mesh);  // computed by mesh_model, cached
  if (cert.delaunay)
    std::printf("regular (weighted Delaunay): yes, every orthosphere is empty (%zu tets); weights written\n",
                cert.tets_checked);
  else
    std::printf("regular (weighted Delaunay): NO, %zu of %zu tets violated, %zu degenerate\n",
                cert.violating_tet_count, cert.tets_checked, cert.degenerate_tet_count);
  int status = kExitOk;
  if (!cert.delaunay) {
    std::fprintf(stderr,
                 "foxi mesh: error: %s: the mesh written to %s fails the weighted Delaunay certificate\n",
                 in.c_str(), out.c_str());
    status = kExitUnreliable;
  }
  if (!report.resampled && !report.areas_match) {
    std::fprintf(stderr,
                 "foxi mesh: error: %s: the area of boundary tag %d differs from the PLC's by more than "
                 "%.3g%% (worst tag: %.3g%%) "
                 "although every facet edge was protected: Mesh_3 did not recover that surface, the mesh "
                 "written to %s "
                 "does not follow its PLC\n",
                 in.c_str(), report.worst_area_marker, 100 * volume_tolerance, 100 * report.worst_area_change,
                 out.c_str());
    status = kExitUnreliable;
  }
  if (!report.resampled && !report.volumes_match) {
    std::fprintf(stderr,
                 "foxi mesh: error: %s: a region's volume differs from the PLC's by %.3g%% (more than "
                 "%.3g%%) although every facet "
                 "edge was protected: the mesh written to %s does not cover its PLC\n",
                 in.c_str(), 100 * report.worst_volume_change, 100 * volume_tolerance, out.c_str());
    status = kExitUnreliable;
  }
  return status;
}

}  // namespace foxi::cli
