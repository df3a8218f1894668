// The painter's pixels (TetRasterizer::Impl, raster_impl.hpp): a polygon's rows, spans and edge-darkened
// pixels (scalar and SSE2), written or recorded for undo.
#include "raster_impl.hpp"
#include "depth_tie.hpp"

#include <cstring>

namespace foxi {

inline void TetRasterizer::Impl::shade_pixel(Framebuffer& fb, const FaceSetup& fs, int x, int y) const {
  const std::size_t p = std::size_t(y) * std::size_t(fb.width) + std::size_t(x);
  if (params.depth_buffer) {
    const double ta = fs.da * (x + 0.5 - fs.x0), tb = fs.db * (y + 0.5 - fs.y0);
    if (!depth_test(fb, p, fs.w0 + ta + tb, fs.da, fs.db, std::abs(fs.w0) + std::abs(ta) + std::abs(tb)))
      return;
  }
  color_row(y)[x] = face_color(fs, x, y, fb.shade[p]);
  fb.id[p] = fs.tet;
}

// The colour of a face at pixel (x, y): flat, darkened near its edges; s its shade.
inline std::uint32_t TetRasterizer::Impl::face_color(const FaceSetup& fs, int x, int y,
                                                     std::uint8_t& s) const {
  std::int64_t e[4];
  for (int k = 0; k < 4; ++k) e[k] = fs.ea[k] * x + fs.eb[k] * y + fs.ec[k];
  if (fs.graded) return graded_color(fs, x, y, nearest_edge(fs, e[0], e[1], e[2], e[3]), s);
  return darkened(fs, nearest_edge(fs, e[0], e[1], e[2], e[3]), s);
}

// The face's colour at distance d from its nearest edge line: its shade times
// 1 - darkness (1 - d / width) (see shade_of), s.
inline std::uint32_t TetRasterizer::Impl::darkened(const FaceSetup& fs, double d, std::uint8_t& s) const {
  if (!(d < params.edge_width)) {
    s = fs.shade;
    return fs.color;
  }
  s = shade_of(fs.level, edge_base + edge_slope * std::max(0.0, d));
  return shade_color(fs.base, s);
}

// One row run of a face. Painter mode: only the pixels not yet written (see `written`), then the
// whole run is marked written.
[[gnu::always_inline]] inline void TetRasterizer::Impl::shade_row(Framebuffer& fb, const FaceSetup& fs, int y,
                                                                  int lo, int hi) {
  if (params.depth_buffer) {
    for (int x = lo; x <= hi; ++x) shade_pixel(fb, fs, x, y);
    return;
  }
  if (!use_mask) {
    shade_span(fb, fs, y, lo, hi);
    return;
  }
  std::uint64_t* row = &written[std::size_t(y) * std::size_t(mask_words)];
  const int w0 = lo >> 6, w1 = hi >> 6;
  const std::uint64_t m0 = ~std::uint64_t(0) << (lo & 63), m1 = ~std::uint64_t(0) >> (63 - (hi & 63));
  if (w0 == w1) {  // a short run: none of it written yet, or all of it (the common cases)
    const std::uint64_t m = m0 & m1, set = row[w0] & m;
    if (set == m) return;
    if (set == 0) {
      if (recording)
        record_span(fb, fs, y, lo, hi);
      else
        shade_span(fb, fs, y, lo, hi);
      row[w0] |= m;
      return;
    }
  }
  int x = lo;
  while (x <= hi) {
    // The first unwritten pixel at or after x.
    int w = x >> 6;
    std::uint64_t free = ~row[w] & (~std::uint64_t(0) << (x & 63));
    while (free == 0 && w < w1) free = ~row[++w];
    if (free == 0) break;
    const int a = (w << 6) + std::countr_zero(free);
    if (a > hi) break;
    // The first written pixel after a (or past the run).
    w = a >> 6;
    std::uint64_t set = row[w] & (~std::uint64_t(0) << (a & 63));
    while (set == 0 && w < w1) set = row[++w];
    const int b = set == 0 ? hi + 1 : std::min(hi + 1, (w << 6) + std::countr_zero(set));
    if (recording)
      record_span(fb, fs, y, a, b - 1);
    else
      shade_span(fb, fs, y, a, b - 1);
    x = b;
  }
  if (w0 == w1) {
    row[w0] |= m0 & m1;
  } else {
    row[w0] |= m0;
    for (int w = w0 + 1; w < w1; ++w) row[w] = ~std::uint64_t(0);
    row[w1] |= m1;
  }
}

// Undoable drawing, a run of pixels not done in this batch: those not yet shown get the face
// (their previous contents kept in `before`), the others hold undraw requests of tets drawn later
// (nearer) whose unshared back faces cover them: this face is what lay behind, their saved value.
inline void TetRasterizer::Impl::record_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) {
  const std::size_t row = std::size_t(y) * std::size_t(fb.width);
  std::uint64_t* shown_row = &shown[std::size_t(y) * std::size_t(mask_words)];
  for (int x = lo; x <= hi;) {
    // The run of pixels from x with x's shown bit, within x's mask word (a word of bits at a time).
    const std::uint64_t bits = shown_row[x >> 6] >> (x & 63);
    const bool was_shown = bits & 1;
    const std::uint64_t change = was_shown ? ~bits : bits;
    const int left = 64 - (x & 63);
    const int e = std::min(hi, x + (change == 0 ? left : std::min(left, std::countr_zero(change))) - 1);
    if (!was_shown) {
      std::copy_n(fb.rgba.begin() + std::ptrdiff_t(row + std::size_t(x)), e - x + 1,
                  before_rgba.begin() + std::ptrdiff_t(row + std::size_t(x)));
      std::copy_n(fb.id.begin() + std::ptrdiff_t(row + std::size_t(x)), e - x + 1,
                  before_id.begin() + std::ptrdiff_t(row + std::size_t(x)));
      std::copy_n(fb.shade.begin() + std::ptrdiff_t(row + std::size_t(x)), e - x + 1,
                  before_shade.begin() + std::ptrdiff_t(row + std::size_t(x)));
      shade_span(fb, fs, y, x, e);
      shown_row[x >> 6] |= (~std::uint64_t(0) >> (63 - (e - x))) << (x & 63);  // [x, e] in one word
      Lane& lane = lanes[std::size_t(lane_of(y))];
      if (lane.unshown_requests) {  // a nearer tet asked for a pixel it did not show: this is behind it
        for (int k = x; k <= e; ++k) {
          std::uint32_t& request = slot[row + std::size_t(k)];
          if (request == kNone) continue;
          lane.saved_rgba[request] = fb.rgba[row + std::size_t(k)];
          lane.saved_id[request] = fb.id[row + std::size_t(k)];
          lane.saved_shade[request] = fb.shade[row + std::size_t(k)];
          request = kNone;
        }
      }
    } else {
      Lane& lane = lanes[std::size_t(lane_of(y))];
      for (int k = x; k <= e; ++k) {
        std::uint32_t& request = slot[row + std::size_t(k)];
        if (request == kNone) continue;  // cannot happen: shown and not done means a request
        lane.saved_rgba[request] = face_color(fs, k, y, lane.saved_shade[request]);
        lane.saved_id[request] = fs.tet;
        request = kNone;
      }
    }
    x = e + 1;
  }
}

