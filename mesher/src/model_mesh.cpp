// A model file to a certified, named mesh (model_mesh.hpp).
#include "foxi/mesher/model_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/size_field.hpp"

namespace foxi {

namespace {

std::string tet_limit_reason(double estimate, double limit) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "the mesh would have about %.3g tets (from the volumes and the size bounds), over the limit "
                "of %.0f; use a larger size, or raise the limit",
                estimate, limit);
  return buf;
}

}  // namespace

TetLimitError::TetLimitError(const std::string& file, double estimate, double limit)
    : IoError(file, 0, IoError::kNoOffset, tet_limit_reason(estimate, limit)),
      estimate_(estimate),
      limit_(limit) {}

void check_tet_estimate(const std::string& file, const Plc& plc, const MeshParams& params,
                        std::span<const double> region_volume, double max_tets) {
  const double est = estimate_tet_count(plc, params, region_volume);
  if (est > max_tets) throw TetLimitError(file, est, max_tets);
}

MeshedModel mesh_model(const std::filesystem::path& path, std::span<const ParameterOverride> overrides,
                       const ModelMeshOptions& options) {
  const std::string file = path.string();
  MeshedModel m;
  m.model = load_model(path, overrides, options.override_origin);
  if (options.physics) check_physics(m.model, *options.physics);
  m.structure = build_structure(m.model);
  Plc plc = m.structure.plc;
  // coarse (a picture of the parts): no sizes, no quality refinement and no conforming rounds, so the
  // tets follow the PLC's points and TetGen's boundary recovery alone; the picture takes the power
  // order where that mesh is Delaunay, else a depth buffer (picture.hpp). With the quality
  // bounds, power_module's thin solders took 612k tets and 44 s; the conforming rounds alone, 185k
  // tets and 90 s; this way 377 tets in 0.1 s.
  Model controls = m.model;
  if (options.coarse)
    controls.mesh = {.max_size = 0, .quality = 0, .min_dihedral = 0, .part_sizes = {}, .refine = {}};
  const double size_scale = options.size_scale;
  if (size_scale != 1 && !options.coarse) {
    if (controls.mesh.max_size <= 0) {
      double d2 = 0;
      for (int i = 0; i < 3; ++i) {
        double lo = INFINITY, hi = -INFINITY;
        for (std::size_t p = 0; p < plc.point_count(); ++p) {
          lo = std::min(lo, plc.points[3 * p + i]);
          hi = std::max(hi, plc.points[3 * p + i]);
        }
        d2 += (hi - lo) * (hi - lo);
      }
      controls.mesh.max_size = std::sqrt(d2) / 10;
    }
    controls.mesh.max_size *= size_scale;
    for (PartSize& p : controls.mesh.part_sizes) p.max_size *= size_scale;
    for (RefineBox& b : controls.mesh.refine) b.max_size *= size_scale;
  }
  const ModelMeshParams mp = mesh_params_from_model(controls, plc);
  MeshParams params = mp.params;
  params.progress = options.progress;
  check_tet_estimate(file, plc, params, m.structure.part_volume, options.max_tets);
  // The model's refinement boxes as a size field, as `foxi mesh` applies them.
  SizeField boxes;
  if (!controls.mesh.refine.empty()) {
    boxes = box_size_field(plc, params, size_controls_from_model(controls));
    params.size_field = &boxes;
    check_tet_estimate(file, plc, params, m.structure.part_volume, options.max_tets);
  }
  // The conforming Delaunay path (thin layers included), so that the mesh the solver gets is
  // certified and the viewer's order is exact.
  if (options.coarse) {
    m.mesh = mesh_plc(plc, params, &m.conforming.tetgen);
  } else {
    m.mesh = mesh_conforming(plc, params, {}, &m.conforming);
  }
  m.report = m.conforming.tetgen;
  name_mesh(m.model, m.structure, m.mesh);
  return m;
}

}  // namespace foxi
