// The painter's rasterizer (see rasterizer.hpp). Face setup works in camera coordinates (x right,
// y up, z depth; a left-handed frame, so cross products there are the mirror of world ones), pixels
// in fixed point with 8 subpixel bits and 64-bit edge functions.
// This file: TetRasterizer's construction, draw and draw_batch (the threads and bands), the
// written-mask and the public functions; the other members are in the files raster_impl.hpp names.
#include "raster_impl.hpp"
#include "depth_tie.hpp"

namespace foxi {

namespace {

constexpr std::uint32_t kPalette[] = {
    pack_rgba(78, 121, 167),  pack_rgba(242, 142, 43),  pack_rgba(89, 161, 79),   pack_rgba(225, 87, 89),
    pack_rgba(118, 183, 178), pack_rgba(237, 201, 72),  pack_rgba(176, 122, 161), pack_rgba(255, 157, 167),
    pack_rgba(156, 117, 95),  pack_rgba(186, 176, 172), pack_rgba(134, 188, 230), pack_rgba(160, 203, 109),
};

}  // namespace

std::uint32_t region_color(std::int32_t id) {
  constexpr std::int64_t n = sizeof kPalette / sizeof kPalette[0];
  return kPalette[((std::int64_t(id) % n) + n) % n];
}

TetRasterizer::Impl::Impl(const MeshView& m, const Camera& c, int w, int h, const RenderParams& p)
    : mesh_view(m), mesh(&mesh_view), proj(c, w, h), params(p) {
  if (!(params.shrink > 0 && params.shrink <= 1))
    throw std::invalid_argument("render: shrink must be in (0, 1]");
  if (params.threads < 1) params.threads = 1;
  if (params.threads > 64) params.threads = 64;
  if (!(params.edge_width > 0)) params.edges = false;
  edge_base = 1 - params.edge_darkness;
  edge_slope = params.edges ? params.edge_darkness / params.edge_width : 0;
#ifdef FOXI_AVX512_REPAINT
  fast_repaint = params.edges && params.edge_darkness >= 0 && params.edge_darkness <= 1 && avx512_repaint();
#endif
  setup_field();
#ifdef FOXI_AVX512_REPAINT
  fast_repaint = fast_repaint && !(field != nullptr && field->graded);  // the vector repaint is flat
#endif
  reverse = !params.depth_buffer;
  mask_words = (w + 63) / 64;
  use_mask = reverse;
  if (params.undoable) {
    if (params.depth_buffer) throw std::invalid_argument("render: undoable drawing needs the painter");
    if (w > 32767 || h > 32767)
      throw std::invalid_argument(
          "render: undoable drawing needs an image at most 32767 pixels wide and high");
    adjacency = &face_adjacency(m);
    drawn_at.assign(m.tet_count(), 0);
    kept.assign((m.tet_count() + 63) / 64, 0);
    tainted.assign(kept.size(), 0);
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    shown.assign(std::size_t(mask_words) * std::size_t(h), 0);
    slot.assign(pixels, kNone);
    before_rgba.assign(pixels, 0);
    before_id.assign(pixels, 0);
    before_shade.assign(pixels, 0);
    lane_count = std::min(params.threads, std::max(1, h >> kBandShift));
    lanes.resize(std::size_t(lane_count));
  }
  double l[3] = {-0.3, 0.45, -1};
  double ln = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  for (int k = 0; k < 3; ++k) light[k] = l[k] / ln;
  // Farthest distance from the eye to the mesh's bounding box bounds |x|, |y| of every point.
  double lo[3], hi[3];
  const std::size_t n = m.node_count();
  if (m.tet.empty()) {
    mesh_bounds(m, lo, hi);
  } else {
    // mesh_bounds (the box of the tets' nodes) and the node check in one pass, on two threads
    // for big meshes: min and max give the same box in any order (NaN ignored as there).
    struct Part {
      double lo[3], hi[3];
      bool bad = false;
    };
    auto scan = [&](std::size_t begin, std::size_t end, Part& part) {
      const double inf = std::numeric_limits<double>::infinity();
      double l0 = inf, l1 = inf, l2 = inf, h0 = -inf, h1 = -inf, h2 = -inf;
      bool bad = false;
      const std::uint32_t* tet = m.tet.data();
      const double* xyz = m.xyz.data();
      for (std::size_t i = begin; i < end; ++i) {
        const std::uint32_t nd = tet[i];
        if (nd >= n) {
          bad = true;
          continue;
        }
        const double* x = xyz + 3 * std::size_t(nd);
        l0 = std::min(l0, x[0]);
        l1 = std::min(l1, x[1]);
        l2 = std::min(l2, x[2]);
        h0 = std::max(h0, x[0]);
        h1 = std::max(h1, x[1]);
        h2 = std::max(h2, x[2]);
      }
      part = Part{{l0, l1, l2}, {h0, h1, h2}, bad};
    };
    Part parts[2];
    const std::size_t total = m.tet.size(), half = total / 2;
    if (total > 80000 && params.threads > 1) {
      run_parts(2, [&](int k) { k == 0 ? scan(0, half, parts[0]) : scan(half, total, parts[1]); });
    } else {
      scan(0, total, parts[0]);
      scan(total, total, parts[1]);
    }
    if (parts[0].bad || parts[1].bad) throw std::out_of_range("render: a tet refers to a missing node");
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(parts[0].lo[k], parts[1].lo[k]);
      hi[k] = std::max(parts[0].hi[k], parts[1].hi[k]);
    }
  }
  double dmax = 0;
  if (lo[0] <= hi[0]) {
    for (int corner = 0; corner < 8; ++corner) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        double v = ((corner >> k) & 1 ? hi[k] : lo[k]) - proj.eye[k];
        d2 += v * v;
      }
      dmax = std::max(dmax, std::sqrt(d2));
    }
  }
  if (!std::isfinite(dmax)) dmax = 0;
  if (proj.perspective) {
    // Points at depth >= near project within kMaxPixel of the centre.
    near = std::max(params.near, dmax * proj.focal / kMaxPixel);
    if (!(near > 0)) near = 1e-300;
  } else if (dmax * proj.scale > kMaxPixel) {
    throw std::invalid_argument("render: orthographic zoom too large for the fixed-point range (" +
                                std::to_string(dmax * proj.scale) + " pixels)");
  }
  node_view.resize(n);
  auto work = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      std::int64_t X = 0, Y = 0;
      std::uint8_t state = 0;
      project_node(&m.xyz[3 * i], node_view[i].c, X, Y, state);
      node_view[i].X = state == 0 ? std::int32_t(X) : kNoPixel;
      node_view[i].Y = state == 0 ? std::int32_t(Y) : state;
    }
  };
  if (n > 20000 && params.threads > 1) {
    run_parts(2, [&](int k) { k == 0 ? work(0, n / 2) : work(n / 2, n); });
  } else {
    work(0, n);
  }
}

