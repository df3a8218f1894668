// Thin layers of a PLC (issue 6: a 20 um die-attach under a 10 mm die). A radius-edge bound cannot hold
// in a layer much thinner than it is wide unless its tets are about as wide as it is thick, which fills
// a 10 mm x 10 mm x 20 um layer with ~10^6 tets. So the quality bounds (radius-edge ratio, minimum
// dihedral angle) are not applied to tets lying wholly inside a thin layer: there the mesh stays
// anisotropic (flat tets spanning the layer, still Delaunay and still size-bounded); everywhere else the
// bounds hold as asked. The quality report counts the exempt tets.
//
// A thin layer is found from two parallel planar facets whose projections overlap in a rectangle at
// least `min_aspect` times wider, in both directions, than the facets are apart: the slab between
// them, clipped to that rectangle.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"

namespace foxi {

struct FOXI_API ThinLayer {
  std::array<double, 3> normal{};  // unit
  std::array<double, 3> u{}, v{};  // unit, in the layer's plane; (u, v, normal) right-handed
  double lo = 0, hi = 0;           // the slab: lo <= normal . p <= hi
  double u_lo = 0, u_hi = 0;       // the overlap rectangle, in u . p and v . p
  double v_lo = 0, v_hi = 0;
  double tolerance = 0;  // slack on every bound (metres)

  bool contains(const double* p) const;
};

// Default aspect: layers 100 times wider than thick are exempt (TetGen would put ~(100/1)^2 x 6 tets
// of the thickness in one; a 1 mm substrate 14 mm wide or a 0.8 mm ceramic 30 mm wide is not thin).
inline constexpr double kThinLayerAspect = 100;

// Default area: a layer is exempt only when TetGen's own refinement would fill it with too many tets.
// It puts about 3.3 tets per thickness squared of the layer's area, whatever the radius-edge bound
// (measured: 0.8 M tets in a 10 x 10 mm x 20 um die attach at -q1.414, 218 k in a 30 x 22 x 0.1 mm
// solder at -q3). Under 1e5 thicknesses squared (~330 k tets) TetGen's mesh of the layer is affordable,
// the quality bounds then hold everywhere, and it took fewer points and half the time of foxi's
// layer path on that solder.
inline constexpr double kThinLayerMinArea = 1e5;

// The thin layers between pairs of parallel facets (see above) whose overlap rectangle's area is at
// least `min_area` times the thickness squared. A layer that lies inside a larger one is dropped.
// Facets whose polygons are degenerate are ignored. O(facets^2).
FOXI_API std::vector<ThinLayer> find_thin_layers(const Plc& plc, double min_aspect = kThinLayerAspect,
                                                 double min_area = kThinLayerMinArea);

// Whether all four vertices of tet t lie in one of the layers.
FOXI_API bool tet_in_thin_layer(const Mesh& mesh, std::size_t t, const std::vector<ThinLayer>& layers);

}  // namespace foxi
