// Internal to the mesher: Delaunay refinement done by foxi for PLCs with thin layers (see
// conforming.hpp and thin_layers.hpp), called by mesh_conforming.
#pragma once

#include <vector>

#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/thin_layers.hpp"

namespace foxi::detail {

// Rounds of: TetGen (-pO0, no refinement of its own) on `current` (the PLC plus the points added so
// far, interior points as isolated PLC points); the exact certificate; then the constraint triangles
// that non-Delaunay tets need split (as mesh_conforming does), and for each tet outside the layers
// over the radius-edge, dihedral or size bound its circumcentre, or the constraint triangles that
// centre encroaches; tets in a layer over the size bound get a pair of mirrored points on the
// layer's faces. Points on a layer's face are always mirrored onto its other face, and a layer's side
// walls are never split. Stops when the mesh is certified and no tet is over a bound, when nothing
// can be added, or after conforming.max_layer_iterations rounds; fills `rep` and returns the last mesh.
// With `first_mesh`, that mesh (of `current`) is round 0's instead of TetGen's: the conforming loop
// hands over the last mesh it could make when TetGen failed on its refined PLC.
Mesh refine_with_thin_layers(const MeshParams& params, const ConformingParams& conforming,
                             const std::vector<ThinLayer>& layers, Plc& current, ConformingReport& rep,
                             const Mesh* first_mesh = nullptr);

}  // namespace foxi::detail