// Draws tet t's front faces into the rows of `rows`.
inline void TetRasterizer::Impl::draw_tet(Framebuffer& fb, const Rows& rows, std::uint32_t t, bool count) {
  TetCorners k;
  if (!load_corners(t, k)) return;
  const double* const* c = k.c;
  const std::int64_t* Y = k.Y;
  const std::uint8_t* st = k.st;
  const int behind = int(st[0]) + st[1] + st[2] + st[3];
  if (behind == 4) {
    if (count) ++stats.tets_behind;
    return;
  }
  if (behind == 0) {
    // Quick reject: the tet's pixel rows are not this thread's, or it is off screen.
    std::int64_t miny = std::min({Y[0], Y[1], Y[2], Y[3]}), maxy = std::max({Y[0], Y[1], Y[2], Y[3]});
    std::int64_t y0 = std::max<std::int64_t>(0, -floor_div(-(miny - kHalf), kOne));
    std::int64_t y1 = std::min<std::int64_t>(fb.height - 1, floor_div(maxy - kHalf, kOne));
    if (!rows.any(int(y0), int(y1))) return;
  }
  PolyVertex poly[4];
  for (int fi = 0; fi < 4; ++fi) {
    const int f = reverse ? 3 - fi : fi;
    bool clipped = false;
    const int n = face_polygon(k, f, false, poly, &clipped);
    if (clipped && count) ++stats.faces_clipped;
    if (n == 0) continue;
    const auto& face = kFace[f];
    const double* v[3] = {c[face[0]], c[face[1]], c[face[2]]};
    const std::uint32_t node[3] = {k.tv[face[0]], k.tv[face[1]], k.tv[face[2]]};
    draw_face(fb, rows, t, v, node, poly, n, !clipped);
  }
}

