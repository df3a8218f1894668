// The painter's undo (TetRasterizer::Impl, raster_impl.hpp): the saves requested while drawing and
// answered at the end of a batch, and undraw, which restores saved pixels and repaints the faces of
// kept neighbours, split into row ranges across threads.
#include "foxi/model/assert.hpp"
#include "raster_impl.hpp"

namespace foxi {

// Calls fn(y, lo, hi) for the pixel runs of a polygon (positive area) in the rows of `rows`, in a
// fixed order.
template <class Fn>
inline void TetRasterizer::Impl::for_each_run(const PolyVertex* poly, int n, const Rows& rows,
                                              Fn&& fn) const {
  for (int q = 1; q + 1 < n; ++q) {
    std::int64_t X[3] = {poly[0].X, poly[q].X, poly[q + 1].X}, Y[3] = {poly[0].Y, poly[q].Y, poly[q + 1].Y};
    std::int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area <= 0) continue;
    raster_triangle(X, Y, proj.width, proj.height, rows, fn);
  }
}

// Calls fn(f, poly, n) for each back face of drawn tet t that covers pixels.
template <class Fn>
inline void TetRasterizer::Impl::for_each_back_face(std::uint32_t t, Fn&& fn) const {
  TetCorners k;
  if (!load_corners(t, k)) return;
  PolyVertex poly[4];
  for (int f = 0; f < 4; ++f) {
    bool clipped = false;
    const int n = face_polygon(k, f, true, poly, &clipped);
    if (n > 0) fn(f, poly, n);
  }
}

// Files t's save in the lane of `rows`: a request for each pixel of its unshared back faces in
// those rows (just after t's front faces were walked, which answered the requests of nearer tets
// on the same pixels).
void TetRasterizer::Impl::request_saves(const Framebuffer& fb, const Rows& rows, std::uint32_t t) {
  Lane& lane = lanes[std::size_t(rows.thread)];
  std::vector<std::uint32_t>& saved_pixel = lane.saved_pixel;
  lane.saves.push_back(Save{drawn_at[t], saved_pixel.size()});
  auto request = [&](const PolyVertex* poly, int n, bool risky_only) {
    for_each_run(poly, n, rows, [&](int y, int lo, int hi) {
      const std::size_t row = std::size_t(y) * std::size_t(fb.width);
      std::uint64_t* done = &written[std::size_t(y) * std::size_t(mask_words)];
      const std::uint64_t* shown_row = &shown[std::size_t(y) * std::size_t(mask_words)];
      for (int x = lo; x <= hi; ++x) {
        if (risky_only && !is_risky(x, y)) continue;
        const std::uint32_t k = std::uint32_t(saved_pixel.size()), p = std::uint32_t(row + std::size_t(x));
        if (!(shown_row[x >> 6] >> (x & 63) & 1)) lane.unshown_requests = true;
        if (slot[p] != kNone) lane.aliases.emplace_back(slot[p], k);
        slot[p] = k;
        saved_pixel.push_back(p);
        done[x >> 6] &= ~(std::uint64_t(1) << (x & 63));  // to be walked again
        tile_full[std::size_t(y >> kBandShift) * std::size_t(mask_words) + std::size_t(x >> 6)] = 0;
      }
    });
  };
  TetCorners k;
  const bool finite = load_corners(t, k);
  // A tet cut by the near plane saves every pixel of its faces, front and back (undraw repaints
  // none of them): its clipped back faces need not cover every pixel its clipped front faces drew
  // (with the eye in the plane of one of its faces, a line of them; found by fuzzing,
  // tests/data/bad/fuzz/mesh_pipeline/undraw_eye_in_face_plane), and where they cover the near
  // plane's cut, the rays start beyond its front faces and a tet drawn after the neighbour may
  // touch that back face, the eye in its plane (see kNearEdge; a lattice with the eye inside). The
  // cuts of the tets the plane cuts tile the picture at most once.
  const bool cut = finite && k.st[0] + k.st[1] + k.st[2] + k.st[3] != 0;  // (not wholly behind: need_save)
  const bool meets_risky = finite && !cut && box_meets_risky(tet_box(k, proj.width, proj.height));
  for_each_back_face(t, [&](int f, const PolyVertex* poly, int n) {
    const std::uint32_t nb = earlier_neighbour(t, f);
    if (nb == kNone || cut)
      request(poly, n, false);
    else if (meets_risky || saves_risky(t, nb))
      request(poly, n, true);
  });
  if (cut) {
    PolyVertex poly[4];
    for (int f = 0; f < 4; ++f) {
      bool clipped = false;
      const int n = face_polygon(k, f, false, poly, &clipped);
      if (n > 0) request(poly, n, false);
    }
  }
  lane.saved_rgba.resize(saved_pixel.size());
  lane.saved_id.resize(saved_pixel.size());
  lane.saved_shade.resize(saved_pixel.size());
}

