// The painter's rasterizer (see rasterizer.hpp). Face setup works in camera coordinates (x right,
// y up, z depth; a left-handed frame, so cross products there are the mirror of world ones), pixels
// in fixed point with 8 subpixel bits and 64-bit edge functions.
#include "foxi/viz/rasterizer.hpp"

#include "foxi/model/adjacency.hpp"
#include "huge_page_allocator.hpp"
#include "thread_pool.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <exception>
#include <functional>
#include <future>
#include <limits>
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

namespace {

constexpr std::int64_t kOne = 256;       // 8 subpixel bits
constexpr std::int64_t kHalf = 128;      // pixel centre offset
constexpr int kBandShift = 4;            // bands of 16 rows, interleaved between threads
constexpr double kMaxPixel = 1048576.0;  // |pixel coordinate - centre| bound (2^20): 64-bit safe

// Local vertex triples of the 4 faces of a positively oriented tet, ordered so that (b - a) x (c - a)
// points out of the tet (world frame); face f is opposite vertex f.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// Runs f(0), ..., f(parts - 1): f(0) on the calling thread, the others on pooled threads (starting a
// thread per call would cost tens of microseconds each, per frame); returns when all are done,
// rethrowing the first exception. not_started() is called if f(0) will not run because a part could
// not be handed to a thread (parts already running may be waiting for f(0): it must let them go).
template <class F, class G>
void run_parts(int parts, F&& f, G&& not_started) {
  std::vector<std::future<void>> others;
  std::exception_ptr error;
  bool posted = false;
  try {
    for (int k = 1; k < parts; ++k) others.push_back(pool::run_async([&f, k] { f(k); }));
    posted = true;
    f(0);
  } catch (...) {
    error = std::current_exception();
    if (!posted) not_started();
  }
  for (auto& other : others) {
    try {
      pool::finish(other);
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

// The same when no part waits for another.
template <class F>
void run_parts(int parts, F&& f) {
  run_parts(parts, f, [] {});
}

std::int64_t floor_div(std::int64_t a, std::int64_t b) {  // b > 0
  std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

std::int64_t to_fixed(double p) {
  return static_cast<std::int64_t>(
      std::llround(std::clamp(p, -4.0 * kMaxPixel, 4.0 * kMaxPixel) * double(kOne)));
}

// Which rows a thread owns: bands of 16 rows, band b belongs to thread b % count, and of those only
// the rows in [lo, hi] (undraw gives each thread one such range, see split_rows).
struct Rows {
  int thread = 0, count = 1;
  int lo = 0, hi = std::numeric_limits<int>::max();
  bool owns(int y) const { return y >= lo && y <= hi && (count == 1 || ((y >> kBandShift) % count) == thread); }
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
bool owns_boundary(std::int64_t dx, std::int64_t dy) { return dy < 0 || (dy == 0 && dx > 0); }

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

struct PolyVertex {
  double c[3] = {0, 0, 0};  // camera coordinates (near-plane cuts only)
  std::int64_t X = 0, Y = 0;
  double w = 0;           // nearness (1 / depth perspective, -depth orthographic), depth mode
  bool mesh_edge = true;  // the edge from this vertex to the next is (part of) a mesh edge
};

// A face's flat colour (before edge darkening): packed, and its channels unrounded.
struct FaceShade {
  std::uint32_t color = 0;
  float r = 0, g = 0, b = 0;
};

// Everything a face's pixels need.
struct FaceSetup {
  std::uint32_t tet = 0;
  std::uint32_t color = 0;
  alignas(16) float rgb[4] = {0, 0, 0, 0};  // FaceShade's r, g, b (and 0), for darkened
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
};

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

struct TetRasterizer::Impl {
  const Mesh* mesh = nullptr;
  Projector proj;
  RenderParams params;
  double near = 0;
  double light[3] = {0, 0, -1};  // toward the light, camera frame
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
    std::vector<Save> saves;                                        // in drawing order
    std::vector<std::uint32_t> saved_pixel, saved_rgba, saved_id;  // y * width + x, colour, id
    std::vector<SaveRegion> regions;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> aliases;  // (request, later request it equals)
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
  std::vector<std::uint8_t> need_save;  // per batch tet
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
    std::int32_t X[4], Y[4];         // fixed-point corners
    std::uint32_t node[4];           // the tet's nodes
    std::uint8_t repaint = 0;        // bit f: back face f is shared with a kept tet
    std::uint32_t neighbour[4];      // repaint face f: that tet's face (4 tet + face)
    FaceShade shade[4];              // repaint face f: that tet's front face's flat colour
  };
  PixelRect changed;  // see changed_rect
  // See changed_rects; during an undraw, per band of 16 rows the x-extent of the undrawn tets' boxes.
  std::vector<PixelRect> changed_list;
  std::vector<int> band_x0, band_x1;
  void changed_is_one_rect() {
    changed_list.clear();
    if (changed.x0 <= changed.x1) changed_list.push_back(changed);
  }

  Impl(const Mesh& m, const Camera& c, int w, int h, const RenderParams& p)
      : mesh(&m), proj(c, w, h), params(p) {
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
    reverse = !params.depth_buffer;
    mask_words = (w + 63) / 64;
    use_mask = reverse;
    if (params.undoable) {
      if (params.depth_buffer) throw std::invalid_argument("render: undoable drawing needs the painter");
      if (w > 32767 || h > 32767)
        throw std::invalid_argument("render: undoable drawing needs an image at most 32767 pixels wide and high");
      adjacency = &face_adjacency(m);
      drawn_at.assign(m.tet_count(), 0);
      kept.assign((m.tet_count() + 63) / 64, 0);
      const std::size_t pixels = std::size_t(w) * std::size_t(h);
      shown.assign(std::size_t(mask_words) * std::size_t(h), 0);
      slot.assign(pixels, kNone);
      before_rgba.assign(pixels, 0);
      before_id.assign(pixels, 0);
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

  // The flat shade of tet `tet`'s face whose corners are `v` (camera frame) in outward order, node[j]
  // the node of v[j]: its region's colour, Lambert + ambient. The normal is computed from the corners
  // in ascending node order (its sign from the permutation's parity), so the two tets sharing a face
  // get the same bits, each side with its sign: undraw shades a kept neighbour's face from the
  // undrawn tet's own corners, as drawing the neighbour did.
  FaceShade face_shade(std::uint32_t tet, const double* const v[3], const std::uint32_t node[3]) const {
    int s0 = 0, s1 = 1, s2 = 2;
    bool odd = false;
    auto swap_if = [&](int& i, int& j) {
      if (node[i] > node[j]) {
        std::swap(i, j);
        odd = !odd;
      }
    };
    swap_if(s0, s1);
    swap_if(s1, s2);
    swap_if(s0, s1);
    const double *p0 = v[s0], *p1 = v[s1], *p2 = v[s2];
    double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    double w[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    double nc[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    double len = std::sqrt(nc[0] * nc[0] + nc[1] * nc[1] + nc[2] * nc[2]);
    // The camera frame is a mirror of the world: the outward normal is -nc there (+nc for an odd
    // permutation of the outward order).
    double lambert = len > 0 ? -(nc[0] * light[0] + nc[1] * light[1] + nc[2] * light[2]) / len : 0;
    if (odd) lambert = -lambert;
    double intensity = params.ambient + (1 - params.ambient) * std::max(0.0, lambert);
    intensity = std::clamp(intensity, 0.0, 1.0);
    const std::int32_t region = mesh->region_of(tet);
    std::uint32_t base = region >= 0 && std::size_t(region) < params.region_colors.size()
                             ? params.region_colors[std::size_t(region)]
                             : region_color(region);
    FaceShade sh;
    sh.r = float((base & 255u) * intensity);
    sh.g = float(((base >> 8) & 255u) * intensity);
    sh.b = float(((base >> 16) & 255u) * intensity);
    sh.color = pack_rgba(std::uint32_t(sh.r + 0.5f), std::uint32_t(sh.g + 0.5f), std::uint32_t(sh.b + 0.5f));
    return sh;
  }

  // The edge line from a to b: E(p) = ex (py - ay) - ey (px - ax) at the pixel centre
  // p = (x, y) kOne + kHalf, as ea x + eb y + ec (|coordinates| <= 2^30 keep every term below 2^62);
  // length: the edge's, in fixed-point units.
  struct EdgeLine {
    std::int64_t ea, eb, ec;
    double length;
  };
  static EdgeLine edge_line(const PolyVertex& a, const PolyVertex& b) {
    const std::int64_t ex = b.X - a.X, ey = b.Y - a.Y;
    return EdgeLine{-ey * kOne, ex * kOne, ex * (kHalf - a.Y) - ey * (kHalf - a.X),
                    std::sqrt(double(ex) * double(ex) + double(ey) * double(ey))};
  }

  // Whether the line ea x + eb y + ec is below 2^52 in magnitude on the whole image (see
  // FaceSetup::exact_double).
  bool exact_in_double(std::int64_t ea, std::int64_t eb, std::int64_t ec) const {
    return std::abs(double(ea)) * proj.width + std::abs(double(eb)) * proj.height + std::abs(double(ec)) < 0x1p52;
  }

  // A face of tet `tet` in shade sh.
  static void set_shade(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh) {
    fs.tet = tet;
    fs.rgb[0] = sh.r;
    fs.rgb[1] = sh.g;
    fs.rgb[2] = sh.b;
    fs.color = sh.color;
  }

#ifdef FOXI_AVX512_REPAINT
  // What repaint_triangle_avx512 reads of setup_face's work for triangle poly (the shade, and the
  // three edge lines in double), false if it does not apply (an edge of no length, or a line not
  // exact in double).
  bool setup_repaint(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh, const PolyVertex* poly) const {
    set_shade(fs, tet, sh);
    fs.lines = 3;
    for (int k = 0; k < 3; ++k) {
      const EdgeLine line = edge_line(poly[k], poly[k == 2 ? 0 : k + 1]);
      if (!(line.length > 0) || !exact_in_double(line.ea, line.eb, line.ec)) return false;
      fs.step[k] = double(line.ea);
      fs.step_y[k] = double(line.eb);
      fs.at0[k] = double(line.ec);
      fs.inv_len[k] = 1 / (double(kOne) * line.length);
    }
    return true;
  }
#endif

  // Shading and edge lines of a face; `v` = the face's three corners (camera frame)
  // in outward order, node their nodes; poly = the polygon to draw (positive area), n its size.
  void setup_face(FaceSetup& fs, std::uint32_t tet, const double* const v[3], const std::uint32_t node[3],
                  const PolyVertex* poly, int n) const {
    setup_face(fs, tet, face_shade(tet, v, node), poly, n);
  }

  // The same with the shade known.
  void setup_face(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh, const PolyVertex* poly, int n) const {
    set_shade(fs, tet, sh);
    fs.lines = 0;
    if (params.edges) {
      for (int i = 0; i < n; ++i) {
        if (!poly[i].mesh_edge) continue;
        const EdgeLine line = edge_line(poly[i], poly[i + 1 == n ? 0 : i + 1]);
        if (!(line.length > 0)) continue;
        const int k = fs.lines++;
        fs.ea[k] = line.ea;
        fs.eb[k] = line.eb;
        fs.ec[k] = line.ec;
        fs.inv_len[k] = 1 / (double(kOne) * line.length);
        fs.flat_e[k] = params.edge_width / fs.inv_len[k];
      }
    }
    fs.exact_double = true;
    for (int k = 0; k < fs.lines; ++k) fs.exact_double = fs.exact_double && exact_in_double(fs.ea[k], fs.eb[k], fs.ec[k]);
    for (int k = fs.lines; k < 4; ++k) {  // padding: far from every pixel
      fs.ea[k] = fs.eb[k] = 0;
      fs.ec[k] = std::int64_t(1) << 62;
      fs.inv_len[k] = 1;
      fs.flat_e[k] = 0;
    }
    for (int k = 0; k < 4; ++k) {
      fs.step[k] = double(fs.ea[k]);
      fs.step_y[k] = double(fs.eb[k]);
      fs.at0[k] = double(fs.ec[k]);
    }
  }

  void shade_pixel(Framebuffer& fb, const FaceSetup& fs, int x, int y) const {
    const std::size_t p = std::size_t(y) * std::size_t(fb.width) + std::size_t(x);
    if (params.depth_buffer) {
      const double z = fs.w0 + fs.da * (x + 0.5 - fs.x0) + fs.db * (y + 0.5 - fs.y0);
      if (!(z > fb.depth[p])) return;
      fb.depth[p] = z;
    }
    fb.rgba[p] = face_color(fs, x, y);
    fb.id[p] = fs.tet;
  }

  // The colour of a face at pixel (x, y): flat, darkened near its edges.
  std::uint32_t face_color(const FaceSetup& fs, int x, int y) const {
    std::int64_t e[4];
    for (int k = 0; k < 4; ++k) e[k] = fs.ea[k] * x + fs.eb[k] * y + fs.ec[k];
    return darkened(fs, nearest_edge(fs, e[0], e[1], e[2], e[3]));
  }

  // The distance in pixels to the nearest edge line from a pixel whose edge functions are e0..e3.
  static double nearest_edge(const FaceSetup& fs, std::int64_t e0, std::int64_t e1, std::int64_t e2,
                             std::int64_t e3) {
    return std::min(std::min(double(e0) * fs.inv_len[0], double(e1) * fs.inv_len[1]),
                    std::min(double(e2) * fs.inv_len[2], double(e3) * fs.inv_len[3]));
  }

  // The face's colour at distance d from its nearest edge line: each channel scaled by
  // 1 - darkness (1 - d / width), rounded (the three channels at once where SSE2 is there, with the
  // same float operations).
  std::uint32_t darkened(const FaceSetup& fs, double d) const {
    if (!(d < params.edge_width)) return fs.color;
    const float f = float(edge_base + edge_slope * std::max(0.0, d));
#ifdef __SSE2__
    const __m128 scaled = _mm_add_ps(_mm_mul_ps(_mm_load_ps(fs.rgb), _mm_set1_ps(f)), _mm_set1_ps(0.5f));
    __m128i channels = _mm_cvttps_epi32(scaled);  // each in [0, 255]
    channels = _mm_packus_epi16(_mm_packs_epi32(channels, channels), channels);
    return std::uint32_t(_mm_cvtsi128_si32(channels)) | 0xff000000u;
#else
    return pack_rgba(std::uint32_t(fs.rgb[0] * f + 0.5f), std::uint32_t(fs.rgb[1] * f + 0.5f),
                     std::uint32_t(fs.rgb[2] * f + 0.5f));
#endif
  }

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

  // One row run of a face. Painter mode: only the pixels not yet written (see `written`), then the
  // whole run is marked written.
  void shade_row(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) {
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
  void record_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) {
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
        shade_span(fb, fs, y, x, e);
        shown_row[x >> 6] |= (~std::uint64_t(0) >> (63 - (e - x))) << (x & 63);  // [x, e] in one word
      } else {
        Lane& lane = lanes[std::size_t(lane_of(y))];
        for (int k = x; k <= e; ++k) {
          std::uint32_t& request = slot[row + std::size_t(k)];
          if (request == kNone) continue;  // cannot happen: shown and not done means a request
          lane.saved_rgba[request] = face_color(fs, k, y);
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
  [[gnu::always_inline]] void shade_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const {
    if (hi - lo >= 12 || fs.lines == 0) {
      shade_long_span(fb, fs, y, lo, hi);
      return;
    }
    std::uint32_t* rgba = fb.rgba.data() + std::size_t(y) * std::size_t(fb.width);
    std::uint32_t* id = fb.id.data() + std::size_t(y) * std::size_t(fb.width);
    if (fs.exact_double) [[likely]] {  // the edge functions at lo straight in double (no 64-bit products)
      const double dx = double(lo), dy = double(y);
      double d[4];
      for (int k = 0; k < 3; ++k) d[k] = fs.step[k] * dx + (fs.step_y[k] * dy + fs.at0[k]);
      if (fs.lines > 3) {
        d[3] = fs.step[3] * dx + (fs.step_y[3] * dy + fs.at0[3]);
        edge_pixels_stepped<true>(rgba, id, fs, d, fs.step, lo, hi);
      } else {
        d[3] = 0;
        edge_pixels_stepped<false>(rgba, id, fs, d, fs.step, lo, hi);
      }
      return;
    }
    std::int64_t e[4];
    edges_at(fs, lo, y, e);
    edge_pixels(rgba, id, fs, e, lo, hi);
  }

  // The edge functions of fs's lines at pixel (x, y) (the padding line's is constant).
  static void edges_at(const FaceSetup& fs, int x, int y, std::int64_t* e) {
    for (int k = 0; k < 3; ++k) e[k] = fs.ea[k] * x + fs.eb[k] * y + fs.ec[k];
    e[3] = fs.lines > 3 ? fs.ea[3] * x + fs.eb[3] * y + fs.ec[3] : fs.ec[3];
  }

  // Pixels [from, to] of a row shaded one by one (rgba, id: the row), e: the edge functions at
  // `from`, stepped on past `to`. The edge functions and colours are held in registers; a face of 3
  // lines or fewer skips the fourth (padding, never the nearest).
  [[gnu::always_inline]] void edge_pixels(std::uint32_t* rgba, std::uint32_t* id, const FaceSetup& fs,
                                          std::int64_t* e, int from, int to) const {
    if (fs.lines > 3)
      edge_pixels_of<true>(rgba, id, fs, e, from, to);
    else
      edge_pixels_of<false>(rgba, id, fs, e, from, to);
  }
  template <bool kFourLines>
  [[gnu::always_inline]] void edge_pixels_of(std::uint32_t* rgba, std::uint32_t* id, const FaceSetup& fs,
                                             std::int64_t* e, int from, int to) const {
    if (!fs.exact_double) [[unlikely]] {  // huge coordinates (near-plane cuts)
      edge_pixels_stepped<kFourLines>(rgba, id, fs, e, fs.ea, from, to);
      return;
    }
    // Stepped in double (see FaceSetup::exact_double): no conversion per pixel.
    double d[4] = {double(e[0]), double(e[1]), double(e[2]), kFourLines ? double(e[3]) : 0};
    edge_pixels_stepped<kFourLines>(rgba, id, fs, d, fs.step, from, to);
    if (to >= from)
      for (int k = 0; k < 4; ++k) e[k] += fs.ea[k] * (to - from + 1);
  }
  // The loop of edge_pixels_of, its edge functions e (at `from`, stepped by `step` per pixel; integers
  // are left past `to`) 64-bit integers or exact doubles.
  template <bool kFourLines, class Edge>
  [[gnu::always_inline]] void edge_pixels_stepped(std::uint32_t* rgba, std::uint32_t* id, const FaceSetup& fs,
                                                  Edge* e, const Edge* step, int from, int to) const {
#ifdef __SSE2__
    if constexpr (std::is_same_v<Edge, double>) {
      edge_pixels_x4<kFourLines>(rgba, id, fs, e, step, from, to);
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
      rgba[x] = d < w ? darkened(fs, d) : color;
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
  // IEEE operations in the same order as the one-pixel loop and darkened() (the edge functions are
  // integers, so e + k step is the stepped value exactly; min and max differ from std::min and
  // std::max only in the sign of a zero, which max(0, d) and d < w do not see; no FMA in an SSE2
  // build), so every pixel gets the same bits. A last group of fewer than 4 stores only its pixels.
  template <bool kFourLines>
  [[gnu::always_inline]] void edge_pixels_x4(std::uint32_t* rgba, std::uint32_t* id, const FaceSetup& fs,
                                             const double* e, const double* step, int from, int to) const {
    if (to < from) return;
    const __m128d w = _mm_set1_pd(params.edge_width), zero = _mm_setzero_pd();
    const __m128d base = _mm_set1_pd(edge_base), slope = _mm_set1_pd(edge_slope);
    const __m128 r = _mm_set1_ps(fs.rgb[0]), g = _mm_set1_ps(fs.rgb[1]), b = _mm_set1_ps(fs.rgb[2]);
    const __m128 half = _mm_set1_ps(0.5f);
    const __m128i color = _mm_set1_epi32(int(fs.color)), tet = _mm_set1_epi32(int(fs.tet));
    const __m128i alpha = _mm_set1_epi32(int(0xff000000u)), none = _mm_setzero_si128();
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
      const __m128 darken = _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(d_lo, w)), _mm_castpd_ps(_mm_cmplt_pd(d_hi, w)),
                                         _MM_SHUFFLE(2, 0, 2, 0));
      __m128i out = color;
      if (_mm_movemask_ps(darken) != 0) {
        const __m128 f = _mm_movelh_ps(_mm_cvtpd_ps(_mm_add_pd(base, _mm_mul_pd(slope, _mm_max_pd(d_lo, zero)))),
                                       _mm_cvtpd_ps(_mm_add_pd(base, _mm_mul_pd(slope, _mm_max_pd(d_hi, zero)))));
        const __m128i cr = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(r, f), half));
        const __m128i cg = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(g, f), half));
        const __m128i cb = _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(b, f), half));
        // Saturated to bytes as darkened() does: r0..r3 g0..g3 b0..b3, then interleaved per pixel.
        const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(cr, cg), _mm_packs_epi32(cb, cb));
        const __m128i rg = _mm_unpacklo_epi8(bytes, _mm_srli_si128(bytes, 4));
        const __m128i b0 = _mm_unpacklo_epi8(_mm_srli_si128(bytes, 8), none);
        const __m128i dark = _mm_or_si128(_mm_unpacklo_epi16(rg, b0), alpha);
        const __m128i m = _mm_castps_si128(darken);
        out = _mm_or_si128(_mm_and_si128(m, dark), _mm_andnot_si128(m, color));
      }
      const int left = to - x + 1;
      if (left >= 4) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(rgba + x), out);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(id + x), tet);
        if (left == 4) return;
      } else {
        if (left >= 2) {
          _mm_storel_epi64(reinterpret_cast<__m128i*>(rgba + x), out);
          _mm_storel_epi64(reinterpret_cast<__m128i*>(id + x), tet);
        }
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

#ifdef FOXI_AVX512_REPAINT
  // Whether this CPU (and its OS) runs repaint_triangle_avx512; FOXI_PORTABLE_RASTER=1 in the
  // environment says no, so that tests compare it with the portable path on the same machine.
  static bool avx512_repaint() {
    static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
                            !(std::getenv("FOXI_PORTABLE_RASTER") && std::getenv("FOXI_PORTABLE_RASTER")[0] == '1');
    return yes;
  }

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
  __attribute__((target("avx512f,avx512vl,avx512bw,avx512dq,avx2"))) void repaint_triangle_avx512(
      Framebuffer& fb, const Rows& rows, const FaceSetup& fs, const PolyVertex* poly) {
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
    const __m256 r = _mm256_set1_ps(fs.rgb[0]), g = _mm256_set1_ps(fs.rgb[1]), b = _mm256_set1_ps(fs.rgb[2]);
    const __m256 half = _mm256_set1_ps(0.5f);
    const __m256i color = _mm256_set1_epi32(int(fs.color)), tet = _mm256_set1_epi32(int(fs.tet));
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
        // d; the channels are in [0, 255] (edge_darkness in [0, 1], see fast_repaint), so its
        // saturation changes nothing. Lanes not covered are garbage the stores skip.
        const __mmask8 dark = _mm512_cmp_pd_mask(d, width, _CMP_LT_OQ);
        const __m256 f = _mm512_cvtpd_ps(_mm512_add_pd(base, _mm512_mul_pd(slope, d)));
        const __m256i cr = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(r, f), half));
        const __m256i cg = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(g, f), half));
        const __m256i cb = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(b, f), half));
        const __m256i px_dark = _mm256_or_si256(_mm256_or_si256(cr, _mm256_slli_epi32(cg, 8)),
                                                _mm256_or_si256(_mm256_slli_epi32(cb, 16), alpha));
        const __m256i out = _mm256_mask_blend_epi32(dark, color, px_dark);
        _mm256_mask_storeu_epi32(rgba + x, todo, out);
        _mm256_mask_storeu_epi32(id + x, todo, tet);
      }
    }
  }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

  // shade_span's long runs (and faces without edge lines).
  [[gnu::noinline]] void shade_long_span(Framebuffer& fb, const FaceSetup& fs, int y, int lo, int hi) const {
    std::uint32_t* rgba = fb.rgba.data() + std::size_t(y) * std::size_t(fb.width);
    std::uint32_t* id = fb.id.data() + std::size_t(y) * std::size_t(fb.width);
    if (fs.lines == 0) {
      std::fill(rgba + lo, rgba + hi + 1, fs.color);
      std::fill(id + lo, id + hi + 1, fs.tet);
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
      edge_pixels(rgba, id, fs, e, lo, hi);
      return;
    }
    edge_pixels(rgba, id, fs, e, lo, a - 1);
    std::fill(rgba + a, rgba + b + 1, fs.color);
    std::fill(id + a, id + b + 1, fs.tet);
    for (int k = 0; k < 4; ++k) e[k] += fs.ea[k] * (b + 1 - a);
    edge_pixels(rgba, id, fs, e, b + 1, hi);
  }

  // Draws a convex polygon (positive area) as a fan from vertex 0.
  void raster_polygon(Framebuffer& fb, const Rows& rows, FaceSetup& fs, const PolyVertex* poly, int n) {
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
      raster_triangle(X, Y, fb.width, fb.height, rows,
                      [&](int y, int lo, int hi) { shade_row(fb, fs, y, lo, hi); });
    }
  }

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

  // The polygon of face f of tet t (corners from `corners`) as drawn when it faces the eye: front
  // (back = false) for t itself, back (back = true) the same face seen from the other side, which is
  // exactly the polygon the neighbour across it draws as its front face (same vertices, same
  // orientation, same pixels under the fill rule). Returns its vertex count (3, or 4 when the near
  // plane cuts it) with positive area, or 0 when the face is not of the asked side or covers nothing.
  // *clipped is set when the near plane cuts a face of the asked side.
  int face_polygon(const TetCorners& k, int f, bool back, PolyVertex* poly, bool* clipped) const {
    const std::uint32_t* tv = k.tv;
    const double* const* c = k.c;
    const std::int64_t *X = k.X, *Y = k.Y;
    const std::uint8_t* st = k.st;
    *clipped = false;
    const auto& face = kFace[f];
    const int a = face[0], b = face[1], d = face[2];
    if (st[a] + st[b] + st[d] == 0) {
      // Front iff the projected outward-ordered triangle has negative area (screen y is down and
      // the camera frame mirrors the world). The neighbour sharing this face computes the same
      // area with the opposite sign, so exactly one of the two draws it.
      const std::int64_t area = (X[b] - X[a]) * (Y[d] - Y[a]) - (Y[b] - Y[a]) * (X[d] - X[a]);
      if (back ? area <= 0 : area >= 0) return 0;
      const int front_order[3] = {a, d, b}, back_order[3] = {a, b, d};  // positive area
      const int* order = back ? back_order : front_order;
      for (int i = 0; i < 3; ++i) {
        poly[i].X = X[order[i]];
        poly[i].Y = Y[order[i]];
        poly[i].w = nearness(c[order[i]]);
        poly[i].mesh_edge = true;
      }
      return 3;
    }
    if (st[a] + st[b] + st[d] == 3) return 0;  // entirely behind the near plane
    // Cut by the near plane. Canonical order (ascending node id) so that both tets sharing the
    // face compute bit-identical polygons; facing from the exact same double expression.
    int s[3] = {a, b, d};
    bool odd = false;
    auto swap_if = [&](int i, int j) {
      if (tv[s[i]] > tv[s[j]]) {
        std::swap(s[i], s[j]);
        odd = !odd;
      }
    };
    swap_if(0, 1);
    swap_if(1, 2);
    swap_if(0, 1);
    const double *p0 = c[s[0]], *p1 = c[s[1]], *p2 = c[s[2]];
    double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    double w[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    double nc[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    // World: front iff n_out . (eye - p0) > 0; in the mirrored camera frame n_out = -nc_out and
    // eye - p0 = -p0, so front iff nc_out . p0 > 0, and nc_out = +-nc by the permutation parity.
    // The neighbour's parity is the opposite one, so its side is exactly -side.
    double side = nc[0] * p0[0] + nc[1] * p0[1] + nc[2] * p0[2];
    if (odd != back) side = -side;
    if (!(side > 0)) return 0;
    *clipped = true;
    // Sutherland-Hodgman against z >= near; intersections computed from the lower node id.
    int n = 0;
    for (int i = 0; i < 3; ++i) {
      const int pi = s[i], qi = s[i == 2 ? 0 : i + 1];
      const bool pin = st[pi] == 0, qin = st[qi] == 0;
      auto cut = [&](PolyVertex& out) {
        int lo = pi, hi = qi;
        if (tv[lo] > tv[hi]) std::swap(lo, hi);
        const double* P = c[lo];
        const double* Q = c[hi];
        double tt = (near - P[2]) / (Q[2] - P[2]);
        out.c[0] = P[0] + tt * (Q[0] - P[0]);
        out.c[1] = P[1] + tt * (Q[1] - P[1]);
        out.c[2] = near;
        out.w = 1 / near;
        std::uint8_t dummy;
        project_camera(out.c, out.X, out.Y, dummy);
      };
      if (pin) {
        poly[n].X = X[pi];
        poly[n].Y = Y[pi];
        poly[n].w = nearness(c[pi]);
        poly[n].mesh_edge = true;
        ++n;
        if (!qin) {
          cut(poly[n]);
          poly[n].mesh_edge = false;
          ++n;
        }
      } else if (qin) {
        cut(poly[n]);
        poly[n].mesh_edge = true;
        ++n;
      }
    }
    std::int64_t area2 = 0;
    for (int i = 0; i < n; ++i) {
      const PolyVertex& p = poly[i];
      const PolyVertex& q = poly[i + 1 == n ? 0 : i + 1];
      area2 += p.X * q.Y - q.X * p.Y;
    }
    if (area2 == 0) return 0;
    if (area2 < 0) {
      // Reverse; the edge leaving vertex i+1 in the new order is the old edge i -> i+1.
      PolyVertex r[4];
      for (int i = 0; i < n; ++i) {
        r[i] = poly[n - 1 - i];
        r[i].mesh_edge = poly[(2 * n - 2 - i) % n].mesh_edge;
      }
      std::copy(r, r + n, poly);
    }
    return n;
  }

  // Draws tet t's front faces into the rows of `rows`.
  void draw_tet(Framebuffer& fb, const Rows& rows, std::uint32_t t, bool count) {
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
  void draw_face(Framebuffer& fb, const Rows& rows, std::uint32_t t, const double* const v[3],
                 const std::uint32_t node[3], const PolyVertex* poly, int n, bool test_hidden) {
    if (use_mask && test_hidden) {  // hidden behind what this batch drew already?
      const Box box = pixel_box(std::min({poly[0].X, poly[1].X, poly[2].X}),
                                std::max({poly[0].X, poly[1].X, poly[2].X}),
                                std::min({poly[0].Y, poly[1].Y, poly[2].Y}),
                                std::max({poly[0].Y, poly[1].Y, poly[2].Y}), fb.width, fb.height);
      if (box.x0 > box.x1 || box_written(rows, box, fb.height)) return;
    }
    FaceSetup fs;
    setup_face(fs, t, v, node, poly, n);
    raster_polygon(fb, rows, fs, poly, n);
  }

  void check_framebuffer(const Framebuffer& fb) const {
    if (fb.width != proj.width || fb.height != proj.height)
      throw std::invalid_argument("render: framebuffer size differs from the rasterizer's");
    if (fb.rgba.size() != std::size_t(fb.width) * fb.height || fb.id.size() != fb.rgba.size())
      throw std::invalid_argument("render: framebuffer buffers have the wrong size");
    if (params.depth_buffer && fb.depth.size() != fb.rgba.size())
      throw std::invalid_argument("render: depth-buffer mode needs a framebuffer with a depth buffer");
  }

  void draw(Framebuffer& fb, std::span<const std::uint32_t> tets) {
    check_framebuffer(fb);
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
  void answer_requests(const Framebuffer& fb, int k) {
    Lane& lane = lanes[std::size_t(k)];
    const SaveRegion& region = lane.regions.back();
    for (std::size_t i = region.first_pixel; i < lane.saved_pixel.size(); ++i) {
      const std::uint32_t p = lane.saved_pixel[i];
      if (slot[p] != i) continue;
      const bool was_shown = (shown[std::size_t(p / std::uint32_t(fb.width)) * std::size_t(mask_words) +
                                   ((p % std::uint32_t(fb.width)) >> 6)] >>
                              ((p % std::uint32_t(fb.width)) & 63)) & 1;
      lane.saved_rgba[i] = was_shown ? before_rgba[p] : fb.rgba[p];
      lane.saved_id[i] = was_shown ? before_id[p] : fb.id[p];
      slot[p] = kNone;
    }
    for (std::size_t i = lane.aliases.size(); i-- > 0;) {
      lane.saved_rgba[lane.aliases[i].first] = lane.saved_rgba[lane.aliases[i].second];
      lane.saved_id[lane.aliases[i].first] = lane.saved_id[lane.aliases[i].second];
    }
    lane.aliases.clear();
    std::reverse(lane.saves.begin() + std::ptrdiff_t(region.first_save), lane.saves.end());
  }

  // Painter or depth-buffer drawing of a batch (see draw); the written-pixel mask is all zero before
  // and after, cleared only on the rows the batch could touch (short batches cost what they draw).
  void draw_batch(Framebuffer& fb, std::span<const std::uint32_t> tets) {
    if (tets.empty()) return;
    // Threads pay for themselves only on long batches. Undoable drawing always uses its lanes'
    // partition (saved pixels are kept per lane), on one thread for short batches.
    const int count = recording       ? lane_count
                      : tets.size() < 256 ? 1
                                          : std::min(params.threads, std::max(1, fb.height >> kBandShift));
    const bool spawn = count > 1 && tets.size() >= 256;
    if (reverse && written.empty()) {
      written.assign(std::size_t(mask_words) * std::size_t(fb.height), 0);
      tile_full.assign(std::size_t(mask_words) * std::size_t((fb.height >> kBandShift) + 1), 0);
    }
    boxes.resize(tets.size());
    auto find_boxes = [&](std::size_t begin, std::size_t end) {
      constexpr std::size_t kAhead = 8;
      for (std::size_t i = begin; i < end; ++i) {
        if (i + kAhead < end) prefetch_tet(tets[i + kAhead]);
        if (i + 2 * kAhead < end) __builtin_prefetch(&mesh->tet[4 * std::size_t(tets[i + 2 * kAhead])]);
        if (recording) {  // has_unshared_back_face reads the tet's neighbours and their positions
          if (i + 2 * kAhead < end) __builtin_prefetch(&adjacency->neighbour[4 * std::size_t(tets[i + 2 * kAhead])]);
          if (i + kAhead < end) prefetch_neighbours(tets[i + kAhead]);
        }
        TetCorners k;
        load_corners(tets[i], k);
        boxes[i] = tet_box(k, fb.width, fb.height);
        if (recording) {
          need_save[i] = false;
          batch_reach[i] = 0;
          if (boxes[i].x0 <= boxes[i].x1) need_save[i] = has_unshared_back_face(tets[i], k, batch_reach[i]);
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
    if (!spawn || tets.size() < 4096) {
      find_boxes(0, tets.size());
    } else {
      const std::size_t half = tets.size() / 2;
      run_parts(2, [&](int k) { k == 0 ? find_boxes(0, half) : find_boxes(half, tets.size()); });
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
  PixelRect boxes_union(std::size_t n) const {
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
  void zero_mask(int y0, int y1) {
    const std::size_t words = std::size_t(mask_words);
    std::fill(written.begin() + std::ptrdiff_t(std::size_t(y0) * words),
              written.begin() + std::ptrdiff_t(std::size_t(y1 + 1) * words), 0);
    std::fill(tile_full.begin() + std::ptrdiff_t(std::size_t(y0 >> kBandShift) * words),
              tile_full.begin() + std::ptrdiff_t(std::size_t((y1 >> kBandShift) + 1) * words), 0);
  }

  // Zeroes the written-pixel mask (and while recording, `shown`) on the rows the batch's boxes span;
  // `changed` becomes their union.
  void clear_mask(std::size_t n) {
    changed = boxes_union(n);
    const int y0 = changed.y0, y1 = changed.y1;
    if (y0 > y1) return;
    zero_mask(y0, y1);
    const std::size_t words = std::size_t(mask_words);
    if (recording)  // else all zero
      std::fill(shown.begin() + std::ptrdiff_t(std::size_t(y0) * words),
                shown.begin() + std::ptrdiff_t(std::size_t(y1 + 1) * words), 0);
  }

  // --- Undraw (seed paper, section 6.2) ---
  // A back face of a drawn tet is shared when the tet across it was drawn before it (with unshrunk
  // tets only): in the picture of the tets before t, its pixels show that neighbour's front face.
  std::uint32_t earlier_neighbour(std::uint32_t t, int f) const {
    if (params.shrink != 1) return kNone;
    const std::uint32_t nb = adjacency->neighbour[4 * std::size_t(t) + std::size_t(f)];
    if (nb == kNone || !is_kept(nb >> 2) || drawn_at[nb >> 2] >= drawn_at[t]) return kNone;
    return nb;
  }

  // Calls fn(y, lo, hi) for the pixel runs of a polygon (positive area) in the rows of `rows`, in a
  // fixed order.
  template <class Fn>
  void for_each_run(const PolyVertex* poly, int n, const Rows& rows, Fn&& fn) const {
    for (int q = 1; q + 1 < n; ++q) {
      std::int64_t X[3] = {poly[0].X, poly[q].X, poly[q + 1].X}, Y[3] = {poly[0].Y, poly[q].Y, poly[q + 1].Y};
      std::int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
      if (area <= 0) continue;
      raster_triangle(X, Y, proj.width, proj.height, rows, fn);
    }
  }

  // Calls fn(f, poly, n) for each back face of drawn tet t that covers pixels.
  template <class Fn>
  void for_each_back_face(std::uint32_t t, Fn&& fn) const {
    TetCorners k;
    if (!load_corners(t, k)) return;
    PolyVertex poly[4];
    for (int f = 0; f < 4; ++f) {
      bool clipped = false;
      const int n = face_polygon(k, f, true, poly, &clipped);
      if (n > 0) fn(f, poly, n);
    }
  }

  // Whether drawn tet t has a back face covering pixels that is not shared (see earlier_neighbour);
  // for every tet of an undoable batch, so the facing of an unclipped face is read off the sign of
  // its projected area (as face_polygon does) without building its polygon; k: its corners (finite).
  // reach: t's repaint reach (see drawn_reach).
  bool has_unshared_back_face(std::uint32_t t, const TetCorners& k, std::uint16_t& reach) const {
    bool unshared = false;
    std::uint32_t least = drawn_at[t];
    const bool unclipped = k.st[0] + k.st[1] + k.st[2] + k.st[3] == 0;
    for (int f = 0; f < 4; ++f) {
      bool back;
      if (unclipped) {
        const int a = kFace[f][0], b = kFace[f][1], d = kFace[f][2];
        back = (k.X[b] - k.X[a]) * (k.Y[d] - k.Y[a]) - (k.Y[b] - k.Y[a]) * (k.X[d] - k.X[a]) > 0;
      } else {
        PolyVertex poly[4];
        bool clipped = false;
        back = face_polygon(k, f, true, poly, &clipped) > 0;
      }
      if (!back) continue;
      const std::uint32_t nb = earlier_neighbour(t, f);
      if (nb == kNone)
        unshared = true;
      else
        least = std::min(least, drawn_at[nb >> 2]);
    }
    reach = std::uint16_t(std::min<std::uint32_t>(drawn_at[t] - least, 0xffff));
    return unshared;
  }

  // Files t's save in the lane of `rows`: a request for each pixel of its unshared back faces in
  // those rows (just after t's front faces were walked, which answered the requests of nearer tets
  // on the same pixels).
  void request_saves(const Framebuffer& fb, const Rows& rows, std::uint32_t t) {
    Lane& lane = lanes[std::size_t(rows.thread)];
    std::vector<std::uint32_t>& saved_pixel = lane.saved_pixel;
    lane.saves.push_back(Save{drawn_at[t], saved_pixel.size()});
    for_each_back_face(t, [&](int f, const PolyVertex* poly, int n) {
      if (earlier_neighbour(t, f) != kNone) return;
      for_each_run(poly, n, rows, [&](int y, int lo, int hi) {
        const std::size_t row = std::size_t(y) * std::size_t(fb.width);
        std::uint64_t* done = &written[std::size_t(y) * std::size_t(mask_words)];
        for (int x = lo; x <= hi; ++x) {
          const std::uint32_t k = std::uint32_t(saved_pixel.size()), p = std::uint32_t(row + std::size_t(x));
          if (slot[p] != kNone) lane.aliases.emplace_back(slot[p], k);
          slot[p] = k;
          saved_pixel.push_back(p);
          done[x >> 6] &= ~(std::uint64_t(1) << (x & 63));  // to be walked again
          tile_full[std::size_t(y >> kBandShift) * std::size_t(mask_words) + std::size_t(x >> 6)] = 0;
        }
      });
    });
    lane.saved_rgba.resize(saved_pixel.size());
    lane.saved_id.resize(saved_pixel.size());
  }

  // During undraw, the tet across face f of undrawn tet t if it is kept (unshrunk tets only; the
  // earlier_neighbour of t then), else kNone.
  std::uint32_t kept_neighbour(std::uint32_t t, int f) const {
    if (params.shrink != 1) return kNone;
    const std::uint32_t nb = adjacency->neighbour[4 * std::size_t(t) + std::size_t(f)];
    return nb != kNone && is_kept(nb >> 2) ? nb : kNone;
  }

  // Fills u for undrawn tet t, whose drawn box (tet_box) is not empty and not cut by the near plane
  // (all its corners in front): its corners and its back faces shared with kept tets (see `kept`),
  // which the walk repaints as those tets' front faces (their shades come after, from
  // shade_repainted). A face is back when its outward-ordered projection has positive area
  // (face_polygon's test).
  void gather_undrawn(std::uint32_t t, UndrawTet& u) const {
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
  void shade_repainted(UndrawTet& u) const {
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
  void undraw(Framebuffer& fb, std::size_t count) {
    if (!params.undoable) throw std::logic_error("render: undraw needs RenderParams::undoable");
    check_framebuffer(fb);
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
    if (changed.x0 > changed.x1 || (changed.x0 == 0 && changed.y0 == 0 && changed.x1 == proj.width - 1 &&
                                    changed.y1 == proj.height - 1)) {
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
  void undraw_part(Framebuffer& fb, std::size_t count) {
    if (written.empty()) {
      written.assign(std::size_t(mask_words) * std::size_t(fb.height), 0);
      tile_full.assign(std::size_t(mask_words) * std::size_t((fb.height >> kBandShift) + 1), 0);
    }
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
    std::vector<double> band_work(threads > 1 ? std::size_t((fb.height + (1 << kBandShift) - 1) >> kBandShift) : 0, 0.0);
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
        rect = PixelRect{std::min(rect.x0, b.x0), std::min(rect.y0, b.y0), std::max(rect.x1, b.x1), std::max(rect.y1, b.y1)};
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
      changed = unknown ? PixelRect{0, 0, fb.width - 1, fb.height - 1} : rect.x0 <= rect.x1 ? rect : PixelRect{};
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
        while ((state = unkept.load(std::memory_order_acquire)) == 0) pool::relax();
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
          }
        }
        if (!shows) continue;
        if (b.y0 >= 0) {
          if (!repaints(i)) continue;
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
          continue;
        }
        for_each_back_face(t, [&](int f, const PolyVertex* poly, int n) {  // cut by the near plane
          const std::uint32_t nb = kept_neighbour(t, f);
          if (nb == kNone) return;
          const std::uint32_t* nv = &mesh->tet[4 * std::size_t(nb >> 2)];
          const auto& face = kFace[nb & 3];
          const std::uint32_t node[3] = {nv[face[0]], nv[face[1]], nv[face[2]]};
          const double* v[3] = {cam(node[0]), cam(node[1]), cam(node[2])};
          draw_face(fb, rows, nb >> 2, v, node, poly, n, false);
        });
      }
      // The mask back to zero on the changed rows of these rows (whole bands: their tiles too).
      while (!extent_found.load(std::memory_order_acquire)) pool::relax();  // long since, as a rule
      const int y0 = std::max(rows.lo, changed.y0), y1 = std::min(rows.hi, changed.y1);
      if (y0 <= y1) zero_mask(y0, y1);
    };
    if (threads == 1) {
      work({0, fb.height}, 0);
    } else {
      const std::vector<int> split = split_rows(band_work, threads, fb.height);
      run_parts(threads, [&](int k) { work(split, k); }, [&] { unkept.store(2, std::memory_order_release); });
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
    }
  }

  // Adds box b's undraw work to `work` (per band of 16 rows): its width plus a per-row cost, times its
  // rows, all on the band of its middle row (a box is a few bands tall at most where it matters: the
  // split need only be about even).
  static void add_band_work(std::vector<double>& work, const Box& b) {
    constexpr int kRowCost = 16;  // pixels' worth of per-row setup
    work[std::size_t(((b.y0 + b.y1) >> 1) >> kBandShift)] += double((b.x1 - b.x0 + 1 + kRowCost) * (b.y1 - b.y0 + 1));
  }

  // Row ranges for `parts` threads undrawing, from their work per band (add_band_work; a box cut by
  // the near plane, unknown, counts on none): split[k] to split[k + 1] - 1 for thread k, whole bands
  // of 16 rows (a thread's mask tiles are its own), of about equal work. Contiguous ranges, not
  // interleaved bands: a tet is a few bands tall, and each thread whose rows it touches pays its setup.
  static std::vector<int> split_rows(const std::vector<double>& work, int parts, int height) {
    const int bands = int(work.size());
    double total = 0;
    for (double w : work) total += w;
    std::vector<int> split(std::size_t(parts) + 1, height);
    split[0] = 0;
    double sum = 0;
    int k = 1;
    for (int band = 0; band < bands && k < parts; ++band) {
      sum += work[std::size_t(band)];
      while (k < parts && sum >= total * double(k) / double(parts)) split[std::size_t(k++)] = std::min(height, (band + 1) << kBandShift);
    }
    for (; k < parts; ++k) split[std::size_t(k)] = height;
    return split;
  }

  // Where save s of a lane's pixels end: saves of one draw() call were filed front to back, so in
  // drawing order a save's pixels run up to those of the save before it in the same call.
  static std::size_t save_end(const Lane& lane, std::size_t s) {
    std::size_t r = lane.regions.size();
    while (r > 0 && lane.regions[r - 1].first_save > s) --r;
    const SaveRegion& region = lane.regions[r - 1];
    const std::size_t region_end = r < lane.regions.size() ? lane.regions[r].first_pixel : lane.saved_pixel.size();
    return s > region.first_save ? lane.saves[s - 1].offset : region_end;
  }

  void forget() {
    std::fill(kept.begin(), kept.end(), 0);
    history.clear();
    drawn_box.clear();
    drawn_reach.clear();
    for (Lane& lane : lanes) lane = Lane{};
  }

  std::size_t saved_pixels() const {
    std::size_t n = 0;
    for (const Lane& lane : lanes) n += lane.saved_rgba.size();
    return n;
  }

  std::size_t undo_bytes() const {
    std::size_t bytes = (history.capacity() + drawn_at.capacity() + slot.capacity() + before_rgba.capacity() +
                         before_id.capacity()) *
                            sizeof(std::uint32_t) +
                        (shown.capacity() + written.capacity() + kept.capacity()) * sizeof(std::uint64_t) +
                        drawn_box.capacity() * sizeof(SmallBox) + drawn_reach.capacity() * sizeof(std::uint16_t);
    for (const Lane& lane : lanes)
      bytes += (lane.saved_pixel.capacity() + lane.saved_rgba.capacity() + lane.saved_id.capacity()) *
                   sizeof(std::uint32_t) +
               lane.saves.capacity() * sizeof(Save) + lane.regions.capacity() * sizeof(SaveRegion);
    return bytes;
  }
};

TetRasterizer::TetRasterizer(const Mesh& mesh, const Camera& camera, int width, int height,
                             const RenderParams& params)
    : impl_(std::make_unique<Impl>(mesh, camera, width, height, params)) {}
TetRasterizer::~TetRasterizer() = default;
TetRasterizer::TetRasterizer(TetRasterizer&&) noexcept = default;
TetRasterizer& TetRasterizer::operator=(TetRasterizer&&) noexcept = default;

void TetRasterizer::draw(Framebuffer& fb, std::span<const std::uint32_t> tets) { impl_->draw(fb, tets); }
const RasterStats& TetRasterizer::stats() const { return impl_->stats; }
const Projector& TetRasterizer::projector() const { return impl_->proj; }
double TetRasterizer::near_plane() const { return impl_->near; }
void TetRasterizer::undraw(Framebuffer& fb, std::size_t count) { impl_->undraw(fb, count); }
std::span<const std::uint32_t> TetRasterizer::drawn_tets() const { return impl_->history; }
std::size_t TetRasterizer::saved_pixels() const { return impl_->saved_pixels(); }
std::size_t TetRasterizer::undo_bytes() const { return impl_->undo_bytes(); }
PixelRect TetRasterizer::changed_rect() const { return impl_->changed; }
std::span<const PixelRect> TetRasterizer::changed_rects() const { return impl_->changed_list; }
void TetRasterizer::forget_drawn() { impl_->forget(); }

Framebuffer render_tets(const Mesh& mesh, const Camera& camera, int width, int height,
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