// Draws front face polygon `poly` (n vertices, positive area, from face_polygon) of tet t, whose
// corners are v (camera frame, outward order; nodes `node`), into the rows of `rows`. test_hidden
// (a triangle): first test its pixel box against the mask, skipping it if hidden.
void TetRasterizer::Impl::draw_face(Framebuffer& fb, const Rows& rows, std::uint32_t t,
                                    const double* const v[3], const std::uint32_t node[3],
                                    const PolyVertex* poly, int n, bool test_hidden) {
  if (use_mask && test_hidden) {  // hidden behind what this batch drew already?
    const Box box =
        pixel_box(std::min({poly[0].X, poly[1].X, poly[2].X}), std::max({poly[0].X, poly[1].X, poly[2].X}),
                  std::min({poly[0].Y, poly[1].Y, poly[2].Y}), std::max({poly[0].Y, poly[1].Y, poly[2].Y}),
                  fb.width, fb.height);
    if (box.x0 > box.x1 || box_written(rows, box, fb.height)) return;
  }
  FaceSetup fs;
  setup_face(fs, t, v, node, poly, n);
  raster_polygon(fb, rows, fs, poly, n);
}

void TetRasterizer::Impl::check_framebuffer(Framebuffer& fb, std::uint32_t* rows, std::size_t row_pixels) {
  if (fb.width != proj.width || fb.height != proj.height)
    throw std::invalid_argument("render: framebuffer size differs from the rasterizer's");
  const std::size_t pixels = std::size_t(fb.width) * std::size_t(fb.height);
  if ((rows == nullptr && fb.rgba.size() != pixels) || fb.id.size() != pixels)
    throw std::invalid_argument("render: framebuffer buffers have the wrong size");
  if (params.depth_buffer && fb.depth.size() != pixels)
    throw std::invalid_argument("render: depth-buffer mode needs a framebuffer with a depth buffer");
  if (rows != nullptr && row_pixels < std::size_t(fb.width))
    throw std::invalid_argument("render: image rows narrower than the framebuffer");
  colors = rows != nullptr ? rows : fb.rgba.data();
  color_stride = rows != nullptr ? row_pixels : std::size_t(fb.width);
}

void TetRasterizer::Impl::draw(Framebuffer& fb, std::span<const std::uint32_t> tets, std::uint32_t* rows,
                               std::size_t row_pixels) {
  if (rows != nullptr && params.undoable)
    throw std::logic_error("render: an undoable picture is drawn into its framebuffer (undraw reads it)");
  check_framebuffer(fb, rows, row_pixels);
  ensure_shade(fb);
  if (params.depth_buffer) ensure_depth_slopes(fb);
  const std::size_t tc = mesh->tet_count();
  for (std::uint32_t t : tets)
    if (t >= tc) throw std::out_of_range("render: tet index " + std::to_string(t) + " out of range");
  stats.tets_drawn += tets.size();
  changed = PixelRect{};
  if (!params.undoable) {
    draw_batch(fb, tets);
    if (!reverse) changed = boxes_union(tets.size());  // the painter's clear_mask found it
    changed_is_one_rect();
    return;
  }
  // Undoable: positions first (a back face is shared with a tet drawn earlier), then one
  // front-to-back walk that answers the saves' requests (see `recording`).
  const std::size_t start = history.size();
  for (std::size_t i = 0; i < tets.size(); ++i) {
    if (is_kept(tets[i])) {
      for (std::size_t k = 0; k < i; ++k) kept[tets[k] >> 6] &= ~(std::uint64_t(1) << (tets[k] & 63));
      throw std::invalid_argument("render: undoable drawing draws each tet once (tet " +
                                  std::to_string(tets[i]) + " again)");
    }
    kept[tets[i] >> 6] |= std::uint64_t(1) << (tets[i] & 63);
    drawn_at[tets[i]] = std::uint32_t(start + i);
    if (any_tainted) tainted[tets[i] >> 6] &= ~(std::uint64_t(1) << (tets[i] & 63));  // drawn afresh
  }
  history.insert(history.end(), tets.begin(), tets.end());
  drawn_box.resize(history.size(), SmallBox{0, 0, -1, -1});  // "unknown" until draw_batch finds them
  drawn_reach.resize(history.size(), 0xffff);
  for (Lane& lane : lanes) lane.regions.push_back(SaveRegion{lane.saves.size(), lane.saved_pixel.size()});
  recording = true;
  try {
    draw_batch(fb, tets);
  } catch (...) {
    clear_mask(tets.size());
    recording = false;
    throw;
  }
  clear_mask(tets.size());
  recording = false;
  changed_is_one_rect();
  for (Lane& lane : lanes)
    if (lane.saves.size() == lane.regions.back().first_save) lane.regions.pop_back();
}

