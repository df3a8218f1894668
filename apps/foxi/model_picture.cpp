// Model pictures: material colours, a cut-away view, the painter (model_picture.hpp).
#include "model_picture.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>

#include "field_options.hpp"
#include "foxi/viz/palette.hpp"
#include "foxi/viz/png.hpp"

namespace foxi::cli {

ModelPicture render_model_picture(const MeshedModel& m, const std::string& path,
                                  const ModelPictureParams& p) {
  const ModelScene scene(m.mesh, p.view);
  ModelPicture out;
  const std::vector<std::uint32_t> colors = model_region_colors(m.mesh);
  for (std::size_t i = 0; i < m.model.parts.size(); ++i)
    out.part_color.push_back(i + 1 < colors.size() ? colors[i + 1] : pack_rgba(128, 128, 128));
  // A field: graded facets and a legend in a panel at the right; the mesh drawn in the rest.
  FieldPicture field;
  std::unique_ptr<TextRenderer> text;
  int width = p.width, panel = 0;
  if (!p.field.empty()) {
    FieldOptions fo;
    fo.spec = p.field;
    fo.graded = true;
    field = resolve_field(fo, scene.mesh(), scene.subset, path);
    text = std::make_unique<TextRenderer>(find_font_file());
    panel = legend_panel(*text, field, p.width, p.height);
    width = std::max(64, p.width - panel);
    out.field_lo = field.legend.unit.to_display(field.legend.scale.lo);
    out.field_hi = field.legend.unit.to_display(field.legend.scale.hi);
    out.field_unit = field.legend.unit.symbol;
  }
  Framebuffer fb(width, p.height);
  const ModelPictureReport report = draw_model_picture(scene, colors, fb, field.paint);
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