// Fills u for undrawn tet t, whose drawn box (tet_box) is not empty and not cut by the near plane
// (all its corners in front): its corners and its back faces shared with kept tets (see `kept`),
// which the walk repaints as those tets' front faces (their shades come after, from
// shade_repainted). A face is back when its outward-ordered projection has positive area
// (face_polygon's test).
inline void TetRasterizer::Impl::gather_undrawn(std::uint32_t t, UndrawTet& u) const {
  TetCorners k;
  load_corners(t, k);
  u.repaint = 0;
  for (int j = 0; j < 4; ++j) {
    u.X[j] = std::int32_t(k.X[j]);
    u.Y[j] = std::int32_t(k.Y[j]);
    u.node[j] = k.tv[j];
  }
  for (int f = 0; f < 4; ++f) {
    const std::uint32_t nb = kept_neighbour(t, f);
    if (nb == kNone) continue;
    const int a = kFace[f][0], b = kFace[f][1], d = kFace[f][2];
    if ((k.X[b] - k.X[a]) * (k.Y[d] - k.Y[a]) - (k.Y[b] - k.Y[a]) * (k.X[d] - k.X[a]) <= 0) continue;
    u.repaint = std::uint8_t(u.repaint | (1 << f));
    u.neighbour[f] = nb;
  }
}

// The shades of u's repainted faces: each the kept neighbour's front face, which is u's face seen
// from the other side (u's corners in reverse outward order), shaded bit for bit as drawing the
// neighbour did (see face_shade).
inline void TetRasterizer::Impl::shade_repainted(UndrawTet& u) const {
  for (int f = 0; f < 4; ++f) {
    if (!(u.repaint >> f & 1)) continue;
    const int a = kFace[f][0], b = kFace[f][2], d = kFace[f][1];  // reversed
    const double* v[3] = {cam(u.node[a]), cam(u.node[b]), cam(u.node[d])};
    const std::uint32_t node[3] = {u.node[a], u.node[b], u.node[d]};
    u.shade[f] = face_shade(u.neighbour[f] >> 2, v, node);
  }
}

