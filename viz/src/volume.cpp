// Direct volume rendering by projected tetrahedra (volume.hpp): each tet's front faces rasterized with
// the painter's fixed point and fill rule, the ray's segment through the tet found per pixel from the
// tet's four planes, and the emission-absorption integral of the linear field over it blended back to
// front. Speed (issue 23): the screen is cut into tiles, a batch's tets binned to the tiles they touch
// in the batch's order, and each thread takes whole tiles (a tile's pixels stay in its core's cache;
// no two threads write one pixel; every pixel still sees its tets in order, so a finished batch is
// the exact picture of the far part); per tet one set-up (its planes, field and rays linear in the
// pixel's x and y), its pixels listed and integrated eight at a time with AVX-512 where the CPU has it,
// with the portable path's operations (the same picture bit for bit).
#include "foxi/viz/volume.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "foxi/model/delaunay.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "raster_impl.hpp"
#ifdef __x86_64__
#include <immintrin.h>
#endif
#include <cstdlib>

namespace foxi {

using namespace raster_detail;

double volume_extinction(const VolumeParams& params, double v) {
  const std::vector<OpacityPoint>& c = params.opacity_curve;
  if (c.empty() || std::isnan(v)) return 0;
  double a = 0;
  if (v <= c.front().value) {
    a = c.front().opacity;
  } else if (v >= c.back().value) {
    a = c.back().opacity;
  } else {
    const auto hi =
        std::upper_bound(c.begin(), c.end(), v, [](double x, const OpacityPoint& p) { return x < p.value; });
    const auto lo = hi - 1;
    const double t = (v - lo->value) / (hi->value - lo->value);
    a = lo->opacity + t * (hi->opacity - lo->opacity);
  }
  return -std::log1p(-std::clamp(a, 0.0, 0.999999)) / params.unit_length;
}

namespace {

// The integral over one segment with a transfer function tf (tau(v), position(v), rgb(v, out)).
template <class Transfer>
void integrate(const Transfer& tf, double v_far, double v_near, double length, float c[3]) {
  if (!(length > 0)) return;
  // Steps of at most 1/64 of the colour scale and of optical depth at most 1/4 (the ends' and the
  // middle's extinction), at most 256.
  const double span = std::abs(tf.position(v_near) - tf.position(v_far));
  const double tau_max = std::max({tf.tau(v_far), tf.tau(v_near), tf.tau(0.5 * (v_far + v_near))});
  const double want = std::max(std::isfinite(span) ? span * 64 : 1.0, tau_max * length * 4);
  const int steps = std::clamp(int(std::ceil(std::min(want, 256.0))), 1, 256);
  const double dl = length / steps;
  for (int k = 0; k < steps; ++k) {
    const double v = v_far + (k + 0.5) / steps * (v_near - v_far);
    const double tau = tf.tau(v);
    if (!(tau > 0)) continue;
    const float a = float(-std::expm1(-tau * dl));
    float rgb[3];
    tf.rgb(v, rgb);
    for (int j = 0; j < 3; ++j) c[j] = rgb[j] * a + c[j] * (1 - a);
  }
}

// The transfer function as given (each extinction from the curve, each colour from the scale).
struct ExactTransfer {
  const VolumeParams& p;
  double tau(double v) const { return volume_extinction(p, v); }
  double position(double v) const { return p.scale.position(v); }
  void rgb(double v, float out[3]) const {
    const std::uint32_t col = p.scale.color(v);
    for (int j = 0; j < 3; ++j) out[j] = float((col >> (8 * j)) & 255u);
  }
};

// The painter's: the extinction tabulated at 4097 values across the curve (constant beyond its ends)
// and interpolated linearly, the colour map's 256 entries, so a sample costs no logarithm. With a
// linear colour scale also the pre-integrated form (integrate_fast): the antiderivatives over the
// value of the extinction, T(v) = int tau dv, and of the extinction-weighted colour, K(v) = int c tau dv,
// tabulated on a fine grid.
struct TableTransfer {
  static constexpr int kN = 4096;
  static constexpr int kG = 8192;  // the antiderivatives' grid: 1/32 of a colour map entry or finer
  const VolumeParams* p = nullptr;
  double lo = 0, hi = 0, inv_step = 0;
  std::vector<double> tau_at;
  float lut[256][3] = {};
  float nan_rgb[3] = {};
  // Pre-integration: grid [g_lo, g_hi], 4 doubles per node (T, K red, K green, K blue); the slopes
  // beyond the grid (tau and the colour are constant there).
  bool pre = false;
  double g_lo = 0, g_hi = 0, g_inv = 0, pos_scale = 0;
  std::vector<double> F;
  double slope_lo[4] = {}, slope_hi[4] = {};
  float lut_step = 0;  // the largest difference of two neighbouring colour map entries, one channel
  explicit TableTransfer(const VolumeParams& params) : p(&params) {
    if (!params.opacity_curve.empty()) {
      lo = params.opacity_curve.front().value;
      hi = params.opacity_curve.back().value;
    }
    tau_at.resize(kN + 1);
    for (int i = 0; i <= kN; ++i) tau_at[std::size_t(i)] = volume_extinction(params, lo + (hi - lo) * i / kN);
    inv_step = hi > lo ? kN / (hi - lo) : 0;
    for (int i = 0; i < 256; ++i) {
      const std::uint32_t e = color_map_entry(params.scale.map, i);
      for (int j = 0; j < 3; ++j) lut[i][j] = float((e >> (8 * j)) & 255u);
    }
    for (int i = 1; i < 256; ++i)
      for (int j = 0; j < 3; ++j) lut_step = std::max(lut_step, std::abs(lut[i][j] - lut[i - 1][j]));
    for (int j = 0; j < 3; ++j) nan_rgb[j] = float((params.scale.nan_color >> (8 * j)) & 255u);
    const ColorScale& sc = params.scale;
    if (!sc.log && std::isfinite(sc.lo) && std::isfinite(sc.hi) && sc.hi > sc.lo &&
        !params.opacity_curve.empty()) {
      pre = true;
      g_lo = std::min(sc.lo, lo);
      g_hi = std::max(sc.hi, hi);
      g_inv = kG / (g_hi - g_lo);
      pos_scale = 1 / (sc.hi - sc.lo);
      // Each cell integrated with 32 midpoint samples (tau is linear and the colour constant between
      // breakpoints, so the error is that of a breakpoint inside a sample: 1/32 of a cell).
      constexpr int kSub = 32;
      F.assign(4 * std::size_t(kG + 1), 0.0);
      const double dv = (g_hi - g_lo) / kG;
      for (int i = 0; i < kG; ++i) {
        double acc[4] = {};
        for (int k = 0; k < kSub; ++k) {
          const double v = g_lo + (i + (k + 0.5) / kSub) * dv;
          const double t = tau(v);
          float c[3];
          rgb(v, c);
          acc[0] += t;
          for (int j = 0; j < 3; ++j) acc[j + 1] += t * c[j];
        }
        for (int j = 0; j < 4; ++j)
          F[4 * std::size_t(i + 1) + std::size_t(j)] =
              F[4 * std::size_t(i) + std::size_t(j)] + acc[j] * dv / kSub;
      }
      const double below = g_lo - 1, above = g_hi + 1;
      float cb[3], ca[3];
      rgb(below, cb);
      rgb(above, ca);
      slope_lo[0] = tau(below);
      slope_hi[0] = tau(above);
      for (int j = 0; j < 3; ++j) {
        slope_lo[j + 1] = slope_lo[0] * cb[j];
        slope_hi[j + 1] = slope_hi[0] * ca[j];
      }
    }
  }
  double tau(double v) const {
    if (std::isnan(v) || tau_at.empty()) return 0;
    const double x = std::clamp((v - lo) * inv_step, 0.0, double(kN));
    const int i = std::min(int(x), kN - 1);
    const double f = x - i;
    return tau_at[std::size_t(i)] + f * (tau_at[std::size_t(i) + 1] - tau_at[std::size_t(i)]);
  }
  double position(double v) const { return p->scale.position(v); }
  void rgb(double v, float out[3]) const {
    const double t = p->scale.position(v);
    const float* c = std::isnan(t) ? nan_rgb : lut[int(std::clamp(t * 256, 0.0, 255.0))];
    std::copy(c, c + 3, out);
  }
  // The antiderivatives (T, K) at v.
  void antiderivative(double v, double out[4]) const {
    const double x = (v - g_lo) * g_inv;
    if (x <= 0) {
      for (int j = 0; j < 4; ++j) out[j] = F[std::size_t(j)] + (v - g_lo) * slope_lo[j];
    } else if (x >= kG) {
      for (int j = 0; j < 4; ++j) out[j] = F[4 * std::size_t(kG) + std::size_t(j)] + (v - g_hi) * slope_hi[j];
    } else {
      const int i = std::min(int(x), kG - 1);
      const double f = x - i;
      const double* a = &F[4 * std::size_t(i)];
      for (int j = 0; j < 4; ++j) out[j] = a[j] + f * (a[j + 4] - a[j]);
    }
  }
};

// The same integral as integrate() in closed form where that is as exact: with the optical depth of
// the segment D = L (T(v_near) - T(v_far)) / (v_near - v_far) (exact for the tabulated tau), its
// opacity is A = 1 - exp(-D), and its colour is taken as the extinction-weighted mean colour
// (K(v_near) - K(v_far)) / (T(v_near) - T(v_far)) times A, which neglects the attenuation of the
// segment's own far part by its near part: the weights e^-(D-u) against A/D (u the optical depth from
// the far end) differ by at most D/2, so the colour errs by at most dc D^2 / 4, dc the colour's spread
// along the segment (at most lut_step per colour map entry crossed). Used where that bound is under
// 1/4 of a level and the optical depth at most 1; a thicker or more colourful segment is cut into
// pieces that meet it. A segment under 2 grid cells (where the table's cell averaging would show)
// takes its midpoint. False (the caller steps) for a log colour scale, NaN, a thin but optically thick
// segment.
// e^-D for 0 <= D <= 1 as (e^-x)^8, x = D/8 <= 1/8, e^-x by its Taylor series to x^5 (error under
// x^6 / 720 < 5e-9, 4e-8 after the squarings), in a short dependency chain: cheaper than exp.
double exp_neg_small(double D) {
  const double x = 0.125 * D, x2 = x * x;
  double e = (1 - x) + x2 * (0.5 - x * (1.0 / 6)) + x2 * x2 * (1.0 / 24 - x * (1.0 / 120));
  e *= e;
  e *= e;
  return e * e;
}

// One piece in closed form, given the antiderivatives at its ends (a: far, b: near): false where the
// bound above does not hold.
bool closed_piece(const TableTransfer& tf, const double a[4], const double b[4], double dv, double length,
                  float c[3]) {
  const double dT = b[0] - a[0];
  const double D = length * dT / dv;
  if (!(D > 0)) return D == 0;  // no extinction anywhere on the piece: nothing to blend
  const double spread = std::min(255.0, (std::abs(dv) * tf.pos_scale * 256 + 1) * tf.lut_step);
  if (D > 1 || spread * D * D > 1) return false;
  const double e = exp_neg_small(D);
  const double w = (1 - e) / dT;
  for (int j = 0; j < 3; ++j) c[j] = float((b[j + 1] - a[j + 1]) * w + c[j] * e);
  return true;
}

bool integrate_fast(const TableTransfer& tf, double v_far, double v_near, double length, float c[3]) {
  if (!tf.pre) return false;
  const double dv = v_near - v_far;
  const double cells = std::abs(dv) * tf.g_inv;
  if (!(cells >= 2)) {
    // Under 2 grid cells (1/16 of a colour map entry): the value's midpoint, as the steps would
    // take it (one step: the spread is under one entry), unless the piece is optically thick.
    if (!(cells >= 0)) return false;  // NaN
    const double vm = 0.5 * (v_far + v_near);
    const double D = tf.tau(vm) * length;
    if (!(D <= 1)) return false;
    float rgb[3];
    tf.rgb(vm, rgb);
    const double e = exp_neg_small(D);
    for (int j = 0; j < 3; ++j) c[j] = float(rgb[j] * (1 - e) + c[j] * e);
    return true;
  }
  double a[4], b[4];
  tf.antiderivative(v_far, a);
  tf.antiderivative(v_near, b);
  if (closed_piece(tf, a, b, dv, length, c)) return true;
  // Too thick or too colourful for one piece: n equal pieces of the value (each at least 2 grid
  // cells), enough that the average piece meets the bound; a piece that still does not is stepped.
  const double D = length * (b[0] - a[0]) / dv;
  const double spread = std::min(255.0, (std::abs(dv) * tf.pos_scale * 256 + 1) * tf.lut_step);
  const int n = std::clamp(int(std::ceil(std::max(D, std::sqrt(spread) * D) * 1.25)), 2,
                           std::max(2, std::min(64, int(cells / 2))));
  if (!(std::isfinite(D)) || cells < 4) return false;
  double lo[4];
  std::copy(a, a + 4, lo);
  for (int i = 0; i < n; ++i) {
    const double v0 = v_far + dv * i / n, v1 = i + 1 == n ? v_near : v_far + dv * (i + 1) / n;
    double hi[4];
    if (i + 1 == n)
      std::copy(b, b + 4, hi);
    else
      tf.antiderivative(v1, hi);
    if (!closed_piece(tf, lo, hi, v1 - v0, length / n, c)) integrate(tf, v0, v1, length / n, c);
    std::copy(hi, hi + 4, lo);
  }
  return true;
}

// Per pixel the colour so far and the nearest tet blended, side by side (16 bytes): a tet's row of
// pixels touches one run of cache lines, not two.
struct Pixel {
  float c[3];
  std::uint32_t front;
};

// A tet's pixels: the ray o + s d of pixel (x, y) (camera frame; perspective: o = 0 and s the depth)
// has o and d linear in x and y, so each plane's n.d and h - n.o, the field's g.(o - P0) and g.d and
// the direction's x and y are A + x B + y C too: set up once per tet, a few multiply-adds a pixel.
struct TetSetup {
  double ndA[4], ndB[4], ndC[4], numA[4], numB[4], numC[4];
  double vA, vB, vC, gdA, gdB, gdC, dxA, dxB, dyA, dyC, dz2, near;
  // The ray's segment through the tet at pixel (x, y): false where the ray misses it (a snapped edge
  // pixel).
  bool segment(int x, int y, double& v_far, double& v_near, double& len) const {
    const double xf = x, yf = y;
    double s_in = near, s_out = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) {
      const double nd = ndA[k] + xf * ndB[k] + yf * ndC[k];
      const double sk = (numA[k] + xf * numB[k] + yf * numC[k]) / nd;
      if (nd < 0)
        s_in = std::max(s_in, sk);
      else if (nd > 0)
        s_out = std::min(s_out, sk);
    }
    if (!(s_out > s_in)) return false;
    const double v0 = vA + xf * vB + yf * vC, gd = gdA + xf * gdB + yf * gdC;
    const double dx = dxA + xf * dxB, dy = dyA + yf * dyC;
    len = (s_out - s_in) * std::sqrt(dx * dx + dy * dy + dz2);
    v_far = v0 + s_out * gd;
    v_near = v0 + s_in * gd;
    return true;
  }
};

void composite(const TableTransfer& tf, double v_far, double v_near, double len, float c[3],
               std::size_t& fast) {
  if (integrate_fast(tf, v_far, v_near, len, c))
    ++fast;
  else
    integrate(tf, v_far, v_near, len, c);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FOXI_VOLUME_AVX512 1
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
// A + x B + y C, in TetSetup::segment's order.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) inline __m512d linear_xy(__m512d xf, __m512d yf,
                                                                                   double A, double B,
                                                                                   double C) {
  return _mm512_add_pd(_mm512_add_pd(_mm512_set1_pd(A), _mm512_mul_pd(xf, _mm512_set1_pd(B))),
                       _mm512_mul_pd(yf, _mm512_set1_pd(C)));
}

// The pixels (xs[i], ys[i]), i < n, eight at a time: TetSetup::segment and, for the common segment
// (the pre-integrated table, at least 2 grid cells, inside the grid, one closed piece),
// integrate_fast with the same operations in the same order (viz is built with -ffp-contract=off, and
// the gathers read the same table), so the picture is bit for bit the portable path's; every other
// segment (thin, thick, outside the grid, NaN, a log scale) goes through composite() one pixel at a
// time.
__attribute__((target("avx512f,avx512vl,avx512dq,avx2"))) void volume_pixels_avx512(
    const TetSetup& r, const TableTransfer& tf, Pixel* acc, int width, const int* xs, const int* ys, int n_px,
    std::uint32_t t, std::size_t& count, std::size_t& fast) {
  const __m512d zero = _mm512_setzero_pd();
  const __m512d one = _mm512_set1_pd(1.0), inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512d abs_mask = _mm512_castsi512_pd(_mm512_set1_epi64(0x7fffffffffffffffLL));
  const __m256i tet = _mm256_set1_epi32(int(t)), w4 = _mm256_set1_epi32(4 * width);
  const __m256i last_cell = _mm256_set1_epi32(TableTransfer::kG - 1);
  const __m512d g_lo = _mm512_set1_pd(tf.g_lo), g_inv = _mm512_set1_pd(tf.g_inv);
  const __m512d grid_end = _mm512_set1_pd(double(TableTransfer::kG)), two = _mm512_set1_pd(2.0);
  const __m512d pos_scale = _mm512_set1_pd(tf.pos_scale), lut_step = _mm512_set1_pd(double(tf.lut_step));
  const __m512d c255 = _mm512_set1_pd(255.0), c256 = _mm512_set1_pd(256.0);
  float* const base_c = &acc[0].c[0];
  for (int i0 = 0; i0 < n_px; i0 += 8) {
    const int n = std::min(8, n_px - i0);
    __mmask8 live = __mmask8((1u << n) - 1u);
    const __m256i xi = _mm256_maskz_loadu_epi32(live, xs + i0), yi = _mm256_maskz_loadu_epi32(live, ys + i0);
    // Each pixel's first float in acc (16 bytes, 4 floats a pixel).
    const __m256i pixel_index = _mm256_add_epi32(_mm256_mullo_epi32(yi, w4), _mm256_slli_epi32(xi, 2));
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
    _mm256_mask_i32scatter_epi32(base_c + 3, live, pixel_index, tet, 4);
    const __m512d v0 = linear_xy(xf, yf, r.vA, r.vB, r.vC), gd = linear_xy(xf, yf, r.gdA, r.gdB, r.gdC);
    const __m512d dx = _mm512_add_pd(_mm512_set1_pd(r.dxA), _mm512_mul_pd(xf, _mm512_set1_pd(r.dxB)));
    const __m512d dy = _mm512_add_pd(_mm512_set1_pd(r.dyA), _mm512_mul_pd(yf, _mm512_set1_pd(r.dyC)));
    const __m512d len = _mm512_mul_pd(
        _mm512_sub_pd(s_out, s_in),
        _mm512_sqrt_pd(_mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)),
                                     _mm512_set1_pd(r.dz2))));
    const __m512d v_far = _mm512_add_pd(v0, _mm512_mul_pd(s_out, gd));
    const __m512d v_near = _mm512_add_pd(v0, _mm512_mul_pd(s_in, gd));
    __mmask8 done = 0;
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
        const __m256i ka = _mm256_slli_epi32(ia, 2), kb = _mm256_slli_epi32(ib, 2);
        __m512d a[4], b[4];
        for (int j = 0; j < 4; ++j) {
          const double* F = tf.F.data() + j;
          const __m512d a0 = _mm512_mask_i32gather_pd(zero, m, ka, F, 8);
          const __m512d a1 = _mm512_mask_i32gather_pd(zero, m, ka, F + 4, 8);
          const __m512d b0 = _mm512_mask_i32gather_pd(zero, m, kb, F, 8);
          const __m512d b1 = _mm512_mask_i32gather_pd(zero, m, kb, F + 4, 8);
          a[j] = _mm512_add_pd(a0, _mm512_mul_pd(fa, _mm512_sub_pd(a1, a0)));
          b[j] = _mm512_add_pd(b0, _mm512_mul_pd(fb, _mm512_sub_pd(b1, b0)));
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
        for (int j = 0; j < 3; ++j) {
          float* base = base_c + j;
          const __m512d c =
              _mm512_cvtps_pd(_mm256_mmask_i32gather_ps(_mm256_setzero_ps(), blend, pixel_index, base, 4));
          const __m512d out = _mm512_add_pd(_mm512_mul_pd(em[j], w), _mm512_mul_pd(c, e));
          _mm256_mask_i32scatter_ps(base, blend, pixel_index, _mm512_cvtpd_ps(out), 4);
        }
      }
      done = __mmask8(blend | none);
      fast += std::size_t(__builtin_popcount(done));
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
#endif

}  // namespace

