// Carrying a source's fields onto a foxi mesh.
//
// By id: the source describes the same mesh. Position-keyed sources (.vtu, .vtk, .msh, .pvd) must
// have the target's node and tet counts, node coordinates equal within the tolerance and the same
// tets; node-id sources (.frd, CSV) give node k (1-based) to target node k - 1 (an id beyond the
// target is an error; nodes the source lacks get NaN, counted), with the coordinates checked where
// the source has them; cell-id CSVs give tet k to target tet k - 1; coordinate CSVs give each target
// node the source point at its coordinates (within the tolerance; no point there: NaN, counted).
//
// By location: each target node is located in the source's tets through a uniform grid over them
// (not a scan) and gets the linear (barycentric) interpolation of the source's node values; a cell
// field takes the value of the source tet holding the target tet's centroid. Where both meshes have
// regions (tet_region not empty), a target node looks only in source tets of the regions of the
// target tets around it, and a centroid only in its own tet's region, so a value near an interface
// never comes from the other material. A point in no such tet is "outside": it gets NaN, or with
// Outside::nearest the value of the nearest source node (cell fields: the nearest source centroid)
// of an allowed region.
//
// Never a silent mismatch: the counts above, the fields asked for, and the unit of a field the target
// already has under the same name are checked (FieldError). NaN source values stay NaN and are counted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/fields/field_source.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

enum class MatchBy : std::uint8_t { id, location };
enum class Outside : std::uint8_t { nan, nearest };

struct TransferParams {
  MatchBy by = MatchBy::location;
  Outside outside = Outside::nan;
  std::vector<std::string> names;  // the fields to carry; empty = all of the source's
  // By id: coordinates agree when they differ by at most this times the target's bounding-box
  // diagonal (a .frd prints 6 significant digits).
  double coordinate_tolerance = 1e-5;
  // By location: a point is in a tet when no barycentric coordinate is below -this (points on a
  // shared face or on the boundary are inside despite rounding).
  double barycentric_tolerance = 1e-9;
  // By location: keep values inside their region where both meshes have regions (a target region
  // id the source lacks is then an error); false ignores regions.
  bool match_regions = true;
  unsigned threads = 0;  // 0: all the hardware has
};

struct TransferReport {
  std::vector<Field> fields;  // over the target's nodes or tets, the source's steps
  std::size_t target_nodes = 0, target_cells = 0;
  std::size_t nodes_outside = 0;  // target nodes located in no source tet (by location)
  std::size_t cells_outside = 0;  // target centroids located in no source tet (by location)
  std::size_t nodes_missing = 0;  // target nodes the source gave no value (by id)
  std::size_t cells_missing = 0;
  std::size_t nan_values = 0;  // NaN values in `fields`, over all components and steps
};

// The fields of `source` (all, or params.names) over `target`. Throws FieldError.
FOXI_API TransferReport transfer_fields(const FieldSource& source, const Mesh& target,
                                        const TransferParams& params = {});

// The tet holding each point (3 coordinates each) in `mesh`'s tets located through the same grid:
// tet index and barycentric coordinates, kNone where it lies in no tet. For tests and benchmarks.
struct PointLocation {
  std::vector<std::uint32_t> tet;
  std::vector<double> bary;  // 4 per point
};
FOXI_API PointLocation locate_points(const Mesh& mesh, const std::vector<double>& xyz,
                                     double barycentric_tolerance = 1e-9);

}  // namespace foxi
