// Conforming Delaunay meshing (issue 6, item 2): TetGen without optimisation (-O0) gives a
// constrained Delaunay mesh, which is not always Delaunay where a boundary or interface triangle
// separates a tet from a vertex inside its circumsphere. mesh_conforming() certifies TetGen's mesh
// (exact global check, delaunay.hpp), and for every violation splits the constraint triangles that
// the offending vertex encroaches (the vertex lies strictly inside the triangle's diametral sphere):
// it adds the triangle's circumcentre to its facet, or, when that centre would fall outside the
// triangle next to a PLC segment or encroach that segment, the subsegment's midpoint to the segment
// (Ruppert/Shewchuk's rule); when the vertex encroaches none (the sphere reaches round a non-convex
// boundary), the triangles that hide it from the tet. By default the first mesh's surface triangles
// become the PLC and are split in place, each round re-meshed by TetGen without refinement of its own
// (ConformingParams::surface_rescue); otherwise the points go into the input PLC (as one-vertex
// polygons of the facet, or as a new vertex of every polygon along the segment) and TetGen meshes the
// refined PLC again. Either way until the certificate passes or the rounds run out.
//
// Sliver policy: Delaunay refinement bounds the radius-edge ratio, not the dihedral angles, so the
// result may hold slivers (four nearly cospherical vertices). They are Delaunay and ordered
// correctly by the viewer; they are counted in the quality report (quality_report.hpp) and left in
// place, because flipping or smoothing them away would break the Delaunay property. A sliver-free
// mesh needs the weighted (regular) path through CGAL with sliver exudation. Flat tets, whose
// corners are coplanar to round-off (ConformingParams::flat_tet_bound), are the exception: no solver
// can assemble them, so each gets a point inside and the PLC is meshed again.
#pragma once

#include <cstddef>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/mesher/thin_layers.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"