// Takes back the last `count` tets. Sequentially (front to back) each tet's back-face pixels are
// repainted; the last write to a pixel is by the farthest undrawn tet covering it, so the tets are
// walked back to front instead and each pixel is written once, first write wins (the mask). Each
// lane's thread does its own rows.
void TetRasterizer::Impl::undraw(Framebuffer& fb, std::size_t count) {
  if (!params.undoable) throw std::logic_error("render: undraw needs RenderParams::undoable");
  check_framebuffer(fb);
  ensure_shade(fb);
  if (count > history.size()) throw std::out_of_range("render: undraw of more tets than are drawn");
  // In parts of at most kUndrawPart tets (the per-tet records of a part stay small; taking back the
  // last a tets, then the b before them, gives the picture of taking back a + b), the changed
  // rectangle the union of the parts'.
  constexpr std::size_t kUndrawPart = std::size_t(1) << 16;
  PixelRect all{proj.width, proj.height, -1, -1};
  const std::size_t bands = std::size_t((proj.height + (1 << kBandShift) - 1) >> kBandShift);
  band_x0.assign(bands, proj.width);
  band_x1.assign(bands, -1);
  while (count > 0) {
    const std::size_t part = std::min(count, kUndrawPart);
    undraw_part(fb, part);
    count -= part;
    if (changed.x0 > changed.x1) continue;
    all = PixelRect{std::min(all.x0, changed.x0), std::min(all.y0, changed.y0), std::max(all.x1, changed.x1),
                    std::max(all.y1, changed.y1)};
  }
  changed = all.x0 <= all.x1 ? all : PixelRect{};
  // The changed bands' rectangles (the whole image if the near plane cut a tet), consecutive bands
  // of the same extent as one.
  if (changed.x0 > changed.x1 ||
      (changed.x0 == 0 && changed.y0 == 0 && changed.x1 == proj.width - 1 && changed.y1 == proj.height - 1)) {
    changed_is_one_rect();
    return;
  }
  changed_list.clear();
  for (std::size_t band = 0; band < bands; ++band) {
    if (band_x0[band] > band_x1[band]) continue;
    const int y0 = std::max(int(band) << kBandShift, changed.y0);
    const int y1 = std::min(((int(band) + 1) << kBandShift) - 1, changed.y1);
    PixelRect* last = changed_list.empty() ? nullptr : &changed_list.back();
    if (last && last->x0 == band_x0[band] && last->x1 == band_x1[band] && last->y1 + 1 == y0)
      last->y1 = y1;
    else
      changed_list.push_back(PixelRect{band_x0[band], y0, band_x1[band], y1});
  }
}