// Painter mode, one run of pixels [lo, hi] of row y: constant colour in the part of the run at
// least edge_width from every edge line, each other pixel shaded as face_color does, stepping the
// edge functions along the row. The flat part is solved for in floating point, narrowed by a
// pixel, and checked exactly at its ends (the distance to each line is monotone along the row), so
// every pixel gets exactly face_color's colour whatever the run. Runs of 12 pixels or fewer (most
// runs of a fine mesh's faces) are not worth solving for: inlined here, each pixel shaded.
[[gnu::always_inline]] inline void TetRasterizer::Impl::shade_span(Framebuffer& fb, const FaceSetup& fs,
                                                                   int y, int lo, int hi) const {
  if (fs.graded) {
    graded_span(fb, fs, y, lo, hi);
    return;
  }
  if (hi - lo >= 12 || fs.lines == 0) {
    shade_long_span(fb, fs, y, lo, hi);
    return;
  }
  std::uint32_t* rgba = color_row(y);
  std::uint32_t* id = fb.id.data() + std::size_t(y) * std::size_t(fb.width);
  std::uint8_t* shade = fb.shade.data() + std::size_t(y) * std::size_t(fb.width);
  if (fs.exact_double) [[likely]] {  // the edge functions at lo straight in double (no 64-bit products)
    const double dx = double(lo), dy = double(y);
    double d[4];
    for (int k = 0; k < 3; ++k) d[k] = fs.step[k] * dx + (fs.step_y[k] * dy + fs.at0[k]);
    if (fs.lines > 3) {
      d[3] = fs.step[3] * dx + (fs.step_y[3] * dy + fs.at0[3]);
      edge_pixels_stepped<true>(rgba, id, shade, fs, d, fs.step, lo, hi);
    } else {
      d[3] = 0;
      edge_pixels_stepped<false>(rgba, id, shade, fs, d, fs.step, lo, hi);
    }
    return;
  }
  std::int64_t e[4];
  edges_at(fs, lo, y, e);
  edge_pixels(rgba, id, shade, fs, e, lo, hi);
}