// End of an undoable batch, in lane k (by its thread): requests no tet answered get what was there
// before the batch; a request replaced at its pixel by a later one (a back face covering a pixel
// its tet's front faces miss, after snapping) takes that one's answer. The lane's saves, filed
// front to back, are then put in drawing order.
inline void TetRasterizer::Impl::answer_requests(const Framebuffer& fb, int k) {
  Lane& lane = lanes[std::size_t(k)];
  const SaveRegion& region = lane.regions.back();
  for (std::size_t i = region.first_pixel; i < lane.saved_pixel.size(); ++i) {
    const std::uint32_t p = lane.saved_pixel[i];
    if (slot[p] != i) continue;
    const bool was_shown = (shown[std::size_t(p / std::uint32_t(fb.width)) * std::size_t(mask_words) +
                                  ((p % std::uint32_t(fb.width)) >> 6)] >>
                            ((p % std::uint32_t(fb.width)) & 63)) &
                           1;
    lane.saved_rgba[i] = was_shown ? before_rgba[p] : fb.rgba[p];
    lane.saved_id[i] = was_shown ? before_id[p] : fb.id[p];
    lane.saved_shade[i] = was_shown ? before_shade[p] : fb.shade[p];
    slot[p] = kNone;
  }
  for (std::size_t i = lane.aliases.size(); i-- > 0;) {
    lane.saved_rgba[lane.aliases[i].first] = lane.saved_rgba[lane.aliases[i].second];
    lane.saved_id[lane.aliases[i].first] = lane.saved_id[lane.aliases[i].second];
    lane.saved_shade[lane.aliases[i].first] = lane.saved_shade[lane.aliases[i].second];
  }
  lane.aliases.clear();
  lane.unshown_requests = false;
  std::reverse(lane.saves.begin() + std::ptrdiff_t(region.first_save), lane.saves.end());
}

// Whether drawn tet t has a back face covering pixels that is not shared (see earlier_neighbour);
// for every tet of an undoable batch, so the facing of an unclipped face is read off the sign of
// its projected area (as face_polygon does) without building its polygon; k: its corners (finite).
// reach: t's repaint reach (see drawn_reach). inverted: t has a front face shared with a tet drawn
// before it (see `tainted`).
inline bool TetRasterizer::Impl::has_unshared_back_face(std::uint32_t t, const TetCorners& k,
                                                        std::uint16_t& reach, bool& inverted,
                                                        unsigned* edge_on) const {
  bool unshared = false;
  std::uint32_t least = drawn_at[t];
  const bool unclipped = k.st[0] + k.st[1] + k.st[2] + k.st[3] == 0;
  int meets_risky = -1;  // whether t's box holds a risky pixel (see kNearEdge), found when first asked
  for (int f = 0; f < 4; ++f) {
    bool back, front;
    if (unclipped) {
      const int a = kFace[f][0], b = kFace[f][1], d = kFace[f][2];
      const std::int64_t ux = k.X[b] - k.X[a], uy = k.Y[b] - k.Y[a], wx = k.X[d] - k.X[a],
                         wy = k.Y[d] - k.Y[a];
      const std::int64_t area = ux * wy - uy * wx;
      back = area > 0;
      front = area < 0;
      // Seen exactly edge on, a face's snapped area is zero to rounding (each corner moved half a
      // unit at most); only such faces are looked at again (a line covers no pixel).
      if (edge_on != nullptr && area != 0 &&
          std::abs(area) <= std::abs(ux) + std::abs(uy) + std::abs(wx) + std::abs(wy) + 6 &&
          edge_on_face(k, f))
        *edge_on |= 1u << f;
    } else {
      PolyVertex poly[4];
      bool clipped = false;
      back = face_polygon(k, f, true, poly, &clipped) > 0;
      front = !back && face_polygon(k, f, false, poly, &clipped) > 0;
    }
    if (front && earlier_neighbour(t, f) != kNone) inverted = true;
    if (!back) continue;
    const std::uint32_t nb = earlier_neighbour(t, f);
    if (nb == kNone) {
      unshared = true;
    } else {
      least = std::min(least, drawn_at[nb >> 2]);
      if (saves_risky(t, nb)) unshared = true;  // it files saves (of its risky pixels only)
      if (!unshared && !risky_tile.empty()) {   // the same (see kNearEdge)
        if (meets_risky < 0) meets_risky = box_meets_risky(tet_box(k, proj.width, proj.height));
        unshared = meets_risky != 0;
      }
    }
  }
  reach = std::uint16_t(std::min<std::uint32_t>(drawn_at[t] - least, 0xffff));
  // A tet cut by the near plane (not wholly behind it) saves its front faces too (request_saves).
  const int behind = k.st[0] + k.st[1] + k.st[2] + k.st[3];
  return unshared || (behind > 0 && behind < 4);
}

