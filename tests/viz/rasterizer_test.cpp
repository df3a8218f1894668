// The painter against independent oracles: its own depth-buffer mode (painter image == depth-buffer
// image for a visibility order), brute-force ray casting (the tet a pixel shows is the first one its
// ray enters), exact coverage counts of triangle fans (fill rule), hole-free silhouettes of closed
// meshes, progressive stops equal to drawing a prefix of the order, and PNG round trips.
#include "foxi/viz/rasterizer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 160, kH = 120;

std::vector<Camera> random_cameras(const Mesh& m, int n, unsigned seed) {
  return test::random_cameras(m, n, seed, double(kW) / kH);
}

// Distance in pixels from (x, y) to the segment a-b.
double seg_dist(double x, double y, const double a[2], const double b[2]) {
  double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / l2, 0.0, 1.0) : 0;
  return std::hypot(x - a[0] - t * dx, y - a[1] - t * dy);
}

// True if the pixel centre lies exactly on the projection of an edge of tet t, as snapped to the
// rasterizer's fixed point (camera frame, shrink about the centroid there, x 256, rounded): the only
// place where front faces of two tets meet at equal depth, so painter and depth buffer may pick
// either. Edges cut by the near plane count when the centre is within 0.02 pixel of the cut edge.
// With tol > 0: within tol pixels of any projected edge instead (unsnapped geometry).
bool on_projected_edge(const Mesh& m, const Projector& p, double near, std::uint32_t t, int x, int y,
                       double shrink = 1, double tol = 0) {
  if (t == kNone) return false;
  double c[4][3], g[3] = {0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    p.to_camera(&m.xyz[3 * std::size_t(m.tet[4 * std::size_t(t) + k])], c[k]);
    for (int j = 0; j < 3; ++j) g[j] += 0.25 * c[k][j];
  }
  if (shrink != 1)
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) c[k][j] = g[j] + shrink * (c[k][j] - g[j]);
  const std::int64_t qx = x * 256 + 128, qy = y * 256 + 128;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b) {
      const bool ina = !p.perspective || c[a][2] >= near, inb = !p.perspective || c[b][2] >= near;
      if (!ina && !inb) continue;
      double pa[2], pb[2];
      if (ina && inb) {
        p.camera_to_pixel(c[a], pa);
        p.camera_to_pixel(c[b], pb);
        if (tol > 0) {
          if (seg_dist(x + 0.5, y + 0.5, pa, pb) < tol) return true;
          continue;
        }
        const std::int64_t ax = std::llround(pa[0] * 256), ay = std::llround(pa[1] * 256);
        const std::int64_t bx = std::llround(pb[0] * 256), by = std::llround(pb[1] * 256);
        if ((bx - ax) * (qy - ay) - (by - ay) * (qx - ax) == 0 && std::min(ax, bx) <= qx &&
            qx <= std::max(ax, bx) && std::min(ay, by) <= qy && qy <= std::max(ay, by))
          return true;
        continue;
      }
      const double* in = ina ? c[a] : c[b];
      const double* out = ina ? c[b] : c[a];
      const double s = (near - in[2]) / (out[2] - in[2]);
      const double cut[3] = {in[0] + s * (out[0] - in[0]), in[1] + s * (out[1] - in[1]), near};
      p.camera_to_pixel(in, pa);
      p.camera_to_pixel(cut, pb);
      if (seg_dist(x + 0.5, y + 0.5, pa, pb) < 0.02) return true;
    }
  return false;
}