void integrate_segment(const VolumeParams& params, double v_far, double v_near, double length, float c[3]) {
  integrate(ExactTransfer{params}, v_far, v_near, length, c);
}

struct VolumePainter::Impl {
  const Mesh* mesh = nullptr;
  Projector proj;
  std::span<const double> corner;
  VolumeParams params;
  int lanes = 1;
  std::vector<Pixel> acc;
  bool vector_rows = false;     // volume_row_avx512 for the pixel rows
  std::vector<double> cam_xyz;  // the nodes in the camera frame, once (not per tet and lane)
  std::vector<std::size_t> lane_samples, lane_fast;
  std::unique_ptr<TableTransfer> transfer;

  Impl(const Mesh& m, const Camera& camera, int w, int h) : mesh(&m), proj(camera, w, h) {}

  // Screen tiles of kTileW x kTileH pixels (128 KiB of Pixel, which stays in the core's cache while
  // the tile's tets are drawn): draw() bins a batch's tets by their screen bounds, in order, and each
  // thread takes whole tiles, so every pixel still sees its tets in the given order and no two
  // threads write one pixel.
  static constexpr int kTileW = 128, kTileH = 64;
  struct Tile {
    int x0, x1, y0, y1;
  };
  int tiles_x = 0, tiles_y = 0;
  std::vector<double> node_px;  // per node its pixel (x, y); NaN where it is not in front of the eye
  std::vector<std::uint32_t> tile_start, tile_tets, cursor;
  std::vector<std::array<std::uint16_t, 4>> tet_tiles;  // per tet of the batch: tiles x0, x1, y0, y1