bool TetRasterizer::Impl::edge_on_face(const TetCorners& k, int f) const {
  const int a = kFace[f][0], b = kFace[f][1], d = kFace[f][2];
  const double *pa = k.c[a], *pb = k.c[b], *pd = k.c[d];
  const double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
  const double w[3] = {pd[0] - pa[0], pd[1] - pa[1], pd[2] - pa[2]};
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  const double lu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]),
               lw = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  // Its plane through the eye (perspective; camera coordinates put the eye at the origin) or along
  // the view (orthographic), to rounding: a generic face is off by a sine under 1e-9 once in 1e9.
  const double off = proj.perspective ? std::abs(pa[0] * n[0] + pa[1] * n[1] + pa[2] * n[2]) /
                                            std::sqrt(pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2])
                                      : std::abs(n[2]);
  return off <= 1e-9 * lu * lw;
}

void TetRasterizer::Impl::mark_near_edge(std::int64_t xa, std::int64_t ya, std::int64_t xb, std::int64_t yb) {
  const std::int64_t dx = xb - xa, dy = yb - ya;
  if (dx == 0 && dy == 0) return;  // the face's other edges hold it
  // Along the edge's longer extent (rows, or columns), the pixel centres within reach across it.
  const bool rows_major = std::abs(dy) >= std::abs(dx);
  const std::int64_t ma = rows_major ? ya : xa, mb = rows_major ? yb : xb;  // major coordinates
  const std::int64_t na = rows_major ? xa : ya, dn = rows_major ? dx : dy, dm = rows_major ? dy : dx;
  const int major_size = rows_major ? proj.height : proj.width,
            minor_size = rows_major ? proj.width : proj.height;
  const std::int64_t reach =
      2 * kNearEdge + 1;  // across, in units (kNearEdge (|dx| + |dy|) / |dm| <= 2 kNearEdge)
  const std::int64_t lo = std::min(ma, mb) - 2 * kNearEdge, hi = std::max(ma, mb) + 2 * kNearEdge;
  for (std::int64_t m = std::max<std::int64_t>(0, -floor_div(-(lo - kHalf), kOne));
       m < major_size && m * kOne + kHalf <= hi; ++m) {
    const double across = double(na) + double(dn) * double(m * kOne + kHalf - ma) / double(dm);
    const std::int64_t first =
        std::max<std::int64_t>(0, -floor_div(-(std::int64_t(std::floor(across)) - reach - kHalf), kOne));
    for (std::int64_t n = first;
         n < minor_size && n * kOne + kHalf <= std::int64_t(std::ceil(across)) + reach; ++n) {
      const int x = int(rows_major ? n : m), y = int(rows_major ? m : n);
      if (near_edge(xa, ya, xb, yb, std::int64_t(x) * kOne + kHalf, std::int64_t(y) * kOne + kHalf))
        mark_risky(x, y);
    }
  }
}

