// A model's parts -> one conforming piecewise linear complex (PLC) for the mesher.
//
// A later part (in file order) carves its volume out of earlier ones, whatever the overlap (nested,
// partial, crossing); parts may touch, nest or be disconnected; touching parts share one set of
// facets (the interface "A/B", A earlier); each part is a region (id = index + 1).
//
// When every part is a set of vertical prisms (boxes, layers, cylinders, extrusions, arrays of
// them), space is cut into z slabs at every prism's top and bottom; in each slab a point belongs to
// the last part whose prism covers it. In each slab the footprint edges, split where they meet (CGAL
// surface sweep, exact), form a planar subdivision; horizontal facets are emitted where the owner
// changes across a level, vertical facets where it changes across an arrangement edge, and each
// facet carries every vertex that its neighbours put on its boundary, so shared areas are one set of
// facets. Footprints are simple polygons, convex or not.
//
// When any part is not a prism (a ball, an STL surface), every part becomes a closed triangle
// surface and the parts are carved and joined with CGAL's corefinement booleans in exact arithmetic
// (structure_solids.cpp): the facets are triangles, horizontal ones facing up or down are "P.top" /
// "P.bottom", all others "P.side"; region seeds are points strictly inside every connected piece.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

struct Structure {
  Plc plc;                                  // metres; region id of parts[i] is i + 1
  std::vector<double> part_volume;          // 1 per part, after carving (m^3)
  std::vector<std::string> boundary_names;  // marker m (1-based) is boundary_names[m - 1]
  std::vector<double> boundary_area;        // 1 per marker (m^2)
  // 1 per facet: the marker it had before the [surfaces] selectors took it (its part face "P.top",
  // ... or interface "A/B"), so that a selected facet's part stays known (diagnostics.hpp).
  std::vector<std::int32_t> facet_own_marker;
};

// Builds the PLC of `model`. Boundary names: "PART.top", "PART.bottom", "PART.side" for outer faces,
// "A/B" (A earlier in the file) for the interface of two parts. Throws IoError (the model file, the
// line of the part, its name) for a part carved away entirely, a part surface that is not closed,
// not consistently oriented or intersects itself (also two items of one array that overlap), and a
// carving that leaves a non-manifold solid. Then the model's [surfaces] get their own markers and its
// conditions are checked (surfaces.hpp).
// `progress` (may be empty) is called by the triangle-surface path with the stages "surfaces",
// "carve", "conform" and "seeds"; returning false cancels with StructureCancelled.
struct FOXI_API StructureCancelled : std::runtime_error, Cancelled {
  StructureCancelled() : std::runtime_error("building the structure was cancelled") {}
};
FOXI_API Structure build_structure(const Model& model, const ProgressFn& progress = {});

// Names a mesh of the structure's PLC: region names and materials from the parts, boundary names
// from the markers. Regions and boundaries the mesh lacks are added.
FOXI_API void name_mesh(const Model& model, const Structure& structure, Mesh& mesh);

}  // namespace foxi