// The edge functions of fs's lines at pixel (x, y) (the padding line's is constant).
inline void TetRasterizer::Impl::edges_at(const FaceSetup& fs, int x, int y, std::int64_t* e) {
  for (int k = 0; k < 3; ++k) e[k] = fs.ea[k] * x + fs.eb[k] * y + fs.ec[k];
  e[3] = fs.lines > 3 ? fs.ea[3] * x + fs.eb[3] * y + fs.ec[3] : fs.ec[3];
}

// Pixels [from, to] of a row shaded one by one (rgba, id: the row), e: the edge functions at
// `from`, stepped on past `to`. The edge functions and colours are held in registers; a face of 3
// lines or fewer skips the fourth (padding, never the nearest).
[[gnu::always_inline]] inline void TetRasterizer::Impl::edge_pixels(std::uint32_t* rgba, std::uint32_t* id,
                                                                    std::uint8_t* shade, const FaceSetup& fs,
                                                                    std::int64_t* e, int from, int to) const {
  if (fs.lines > 3)
    edge_pixels_of<true>(rgba, id, shade, fs, e, from, to);
  else
    edge_pixels_of<false>(rgba, id, shade, fs, e, from, to);
}

template <bool kFourLines>
[[gnu::always_inline]] inline void TetRasterizer::Impl::edge_pixels_of(std::uint32_t* rgba, std::uint32_t* id,
                                                                       std::uint8_t* shade,
                                                                       const FaceSetup& fs, std::int64_t* e,
                                                                       int from, int to) const {
  if (!fs.exact_double) [[unlikely]] {  // huge coordinates (near-plane cuts)
    edge_pixels_stepped<kFourLines>(rgba, id, shade, fs, e, fs.ea, from, to);
    return;
  }
  // Stepped in double (see FaceSetup::exact_double): no conversion per pixel.
  double d[4] = {double(e[0]), double(e[1]), double(e[2]), kFourLines ? double(e[3]) : 0};
  edge_pixels_stepped<kFourLines>(rgba, id, shade, fs, d, fs.step, from, to);
  if (to >= from)
    for (int k = 0; k < 4; ++k) e[k] += fs.ea[k] * (to - from + 1);
}

