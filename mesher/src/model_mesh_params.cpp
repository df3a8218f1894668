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

}  // namespace foxi
