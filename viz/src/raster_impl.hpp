// Internal to the painter's rasterizer: the state of TetRasterizer::Impl and the fixed-point and
// face types its files share. Its members are defined, by concern, in rasterizer.cpp (construction,
// draw, batches and the written-mask), raster_face.cpp (face shading, edge lines, near-plane
// clipping), raster_spans.cpp (rows, spans and edge pixels), raster_avx512.cpp (undraw's vector
// repaint) and undraw.cpp (the undo saves and undraw); the small ones several of them use stay here.
// Members declared inline are defined in the one file that calls them: they were inline (defined in
// the class) before the split, and GCC's inliner treats an inline function more generously (shade_row
// into raster_polygon, answer_requests into draw_batch: without it the painter ran ~6% more instructions).
//
// The painter's rasterizer (see rasterizer.hpp). Face setup works in camera coordinates (x right,
// y up, z depth; a left-handed frame, so cross products there are the mirror of world ones), pixels
// in fixed point with 8 subpixel bits and 64-bit edge functions.
#pragma once

#include "foxi/viz/rasterizer.hpp"

#include "foxi/model/adjacency.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/model/parallel.hpp"
#include "huge_page_allocator.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <exception>
#include <functional>
#include <future>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FOXI_AVX512_REPAINT 1  // see TetRasterizer::Impl::repaint_triangle_avx512
#endif
#include <cstdlib>