// The loop of edge_pixels_of, its edge functions e (at `from`, stepped by `step` per pixel; integers
// are left past `to`) 64-bit integers or exact doubles.
template <bool kFourLines, class Edge>
[[gnu::always_inline]] inline void TetRasterizer::Impl::edge_pixels_stepped(
    std::uint32_t* rgba, std::uint32_t* id, std::uint8_t* shade, const FaceSetup& fs, Edge* e,
    const Edge* step, int from, int to) const {
#ifdef __SSE2__
  if constexpr (std::is_same_v<Edge, double>) {
    edge_pixels_x4<kFourLines>(rgba, id, shade, fs, e, step, from, to);
    return;
  }
#endif
  const std::uint32_t tet = fs.tet, color = fs.color;
  const double w = params.edge_width;
  Edge e0 = e[0], e1 = e[1], e2 = e[2], e3 = e[3];
  const Edge s0 = step[0], s1 = step[1], s2 = step[2], s3 = step[3];
  const double i0 = fs.inv_len[0], i1 = fs.inv_len[1], i2 = fs.inv_len[2], i3 = fs.inv_len[3];
  for (int x = from; x <= to; ++x) {
    // As nearest_edge (min is exact: the order of the minima does not matter).
    const double d = kFourLines ? std::min(std::min(double(e0) * i0, double(e1) * i1),
                                           std::min(double(e2) * i2, double(e3) * i3))
                                : std::min(std::min(double(e0) * i0, double(e1) * i1), double(e2) * i2);
    if (d < w) {
      rgba[x] = darkened(fs, d, shade[x]);
    } else {
      rgba[x] = color;
      shade[x] = fs.shade;
    }
    id[x] = tet;
    e0 += s0;
    e1 += s1;
    e2 += s2;
    if (kFourLines) e3 += s3;
  }
  if constexpr (std::is_integral_v<Edge>) {  // (the double path steps the integers once)
    e[0] = e0;
    e[1] = e1;
    e[2] = e2;
    e[3] = e3;  // padding steps by 0
  }
}