// Undoable, a batch with inverted pairs (rare: a face seen edge-on): taints the pairs' tets (see
// `tainted`), then finds again which tets file saves (a tet's back face shared with a tet tainted
// earlier in the batch is now unshared). In drawing order, as if every tet of the batch were looked at
// again with the taints of the tets before it; but only the tets that can answer differently are: the
// inverted tets (inverted_at, batch positions in ascending order), and the tets drawn later in the
// batch next to a tet just tainted (what the others file depends on no taint made in this batch).
// A serial pass over the whole batch cost undoable drawing 13 % of its time at 0.97M tets.
void TetRasterizer::Impl::taint_inverted(std::span<const std::uint32_t> tets,
                                         std::span<const std::uint32_t> inverted_at) {
  const std::size_t start = history.size() - tets.size();  // the batch is the end of the history
  std::priority_queue<std::uint32_t, std::vector<std::uint32_t>, std::greater<>> due(
      std::greater<>{}, std::vector<std::uint32_t>(inverted_at.begin(), inverted_at.end()));
  // Taints tet x while tet i of the batch is looked at; x's neighbours drawn after tet i are due.
  auto taint_from = [&](std::uint32_t x, std::size_t i) {
    taint(x);
    for (int f = 0; f < 4; ++f) {
      const std::uint32_t nb = adjacency->neighbour[4 * std::size_t(x) + std::size_t(f)];
      if (nb == kNone || !is_kept(nb >> 2)) continue;
      const std::size_t at = drawn_at[nb >> 2];
      if (at > start + i) due.push(std::uint32_t(at - start));
    }
  };
  std::size_t last = std::numeric_limits<std::size_t>::max();
  while (!due.empty()) {
    const std::size_t i = due.top();
    due.pop();
    if (i == last) continue;  // due twice
    last = i;
    if (boxes[i].x0 > boxes[i].x1) continue;
    TetCorners k;
    load_corners(tets[i], k);
    bool inverted = false;
    std::uint16_t reach = 0;
    need_save[i] = has_unshared_back_face(tets[i], k, reach, inverted);
    if (inverted) {
      // Where the front face shared with an earlier tet covers pixels (after snapping, a sliver that
      // seldom holds a pixel centre), they become risky, and t and that tet tainted.
      const Rows all{0, 1, 0, proj.height - 1};
      bool covers = false;
      for (int f = 0; f < 4; ++f) {
        const std::uint32_t nb = earlier_neighbour(tets[i], f);
        if (nb == kNone) continue;
        PolyVertex poly[4];
        bool clipped = false;
        const int n = face_polygon(k, f, false, poly, &clipped);
        bool pixels = false;
        for (int q = 1; q + 1 < n; ++q) {  // its fan triangles, as for_each_run walks them
          const std::int64_t X[3] = {poly[0].X, poly[q].X, poly[q + 1].X},
                             Y[3] = {poly[0].Y, poly[q].Y, poly[q + 1].Y};
          if ((X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]) <= 0) continue;
          raster_triangle(X, Y, proj.width, proj.height, all, [&](int y, int lo, int hi) {
            if (risky.empty()) risky.assign(shown.size(), 0);
            for (int x = lo; x <= hi; ++x)
              risky[std::size_t(y) * std::size_t(mask_words) + std::size_t(x >> 6)] |= std::uint64_t(1)
                                                                                       << (x & 63);
            pixels = true;
          });
        }
        if (!pixels) continue;
        taint_from(nb >> 2, i);
        covers = true;
      }
      if (covers) {
        taint_from(tets[i], i);
        need_save[i] = has_unshared_back_face(tets[i], k, reach, inverted);
      }
    }
    batch_reach[i] = reach;
  }
}

