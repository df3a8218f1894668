// Meshing a PLC with CGAL's Mesh_3 (issue 6, item 3; issue 22): the PLC's facets become the patches of
// a polyhedral-complex domain (each with the cells on its two sides, so multiple materials and
// interfaces are kept), then Delaunay refinement with facet/cell size and radius-edge criteria, then
// sliver exudation (and optionally perturbation).
//
// Features. By default every facet is its own patch and every facet edge of the PLC is a protected
// feature: the boundary mesh is an exact retriangulation of the PLC's facets, so boxes stay boxes and a
// faceted cylinder keeps its facets, and each region's volume is the PLC's (checked: see
// CgalMeshReport::volumes_match). Only coplanar facets of one marker and pair of cells that share an
// edge no other facet meets are one patch (the triangle soup a corefined structure gives, e.g. the ball
// grid array): the edges between them are no feature of the geometry. With `resample`, facets of one marker
// and pair of cells form one patch and only the patch borders and the edges where the facets turn by more
// than `feature_angle` are protected: a faceted cylinder's wall is then one smooth patch, resampled within
// facet_distance, and the region volumes change (reported per region).
//
// The result is a subset of a regular (weighted Delaunay) triangulation: the tets inside the domain.
// Every node gets its weight in Mesh::weight (the regular triangulation's point weight, a squared
// radius, the convention of delaunay.hpp): with them the mesh passes the weighted Delaunay certificate
// and the viewer orders it exactly by orthosphere power. The weights of vertices outside the exported
// subset are dropped with those vertices; they bound nothing that is drawn.
//
// Regions: each cell of the PLC (component of space minus the facets) takes the id of the first region
// seed inside it, and each tet the region of the PLC cell its centroid lies in (Mesh_3's own label, by
// circumcentre, puts flat tets of a thin layer in the next part); enclosed cells with no seed are region 0;
// the unbounded cell and cells holding a volume hole point are not meshed. Boundary triangles carry their
// facet's marker. Facets with the same cell on both sides (a membrane inside one region) are not kept.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/mesher/mesher.hpp"      // MesherError, MesherFailure
#include "foxi/mesher/size_field.hpp"  // RefinementBox
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

struct CgalMeshParams {
  // Largest tet circumradius (PLC units); 0: a twentieth of the bounding box diagonal. A region seed's
  // max_volume lowers it inside that region (the circumradius of a regular tet of that volume).
  double max_size = 0;
  double facet_size = 0;  // largest surface Delaunay ball radius; 0: max_size
  double edge_size = 0;   // largest protecting ball along facet edges; 0: facet_size
  // Refinement boxes, each with a target edge length h inside (as TetGen's boxes and region sizes):
  // at a point inside a box the cell size, the facet size and the edge size are at most the
  // circumradius of the regular tet of edge h (h sqrt6 / 4, the conversion of the region sizes), the
  // smallest over the boxes that hold the point. A box needs finite corners with lo <= hi and h > 0.
  std::vector<RefinementBox> boxes;
  // Largest distance of a boundary triangle's circumcentre from the PLC surface: with `resample` it
  // bounds how far a curved-looking surface (a faceted cylinder) is cut inside; 0: facet_size / 20.
  double facet_distance = 0;
  // false (default): every PLC facet edge is protected and region volumes are the PLC's. true: facets
  // are resampled, only patch borders and edges turning by more than feature_angle are protected.
  bool resample = false;
  double feature_angle = 60;  // degrees between facet normals; used with `resample` only
  double facet_angle = 25;    // lower bound of boundary triangle angles (degrees, at most 30)
  double radius_edge = 2;     // circumradius / shortest edge bound of tets (>= 2 guarantees termination)
  bool exude = true;          // sliver exudation (weight pumping: keeps the triangulation regular)
  bool perturb = false;       // sliver perturbation before exudation (moves vertices)
  // Perturbation and exudation work on tets whose smallest dihedral angle is below this (degrees); 0
  // (CGAL's default) has them improve the worst tet for as long as they can, which on some PLCs (the
  // via example) does not end in minutes.
  double sliver_bound = 12;
  double optimiser_seconds =
      60;  // time limit of each of perturb / exude; 0: none (both also end by time_limit)
  // Wall-clock limit of the whole run in seconds; 0: none. Mesh_3 has no bound on its refinement (a
  // thin layer under a wide part asks for millions of tets): past the limit its child process is
  // killed and MesherFailure::time_limit is thrown.
  double time_limit = 300;
  // Relative tolerance of each region's volume against the PLC's (CgalMeshReport::volumes_match).
  double volume_tolerance = 1e-3;
  // Asked about every 100 ms while Mesh_3 runs in its child process (fraction -1: unknown);
  // returning false kills it and mesh_plc_cgal throws MesherError (MesherFailure::cancelled).
  ProgressFn progress;
};

// One region's volume in the PLC (divergence theorem over its cells' facets) and in the mesh.
struct CgalRegionVolume {
  std::int32_t region = 0;
  double plc = 0;
  double mesh = 0;
  double relative_change() const { return plc > 0 ? mesh / plc - 1 : (mesh > 0 ? 1.0 : 0.0); }
};

struct CgalMeshReport {
  std::size_t input_points = 0;
  std::size_t facet_triangles = 0;  // triangles of the PLC's facets handed to CGAL
  std::size_t patches = 0;          // surface patches of the domain (input polyhedra)
  std::size_t cells = 0;            // meshed cells (regions of space) of the PLC
  std::size_t coordinates_snapped =
      0;  // coordinates made equal to others they differ from by rounding (1e-12 of the extent)
  std::size_t points_welded = 0;  // points merged into one they coincide with to 1e-12 of the extent
  std::size_t facets_joined = 0;  // PLC facets in the patch of a coplanar neighbour (see above)
  std::size_t facets_without_area =
      0;                   // facets of only segments or points (or collinear): they bound nothing, left out
  bool resampled = false;  // CgalMeshParams::resample was set
  double max_size = 0;     // the size bounds used
  double facet_size = 0, edge_size = 0, facet_distance = 0;
  std::size_t boxes = 0;  // refinement boxes taken (CgalMeshParams::boxes)
  // Tets labelled by their centroid's part where Mesh_3's label (its circumcentre's part) differs
  // (see "Regions" above).
  std::size_t tets_relabelled = 0;
  std::vector<CgalRegionVolume> volumes;  // by region id, every meshed region of the PLC
  double worst_volume_change = 0;         // largest |relative_change()|
  // Every region's volume within volume_tolerance of the PLC's. Always expected without `resample`
  // (false there means the mesh does not cover its PLC: a result to refuse); with it, the report says
  // by how much resampling changed each region.
  bool volumes_match = false;
  // The same for each facet marker's area (PLC facets between two different cells against the mesh's
  // boundary triangles of that tag), to the same tolerance: a surface Mesh_3 did not recover (an
  // interface inside a thin stack, which the tets then straddle) shows here.
  bool areas_match = false;
  double worst_area_change = 0;
  std::int32_t worst_area_marker = 0;  // a marker whose area is off (when !areas_match)
  double seconds = 0;
};

// Throws MesherError: MesherFailure::bad_input for a PLC or parameters it cannot use (the message names
// the facet, seed or value), time_limit past params.time_limit, cancelled when params.progress says stop,
// internal_error for a CGAL failure (the message says which).
FOXI_API Mesh mesh_plc_cgal(const Plc& plc, const CgalMeshParams& params = {},
                            CgalMeshReport* report = nullptr);

}  // namespace foxi