  // The tiles tet t's projection can touch (the bounds of its nodes' pixels, a pixel wider: the
  // rasterized pixels' centres lie in the snapped projection); none off screen. A tet with a node not
  // in front of the eye: the bounds of its part at depth >= nb, nb the least near plane clip_near
  // can use for any of its faces (that part holds every face's clipped polygon).
  std::array<std::uint16_t, 4> tiles_of(std::uint32_t t) const {
    double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
    auto add = [&](const double* q) {
      x_lo = std::min(x_lo, q[0]);
      x_hi = std::max(x_hi, q[0]);
      y_lo = std::min(y_lo, q[1]);
      y_hi = std::max(y_hi, q[1]);
    };
    const std::uint32_t* node = &mesh->tet[4 * std::size_t(t)];
    bool behind = false;
    for (int k = 0; k < 4; ++k) behind = behind || std::isnan(node_px[2 * std::size_t(node[k])]);
    if (!behind) {
      for (int k = 0; k < 4; ++k) add(&node_px[2 * std::size_t(node[k])]);
    } else {
      const double* P[4];
      double dmin = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 4; ++k) {
        P[k] = &cam_xyz[3 * std::size_t(node[k])];
        dmin = std::min(dmin, std::sqrt(P[k][0] * P[k][0] + P[k][1] * P[k][1] + P[k][2] * P[k][2]));
      }
      // clip_near: a face's plane is max(near, dmax * focal / kMaxPixel), dmax over its corners.
      const double nb = std::max(params.near, dmin * proj.focal / kMaxPixel);
      if (!(nb > 0)) return {0, std::uint16_t(tiles_x - 1), 0, std::uint16_t(tiles_y - 1)};
      for (int i = 0; i < 4; ++i) {
        double q[2];
        if (P[i][2] >= nb) {
          proj.camera_to_pixel(P[i], q);
          add(q);
        }
        for (int j = i + 1; j < 4; ++j)
          if ((P[i][2] < nb) != (P[j][2] < nb)) {
            const double u = (nb - P[i][2]) / (P[j][2] - P[i][2]);
            const double c[3] = {P[i][0] + u * (P[j][0] - P[i][0]), P[i][1] + u * (P[j][1] - P[i][1]), nb};
            proj.camera_to_pixel(c, q);
            add(q);
          }
      }
      // Snapping and the rounding of the cut points: a few pixels more.
      x_lo -= 4;
      y_lo -= 4;
      x_hi += 4;
      y_hi += 4;
    }
    if (!(x_hi >= -1 && y_hi >= -1 && x_lo <= proj.width + 1 && y_lo <= proj.height + 1)) return {1, 0, 1, 0};
    auto tile = [](double p, int size, int count) {
      return std::uint16_t(std::clamp(int(std::floor(std::clamp(p, -2.0, 1e7) / size)), 0, count - 1));
    };
    return {tile(x_lo - 1, kTileW, tiles_x), tile(x_hi + 1, kTileW, tiles_x), tile(y_lo - 1, kTileH, tiles_y),
            tile(y_hi + 1, kTileH, tiles_y)};
  }

  // The batch's tets into the tiles' lists (tile_start, tile_tets), each list in the batch's order:
  // the batch cut into `lanes` consecutive parts, each part's tets counted per tile and then written
  // by its own thread after the earlier parts' (so the order holds within each tile).
  void bin(std::span<const std::uint32_t> tets) {
    const std::size_t n_tiles = std::size_t(tiles_x) * std::size_t(tiles_y);
    const std::size_t parts = std::size_t(lanes);
    tet_tiles.resize(tets.size());
    cursor.assign(parts * n_tiles, 0);  // per part: its count per tile, then where it writes next
    auto part_range = [&](std::size_t part) {
      return std::pair{tets.size() * part / parts, tets.size() * (part + 1) / parts};
    };
    auto each_tile = [&](const std::array<std::uint16_t, 4>& b, auto&& fn) {
      for (int ty = b[2]; ty <= b[3]; ++ty)
        for (int tx = b[0]; tx <= b[1]; ++tx) fn(std::size_t(ty) * std::size_t(tiles_x) + std::size_t(tx));
    };
    run_parts(lanes, [&](int lane) {
      const auto [i0, i1] = part_range(std::size_t(lane));
      std::uint32_t* count = &cursor[std::size_t(lane) * n_tiles];
      for (std::size_t i = i0; i < i1; ++i) {
        // Fetched ahead as in draw(): the order's tets lie far apart in memory.
        if (i + 8 < i1) __builtin_prefetch(&mesh->tet[4 * std::size_t(tets[i + 8])]);
        if (i + 4 < i1) {
          const std::uint32_t* node = &mesh->tet[4 * std::size_t(tets[i + 4])];
          for (int j = 0; j < 4; ++j) __builtin_prefetch(&node_px[2 * std::size_t(node[j])]);
        }
        each_tile(tet_tiles[i] = tiles_of(tets[i]), [&](std::size_t k) { ++count[k]; });
      }
    });
    tile_start.assign(n_tiles + 1, 0);
    std::uint32_t total = 0;
    for (std::size_t k = 0; k < n_tiles; ++k) {
      tile_start[k] = total;
      for (std::size_t part = 0; part < parts; ++part) {
        const std::uint32_t c = cursor[part * n_tiles + k];
        cursor[part * n_tiles + k] = total;
        total += c;
      }
    }
    tile_start[n_tiles] = total;
    tile_tets.resize(total);
    run_parts(lanes, [&](int lane) {
      const auto [i0, i1] = part_range(std::size_t(lane));
      std::uint32_t* next = &cursor[std::size_t(lane) * n_tiles];
      for (std::size_t i = i0; i < i1; ++i)
        each_tile(tet_tiles[i], [&](std::size_t k) { tile_tets[next[k]++] = tets[i]; });
    });
  }

  // A thread's list of the pixels of the tet it draws.
  struct Scratch {
    static constexpr int kRun = 256;
    alignas(64) int xs[kRun];
    alignas(64) int ys[kRun];
  };

  void draw_tet(std::uint32_t t, const Tile& tile, Scratch& scratch, std::size_t& count, std::size_t& fast) {
    const Rows rows{0, 1, tile.y0, tile.y1};
    const std::uint32_t* node = &mesh->tet[4 * std::size_t(t)];
    const double* cv = &corner[4 * std::size_t(t)];
    double P[4][3];
    for (int k = 0; k < 4; ++k) std::copy_n(&cam_xyz[3 * std::size_t(node[k])], 3, P[k]);
    // The field's gradient in the camera frame: (P[k] - P[0]) . g = cv[k] - cv[0], by Cramer's rule.
    double e[3][3], df[3];
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) e[k][j] = P[k + 1][j] - P[0][j];
      df[k] = cv[k + 1] - cv[0];
    }
    auto det3 = [](const double a[3], const double b[3], const double c[3]) {
      return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
             a[2] * (b[0] * c[1] - b[1] * c[0]);
    };
    const double det = det3(e[0], e[1], e[2]);
    if (!(std::abs(det) > 0)) return;  // flat
    double g[3];
    for (int j = 0; j < 3; ++j) {
      double m[3][3];
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) m[k][i] = i == j ? df[k] : e[k][i];
      g[j] = det3(m[0], m[1], m[2]) / det;
    }
    // Outward planes n . x = h of the four faces.
    double n[4][3], h[4];
    bool facing[4];
    int front_count = 0;
    for (int f = 0; f < 4; ++f) {
      const double* a = P[kFace[f][0]];
      const double* b = P[kFace[f][1]];
      const double* c = P[kFace[f][2]];
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                   w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      n[f][0] = u[1] * w[2] - u[2] * w[1];
      n[f][1] = u[2] * w[0] - u[0] * w[2];
      n[f][2] = u[0] * w[1] - u[1] * w[0];
      const double* opp = P[f];
      if (n[f][0] * (opp[0] - a[0]) + n[f][1] * (opp[1] - a[1]) + n[f][2] * (opp[2] - a[2]) > 0)
        for (double& x : n[f]) x = -x;
      h[f] = n[f][0] * a[0] + n[f][1] * a[1] + n[f][2] * a[2];
      facing[f] = proj.perspective ? h[f] < 0 : n[f][2] < 0;  // the eye on its outer side
      front_count += facing[f];
    }
    // The eye inside the tet (perspective, every plane's inner side): its back faces cover the screen
    // where the rays start inside it.
    const bool inside = front_count == 0;
    TetSetup r;
    {
      // o = o0 + x ox + y oy, d = d0 + x dx + y dy (see TetSetup).
      double o0[3] = {0, 0, 0}, d0[3] = {0, 0, 1}, ox = 0, oy = 0, dx = 0, dy = 0;
      if (proj.perspective) {
        d0[0] = (0.5 - proj.cx) / proj.focal;
        dx = 1 / proj.focal;
        d0[1] = -(0.5 - proj.cy) / proj.focal;
        dy = -1 / proj.focal;
      } else {
        o0[0] = (0.5 - proj.cx) / proj.scale;
        ox = 1 / proj.scale;
        o0[1] = -(0.5 - proj.cy) / proj.scale;
        oy = -1 / proj.scale;
      }
      for (int k = 0; k < 4; ++k) {
        r.ndA[k] = n[k][0] * d0[0] + n[k][1] * d0[1] + n[k][2] * d0[2];
        r.ndB[k] = n[k][0] * dx;
        r.ndC[k] = n[k][1] * dy;
        r.numA[k] = h[k] - (n[k][0] * o0[0] + n[k][1] * o0[1]);
        r.numB[k] = -n[k][0] * ox;
        r.numC[k] = -n[k][1] * oy;
      }
      r.vA = cv[0] + g[0] * (o0[0] - P[0][0]) + g[1] * (o0[1] - P[0][1]) - g[2] * P[0][2];
      r.vB = g[0] * ox;
      r.vC = g[1] * oy;
      r.gdA = g[0] * d0[0] + g[1] * d0[1] + g[2] * d0[2];
      r.gdB = g[0] * dx;
      r.gdC = g[1] * dy;
      r.dxA = d0[0];
      r.dxB = dx;
      r.dyA = d0[1];
      r.dyC = dy;
      r.dz2 = d0[2] * d0[2];
      r.near = proj.perspective ? std::max(params.near, 0.0) : -std::numeric_limits<double>::infinity();
    }
    // The tet's pixels (its front faces', which cover its projection once) are listed, then
    // integrated in runs of kRun: the vector path takes eight pixels of any rows at once.
    int n_px = 0;
    auto flush = [&] {
#ifdef FOXI_VOLUME_AVX512
      if (vector_rows) {
        volume_pixels_avx512(r, *transfer, acc.data(), proj.width, scratch.xs, scratch.ys, n_px, t, count,
                             fast);
        n_px = 0;
        return;
      }
#endif
      for (int i = 0; i < n_px; ++i) {
        double v_far, v_near, len;
        if (!r.segment(scratch.xs[i], scratch.ys[i], v_far, v_near, len))
          continue;  // a snapped edge pixel the ray misses
        Pixel& pix = acc[std::size_t(scratch.ys[i]) * std::size_t(proj.width) + std::size_t(scratch.xs[i])];
        composite(*transfer, v_far, v_near, len, pix.c, fast);
        pix.front = t;
        ++count;
      }
      n_px = 0;
    };
    auto add_run = [&](int y, int lo, int hi) {
      lo = std::max(lo, tile.x0);
      hi = std::min(hi, tile.x1);
      // Eight entries at a time (a fixed count the compiler writes as vectors), those past hi left
      // beyond n_px: the list keeps room for eight.
      for (int x = lo; x <= hi;) {
        if (n_px > Scratch::kRun - 8) flush();
        for (int i = 0; i < 8; ++i) {
          scratch.xs[n_px + i] = x + i;
          scratch.ys[n_px + i] = y;
        }
        const int m = std::min(8, hi - x + 1);
        n_px += m;
        x += m;
      }
    };
    // No node before the near plane clip_near would use for any face (the usual case): the four
    // corners snapped once, each front face from them (the same corners snap_polygon would give).
    bool direct = !inside;
    if (direct && proj.perspective) {
      double dmax = 0;
      for (int k = 0; k < 4; ++k)
        dmax = std::max(dmax, std::sqrt(P[k][0] * P[k][0] + P[k][1] * P[k][1] + P[k][2] * P[k][2]));
      double near_clip = std::max(params.near, dmax * proj.focal / kMaxPixel);
      if (!(near_clip > 0)) near_clip = 1e-300;
      for (int k = 0; k < 4; ++k) direct = direct && P[k][2] >= near_clip;
    }
    if (direct) {
      std::int64_t X4[4], Y4[4];
      for (int k = 0; k < 4; ++k) {
        double q[2];
        proj.camera_to_pixel(P[k], q);
        X4[k] = to_fixed(q[0]);
        Y4[k] = to_fixed(q[1]);
      }
      for (int f = 0; f < 4; ++f) {
        if (!facing[f]) continue;
        const std::int64_t X[3] = {X4[kFace[f][0]], X4[kFace[f][1]], X4[kFace[f][2]]},
                           Y[3] = {Y4[kFace[f][0]], Y4[kFace[f][1]], Y4[kFace[f][2]]};
        for_each_fan_triangle(X, Y, 3, [&](const std::int64_t* TX, const std::int64_t* TY, const int*) {
          raster_triangle(TX, TY, proj.width, proj.height, rows, add_run);
        });
      }
      flush();
      return;
    }
    for (int f = 0; f < 4; ++f) {
      if (facing[f] == inside) continue;
      double tri[3][3], v[kMaxPolyVolume][3];
      for (int k = 0; k < 3; ++k) std::copy(P[kFace[f][k]], P[kFace[f][k]] + 3, tri[k]);
      const int m = clip_near(proj, params.near, tri, 3, v);
      if (m == 0) continue;
      std::int64_t X[kMaxPolyVolume], Y[kMaxPolyVolume];
      double px[kMaxPolyVolume][2], w[kMaxPolyVolume];
      snap_polygon(
          proj, m, [&](int i) { return v[i]; }, X, Y, px, w);
      for_each_fan_triangle(X, Y, m, [&](const std::int64_t* TX, const std::int64_t* TY, const int*) {
        raster_triangle(TX, TY, proj.width, proj.height, rows, add_run);
      });
    }
    flush();
  }
  static constexpr int kMaxPolyVolume = 8;
};