// Brute-force ray casting, independent of the rasterizer: the ray through the centre of pixel (x, y)
// enters tets (of `subset`, all if empty; shrunk about their centroids) at depths t; a tet shows
// where the ray enters it through a front face beyond the near plane (a tet holding the eye, or
// entered before the near plane, shows nothing there). Returns the first such tet (kNone if none),
// its entry depth and the next entry depth.
std::uint32_t cast_ray(const Mesh& m, const Projector& p, double near, int x, int y,
                       std::span<const std::uint32_t> subset, double shrink, double* best, double* second) {
  static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  const double a = (x + 0.5 - p.cx), b = -(y + 0.5 - p.cy);
  double o[3], d[3];
  for (int k = 0; k < 3; ++k) {
    if (p.perspective) {
      o[k] = p.eye[k];
      d[k] = p.forward[k] + (a * p.right[k] + b * p.up[k]) / p.focal;
    } else {
      o[k] = p.eye[k] + (a * p.right[k] + b * p.up[k]) / p.scale;
      d[k] = p.forward[k];
    }
  }
  // Depth along forward is t, since d . forward = 1.
  const double tmin = p.perspective ? near : -1e300;
  *best = *second = 1e300;
  std::uint32_t best_tet = kNone;
  const std::size_t count = subset.empty() ? m.tet_count() : subset.size();
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t t = subset.empty() ? std::uint32_t(i) : subset[i];
    double q[4][3], g[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) {
        q[k][j] = m.xyz[3 * std::size_t(m.tet[4 * std::size_t(t) + k]) + j];
        g[j] += 0.25 * q[k][j];
      }
    if (shrink != 1)
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j) q[k][j] = g[j] + shrink * (q[k][j] - g[j]);
    double t0 = -1e300, t1 = 1e300;
    for (const auto& f : face) {
      const double* A = q[f[0]];
      const double* B = q[f[1]];
      const double* C = q[f[2]];
      double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]}, w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
      double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      double num = -(n[0] * (o[0] - A[0]) + n[1] * (o[1] - A[1]) + n[2] * (o[2] - A[2]));
      double den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
      if (den > 0)
        t1 = std::min(t1, num / den);
      else if (den < 0)
        t0 = std::max(t0, num / den);
      else if (num < 0)
        t1 = -1e300;
    }
    if (t1 <= t0 || t0 < tmin) continue;
    if (t0 < *best) {
      *second = *best;
      *best = t0;
      best_tet = t;
    } else if (t0 < *second) {
      *second = t0;
    }
  }
  return best_tet;
}

struct Diff {
  std::size_t differing = 0;  // pixels whose colour or tet differ
  std::size_t ties = 0;       // of those, pixels exactly on a projected edge of either tet (depth ties)
  std::size_t grazing = 0;    // of those, pixels where exact ray casting agrees with `a` and the next
                              // layer is within 1e-4 (relative) of its depth: the depth buffer
                              // interpolates depth from snapped vertices, off by up to 1/512 pixel
                              // times the depth slope
};

Diff compare(const Mesh& m, const Camera& cam, const Framebuffer& a, const Framebuffer& b, double shrink = 1,
             std::span<const std::uint32_t> subset = {}) {
  Diff d;
  const TetRasterizer r(m, cam, a.width, a.height);
  const Projector& p = r.projector();
  const double near = r.near_plane();
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      std::size_t i = a.index(x, y);
      if (a.rgba[i] == b.rgba[i] && a.id[i] == b.id[i]) continue;
      ++d.differing;
      if (on_projected_edge(m, p, near, a.id[i], x, y, shrink) ||
          on_projected_edge(m, p, near, b.id[i], x, y, shrink))
        ++d.ties;
      else {
        double first = 0, next = 0;
        const std::uint32_t shown = cast_ray(m, p, near, x, y, subset, shrink, &first, &next);
        if (shown == a.id[i] && std::abs(next - first) <= 1e-4 * std::abs(first)) ++d.grazing;
      }
    }
  return d;
}

// Painter (visibility order) vs depth buffer for every camera; returns the differing pixels (ties and
// grazing ones; every differing pixel must be one of them, and there must be very few).
Diff check_painter_equals_zbuffer(const Mesh& m, const std::vector<Camera>& cams,
                                  std::span<const std::uint32_t> subset = {}, double shrink = 1) {
  const SphereTable table = compute_spheres(m);
  Diff total;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < cams.size(); ++i) {
    const auto order = visibility_order(m, table, view_of(cams[i]), subset);
    RenderParams pp;
    pp.shrink = shrink;
    RenderParams zp = pp;
    zp.depth_buffer = true;
    Framebuffer painter = render_tets(m, cams[i], kW, kH, order, pp);
    std::vector<std::uint32_t> shuffled(order.begin(), order.end());
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(unsigned(i)));
    Framebuffer zbuf = render_tets(m, cams[i], kW, kH, shuffled, zp);
    Diff d = compare(m, cams[i], painter, zbuf, shrink, subset);
    EXPECT_EQ(d.differing, d.ties + d.grazing) << "view " << i << ": " << d.differing - d.ties - d.grazing
                                               << " pixels differ, neither ties nor grazing";
    total.differing += d.differing;
    total.ties += d.ties;
    total.grazing += d.grazing;
    for (std::uint32_t id : painter.id) covered += id != kNone;
  }
  EXPECT_GT(covered, cams.size() * kW * kH / 20) << "the views should show the mesh";
  EXPECT_LE(total.differing, covered / 10000 + 10) << "too many differing pixels";
  return total;
}