namespace foxi {

struct ConformingParams {
  std::size_t max_iterations = 12;        // TetGen runs after the first
  std::size_t max_layer_iterations = 60;  // with thin layers: refinement rounds (one TetGen run each)
  // Surface rounds: when the first mesh is not certified, refine from it by splitting its own surface
  // triangles, TetGen recovering them without refinement of its own (see remesh_plc_first). Certifies
  // PLCs on which TetGen's facet triangulation of a refined PLC fails (curved faceted surfaces,
  // corefinement slivers) or on which its refinement answers splits with new violations. Also joins
  // coplanar facet pieces of the input first (coplanar_facets.hpp). No effect on PLCs with thin
  // layers. Off: only the rounds that re-mesh the refined PLC (max_iterations).
  bool surface_rescue = true;
  // With surface_rescue: first re-mesh the refined PLC with TetGen's own refinement (the rounds above,
  // while the violations fall), then the surface rounds. Off by default: the surface rounds alone
  // certify in a third of the time with half the points (power_module: 21 s and 651 points against
  // 55 s and 1,355; bga 1.4 s and 70 against 4.1 s and 219), leaving about as many tets over the
  // radius-edge bound (30 against 11 of 600k; 53 against 152 of 50k).
  bool remesh_plc_first = false;
  // Thin layers at least this many times wider than thick are exempt from the quality bounds
  // (thin_layers.hpp), and foxi then refines by itself; 0: no exemption (TetGen's refinement then
  // fills a thin layer with tets as wide as it is thick).
  double thin_layer_aspect = kThinLayerAspect;
  // ... and whose area is at least this many thicknesses squared (thin_layers.hpp: below it TetGen's
  // own refinement meshes the layer at an affordable cost, and the quality bounds hold everywhere).
  double thin_layer_min_area = kThinLayerMinArea;
  double max_added_fraction = 0.15;    // stop once the points added exceed this fraction of the
                                       // first (-O0) mesh's point count ...
  std::size_t min_added_budget = 100;  // ... or this many, whichever is more (small meshes)
  // Flat tets: |6V| below this times the longest edge cubed (corners coplanar to round-off; a
  // regular tet has 0.71, TetGen's slivers 1e-3 and more, the flat ones 1e-17). Each gets a point
  // inside and the PLC is meshed again, at most max_flat_rounds times; 0: kept.
  double flat_tet_bound = 1e-9;
  // foxi's own refinement (thin layers, surface rounds) splits every tet outside the layers with a
  // dihedral angle under this many degrees (four almost cocircular coplanar points); 0: none.
  double split_dihedral_deg = 1.0;
  std::size_t max_flat_rounds = 3;
};

struct ConformingReport {
  MeshReport tetgen;                      // the last TetGen run
  std::size_t first_mesh_points = 0;      // points of the first -O0 mesh
  std::size_t first_mesh_violations = 0;  // its non-Delaunay tets
  std::size_t added_points = 0;           // Steiner points added to the PLC for conformity
  std::size_t iterations = 0;             // TetGen re-runs after the first
  std::vector<std::size_t> violations;    // non-Delaunay tets after each TetGen run
  bool delaunay = false;                  // the final mesh passed the exact certificate
  // TetGen 1.5.0 failed on a refined PLC (its segment recovery asserts on some inputs), or its mesh
  // of it lost a region (a region's volume changed): the last good mesh is returned, with that
  // mesh's certificate, and refinement stops.
  bool tetgen_failed = false;
  double seconds = 0;  // all TetGen runs, certificates and splits
  // Thin layers (thin_layers.hpp; ConformingParams::thin_layer_aspect): when the PLC has any, TetGen runs
  // without its own refinement (which would fill them with tets as wide as they are thick) and foxi
  // refines for quality and size itself, outside the layers.
  std::vector<ThinLayer> thin_layers;
  std::size_t thin_layer_tets = 0;  // tets lying in them (exempt from the quality bounds)
  std::size_t quality_points = 0;   // points foxi added for quality and size
  std::size_t quality_unmet = 0;    // tets outside the layers still over a bound at the end
  // Without thin layers: the radius-edge bound (0: none) and the tets of the final mesh over it.
  // TetGen's refinement leaves some near small input angles, and the conformity rounds (surface
  // rounds above all) some next to the boundary points they add.
  double radius_edge_bound = 0;
  std::size_t over_radius_edge = 0;
  double certificate_seconds = 0;  // of which the certificates
  // Rounds that refined the mesh's own surface triangles after TetGen failed on a refined PLC or the
  // conforming rounds ran out (0: none were needed).
  std::size_t surface_rounds = 0;
  // Flat tets (ConformingParams::flat_tet_bound): those left in the final mesh, those the flat rounds
  // removed, and the points they added (also counted in added_points' rounds, not in added_points).
  std::size_t flat_tets = 0;
  std::size_t flat_tets_removed = 0;
  std::size_t flat_points = 0;
};

// Meshes `plc` with TetGen (params.optimize is forced off) and refines until the exact Delaunay
// certificate passes. Returns the last mesh even when it is not certified (report->delaunay says);
// throws MesherError like mesh_plc, and MesherError(-1) when params.progress cancels (stage
// "conforming refinement" between runs, fraction = iteration / max_iterations). `refined_plc`, if
// given, receives the PLC with the added points (after surface rounds: the mesh's surface triangles
// as facets and all its vertices, TetGen's Steiner points among them).
FOXI_API Mesh mesh_conforming(const Plc& plc, const MeshParams& params = {},
                              const ConformingParams& conforming = {}, ConformingReport* report = nullptr,
                              Plc* refined_plc = nullptr);

// The split points for one mesh of `plc`: for every tet in `violating_tets`, every constraint
// triangle (mesh.bface) encroached by a vertex inside that tet's circumsphere is split; `plc` gets
// the points. Returns the number of points added (0: nothing found to split). Exposed for tests.
// The tets of `mesh` with |6V| < bound x (longest edge)^3, in order.
FOXI_API std::vector<std::uint32_t> flat_tets(const Mesh& mesh, double bound);

FOXI_API std::size_t split_encroached_constraints(const Mesh& mesh,
                                                  const std::vector<std::uint32_t>& violating_tets, Plc& plc);

}  // namespace foxi
