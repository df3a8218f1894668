// Undraw's AVX-512 repaint of a triangle (TetRasterizer::Impl, raster_impl.hpp); compiled for that
// target by its attribute and chosen at run time (avx512_repaint).
#include "raster_impl.hpp"

namespace foxi {

#ifdef FOXI_AVX512_REPAINT
// Undraw's repaint of a triangle face in painter mode with the mask (not recording), fs from
// setup_repaint for poly[0..2] (3 mesh-edge lines exact in double, edge k from vertex k to k + 1): the pixels
// raster_triangle covers and shade_row writes, with the same bits, eight at a time. Line k is edge
// k's coverage function without the top-left bias, so a pixel is covered when every line's value is
// at least 0 (top-left edges) or 1 (the others); the colour goes through edge_pixels_x4's
// operations (no FMA: viz is built with -ffp-contract=off). A row's candidate pixels come from a
// floating-point bound on each edge, widened to whole pixels, then tested exactly.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's own _mm512_undefined_pd in its intrinsics
#endif
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2"))) void
TetRasterizer::Impl::repaint_triangle_avx512(Framebuffer& fb, const Rows& rows, const FaceSetup& fs,
                                             const PolyVertex* poly) {
  const std::int64_t X[3] = {poly[0].X, poly[1].X, poly[2].X}, Y[3] = {poly[0].Y, poly[1].Y, poly[2].Y};
  if ((X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]) <= 0) return;
  const std::int64_t minx = std::min({X[0], X[1], X[2]}), maxx = std::max({X[0], X[1], X[2]});
  const std::int64_t miny = std::min({Y[0], Y[1], Y[2]}), maxy = std::max({Y[0], Y[1], Y[2]});
  const int bx0 = int(std::max<std::int64_t>(0, -floor_div(-(minx - kHalf), kOne)));
  const int bx1 = int(std::min<std::int64_t>(fb.width - 1, floor_div(maxx - kHalf, kOne)));
  const int by0 = int(std::max<std::int64_t>({0, -floor_div(-(miny - kHalf), kOne), rows.lo}));
  const int by1 = int(std::min<std::int64_t>({fb.height - 1, floor_div(maxy - kHalf, kOne), rows.hi}));
  if (bx0 > bx1 || by0 > by1) return;
  double least[3], inv_a[3];  // per edge: the least covered value (0 or 1), 1 / its x step
  __m512d a[3], a8[3], inv[3], at_least[3];
  for (int k = 0; k < 3; ++k) {
    const int j = k == 2 ? 0 : k + 1;
    const std::int64_t dx = X[j] - X[k], dy = Y[j] - Y[k];
    least[k] = owns_boundary(dx, dy) ? 0 : 1;
    inv_a[k] = fs.step[k] != 0 ? 1 / fs.step[k] : 0;
    a[k] = _mm512_set1_pd(fs.step[k]);
    a8[k] = _mm512_set1_pd(8 * fs.step[k]);  // exact: 8 pixels' step of a line exact in double
    inv[k] = _mm512_set1_pd(fs.inv_len[k]);
    at_least[k] = _mm512_set1_pd(least[k]);
  }
  const __m512d lane = _mm512_set_pd(7, 6, 5, 4, 3, 2, 1, 0);
  const __m512d width = _mm512_set1_pd(params.edge_width), base = _mm512_set1_pd(edge_base),
                slope = _mm512_set1_pd(edge_slope);
  const __m512d level = _mm512_set1_pd(fs.level), half = _mm512_set1_pd(0.5), zero = _mm512_setzero_pd(),
                top = _mm512_set1_pd(255);
  const __m256i r = _mm256_set1_epi32(int(fs.base & 255u)), g = _mm256_set1_epi32(int((fs.base >> 8) & 255u)),
                b = _mm256_set1_epi32(int((fs.base >> 16) & 255u)), round = _mm256_set1_epi32(128);
  const __m256i tet = _mm256_set1_epi32(int(fs.tet)), face_shade = _mm256_set1_epi32(fs.shade);
  const __m256i alpha = _mm256_set1_epi32(int(0xff000000u));
  const double lo_clamp = bx0 - 1, hi_clamp = bx1 + 1;
  for (int y = rows.first(by0); y <= by1; y = rows.next(y)) {
    double row_at[3];
    int xa = bx0, xb = bx1;
    for (int k = 0; k < 3; ++k) {
      row_at[k] = fs.step_y[k] * double(y) + fs.at0[k];  // exact (see FaceSetup::exact_double)
      // x step ea: covered needs ea x + row_at >= least, a bound (t) on x good to far below a pixel.
      if (fs.step[k] == 0) {
        if (row_at[k] < least[k]) xb = xa - 1;
        continue;
      }
      const double t = std::clamp((least[k] - row_at[k]) * inv_a[k], lo_clamp, hi_clamp);
      if (fs.step[k] > 0)
        xa = std::max(xa, int(std::floor(t)));
      else
        xb = std::min(xb, int(std::ceil(t)));
    }
    if (xa > xb) continue;
    std::uint32_t* rgba = fb.rgba.data() + std::size_t(y) * std::size_t(fb.width);
    std::uint32_t* id = fb.id.data() + std::size_t(y) * std::size_t(fb.width);
    std::uint8_t* shade = fb.shade.data() + std::size_t(y) * std::size_t(fb.width);
    std::uint64_t* done = &written[std::size_t(y) * std::size_t(mask_words)];
    const __m512d at0 = _mm512_set1_pd(row_at[0]), at1 = _mm512_set1_pd(row_at[1]),
                  at2 = _mm512_set1_pd(row_at[2]);
    // The lines at the run's first 8 pixels, then 8 pixels on at each step (integers: exact).
    const __m512d px = _mm512_add_pd(_mm512_set1_pd(double(xa)), lane);
    __m512d e0 = _mm512_add_pd(_mm512_mul_pd(a[0], px), at0);
    __m512d e1 = _mm512_add_pd(_mm512_mul_pd(a[1], px), at1);
    __m512d e2 = _mm512_add_pd(_mm512_mul_pd(a[2], px), at2);
    for (int x = xa; x <= xb; x += 8) {
      const int left = xb - x + 1;
      __mmask8 cover = __mmask8(left >= 8 ? 0xff : (1u << left) - 1);
      cover &= _mm512_cmp_pd_mask(e0, at_least[0], _CMP_GE_OQ);
      cover &= _mm512_cmp_pd_mask(e1, at_least[1], _CMP_GE_OQ);
      cover &= _mm512_cmp_pd_mask(e2, at_least[2], _CMP_GE_OQ);
      // The mask's 8 bits at x (they may run into the next word), then all covered set; no branch
      // on the data (a pixel already written, or none covered, is a lane the stores skip).
      const int w = x >> 6, shift = x & 63;
      std::uint64_t past_row = 0;
      std::uint64_t* next = w + 1 < mask_words ? &done[w + 1] : &past_row;
      const std::uint64_t set = (done[w] >> shift) | ((*next << 1) << (63 - shift));
      done[w] |= std::uint64_t(cover) << shift;
      *next |= (std::uint64_t(cover) >> 1) >> (63 - shift);
      const __mmask8 todo = __mmask8(cover & ~set);
      const __m512d d = _mm512_min_pd(_mm512_min_pd(_mm512_mul_pd(e0, inv[0]), _mm512_mul_pd(e1, inv[1])),
                                      _mm512_mul_pd(e2, inv[2]));
      e0 = _mm512_add_pd(e0, a8[0]);
      e1 = _mm512_add_pd(e1, a8[1]);
      e2 = _mm512_add_pd(e2, a8[2]);
      // A covered pixel's d is at least +0 (every line's value is), so darkened()'s max(0, d) is
      // d; then shade_of and shade_color as darkened() (the face's shade where d >= width). Lanes not
      // covered are garbage the stores skip.
      const __mmask8 dark = _mm512_cmp_pd_mask(d, width, _CMP_LT_OQ);
      const __m512d v =
          _mm512_add_pd(_mm512_mul_pd(level, _mm512_add_pd(base, _mm512_mul_pd(slope, d))), half);
      const __m256i s = _mm256_mask_blend_epi32(
          dark, face_shade, _mm512_cvttpd_epi32(_mm512_min_pd(_mm512_max_pd(v, zero), top)));
      // shade_color's rounding, per 32-bit lane (a lambda would not take the function's target); both
      // factors below 256, the 16-bit product is the whole product.
      __m256i c[3] = {_mm256_mullo_epi16(s, r), _mm256_mullo_epi16(s, g), _mm256_mullo_epi16(s, b)};
      for (__m256i& t : c) {
        t = _mm256_add_epi32(t, round);
        t = _mm256_srli_epi32(_mm256_add_epi32(t, _mm256_srli_epi32(t, 8)), 8);
      }
      const __m256i out = _mm256_or_si256(_mm256_or_si256(c[0], _mm256_slli_epi32(c[1], 8)),
                                          _mm256_or_si256(_mm256_slli_epi32(c[2], 16), alpha));
      _mm256_mask_storeu_epi32(rgba + x, todo, out);
      _mm256_mask_storeu_epi32(id + x, todo, tet);
      _mm256_mask_cvtepi32_storeu_epi8(shade + x, todo, s);
    }
  }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

}  // namespace foxi
