// The volume renderer's pixels eight at a time with AVX-512 (volume_impl.hpp): the same operations as
// the portable path (TetSetup::segment, then integrate_fast's common case), so the same picture bit
// for bit.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <limits>

#include "volume_impl.hpp"

#ifdef FOXI_VOLUME_AVX512
#include <immintrin.h>

namespace foxi {
namespace volume_detail {

// Whether this CPU runs volume_row_avx512; FOXI_PORTABLE_RASTER=1 says no (the painter's switch),
// so that the tests can compare the two paths on one machine.
bool volume_avx512() {
  static const bool yes =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512dq") &&
      !(std::getenv("FOXI_PORTABLE_RASTER") && std::getenv("FOXI_PORTABLE_RASTER")[0] == '1');
  return yes;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's own _mm512_undefined_pd in its intrinsics
#endif
namespace {

// A + x B + y C, in TetSetup::segment's order.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) inline __m512d linear_xy(__m512d xf, __m512d yf,
                                                                                   double A, double B,
                                                                                   double C) {
  return _mm512_add_pd(_mm512_add_pd(_mm512_set1_pd(A), _mm512_mul_pd(xf, _mm512_set1_pd(B))),
                       _mm512_mul_pd(yf, _mm512_set1_pd(C)));
}

// The table rows of the cells cell[0..7] (F + 4 cell, 8 doubles each) transposed: out[j] holds
// element j of every lane's row (j < 4: node cell's T, K; j >= 4: node cell + 1's).
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) inline void table_rows(const double* F,
                                                                                 const int* cell,
                                                                                 __m512d out[8]) {
  __m512d r[8];
  for (int i = 0; i < 8; ++i) r[i] = _mm512_loadu_pd(F + 4 * std::size_t(cell[i]));
  // Pairs of lanes, then quadruples, then halves: unpack, 2-element and 4-element shuffles.
  __m512d s[8], u[8];
  for (int i = 0; i < 8; i += 2) {
    s[i] = _mm512_unpacklo_pd(r[i], r[i + 1]);      // r_i0 r_{i+1}0 r_i2 r_{i+1}2 ...
    s[i + 1] = _mm512_unpackhi_pd(r[i], r[i + 1]);  // r_i1 r_{i+1}1 r_i3 r_{i+1}3 ...
  }
  for (int i = 0; i < 8; i += 4)
    for (int k = 0; k < 2; ++k) {
      // 128-bit blocks: (0, 2) of s[i + k] with (0, 2) of s[i + 2 + k], and (1, 3) with (1, 3).
      u[i + k] = _mm512_shuffle_f64x2(s[i + k], s[i + 2 + k], 0x88);
      u[i + 2 + k] = _mm512_shuffle_f64x2(s[i + k], s[i + 2 + k], 0xdd);
    }
  const __m512i lo_idx = _mm512_set_epi64(13, 12, 9, 8, 5, 4, 1, 0);
  const __m512i hi_idx = _mm512_set_epi64(15, 14, 11, 10, 7, 6, 3, 2);
  for (int k = 0; k < 4; ++k) {
    out[k] = _mm512_permutex2var_pd(u[k], lo_idx, u[k + 4]);
    out[k + 4] = _mm512_permutex2var_pd(u[k], hi_idx, u[k + 4]);
  }
}

}  // namespace

// The pixels (xs[i], ys[i]), i < n, eight at a time: TetSetup::segment and, for the common segment
// (the pre-integrated table, at least 2 grid cells, inside the grid, one closed piece),
// integrate_fast with the same operations in the same order (viz is built with -ffp-contract=off, and
// the same table entries are read), so the picture is bit for bit the portable path's; every other
// segment (thin, thick, outside the grid, NaN, a log scale) goes through composite() one pixel at a
// time.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) void volume_pixels_avx512(
    const TetSetup& r, const TableTransfer& tf, Pixel* acc, int width, const int* xs, const int* ys, int n_px,
    std::uint32_t t, std::size_t& count, std::size_t& fast) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d one = _mm512_set1_pd(1.0), inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d abs_mask = _mm512_castsi512_pd(_mm512_set1_epi64(0x7fffffffffffffffLL));
  const __m256i tet = _mm256_set1_epi32(int(t)), wv = _mm256_set1_epi32(width);
  const __m256i last_cell = _mm256_set1_epi32(TableTransfer::kG - 1);
  const __m512d g_lo = _mm512_set1_pd(tf.g_lo), g_inv = _mm512_set1_pd(tf.g_inv);
  const __m512d grid_end = _mm512_set1_pd(double(TableTransfer::kG)), two = _mm512_set1_pd(2.0);
  const __m512d pos_scale = _mm512_set1_pd(tf.pos_scale), lut_step = _mm512_set1_pd(double(tf.lut_step));
  const __m512d c255 = _mm512_set1_pd(255.0), c256 = _mm512_set1_pd(256.0);
  for (int i0 = 0; i0 < n_px; i0 += 8) {
    const int n = std::min(8, n_px - i0);
    __mmask8 live = __mmask8((1u << n) - 1u);
    const __m256i xi = _mm256_maskz_loadu_epi32(live, xs + i0), yi = _mm256_maskz_loadu_epi32(live, ys + i0);
    // Each pixel's index in acc.
    const __m256i pixel = _mm256_add_epi32(_mm256_mullo_epi32(yi, wv), xi);
    const __m512d xf = _mm512_cvtepi32_pd(xi), yf = _mm512_cvtepi32_pd(yi);
    __m512d s_in = _mm512_set1_pd(r.near), s_out = inf;
    for (int k = 0; k < 4; ++k) {
      const __m512d nd = linear_xy(xf, yf, r.ndA[k], r.ndB[k], r.ndC[k]);
      const __m512d sk = _mm512_div_pd(linear_xy(xf, yf, r.numA[k], r.numB[k], r.numC[k]), nd);
      // max(sk, s_in) is sk > s_in ? sk : s_in (s_in for a NaN sk), as std::max(s_in, sk).
      s_in = _mm512_mask_max_pd(s_in, _mm512_cmp_pd_mask(nd, zero, _CMP_LT_OQ), sk, s_in);
      s_out = _mm512_mask_min_pd(s_out, _mm512_cmp_pd_mask(nd, zero, _CMP_GT_OQ), sk, s_out);
    }
    live &= _mm512_cmp_pd_mask(s_out, s_in, _CMP_GT_OQ);
    if (!live) continue;
    count += std::size_t(__builtin_popcount(live));
    const __m512d v0 = linear_xy(xf, yf, r.vA, r.vB, r.vC), gd = linear_xy(xf, yf, r.gdA, r.gdB, r.gdC);
    const __m512d dx = _mm512_add_pd(_mm512_set1_pd(r.dxA), _mm512_mul_pd(xf, _mm512_set1_pd(r.dxB)));
    const __m512d dy = _mm512_add_pd(_mm512_set1_pd(r.dyA), _mm512_mul_pd(yf, _mm512_set1_pd(r.dyC)));
    const __m512d len = _mm512_mul_pd(
        _mm512_sub_pd(s_out, s_in),
        _mm512_sqrt_pd(_mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                     _mm512_set1_pd(r.dz2))));
    const __m512d v_far = _mm512_add_pd(v0, _mm512_mul_pd(s_out, gd));
    const __m512d v_near = _mm512_add_pd(v0, _mm512_mul_pd(s_in, gd));
    __mmask8 done = 0, written = 0;  // written: the lanes whose pixel (colour and front) is stored
    if (tf.pre) {
      const __m512d dv = _mm512_sub_pd(v_near, v_far);
      const __m512d adv = _mm512_and_pd(dv, abs_mask);
      const __m512d cells = _mm512_mul_pd(adv, g_inv);
      const __m512d xa = _mm512_mul_pd(_mm512_sub_pd(v_far, g_lo), g_inv);
      const __m512d xb = _mm512_mul_pd(_mm512_sub_pd(v_near, g_lo), g_inv);
      __mmask8 m = live & _mm512_cmp_pd_mask(cells, two, _CMP_GE_OQ);
      m &= _mm512_cmp_pd_mask(xa, zero, _CMP_GT_OQ);
      m &= _mm512_cmp_pd_mask(xa, grid_end, _CMP_LT_OQ);
      m &= _mm512_cmp_pd_mask(xb, zero, _CMP_GT_OQ);
      m &= _mm512_cmp_pd_mask(xb, grid_end, _CMP_LT_OQ);
      // Under 2 grid cells (not NaN): the midpoint's extinction and colour (integrate_fast's first case).
      const __mmask8 thin = __mmask8(live & _mm512_cmp_pd_mask(cells, two, _CMP_LT_OQ));
      // Per lane the segment's optical depth D, the emitted colour's numerators em and its divisor dT
      // (the pre-integrated piece: K differences over T's; a thin one: the colour over 1).
      __m512d D = zero, dT = one, em[3] = {zero, zero, zero};
      __mmask8 blend = 0, none = 0;
      if (m) {
        // The antiderivatives at both ends: cell i = min(int(x), kG - 1), f = x - i, 4 doubles a node.
        const __m256i ia = _mm256_min_epi32(_mm512_cvttpd_epi32(xa), last_cell);
        const __m256i ib = _mm256_min_epi32(_mm512_cvttpd_epi32(xb), last_cell);
        const __m512d fa = _mm512_sub_pd(xa, _mm512_cvtepi32_pd(ia));
        const __m512d fb = _mm512_sub_pd(xb, _mm512_cvtepi32_pd(ib));
        // A cell's two nodes are 8 consecutive doubles of F (64 bytes): one load a lane and an 8 x 8
        // transpose in place of 16 gathers (the lanes outside m read cell 0 and are not used).
        alignas(32) int cell_a[8], cell_b[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(cell_a), _mm256_maskz_mov_epi32(m, ia));
        _mm256_store_si256(reinterpret_cast<__m256i*>(cell_b), _mm256_maskz_mov_epi32(m, ib));
        __m512d na[8], nb[8];
        table_rows(tf.F.data(), cell_a, na);
        table_rows(tf.F.data(), cell_b, nb);
        __m512d a[4], b[4];
        for (int j = 0; j < 4; ++j) {
          a[j] = _mm512_add_pd(na[j], _mm512_mul_pd(fa, _mm512_sub_pd(na[j + 4], na[j])));
          b[j] = _mm512_add_pd(nb[j], _mm512_mul_pd(fb, _mm512_sub_pd(nb[j + 4], nb[j])));
        }
        // closed_piece: D = length dT / dv; D == 0 blends nothing; 0 < D <= 1 with spread D^2 <= 1
        // in closed form.
        const __m512d dTm = _mm512_sub_pd(b[0], a[0]);
        const __m512d Dm = _mm512_div_pd(_mm512_mul_pd(len, dTm), dv);
        none = __mmask8(m & _mm512_cmp_pd_mask(Dm, zero, _CMP_EQ_OQ));
        const __m512d spread = _mm512_min_pd(
            c255,
            _mm512_mul_pd(_mm512_add_pd(_mm512_mul_pd(_mm512_mul_pd(adv, pos_scale), c256), one), lut_step));
        blend = m & _mm512_cmp_pd_mask(Dm, zero, _CMP_GT_OQ);
        blend &= _mm512_cmp_pd_mask(Dm, one, _CMP_LE_OQ);
        blend &= _mm512_cmp_pd_mask(_mm512_mul_pd(_mm512_mul_pd(spread, Dm), Dm), one, _CMP_LE_OQ);
        D = _mm512_mask_mov_pd(D, blend, Dm);
        dT = _mm512_mask_mov_pd(dT, blend, dTm);
        for (int j = 0; j < 3; ++j) em[j] = _mm512_mask_sub_pd(em[j], blend, b[j + 1], a[j + 1]);
      }
      if (thin) {
        // tf.tau(vm), tf.rgb(vm) with the same operations: the extinction table interpolated, the
        // colour map's entry of the scale position.
        const __m512d vm = _mm512_mul_pd(_mm512_set1_pd(0.5), _mm512_add_pd(v_far, v_near));
        const __m512d xt = _mm512_min_pd(
            _mm512_max_pd(
                _mm512_mul_pd(_mm512_sub_pd(vm, _mm512_set1_pd(tf.lo)), _mm512_set1_pd(tf.inv_step)), zero),
            _mm512_set1_pd(double(TableTransfer::kN)));
        const __m256i it =
            _mm256_min_epi32(_mm512_cvttpd_epi32(xt), _mm256_set1_epi32(TableTransfer::kN - 1));
        const __m512d ft = _mm512_sub_pd(xt, _mm512_cvtepi32_pd(it));
        const __m512d t0 = _mm512_mask_i32gather_pd(zero, thin, it, tf.tau_at.data(), 8);
        const __m512d t1 = _mm512_mask_i32gather_pd(zero, thin, it, tf.tau_at.data() + 1, 8);
        const __m512d Dt = _mm512_mul_pd(_mm512_add_pd(t0, _mm512_mul_pd(ft, _mm512_sub_pd(t1, t0))), len);
        const __mmask8 ok = __mmask8(thin & _mm512_cmp_pd_mask(Dt, one, _CMP_LE_OQ));
        const __m512d pos = _mm512_div_pd(_mm512_sub_pd(vm, _mm512_set1_pd(tf.p->scale.lo)),
                                          _mm512_set1_pd(tf.p->scale.hi - tf.p->scale.lo));
        const __m256i entry =
            _mm512_cvttpd_epi32(_mm512_min_pd(_mm512_max_pd(_mm512_mul_pd(pos, c256), zero), c255));
        const __m256i k3 = _mm256_mullo_epi32(entry, _mm256_set1_epi32(3));
        D = _mm512_mask_mov_pd(D, ok, Dt);
        for (int j = 0; j < 3; ++j)
          em[j] = _mm512_mask_mov_pd(
              em[j], ok,
              _mm512_cvtps_pd(_mm256_mmask_i32gather_ps(_mm256_setzero_ps(), ok, k3, &tf.lut[0][j], 4)));
        blend |= ok;
      }
      if (blend) {
        // exp_neg_small(D), the same operations.
        const __m512d q = _mm512_mul_pd(_mm512_set1_pd(0.125), D), q2 = _mm512_mul_pd(q, q);
        __m512d e = _mm512_add_pd(
            _mm512_add_pd(_mm512_sub_pd(one, q),
                          _mm512_mul_pd(q2, _mm512_sub_pd(_mm512_set1_pd(0.5),
                                                          _mm512_mul_pd(q, _mm512_set1_pd(1.0 / 6))))),
            _mm512_mul_pd(_mm512_mul_pd(q2, q2), _mm512_sub_pd(_mm512_set1_pd(1.0 / 24),
                                                               _mm512_mul_pd(q, _mm512_set1_pd(1.0 / 120)))));
        e = _mm512_mul_pd(e, e);
        e = _mm512_mul_pd(e, e);
        e = _mm512_mul_pd(e, e);
        // Pre-integrated: (K_b - K_a) (1 - e) / dT + c e; thin: rgb (1 - e) + c e (dT = 1 exactly).
        const __m512d w = _mm512_div_pd(_mm512_sub_pd(one, e), dT);
        // The eight pixels (16 bytes each: r, g, b, front) loaded whole and transposed, in place of
        // three gathers and four scatters; written back with the tet as their front.
        alignas(32) int at[8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(at), pixel);
        __m512 q0 = _mm512_castps128_ps512(_mm_loadu_ps(acc[at[0]].c));
        __m512 q1 = _mm512_castps128_ps512(_mm_loadu_ps(acc[at[4]].c));
        q0 = _mm512_insertf32x4(q0, _mm_loadu_ps(acc[at[1]].c), 1);
        q1 = _mm512_insertf32x4(q1, _mm_loadu_ps(acc[at[5]].c), 1);
        q0 = _mm512_insertf32x4(q0, _mm_loadu_ps(acc[at[2]].c), 2);
        q1 = _mm512_insertf32x4(q1, _mm_loadu_ps(acc[at[6]].c), 2);
        q0 = _mm512_insertf32x4(q0, _mm_loadu_ps(acc[at[3]].c), 3);
        q1 = _mm512_insertf32x4(q1, _mm_loadu_ps(acc[at[7]].c), 3);
        __m256 out[3];
        for (int j = 0; j < 3; ++j) {
          // Channel j of pixel i is float 4 i + j of (q0, q1).
          const __m512i idx = _mm512_add_epi32(
              _mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 28, 24, 20, 16, 12, 8, 4, 0), _mm512_set1_epi32(j));
          const __m512d c = _mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_permutex2var_ps(q0, idx, q1)));
          out[j] = _mm512_cvtpd_ps(_mm512_add_pd(_mm512_mul_pd(em[j], w), _mm512_mul_pd(c, e)));
        }
        // Back to (r, g, b, front) per pixel: (r | g) and (b | front) as 16 floats, pixel i's four
        // from floats i, 8 + i of the first and i, 8 + i of the second.
        const __m512 rg = _mm512_insertf32x8(_mm512_castps256_ps512(out[0]), out[1], 1);
        const __m512 bt = _mm512_insertf32x8(_mm512_castps256_ps512(out[2]), _mm256_castsi256_ps(tet), 1);
        const __m512i lo_idx = _mm512_set_epi32(27, 19, 11, 3, 26, 18, 10, 2, 25, 17, 9, 1, 24, 16, 8, 0);
        const __m512i hi_idx = _mm512_set_epi32(31, 23, 15, 7, 30, 22, 14, 6, 29, 21, 13, 5, 28, 20, 12, 4);
        alignas(64) float px_out[32];
        _mm512_store_ps(px_out, _mm512_permutex2var_ps(rg, lo_idx, bt));
        _mm512_store_ps(px_out + 16, _mm512_permutex2var_ps(rg, hi_idx, bt));
        for (int i = 0; i < 8; ++i)
          if (blend >> i & 1) _mm_storeu_ps(acc[at[i]].c, _mm_load_ps(px_out + 4 * i));
        written = blend;
      }
      done = __mmask8(blend | none);
      fast += std::size_t(__builtin_popcount(done));
    }
    // The front of the pixels not written above.
    if (const __mmask8 front = __mmask8(live & ~written)) {
      alignas(32) int at[8];
      _mm256_store_si256(reinterpret_cast<__m256i*>(at), pixel);
      for (int i = 0; i < 8; ++i)
        if (front >> i & 1) acc[at[i]].front = t;
    }
    if (const __mmask8 rest = __mmask8(live & ~done)) {
      alignas(64) double vf[8], vn[8], ln[8];
      _mm512_store_pd(vf, v_far);
      _mm512_store_pd(vn, v_near);
      _mm512_store_pd(ln, len);
      for (int i = 0; i < 8; ++i)
        if (rest >> i & 1)
          composite(tf, vf[i], vn[i], ln[i],
                    acc[std::size_t(ys[i0 + i]) * std::size_t(width) + std::size_t(xs[i0 + i])].c, fast);
    }
  }
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace volume_detail
}  // namespace foxi
#endif
