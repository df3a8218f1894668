// Model pictures (model_picture.hpp): moved from the CLI so that foxi model show and the workbench
// draw the same pixels.
#include "foxi/viz/model_picture.hpp"

#include <algorithm>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/palette.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi {

ModelScene::ModelScene(const Mesh& mesh, ModelView v) : source(&mesh), view(v) {
  double lo[3], hi[3];
  mesh_bounds(mesh, lo, hi);
  const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (view == ModelView::exploded) exploded = exploded_mesh(mesh, 0.12 * size);
  if (view == ModelView::cut) {
    const double mid = 0.5 * (lo[1] + hi[1]);
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      double cy = 0;
      for (int k = 0; k < 4; ++k) cy += mesh.xyz[3 * std::size_t{mesh.tet[4 * t + k]} + 1];
      if (cy >= 4 * mid) subset.push_back(static_cast<std::uint32_t>(t));
    }
  }
}

std::vector<std::uint32_t> model_region_colors(const Mesh& mesh) {
  std::int32_t top = 0;
  for (const Region& r : mesh.regions) top = std::max(top, r.id);
  std::vector<std::uint32_t> out(static_cast<std::size_t>(top) + 1, pack_rgba(128, 128, 128));
  for (const Region& r : mesh.regions)
    if (r.id > 0 && r.material < mesh.materials.size())
      out[static_cast<std::size_t>(r.id)] = material_color(mesh.materials[r.material].name, r.material);
  return out;
}

ModelPictureReport draw_model_picture(const ModelScene& scene,
                                      const std::vector<std::uint32_t>& region_colors, Framebuffer& fb,
                                      std::shared_ptr<const FieldPaint> field) {
  const Mesh& mesh = scene.mesh();
  RenderParams rp;
  rp.region_colors = region_colors;
  rp.edge_darkness = 0.35;  // the parts' colours first, the mesh second
  rp.field = std::move(field);
  double lo[3], hi[3];
  mesh_bounds(mesh, lo, hi);
  // flat structures (packages) fill the picture better seen from lower down
  const double dir[3] = {-0.55, 1, -0.55}, up[3] = {0, 0, 1};
  const Camera camera = fit_camera(lo, hi, dir, up, true, 30, double(fb.width) / fb.height, 0.95);
  const SphereTable table = compute_spheres(mesh);
  PictureParams pp;
  pp.render = rp;
  pp.subset = scene.subset;
  if (scene.view == ModelView::interior) {
    pp.stop_fraction = 0.6;
    if (!pp.render.field) pp.render.shrink = 0.85;
  }
  const PictureReport report = draw_picture(mesh, table, camera, fb, pp);
  return {report.tets_drawn, report.delaunay};
}

}  // namespace foxi
