// [mesh] controls -> TetGen volume bounds (model_mesh_params.hpp).
#include "foxi/mesher/model_mesh_params.hpp"

#include "foxi/mesher/size_field.hpp"

namespace foxi {

ModelMeshParams mesh_params_from_model(const Model& model, Plc& plc, double default_size) {
  ModelMeshParams out;
  const ModelMeshControls& mc = model.mesh;
  const double size = mc.max_size > 0 ? mc.max_size : default_size;
  if (size > 0) out.params.max_volume = regular_tet_volume(size);
  if (mc.quality >= 0) out.params.radius_edge = mc.quality;
  out.params.min_dihedral = mc.min_dihedral;
  for (const PartSize& ps : mc.part_sizes)
    for (std::size_t i = 0; i < model.parts.size(); ++i)
      if (model.parts[i].name == ps.part)
        for (RegionSeed& seed : plc.regions)
          if (seed.id == static_cast<std::int32_t>(i + 1)) seed.max_volume = regular_tet_volume(ps.max_size);
  out.ignored_refine_boxes = mc.refine.size();
  return out;
}

SizeControls size_controls_from_model(const Model& model) {
  SizeControls controls;
  controls.max_size = model.mesh.max_size;
  for (const PartSize& ps : model.mesh.part_sizes)
    for (std::size_t i = 0; i < model.parts.size(); ++i)
      if (model.parts[i].name == ps.part) {
        controls.region_ids.push_back(static_cast<std::int32_t>(i + 1));
        controls.region_sizes.push_back(ps.max_size);
      }
  for (const RefineBox& b : model.mesh.refine) {
    RefinementBox box;
    for (int k = 0; k < 3; ++k) {
      box.lo[k] = b.lo[k];
      box.hi[k] = b.hi[k];
    }
    box.size = b.max_size;
    controls.boxes.push_back(box);
  }
  return controls;
}

}  // namespace foxi