namespace foxi {
namespace raster_detail {

constexpr std::int64_t kOne = 256;       // 8 subpixel bits
constexpr std::int64_t kHalf = 128;      // pixel centre offset
constexpr int kBandShift = 4;            // bands of 16 rows, interleaved between threads
constexpr double kMaxPixel = 1048576.0;  // |pixel coordinate - centre| bound (2^20): 64-bit safe

// Local vertex triples of the 4 faces of a positively oriented tet, ordered so that (b - a) x (c - a)
// points out of the tet (world frame); face f is opposite vertex f.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// The painter's parts run on the one pool (foxi/model/parallel.hpp): a frame starts no thread.
using detail::run_parts;

inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {  // b > 0
  std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

inline std::int64_t to_fixed(double p) {
  return static_cast<std::int64_t>(
      std::llround(std::clamp(p, -4.0 * kMaxPixel, 4.0 * kMaxPixel) * double(kOne)));
}

// Which rows a thread owns: bands of 16 rows, band b belongs to thread b % count, and of those only
// the rows in [lo, hi] (undraw gives each thread one such range, see split_rows).
struct Rows {
  int thread = 0, count = 1;
  int lo = 0, hi = std::numeric_limits<int>::max();
  bool owns(int y) const {
    return y >= lo && y <= hi && (count == 1 || ((y >> kBandShift) % count) == thread);
  }
  // The first owned row >= y, and the owned row after the owned row y (one division per band).
  int first(int y) const {
    if (count == 1) return y;
    const int b = y >> kBandShift, r = b % count;
    return r == thread ? y : (b + (thread - r + count) % count) << kBandShift;
  }
  int next(int y) const {
    ++y;
    return (count == 1 || (y & ((1 << kBandShift) - 1)) != 0) ? y : first(y);
  }
  // True if some row in [y0, y1] is owned.
  bool any(int y0, int y1) const {
    y0 = std::max(y0, lo);
    y1 = std::min(y1, hi);
    if (count == 1) return y0 <= y1;
    if (y0 > y1) return false;
    int b0 = y0 >> kBandShift, b1 = y1 >> kBandShift;
    if (b1 - b0 + 1 >= count) return true;
    for (int b = b0; b <= b1; ++b)
      if (b % count == thread) return true;
    return false;
  }
};

// Calls fn(y, x_first, x_last) for every row run of pixels whose centres the triangle covers under the
// top-left rule; the triangle must have positive area: (x1 - x0)(y2 - y0) - (y1 - y0)(x2 - x0) > 0 (clockwise
// on the screen, y down). Only rows owned by `rows` are visited.
// The top-left rule: an edge from (x, y) to (x + dx, y + dy) of a triangle clockwise on the screen
// owns the pixels on it if it is a top or left edge.
inline bool owns_boundary(std::int64_t dx, std::int64_t dy) { return dy < 0 || (dy == 0 && dx > 0); }

// Undraw repaints a back face of a tet as the front face of the tet across it, drawn earlier: what
// the picture held there just before the tet was drawn, unless a tet drawn in between covers some
// of the face's pixels. In a visibility order that tet's exact projection can only touch the face's,
// so after snapping (each corner moved at most 0.71 units) it covers only pixel centres within 1.42
// units of the face's snapped edges, and only where two edges lie on one line of the screen, the
// projection of a plane through the eye (or along the view) holding mesh faces (a lattice seen from
// one of its planes): such a face is seen exactly edge on. Pixel centres that near (|E| <= kNearEdge
// (|dx| + |dy|) for the edge function E of an edge (dx, dy): at least kNearEdge units) to an edge-on
// face are risky, and saved rather than repainted (tests/data/bad/fuzz/mesh_pipeline/
// undraw_eye_in_inner_face_planes).
constexpr std::int64_t kNearEdge = 2;

// Whether the edge function of the edge from (xa, ya) to (xb, yb) is near zero (see kNearEdge) at
// (px, py) (fixed point).
inline bool near_edge(std::int64_t xa, std::int64_t ya, std::int64_t xb, std::int64_t yb, std::int64_t px,
                      std::int64_t py) {
  const std::int64_t dx = xb - xa, dy = yb - ya;
  return std::abs(dx * (py - ya) - dy * (px - xa)) <= kNearEdge * (std::abs(dx) + std::abs(dy));
}

template <class Fn>
void raster_triangle(const std::int64_t* X, const std::int64_t* Y, int width, int height, const Rows& rows,
                     Fn&& fn) {
  std::int64_t minx = std::min({X[0], X[1], X[2]}), maxx = std::max({X[0], X[1], X[2]});
  std::int64_t miny = std::min({Y[0], Y[1], Y[2]}), maxy = std::max({Y[0], Y[1], Y[2]});
  std::int64_t x0 = std::max<std::int64_t>(0, -floor_div(-(minx - kHalf), kOne));
  std::int64_t x1 = std::min<std::int64_t>(width - 1, floor_div(maxx - kHalf, kOne));
  std::int64_t y0 = std::max<std::int64_t>(0, -floor_div(-(miny - kHalf), kOne));
  std::int64_t y1 = std::min<std::int64_t>(height - 1, floor_div(maxy - kHalf, kOne));
  y0 = std::max<std::int64_t>(y0, rows.lo);
  y1 = std::min<std::int64_t>(y1, rows.hi);
  if (x0 > x1 || y0 > y1) return;
  if (!rows.any(int(y0), int(y1))) return;
  // Edge i goes from vertex i to vertex i+1; E_i(p) = (bx - ax)(py - ay) - (by - ay)(px - ax) >= 0
  // inside. Top-left edges (dy < 0, or dy == 0 and dx > 0) own their boundary pixels (E == 0);
  // the others do not (bias -1). A shared edge runs the other way in the neighbour, so exactly one
  // of the two owns it.
  std::int64_t dx[3], dy[3], bias[3];
  for (int i = 0; i < 3; ++i) {
    int j = i == 2 ? 0 : i + 1;
    dx[i] = X[j] - X[i];
    dy[i] = Y[j] - Y[i];
    bias[i] = owns_boundary(dx[i], dy[i]) ? 0 : -1;
  }
  const std::int64_t px0 = x0 * kOne + kHalf;
  // The covered run of a row, exactly: E_i(x) = e_i + s_i (x - x0) >= 0 for all i, with
  // s_i = -dy_i kOne. For s_i > 0 the run starts at x0 - floor(e_i / s_i) (the smallest k with
  // e_i + s_i k >= 0 is ceil(-e_i / s_i)), for s_i < 0 it ends at x0 + floor(e_i / |s_i|), for s_i = 0
  // it is empty if e_i < 0. From row to row e_i grows by dx_i kOne, so the quotient q_i and
  // remainder r_i of e_i = q_i |s_i| + r_i (0 <= r_i < |s_i|) are carried on exactly without dividing
  // (recomputed after a skipped band).
  std::int64_t q[3] = {}, r[3] = {}, e[3] = {}, s[3] = {}, dq[3] = {}, dr[3] = {};
  for (int i = 0; i < 3; ++i) {
    s[i] = std::abs(dy[i]) * kOne;
    if (s[i] != 0) {
      dq[i] = floor_div(dx[i] * kOne, s[i]);
      dr[i] = dx[i] * kOne - dq[i] * s[i];
    }
  }
  auto start_row = [&](std::int64_t y) {
    const std::int64_t py = y * kOne + kHalf;
    for (int i = 0; i < 3; ++i) {
      e[i] = dx[i] * (py - Y[i]) - dy[i] * (px0 - X[i]) + bias[i];
      if (s[i] != 0) {
        q[i] = floor_div(e[i], s[i]);
        r[i] = e[i] - q[i] * s[i];
      }
    }
  };
  std::int64_t prev = -2;
  for (std::int64_t y = rows.first(int(y0)); y <= y1; y = rows.next(int(y))) {
    if (y != prev + 1) {
      start_row(y);
    } else {
      for (int i = 0; i < 3; ++i) {
        if (s[i] != 0) {
          q[i] += dq[i];
          r[i] += dr[i];
          const std::int64_t carry = -std::int64_t(r[i] >= s[i]);  // branch-free: 0 or -1
          r[i] -= s[i] & carry;
          q[i] -= carry;
        } else {
          e[i] += dx[i] * kOne;
        }
      }
    }
    prev = y;
    std::int64_t lo = x0, hi = x1;
    for (int i = 0; i < 3; ++i) {
      if (dy[i] < 0) {
        lo = std::max(lo, x0 - q[i]);
      } else if (dy[i] > 0) {
        hi = std::min(hi, x0 + q[i]);
      } else if (e[i] < 0) {
        hi = lo - 1;
      }
    }
    if (lo <= hi) fn(int(y), int(lo), int(hi));
  }
}

// The near-plane clip of a convex polygon of n <= 8 points in camera coordinates (perspective): out
// gets the part at depth >= near, near being near_given or, larger, the tet painter's rule (a point no
// farther than dmax from the eye then projects within kMaxPixel of the centre). Returns its count,
// 0 when fewer than 3 remain. Orthographic: a copy.
inline int clip_near(const Projector& proj, double near_given, const double (*in)[3], int n,
                     double (*out)[3]) {
  if (!proj.perspective) {
    for (int i = 0; i < n; ++i) std::copy(in[i], in[i] + 3, out[i]);
    return n;
  }
  double dmax = 0;
  for (int i = 0; i < n; ++i)
    dmax = std::max(dmax, std::sqrt(in[i][0] * in[i][0] + in[i][1] * in[i][1] + in[i][2] * in[i][2]));
  double near = std::max(near_given, dmax * proj.focal / kMaxPixel);
  if (!(near > 0)) near = 1e-300;
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const double* a = in[i];
    const double* b = in[(i + 1) % n];
    const bool ina = a[2] >= near, inb = b[2] >= near;
    if (ina) std::copy(a, a + 3, out[m++]);
    if (ina != inb) {
      const double t = (near - a[2]) / (b[2] - a[2]);
      double* o = out[m++];
      for (int k = 0; k < 3; ++k) o[k] = a[k] + t * (b[k] - a[k]);
      o[2] = near;
    }
  }
  return m >= 3 ? m : 0;
}

// Projects the n camera-frame points cam(i) (in front of the eye) of a polygon: their corners in
// fixed point (X, Y), the snapped positions in pixels px (what the painters interpolate from) and
// their nearness w (1 / depth perspective, -depth orthographic).
template <class Cam>
void snap_polygon(const Projector& proj, int n, Cam&& cam, std::int64_t* X, std::int64_t* Y, double (*px)[2],
                  double* w) {
  for (int i = 0; i < n; ++i) {
    const double* c = cam(i);
    proj.camera_to_pixel(c, px[i]);
    X[i] = to_fixed(px[i][0]);
    Y[i] = to_fixed(px[i][1]);
    px[i][0] = double(X[i]) / double(kOne);  // interpolate from the snapped vertices
    px[i][1] = double(Y[i]) / double(kOne);
    w[i] = proj.perspective ? 1 / c[2] : -c[2];
  }
}

// Calls fn(TX, TY, idx) for each triangle (0, i, i + 1) of the fan of a convex polygon of n vertices in
// fixed point that has positive area on the screen, its corners reordered clockwise as raster_triangle
// wants (idx: the polygon vertices they are). The iso and translucent painters draw polygons so.
template <class Fn>
void for_each_fan_triangle(const std::int64_t* X, const std::int64_t* Y, int n, Fn&& fn) {
  for (int i = 1; i + 1 < n; ++i) {
    int idx[3] = {0, i, i + 1};
    std::int64_t TX[3] = {X[0], X[i], X[i + 1]}, TY[3] = {Y[0], Y[i], Y[i + 1]};
    const std::int64_t area = (TX[1] - TX[0]) * (TY[2] - TY[0]) - (TY[1] - TY[0]) * (TX[2] - TX[0]);
    if (area == 0) continue;
    if (area < 0) {
      std::swap(TX[1], TX[2]);
      std::swap(TY[1], TY[2]);
      std::swap(idx[1], idx[2]);
    }
    fn(TX, TY, idx);
  }
}

struct PolyVertex {
  double c[3] = {0, 0, 0};  // camera coordinates (near-plane cuts only)
  std::int64_t X = 0, Y = 0;
  double w = 0;           // nearness (1 / depth perspective, -depth orthographic), depth mode
  bool mesh_edge = true;  // the edge from this vertex to the next is (part of) a mesh edge
  float pos = 0;          // graded field paint: the position on the colour scale (FieldPaint)
};

// Shading: a pixel's colour is its base colour (region or field colour, opaque) scaled by its shade
// byte s / 255, each channel rounded (shade_color). The shade is the face's Lambert intensity times the
// edge darkening at the pixel (1 away from edges), as level = intensity x 255 times that factor,
// rounded and clamped (shade_of). Every path that colours a pixel (painter, depth buffer, undraw's
// repaints, scalar or vector) goes through these two, and keeps s in Framebuffer::shade, so that
// recolouring a flat picture is a table lookup per pixel (recolor.cpp).
inline std::uint8_t shade_of(double level, double factor) {
  return std::uint8_t(std::min(std::max(level * factor + 0.5, 0.0), 255.0));
}
// round(c s / 255) per channel, exactly (t + t / 256 with t = c s + 128, over 256, for c s <= 255^2).
inline std::uint32_t shade_color(std::uint32_t base, std::uint32_t s) {
  std::uint32_t out = 0xff000000u;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t t = ((base >> (8 * k)) & 255u) * s + 128;
    out |= ((t + (t >> 8)) >> 8) << (8 * k);
  }
  return out;
}

// A face's flat colour (before edge darkening): packed, its base colour and its shade.
struct FaceShade {
  std::uint32_t color = 0;  // shade_color(base, shade)
  std::uint32_t base = 0;   // the region's or the field's colour (graded: unused)
  double level = 0;         // the Lambert intensity x 255 (see shade_of)
  std::uint8_t shade = 0;   // shade_of(level, 1): the face away from its edges
};

// Everything a face's pixels need.
struct FaceSetup {
  std::uint32_t tet = 0;
  std::uint32_t color = 0;  // FaceShade's
  std::uint32_t base = 0;
  double level = 0;
  std::uint8_t shade = 0;
  // Mesh edges (up to 4; unused ones never darken): the edge function of edge k at the centre of
  // pixel (x, y), ea x + eb y + ec, exact in 64 bits (fixed point squared, inside >= 0); times
  // inv_len it is the distance in pixels. Exact integers make the distance the same bits whether a
  // span steps along a row or a single pixel evaluates it.
  int lines = 0;
  std::int64_t ea[4], eb[4], ec[4];
  double inv_len[4];
  double flat_e[4];  // edge_width / inv_len: a pixel with edge function >= this is not darkened by k
  // Every edge line's function is below 2^52 in magnitude on the whole image, so a row may step it in
  // double exactly (each value an integer that a double holds): the same bits as converting the
  // 64-bit one at each pixel.
  bool exact_double = false;
  double step[4];  // ea as doubles (exact_double)
  // eb and ec as doubles (exact_double): a short run's edge functions at its first pixel evaluated in
  // double, step x + step_y y + at0, exactly (every partial sum an integer below 2^52).
  double step_y[4], at0[4];
  // Depth mode, per fan triangle: nearness = w0 + da (x - x0) + db (y - y0), interpolated from the
  // snapped vertices so that faces sharing an edge agree on it exactly (up to rounding).
  double x0 = 0, y0 = 0, w0 = 0, da = 0, db = 0;
  // Graded field paint, per fan triangle: the scale position at pixel centre (x, y) is
  // (g0 + ga dx + gb dy) / (h0 + ha dx + hb dy), dx = x + 0.5 - gx0, dy = y + 0.5 - gy0: position x
  // nearness and nearness are affine on the screen under perspective (h = 1 orthographic), so the
  // position is interpolated linearly across the face in the world.
  bool graded = false;
  double gx0 = 0, gy0 = 0, g0 = 0, ga = 0, gb = 0, h0 = 1, ha = 0, hb = 0;
};

}  // namespace raster_detail

