// The volume renderer's pixel rows sixteen at a time with AVX-512 in float (volume_impl.hpp): per row
// of a tet the four planes' ray parameters stepped along x (no per-pixel list), the entry and exit,
// the pre-integrated closed form with its table rows loaded and transposed, and the row's colour and
// front planes loaded and stored contiguously.
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

RowSetup::RowSetup(const TetSetup& r, double s_ref, int x_ref, int y_ref) : xr(x_ref), yr(y_ref) {
  const double X = x_ref, Y = y_ref;
  for (int k = 0; k < 4; ++k) {
    nd[k] = float(r.ndA[k] + X * r.ndB[k] + Y * r.ndC[k]);
    ndx[k] = float(r.ndB[k]);
    ndy[k] = float(r.ndC[k]);
    // s - s_ref at plane k: (num - s_ref nd) / nd.
    const double A = r.numA[k] - s_ref * r.ndA[k], B = r.numB[k] - s_ref * r.ndB[k],
                 C = r.numC[k] - s_ref * r.ndC[k];
    num[k] = float(A + X * B + Y * C);
    numx[k] = float(B);
    numy[k] = float(C);
  }
  // The field at s_ref on the ray: v0 + s_ref gd.
  const double vA = r.vA + s_ref * r.gdA, vB = r.vB + s_ref * r.gdB, vC = r.vC + s_ref * r.gdC;
  v = float(vA + X * vB + Y * vC);
  vx = float(vB);
  vy = float(vC);
  gd = float(r.gdA + X * r.gdB + Y * r.gdC);
  gdx = float(r.gdB);
  gdy = float(r.gdC);
  dx = float(r.dxA + X * r.dxB);
  dxx = float(r.dxB);
  dy = float(r.dyA + Y * r.dyC);
  dyy = float(r.dyC);
  dz2 = float(r.dz2);
  near = float(r.near - s_ref);
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC 12's own _mm512_undefined_ps in its intrinsics
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif
namespace {

#define FOXI_TARGET __attribute__((target("avx512f,avx512vl,avx512dq,avx2,fma")))

// The table rows of the cells cell[0..15] (Ff + 4 cell, 8 floats each) transposed: out[j] holds
// element j of every lane's row (j < 4: node cell's T, K; j >= 4: node cell + 1's). The rows go in
// pairs into 512-bit registers (rows j and j + 4, then j + 8 and j + 12) so that the 8 x 8 transpose
// of each half, finished by 128-bit block shuffles, leaves lane i with row i.
FOXI_TARGET inline void table_rows(const float* F, const int* cell, __m512 out[8]) {
  __m512 z[8];
  for (int j = 0; j < 4; ++j) {
    z[j] = _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_loadu_ps(F + 4 * std::size_t(cell[j]))),
                              _mm256_loadu_ps(F + 4 * std::size_t(cell[j + 4])), 1);
    z[j + 4] = _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_loadu_ps(F + 4 * std::size_t(cell[j + 8]))),
                                  _mm256_loadu_ps(F + 4 * std::size_t(cell[j + 12])), 1);
  }
  __m512 t[8], u[8];
  for (int i = 0; i < 8; i += 2) {
    t[i] = _mm512_unpacklo_ps(z[i], z[i + 1]);      // per 128-bit block: a0 b0 a1 b1
    t[i + 1] = _mm512_unpackhi_ps(z[i], z[i + 1]);  // a2 b2 a3 b3
  }
  for (int i = 0; i < 8; i += 4) {
    u[i] = _mm512_shuffle_ps(t[i], t[i + 2], 0x44);      // a0 b0 c0 d0
    u[i + 1] = _mm512_shuffle_ps(t[i], t[i + 2], 0xee);  // a1 b1 c1 d1
    u[i + 2] = _mm512_shuffle_ps(t[i + 1], t[i + 3], 0x44);
    u[i + 3] = _mm512_shuffle_ps(t[i + 1], t[i + 3], 0xee);
  }
  // u[c] (rows 0-3 low half, 4-7 high half), u[c + 4] (rows 8-11, 12-15): blocks 0 and 2 hold
  // element c, blocks 1 and 3 element c + 4.
  for (int c = 0; c < 4; ++c) {
    out[c] = _mm512_shuffle_f32x4(u[c], u[c + 4], 0x88);
    out[c + 4] = _mm512_shuffle_f32x4(u[c], u[c + 4], 0xdd);
  }
}

