// The painter's field colours (RenderParams::field, field_paint.hpp): the paint's checks, and the
// per-pixel colour of graded facets (flat field colours go through the faces' flat shade, see
// face_shade).
#include "raster_impl.hpp"

namespace foxi {

void TetRasterizer::Impl::setup_field() {
  if ((field = params.field.get()) == nullptr) return;
  const MeshView& m = *mesh;
  if (field->graded ? field->corner_position.size() != m.tet.size()
                    : field->tet_color.size() != m.tet_count())
    throw std::invalid_argument(
        "render: the field paint has " +
        std::to_string(field->graded ? field->corner_position.size() : field->tet_color.size()) +
        " values for a mesh of " + std::to_string(m.tet_count()) + " tets");
  if (!(field->shade_min >= 0 && field->shade_min <= 1))
    throw std::invalid_argument("render: the field paint's shade_min must be in [0, 1]");
  for (int i = 0; i < 256; ++i) {
    const std::uint32_t entry = color_map_entry(field->scale.map, i);
    field_lut[i] = entry | 0xff000000u;
  }
}

// The entry of the interpolated scale position (the NaN colour for no value) in the pixel's shade
// (the face's Lambert intensity and the edge darkening, see shade_of), s.
std::uint32_t TetRasterizer::Impl::graded_color(const FaceSetup& fs, int x, int y, double d,
                                                std::uint8_t& s) const {
  const double dx = x + 0.5 - fs.gx0, dy = y + 0.5 - fs.gy0;
  double t = fs.g0 + fs.ga * dx + fs.gb * dy;
  if (proj.perspective) t /= fs.h0 + fs.ha * dx + fs.hb * dy;
  s = d < params.edge_width ? shade_of(fs.level, edge_base + edge_slope * std::max(0.0, d)) : fs.shade;
  const std::uint32_t base =
      std::isnan(t) ? field->scale.nan_color : field_lut[int(std::clamp(t * 256, 0.0, 255.0))];
  return shade_color(base, s);
}

void TetRasterizer::Impl::neighbour_positions(std::uint32_t nb, const std::uint32_t* tv, float out[4]) const {
  const std::uint32_t* nv = &mesh->tet[4 * std::size_t(nb)];
  const float* pos = &field->corner_position[4 * std::size_t(nb)];
  for (int j = 0; j < 4; ++j) {
    out[j] = 0;
    for (int k = 0; k < 4; ++k)
      if (nv[k] == tv[j]) out[j] = pos[k];
  }
}

void TetRasterizer::Impl::graded_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const {
  std::uint32_t* rgba = color_row(y);
  std::uint32_t* id = &fb.id[std::size_t(y) * std::size_t(fb.width)];
  std::uint8_t* shade = &fb.shade[std::size_t(y) * std::size_t(fb.width)];
  for (int x = lo; x <= hi; ++x) {
    std::int64_t e[4];
    for (int k = 0; k < 4; ++k) e[k] = fs.ea[k] * x + fs.eb[k] * y + fs.ec[k];
    rgba[x] = graded_color(fs, x, y, nearest_edge(fs, e[0], e[1], e[2], e[3]), shade[x]);
    id[x] = fs.tet;
  }
}

}  // namespace foxi
