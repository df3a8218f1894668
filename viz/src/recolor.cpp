// Recolouring a drawn picture through its id buffer (issue 17: another field or colour map without
// drawing the mesh again; TetRasterizer::recolor). The id buffer says which tet each pixel shows;
// rasterizing those tets' front faces again, and writing only the pixels that show them, gives each
// pixel exactly the colour a fresh draw with the new paint would: the same face setup (shade, edge
// lines, graded planes) and the same per-pixel colour functions as drawing. Hidden tets, the bulk
// of a 1M-tet view, are never looked at.
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

void TetRasterizer::Impl::recolor(Framebuffer& fb, std::shared_ptr<const FieldPaint> paint) {
  check_framebuffer(fb);
  std::shared_ptr<const FieldPaint> old = std::move(params.field);
  params.field = std::move(paint);
  try {
    setup_field();
  } catch (...) {
    params.field = std::move(old);
    setup_field();
    throw;
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