// undraw of count > 0 tets, at most kUndrawPart.
inline void TetRasterizer::Impl::undraw_part(Framebuffer& fb, std::size_t count) {
  if (written.empty()) {
    written.assign(std::size_t(mask_words) * std::size_t(fb.height), 0);
    tile_full.assign(std::size_t(mask_words) * std::size_t((fb.height >> kBandShift) + 1), 0);
  }
  FOXI_ASSERT(count > 0 && count <= history.size(),
              "undraw of " << count << " of " << history.size() << " tets");
  FOXI_ASSERT(drawn_box.size() == history.size() && drawn_reach.size() == history.size(),
              "per-tet undo records: " << drawn_box.size() << " boxes, " << drawn_reach.size()
                                       << " reaches for " << history.size() << " drawn tets");
  const std::size_t first = history.size() - count;
  auto first_save = [&](const Lane& lane) {
    return std::size_t(std::lower_bound(lane.saves.begin(), lane.saves.end(), first,
                                        [](const Save& s, std::size_t at) { return s.at < at; }) -
                       lane.saves.begin());
  };
  const int threads = count >= 256 ? std::min(params.threads, std::max(1, fb.height >> kBandShift)) : 1;
  const SmallBox* small_box = drawn_box.data() + first;
  auto box_of = [small_box](std::size_t i) {
    const SmallBox& small = small_box[i];
    return Box{small.x0, small.x1, small.y0, small.y1};
  };
  // The threads' split of the rows (see split_rows) needs only an estimate of each band's work:
  // every 8th box's.
  std::vector<double> band_work(
      threads > 1 ? std::size_t((fb.height + (1 << kBandShift) - 1) >> kBandShift) : 0, 0.0);
  if (threads > 1)
    for (std::size_t i = 0; i < count; i += 8) {
      const Box b = box_of(i);
      if (b.x0 <= b.x1 && b.y0 >= 0) add_band_work(band_work, b);
    }
  // One pass over the undrawn tets' boxes: the rectangle they may change (`changed`, the whole
  // image if the near plane cuts one) and each band's extent (see changed_rects).
  auto find_extent = [&] {
    PixelRect rect{fb.width, fb.height, -1, -1};
    bool unknown = false;
    for (std::size_t i = 0; i < count; ++i) {
      const Box b = box_of(i);
      if (b.x0 > b.x1) continue;
      if (b.y0 < 0) {
        unknown = true;
        continue;
      }
      rect = PixelRect{std::min(rect.x0, b.x0), std::min(rect.y0, b.y0), std::max(rect.x1, b.x1),
                       std::max(rect.y1, b.y1)};
      // The box's first and last band (often the same), then any between: no branch on its height.
      const int band_a = b.y0 >> kBandShift, band_b = b.y1 >> kBandShift;
      band_x0[std::size_t(band_a)] = std::min(band_x0[std::size_t(band_a)], b.x0);
      band_x1[std::size_t(band_a)] = std::max(band_x1[std::size_t(band_a)], b.x1);
      band_x0[std::size_t(band_b)] = std::min(band_x0[std::size_t(band_b)], b.x0);
      band_x1[std::size_t(band_b)] = std::max(band_x1[std::size_t(band_b)], b.x1);
      for (int band = band_a + 1; band < band_b; ++band) {
        band_x0[std::size_t(band)] = std::min(band_x0[std::size_t(band)], b.x0);
        band_x1[std::size_t(band)] = std::max(band_x1[std::size_t(band)], b.x1);
      }
    }
    changed = unknown              ? PixelRect{0, 0, fb.width - 1, fb.height - 1}
              : rect.x0 <= rect.x1 ? rect
                                   : PixelRect{};
  };
  // Thread k takes rows [split[k], split[k + 1]): the lanes' saved pixels in those rows and the
  // undrawn tets' faces there, walked in drawing order.
  std::atomic<int> unkept{0};  // 1 once the undrawn tets are off `kept`, 2 if that will not happen
  std::atomic<bool> extent_found{false};
  auto work = [&](const std::vector<int>& split, int k) {
    // Thread 0 (the caller's) takes the tets off `kept` while thread 1 finds their extent, then
    // all wait for `kept`, which the walk reads, and before clearing the mask for the extent (first
    // thing: nothing above the waits throws).
    if (k == 0)
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t t = history[first + i];
        kept[t >> 6] &= ~(std::uint64_t(1) << (t & 63));
      }
    if (k == (threads > 1 ? 1 : 0)) {
      find_extent();
      extent_found.store(true, std::memory_order_release);
    }
    if (threads > 1) {
      if (k == 0) unkept.store(1, std::memory_order_release);
      int state;
      while ((state = unkept.load(std::memory_order_acquire)) == 0) detail::relax();
      if (state == 2) return;  // thread 0 will not run (a part could not be handed out)
    }
    const Rows rows{0, 1, split[std::size_t(k)], split[std::size_t(k) + 1] - 1};
    const std::uint32_t p_lo = std::uint32_t(rows.lo) * std::uint32_t(fb.width),
                        p_hi = std::uint32_t(rows.hi + 1) * std::uint32_t(fb.width);
    std::vector<std::size_t> save(lanes.size());
    for (std::size_t l = 0; l < lanes.size(); ++l) save[l] = first_save(lanes[l]);
    // Whether tet j may show in these rows is decided kFar tets ahead (a tet hidden then stays
    // hidden, the mask only grows; one that shows then but is hidden when met writes nothing, the
    // mask holding its pixels): its mesh rows are fetched then, its nodes' positions and shades'
    // inputs kNear tets ahead, so that the walk finds them in the cache.
    constexpr std::size_t kFar = 24, kNear = 12, kRing = 32;
    bool may_show[kRing];
    const std::uint16_t* reach = drawn_reach.data() + first;
    auto repaints = [&](std::size_t j) { return reach[j] > j || reach[j] == 0xffff; };
    auto look_far = [&](std::size_t j) {
      const Box b = box_of(j);
      const bool may = b.x0 <= b.x1 && b.y0 >= 0 && rows.any(b.y0, b.y1) && !box_written(rows, b, fb.height);
      may_show[j % kRing] = may;
      if (!may || !repaints(j)) return;
      const std::uint32_t t = history[first + j];
      __builtin_prefetch(&mesh->tet[4 * std::size_t(t)]);
      __builtin_prefetch(&adjacency->neighbour[4 * std::size_t(t)]);
    };
    auto look_near = [&](std::size_t j) {
      if (!may_show[j % kRing] || !repaints(j)) return;
      const std::uint32_t t = history[first + j];
      const std::uint32_t* tv = &mesh->tet[4 * std::size_t(t)];
      const std::uint32_t* nb = &adjacency->neighbour[4 * std::size_t(t)];
      for (int f = 0; f < 4; ++f)
        if (nb[f] != kNone && is_kept(nb[f] >> 2) && !mesh->tet_region.empty())
          __builtin_prefetch(&mesh->tet_region[nb[f] >> 2]);
      for (int c = 0; c < 4; ++c) {  // it repaints a face: its nodes' positions and shades' inputs
        __builtin_prefetch(&node_view[tv[c]]);
      }
    };
    for (std::size_t j = 0; j < std::min(count, kFar); ++j) look_far(j);
    for (std::size_t j = 0; j < std::min(count, kNear); ++j) look_near(j);
    for (std::size_t i = 0; i < count; ++i) {
      if (i + kFar < count) look_far(i + kFar);
      if (i + kNear < count) look_near(i + kNear);
      const std::uint32_t t = history[first + i];
      const Box b = box_of(i);
      const bool shows = b.x0 <= b.x1 && (b.y0 < 0 || may_show[i % kRing]);
      for (std::size_t l = 0; l < lanes.size(); ++l) {
        const Lane& lane = lanes[l];
        if (save[l] >= lane.saves.size() || lane.saves[save[l]].at != first + i) continue;
        const std::size_t s = save[l]++;
        if (!shows) continue;
        const std::size_t to = save_end(lane, s);
        for (std::size_t j = lane.saves[s].offset; j < to; ++j) {
          const std::uint32_t p = lane.saved_pixel[j];
          if (p < p_lo || p >= p_hi) continue;
          const std::uint32_t x = p % std::uint32_t(fb.width), y = p / std::uint32_t(fb.width);
          std::uint64_t& word = written[std::size_t(y) * std::size_t(mask_words) + (x >> 6)];
          const std::uint64_t bit = std::uint64_t(1) << (x & 63);
          if (word & bit) continue;
          word |= bit;
          fb.rgba[p] = lane.saved_rgba[j];
          fb.id[p] = lane.saved_id[j];
          fb.shade[p] = lane.saved_shade[j];
        }
      }
      if (!shows) continue;
      // A tet cut by the near plane (its box not known) saved every pixel of its faces (request_saves).
      if (b.y0 < 0 || !repaints(i)) continue;
      UndrawTet u;
      gather_undrawn(t, u);
      shade_repainted(u);
      // Each back face shared with a kept tet is repainted as that tet's front face: the same
      // polygon (face_polygon's back order), in its colour. One shared with an earlier tet of the
      // batch is already written: that tet, met before t in this walk, wrote every pixel of its
      // projection in these rows.
      for (int f = 0; f < 4; ++f) {
        if (!(u.repaint >> f & 1)) continue;
        const auto& face = kFace[f];
        PolyVertex poly[3];
        for (int j = 0; j < 3; ++j) {
          poly[j].X = u.X[face[j]];
          poly[j].Y = u.Y[face[j]];
        }
        if (field != nullptr && field->graded) {  // the neighbour's positions, and nearness for perspective
          float pos[4];
          neighbour_positions(u.neighbour[f] >> 2, u.node, pos);
          for (int j = 0; j < 3; ++j) {
            poly[j].pos = pos[face[j]];
            poly[j].w = nearness(cam(u.node[face[j]]));
          }
        }
        FaceSetup fs;
#ifdef FOXI_AVX512_REPAINT
        if (fast_repaint && setup_repaint(fs, u.neighbour[f] >> 2, u.shade[f], poly)) {
          repaint_triangle_avx512(fb, rows, fs, poly);
          continue;
        }
#endif
        setup_face(fs, u.neighbour[f] >> 2, u.shade[f], poly, 3);
        raster_polygon(fb, rows, fs, poly, 3);  // seldom hidden: not worth the test
      }
    }
    // The mask back to zero on the changed rows of these rows (whole bands: their tiles too).
    while (!extent_found.load(std::memory_order_acquire)) detail::relax();  // long since, as a rule
    const int y0 = std::max(rows.lo, changed.y0), y1 = std::min(rows.hi, changed.y1);
    if (y0 <= y1) zero_mask(y0, y1);
  };
  if (threads == 1) {
    work({0, fb.height}, 0);
  } else {
    const std::vector<int> split = split_rows(band_work, threads, fb.height);
    run_parts(
        threads, [&](int k) { work(split, k); }, [&] { unkept.store(2, std::memory_order_release); });
  }
  history.resize(first);
  drawn_box.resize(first);
  drawn_reach.resize(first);
  for (Lane& lane : lanes) {
    lane.saves.resize(first_save(lane));
    while (!lane.regions.empty() && lane.regions.back().first_save >= lane.saves.size()) {
      lane.saved_pixel.resize(lane.regions.back().first_pixel);
      lane.regions.pop_back();
    }
    lane.saved_rgba.resize(lane.saved_pixel.size());
    lane.saved_id.resize(lane.saved_pixel.size());
    lane.saved_shade.resize(lane.saved_pixel.size());
    FOXI_ASSERT(lane.saves.empty() ||
                    (lane.saves.back().at < first && lane.saves.back().offset <= lane.saved_pixel.size()),
                "a save of an undrawn tet (position " << lane.saves.back().at << " of " << first
                                                      << ") or past the saved pixels");
  }
}

