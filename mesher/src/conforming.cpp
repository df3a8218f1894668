#include "foxi/mesher/conforming.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
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

std::vector<std::uint32_t> flat_tets(const Mesh& mesh, double bound) {
  std::vector<std::uint32_t> flat;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    const Vec a = at(mesh.xyz, v[0]), b = sub(at(mesh.xyz, v[1]), a), c = sub(at(mesh.xyz, v[2]), a),
              d = sub(at(mesh.xyz, v[3]), a);
    const double l2 =
        std::max({norm2(b), norm2(c), norm2(d), norm2(sub(c, b)), norm2(sub(d, b)), norm2(sub(d, c))});
    const double six_v = std::abs(dot(b, cross(c, d)));
    if (!(six_v >= bound * l2 * std::sqrt(l2))) flat.push_back(static_cast<std::uint32_t>(t));
  }
  return flat;
}

namespace {

// A point inside each flat tet, for the PLC: the tet's centroid moved within the tet's plane by a
// fifth of its shortest edge in a direction drawn from the tet's own coordinates and the round
// (reproducible), so that the new point is strictly inside the tet's circumsphere (which destroys
// the tet) and does not recreate the symmetric, cospherical arrangement that made it. A tet on a
// facet of the PLC (its centroid there) gets no point: an isolated point on a facet would not be a
// PLC. Returns the points added.
std::size_t add_points_in_flat_tets(const Mesh& mesh, const std::vector<std::uint32_t>& flat,
                                    std::size_t round, Plc& plc) {
  EditablePlc edit(plc);
  const std::size_t before = plc.point_count();
  NearPoints added(edit.tol > 0 ? edit.tol * 1e6 : 1);
  for (std::uint32_t t : flat) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    std::array<Vec, 4> p{};
    for (int k = 0; k < 4; ++k) p[std::size_t(k)] = at(mesh.xyz, v[k]);
    Vec centroid = scale(add(add(p[0], p[1]), add(p[2], p[3])), 0.25);
    // The plane: the largest of the corner triangles' normals.
    Vec normal{0, 0, 0};
    double shortest2 = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 4; ++i) {
      const Vec n = cross(sub(p[std::size_t((i + 1) % 4)], p[std::size_t(i)]),
                          sub(p[std::size_t((i + 2) % 4)], p[std::size_t(i)]));
      if (norm2(n) > norm2(normal)) normal = n;
      for (int j = i + 1; j < 4; ++j)
        shortest2 = std::min(shortest2, norm2(sub(p[std::size_t(i)], p[std::size_t(j)])));
    }
    if (!(norm2(normal) > 0) || !(shortest2 > 0)) continue;  // collinear corners: nothing to aim at
    normal = scale(normal, 1 / std::sqrt(norm2(normal)));
    const Vec axis = std::abs(normal[0]) < 0.6 ? Vec{1, 0, 0} : Vec{0, 1, 0};
    const Vec across = cross(normal, axis);
    const Vec u = scale(across, 1 / norm(across)), w = cross(normal, u);
    std::uint64_t h = 1469598103934665603ull ^ round;  // FNV-1a over the corners' bits
    for (const Vec& q : p)
      for (double x : q) {
        std::uint64_t bits = 0;
        std::memcpy(&bits, &x, sizeof bits);
        h = (h ^ bits) * 1099511628211ull;
      }
    const double angle = double(h >> 11) * 0x1p-53 * 6.283185307179586;
    const Vec at_point = add(centroid, scale(add(scale(u, std::cos(angle)), scale(w, std::sin(angle))),
                                             0.2 * std::sqrt(shortest2)));
    if (edit.facet_at(at_point) != edit.facets.size()) continue;
    if (added.near(at_point, 0.5 * std::sqrt(shortest2))) continue;  // a neighbouring flat tet's
    added.add(at_point);
    edit.add_point(at_point);
  }
  edit.write_back();
  return plc.point_count() - before;
}

}  // namespace