// 1 / x by the reciprocal estimate and one Newton step (relative error about 2^-23, a few units in
// the last place of a division; 0 gives NaN, which no comparison below passes).
FOXI_TARGET inline __m512 recip(__m512 x) {
  const __m512 r = _mm512_rcp14_ps(x);
  return _mm512_mul_ps(r, _mm512_fnmadd_ps(x, r, _mm512_set1_ps(2.0f)));
}

// A quantity Q0 + xo Qx + yo Qy per lane.
FOXI_TARGET inline __m512 at(__m512 xo, __m512 yo, float q0, float qx, float qy) {
  return _mm512_fmadd_ps(yo, _mm512_set1_ps(qy), _mm512_fmadd_ps(xo, _mm512_set1_ps(qx), _mm512_set1_ps(q0)));
}

}  // namespace

// The float arithmetic against the portable path's double (the tests bound the difference): the ray
// parameters relative to the tet (RowSetup) err by a few units in the last place of the tet's depth
// extent, the plane divisions by a refined reciprocal (2^-23), the table (Ff) as said there; a
// segment's colour differs by well under one level of 255.
//
// The runs are packed into the sixteen lanes one after another (a tet's rows are short: about 9
// pixels at 0.1M tets at 1920 x 1080, fewer at 1M, so a lane group per row would run half empty);
// each piece of a run in a group keeps its lanes and the address of its first lane's pixel less its
// lane, so its pixels are one masked load and store per plane.
namespace {

// A lane group between its two halves (runs_impl): after the first (the rays' entry and exit, the
// field at both ends, the pre-integration table's cells), before the second (the table's rows, the
// integral, the picture).
struct StagedGroup {
  alignas(64) int cell_a[16];
  alignas(64) int cell_b[16];
  alignas(64) float fa[16], fb[16], len[16], dv[16], adv[16], v_far[16], v_near[16];
  std::ptrdiff_t base[16];
  __mmask16 piece[16];
  int n_pieces = 0;
  __mmask16 live = 0, m = 0, thin = 0;
};

// A group's second half (runs_impl): the table rows, the integral and the picture.
FOXI_TARGET __attribute__((always_inline)) inline void second_half(const StagedGroup& s,
                                                                   const TableTransfer& tf,
                                                                   const VolumeAcc& acc, std::size_t& fast) {
  const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
  constexpr float kSixth = 1.0f / 6, k24th = 1.0f / 24, k120th = 1.0f / 120;
  __mmask16 done = 0;
  if (const __mmask16 m = s.m) {
    __m512 na[8], nb[8];
    table_rows(tf.Ff.data(), s.cell_a, na);
    table_rows(tf.Ff.data(), s.cell_b, nb);
    const __m512 fa = _mm512_load_ps(s.fa), fb = _mm512_load_ps(s.fb);
    __m512 a[4], b[4];
    for (int j = 0; j < 4; ++j) {
      a[j] = _mm512_fmadd_ps(fa, _mm512_sub_ps(na[j + 4], na[j]), na[j]);
      b[j] = _mm512_fmadd_ps(fb, _mm512_sub_ps(nb[j + 4], nb[j]), nb[j]);
    }
    // integrate_fast's closed piece: D = length dT / dv; D == 0 blends nothing; 0 < D <= 1 with
    // spread D^2 <= 1 (a thin segment: D <= 1) in closed form.
    const __m512 spread_a = _mm512_set1_ps(float(tf.pos_scale * 256 * tf.lut_step)),
                 spread_b = _mm512_set1_ps(tf.lut_step), c255 = _mm512_set1_ps(255.0f);
    const __m512 dT = _mm512_sub_ps(b[0], a[0]);
    const __m512 D = _mm512_mul_ps(_mm512_mul_ps(_mm512_load_ps(s.len), dT), recip(_mm512_load_ps(s.dv)));
    const __mmask16 none = m & _mm512_cmp_ps_mask(D, zero, _CMP_EQ_OQ);
    const __m512 spread = _mm512_min_ps(c255, _mm512_fmadd_ps(_mm512_load_ps(s.adv), spread_a, spread_b));
    __mmask16 blend = m & _mm512_cmp_ps_mask(D, zero, _CMP_GT_OQ);
    blend &= _mm512_cmp_ps_mask(D, one, _CMP_LE_OQ);
    blend &=
        __mmask16(s.thin | _mm512_cmp_ps_mask(_mm512_mul_ps(_mm512_mul_ps(spread, D), D), one, _CMP_LE_OQ));
    if (blend) {
      // exp_neg_small(D) in float: (e^-D/8)^8, e^-q by its series to q^5.
      const __m512 q = _mm512_mul_ps(_mm512_set1_ps(0.125f), D), q2 = _mm512_mul_ps(q, q);
      __m512 e = _mm512_add_ps(
          _mm512_add_ps(_mm512_sub_ps(one, q),
                        _mm512_mul_ps(q2, _mm512_fnmadd_ps(q, _mm512_set1_ps(kSixth), _mm512_set1_ps(0.5f)))),
          _mm512_mul_ps(_mm512_mul_ps(q2, q2),
                        _mm512_fnmadd_ps(q, _mm512_set1_ps(k120th), _mm512_set1_ps(k24th))));
      e = _mm512_mul_ps(e, e);
      e = _mm512_mul_ps(e, e);
      e = _mm512_mul_ps(e, e);
      // (K_b - K_a) (1 - e) / dT + c e.
      const __m512 w = _mm512_mul_ps(_mm512_sub_ps(one, e), recip(dT));
      // The three planes in one pass over the pieces to load and one to store (a plane at a time
      // was six loops whose count depends on the data: 4% more CPU a frame).
      __m512 c[3] = {zero, zero, zero};
      for (int p = 0; p < s.n_pieces; ++p) {
        const __mmask16 lanes = blend & s.piece[p];
        for (int j = 0; j < 3; ++j) c[j] = _mm512_mask_loadu_ps(c[j], lanes, acc.c[j] + s.base[p]);
      }
      for (int j = 0; j < 3; ++j)
        c[j] = _mm512_fmadd_ps(_mm512_sub_ps(b[j + 1], a[j + 1]), w, _mm512_mul_ps(c[j], e));
      for (int p = 0; p < s.n_pieces; ++p) {
        const __mmask16 lanes = blend & s.piece[p];
        for (int j = 0; j < 3; ++j) _mm512_mask_storeu_ps(acc.c[j] + s.base[p], lanes, c[j]);
      }
    }
    done = __mmask16(blend | none);
    fast += std::size_t(__builtin_popcount(done));
  }
  if (const __mmask16 rest = __mmask16(s.live & ~done)) {
    for (int p = 0; p < s.n_pieces; ++p)
      for (int i = 0; i < 16; ++i)
        if ((rest & s.piece[p]) >> i & 1) {
          const std::ptrdiff_t q = s.base[p] + i;
          float c[3] = {acc.c[0][q], acc.c[1][q], acc.c[2][q]};
          composite(tf, s.v_far[i], s.v_near[i], s.len[i], c, fast);
          for (int j = 0; j < 3; ++j) acc.c[j][q] = c[j];
        }
  }
}

FOXI_TARGET __attribute__((always_inline)) inline void runs_impl(const RowSetup& r, const TableTransfer& tf,
                                                                 const VolumeAcc& acc, const PixelRun* runs,
                                                                 int n_runs, std::uint32_t t,
                                                                 std::size_t& count, std::size_t& fast) {
  const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f), two = _mm512_set1_ps(2.0f);
  const __m512 inf = _mm512_set1_ps(std::numeric_limits<float>::infinity());
  const __m512 iota = _mm512_set_ps(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  const __m512i tet = _mm512_set1_epi32(int(t));
  const bool pre = tf.pre;
  // Each group's first half, then the second half of the group before it: the two chains are
  // independent, so the core overlaps them (one group at a time waited on its table rows and
  // pixels: the pipelined groups took about 9% less CPU, measured alternately in one process).
  StagedGroup st[2];
  int cur = 0;
  bool have_prev = false;
  __m512 xo = zero, yo = zero;
  // The first half of the group in st[cur]: false where no lane's ray meets the tet.
  auto first = [&](StagedGroup & s, __mmask16 live) FOXI_TARGET __attribute__((always_inline)) {
    __m512 s_in = _mm512_set1_ps(r.near), s_out = inf;
    for (int k = 0; k < 4; ++k) {
      const __m512 nd = at(xo, yo, r.nd[k], r.ndx[k], r.ndy[k]);
      const __m512 sk = _mm512_mul_ps(at(xo, yo, r.num[k], r.numx[k], r.numy[k]), recip(nd));
      // max(sk, s_in) is s_in for a NaN sk, as std::max(s_in, sk).
      s_in = _mm512_mask_max_ps(s_in, _mm512_cmp_ps_mask(nd, zero, _CMP_LT_OQ), sk, s_in);
      s_out = _mm512_mask_min_ps(s_out, _mm512_cmp_ps_mask(nd, zero, _CMP_GT_OQ), sk, s_out);
    }
    live &= _mm512_cmp_ps_mask(s_out, s_in, _CMP_GT_OQ);
    if (!live) return false;
    count += std::size_t(__builtin_popcount(live));
    for (int p = 0; p < s.n_pieces; ++p)
      _mm512_mask_storeu_epi32(acc.front + s.base[p], __mmask16(live & s.piece[p]), tet);
    const __m512 v0 = at(xo, yo, r.v, r.vx, r.vy), gd = at(xo, yo, r.gd, r.gdx, r.gdy);
    const __m512 dxv = _mm512_fmadd_ps(xo, _mm512_set1_ps(r.dxx), _mm512_set1_ps(r.dx));
    const __m512 dyv = _mm512_fmadd_ps(yo, _mm512_set1_ps(r.dyy), _mm512_set1_ps(r.dy));
    const __m512 len = _mm512_mul_ps(
        _mm512_sub_ps(s_out, s_in),
        _mm512_sqrt_ps(_mm512_fmadd_ps(dxv, dxv, _mm512_fmadd_ps(dyv, dyv, _mm512_set1_ps(r.dz2)))));
    const __m512 v_far = _mm512_fmadd_ps(s_out, gd, v0), v_near = _mm512_fmadd_ps(s_in, gd, v0);
    _mm512_store_ps(s.len, len);
    _mm512_store_ps(s.v_far, v_far);
    _mm512_store_ps(s.v_near, v_near);
    s.live = live;
    s.m = 0;
    if (pre) {
      const __m512 g_inv = _mm512_set1_ps(float(tf.g_inv)), g_off = _mm512_set1_ps(float(tf.g_lo * tf.g_inv));
      const __m512 grid_end = _mm512_set1_ps(float(TableTransfer::kG));
      const __m512i last_cell = _mm512_set1_epi32(TableTransfer::kG - 1);
      const __m512 dv = _mm512_sub_ps(v_near, v_far);
      const __m512 adv = _mm512_abs_ps(dv);
      const __m512 cells = _mm512_mul_ps(adv, g_inv);
      __m512 xa = _mm512_fmsub_ps(v_far, g_inv, g_off), xb = _mm512_fmsub_ps(v_near, g_inv, g_off);
      // Under 2 grid cells (1/16 of a colour map entry): the grid cell of the midpoint, its mean
      // extinction and colour (its ends' differences over the cell's width).
      const __mmask16 thin = _mm512_cmp_ps_mask(cells, two, _CMP_LT_OQ);
      const __m512 xm = _mm512_roundscale_ps(_mm512_mul_ps(_mm512_set1_ps(0.5f), _mm512_add_ps(xa, xb)),
                                             _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
      xa = _mm512_mask_mov_ps(xa, thin, xm);
      xb = _mm512_mask_add_ps(xb, thin, xm, one);
      const __m512 cell_w = _mm512_set1_ps(float((tf.g_hi - tf.g_lo) / TableTransfer::kG));
      const __m512 dv_eff = _mm512_mask_mov_ps(dv, thin, cell_w);
      __mmask16 m = live & _mm512_cmp_ps_mask(xa, zero, _CMP_GE_OQ);
      m &= _mm512_cmp_ps_mask(xa, grid_end, _CMP_LT_OQ);
      m &= _mm512_cmp_ps_mask(xb, zero, _CMP_GT_OQ);
      m &= _mm512_cmp_ps_mask(xb, grid_end, _CMP_LE_OQ);
      m &= __mmask16(thin | _mm512_cmp_ps_mask(cells, two, _CMP_GE_OQ));  // not NaN
      const __m512i ia = _mm512_min_epi32(_mm512_cvttps_epi32(xa), last_cell);
      const __m512i ib = _mm512_min_epi32(_mm512_cvttps_epi32(xb), last_cell);
      _mm512_store_ps(s.fa, _mm512_sub_ps(xa, _mm512_cvtepi32_ps(ia)));
      _mm512_store_ps(s.fb, _mm512_sub_ps(xb, _mm512_cvtepi32_ps(ib)));
      // The lanes outside m read cell 0 and are not used. The second half reads the cells back from
      // memory (one load each, not three instructions to extract each from a register).
      _mm512_store_si512(s.cell_a, _mm512_maskz_mov_epi32(m, ia));
      _mm512_store_si512(s.cell_b, _mm512_maskz_mov_epi32(m, ib));
      _mm512_store_ps(s.dv, dv_eff);
      _mm512_store_ps(s.adv, adv);
      s.m = m;
      s.thin = thin;
    }
    return true;
  };
  // A full (or last) group: its first half, then the second half of the group before it (whose
  // chain is independent of this one's, so the two overlap in the core).
  auto group = [&](__mmask16 live) FOXI_TARGET __attribute__((always_inline)) {
    const bool staged = first(st[cur], live);
    if (have_prev) second_half(st[cur ^ 1], tf, acc, fast);
    have_prev = staged;
    if (staged) cur ^= 1;
  };
  int k = 0;  // lanes filled
  // Lanes k.. k + n - 1 for the pixels x.. x + n - 1 of a row (n = 0: none).
  auto put = [&](std::ptrdiff_t row, float yr, int x, int n) FOXI_TARGET __attribute__((always_inline)) {
    const __mmask16 lanes = __mmask16(((1u << n) - 1u) << k);
    xo = _mm512_mask_add_ps(xo, lanes, _mm512_set1_ps(float(x - k - r.xr)), iota);
    yo = _mm512_mask_mov_ps(yo, lanes, _mm512_set1_ps(yr));
    StagedGroup& s = st[cur];
    s.base[s.n_pieces] = row + x - k;
    s.piece[s.n_pieces] = lanes;
    s.n_pieces += n > 0;
    k += n;
  };
  auto full = [&]() FOXI_TARGET __attribute__((always_inline)) {
    group(__mmask16(0xffff));
    k = 0;
    st[cur].n_pieces = 0;
  };
  for (int i = 0; i < n_runs; ++i) {
    const PixelRun& run = runs[i];
    const float yr = float(run.y - r.yr);
    const std::ptrdiff_t row = std::ptrdiff_t(run.y) * acc.width;
    const int len = run.hi - run.lo + 1;
    if (len <= 16) [[likely]] {
      // At most two pieces, the second (perhaps empty) in the next group: no loop whose count
      // depends on the data (its exit was often mispredicted: 3-4% of a frame's CPU).
      const int n = std::min(len, 16 - k);
      put(row, yr, run.lo, n);
      if (k == 16) {
        full();
        put(row, yr, run.lo + n, len - n);
      }
    } else {
      for (int x = run.lo; x <= run.hi;) {
        const int n = std::min(run.hi - x + 1, 16 - k);
        put(row, yr, x, n);
        x += n;
        if (k == 16) full();
      }
    }
  }
  if (k > 0) group(__mmask16((1u << k) - 1u));
  if (have_prev) second_half(st[cur ^ 1], tf, acc, fast);
}

}  // namespace

namespace {

// corner_edges (volume_impl.hpp) for four points, the six segments at once and without a branch on
// which end is lower (a data-dependent branch per pair, mispredicted about half the time, in each of a
// frame's million tets): the same values, as a segment's slope is the same whichever end is
// subtracted from which, and its start the lower end. A level segment's y0 is NaN (no row's centre
// line is in it), so the six are always all listed.
FOXI_TARGET bool corner_edges4(const double (*q)[2], int y0, int y1, CornerEdges& e) {
  if (!corner_rows(q, 4, y0, y1, e)) return false;
  // Pairs (i, j): (0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3), and (0, 1) twice more, left out.
  const __m512d xy = _mm512_loadu_pd(&q[0][0]);  // x0 y0 x1 y1 x2 y2 x3 y3
  const __m512d xi = _mm512_permutexvar_pd(_mm512_set_epi64(0, 0, 4, 2, 2, 0, 0, 0), xy);
  const __m512d yi = _mm512_permutexvar_pd(_mm512_set_epi64(1, 1, 5, 3, 3, 1, 1, 1), xy);
  const __m512d xj = _mm512_permutexvar_pd(_mm512_set_epi64(2, 2, 6, 6, 4, 6, 4, 2), xy);
  const __m512d yj = _mm512_permutexvar_pd(_mm512_set_epi64(3, 3, 7, 7, 5, 7, 5, 3), xy);
  const __mmask8 i_low = _mm512_cmp_pd_mask(yi, yj, _CMP_LE_OQ);
  const __m512d lower = _mm512_mask_blend_pd(i_low, yj, yi), upper = _mm512_mask_blend_pd(i_low, yi, yj);
  const __mmask8 rising = __mmask8(0x3f & _mm512_cmp_pd_mask(upper, lower, _CMP_GT_OQ));
  const __m512d nan = _mm512_set1_pd(std::numeric_limits<double>::quiet_NaN());
  _mm512_storeu_pd(e.y0, _mm512_mask_blend_pd(rising, nan, lower));
  _mm512_storeu_pd(e.y1, upper);
  _mm512_storeu_pd(e.x0, _mm512_mask_blend_pd(i_low, xj, xi));
  _mm512_storeu_pd(e.slope, _mm512_div_pd(_mm512_sub_pd(xj, xi), _mm512_sub_pd(yj, yi)));
  e.n = 6;
  return true;
}

}  // namespace

// Eight tets' set-ups (volume_impl.hpp's TetBatch): draw_tet's arithmetic, lane-wise in double
// (GCC's vector operators on __m512d), then RowSetup's.
FOXI_TARGET void tet_batch_avx512(TetBatch& b) {
  using V = __m512d;
  // (Lambdas with a capture default: a captureless one's conversion to a function pointer has no
  // target attribute, and GCC warns of its ABI.)
  const auto ld = [&](const double* p) FOXI_TARGET __attribute__((always_inline)) {
    return _mm512_load_pd(p);
  };
  const auto all = [&](double x) FOXI_TARGET __attribute__((always_inline)) { return _mm512_set1_pd(x); };
  const auto sel = [&](__mmask8 m, V yes, V no) FOXI_TARGET __attribute__((always_inline)) {
    return _mm512_mask_blend_pd(m, no, yes);
  };
  V P[4][3];
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 3; ++j) P[k][j] = ld(b.P[k][j]);
  V n[4][3], h[4];
  for (int f = 0; f < 4; ++f) {
    const V* a = P[kFace[f][0]];
    const V* bb = P[kFace[f][1]];
    const V* c = P[kFace[f][2]];
    const V u[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[f][0] = u[1] * w[2] - u[2] * w[1];
    n[f][1] = u[2] * w[0] - u[0] * w[2];
    n[f][2] = u[0] * w[1] - u[1] * w[0];
  }
  const V det =
      -(n[1][0] * (P[1][0] - P[0][0]) + n[1][1] * (P[1][1] - P[0][1]) + n[1][2] * (P[1][2] - P[0][2]));
  __mmask8 ok = _mm512_cmp_pd_mask(_mm512_abs_pd(det), _mm512_setzero_pd(), _CMP_GT_OQ);
  const V cv0 = ld(b.cv[0]);
  const V df1 = ld(b.cv[1]) - cv0, df2 = ld(b.cv[2]) - cv0, df3 = ld(b.cv[3]) - cv0, inv = all(-1) / det;
  V g[3];
  for (int j = 0; j < 3; ++j) g[j] = (df1 * n[1][j] + df2 * n[2][j] + df3 * n[3][j]) * inv;
  const V sign = sel(_mm512_cmp_pd_mask(det, _mm512_setzero_pd(), _CMP_GT_OQ), all(1), all(-1));
  for (int f = 0; f < 4; ++f) {
    for (V& x : n[f]) x = x * sign;
    const V* a = P[kFace[f][0]];
    h[f] = n[f][0] * a[0] + n[f][1] * a[1] + n[f][2] * a[2];
  }
  // TetSetup's.
  const V o00 = all(b.o0[0]), o01 = all(b.o0[1]), d00 = all(b.d0[0]), d01 = all(b.d0[1]), d02 = all(b.d0[2]);
  const V ox = all(b.ox), oy = all(b.oy), dx = all(b.dx), dy = all(b.dy);
  V ndA[4], ndB[4], ndC[4], numA[4], numB[4], numC[4];
  for (int k = 0; k < 4; ++k) {
    ndA[k] = n[k][0] * d00 + n[k][1] * d01 + n[k][2] * d02;
    ndB[k] = n[k][0] * dx;
    ndC[k] = n[k][1] * dy;
    numA[k] = h[k] - (n[k][0] * o00 + n[k][1] * o01);
    numB[k] = -n[k][0] * ox;
    numC[k] = -n[k][1] * oy;
  }
  const V vA = cv0 + g[0] * (o00 - P[0][0]) + g[1] * (o01 - P[0][1]) - g[2] * P[0][2];
  const V vB = g[0] * ox, vC = g[1] * oy;
  const V gdA = g[0] * d00 + g[1] * d01 + g[2] * d02, gdB = g[0] * dx, gdC = g[1] * dy;
  // The clipping plane (draw_tet's), all four corners beyond it; the face planes through the eye
  // (or along the rays) bound nothing.
  V d2[4];  // the corners' squared distances from the eye
  for (int k = 0; k < 4; ++k) d2[k] = P[k][0] * P[k][0] + P[k][1] * P[k][1] + P[k][2] * P[k][2];
  if (b.perspective) {
    const V reach2 = _mm512_max_pd(_mm512_max_pd(d2[0], d2[1]), _mm512_max_pd(d2[2], d2[3]));
    V clip = _mm512_max_pd(_mm512_sqrt_pd(reach2) * all(b.focal) / all(kMaxPixel), all(b.near));
    clip = sel(_mm512_cmp_pd_mask(clip, _mm512_setzero_pd(), _CMP_GT_OQ), clip, all(1e-300));
    for (int k = 0; k < 4; ++k) ok &= _mm512_cmp_pd_mask(P[k][2], clip, _CMP_GE_OQ);
  }
  // draw_tet's test of a face plane through the eye: to a millionth of the face's nearest drawn
  // distance (its nearest corner, or its clipping plane from its own farthest corner).
  for (int k = 0; k < 4; ++k) {
    const V nn = n[k][0] * n[k][0] + n[k][1] * n[k][1] + n[k][2] * n[k][2];
    const V off = b.perspective ? h[k] : n[k][2];
    V scale2 = all(1);
    if (b.perspective) {
      const int c0 = k == 0 ? 1 : 0, c1 = k <= 1 ? 2 : 1, c2 = k <= 2 ? 3 : 2;  // the face's corners
      const V lo2 = _mm512_min_pd(_mm512_min_pd(d2[c0], d2[c1]), d2[c2]);
      const V hi2 = _mm512_max_pd(_mm512_max_pd(d2[c0], d2[c1]), d2[c2]);
      const V clip_f = _mm512_max_pd(_mm512_sqrt_pd(hi2) * all(b.focal) / all(kMaxPixel), all(b.near));
      scale2 = _mm512_max_pd(clip_f * clip_f, lo2);
    }
    const __mmask8 edge_on = _mm512_cmp_pd_mask(off * off, all(1e-12) * nn * scale2, _CMP_LE_OQ);
    const V zero = _mm512_setzero_pd();
    ndA[k] = sel(edge_on, zero, ndA[k]);
    ndB[k] = sel(edge_on, zero, ndB[k]);
    ndC[k] = sel(edge_on, zero, ndC[k]);
    numA[k] = sel(edge_on, zero, numA[k]);
    numB[k] = sel(edge_on, zero, numB[k]);
    numC[k] = sel(edge_on, zero, numC[k]);
  }
  // RowSetup's: re-centred on the first corner's pixel (within the tile) and depth.
  const V X = _mm512_cvtepi32_pd(
      _mm512_cvttpd_epi32(_mm512_min_pd(_mm512_max_pd(ld(b.q0[0]), all(b.x0)), all(b.x1))));
  const V Y = _mm512_cvtepi32_pd(
      _mm512_cvttpd_epi32(_mm512_min_pd(_mm512_max_pd(ld(b.q0[1]), all(b.y0)), all(b.y1))));
  const V s_ref = P[0][2];
  alignas(64) float out[40][8];
  auto put = [&](int field, V x) FOXI_TARGET __attribute__((always_inline)) {
    _mm256_store_ps(out[field], _mm512_cvtpd_ps(x));
  };
  for (int k = 0; k < 4; ++k) {
    put(k, ndA[k] + X * ndB[k] + Y * ndC[k]);
    put(4 + k, ndB[k]);
    put(8 + k, ndC[k]);
    const V A = numA[k] - s_ref * ndA[k], B = numB[k] - s_ref * ndB[k], C = numC[k] - s_ref * ndC[k];
    put(12 + k, A + X * B + Y * C);
    put(16 + k, B);
    put(20 + k, C);
  }
  const V vA2 = vA + s_ref * gdA, vB2 = vB + s_ref * gdB, vC2 = vC + s_ref * gdC;
  put(24, vA2 + X * vB2 + Y * vC2);
  put(25, vB2);
  put(26, vC2);
  put(27, gdA + X * gdB + Y * gdC);
  put(28, gdB);
  put(29, gdC);
  put(30, d00 + X * dx);
  put(31, d01 + Y * dy);
  put(32, (b.perspective ? all(b.near) : all(-std::numeric_limits<double>::infinity())) - s_ref);
  alignas(32) int xr[8], yr[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(xr), _mm512_cvtpd_epi32(X));
  _mm256_store_si256(reinterpret_cast<__m256i*>(yr), _mm512_cvtpd_epi32(Y));
  const float dxx = float(b.dx), dyy = float(b.dy), dz2 = float(b.d0[2] * b.d0[2]);
  for (int l = 0; l < TetBatch::kLanes; ++l) {
    RowSetup& r = b.rs[l];
    for (int k = 0; k < 4; ++k) {
      r.nd[k] = out[k][l];
      r.ndx[k] = out[4 + k][l];
      r.ndy[k] = out[8 + k][l];
      r.num[k] = out[12 + k][l];
      r.numx[k] = out[16 + k][l];
      r.numy[k] = out[20 + k][l];
    }
    r.v = out[24][l];
    r.vx = out[25][l];
    r.vy = out[26][l];
    r.gd = out[27][l];
    r.gdx = out[28][l];
    r.gdy = out[29][l];
    r.dx = out[30][l];
    r.dxx = dxx;
    r.dy = out[31][l];
    r.dyy = dyy;
    r.dz2 = dz2;
    r.near = out[32][l];
    r.xr = xr[l];
    r.yr = yr[l];
    b.ok[l] = (ok >> l) & 1;
  }
}

FOXI_TARGET void volume_tet_avx512(const RowSetup& r, const TableTransfer& tf, const VolumeAcc& acc,
                                   const double (*q)[2], int n_q, int x0, int x1, int y0, int y1,
                                   std::uint32_t t, PixelRun* runs, std::size_t& count, std::size_t& fast) {
  // The rows and the points' segments (corner_edges, shared with the portable path's tet_row_spans).
  CornerEdges e;
  // Four points (the usual tet): their six segments at once.
  if (!(n_q == 4 ? corner_edges4(q, y0, y1, e) : corner_edges(q, n_q, y0, y1, e))) return;
  const int ya = e.ya, yb = e.yb, n_edges = e.n;
  const __m512d iota = _mm512_set_pd(7, 6, 5, 4, 3, 2, 1, 0);
  const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d x_first = _mm512_set1_pd(double(x0)), x_last = _mm512_set1_pd(double(x1));
  const __m512d x_after = _mm512_set1_pd(double(x1) + 1);
  const __m512d half = _mm512_set1_pd(0.5), one = _mm512_set1_pd(1.0);
  int n_runs = 0;
  for (int y = ya; y <= yb; y += 8) {
    const __m512d yc = _mm512_add_pd(_mm512_set1_pd(y + 0.5), iota);
    __m512d lo = inf, hi = _mm512_sub_pd(_mm512_setzero_pd(), inf);
    for (int k = 0; k < n_edges; ++k) {
      const __mmask8 in = _mm512_cmp_pd_mask(yc, _mm512_set1_pd(e.y0[k]), _CMP_GE_OQ) &
                          _mm512_cmp_pd_mask(yc, _mm512_set1_pd(e.y1[k]), _CMP_LE_OQ);
      // On a grid of 2^-15 pixel (volume_setup.cpp's tet_row_spans says why), rounded to nearest.
      const __m512d x =
          _mm512_roundscale_pd(_mm512_fmadd_pd(_mm512_sub_pd(yc, _mm512_set1_pd(e.y0[k])),
                                               _mm512_set1_pd(e.slope[k]), _mm512_set1_pd(e.x0[k])),
                               (15 << 4) | _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
      lo = _mm512_mask_min_pd(lo, in, lo, x);
      hi = _mm512_mask_max_pd(hi, in, hi, x);
    }
    // The pixels whose centre x + 0.5 lies in [lo, hi): from ceil(lo - 0.5) to ceil(hi - 0.5) - 1,
    // within the tile (an empty row: first > last).
    lo = _mm512_min_pd(_mm512_max_pd(_mm512_sub_pd(lo, half), x_first), x_after);
    hi = _mm512_max_pd(_mm512_min_pd(_mm512_sub_pd(hi, half), _mm512_add_pd(x_last, one)), x_first);
    alignas(32) int ilo[8], ihi[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(ilo),
                       _mm512_cvt_roundpd_epi32(lo, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC));
    _mm256_store_si256(
        reinterpret_cast<__m256i*>(ihi),
        _mm256_sub_epi32(_mm512_cvt_roundpd_epi32(hi, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC),
                         _mm256_set1_epi32(1)));
    // The rows with pixels appended without a branch on each (whether a row has pixels depends on
    // the data: a branch there was mispredicted often; 6% of a frame's CPU with corner_edges4).
    if (n_runs > kMaxRuns - 8) {
      runs_impl(r, tf, acc, runs, n_runs, t, count, fast);
      n_runs = 0;
    }
    const int rows = std::min(8, yb - y + 1);
    for (int i = 0; i < rows; ++i) {
      runs[n_runs] = {y + i, ilo[i], ihi[i]};
      n_runs += ilo[i] <= ihi[i];
    }
  }
  if (n_runs > 0) runs_impl(r, tf, acc, runs, n_runs, t, count, fast);
}
#undef FOXI_TARGET
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace volume_detail
}  // namespace foxi
#endif