// Adds box b's undraw work to `work` (per band of 16 rows): its width plus a per-row cost, times its
// rows, all on the band of its middle row (a box is a few bands tall at most where it matters: the
// split need only be about even).
inline void TetRasterizer::Impl::add_band_work(std::vector<double>& work, const Box& b) {
  constexpr int kRowCost = 16;  // pixels' worth of per-row setup
  work[std::size_t(((b.y0 + b.y1) >> 1) >> kBandShift)] +=
      double((b.x1 - b.x0 + 1 + kRowCost) * (b.y1 - b.y0 + 1));
}

// Row ranges for `parts` threads undrawing, from their work per band (add_band_work; a box cut by
// the near plane, unknown, counts on none): split[k] to split[k + 1] - 1 for thread k, whole bands
// of 16 rows (a thread's mask tiles are its own), of about equal work. Contiguous ranges, not
// interleaved bands: a tet is a few bands tall, and each thread whose rows it touches pays its setup.
inline std::vector<int> TetRasterizer::Impl::split_rows(const std::vector<double>& work, int parts,
                                                        int height) {
  const int bands = int(work.size());
  double total = 0;
  for (double w : work) total += w;
  std::vector<int> split(std::size_t(parts) + 1, height);
  split[0] = 0;
  double sum = 0;
  int k = 1;
  for (int band = 0; band < bands && k < parts; ++band) {
    sum += work[std::size_t(band)];
    while (k < parts && sum >= total * double(k) / double(parts))
      split[std::size_t(k++)] = std::min(height, (band + 1) << kBandShift);
  }
  for (; k < parts; ++k) split[std::size_t(k)] = height;
  return split;
}