// Painter or depth-buffer drawing of a batch (see draw); the written-pixel mask is all zero before
// and after, cleared only on the rows the batch could touch (short batches cost what they draw).
inline void TetRasterizer::Impl::draw_batch(Framebuffer& fb, std::span<const std::uint32_t> tets) {
  if (tets.empty()) return;
  // Threads pay for themselves only on long batches. Undoable drawing always uses its lanes'
  // partition (saved pixels are kept per lane), on one thread for short batches.
  const int count = recording           ? lane_count
                    : tets.size() < 256 ? 1
                                        : std::min(params.threads, std::max(1, fb.height >> kBandShift));
  const bool spawn = count > 1 && tets.size() >= 256;
  if (reverse && written.empty()) {
    written.assign(std::size_t(mask_words) * std::size_t(fb.height), 0);
    tile_full.assign(std::size_t(mask_words) * std::size_t((fb.height >> kBandShift) + 1), 0);
  }
  boxes.resize(tets.size());
  // Per half of the batch: the tets with faces seen edge on (batch position * 16 + their faces).
  std::vector<std::uint64_t> edge_on[2];
  auto find_boxes = [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& inverted_at) {
    std::vector<std::uint64_t>& edge_on_here = edge_on[begin == 0 ? 0 : 1];
    constexpr std::size_t kAhead = 8;
    for (std::size_t i = begin; i < end; ++i) {
      if (i + kAhead < end) prefetch_tet(tets[i + kAhead]);
      if (i + 2 * kAhead < end) __builtin_prefetch(&mesh->tet[4 * std::size_t(tets[i + 2 * kAhead])]);
      if (recording) {  // has_unshared_back_face reads the tet's neighbours and their positions
        if (i + 2 * kAhead < end)
          __builtin_prefetch(&adjacency->neighbour[4 * std::size_t(tets[i + 2 * kAhead])]);
        if (i + kAhead < end) prefetch_neighbours(tets[i + kAhead]);
      }
      TetCorners k;
      load_corners(tets[i], k);
      boxes[i] = tet_box(k, fb.width, fb.height);
      if (recording) {
        need_save[i] = false;
        batch_reach[i] = 0;
        bool inverted = false;
        if (boxes[i].x0 <= boxes[i].x1) {
          unsigned faces = 0;
          need_save[i] = has_unshared_back_face(tets[i], k, batch_reach[i], inverted,
                                                params.shrink == 1 ? &faces : nullptr);
          if (faces != 0) edge_on_here.push_back(std::uint64_t(i) << 4 | faces);
        }
        if (inverted) inverted_at.push_back(std::uint32_t(i));
      }
    }
  };
  auto draw_one = [&](const Rows& rows, std::size_t i, bool first) {
    const Box& b = boxes[i];
    if (b.x0 > b.x1) return;  // draws nothing
    const bool files_save = recording && need_save[i];
    if (b.y0 >= 0) {
      if (!rows.any(b.y0, b.y1)) return;
      // Hidden behind what this batch drew already (a tet with a save still files its requests).
      if (use_mask && !files_save && box_written(rows, b, fb.height)) return;
    }
    draw_tet(fb, rows, tets[i], first);
    if (files_save) request_saves(fb, rows, tets[i]);
  };
  auto work = [&](int k) {
    Rows rows{k, count};
    if (reverse) {
      for (std::size_t i = tets.size(); i-- > 0;) draw_one(rows, i, k == 0);
    } else {
      for (std::size_t i = 0; i < tets.size(); ++i) draw_one(rows, i, k == 0);
    }
    if (recording) answer_requests(fb, k);
  };
  if (recording) {
    need_save.resize(tets.size());
    batch_reach.resize(tets.size());
  }
  std::vector<std::uint32_t> inverted[2];  // batch positions of the tets of inverted pairs, ascending
  if (!spawn || tets.size() < 4096) {
    find_boxes(0, tets.size(), inverted[0]);
  } else {
    const std::size_t half = tets.size() / 2;
    run_parts(2, [&](int k) {
      k == 0 ? find_boxes(0, half, inverted[0]) : find_boxes(half, tets.size(), inverted[1]);
    });
  }
  if (recording && !(inverted[0].empty() && inverted[1].empty())) {
    inverted[0].insert(inverted[0].end(), inverted[1].begin(), inverted[1].end());
    taint_inverted(tets, inverted[0]);
  }
  if (recording && !(edge_on[0].empty() && edge_on[1].empty())) {
    // Faces seen edge on: their pixels' neighbourhoods become risky, and the tets of the batch whose
    // boxes meet them save those pixels of their shared back faces (see kNearEdge).
    for (const auto& half : edge_on)
      for (const std::uint64_t entry : half) {
        TetCorners k;
        load_corners(tets[std::size_t(entry >> 4)], k);
        for (int f = 0; f < 4; ++f)
          if (entry >> f & 1)
            for (int e = 0; e < 3; ++e) {
              const int a = kFace[f][e], b = kFace[f][(e + 1) % 3];
              mark_near_edge(k.X[a], k.Y[a], k.X[b], k.Y[b]);
            }
      }
    for (std::size_t i = 0; i < tets.size(); ++i)
      if (!need_save[i] && box_meets_risky(boxes[i])) {
        TetCorners k;
        load_corners(tets[i], k);
        bool inverted_pair = false;  // the taint rule above has had its say
        need_save[i] = has_unshared_back_face(tets[i], k, batch_reach[i], inverted_pair);
      }
  }
  if (recording) {  // the batch is the end of the history
    SmallBox* kept_box = drawn_box.data() + (drawn_box.size() - tets.size());
    for (std::size_t i = 0; i < tets.size(); ++i)
      kept_box[i] = SmallBox{std::int16_t(boxes[i].x0), std::int16_t(boxes[i].x1), std::int16_t(boxes[i].y0),
                             std::int16_t(boxes[i].y1)};
    std::copy(batch_reach.begin(), batch_reach.end(), drawn_reach.end() - std::ptrdiff_t(tets.size()));
  }
  if (!spawn) {
    for (int k = 0; k < count; ++k) work(k);
  } else {
    run_parts(count, work);
  }
  if (reverse && !recording) clear_mask(tets.size());
}

// The union of the first n boxes of the batch (the whole image if one is unknown): where drawing or
// undrawing them may have changed pixels.
inline PixelRect TetRasterizer::Impl::boxes_union(std::size_t n) const {
  PixelRect r{proj.width, proj.height, -1, -1};
  for (std::size_t i = 0; i < n; ++i) {
    const Box& b = boxes[i];
    if (b.x0 > b.x1) continue;
    if (b.y0 < 0) return PixelRect{0, 0, proj.width - 1, proj.height - 1};
    r.x0 = std::min(r.x0, b.x0);
    r.x1 = std::max(r.x1, b.x1);
    r.y0 = std::min(r.y0, b.y0);
    r.y1 = std::max(r.y1, b.y1);
  }
  return r.x0 <= r.x1 ? r : PixelRect{};
}