namespace {

Mesh conform(const Plc& plc, const MeshParams& params, const ConformingParams& conforming,
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

}  // namespace

Mesh mesh_conforming(const Plc& plc, const MeshParams& params, const ConformingParams& conforming,
                     ConformingReport* report, Plc* refined_plc) {
  ConformingReport rep;
  Plc current;
  Mesh mesh = conform(plc, params, conforming, &rep, &current);
  // Flat tets: TetGen's Steiner points in symmetric places (the midpoints of a bar's four sides at
  // one height) make groups of four nearly coplanar and cocircular points, and the Delaunay mesh holds
  // the flat tet across them (6V 1e-17 of its edges cubed; 0 in double), which no solver can assemble
  // (its stiffness is 1e17 of its neighbours') and the sphere table cannot key. A point inside each,
  // into the mesh's own vertices and surface triangles, TetGen without refinement of its own: the
  // Delaunay mesh changes only where the new points are (meshing the PLC again moved every Steiner
  // point and made new flat tets elsewhere: 18 flat tets fell to 10 in three rounds on a thin bar).
  std::vector<std::uint32_t> flat = conforming.flat_tet_bound > 0 && rep.delaunay
                                        ? flat_tets(mesh, conforming.flat_tet_bound)
                                        : std::vector<std::uint32_t>{};
  MeshParams certify_only = params;
  certify_only.radius_edge = 0;
  certify_only.max_volume = 0;
  certify_only.size_field = nullptr;
  for (std::size_t round = 0; round < conforming.max_flat_rounds && !flat.empty(); ++round) {
    Plc more = surface_plc(mesh, current);
    for (RegionSeed& s : more.regions) s.max_volume = 0;
    const std::size_t n = add_points_in_flat_tets(mesh, flat, round, more);
    if (n == 0) break;
    if (params.progress && !params.progress("removing flat tets", -1.0))
      throw MesherCancelled("meshing cancelled");
    ConformingReport again;
    Plc again_plc;
    Mesh again_mesh;
    try {
      // Certified as the surface rounds do (split encroached surface triangles), and no other split:
      // TetGen's slivers stay as they were.
      ConformingParams only_certify = conforming;
      only_certify.split_dihedral_deg = 0;
      again_plc = std::move(more);
      again_mesh = detail::refine_with_thin_layers(certify_only, only_certify, {}, again_plc, again);
    } catch (const MesherError& e) {
      if (e.tetgen_code() == -1) throw;  // cancelled
      break;                             // TetGen failed on it: the certified mesh stays
    }
    if (!again.delaunay || again_mesh.tet_count() == 0) break;
    if (!same_region_volumes(region_volumes(mesh), region_volumes(again_mesh))) break;
    std::vector<std::uint32_t> again_flat = flat_tets(again_mesh, conforming.flat_tet_bound);
    if (again_flat.size() >= flat.size()) continue;  // another draw of the points next round
    rep.flat_tets_removed += flat.size() - again_flat.size();
    rep.flat_points += n;
    rep.added_points += again.added_points;
    rep.iterations += again.iterations + 1;
    rep.surface_rounds += again.surface_rounds;
    rep.seconds += again.seconds;
    rep.certificate_seconds += again.certificate_seconds;
    rep.violations.insert(rep.violations.end(), again.violations.begin(), again.violations.end());
    rep.tetgen = again.tetgen;
    mesh = std::move(again_mesh);
    current = std::move(again_plc);
    flat = std::move(again_flat);
  }
  rep.flat_tets = flat.size();
  if (rep.flat_tets_removed > 0 && rep.radius_edge_bound > 0) {
    rep.over_radius_edge = 0;
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      const std::uint32_t* v = &mesh.tet[4 * t];
      const TetQuality q =
          tet_quality(&mesh.xyz[3 * v[0]], &mesh.xyz[3 * v[1]], &mesh.xyz[3 * v[2]], &mesh.xyz[3 * v[3]]);
      rep.over_radius_edge += q.radius_edge > rep.radius_edge_bound * (1 + 1e-9);
    }
  }
  if (report) *report = rep;
  if (refined_plc) *refined_plc = std::move(current);
  return mesh;
}

}  // namespace foxi
