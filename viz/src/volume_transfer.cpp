// The volume renderer's transfer function and segment integral (volume.hpp, volume_impl.hpp): the
// extinction of the opacity curve, the stepped integral, the painter's tables and the pre-integrated
// closed form.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "volume_impl.hpp"

namespace foxi {

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

namespace volume_detail {

TableTransfer::TableTransfer(const VolumeParams& params) : p(&params) {
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
  // The pre-integration grid needs its cells' widths and their reciprocals as doubles (a range of
  // -1e308 to 1e308, or of 1e-310, steps instead).
  const double g_span = std::max(sc.hi, hi) - std::min(sc.lo, lo);
  if (!sc.log && std::isfinite(sc.lo) && std::isfinite(sc.hi) && sc.hi > sc.lo &&
      !params.opacity_curve.empty() && std::isfinite(sc.hi - sc.lo) && std::isfinite(1 / (sc.hi - sc.lo)) &&
      std::isfinite(g_span) && std::isfinite(kG / g_span)) {
    pre = true;
    g_lo = std::min(sc.lo, lo);
    g_hi = std::max(sc.hi, hi);
    g_inv = kG / (g_hi - g_lo);
    pos_scale = 1 / (sc.hi - sc.lo);
    // Each cell integrated with 32 midpoint samples (tau is linear and the colour constant between
    // breakpoints, so the error is that of a breakpoint inside a sample: 1/32 of a cell).
    // The cells' sums on the painter's threads, then added up in order; the colour inline (rgb()'s
    // arithmetic: ColorScale::position of a linear scale, the entry of floor(256 t)): 262k samples
    // took some 4.5 ms of every painter's construction, on one thread.
    constexpr int kSub = 32;
    F.assign(4 * std::size_t(kG + 1), 0.0);
    const double dv = (g_hi - g_lo) / kG;
    std::vector<double> sums(4 * std::size_t(kG));
    const int parts = std::clamp(params.threads, 1, 8);
    run_parts(parts, [&](int part) {
      for (int i = kG * part / parts; i < kG * (part + 1) / parts; ++i) {
        double acc[4] = {};
        for (int k = 0; k < kSub; ++k) {
          const double v = g_lo + (i + (k + 0.5) / kSub) * dv;
          const double t = tau(v);
          const double at = (v - sc.lo) / (sc.hi - sc.lo);
          const float* c = std::isnan(at) ? nan_rgb : lut[int(std::clamp(at * 256, 0.0, 255.0))];
          acc[0] += t;
          for (int j = 0; j < 3; ++j) acc[j + 1] += t * c[j];
        }
        std::copy_n(acc, 4, &sums[4 * std::size_t(i)]);
      }
    });
    for (int i = 0; i < kG; ++i)
      for (int j = 0; j < 4; ++j)
        F[4 * std::size_t(i + 1) + std::size_t(j)] =
            F[4 * std::size_t(i) + std::size_t(j)] + sums[4 * std::size_t(i) + std::size_t(j)] * dv / kSub;
    Ff.assign(F.begin(), F.end());
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
namespace {

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

}  // namespace

namespace {

// integrate_fast, else integrate (the near part of an optically deep segment).
void composite_near(const TableTransfer& tf, double v_far, double v_near, double length, float c[3]) {
  if (!integrate_fast(tf, v_far, v_near, length, c)) integrate(tf, v_far, v_near, length, c);
}

}  // namespace

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
    // Optically thick too: the colour is the same along it, and D exact for the table's linear tau.
    if (!(D >= 0) || std::isinf(D)) return false;
    float rgb[3];
    tf.rgb(vm, rgb);
    const double e = D <= 1 ? exp_neg_small(D) : std::exp(-D);
    for (int j = 0; j < 3; ++j) c[j] = float(rgb[j] * (1 - e) + c[j] * e);
    return true;
  }
  double a[4], b[4];
  tf.antiderivative(v_far, a);
  tf.antiderivative(v_near, b);
  if (closed_piece(tf, a, b, dv, length, c)) return true;
  // Optically deeper than kOpaque (a short opacity length): what lies behind the near part of that
  // depth reaches the eye dimmed by e^-kOpaque (under 1e-10 of a level), so only that part is
  // integrated, found by bisection on the table (the depth from the near end grows with the part);
  // stepping the whole took up to 64 x 256 steps a segment (minutes a picture).
  constexpr double kOpaque = 24;
  if (const double depth = length * (b[0] - a[0]) / dv; depth > kOpaque && std::isfinite(depth)) {
    double u_lo = 0, u_hi = 1;  // the near part's fraction: depth under kOpaque at u_lo, not under at u_hi
    for (int it = 0; it < 64 && u_hi - u_lo > 1e-12; ++it) {
      const double u = 0.5 * (u_lo + u_hi);
      double m[4];
      tf.antiderivative(v_near - u * dv, m);
      (length * (b[0] - m[0]) / dv < kOpaque ? u_lo : u_hi) = u;
    }
    const double e = std::exp(-depth);
    for (int j = 0; j < 3; ++j) c[j] = float(c[j] * e);
    if (u_lo > 0) composite_near(tf, v_near - u_lo * dv, v_near, length * u_lo, c);
    return true;
  }
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

void composite(const TableTransfer& tf, double v_far, double v_near, double len, float c[3],
               std::size_t& fast) {
  if (integrate_fast(tf, v_far, v_near, len, c))
    ++fast;
  else
    integrate(tf, v_far, v_near, len, c);
}

}  // namespace volume_detail

void integrate_segment(const VolumeParams& params, double v_far, double v_near, double length, float c[3]) {
  integrate(ExactTransfer{params}, v_far, v_near, length, c);
}

}  // namespace foxi