VolumePainter::VolumePainter(const Mesh& mesh, const Camera& camera, int width, int height,
                             std::span<const double> corner, const VolumeParams& params)
    : impl_(std::make_unique<Impl>(mesh, camera, width, height)) {
  Impl& s = *impl_;
  if (corner.size() != mesh.tet.size())
    throw std::invalid_argument("volume: " + std::to_string(corner.size()) + " corner values for a mesh of " +
                                std::to_string(mesh.tet_count()) + " tets (4 per tet expected)");
  if (!(params.unit_length > 0) || !std::isfinite(params.unit_length))
    throw std::invalid_argument("volume: the unit length must be positive");
  for (std::size_t i = 0; i < params.opacity_curve.size(); ++i) {
    const OpacityPoint& p = params.opacity_curve[i];
    if (!(p.opacity >= 0 && p.opacity < 1) || !std::isfinite(p.value))
      throw std::invalid_argument("volume: opacity curve point " + std::to_string(i + 1) +
                                  ": the opacity must be in [0, 1) and the value finite");
    if (i > 0 && !(p.value > params.opacity_curve[i - 1].value))
      throw std::invalid_argument("volume: the opacity curve's values must increase");
  }
  s.corner = corner;
  s.params = params;
  s.cam_xyz.resize(mesh.xyz.size());
  for (std::size_t k = 0; k < mesh.node_count(); ++k) s.proj.to_camera(&mesh.xyz[3 * k], &s.cam_xyz[3 * k]);
  s.transfer = std::make_unique<TableTransfer>(s.params);
#ifdef FOXI_VOLUME_AVX512
  // Its pixel offsets are 32-bit (4 floats a pixel).
  s.vector_rows = volume_avx512() && std::size_t(width) * std::size_t(height) < (std::size_t(1) << 29);
#endif
  s.tiles_x = (width + Impl::kTileW - 1) / Impl::kTileW;
  s.tiles_y = (height + Impl::kTileH - 1) / Impl::kTileH;
  if (s.tiles_x > 65535 || s.tiles_y > 65535) throw std::invalid_argument("volume: the picture is too large");
  s.node_px.resize(2 * mesh.node_count());
  for (std::size_t k = 0; k < mesh.node_count(); ++k) {
    const double* c = &s.cam_xyz[3 * k];
    double* q = &s.node_px[2 * k];
    if (s.proj.perspective && !(c[2] > std::max(params.near, 0.0) && c[2] > 0))
      q[0] = q[1] = std::numeric_limits<double>::quiet_NaN();
    else
      s.proj.camera_to_pixel(c, q);
  }
  s.lanes = std::clamp(params.threads, 1, s.tiles_x * s.tiles_y);
  s.lane_samples.assign(std::size_t(s.lanes), 0);
  s.lane_fast.assign(std::size_t(s.lanes), 0);
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  s.acc.resize(pixels);
  const float bg[3] = {float(params.background & 255u), float((params.background >> 8) & 255u),
                       float((params.background >> 16) & 255u)};
  for (Pixel& p : s.acc) p = {{bg[0], bg[1], bg[2]}, kNone};
}

