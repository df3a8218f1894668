// Recolouring a drawn picture through its id buffer (issue 17: another field or colour map without
// drawing the mesh again; TetRasterizer::recolor). Two ways, each giving every pixel exactly the
// colour a fresh draw with the new paint would:
// - flat colours (a flat field paint, or region colours) of the same shading band (shade_min, or
//   ambient for regions) as the picture's: a pixel's colour is shade_color(its tet's base colour, its
//   shade byte) (see shade_of), so one pass over the pixels, a lookup each (a few ms at 1920x1080);
// - otherwise (graded facets, another shading band): the id buffer says which tet each pixel shows;
//   rasterizing those tets' front faces again, and writing only the pixels that show them, with the
//   same face setup (shade, edge lines, graded planes) and per-pixel colour functions as drawing.
//   Hidden tets, the bulk of a 1M-tet view, are never looked at.
#include "raster_impl.hpp"

namespace foxi {

// Tet t's front faces, rasterized into the rows of `rows` in recolouring mode (shade_row).
void TetRasterizer::Impl::recolor_tet(Framebuffer& fb, const Rows& rows, std::uint32_t t) {
  TetCorners k;
  if (!load_corners(t, k)) return;
  const std::int64_t* Y = k.Y;
  const std::uint8_t* st = k.st;
  if (int(st[0]) + st[1] + st[2] + st[3] == 0) {
    const std::int64_t miny = std::min({Y[0], Y[1], Y[2], Y[3]}), maxy = std::max({Y[0], Y[1], Y[2], Y[3]});
    const std::int64_t y0 = std::max<std::int64_t>(0, -floor_div(-(miny - kHalf), kOne));
    const std::int64_t y1 = std::min<std::int64_t>(fb.height - 1, floor_div(maxy - kHalf, kOne));
    if (!rows.any(int(y0), int(y1))) return;
  }
  PolyVertex poly[4];
  for (int f = 0; f < 4; ++f) {
    bool clipped = false;
    const int n = face_polygon(k, f, false, poly, &clipped);
    if (n == 0) continue;
    const auto& face = kFace[f];
    const double* v[3] = {k.c[face[0]], k.c[face[1]], k.c[face[2]]};
    const std::uint32_t node[3] = {k.tv[face[0]], k.tv[face[1]], k.tv[face[2]]};
    FaceSetup fs;
    setup_face(fs, t, v, node, poly, n);
    recolor_polygon(fb, rows, fs, poly, n);
  }
}

// The first way: each pixel showing a tet gets shade_color(that tet's base colour, its shade).
void TetRasterizer::Impl::recolor_by_shade(Framebuffer& fb) {
  const std::size_t tc = mesh->tet_count();
  const std::uint32_t* tet_color = field != nullptr ? field->tet_color.data() : nullptr;
  auto base_of = [&](std::uint32_t t) {
    if (tet_color != nullptr) return tet_color[t];
    const std::int32_t region = mesh->region_of(t);  // as face_shade
    return region >= 0 && std::size_t(region) < params.region_colors.size()
               ? params.region_colors[std::size_t(region)]
               : region_color(region);
  };
  // Bands of rows, one per thread (the pixels are independent).
  const int count = fb.height < 64 ? 1 : std::max(1, params.threads);
  run_parts(count, [&](int part) {
    const std::size_t begin =
        std::size_t(fb.height) * std::size_t(part) / std::size_t(count) * std::size_t(fb.width);
    const std::size_t end =
        std::size_t(fb.height) * std::size_t(part + 1) / std::size_t(count) * std::size_t(fb.width);
    const std::uint32_t* id = fb.id.data();
    const std::uint8_t* shade = fb.shade.data();
    std::uint32_t* rgba = fb.rgba.data();
    std::uint32_t last = kNone, base = 0;  // neighbouring pixels mostly show the same tet
    for (std::size_t p = begin; p < end; ++p) {
      const std::uint32_t t = id[p];
      if (t >= tc) continue;  // background (kNone)
      if (t != last) {
        last = t;
        base = base_of(t);
      }
      rgba[p] = shade_color(base, shade[p]);
    }
  });
  // Undoable: the saved pixels too (what undraw restores), each lane on its thread.
  if (lanes.empty()) return;
  run_parts(int(lanes.size()), [&](int k) {
    Lane& lane = lanes[std::size_t(k)];
    for (std::size_t j = 0; j < lane.saved_id.size(); ++j)
      if (lane.saved_id[j] < tc)
        lane.saved_rgba[j] = shade_color(base_of(lane.saved_id[j]), lane.saved_shade[j]);
  });
}

bool TetRasterizer::Impl::recolors_by_shade(const FieldPaint* paint) const {
  const double old_band = field != nullptr ? field->shade_min : params.ambient;
  const double new_band = paint != nullptr ? paint->shade_min : params.ambient;
  return new_band == old_band && !(paint != nullptr && paint->graded);
}

void TetRasterizer::Impl::recolor(Framebuffer& fb, std::shared_ptr<const FieldPaint> paint) {
  check_framebuffer(fb);
  const bool by_shade = fb.shade.size() == fb.rgba.size() && recolors_by_shade(paint.get());
  ensure_shade(fb);
  std::shared_ptr<const FieldPaint> old = std::move(params.field);
  params.field = std::move(paint);
  try {
    setup_field();
  } catch (...) {
    params.field = std::move(old);
    setup_field();
    throw;
  }
  // The picture's shades hold for the new colours if the Lambert band is the same (the edges are).
  if (by_shade) {
    recolor_by_shade(fb);
    changed = fb.rgba.empty() ? PixelRect{} : PixelRect{0, 0, fb.width - 1, fb.height - 1};
    changed_is_one_rect();
    return;
  }
  // The tets visible, each once (a bit per mesh tet: 125 kB at 1M tets), in the order first seen.
  const std::size_t tc = mesh->tet_count();
  std::vector<std::uint64_t> seen((tc + 63) / 64, 0);
  std::vector<std::uint32_t> visible;
  for (const std::uint32_t t : fb.id) {
    if (t >= tc) continue;  // background (kNone)
    std::uint64_t& word = seen[t >> 6];
    const std::uint64_t bit = std::uint64_t(1) << (t & 63);
    if ((word & bit) == 0) {
      word |= bit;
      visible.push_back(t);
    }
  }
  // Threads take parts of the visible tets (not bands of rows, as drawing does: each tet's setup would be
  // repeated by every thread); they write disjoint pixels, those whose id is one of their tets.
  const int count = visible.size() < 256 ? 1 : std::max(1, params.threads);
  run_parts(count, [&](int part) {
    const std::size_t begin = visible.size() * std::size_t(part) / std::size_t(count);
    const std::size_t end = visible.size() * std::size_t(part + 1) / std::size_t(count);
    for (std::size_t i = begin; i < end; ++i) recolor_tet(fb, Rows{}, visible[i]);
  });
  changed = visible.empty() ? PixelRect{} : PixelRect{0, 0, fb.width - 1, fb.height - 1};
  changed_is_one_rect();
}

}  // namespace foxi