void report(const char* what, const Diff& d, std::size_t views) {
  std::printf("%s: %zu differing pixels over %zu views (%zu exact edge ties, %zu grazing)\n", what,
              d.differing, views, d.ties, d.grazing);
}

TEST(Rasterizer, PainterEqualsDepthBufferOnRandomDelaunay) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 800, 11);
  report("random Delaunay", check_painter_equals_zbuffer(m, random_cameras(m, 60, 3)), 60);
}

TEST(Rasterizer, PainterEqualsDepthBufferOnGrids) {
  for (int tets_per_cell : {5, 6}) {
    Mesh m = test::grid_mesh(5, 4, 3, 1.0, 1.3, 0.9, tets_per_cell);
    report(tets_per_cell == 5 ? "grid, 5 tets per cell" : "grid, 6 tets per cell",
           check_painter_equals_zbuffer(m, random_cameras(m, 30, 5 + tets_per_cell)), 30);
  }
}

TEST(Rasterizer, PainterEqualsDepthBufferOnNonConvexSubsetsAndRegions) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 1000, 21, 2, 1, 1);
  // Regions by position (multi-material).
  test::regions_along_x(m, 0.7, 1.3);
  std::mt19937 rng(4);
  std::vector<std::uint32_t> subset;
  for (std::uint32_t t = 0; t < m.tet_count(); ++t)
    if (rng() % 10 < 4) subset.push_back(t);
  report("random 40% of a 3-region mesh", check_painter_equals_zbuffer(m, random_cameras(m, 30, 8), subset),
         30);
  // Shrunk tets (gaps between them) keep the equality.
  report("shrink 0.8", check_painter_equals_zbuffer(m, random_cameras(m, 15, 9), {}, 0.8), 15);
}

// Brute-force ray casting, independent of the rasterizer: the ray through a pixel centre enters
// tets at parameters t; the first entered (smallest t beyond the near plane) is what the pixel shows.
TEST(Rasterizer, IdBufferMatchesRayCasting) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 300, 31);
  const SphereTable table = compute_spheres(m);
  std::mt19937 rng(2);
  std::size_t checked = 0, ambiguous = 0;
  for (const Camera& cam : random_cameras(m, 9, 17)) {
    TetRasterizer r(m, cam, kW, kH);
    Framebuffer fb(kW, kH);
    r.draw(fb, visibility_order(m, table, view_of(cam)));
    const Projector& p = r.projector();
    for (int s = 0; s < 300; ++s) {
      const int x = int(rng() % kW), y = int(rng() % kH);
      double best = 0, second = 0;
      const std::uint32_t best_tet = cast_ray(m, p, r.near_plane(), x, y, {}, 1, &best, &second);
      const std::uint32_t shown = fb.id[fb.index(x, y)];
      // Rays within snapping distance of an edge may see either tet: skip those (counted).
      if (on_projected_edge(m, p, r.near_plane(), shown, x, y, 1, 0.01) ||
          on_projected_edge(m, p, r.near_plane(), best_tet, x, y, 1, 0.01) ||
          (best_tet != kNone && std::abs(best - second) < 1e-9 * std::abs(best))) {
        ++ambiguous;
        continue;
      }
      ++checked;
      EXPECT_EQ(shown, best_tet) << "pixel " << x << "," << y << " entry " << best << " next " << second;
    }
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_LT(ambiguous, checked / 20);
}

