// Meshing a PLC with CGAL's Mesh_3 (issue 6, item 3): the PLC's facets become the patches of a
// polyhedral-complex domain (one per facet marker and pair of cells on its sides, so multiple materials
// and interfaces are kept), patch borders and sharp facet edges are protected features (boxes stay
// boxes; a faceted cylinder's wall is resampled within facet_distance), then
// Delaunay refinement with facet/cell size and radius-edge criteria, then sliver exudation (and
// optionally perturbation).
//
// The result is a subset of a regular (weighted Delaunay) triangulation: the tets inside the domain.
// Every node gets its weight in Mesh::weight (the regular triangulation's point weight, a squared
// radius, the convention of delaunay.hpp): with them the mesh passes the weighted Delaunay certificate
// and the viewer orders it exactly by orthosphere power. The weights of vertices outside the exported
// subset are dropped with those vertices; they bound nothing that is drawn.
//
// Regions: each cell of the PLC (component of space minus the facets) takes the id of the first region
// seed inside it; enclosed cells with no seed are region 0; the unbounded cell and cells holding a
// volume hole point are not meshed. Boundary triangles carry their facet's marker. Facets with the same
// cell on both sides (a membrane inside one region) are not kept.
#pragma once

#include <cstddef>

#include "foxi/mesher/tetgen_mesher.hpp"  // MesherError
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

struct CgalMeshParams {
  // Largest tet circumradius (PLC units); 0: a twentieth of the bounding box diagonal. A region seed's
  // max_volume lowers it inside that region (the circumradius of a regular tet of that volume).
  double max_size = 0;
  double facet_size = 0;       // largest surface Delaunay ball radius; 0: max_size
  double edge_size = 0;        // largest protecting ball along facet edges; 0: facet_size
  // Largest distance of a boundary triangle's circumcentre from the PLC surface: it bounds how far a
  // curved-looking surface (a faceted cylinder) is cut inside; 0: facet_size / 20.
  double facet_distance = 0;
  // Facet edges that are not patch borders are protected features where the facets turn by more than
  // this (degrees between normals); 60 keeps boxes sharp and lets faceted cylinders be resampled.
  double feature_angle = 60;
  double facet_angle = 25;     // lower bound of boundary triangle angles (degrees, at most 30)
  double radius_edge = 2;      // circumradius / shortest edge bound of tets (>= 2 guarantees termination)
  bool exude = true;           // sliver exudation (weight pumping: keeps the triangulation regular)
  bool perturb = false;        // sliver perturbation before exudation (moves vertices)
  // Perturbation and exudation work on tets whose smallest dihedral angle is below this (degrees); 0
  // (CGAL's default) has them improve the worst tet for as long as they can, which on some PLCs (the
  // via example) does not end in minutes.
  double sliver_bound = 12;
  double optimiser_seconds = 60;  // time limit of each of perturb / exude; 0: none
  // Asked about every 100 ms while Mesh_3 runs in its child process (fraction -1: unknown);
  // returning false kills it and mesh_plc_cgal throws MesherError (code -1, "meshing cancelled").
  ProgressFn progress;
};

struct CgalMeshReport {
  std::size_t input_points = 0;
  std::size_t facet_triangles = 0;  // triangles of the PLC's facets handed to CGAL
  std::size_t patches = 0;          // surface patches of the domain
  std::size_t cells = 0;            // meshed cells (regions of space) of the PLC
  double max_size = 0;              // the size bounds used
  double facet_size = 0, edge_size = 0, facet_distance = 0;
  double seconds = 0;
};

// Throws MesherError: code 10 for a PLC it cannot read (see plc_surface), 2 for a CGAL failure (the
// message says which), -1 when cancelled.
Mesh mesh_plc_cgal(const Plc& plc, const CgalMeshParams& params = {}, CgalMeshReport* report = nullptr);

}  // namespace foxi