using namespace raster_detail;

struct TetRasterizer::Impl {
  // The lent view, kept here (a caller's MeshView may be a temporary); `mesh` points at it.
  MeshView mesh_view;
  const MeshView* mesh = nullptr;
  Projector proj;
  RenderParams params;
  double near = 0;
  double light[3] = {0, 0, -1};       // toward the light, camera frame
  const FieldPaint* field = nullptr;  // params.field, if any
  std::uint32_t field_lut[256] = {};  // graded: the colour map's entries
  // Edge darkening: a pixel at distance d < edge_width from an edge is scaled by edge_base +
  // edge_slope d (1 - edge_darkness at the edge, 1 at edge_width).
  double edge_base = 1, edge_slope = 0;
  // Whether undraw repaints triangles with repaint_triangle_avx512: the CPU has it, edges are drawn
  // and a darkened channel stays in [0, 255] unclamped (edge_darkness in [0, 1]).
  bool fast_repaint = false;
  // Per node, in one 32-byte record (two to a cache line: the tets a view reads at random, the undraw
  // walk's above all, cost a line per corner): camera coordinates, fixed-point pixel coordinates
  // (they fit 32 bits: |p| <= 4 kMaxPixel kOne = 2^30) and the state (0 in front, 1 behind the near
  // plane, 2 not finite), the last as X = kNoPixel, Y = state where it is not 0.
  struct alignas(32) NodeView {
    double c[3];
    std::int32_t X, Y;
  };
  static constexpr std::int32_t kNoPixel = std::numeric_limits<std::int32_t>::min();
  std::vector<NodeView, HugePageAllocator<NodeView>> node_view;
  const double* cam(std::uint32_t n) const { return node_view[n].c; }
  // Per draw() call, per tet of the batch (in batch order): its pixel box, filled by both threads
  // from halves of the batch so that hidden or off-band tets cost each thread a sequential read.
  struct Box {
    std::int32_t x0 = 0, x1 = -1, y0 = 0, y1 = -1;  // x0 > x1: draws nothing; y0 < 0: not known
  };
  std::vector<Box> boxes;
  RasterStats stats;
  // Where draw() writes the colours: fb.rgba (rows fb.width apart), or a host's image drawn in place
  // (rows color_stride pixels apart; draw_into). Set by check_framebuffer at every entry.
  std::uint32_t* colors = nullptr;
  std::size_t color_stride = 0;
  std::uint32_t* color_row(int y) const { return colors + std::size_t(y) * color_stride; }
  // Painter mode draws each batch front to back (tets, faces and fan triangles in reverse order)
  // and writes only pixels not yet written in this batch: "first write wins" in reverse order is
  // "last write wins" in the given order, pixel for pixel, and hidden tets cost only a mask test.
  // One bit per pixel, rows of `mask_words` 64-bit words; a row is touched only by its thread.
  bool reverse = false;
  int mask_words = 0;
  std::vector<std::uint64_t> written;
  // Per band of 16 rows and mask word: 1 once all 16 x 64 pixels (those in the image) are known to
  // be written, so that a hidden tet costs a few byte tests (set lazily by box_written).
  std::vector<std::uint8_t> tile_full;
  // Whether painter drawing tests and sets the mask (off while undraw repaints neighbours' faces).
  bool use_mask = false;
  // Undoable mode (params.undoable): the tets drawn so far in order, which tets are drawn (`kept`,
  // bit t of word t / 64; during undraw, less the tets being undrawn), each drawn tet's position in
  // the order (drawn_at, stale where the bit is clear: undraw leaves it), and the undraw stack of
  // saved pixels: per tet with an unshared back face, where its pixels start in saved_rgba / saved_id
  // (the runs of those faces, in raster order). The bits fit the cache where drawn_at does not.
  const FaceAdjacency* adjacency = nullptr;
  std::vector<std::uint32_t> history;
  std::vector<std::uint32_t> drawn_at;
  std::vector<std::uint64_t> kept;
  bool is_kept(std::uint32_t t) const { return kept[t >> 6] >> (t & 63) & 1; }
  // Undoable: the tets of inverted pairs. A pair is inverted when a tet has a front face (on the
  // snapped pixels) shared with a tet drawn before it: in the picture it lies behind that tet across
  // the face yet was drawn after it. A face seen edge-on makes it so after snapping (the order, from
  // the exact geometry, may put either side first), as does an order that is not a visibility order.
  // Where that face covers pixels (`risky`, one bit per pixel like `shown`), the later tet covers
  // pixels of the earlier one's front faces, so that the picture before a tet need not show the
  // neighbour across its back face there (what earlier_neighbour assumes): a back face shared with a
  // tainted tet, and every back face of one, also saves its risky pixels. Found by fuzzing
  // (tests/data/bad/fuzz/mesh_pipeline/undraw_edge_on_face). `any_tainted` spares the common case
  // the bit reads.
  std::vector<std::uint64_t> tainted, risky;
  bool any_tainted = false;
  bool is_risky(int x, int y) const {
    return risky[std::size_t(y) * std::size_t(mask_words) + std::size_t(x >> 6)] >> (x & 63) & 1;
  }
  // Whether back face f of t, shared with earlier tet nb, saves its risky pixels.
  bool saves_risky(std::uint32_t t, std::uint32_t nb) const {
    return any_tainted && (is_tainted(t) || is_tainted(nb >> 2));
  }
  bool is_tainted(std::uint32_t t) const { return tainted[t >> 6] >> (t & 63) & 1; }
  // Risky pixels near faces seen edge on (see kNearEdge) are marked in `risky` too, and here one bit
  // per band of 16 rows and 64 columns that holds one (empty while none is). A tet whose pixel box
  // holds a risky pixel saves the risky pixels of its shared back faces.
  std::vector<std::uint64_t> risky_tile;
  bool box_meets_risky(const Box& b) const {
    if (risky_tile.empty() || b.x0 > b.x1 || b.y0 < 0) return false;
    bool tile = false;
    for (int band = b.y0 >> kBandShift; band <= b.y1 >> kBandShift && !tile; ++band)
      for (int w = b.x0 >> 6; w <= b.x1 >> 6 && !tile; ++w)
        tile = risky_tile[std::size_t(band) * std::size_t(mask_words) + std::size_t(w)] != 0;
    if (!tile) return false;
    for (int y = b.y0; y <= b.y1; ++y)
      for (int w = b.x0 >> 6; w <= b.x1 >> 6; ++w) {
        std::uint64_t bits = risky[std::size_t(y) * std::size_t(mask_words) + std::size_t(w)];
        if (w == b.x0 >> 6) bits &= ~std::uint64_t(0) << (b.x0 & 63);
        if (w == b.x1 >> 6 && (b.x1 & 63) != 63) bits &= (std::uint64_t(1) << ((b.x1 & 63) + 1)) - 1;
        if (bits) return true;
      }
    return false;
  }
  void mark_risky(int x, int y) {
    if (risky.empty()) risky.assign(shown.size(), 0);
    if (risky_tile.empty())
      risky_tile.assign(std::size_t(mask_words) * std::size_t((proj.height >> kBandShift) + 1), 0);
    risky[std::size_t(y) * std::size_t(mask_words) + std::size_t(x >> 6)] |= std::uint64_t(1) << (x & 63);
    risky_tile[std::size_t(y >> kBandShift) * std::size_t(mask_words) + std::size_t(x >> 6)] = 1;
  }
  // Marks the risky pixels near the edge from (xa, ya) to (xb, yb) (snapped; see kNearEdge) over its
  // extent.
  void mark_near_edge(std::int64_t xa, std::int64_t ya, std::int64_t xb, std::int64_t yb);
  void taint(std::uint32_t t) {
    tainted[t >> 6] |= std::uint64_t(1) << (t & 63);
    any_tainted = true;
  }
  struct Save {
    std::uint32_t at = 0;    // position in history
    std::size_t offset = 0;  // first saved pixel (in its lane)
  };
  // Per draw() call: where its saves and saved pixels begin (a call's saves are freed together).
  struct SaveRegion {
    std::size_t first_save = 0, first_pixel = 0;
  };
  // The saved pixels live in lanes, one per thread of the band partition (lane k holds the pixels of
  // the rows Rows{k, lane_count} owns, see lane_of), so that threads record and restore them
  // independently. A tet's save is filed in each lane whose rows it touches.
  struct Lane {
    std::vector<Save> saves;                                       // in drawing order
    std::vector<std::uint32_t> saved_pixel, saved_rgba, saved_id;  // y * width + x, colour, id
    std::vector<std::uint8_t> saved_shade;                         // and shade
    std::vector<SaveRegion> regions;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> aliases;  // (request, later request it equals)
    // A request at a pixel its tet's front faces did not show (the tet holds the eye, so it has no
    // front face; or snapping left the pixel to a back face alone) is answered by the next tet that
    // shows the pixel, in record_span's unshown branch, which looks for requests only when this is
    // set (for this batch).
    bool unshown_requests = false;
  };
  std::vector<Lane> lanes;
  int lane_count = 1;
  int lane_of(int y) const { return (y >> kBandShift) % lane_count; }
  // Undoable drawing walks a batch front to back like the painter (see `written`, here "done"), so
  // the value a tet's save needs, what was drawn before it, comes later in the walk: each saved
  // pixel is a request (slot: its index in its lane, per pixel, kNone if none), answered by the next
  // tet that covers the pixel, or at the end of the batch by what was there before the batch (fb, or
  // `before` where the batch overwrote it). `shown`: pixels the batch has given their final value.
  bool recording = false;
  std::vector<std::uint64_t> shown;
  std::vector<std::uint32_t> slot, before_rgba, before_id;
  std::vector<std::uint8_t> before_shade;
  std::vector<std::uint8_t> need_save;     // per batch tet
  std::vector<std::uint16_t> batch_reach;  // per batch tet: its repaint reach (see drawn_reach)
  // Undoable: each drawn tet's pixel box (tet_box, in drawing order, 8 bytes), so that undraw finds
  // the undrawn tets hidden behind farther undrawn ones (most of them) without reading the mesh.
  struct SmallBox {
    std::int16_t x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  };
  std::vector<SmallBox> drawn_box;
  // Undoable: per drawn tet (in drawing order), how far back in the drawing its back faces' earlier
  // neighbours reach: its position less the least of theirs, at most 65535 (0: none). Undrawing the
  // tets from position `first` on, tet i of them (position first + i) repaints a face only if one
  // of those neighbours is kept (drawn before first): reach > i (or reach 65535; parts are at most
  // 2^16 tets). A third of the undrawn tets that show repaint nothing (their neighbours behind are
  // undrawn too): this spares the walk their mesh rows, nodes and neighbours.
  std::vector<std::uint16_t> drawn_reach;
  // What undraw's walk needs of an undrawn tet that shows, its box not cut by the near plane
  // (gather_undrawn, shade_repainted): the walk fetches it a few tets ahead (see undraw_part), so the
  // mesh's scattered arrays are read only for the tets that show, their lookups overlapping.
  struct UndrawTet {
    std::int32_t X[4], Y[4];     // fixed-point corners
    std::uint32_t node[4];       // the tet's nodes
    std::uint8_t repaint = 0;    // bit f: back face f is shared with a kept tet
    std::uint32_t neighbour[4];  // repaint face f: that tet's face (4 tet + face)
    FaceShade shade[4];          // repaint face f: that tet's front face's flat colour
  };
  PixelRect changed;  // see changed_rect
  // See changed_rects; during an undraw, per band of 16 rows the x-extent of the undrawn tets' boxes.
  std::vector<PixelRect> changed_list;
  std::vector<int> band_x0, band_x1;
  void changed_is_one_rect() {
    changed_list.clear();
    if (changed.x0 <= changed.x1) changed_list.push_back(changed);
  }

