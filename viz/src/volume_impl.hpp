// Internal to the volume renderer (volume.hpp): the types its files share. VolumePainter::Impl's
// members are defined, by concern, in volume.cpp (construction, draw, resolve, draw_volume_picture),
// volume_tiles.cpp (the screen tiles and the binning of a batch's tets to them), volume_setup.cpp (a
// tet's set-up, its pixels' spans and their integral on the portable path) and volume_avx512.cpp (the
// vector path: a tet's rows found and integrated sixteen pixels at a time in float); the transfer
// function, the segment integral and its pre-integrated form are in volume_transfer.cpp.
//
// Speed (issue 23): the screen is cut into tiles, a batch's tets binned to the tiles they touch in
// the batch's order, and each thread takes whole tiles (a tile's pixels stay in its core's cache; no
// two threads write one pixel; every pixel still sees its tets in order, so a finished batch is the
// exact picture of the far part); per tet one set-up (its planes, field and rays linear in the
// pixel's x and y). Where the CPU has AVX-512 the tet's pixel rows are the spans of pixel centres in
// its corners' projection, packed sixteen to a lane group and each pixel decided by its ray, in float
// re-centred on the tet (RowSetup); elsewhere the same spans one row at a time and each pixel
// integrated in double (a tet the near plane cuts: the spans of its part beyond the plane, on both
// paths). The two pictures differ by at most a level of 255 on a few pixels (volume_test compares
// them).
#pragma once

#include "foxi/viz/volume.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "raster_impl.hpp"