VolumePainter::~VolumePainter() = default;
VolumePainter::VolumePainter(VolumePainter&&) noexcept = default;
VolumePainter& VolumePainter::operator=(VolumePainter&&) noexcept = default;

void VolumePainter::draw(std::span<const std::uint32_t> tets) {
  Impl& s = *impl_;
  for (std::uint32_t t : tets)
    if (t >= s.mesh->tet_count()) throw std::invalid_argument("volume: tet index out of range");
  s.bin(tets);
  std::atomic<int> next{0};
  const int n_tiles = s.tiles_x * s.tiles_y;
  run_parts(s.lanes, [&](int lane) {
    std::size_t count = 0, fast = 0;
    auto scratch = std::make_unique<Impl::Scratch>();
    for (int k; (k = next.fetch_add(1, std::memory_order_relaxed)) < n_tiles;) {
      const int tx = k % s.tiles_x, ty = k / s.tiles_x;
      const Impl::Tile tile{tx * Impl::kTileW, std::min(s.proj.width, (tx + 1) * Impl::kTileW) - 1,
                            ty * Impl::kTileH, std::min(s.proj.height, (ty + 1) * Impl::kTileH) - 1};
      const std::uint32_t end = s.tile_start[std::size_t(k) + 1];
      for (std::uint32_t i = s.tile_start[std::size_t(k)]; i < end; ++i) {
        // The order visits tets far apart in memory: their nodes and values are fetched ahead (the
        // node indices 8 tets ahead, the nodes' coordinates 4 ahead), else draw_tet waits on them.
        if (i + 8 < end) {
          __builtin_prefetch(&s.mesh->tet[4 * std::size_t(s.tile_tets[i + 8])]);
          __builtin_prefetch(&s.corner[4 * std::size_t(s.tile_tets[i + 8])]);
        }
        if (i + 4 < end) {
          const std::uint32_t* node = &s.mesh->tet[4 * std::size_t(s.tile_tets[i + 4])];
          for (int j = 0; j < 4; ++j) __builtin_prefetch(&s.cam_xyz[3 * std::size_t(node[j])]);
        }
        s.draw_tet(s.tile_tets[i], tile, *scratch, count, fast);
      }
    }
    s.lane_samples[std::size_t(lane)] += count;
    s.lane_fast[std::size_t(lane)] += fast;
  });
}

