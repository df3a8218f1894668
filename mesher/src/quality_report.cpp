#include "foxi/mesher/quality_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace foxi {

MeshQualityReport mesh_quality_report(const Mesh& mesh, const ConformingReport& conforming,
                                      const QualityReportParams& params) {
  MeshQualityReport r;
  r.nodes = mesh.node_count();
  r.tets = mesh.tet_count();
  r.boundary_triangles = mesh.bface_count();
  r.shape = summarize_quality(mesh);
  r.sliver_angle_deg = params.sliver_angle_deg;
  std::map<std::int32_t, RegionSize> regions;
  const std::size_t nv = mesh.node_count();
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    if (v[0] >= nv || v[1] >= nv || v[2] >= nv || v[3] >= nv) continue;
    const TetQuality q =
        tet_quality(&mesh.xyz[3 * v[0]], &mesh.xyz[3 * v[1]], &mesh.xyz[3 * v[2]], &mesh.xyz[3 * v[3]]);
    if (q.min_dihedral_deg < params.sliver_angle_deg) ++r.slivers;
    const double bin = std::floor(q.min_dihedral_deg / 5);
    const std::size_t last = r.min_dihedral_histogram.size() - 1;
    r.min_dihedral_histogram[bin > 0 ? std::min(std::size_t(bin), last) : 0]++;
    if (!conforming.thin_layers.empty()) {
      if (tet_in_thin_layer(mesh, t, conforming.thin_layers))
        ++r.thin_layer_tets;
      else
        r.max_radius_edge_outside_layers = std::max(r.max_radius_edge_outside_layers, q.radius_edge);
    }
    RegionSize& rs = regions[mesh.region_of(t)];
    ++rs.tets;
    rs.volume += std::abs(q.volume);
  }
  for (auto& [id, rs] : regions) {
    rs.id = id;
    for (const Region& reg : mesh.regions)
      if (reg.id == id) rs.name = reg.name;
    r.regions.push_back(rs);
  }
  r.tetgen_steiner_points = conforming.tetgen.steiner_points;  // the added points were TetGen's input
  r.conforming_points = conforming.added_points;
  r.conforming_overhead = conforming.first_mesh_points
                              ? double(conforming.added_points) / double(conforming.first_mesh_points)
                              : 0;
  r.iterations = conforming.iterations;
  r.thin_layers = conforming.thin_layers.size();
  r.quality_points = conforming.quality_points;
  r.quality_unmet = conforming.quality_unmet;
  r.radius_edge_bound = conforming.radius_edge_bound;
  r.over_radius_edge = conforming.over_radius_edge;
  if (r.thin_layers > 0 && r.nodes > r.conforming_points)  // the first mesh is the bare PLC there
    r.conforming_overhead = double(r.conforming_points) / double(r.nodes - r.conforming_points);
  r.first_mesh_violations = conforming.first_mesh_violations;
  r.delaunay = conforming.delaunay;
  r.tetgen_failed = conforming.tetgen_failed;
  r.violating_tets = conforming.violations.empty() ? 0 : conforming.violations.back();
  r.flat_tets_removed = conforming.flat_tets_removed;
  r.flat_points = conforming.flat_points;
  r.flat_tets = conforming.flat_tets;
  r.mesh_seconds = conforming.seconds;
  r.certificate_seconds = conforming.certificate_seconds;
  return r;
}

std::string format_quality_report(const MeshQualityReport& r) {
  std::string s;
  char line[512];
  auto put = [&](const char* fmt, auto... args) {
    std::snprintf(line, sizeof line, fmt, args...);
    if (!s.empty()) s += '\n';
    s += line;
  };
  put("mesh: %zu nodes, %zu tets, %zu boundary triangles", r.nodes, r.tets, r.boundary_triangles);
  put("radius-edge ratio: min %.3g, mean %.3g, max %.3g (regular tet 0.612)", r.shape.radius_edge.min,
      r.shape.radius_edge.mean, r.shape.radius_edge.max);
  put("min dihedral angle: min %.3g, mean %.3g deg; %zu slivers below %g deg (kept: Delaunay refinement does "
      "not "
      "remove slivers, flips or smoothing would break the Delaunay property)",
      r.shape.min_dihedral_deg.min, r.shape.min_dihedral_deg.mean, r.slivers, r.sliver_angle_deg);
  std::string hist = "min dihedral histogram (5 deg bins from 0):";
  for (std::size_t c : r.min_dihedral_histogram) hist += " " + std::to_string(c);
  put("%s", hist.c_str());
  put("tet volume: min %.4g, max %.4g m^3, total %.6g m^3", r.shape.volume.min, r.shape.volume.max,
      r.shape.total_volume);
  for (const RegionSize& rs : r.regions)
    put("  region %d%s%s: %zu tets, %.6g m^3", rs.id, rs.name.empty() ? "" : " ", rs.name.c_str(), rs.tets,
        rs.volume);
  if (r.thin_layers == 0) {
    put("Steiner points: %zu by TetGen, %zu for conformity (%.2f%% of the first -O0 mesh's points) in %zu "
        "iterations",
        r.tetgen_steiner_points, r.conforming_points, 100 * r.conforming_overhead, r.iterations);
    if (r.over_radius_edge > 0)
      put("radius-edge bound %g: %zu tets over it (TetGen leaves some near small input angles, the "
          "conformity "
          "rounds some next to the boundary points they add; refining those did not settle on faceted curved "
          "surfaces)",
          r.radius_edge_bound, r.over_radius_edge);
  } else {
    put("thin layers: %zu, exempt from the quality bounds: %zu tets in them; outside them radius-edge max "
        "%.3g, "
        "%zu tets still over a bound",
        r.thin_layers, r.thin_layer_tets, r.max_radius_edge_outside_layers, r.quality_unmet);
    put("Steiner points: %zu by TetGen, %zu by foxi's refinement for quality and size, %zu for conformity "
        "(%.2f%% "
        "of the other points) in %zu iterations",
        r.tetgen_steiner_points, r.quality_points, r.conforming_points, 100 * r.conforming_overhead,
        r.iterations);
  }
  if (r.delaunay)
    put("delaunay: yes, every circumsphere is empty (exact; the first -O0 mesh had %zu non-Delaunay tets)",
        r.first_mesh_violations);
  else
    put("delaunay: NO, %zu tets have a vertex inside their circumsphere (the first -O0 mesh had %zu)",
        r.violating_tets, r.first_mesh_violations);
  if (r.flat_tets_removed > 0)
    put("flat tets: %zu removed (corners coplanar to round-off; %zu %s added inside them, meshed again)",
        r.flat_tets_removed, r.flat_points, r.flat_points == 1 ? "point" : "points");
  if (r.flat_tets > 0)
    put("flat tets: %zu left (corners coplanar to round-off: solvers may refuse this mesh; mesh again with "
        "another --max-size)",
        r.flat_tets);
  if (r.tetgen_failed)
    put("refinement stopped early: TetGen failed on the refined PLC (or lost a region); this is the last "
        "good mesh");
  put("time: %.3f s meshing and refinement, of which %.3f s certificates", r.mesh_seconds,
      r.certificate_seconds);
  return s;
}

}  // namespace foxi