namespace foxi {
namespace volume_detail {

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
  // F in float for the vector path (a node's 4 values 16 bytes, a cell's two nodes 32): a difference
  // over 2 cells keeps about 1/4000 of the whole range's T, and a segment's optical depth errs by at
  // most about 2.4e-4 of its extinction's largest times its length (a tenth of a level at depth 1).
  std::vector<float> Ff;
  double slope_lo[4] = {}, slope_hi[4] = {};
  float lut_step = 0;  // the largest difference of two neighbouring colour map entries, one channel
  explicit TableTransfer(const VolumeParams& params);  // volume_transfer.cpp
  double tau(double v) const {
    if (std::isnan(v) || tau_at.empty()) return 0;
    double x = (v - lo) * inv_step;  // NaN for an infinite v on a one-point curve (inv_step 0)
    x = x > 0 ? std::min(x, double(kN)) : 0.0;
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

// e^-D for 0 <= D <= 1 as (e^-x)^8, x = D/8 <= 1/8, e^-x by its Taylor series to x^5 (error under
// x^6 / 720 < 5e-9, 4e-8 after the squarings), in a short dependency chain: cheaper than exp.
inline double exp_neg_small(double D) {
  const double x = 0.125 * D, x2 = x * x;
  double e = (1 - x) + x2 * (0.5 - x * (1.0 / 6)) + x2 * x2 * (1.0 / 24 - x * (1.0 / 120));
  e *= e;
  e *= e;
  return e * e;
}

// The segment's integral in closed form (volume_transfer.cpp says when): false where it does not
// apply (the caller steps with integrate()).
bool integrate_fast(const TableTransfer& tf, double v_far, double v_near, double length, float c[3]);
// integrate_fast where it applies, else integrate(); counts the closed-form ones in fast.
void composite(const TableTransfer& tf, double v_far, double v_near, double len, float c[3],
               std::size_t& fast);

// The picture so far, one plane per channel and one of the nearest tet blended: a row of a tet's
// pixels is a contiguous run in each, loaded and stored sixteen at a time by the vector path.
struct VolumeAcc {
  float* c[3];
  std::uint32_t* front;
  int width;
};

// A tet's pixels: the ray o + s d of pixel (x, y) (camera frame; perspective: o = 0 and s the depth)
// has o and d linear in x and y, so each plane's n.d and h - n.o, the field's g.(o - P0) and g.d and
// the direction's x and y are A + x B + y C too: set up once per tet, a few multiply-adds a pixel.
struct TetSetup {
  double ndA[4], ndB[4], ndC[4], numA[4], numB[4], numC[4];
  double vA, vB, vC, gdA, gdB, gdC, dxA, dxB, dyA, dyC, dz2, near;
  // The ray's segment through the tet at pixel (x, y): false where the ray misses it (a pixel centre
  // on the projection's edge, or a segment of no length).
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

// The rows of pixels of the convex hull of n points q (pixel coordinates: a tet's four corners, or
// the corners of its part beyond the near plane, at most 6), as both paths find them: the rows ya..yb
// whose centre line y + 0.5 lies in [least, largest) of the points' y, within y0..y1 (half-open, as
// x: a face seen edge on bounds no ray, so the spans alone decide a pixel centre on its projection,
// and each goes to one of the two tets beside it, the painter's fill rule on the unsnapped corners),
// and the segments between the points from the lower y to the higher (y range, x at its start,
// dx/dy; level ones left out: their ends lie on the others). Every hull edge is one of them and every
// segment lies in the hull, so a row's least and largest x over them is the hull's span. False for
// no row (or a point not a number: the casts need numbers).
struct CornerEdges {
  static constexpr int kMax = 15;  // the pairs of 6 points
  int ya = 0, yb = -1, n = 0;
  double y0[kMax], y1[kMax], x0[kMax], slope[kMax];
};
// Its rows (ya, yb) alone.
inline bool corner_rows(const double (*q)[2], int n_q, int y0, int y1, CornerEdges& e) {
  double y_lo = q[0][1], y_hi = q[0][1];
  for (int k = 1; k < n_q; ++k) {
    y_lo = std::min(y_lo, q[k][1]);
    y_hi = std::max(y_hi, q[k][1]);
  }
  if (!(y_lo <= y_hi)) return false;
  e.ya = int(std::max(double(y0), std::ceil(std::max(y_lo - 0.5, -1.0))));
  e.yb = int(std::min(double(y1), std::ceil(std::min(y_hi - 0.5, 1e9)) - 1));
  return e.ya <= e.yb;
}
inline bool corner_edges(const double (*q)[2], int n_q, int y0, int y1, CornerEdges& e) {
  if (!corner_rows(q, n_q, y0, y1, e)) return false;
  e.n = 0;
  for (int i = 0; i < n_q; ++i)
    for (int j = i + 1; j < n_q; ++j) {
      const double* a = q[i][1] <= q[j][1] ? q[i] : q[j];
      const double* b = q[i][1] <= q[j][1] ? q[j] : q[i];
      if (!(b[1] > a[1])) continue;
      e.y0[e.n] = a[1];
      e.y1[e.n] = b[1];
      e.x0[e.n] = a[0];
      e.slope[e.n++] = (b[0] - a[0]) / (b[1] - a[1]);
    }
  return true;
}

// The values the vector path's float holds with room to spare (volume.cpp, draw_tet).
constexpr double kFloatSafe = 1e30;

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FOXI_VOLUME_AVX512 1
// Whether this CPU runs volume_row_avx512; FOXI_PORTABLE_RASTER=1 says no (the painter's switch),
// so that the tests can compare the two paths on one machine.
bool volume_avx512();
// TetSetup in float for the vector path, re-centred where float keeps the tet's own precision: x and
// y counted from the pixel (xr, yr) of the tet's first row, the ray parameter from the depth s_ref of
// one of its corners (s' = s - s_ref, so an entry and exit a tet apart differ in their leading bits,
// not in the last ones of the eye's distance), the field at s_ref in place of the eye's. Each
// quantity Q is Q0 + (x - xr) Qx + (y - yr) Qy.
struct RowSetup {
  float nd[4], ndx[4], ndy[4], num[4], numx[4], numy[4];
  float v, vx, vy, gd, gdx, gdy, dx, dxx, dy, dyy, dz2, near;
  int xr, yr;
  RowSetup() = default;
  RowSetup(const TetSetup& r, double s_ref, int xr, int yr);  // volume_avx512.cpp
};
// Eight tets' set-ups at once (tet_batch_avx512), each lane what draw_tet's TetSetup and RowSetup
// give for a tet whose four corners lie beyond its clipping plane and have pixels (ok; the others,
// and flat ones, go through draw_tet). In: the corners in the camera frame, the field's values,
// the first corner's pixel (lane-wise), the frame's rays (VolumePainter::Impl::Rays) and the tile.
struct TetBatch {
  static constexpr int kLanes = 8;
  alignas(64) double P[4][3][kLanes], cv[4][kLanes], q0[2][kLanes];
  double o0[3], d0[3], ox, oy, dx, dy, near, focal;  // near: the painter's, at least 0
  bool perspective;
  int x0, x1, y0, y1;
  // Out: per lane its RowSetup (s_ref its first corner's depth) and whether it applies.
  RowSetup rs[kLanes];
  bool ok[kLanes];
};
void tet_batch_avx512(TetBatch& b);
// A run of a tet's pixels: lo..hi of row y; a thread's list holds kMaxRuns.
struct PixelRun {
  int y, lo, hi;
};
constexpr int kMaxRuns = 256;
// Tet t's pixels inside the convex hull of the n_q points q (pixel coordinates: corner_edges) within
// the tile x0..x1, y0..y1, blended into acc sixteen float lanes at a time (volume_avx512.cpp): per
// row the span of pixel centres inside the hull (eight rows at a time), the spans packed into the
// lanes one after another; per lane the four planes' ray parameters at its pixel, entry the largest
// of the front faces', exit the least of the back faces', and the pre-integrated closed form in
// float; a segment outside its conditions goes through composite() (double) one pixel at a time.
// Not bit for bit the portable path: float, and its own thin-segment rule (the grid cell's mean
// extinction and colour); the tests bound the difference. runs: room for kMaxRuns. count: the
// segments integrated, fast: of those, in closed form.
void volume_tet_avx512(const RowSetup& r, const TableTransfer& tf, const VolumeAcc& acc, const double (*q)[2],
                       int n_q, int x0, int x1, int y0, int y1, std::uint32_t t, PixelRun* runs,
                       std::size_t& count, std::size_t& fast);
#endif

}  // namespace volume_detail

using namespace volume_detail;

struct VolumePainter::Impl {
  const Mesh* mesh = nullptr;
  Projector proj;
  std::span<const double> corner;
  VolumeParams params;
  int lanes = 1;
  // The colour so far, one plane per channel (VolumeAcc), and the nearest tet blended, per pixel;
  // a tile's pixels hold these only once it is cleared (tile_ready, clear_tile).
  std::unique_ptr<float[]> chan[3];
  std::unique_ptr<std::uint32_t[]> front;
  std::vector<std::uint8_t> tile_ready;
  std::vector<std::uint8_t> tile_drawn;  // drawn since the last resolve_drawn (all, at first)
  bool vector_rows = false;              // volume_row_avx512 for the pixel rows
  std::vector<double> cam_xyz;           // the nodes in the camera frame, once (not per tet and lane)
  std::vector<std::size_t> lane_samples, lane_fast;
  std::unique_ptr<TableTransfer> transfer;
  // The pixel's ray o + s d in the camera frame: o = o0 + x ox + y oy, d = d0 + x dx + y dy (see
  // TetSetup), once per painter.
  struct Rays {
    double o0[3] = {0, 0, 0}, d0[3] = {0, 0, 1}, ox = 0, oy = 0, dx = 0, dy = 0;
  } rays;

  Impl(const Mesh& m, const Camera& camera, int w, int h) : mesh(&m), proj(camera, w, h) {}

  // Screen tiles of kTileW x kTileH pixels (their four planes 512 KiB, which stay in the core's L2
  // while the tile's tets are drawn): draw() bins a batch's tets by their screen bounds, in order,
  // and each thread takes whole tiles, so every pixel still sees its tets in the given order and no
  // two threads write one pixel. 256 x 128 against 128 x 64 (measured alternately in one process,
  // 2026-11-28, the 0.97M box at 1920x1080): about 10% less wall a frame (fewer tets drawn in two
  // tiles, each set up twice); 256 x 256 no better.
  static constexpr int kTileW = 256, kTileH = 128;
  struct Tile {
    int x0, x1, y0, y1;
  };
  Tile tile_at(int k) const;          // tile k, row by row (volume.cpp)
  void clear_tile(const Tile& tile);  // its pixels the background, no tet
  // The tiles `tiles` (indices) of the picture into fb, which has the painter's size (fits).
  void resolve_tiles(Framebuffer& fb, std::span<const int> tiles) const;
  bool fits(const Framebuffer& fb) const;  // the painter's size and planes
  int tiles_x = 0, tiles_y = 0;
  std::vector<double> node_px;  // per node its pixel (x, y); NaN where it is not in front of the eye
  std::vector<std::uint32_t> tile_start, tile_tets, cursor;
  std::vector<std::array<std::uint16_t, 4>> tet_tiles;  // per tet of the batch: tiles x0, x1, y0, y1

  // The tiles tet t's projection can touch (volume_tiles.cpp): x0, x1, y0, y1; x0 > x1 for none.
  std::array<std::uint16_t, 4> tiles_of(std::uint32_t t) const;
  // The batch's tets into the tiles' lists (tile_start, tile_tets), each list in the batch's order.
  void bin(std::span<const std::uint32_t> tets);

  // A thread's runs of the tet it draws (the vector path).
  struct Scratch {
    PixelRun runs[kMaxRuns];
#ifdef FOXI_VOLUME_AVX512
    TetBatch batch;
#endif
  };

  // Tet t's segments at its pixels inside `tile` blended into acc (volume_setup.cpp).
  void draw_tet(std::uint32_t t, const Tile& tile, Scratch& scratch, std::size_t& count, std::size_t& fast);
  // draw_tet for up to TetBatch::kLanes tets (the vector path): their set-ups eight at a time
  // (volume_setup.cpp).
  void draw_tets(const std::uint32_t* tets, int n, const Tile& tile, Scratch& scratch, std::size_t& count,
                 std::size_t& fast);
};

}  // namespace foxi