void TetRasterizer::Impl::forget() {
  std::fill(kept.begin(), kept.end(), 0);
  std::fill(tainted.begin(), tainted.end(), 0);
  risky.clear();
  risky_tile.clear();
  any_tainted = false;
  history.clear();
  drawn_box.clear();
  drawn_reach.clear();
  for (Lane& lane : lanes) lane = Lane{};
}

std::size_t TetRasterizer::Impl::saved_pixels() const {
  std::size_t n = 0;
  for (const Lane& lane : lanes) n += lane.saved_rgba.size();
  return n;
}

std::size_t TetRasterizer::Impl::undo_bytes() const {
  std::size_t bytes = (history.capacity() + drawn_at.capacity() + slot.capacity() + before_rgba.capacity() +
                       before_id.capacity()) *
                          sizeof(std::uint32_t) +
                      (shown.capacity() + written.capacity() + kept.capacity()) * sizeof(std::uint64_t) +
                      drawn_box.capacity() * sizeof(SmallBox) +
                      drawn_reach.capacity() * sizeof(std::uint16_t) + before_shade.capacity();
  for (const Lane& lane : lanes)
    bytes += (lane.saved_pixel.capacity() + lane.saved_rgba.capacity() + lane.saved_id.capacity()) *
                 sizeof(std::uint32_t) +
             lane.saved_shade.capacity() + lane.saves.capacity() * sizeof(Save) +
             lane.regions.capacity() * sizeof(SaveRegion);
  return bytes;
}

}  // namespace foxi