  Impl(const MeshView& m, const Camera& c, int w, int h, const RenderParams& p);

  void project_camera(const double* c, std::int64_t& X, std::int64_t& Y, std::uint8_t& st) const {
    if (!(std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]))) {
      st = 2;
      return;
    }
    if (proj.perspective && !(c[2] >= near)) {
      st = 1;
      return;
    }
    double px[2];
    proj.camera_to_pixel(c, px);
    X = to_fixed(px[0]);
    Y = to_fixed(px[1]);
    st = 0;
  }

  double nearness(const double* c) const { return proj.perspective ? 1 / c[2] : -c[2]; }

  void project_node(const double* p, double* c, std::int64_t& X, std::int64_t& Y, std::uint8_t& st) const {
    proj.to_camera(p, c);
    project_camera(c, X, Y, st);
  }

  FaceShade face_shade(std::uint32_t tet, const double* const v[3], const std::uint32_t node[3]) const;

  // The edge line from a to b: E(p) = ex (py - ay) - ey (px - ax) at the pixel centre
  // p = (x, y) kOne + kHalf, as ea x + eb y + ec (|coordinates| <= 2^30 keep every term below 2^62);
  // length: the edge's, in fixed-point units.
  struct EdgeLine {
    std::int64_t ea, eb, ec;
    double length;
  };
  static inline EdgeLine edge_line(const PolyVertex& a, const PolyVertex& b);

  inline bool exact_in_double(std::int64_t ea, std::int64_t eb, std::int64_t ec) const;

  static inline void set_shade(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh);