void VolumePainter::resolve(Framebuffer& fb) const {
  const Impl& s = *impl_;
  fb.resize(s.proj.width, s.proj.height, false, s.params.background);
  auto to8 = [](float c) { return std::uint32_t(std::clamp(c, 0.0f, 255.0f) + 0.5f); };
  for (std::size_t p = 0; p < fb.rgba.size(); ++p) {
    fb.rgba[p] = pack_rgba(to8(s.acc[p].c[0]), to8(s.acc[p].c[1]), to8(s.acc[p].c[2]));
    fb.id[p] = s.acc[p].front;
  }
}

std::size_t VolumePainter::pre_integrated() const {
  std::size_t n = 0;
  for (std::size_t c : impl_->lane_fast) n += c;
  return n;
}

std::size_t VolumePainter::samples() const {
  std::size_t n = 0;
  for (std::size_t c : impl_->lane_samples) n += c;
  return n;
}

VolumeReport draw_volume_picture(const Mesh& mesh, const SphereTable& table, const Camera& camera,
                                 Framebuffer& fb, std::span<const std::uint32_t> subset,
                                 std::span<const double> corner, const VolumeParams& params) {
  if (fb.width < 1 || fb.height < 1)
    throw std::invalid_argument("draw_volume_picture: the framebuffer is empty");
  if (table.tet_count() != mesh.tet_count())
    throw std::invalid_argument("draw_volume_picture: the sphere table belongs to another mesh");
  auto ms_since = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
  };
  VolumeReport report;
  auto t0 = std::chrono::steady_clock::now();
  report.delaunay = delaunay_certificate(mesh).delaunay;
  report.certificate_ms = ms_since(t0);
  report.exact_order = report.delaunay;
  t0 = std::chrono::steady_clock::now();
  const std::vector<std::uint32_t> order =
      report.delaunay ? visibility_order(mesh, table, view_of(camera), subset)
                      : mpvo_order(mesh, table, view_of(camera), subset, &report.cycles_broken);
  report.order_ms = ms_since(t0);
  report.tets = order.size();
  t0 = std::chrono::steady_clock::now();
  VolumePainter painter(mesh, camera, fb.width, fb.height, corner, params);
  painter.draw(order);
  painter.resolve(fb);
  report.samples = painter.samples();
  report.draw_ms = ms_since(t0);
  return report;
}

}  // namespace foxi
