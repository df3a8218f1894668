#include "foxi/mesher/conforming.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "coplanar_facets.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/quality.hpp"
#include "layer_refinement.hpp"
#include "plc_edit.hpp"
#include "refinement_round.hpp"

namespace foxi {

using namespace detail;

std::size_t split_encroached_constraints(const Mesh& mesh, const std::vector<std::uint32_t>& violating_tets,
                                         Plc& plc) {
  const MeshSearch search(mesh);
  std::vector<char> split(mesh.bface_count(), 0);
  mark_faces_for_violations(search, violating_tets, split);
  EditablePlc edit(plc);
  const std::size_t before = plc.point_count();
  NearPoints added(search.vertices.cell);
  split_faces(mesh, search.face_ball, split, edit, added);
  edit.write_back();
  return plc.point_count() - before;
}

Mesh mesh_conforming(const Plc& plc, const MeshParams& params, const ConformingParams& conforming,
                     ConformingReport* report, Plc* refined_plc) {
  const auto t0 = std::chrono::steady_clock::now();
  ConformingReport rep;
  MeshParams p = params;
  p.optimize = false;
  Plc current = plc;
  detail::snap_coordinates(current);
  detail::weld_coincident_points(current);
  if (conforming.surface_rescue) detail::merge_coplanar_facets(current);
  Mesh mesh;
  const std::vector<ThinLayer> layers =
      conforming.thin_layer_aspect > 0 && (params.radius_edge > 0 || params.max_volume > 0 ||
                                           (params.size_field && !params.size_field->empty()) ||
                                           std::any_of(plc.regions.begin(), plc.regions.end(),
                                                       [](const RegionSeed& s) { return s.max_volume > 0; }))
          ? find_thin_layers(plc, conforming.thin_layer_aspect, conforming.thin_layer_min_area)
          : std::vector<ThinLayer>{};
  RefinementRounds rounds(p, rep);
  if (!layers.empty()) mesh = detail::refine_with_thin_layers(params, conforming, layers, current, rep);
  for (std::size_t it = 0; layers.empty(); ++it) {
    const std::optional<DelaunayCertificate> round = rounds.run(it, current, mesh);
    if (!round) break;
    const DelaunayCertificate& cert = *round;
    if (cert.delaunay || it >= conforming.max_iterations) break;
    if (conforming.surface_rescue && !conforming.remesh_plc_first) break;  // straight to the surface rounds
    // TetGen's own refinement answering a round's splits with new violations: the rounds are not
    // settling, and the surface rescue below settles faster from here.
    if (conforming.surface_rescue && it > 0 && rep.violations[it] >= rep.violations[it - 1]) break;
    const double budget = std::max(conforming.max_added_fraction * double(rep.first_mesh_points),
                                   double(conforming.min_added_budget));
    if (double(rep.added_points) >= budget) break;
    if (params.progress &&
        !params.progress("conforming refinement", double(it + 1) / double(conforming.max_iterations + 1)))
      throw MesherCancelled("meshing cancelled");
    rounds.keep(current, mesh);
    const std::size_t n = split_encroached_constraints(mesh, cert.violating_tets, current);
    if (n == 0) break;
    rep.added_points += n;
    rep.iterations = it + 1;
  }
  // TetGen 1.5.0 fails on some refined PLCs (curved faceted surfaces, slivers from corefinement),
  // and its own quality refinement can undo a round's splits: from the last mesh this loop made, go on
  // refining the mesh's own surface triangles, TetGen recovering them without refinement of its own.
  if (conforming.surface_rescue && layers.empty() && !rep.delaunay && rep.violations.size() > 0) {
    ConformingReport rescue;
    // TetGen's refinement made the quality; the rescue only makes the certificate pass (a radius-edge
    // bound of its own, near the boundary where TetGen's -q leaves some tets over it, does not settle).
    MeshParams certify_only = params;
    certify_only.radius_edge = 0;
    certify_only.max_volume = 0;
    certify_only.size_field = nullptr;
    for (RegionSeed& s : current.regions) s.max_volume = 0;
    mesh = detail::refine_with_thin_layers(certify_only, conforming, {}, current, rescue, &mesh);
    rep.added_points += rescue.added_points;
    rep.quality_points += rescue.quality_points;
    rep.quality_unmet = rescue.quality_unmet;
    rep.iterations += rescue.iterations;
    rep.violations.insert(rep.violations.end(), rescue.violations.begin() + 1, rescue.violations.end());
    rep.delaunay = rescue.delaunay;
    rep.tetgen_failed = rescue.tetgen_failed;
    rep.certificate_seconds += rescue.certificate_seconds;
    rep.surface_rounds = rescue.iterations;
  }
  if (layers.empty() && params.radius_edge > 0) {
    rep.radius_edge_bound = params.radius_edge;
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      const std::uint32_t* v = &mesh.tet[4 * t];
      const TetQuality q =
          tet_quality(&mesh.xyz[3 * v[0]], &mesh.xyz[3 * v[1]], &mesh.xyz[3 * v[2]], &mesh.xyz[3 * v[3]]);
      rep.over_radius_edge += q.radius_edge > params.radius_edge * (1 + 1e-9);
    }
  }
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = rep;
  if (refined_plc) *refined_plc = std::move(current);
  return mesh;
}

}  // namespace foxi
