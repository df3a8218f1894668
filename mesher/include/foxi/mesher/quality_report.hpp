// The quality report of a conforming mesh (issue 6, item 5): shape (radius-edge ratio, minimum
// dihedral angle per tet as a histogram, volumes, slivers), size per region, the Steiner points and
// iterations of the conforming refinement, the Delaunay certificate and the times. A library result:
// format_quality_report() gives the text the CLI prints.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/quality.hpp"

namespace foxi {

struct QualityReportParams {
  double sliver_angle_deg = 5;  // a tet whose smallest dihedral angle is below this is a sliver
};

struct RegionSize {
  std::int32_t id = 0;
  std::string name;
  std::size_t tets = 0;
  double volume = 0;  // m^3
};

struct MeshQualityReport {
  std::size_t nodes = 0, tets = 0, boundary_triangles = 0;
  QualitySummary shape;  // radius-edge, minimum dihedral, volume statistics (quality.hpp)
  double sliver_angle_deg = 5;
  std::size_t slivers = 0;  // tets with a minimum dihedral below sliver_angle_deg (flat ones too)
  // Tets by their minimum dihedral angle, 5-degree bins: [0,5), [5,10), ... [70,75) (the regular
  // tet's 70.53 falls in the last).
  std::array<std::size_t, 15> min_dihedral_histogram{};
  std::vector<RegionSize> regions;  // ascending id
  // Conforming refinement (conforming.hpp).
  std::size_t tetgen_steiner_points = 0;  // added by TetGen in the last run (quality, volume, recovery)
  std::size_t conforming_points = 0;      // added for the Delaunay property
  double conforming_overhead = 0;         // conforming_points / points of the first -O0 mesh
  std::size_t iterations = 0;
  // Thin layers (thin_layers.hpp), exempt from the quality bounds; the shape outside them.
  std::size_t thin_layers = 0, thin_layer_tets = 0;
  double max_radius_edge_outside_layers = 0;
  std::size_t quality_points = 0;    // added by foxi's own refinement (thin-layer meshes)
  std::size_t quality_unmet = 0;     // tets outside the layers still over a bound
  double radius_edge_bound = 0;      // without layers (ConformingReport): the bound, 0: none,
  std::size_t over_radius_edge = 0;  // and the tets over it
  std::size_t first_mesh_violations = 0;
  bool delaunay = false;       // the exact certificate of the final mesh
  bool tetgen_failed = false;  // refinement stopped where TetGen failed (conforming.hpp)
  std::size_t violating_tets = 0;
  // Flat tets (ConformingParams::flat_tet_bound): removed by points inside them, and left.
  std::size_t flat_tets_removed = 0, flat_points = 0, flat_tets = 0;
  double mesh_seconds = 0, certificate_seconds = 0;
};

FOXI_API MeshQualityReport mesh_quality_report(const Mesh& mesh, const ConformingReport& conforming,
                                               const QualityReportParams& params = {});

// Several lines of text, no trailing newline.
FOXI_API std::string format_quality_report(const MeshQualityReport& report);

}  // namespace foxi