#ifdef __SSE2__
// edge_pixels_stepped's exact-double loop four pixels at a time: each pixel goes through the same
// IEEE operations in the same order as the one-pixel loop, darkened() and shade_of (the edge
// functions are integers, so e + k step is the stepped value exactly; min and max differ from
// std::min and std::max only in the sign of a zero, which max(0, d), d < w and the clamp do not see;
// no FMA in an SSE2 build), and shade_color's integer rounding, so every pixel gets the same bits. A
// last group of fewer than 4 stores only its pixels.
template <bool kFourLines>
[[gnu::always_inline]] inline void TetRasterizer::Impl::edge_pixels_x4(std::uint32_t* rgba, std::uint32_t* id,
                                                                       std::uint8_t* shade,
                                                                       const FaceSetup& fs, const double* e,
                                                                       const double* step, int from,
                                                                       int to) const {
  if (to < from) return;
  const __m128d w = _mm_set1_pd(params.edge_width), zero = _mm_setzero_pd();
  const __m128d base = _mm_set1_pd(edge_base), slope = _mm_set1_pd(edge_slope);
  const __m128d level = _mm_set1_pd(fs.level), half = _mm_set1_pd(0.5), top = _mm_set1_pd(255);
  const __m128i r = _mm_set1_epi32(int(fs.base & 255u)), g = _mm_set1_epi32(int((fs.base >> 8) & 255u)),
                b = _mm_set1_epi32(int((fs.base >> 16) & 255u)), round = _mm_set1_epi32(128);
  const __m128i face_shade = _mm_set1_epi32(fs.shade);
  const __m128i color = _mm_set1_epi32(int(fs.color)), tet = _mm_set1_epi32(int(fs.tet));
  const __m128i alpha = _mm_set1_epi32(int(0xff000000u));
  const std::uint32_t flat_shades = 0x01010101u * fs.shade;
  // shade_color of 4 shades (32-bit lanes, each < 256: the 16-bit product is the whole product).
  auto channel = [&](__m128i s, __m128i c) {
    const __m128i t = _mm_add_epi32(_mm_mullo_epi16(s, c), round);
    return _mm_srli_epi32(_mm_add_epi32(t, _mm_srli_epi32(t, 8)), 8);
  };
  constexpr int kLines = kFourLines ? 4 : 3;
  __m128d lo[kLines], hi[kLines], inv[kLines], step4[kLines];  // pixels (x, x + 1), (x + 2, x + 3)
  for (int k = 0; k < kLines; ++k) {
    lo[k] = _mm_set_pd(e[k] + step[k], e[k]);
    hi[k] = _mm_set_pd(e[k] + 3 * step[k], e[k] + 2 * step[k]);
    inv[k] = _mm_set1_pd(fs.inv_len[k]);
    step4[k] = _mm_set1_pd(4 * step[k]);
  }
  for (int x = from;; x += 4) {
    __m128d d_lo = _mm_min_pd(_mm_mul_pd(lo[0], inv[0]), _mm_mul_pd(lo[1], inv[1]));
    __m128d d_hi = _mm_min_pd(_mm_mul_pd(hi[0], inv[0]), _mm_mul_pd(hi[1], inv[1]));
    if constexpr (kFourLines) {
      d_lo = _mm_min_pd(d_lo, _mm_min_pd(_mm_mul_pd(lo[2], inv[2]), _mm_mul_pd(lo[3], inv[3])));
      d_hi = _mm_min_pd(d_hi, _mm_min_pd(_mm_mul_pd(hi[2], inv[2]), _mm_mul_pd(hi[3], inv[3])));
    } else {
      d_lo = _mm_min_pd(d_lo, _mm_mul_pd(lo[2], inv[2]));
      d_hi = _mm_min_pd(d_hi, _mm_mul_pd(hi[2], inv[2]));
    }
    const __m128 darken = _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(d_lo, w)),
                                         _mm_castpd_ps(_mm_cmplt_pd(d_hi, w)), _MM_SHUFFLE(2, 0, 2, 0));
    __m128i out = color;
    std::uint32_t shades = flat_shades;  // the 4 pixels' shade bytes
    if (_mm_movemask_ps(darken) != 0) {
      // shade_of(level, base + slope max(0, d)) in each lane, as 32-bit integers.
      auto shade4 = [&](__m128d d) {
        const __m128d v =
            _mm_add_pd(_mm_mul_pd(level, _mm_add_pd(base, _mm_mul_pd(slope, _mm_max_pd(d, zero)))), half);
        return _mm_cvttpd_epi32(_mm_min_pd(_mm_max_pd(v, zero), top));
      };
      const __m128i m = _mm_castps_si128(darken);
      const __m128i s = _mm_or_si128(_mm_and_si128(m, _mm_unpacklo_epi64(shade4(d_lo), shade4(d_hi))),
                                     _mm_andnot_si128(m, face_shade));
      out = _mm_or_si128(_mm_or_si128(channel(s, r), _mm_slli_epi32(channel(s, g), 8)),
                         _mm_or_si128(_mm_slli_epi32(channel(s, b), 16), alpha));
      const __m128i packed = _mm_packs_epi32(s, s);
      shades = std::uint32_t(_mm_cvtsi128_si32(_mm_packus_epi16(packed, packed)));
    }
    const int left = to - x + 1;
    if (left >= 4) {
      _mm_storeu_si128(reinterpret_cast<__m128i*>(rgba + x), out);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(id + x), tet);
      std::memcpy(shade + x, &shades, 4);
      if (left == 4) return;
    } else {
      if (left >= 2) {
        _mm_storel_epi64(reinterpret_cast<__m128i*>(rgba + x), out);
        _mm_storel_epi64(reinterpret_cast<__m128i*>(id + x), tet);
      }
      std::memcpy(shade + x, &shades, std::size_t(left));  // little-endian: pixel k is byte k
      if (left != 2) {
        const int last = x + left - 1;
        rgba[last] = std::uint32_t(_mm_cvtsi128_si32(left == 1 ? out : _mm_srli_si128(out, 8)));
        id[last] = fs.tet;
      }
      return;
    }
    for (int k = 0; k < kLines; ++k) {
      lo[k] = _mm_add_pd(lo[k], step4[k]);
      hi[k] = _mm_add_pd(hi[k], step4[k]);
    }
  }
}
#endif

