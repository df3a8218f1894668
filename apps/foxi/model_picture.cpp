// Model pictures: material colours, a cut-away view, the painter (model_picture.hpp).
#include "model_picture.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>

#include "field_options.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/palette.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi::cli {

ModelPicture render_model_picture(const MeshedModel& m, const std::string& path,
                                  const ModelPictureParams& p) {
  double lo[3], hi[3];
  mesh_bounds(m.mesh, lo, hi);
  const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const Mesh exploded = p.view == ModelView::exploded ? exploded_mesh(m.mesh, 0.12 * size) : Mesh{};
  const Mesh& mesh = p.view == ModelView::exploded ? exploded : m.mesh;
  ModelPicture out;
  RenderParams rp;
  rp.region_colors.assign(m.model.parts.size() + 1, pack_rgba(128, 128, 128));
  for (std::size_t i = 0; i < m.model.parts.size(); ++i) {
    std::size_t index = 0;
    for (std::size_t k = 0; k < m.model.materials.size(); ++k)
      if (m.model.materials[k].name == m.model.parts[i].material) index = k;
    out.part_color.push_back(material_color(m.model.parts[i].material, index));
    rp.region_colors[i + 1] = out.part_color.back();
  }
  rp.edge_darkness = 0.35;  // the parts' colours first, the mesh second

  mesh_bounds(mesh, lo, hi);
  std::vector<std::uint32_t> subset;
  if (p.view == ModelView::cut) {
    const double mid = 0.5 * (lo[1] + hi[1]);
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      double cy = 0;
      for (int v = 0; v < 4; ++v) cy += mesh.xyz[3 * std::size_t{mesh.tet[4 * t + v]} + 1];
      if (cy >= 4 * mid) subset.push_back(static_cast<std::uint32_t>(t));
    }
  }
  // A field: graded facets and a legend in a panel at the right; the mesh drawn in the rest.
  FieldPicture field;
  std::unique_ptr<TextRenderer> text;
  int width = p.width, panel = 0;
  if (!p.field.empty()) {
    FieldOptions fo;
    fo.spec = p.field;
    fo.graded = true;
    field = resolve_field(fo, mesh, subset, path);
    rp.field = field.paint;
    text = std::make_unique<TextRenderer>(find_font_file());
    panel = legend_panel(*text, field, p.width, p.height);
    width = std::max(64, p.width - panel);
    out.field_lo = field.legend.unit.to_display(field.legend.scale.lo);
    out.field_hi = field.legend.unit.to_display(field.legend.scale.hi);
    out.field_unit = field.legend.unit.symbol;
  }
  // flat structures (packages) fill the picture better seen from lower down
  const double dir[3] = {-0.55, 1, -0.55}, up[3] = {0, 0, 1};
  const Camera camera = fit_camera(lo, hi, dir, up, true, 30, double(width) / p.height, 0.95);
  const SphereTable table = compute_spheres(mesh);
  PictureParams pp;
  pp.render = rp;
  pp.subset = subset;
  if (p.view == ModelView::interior) {
    pp.stop_fraction = 0.6;
    if (!rp.field) pp.render.shrink = 0.85;
  }
  Framebuffer fb(width, p.height);
  const PictureReport report = draw_picture(mesh, table, camera, fb, pp);
  out.delaunay = report.delaunay;
  write_png(path, text ? with_legend(fb, *text, field, panel) : fb);
  out.tets_drawn = report.tets_drawn;
  return out;
}

void print_legend(const MeshedModel& m, const ModelPicture& picture) {
  for (std::size_t i = 0; i < m.model.parts.size(); ++i) {
    const std::uint32_t c = picture.part_color[i];
    std::printf("  %-16s %-16s #%02x%02x%02x\n", m.model.parts[i].name.c_str(),
                m.model.parts[i].material.c_str(), c & 255u, (c >> 8) & 255u, (c >> 16) & 255u);
  }
}

}  // namespace foxi::cli
