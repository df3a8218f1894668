// Tet shape quality: radius-edge ratio (circumradius / shortest edge; 0.612 for the regular tet) and
// minimum dihedral angle (degrees; 70.53 for the regular tet), and volumes.
#pragma once

#include <cstddef>
#include <span>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

struct TetQuality {
  double volume = 0;            // signed, m^3
  double radius_edge = 0;       // +inf for a flat tet
  double min_dihedral_deg = 0;  // 0 for a flat tet
};

// Each p points to 3 doubles. Exactly zero volume (in double) counts as flat.
FOXI_API TetQuality tet_quality(const double* p0, const double* p1, const double* p2, const double* p3);

struct Stat {
  double min = 0, max = 0, mean = 0;
};

struct QualitySummary {
  std::size_t tets = 0;
  double total_volume = 0;  // sum of |volume|
  Stat volume, radius_edge, min_dihedral_deg;
  std::size_t slivers = 0;  // min dihedral below 5 degrees
};

// Over every tet whose indices are in range (others skipped; see validate()). Volume statistics are
// signed; a flat tet makes radius_edge.max and .mean +inf.
FOXI_API QualitySummary summarize_quality(const Mesh& mesh);

}  // namespace foxi