// Fans of triangles around a centre (a star-shaped polygon), vertices often exactly on pixel centres:
// every pixel centre inside the polygon (its interior, shared edges included) is covered exactly once,
// none outside it; a triangle covers the same pixels in either winding.
TEST(Rasterizer, FillRuleCoversFansExactlyOnce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const int W = 40, H = 40;
  for (int trial = 0; trial < 400; ++trial) {
    auto snap = [&](double v) {  // every other vertex on a pixel centre or a pixel corner
      std::int64_t f = std::int64_t(std::llround(v * 256));
      if (trial % 3 == 0) f = (f / 256) * 256 + 128;
      if (trial % 3 == 1) f = (f / 256) * 256;
      return f;
    };
    const std::int64_t cx = snap(10 + 20 * u(rng)), cy = snap(10 + 20 * u(rng));
    const int n = 3 + int(rng() % 8);
    std::vector<std::int64_t> px(n), py(n);
    const double phase = 6.283185307179586 * u(rng);
    for (int i = 0; i < n; ++i) {
      double ang = phase + 6.283185307179586 * (i + 0.8 * u(rng)) / n, rad = 3 + 12 * u(rng);
      px[i] = snap(double(cx) / 256.0 + rad * std::cos(ang));
      py[i] = snap(double(cy) / 256.0 + rad * std::sin(ang));
    }
    std::vector<int> count(W * H, 0);
    bool valid = true;
    auto cross = [](std::int64_t ax, std::int64_t ay, std::int64_t bx, std::int64_t by, std::int64_t qx,
                    std::int64_t qy) { return (bx - ax) * (qy - ay) - (by - ay) * (qx - ax); };
    for (int i = 0; i < n; ++i) {
      const int j = (i + 1) % n;
      std::int64_t X[3] = {cx, px[i], px[j]}, Y[3] = {cy, py[i], py[j]};
      if (cross(X[0], Y[0], X[1], Y[1], X[2], Y[2]) == 0) valid = false;
      auto cov = triangle_coverage(X, Y, W, H);
      std::int64_t X2[3] = {cx, px[j], px[i]}, Y2[3] = {cy, py[j], py[i]};
      EXPECT_EQ(cov, triangle_coverage(X2, Y2, W, H)) << "winding changes coverage";
      for (std::uint32_t p : cov) ++count[p];
    }
    for (int i = 0; i < n; ++i) {  // a star-shaped fan: every triangle turns the same way
      const int j = (i + 1) % n;
      const std::int64_t a0 = cross(cx, cy, px[0], py[0], px[1], py[1]),
                         ai = cross(cx, cy, px[i], py[i], px[j], py[j]);
      if ((a0 > 0) != (ai > 0)) valid = false;
    }
    if (!valid) continue;
    // Oracle, exact integers: on an outer edge -> either; inside a (closed) fan triangle -> 1; else 0.
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::int64_t qx = x * 256 + 128, qy = y * 256 + 128;
        bool on_outer = false, inside = false;
        for (int i = 0; i < n; ++i) {
          const int j = (i + 1) % n;
          std::int64_t e = cross(px[i], py[i], px[j], py[j], qx, qy);
          if (e == 0 && std::min(px[i], px[j]) <= qx && qx <= std::max(px[i], px[j]) &&
              std::min(py[i], py[j]) <= qy && qy <= std::max(py[i], py[j]))
            on_outer = true;
          std::int64_t area = cross(cx, cy, px[i], py[i], px[j], py[j]);
          std::int64_t s = area > 0 ? 1 : -1;
          if (s * cross(cx, cy, px[i], py[i], qx, qy) >= 0 &&
              s * cross(px[i], py[i], px[j], py[j], qx, qy) >= 0 &&
              s * cross(px[j], py[j], cx, cy, qx, qy) >= 0)
            inside = true;
        }
        const int c = count[y * W + x];
        if (on_outer)
          EXPECT_LE(c, 1) << "trial " << trial << " pixel " << x << "," << y;
        else
          EXPECT_EQ(c, inside ? 1 : 0) << "trial " << trial << " pixel " << x << "," << y;
      }
  }
}

