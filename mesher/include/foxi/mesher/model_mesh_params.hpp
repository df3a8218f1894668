// A model's mesh controls ([mesh], foxi/model/conditions.hpp) as TetGen parameters, until the mesher
// takes a size field: TetGen bounds tet volumes, so an edge length a becomes the volume of the
// regular tet of edge a, a^3 / (6 sqrt 2).
#pragma once

#include "foxi/api.hpp"
#include "foxi/mesher/size_field.hpp"  // regular_tet_volume
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"

namespace foxi {

// MeshParams with max_volume from model.mesh.max_size (or `default_size` when the model gives none;
// 0: no limit), radius_edge from model.mesh.quality (when given) and min_dihedral; the region seeds in `plc`
// of parts with their own size get that part's volume bound. Refinement boxes are not applied here (TetGen
// has no box sizes); the result's count of ignored boxes is `ignored_refine_boxes`.
struct ModelMeshParams {
  MeshParams params;
  std::size_t ignored_refine_boxes = 0;
};
FOXI_API ModelMeshParams mesh_params_from_model(const Model& model, Plc& plc, double default_size = 0);

// A model's [mesh] controls as the mesher's size controls (size_field.hpp): the global size, each
// sized part's region (id = part index + 1) and the refinement boxes. Quality and dihedral bounds are
// not size controls: take them from mesh_params_from_model or model.mesh.
FOXI_API SizeControls size_controls_from_model(const Model& model);

}  // namespace foxi