// shade_span's long runs (and faces without edge lines).
[[gnu::noinline]] void TetRasterizer::Impl::shade_long_span(Framebuffer& fb, const FaceSetup& fs, int y,
                                                            int lo, int hi) const {
  std::uint32_t* rgba = color_row(y);
  std::uint32_t* id = fb.id.data() + std::size_t(y) * std::size_t(fb.width);
  std::uint8_t* shade = fb.shade.data() + std::size_t(y) * std::size_t(fb.width);
  if (fs.lines == 0) {
    std::fill(rgba + lo, rgba + hi + 1, fs.color);
    std::fill(id + lo, id + hi + 1, fs.tet);
    std::fill(shade + lo, shade + hi + 1, fs.shade);
    return;
  }
  std::int64_t e[4];
  edges_at(fs, lo, y, e);
  int a = lo, b = hi;  // the flat part
  for (int k = 0; k < fs.lines && a <= b; ++k) {
    // e_k + ea_k (x - lo) >= flat_e_k beyond x = lo + t.
    if (fs.ea[k] == 0) {
      if (double(e[k]) < fs.flat_e[k]) b = a - 1;
      continue;
    }
    const double t = std::clamp((fs.flat_e[k] - double(e[k])) / double(fs.ea[k]), -4.0, double(hi - lo) + 4);
    const int i = int(t);  // truncation, then floor or ceiling by one test
    if (fs.ea[k] > 0)
      a = std::max(a, lo + i - int(double(i) > t) + 1);
    else
      b = std::min(b, lo + i + int(double(i) < t) - 1);
  }
  if (a <= b) {
    std::int64_t ea[4], eb[4];
    for (int k = 0; k < 4; ++k) {
      ea[k] = e[k] + fs.ea[k] * (a - lo);
      eb[k] = e[k] + fs.ea[k] * (b - lo);
    }
    if (!(nearest_edge(fs, ea[0], ea[1], ea[2], ea[3]) >= params.edge_width &&
          nearest_edge(fs, eb[0], eb[1], eb[2], eb[3]) >= params.edge_width))
      b = a - 1;
  }
  if (a > b) {  // no flat part
    edge_pixels(rgba, id, shade, fs, e, lo, hi);
    return;
  }
  edge_pixels(rgba, id, shade, fs, e, lo, a - 1);
  std::fill(rgba + a, rgba + b + 1, fs.color);
  std::fill(id + a, id + b + 1, fs.tet);
  std::fill(shade + a, shade + b + 1, fs.shade);
  for (int k = 0; k < 4; ++k) e[k] += fs.ea[k] * (b + 1 - a);
  edge_pixels(rgba, id, shade, fs, e, b + 1, hi);
}