// Zeroes the written-pixel mask on rows y0 to y1 (y0 <= y1) and the tiles of their bands.
void TetRasterizer::Impl::zero_mask(int y0, int y1) {
  const std::size_t words = std::size_t(mask_words);
  std::fill(written.begin() + std::ptrdiff_t(std::size_t(y0) * words),
            written.begin() + std::ptrdiff_t(std::size_t(y1 + 1) * words), 0);
  std::fill(tile_full.begin() + std::ptrdiff_t(std::size_t(y0 >> kBandShift) * words),
            tile_full.begin() + std::ptrdiff_t(std::size_t((y1 >> kBandShift) + 1) * words), 0);
}

// Zeroes the written-pixel mask (and while recording, `shown`) on the rows the batch's boxes span;
// `changed` becomes their union.
inline void TetRasterizer::Impl::clear_mask(std::size_t n) {
  changed = boxes_union(n);
  const int y0 = changed.y0, y1 = changed.y1;
  if (y0 > y1) return;
  zero_mask(y0, y1);
  const std::size_t words = std::size_t(mask_words);
  if (recording)  // else all zero
    std::fill(shown.begin() + std::ptrdiff_t(std::size_t(y0) * words),
              shown.begin() + std::ptrdiff_t(std::size_t(y1 + 1) * words), 0);
}

TetRasterizer::TetRasterizer(const MeshView& mesh, const Camera& camera, int width, int height,
                             const RenderParams& params)
    : impl_(std::make_unique<Impl>(mesh, camera, width, height, params)) {}
TetRasterizer::~TetRasterizer() = default;
TetRasterizer::TetRasterizer(TetRasterizer&&) noexcept = default;
TetRasterizer& TetRasterizer::operator=(TetRasterizer&&) noexcept = default;

void TetRasterizer::draw(Framebuffer& fb, std::span<const std::uint32_t> tets) { impl_->draw(fb, tets); }
void TetRasterizer::draw_into(Framebuffer& fb, std::span<const std::uint32_t> tets, std::uint32_t* rows,
                              std::size_t row_pixels) {
  if (rows == nullptr) throw std::invalid_argument("render: draw_into needs the image's rows");
  impl_->draw(fb, tets, rows, row_pixels);
}
const RasterStats& TetRasterizer::stats() const { return impl_->stats; }
const Projector& TetRasterizer::projector() const { return impl_->proj; }
double TetRasterizer::near_plane() const { return impl_->near; }
void TetRasterizer::undraw(Framebuffer& fb, std::size_t count) { impl_->undraw(fb, count); }
void TetRasterizer::recolor(Framebuffer& fb, std::shared_ptr<const FieldPaint> field) {
  impl_->recolor(fb, std::move(field));
}
bool TetRasterizer::recolors_by_shade(const FieldPaint* field) const {
  return impl_->recolors_by_shade(field);
}
std::span<const std::uint32_t> TetRasterizer::drawn_tets() const { return impl_->history; }
std::size_t TetRasterizer::saved_pixels() const { return impl_->saved_pixels(); }
std::size_t TetRasterizer::undo_bytes() const { return impl_->undo_bytes(); }
PixelRect TetRasterizer::changed_rect() const { return impl_->changed; }
std::span<const PixelRect> TetRasterizer::changed_rects() const { return impl_->changed_list; }
void TetRasterizer::forget_drawn() { impl_->forget(); }

Framebuffer render_tets(const MeshView& mesh, const Camera& camera, int width, int height,
                        std::span<const std::uint32_t> tets, const RenderParams& params) {
  Framebuffer fb(width, height, params.depth_buffer);
  TetRasterizer r(mesh, camera, width, height, params);
  r.draw(fb, tets);
  return fb;
}

std::vector<std::uint32_t> triangle_coverage(const std::int64_t x[3], const std::int64_t y[3], int width,
                                             int height) {
  std::int64_t X[3] = {x[0], x[1], x[2]}, Y[3] = {y[0], y[1], y[2]};
  std::int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
  std::vector<std::uint32_t> out;
  if (area == 0) return out;
  if (area < 0) {
    std::swap(X[1], X[2]);
    std::swap(Y[1], Y[2]);
  }
  raster_triangle(X, Y, width, height, Rows{}, [&](int py, int lo, int hi) {
    for (int px = lo; px <= hi; ++px)
      out.push_back(std::uint32_t(py) * std::uint32_t(width) + std::uint32_t(px));
  });
  return out;
}

}  // namespace foxi