// A closed mesh's front faces leave no hole: every background pixel connects to the image border
// through background pixels (flood fill). Also with the eye inside (clipped faces).
TEST(Rasterizer, ClosedMeshSilhouetteHasNoHoles) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 600, 41);
  const SphereTable table = compute_spheres(m);
  for (const Camera& cam : random_cameras(m, 12, 23)) {
    RenderParams params;
    params.edges = false;
    Framebuffer fb = render_tets(m, cam, kW, kH, visibility_order(m, table, view_of(cam)), params);
    std::vector<std::uint8_t> seen(fb.id.size(), 0);
    std::vector<int> stack;
    auto push = [&](int x, int y) {
      if (x < 0 || y < 0 || x >= kW || y >= kH) return;
      std::size_t i = fb.index(x, y);
      if (seen[i] || fb.id[i] != kNone) return;
      seen[i] = 1;
      stack.push_back(int(i));
    };
    for (int x = 0; x < kW; ++x) push(x, 0), push(x, kH - 1);
    for (int y = 0; y < kH; ++y) push(0, y), push(kW - 1, y);
    while (!stack.empty()) {
      int i = stack.back();
      stack.pop_back();
      int x = i % kW, y = i / kW;
      push(x + 1, y), push(x - 1, y), push(x, y + 1), push(x, y - 1);
    }
    std::size_t holes = 0;
    for (std::size_t i = 0; i < fb.id.size(); ++i) holes += fb.id[i] == kNone && !seen[i];
    EXPECT_EQ(holes, 0u);
  }
}

// Stopping after 40% of the progressive order equals drawing exactly the first 40% of the whole
// order, and also the depth-buffer picture of those tets (a prefix of a visibility order is one).
TEST(Rasterizer, ProgressiveStopEqualsPrefix) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 1500, 51);
  const SphereTable table = compute_spheres(m);
  for (const Camera& cam : random_cameras(m, 6, 29)) {
    const View view = view_of(cam);
    const auto order = visibility_order(m, table, view);
    const std::size_t k = order.size() * 40 / 100;
    TetRasterizer r(m, cam, kW, kH);
    Framebuffer progressive(kW, kH);
    ProgressiveOrder po(m, table, view);
    std::size_t drawn = 0, batches = 0;
    for (auto batch = po.next(); !batch.empty() && drawn < k; batch = po.next()) {
      auto part = batch.first(std::min(batch.size(), k - drawn));
      r.draw(progressive, part);
      drawn += part.size();
      ++batches;
    }
    ASSERT_EQ(drawn, k);
    Framebuffer prefix = render_tets(m, cam, kW, kH, std::span<const std::uint32_t>(order).first(k));
    Diff d = compare(m, cam, progressive, prefix);
    EXPECT_EQ(d.differing, 0u) << batches << " batches";
    RenderParams zp;
    zp.depth_buffer = true;
    Framebuffer z = render_tets(m, cam, kW, kH, std::span<const std::uint32_t>(order).first(k), zp);
    d = compare(m, cam, prefix, z, 1, std::span<const std::uint32_t>(order).first(k));
    EXPECT_EQ(d.differing, d.ties + d.grazing);
  }
}

TEST(Rasterizer, ThreadsDoNotChangeThePicture) {
  Mesh m = test::grid_mesh(6, 6, 6, 1, 1, 1, 6);
  const SphereTable table = compute_spheres(m);
  for (const Camera& cam : random_cameras(m, 6, 37)) {
    const auto order = visibility_order(m, table, view_of(cam));
    RenderParams one, three;
    one.threads = 1;
    three.threads = 3;
    Framebuffer a = render_tets(m, cam, kW, kH, order, one), b = render_tets(m, cam, kW, kH, order);
    Framebuffer c = render_tets(m, cam, kW, kH, order, three);
    EXPECT_EQ(a.rgba, b.rgba);
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.rgba, c.rgba);
  }
}