#ifdef FOXI_AVX512_REPAINT
  bool setup_repaint(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh, const PolyVertex* poly) const;
#endif

  void setup_face(FaceSetup& fs, std::uint32_t tet, const double* const v[3], const std::uint32_t node[3],
                  const PolyVertex* poly, int n) const;

  void setup_face(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh, const PolyVertex* poly, int n) const;

  inline void shade_pixel(Framebuffer& fb, const FaceSetup& fs, int x, int y) const;

  // The face's colour at pixel (x, y), s its shade.
  inline std::uint32_t face_color(const FaceSetup& fs, int x, int y, std::uint8_t& s) const;

  static inline double nearest_edge(const FaceSetup& fs, std::int64_t e0, std::int64_t e1, std::int64_t e2,
                                    std::int64_t e3);

  inline std::uint32_t darkened(const FaceSetup& fs, double d, std::uint8_t& s) const;

  // Graded field paint (raster_field.cpp): the colour at pixel (x, y), d pixels from the nearest edge
  // line; a run of a row in painter mode; the scale positions of the tet whose node row is tv.
  std::uint32_t graded_color(const FaceSetup& fs, int x, int y, double d, std::uint8_t& s) const;
  void graded_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const;
  const float* corner_positions(const std::uint32_t* tv) const {
    return field != nullptr && field->graded ? &field->corner_position[std::size_t(tv - mesh->tet.data())]
                                             : nullptr;
  }
  // Graded: the scale positions the kept tet nb (mesh tet index) gives the nodes tv[0..3] (a cell
  // field averaged per region gives a node a different position in each region); nodes not in nb
  // keep 0 (the one corner off a shared face, never used).
  void neighbour_positions(std::uint32_t nb, const std::uint32_t* tv, float out[4]) const;
  // The field paint's checks and colour table (raster_field.cpp; the constructor calls it).
  void setup_field();

  // True if every owned pixel of the pixel box b (not empty, y0 >= 0) is already written: nothing
  // drawn inside it can show.
  bool box_written(const Rows& rows, const Box& b, int height) {
    const int w0 = b.x0 >> 6, w1 = b.x1 >> 6, y1 = std::min(b.y1, rows.hi);
    for (int y = rows.first(std::max(b.y0, rows.lo)); y <= y1;) {
      const int band = y >> kBandShift, band_end = std::min(((band + 1) << kBandShift) - 1, height - 1);
      const int last = std::min(y1, band_end);
      std::uint8_t* tiles = &tile_full[std::size_t(band) * std::size_t(mask_words)];
      for (int w = w0; w <= w1; ++w) {
        if (tiles[w]) continue;
        const int lo = std::max(b.x0, w << 6) & 63, hi = std::min(b.x1, (w << 6) + 63) & 63;
        const std::uint64_t m = (~std::uint64_t(0) << lo) & (~std::uint64_t(0) >> (63 - hi));
        for (int r = y; r <= last; ++r)
          if ((written[std::size_t(r) * std::size_t(mask_words) + std::size_t(w)] & m) != m) return false;
        // The box's part of the tile is written; is all of it (later boxes then skip it)?
        bool full = true;
        for (int r = band << kBandShift; r <= band_end && full; ++r)
          full = written[std::size_t(r) * std::size_t(mask_words) + std::size_t(w)] == ~std::uint64_t(0);
        if (full) tiles[w] = 1;
      }
      y = rows.first(band_end + 1);
    }
    return true;
  }

  // Inlined into raster_polygon's row loop, as it was before the split (out of line it cost ~4% more
  // instructions per frame: GCC now inlines raster_triangle into raster_polygon and stops there).
  [[gnu::always_inline]] inline void shade_row(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi);

  inline void record_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi);

  [[gnu::always_inline]] inline void shade_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo,
                                                int hi) const;

  static inline void edges_at(const FaceSetup& fs, int x, int y, std::int64_t* e);

  // rgba, id, shade: the row's pixels.
  [[gnu::always_inline]] inline void edge_pixels(std::uint32_t* rgba, std::uint32_t* id, std::uint8_t* shade,
                                                 const FaceSetup& fs, std::int64_t* e, int from,
                                                 int to) const;
  template <bool kFourLines>
  [[gnu::always_inline]] inline void edge_pixels_of(std::uint32_t* rgba, std::uint32_t* id,
                                                    std::uint8_t* shade, const FaceSetup& fs, std::int64_t* e,
                                                    int from, int to) const;
  template <bool kFourLines, class Edge>
  [[gnu::always_inline]] inline void edge_pixels_stepped(std::uint32_t* rgba, std::uint32_t* id,
                                                         std::uint8_t* shade, const FaceSetup& fs, Edge* e,
                                                         const Edge* step, int from, int to) const;