// Recolouring (recolor.cpp): the runs of row y in [lo, hi] that show the face's tet are shaded again
// as the painter shades a span (the same bits whatever the run's bounds, see FaceSetup).
void TetRasterizer::Impl::recolor_row(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const {
  const std::uint32_t* id = &fb.id[std::size_t(y) * std::size_t(fb.width)];
  for (int x = lo; x <= hi;) {
    while (x <= hi && id[x] != fs.tet) ++x;
    const int a = x;
    while (x <= hi && id[x] == fs.tet) ++x;
    if (a < x) shade_span(fb, fs, y, a, x - 1);
  }
}

// Draws a convex polygon (positive area) as a fan from vertex 0.
// raster_polygon's work; kRecolor: recolor_row in place of shade_row (a template, so that the painter's
// rows stay as they were, without a test of the mode).
template <bool kRecolor>
[[gnu::always_inline]] inline void TetRasterizer::Impl::raster_fan(Framebuffer& fb, const Rows& rows,
                                                                   FaceSetup& fs, const PolyVertex* poly,
                                                                   int n) {
  for (int q = 1; q + 1 < n; ++q) {
    const int i = reverse ? n - 1 - q : q;  // painter mode draws the fan back to front too
    std::int64_t X[3] = {poly[0].X, poly[i].X, poly[i + 1].X}, Y[3] = {poly[0].Y, poly[i].Y, poly[i + 1].Y};
    std::int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area <= 0) continue;
    if (params.depth_buffer) {
      const double inv = double(kOne) * double(kOne) / double(area), s = 1.0 / double(kOne);
      const double x1 = double(X[1] - X[0]) * s, y1 = double(Y[1] - Y[0]) * s;
      const double x2 = double(X[2] - X[0]) * s, y2 = double(Y[2] - Y[0]) * s;
      const double w1 = poly[i].w - poly[0].w, w2 = poly[i + 1].w - poly[0].w;
      fs.x0 = double(X[0]) * s;
      fs.y0 = double(Y[0]) * s;
      fs.w0 = poly[0].w;
      fs.da = (w1 * y2 - w2 * y1) * inv;
      fs.db = (x1 * w2 - x2 * w1) * inv;
    }
    if (fs.graded) {
      // The triangle's corners in a canonical order (by y, then x), so that the plane has the same
      // bits however the polygon was given: undraw repaints a neighbour's face from the other tet's
      // corners, and must give its pixels the colours drawing it gave.
      const PolyVertex* v[3] = {&poly[0], &poly[i], &poly[i + 1]};
      auto before = [](const PolyVertex* a, const PolyVertex* b) {
        return a->Y != b->Y ? a->Y < b->Y : a->X < b->X;
      };
      if (before(v[1], v[0])) std::swap(v[0], v[1]);
      if (before(v[2], v[1])) std::swap(v[1], v[2]);
      if (before(v[1], v[0])) std::swap(v[0], v[1]);
      const std::int64_t area_c =
          (v[1]->X - v[0]->X) * (v[2]->Y - v[0]->Y) - (v[1]->Y - v[0]->Y) * (v[2]->X - v[0]->X);
      const double inv = double(kOne) * double(kOne) / double(area_c), s = 1.0 / double(kOne);
      const double x1 = double(v[1]->X - v[0]->X) * s, y1 = double(v[1]->Y - v[0]->Y) * s;
      const double x2 = double(v[2]->X - v[0]->X) * s, y2 = double(v[2]->Y - v[0]->Y) * s;
      double g[3], h[3];
      for (int k = 0; k < 3; ++k) {
        h[k] = proj.perspective ? v[k]->w : 1.0;
        g[k] = double(v[k]->pos) * h[k];
      }
      fs.gx0 = double(v[0]->X) * s;
      fs.gy0 = double(v[0]->Y) * s;
      fs.g0 = g[0];
      fs.ga = ((g[1] - g[0]) * y2 - (g[2] - g[0]) * y1) * inv;
      fs.gb = (x1 * (g[2] - g[0]) - x2 * (g[1] - g[0])) * inv;
      fs.h0 = h[0];
      fs.ha = ((h[1] - h[0]) * y2 - (h[2] - h[0]) * y1) * inv;
      fs.hb = (x1 * (h[2] - h[0]) - x2 * (h[1] - h[0])) * inv;
    }
    raster_triangle(X, Y, fb.width, fb.height, rows, [&](int y, int lo, int hi) {
      if constexpr (kRecolor)
        recolor_row(fb, fs, y, lo, hi);
      else
        shade_row(fb, fs, y, lo, hi);
    });
  }
}

void TetRasterizer::Impl::raster_polygon(Framebuffer& fb, const Rows& rows, FaceSetup& fs,
                                         const PolyVertex* poly, int n) {
  raster_fan<false>(fb, rows, fs, poly, n);
}

void TetRasterizer::Impl::recolor_polygon(Framebuffer& fb, const Rows& rows, FaceSetup& fs,
                                          const PolyVertex* poly, int n) {
  raster_fan<true>(fb, rows, fs, poly, n);
}

}  // namespace foxi