// Painter mode is "later overwrites earlier" for ANY order, not only visibility orders (it draws each
// batch front to back into a written-pixel mask, which must not change that): a shuffled order with
// repeats, in one batch or several, equals overlaying the tets' single-tet pictures one by one.
TEST(Rasterizer, PainterIsLastWriteWinsForAnyOrder) {
  Mesh m = test::grid_mesh(3, 3, 3, 1, 1, 1, 5);
  std::mt19937 rng(61);
  std::vector<std::uint32_t> order(m.tet_count());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = std::uint32_t(i);
  for (int i = 0; i < 40; ++i) order.push_back(std::uint32_t(rng() % m.tet_count()));
  std::shuffle(order.begin(), order.end(), rng);
  for (const Camera& cam : random_cameras(m, 6, 67)) {
    for (double shrink : {1.0, 0.7}) {
      RenderParams p;
      p.shrink = shrink;
      Framebuffer expect(kW, kH);
      for (std::uint32_t t : order) {
        const Framebuffer one = render_tets(m, cam, kW, kH, std::span<const std::uint32_t>(&t, 1), p);
        for (std::size_t i = 0; i < one.id.size(); ++i) {
          if (one.id[i] == kNone) continue;
          expect.rgba[i] = one.rgba[i];
          expect.id[i] = one.id[i];
        }
      }
      const Framebuffer whole = render_tets(m, cam, kW, kH, order, p);
      EXPECT_EQ(whole.rgba, expect.rgba);
      EXPECT_EQ(whole.id, expect.id);
      TetRasterizer r(m, cam, kW, kH, p);
      Framebuffer batches(kW, kH);
      for (std::size_t s = 0; s < order.size(); s += 37)
        r.draw(batches,
               std::span<const std::uint32_t>(order).subspan(s, std::min<std::size_t>(37, order.size() - s)));
      EXPECT_EQ(batches.rgba, expect.rgba);
      EXPECT_EQ(batches.id, expect.id);
    }
  }
}

// Edges are drawn inside the faces: turning them off changes colours but never which tet a pixel shows.
TEST(Rasterizer, EdgesStayInsideFaces) {
  Mesh m = test::grid_mesh(4, 4, 4, 1, 1, 1, 5);
  const SphereTable table = compute_spheres(m);
  for (const Camera& cam : random_cameras(m, 3, 43)) {
    const auto order = visibility_order(m, table, view_of(cam));
    RenderParams plain;
    plain.edges = false;
    Framebuffer a = render_tets(m, cam, kW, kH, order), b = render_tets(m, cam, kW, kH, order, plain);
    EXPECT_EQ(a.id, b.id);
    EXPECT_NE(a.rgba, b.rgba);
  }
}

TEST(Rasterizer, BadInputIsRejected) {
  Mesh m = test::grid_mesh(1, 1, 1, 1, 1, 1, 5);
  Camera cam;
  cam.eye[0] = 3;
  cam.eye[1] = -4;
  cam.eye[2] = 2;
  TetRasterizer r(m, cam, 20, 10);
  Framebuffer small(10, 10), ok(20, 10);
  const std::uint32_t bad[1] = {99};
  EXPECT_THROW(r.draw(small, {}), std::invalid_argument);
  EXPECT_THROW(r.draw(ok, bad), std::out_of_range);
  RenderParams z;
  z.depth_buffer = true;
  TetRasterizer rz(m, cam, 20, 10, z);
  EXPECT_THROW(rz.draw(ok, {}), std::invalid_argument);  // no depth buffer
  RenderParams s;
  s.shrink = 0;
  EXPECT_THROW(TetRasterizer(m, cam, 20, 10, s), std::invalid_argument);
}

TEST(Png, RoundTrip) {
  test::TempDir dir;
  Framebuffer fb(7, 5);
  for (std::size_t i = 0; i < fb.rgba.size(); ++i)
    fb.rgba[i] = pack_rgba(std::uint32_t(i * 37), std::uint32_t(i * 11), std::uint32_t(255 - i),
                           std::uint32_t(100 + i));
  write_png(dir / "a.png", fb);
  Framebuffer back = read_png(dir / "a.png");
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgba, fb.rgba);
  EXPECT_THROW(write_png(dir / "missing-dir" / "a.png", fb), std::runtime_error);
  EXPECT_THROW(read_png(dir / "nothing.png"), std::runtime_error);
}

}  // namespace
}  // namespace foxi