#ifdef __SSE2__
  template <bool kFourLines>
  [[gnu::always_inline]] inline void edge_pixels_x4(std::uint32_t* rgba, std::uint32_t* id,
                                                    std::uint8_t* shade, const FaceSetup& fs, const double* e,
                                                    const double* step, int from, int to) const;
#endif

#ifdef FOXI_AVX512_REPAINT
  // Whether this CPU (and its OS) runs repaint_triangle_avx512; FOXI_PORTABLE_RASTER=1 in the
  // environment says no, so that tests compare it with the portable path on the same machine.
  static bool avx512_repaint() {
    static const bool yes =
        __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
        !(std::getenv("FOXI_PORTABLE_RASTER") && std::getenv("FOXI_PORTABLE_RASTER")[0] == '1');
    return yes;
  }

  __attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2"))) void repaint_triangle_avx512(
      Framebuffer& fb, const Rows& rows, const FaceSetup& fs, const PolyVertex* poly);
#endif

  [[gnu::noinline]] void shade_long_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const;

  void raster_polygon(Framebuffer& fb, const Rows& rows, FaceSetup& fs, const PolyVertex* poly, int n);
  void recolor_polygon(Framebuffer& fb, const Rows& rows, FaceSetup& fs, const PolyVertex* poly, int n);
  template <bool kRecolor>
  inline void raster_fan(Framebuffer& fb, const Rows& rows, FaceSetup& fs, const PolyVertex* poly, int n);

  // A tet's corners as `corners` gives them (c may point into local). Filled by load_corners, not
  // initialized here: it is made for every tet of every batch.
  struct TetCorners {
    const std::uint32_t* tv;
    const double* c[4];
    double local[12];
    std::int64_t X[4], Y[4];
    std::uint8_t st[4];
  };  // The pixel box of tet t (see Box): what draw_tet would draw is inside it, and if it is empty,
  // draw_tet draws and counts nothing.
  Box tet_box(std::uint32_t t, int width, int height) const {
    TetCorners k;
    load_corners(t, k);
    return tet_box(k, width, height);
  }
  // The same from the tet's corners (load_corners).
  static Box tet_box(const TetCorners& k, int width, int height) {
    const std::int64_t *X = k.X, *Y = k.Y;
    const std::uint8_t* st = k.st;
    Box box;
    if (st[0] == 2 || st[1] == 2 || st[2] == 2 || st[3] == 2) return box;
    if (st[0] + st[1] + st[2] + st[3] != 0) {
      box.y0 = -1;  // cut by the near plane (or behind it): not known
      box.x0 = box.x1 = 0;
      return box;
    }
    return pixel_box(std::min({X[0], X[1], X[2], X[3]}), std::max({X[0], X[1], X[2], X[3]}),
                     std::min({Y[0], Y[1], Y[2], Y[3]}), std::max({Y[0], Y[1], Y[2], Y[3]}), width, height);
  }

  // The pixels whose centres lie in the fixed-point box [minx, maxx] x [miny, maxy], in the image.
  static Box pixel_box(std::int64_t minx, std::int64_t maxx, std::int64_t miny, std::int64_t maxy, int width,
                       int height) {
    Box box;
    const std::int64_t x0 = std::max<std::int64_t>(0, -floor_div(-(minx - kHalf), kOne));
    const std::int64_t x1 = std::min<std::int64_t>(width - 1, floor_div(maxx - kHalf, kOne));
    const std::int64_t y0 = std::max<std::int64_t>(0, -floor_div(-(miny - kHalf), kOne));
    const std::int64_t y1 = std::min<std::int64_t>(height - 1, floor_div(maxy - kHalf, kOne));
    if (x0 > x1 || y0 > y1) return box;
    box.x0 = std::int32_t(x0);
    box.x1 = std::int32_t(x1);
    box.y0 = std::int32_t(y0);
    box.y1 = std::int32_t(y1);
    return box;
  }

  // Hints the cache about tet t's corners (the batch order jumps around the mesh): their node records.
  void prefetch_tet(std::uint32_t t) const {
    const std::uint32_t* tv = &mesh->tet[4 * std::size_t(t)];
    for (int k = 0; k < 4; ++k) __builtin_prefetch(&node_view[tv[k]]);
  }

  // Undoable: hints the cache about tet t's neighbours' positions in the drawing, read by
  // earlier_neighbour; t's adjacency row should be prefetched earlier.
  void prefetch_neighbours(std::uint32_t t) const {
    const std::uint32_t* nb = &adjacency->neighbour[4 * std::size_t(t)];
    for (int f = 0; f < 4; ++f)
      if (nb[f] != kNone && is_kept(nb[f] >> 2)) __builtin_prefetch(&drawn_at[nb[f] >> 2]);
  }

  // A tet's corners: camera coordinates (c, pointing into cam or local), fixed-point pixel
  // coordinates and states.
  void corners(const std::uint32_t* tv, const double** c, double* local, std::int64_t* X, std::int64_t* Y,
               std::uint8_t* st) const {
    if (params.shrink == 1) {
      for (int k = 0; k < 4; ++k) {
        const NodeView& v = node_view[tv[k]];
        c[k] = v.c;
        const bool in_front = v.X != kNoPixel;
        X[k] = v.X;
        Y[k] = v.Y;
        st[k] = in_front ? 0 : std::uint8_t(v.Y);
      }
    } else {
      double centre[3] = {0, 0, 0};
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j) centre[j] += 0.25 * cam(tv[k])[j];
      for (int k = 0; k < 4; ++k) {
        const double* p = cam(tv[k]);
        for (int j = 0; j < 3; ++j) local[3 * k + j] = centre[j] + params.shrink * (p[j] - centre[j]);
        c[k] = &local[3 * k];
        project_camera(c[k], X[k], Y[k], st[k]);
      }
    }
  }

  // Loads tet t's corners into k; false if one of them is not finite (the tet draws nothing).
  bool load_corners(std::uint32_t t, TetCorners& k) const {
    k.tv = &mesh->tet[4 * std::size_t(t)];
    corners(k.tv, k.c, k.local, k.X, k.Y, k.st);
    return k.st[0] != 2 && k.st[1] != 2 && k.st[2] != 2 && k.st[3] != 2;
  }

  // pos: graded field paint, the scale positions to give k's corners (4, k's local order) instead of
  // the tet's own (undraw repaints a kept neighbour's face with the neighbour's, see neighbour_positions).
  int face_polygon(const TetCorners& k, int f, bool back, PolyVertex* poly, bool* clipped,
                   const float* pos = nullptr) const;

  inline void draw_tet(Framebuffer& fb, const Rows& rows, std::uint32_t t, bool count);

  void draw_face(Framebuffer& fb, const Rows& rows, std::uint32_t t, const double* const v[3],
                 const std::uint32_t node[3], const PolyVertex* poly, int n, bool test_hidden);

  // Checks fb's sizes and aims the colour writes (`colors`) at fb.rgba, or at `rows` (row_pixels
  // apart) when given, fb.rgba then being left as it is (it may be empty).
  void check_framebuffer(Framebuffer& fb, std::uint32_t* rows = nullptr, std::size_t row_pixels = 0);
  // Gives fb a shade buffer if it has none of its size (a framebuffer put together by hand).
  static void ensure_shade(Framebuffer& fb) {
    if (fb.shade.size() != fb.id.size()) fb.shade.assign(fb.id.size(), 0);
  }

  // Recolouring a drawn picture through its id buffer (recolor.cpp).
  void recolor(Framebuffer& fb, std::shared_ptr<const FieldPaint> paint);
  void recolor_tet(Framebuffer& fb, const Rows& rows, std::uint32_t t);
  void recolor_row(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const;
  void recolor_by_shade(Framebuffer& fb);
  bool recolors_by_shade(const FieldPaint* paint) const;

  void draw(Framebuffer& fb, std::span<const std::uint32_t> tets, std::uint32_t* rows = nullptr,
            std::size_t row_pixels = 0);

  inline void answer_requests(const Framebuffer& fb, int k);

  inline void draw_batch(Framebuffer& fb, std::span<const std::uint32_t> tets);

  inline PixelRect boxes_union(std::size_t n) const;

  void zero_mask(int y0, int y1);

  inline void clear_mask(std::size_t n);

  // --- Undraw (seed paper, section 6.2) ---
  // A back face of a drawn tet is shared when the tet across it was drawn before it (with unshrunk
  // tets only): in the picture of the tets before t, its pixels show that neighbour's front face.
  std::uint32_t earlier_neighbour(std::uint32_t t, int f) const {
    if (params.shrink != 1) return kNone;
    const std::uint32_t nb = adjacency->neighbour[4 * std::size_t(t) + std::size_t(f)];
    if (nb == kNone || !is_kept(nb >> 2) || drawn_at[nb >> 2] >= drawn_at[t]) return kNone;
    return nb;
  }

  template <class Fn>
  inline void for_each_run(const PolyVertex* poly, int n, const Rows& rows, Fn&& fn) const;

  template <class Fn>
  inline void for_each_back_face(std::uint32_t t, Fn&& fn) const;

  inline bool has_unshared_back_face(std::uint32_t t, const TetCorners& k, std::uint16_t& reach,
                                     bool& inverted, unsigned* edge_on = nullptr) const;

  void taint_inverted(std::span<const std::uint32_t> tets, std::span<const std::uint32_t> inverted_at);

  // Whether face f of a tet (corners k, none cut by the near plane) is seen exactly edge on, to
  // rounding (see kNearEdge).
  bool edge_on_face(const TetCorners& k, int f) const;

  void request_saves(const Framebuffer& fb, const Rows& rows, std::uint32_t t);

  // During undraw, the tet across face f of undrawn tet t if it is kept (unshrunk tets only; the
  // earlier_neighbour of t then), else kNone.
  std::uint32_t kept_neighbour(std::uint32_t t, int f) const {
    if (params.shrink != 1) return kNone;
    const std::uint32_t nb = adjacency->neighbour[4 * std::size_t(t) + std::size_t(f)];
    return nb != kNone && is_kept(nb >> 2) ? nb : kNone;
  }

  inline void gather_undrawn(std::uint32_t t, UndrawTet& u) const;

  inline void shade_repainted(UndrawTet& u) const;

  void undraw(Framebuffer& fb, std::size_t count);

  inline void undraw_part(Framebuffer& fb, std::size_t count);

  static inline void add_band_work(std::vector<double>& work, const Box& b);

  static inline std::vector<int> split_rows(const std::vector<double>& work, int parts, int height);

  // Where save s of a lane's pixels end: saves of one draw() call were filed front to back, so in
  // drawing order a save's pixels run up to those of the save before it in the same call.
  static std::size_t save_end(const Lane& lane, std::size_t s) {
    std::size_t r = lane.regions.size();
    while (r > 0 && lane.regions[r - 1].first_save > s) --r;
    const SaveRegion& region = lane.regions[r - 1];
    const std::size_t region_end =
        r < lane.regions.size() ? lane.regions[r].first_pixel : lane.saved_pixel.size();
    return s > region.first_save ? lane.saves[s - 1].offset : region_end;
  }

  void forget();

  std::size_t saved_pixels() const;

  std::size_t undo_bytes() const;
};

// The distance in pixels to the nearest edge line from a pixel whose edge functions are e0..e3.
inline double TetRasterizer::Impl::nearest_edge(const FaceSetup& fs, std::int64_t e0, std::int64_t e1,
                                                std::int64_t e2, std::int64_t e3) {
  return std::min(std::min(double(e0) * fs.inv_len[0], double(e1) * fs.inv_len[1]),
                  std::min(double(e2) * fs.inv_len[2], double(e3) * fs.inv_len[3]));
}

}  // namespace foxi
