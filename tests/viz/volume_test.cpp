// Volume rendering (volume.hpp) against a brute-force ray caster written here: for every pixel, the
// ray's exact intersection with every tet of the drawn set (the ray clipped against the tet's four
// planes in double), the segments sorted by depth, the field at their ends from barycentric
// coordinates, and the emission-absorption integral of each in 256 steps, blended far to near. The
// painter (power order, its own step rule) must agree within 2/255 per channel on random
// Delaunay meshes, the degenerate Kuhn grid, a non-convex subset, eyes inside the mesh and orthographic
// views; a centroid order instead differs on many pixels.
#include "foxi/viz/volume.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <random>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "mesh_factory.hpp"
#include "pixel_ray.hpp"
#include "random_cameras.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr int kW = 80, kH = 60;
// Under AddressSanitizer (CI's second pass) each check takes a third of its cameras: the same code
// paths, a third of the brute-force rays (the four checks took over 3 of the pass's 15.5 minutes).
#if defined(__SANITIZE_ADDRESS__)
constexpr int kCameraShare = 3;
#else
constexpr int kCameraShare = 1;
#endif

std::vector<double> smooth_field(const Mesh& m) {
  std::vector<double> corner(m.tet.size());
  for (std::size_t i = 0; i < corner.size(); ++i) {
    const double* x = &m.xyz[3 * std::size_t(m.tet[i])];
    corner[i] = x[0] + 0.4 * std::sin(5 * x[1]) + 0.3 * x[2] * x[2];
  }
  return corner;
}

VolumeParams params_for(const Mesh& m, double light = 1) {
  VolumeParams p;
  p.scale.lo = -0.4;
  p.scale.hi = 1.7;
  p.opacity_curve = {{-0.4, 0.1}, {0.5, 0.7}, {0.9, 0.2}, {1.7, 0.8}};
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  p.unit_length =
      light * (hi[0] - lo[0]) / 25;  // dense: a tet's segment is strongly opaque, so the order shows
  return p;
}

// The ray caster: the picture of the tets `set` as the volume-rendering integral along each pixel's ray
// (a W x H picture; where `cast` is given, only the pixels it marks, the others white). `opaque`: a
// medium so dense that only where the ray enters it shows: each pixel the colour of the value there.
Framebuffer ray_cast(const Mesh& m, const Camera& cam, std::span<const std::uint32_t> set,
                     std::span<const double> corner, const VolumeParams& p, int W = kW, int H = kH,
                     const std::vector<char>* cast = nullptr, bool opaque = false) {
  const Projector proj(cam, W, H);
  std::vector<std::array<double, 12>> P(set.size());  // camera coordinates of the corners
  for (std::size_t i = 0; i < set.size(); ++i)
    for (int k = 0; k < 4; ++k)
      proj.to_camera(&m.xyz[3 * std::size_t(m.tet[4 * std::size_t(set[i]) + std::size_t(k)])],
                     &P[i][3 * std::size_t(k)]);
  Framebuffer fb(W, H);
  struct Seg {
    double s0, s1, v0, v1;
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (cast && !(*cast)[fb.index(x, y)]) continue;
      double o[3], d[3];
      test::pixel_ray(proj, x, y, o, d);
      std::vector<Seg> segs;
      for (std::size_t i = 0; i < set.size(); ++i) {
        const double* c = P[i].data();
        double s0 = proj.perspective ? std::max(p.near, 0.0) : -1e300, s1 = 1e300;  // from the near plane
        bool empty = false;
        for (int f = 0; f < 4 && !empty; ++f) {
          // The plane through the three corners other than f; inside is f's side.
          int q[3], nq = 0;
          for (int k = 0; k < 4; ++k)
            if (k != f) q[nq++] = k;
          const double* a = c + 3 * q[0];
          const double* b = c + 3 * q[1];
          const double* e = c + 3 * q[2];
          const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                       w[3] = {e[0] - a[0], e[1] - a[1], e[2] - a[2]};
          double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
          const double* pf = c + 3 * f;
          if (n[0] * (pf[0] - a[0]) + n[1] * (pf[1] - a[1]) + n[2] * (pf[2] - a[2]) < 0)
            for (double& t : n) t = -t;  // n points inside
          // inside: n . (o + s d - a) >= 0
          const double base = n[0] * (o[0] - a[0]) + n[1] * (o[1] - a[1]) + n[2] * (o[2] - a[2]);
          const double slope = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
          if (slope == 0) {
            empty = base < 0;
          } else if (slope > 0) {
            s0 = std::max(s0, -base / slope);
          } else {
            s1 = std::min(s1, -base / slope);
          }
        }
        if (empty || !(s1 > s0)) continue;
        // The field at a point: barycentric coordinates (volume ratios).
        auto value = [&](double s) {
          const double pt[3] = {o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]};
          auto vol = [](const double* a, const double* b, const double* cc, const double* dd) {
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                         v[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]},
                         w[3] = {dd[0] - a[0], dd[1] - a[1], dd[2] - a[2]};
            return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                   u[2] * (v[0] * w[1] - v[1] * w[0]);
          };
          const double* q0 = c;
          const double* q1 = c + 3;
          const double* q2 = c + 6;
          const double* q3 = c + 9;
          const double total = vol(q0, q1, q2, q3);
          const double l[4] = {vol(pt, q1, q2, q3) / total, vol(q0, pt, q2, q3) / total,
                               vol(q0, q1, pt, q3) / total, vol(q0, q1, q2, pt) / total};
          double v = 0;
          for (int k = 0; k < 4; ++k) v += l[k] * corner[4 * std::size_t(set[i]) + std::size_t(k)];
          return v;
        };
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        segs.push_back({s0 * len, s1 * len, value(s0), value(s1)});
      }
      std::sort(segs.begin(), segs.end(), [](const Seg& a, const Seg& b) { return a.s0 > b.s0; });
      double col[3] = {255, 255, 255};
      if (opaque && !segs.empty()) {
        const std::uint32_t rgb = p.scale.color(segs.back().v0);
        for (int j = 0; j < 3; ++j) col[j] = double((rgb >> (8 * j)) & 255u);
        segs.clear();
      }
      for (const Seg& sg : segs) {
        const int steps = 256;
        const double dl = (sg.s1 - sg.s0) / steps;
        for (int k = 0; k < steps; ++k) {  // far end first
          const double v = sg.v1 + (k + 0.5) / steps * (sg.v0 - sg.v1);
          const double a = 1 - std::exp(-volume_extinction(p, v) * dl);
          const std::uint32_t rgb = p.scale.color(v);
          for (int j = 0; j < 3; ++j) col[j] = double((rgb >> (8 * j)) & 255u) * a + col[j] * (1 - a);
        }
      }
      fb.rgba[fb.index(x, y)] =
          pack_rgba(std::uint32_t(col[0] + 0.5), std::uint32_t(col[1] + 0.5), std::uint32_t(col[2] + 0.5));
    }
  return fb;
}

Framebuffer paint(const Mesh& m, const Camera& cam, std::span<const std::uint32_t> order,
                  std::span<const double> corner, const VolumeParams& p, std::size_t* samples = nullptr,
                  std::size_t* pre_integrated = nullptr, int W = kW, int H = kH) {
  VolumePainter painter(m, cam, W, H, corner, p);
  const std::size_t half = order.size() / 2;
  painter.draw(order.first(half));  // progressive: two batches
  painter.draw(order.subspan(half));
  if (samples) *samples += painter.samples();
  if (pre_integrated) *pre_integrated += painter.pre_integrated();
  Framebuffer fb;
  painter.resolve(fb);
  return fb;
}

// Pixels where a channel differs by more than `tol`, and the largest difference.
std::size_t differing(const Framebuffer& a, const Framebuffer& b, int tol, int* worst) {
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.rgba.size(); ++p) {
    int d = 0;
    for (int k = 0; k < 3; ++k)
      d = std::max(d, std::abs(int((a.rgba[p] >> (8 * k)) & 255u) - int((b.rgba[p] >> (8 * k)) & 255u)));
    if (worst) *worst = std::max(*worst, d);
    n += d > tol;
  }
  return n;
}

// light: the unit length times this (light > 1: most segments are thin enough for the closed form,
// and the order matters less, so the centroid order is not required to differ).
void check(const Mesh& m, std::span<const std::uint32_t> subset, int cameras, unsigned seed, const char* what,
           double light = 1) {
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = smooth_field(m);
  const VolumeParams p = params_for(m, light);
  std::vector<std::uint32_t> set(subset.begin(), subset.end());
  if (set.empty())
    for (std::uint32_t t = 0; t < m.tet_count(); ++t) set.push_back(t);
  std::size_t power_bad = 0, centroid_bad = 0, covered = 0, samples = 0, pre = 0;
  int worst = 0;
  cameras = std::max(2, cameras / kCameraShare);
  for (const Camera& cam : test::random_cameras(m, cameras, seed, double(kW) / kH)) {
    const Framebuffer want = ray_cast(m, cam, set, corner, p);
    for (std::uint32_t c : want.rgba) covered += c != pack_rgba(255, 255, 255);
    power_bad +=
        differing(paint(m, cam, visibility_order(m, table, view_of(cam), set), corner, p, &samples, &pre),
                  want, 2, &worst);
    centroid_bad +=
        differing(paint(m, cam, centroid_order(m, view_of(cam), set), corner, p), want, 2, nullptr);
  }
  std::printf(
      "%s: %zu pixels covered; power order: %zu differ by more than 2/255 (worst %d; %zu of %zu segments "
      "pre-integrated); centroid order: %zu\n",
      what, covered, power_bad, worst, pre, samples, centroid_bad);
  EXPECT_GT(covered, std::size_t(cameras) * kW * kH / 4) << what;
  EXPECT_EQ(power_bad, 0u) << what;
  if (light == 1) {
    EXPECT_GT(centroid_bad, 10u) << what << ": the order should matter";
  } else {
    EXPECT_GT(pre, samples / 2) << what << ": the closed form should be tested";
  }
}

TEST(Volume, RandomDelaunayMatchesTheRayCaster) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 200, 3);
  ASSERT_TRUE(delaunay_certificate(m).delaunay);
  check(m, {}, 6, 61, "random Delaunay");
}

// A light transfer function on a finer mesh: most segments take the pre-integrated closed form
// (volume.cpp's integrate_fast), which must agree with the ray caster's 256 steps as well.
TEST(Volume, PreIntegratedSegmentsMatchTheRayCaster) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 400, 8);
  check(m, {}, 4, 64, "light, pre-integrated", 8);
}

// An opacity length of a billionth of the mesh: every segment is thousands of e-folds deep, and each
// pixel shows the colour of the value where its ray enters the mesh. (Stepping such segments through
// (a segment's 64 pieces of 256 steps each) took minutes a picture: volume_transfer.cpp's
// integrate_fast integrates only the near part whose depth matters.)
TEST(Volume, OpticallyDeepVolumeShowsWhereTheRaysEnter) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 300, 5);
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = smooth_field(m);
  VolumeParams p = params_for(m);
  p.unit_length *= 1e-9;
  std::vector<std::uint32_t> all(m.tet_count());
  for (std::uint32_t t = 0; t < all.size(); ++t) all[t] = t;
  std::size_t bad = 0, covered = 0;
  int worst = 0;
  for (const Camera& cam : test::random_cameras(m, 3, 91, double(kW) / kH)) {
    const Framebuffer want = ray_cast(m, cam, all, corner, p, kW, kH, nullptr, true);
    for (std::uint32_t c : want.rgba) covered += c != pack_rgba(255, 255, 255);
    // A pixel whose entry value lies within a hair of a colour map entry's edge may take the next
    // entry (the painter's value there is a float's): a few in a thousand at most.
    bad +=
        differing(paint(m, cam, visibility_order(m, table, view_of(cam), all), corner, p), want, 2, &worst);
  }
  std::printf("optically deep: %zu pixels covered, %zu differ by more than 2/255 (worst %d)\n", covered, bad,
              worst);
  EXPECT_GT(covered, std::size_t(3) * kW * kH / 4);
  EXPECT_LE(bad, covered / 300);
}

// The picture does not depend on the values' scale: a field, its colour range and its opacity curve
// all times 1e300 (beyond what the vector path's float holds: such a picture takes the portable path)
// or times 1e-20 give the picture of the unscaled ones (a field of 1e300 once drew nothing).
TEST(Volume, ValuesScaledBeyondFloatGiveTheSamePicture) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 200, 9);
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = smooth_field(m);
  const VolumeParams p = params_for(m);
  std::vector<std::uint32_t> all(m.tet_count());
  for (std::uint32_t t = 0; t < all.size(); ++t) all[t] = t;
  const Camera cam = test::random_cameras(m, 1, 17, double(kW) / kH)[0];
  const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam), all);
  const Framebuffer want = paint(m, cam, order, corner, p);
  std::size_t covered = 0;
  for (std::uint32_t c : want.rgba) covered += c != pack_rgba(255, 255, 255);
  EXPECT_GT(covered, std::size_t(kW) * kH / 4);
  for (const double s : {1e300, 1e-20}) {
    std::vector<double> scaled = corner;
    for (double& v : scaled) v *= s;
    VolumeParams q = p;
    q.scale.lo *= s;
    q.scale.hi *= s;
    for (OpacityPoint& c : q.opacity_curve) c.value *= s;
    int worst = 0;
    EXPECT_EQ(differing(paint(m, cam, order, scaled, q), want, 2, &worst), 0u)
        << "scale " << s << ", worst " << worst;
  }
  // A few nodes' values 1e300 on the usual scale (those tets alone take the portable path): the
  // picture of 1e20 there, as far beyond the curve's and the range's ends (the same extinction and
  // colour but within a ten-billionth of those nodes).
  std::vector<double> far = corner, beyond = corner;
  for (std::size_t i = 0; i < corner.size(); ++i)
    if (m.tet[i] % 7 == 0) far[i] = 1e300, beyond[i] = 1e20;
  int worst = 0;
  const Framebuffer near_ones = paint(m, cam, order, beyond, p);
  EXPECT_EQ(differing(paint(m, cam, order, far, p), near_ones, 2, &worst), 0u) << "worst " << worst;
  EXPECT_GT(differing(near_ones, want, 2, nullptr), 50u) << "the nodes changed the picture";
}

TEST(Volume, DegenerateKuhnGridMatchesTheRayCaster) {
  const Mesh m = bench::cube_grid_mesh(5);
  check(m, {}, 6, 62, "Kuhn grid");
}

TEST(Volume, NonConvexSubsetMatchesTheRayCaster) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 250, 4);
  std::mt19937 rng(5);
  std::vector<std::uint32_t> subset;
  for (std::uint32_t t = 0; t < m.tet_count(); ++t)
    if (rng() % 2 == 0) subset.push_back(t);
  check(m, subset, 6, 63, "random half");
}

// Tets listed with either orientation (every other one with two nodes swapped, as a mesh written
// by another program may have them): the painter takes a tet's face planes outward whichever way its
// nodes turn, and its field's gradient with the right sign.
TEST(Volume, TetsOfBothOrientationsMatchTheRayCaster) {
  test::TempDir dir;
  Mesh m = test::random_delaunay(dir, 200, 6);
  for (std::size_t t = 0; t < m.tet_count(); t += 2) std::swap(m.tet[4 * t + 2], m.tet[4 * t + 3]);
  check(m, {}, 6, 66, "both orientations");
}

// A picture of several screen tiles (the painter bins tets to tiles of 128 x 64 pixels, each thread
// drawing whole tiles): the ray caster at the pixels either side of every tile border and on a grid,
// and one thread's picture the same as two threads'.
TEST(Volume, TiledPictureMatchesTheRayCaster) {
  test::TempDir dir;
  const Mesh m = test::random_delaunay(dir, 200, 9);
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = smooth_field(m);
  VolumeParams p = params_for(m);
  constexpr int W = 300, H = 150;
  std::vector<char> cast(std::size_t(W) * H, 0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      cast[std::size_t(y) * W + std::size_t(x)] =
          (x % 6 == 0 && y % 6 == 0) || (x + 2) % 128 < 4 || (y + 2) % 64 < 4;
  std::size_t bad = 0, covered = 0, compared = 0;
  int worst = 0;
  for (const Camera& cam : test::random_cameras(m, std::max(2, 3 / kCameraShare), 65, double(W) / H)) {
    const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
    p.threads = 2;
    Framebuffer got = paint(m, cam, order, corner, p, nullptr, nullptr, W, H);
    p.threads = 1;
    EXPECT_EQ(got.rgba, paint(m, cam, order, corner, p, nullptr, nullptr, W, H).rgba);
    const Framebuffer want = ray_cast(m, cam, order, corner, p, W, H, &cast);
    for (std::size_t i = 0; i < cast.size(); ++i) {
      if (!cast[i]) got.rgba[i] = pack_rgba(255, 255, 255);
      covered += cast[i] && want.rgba[i] != pack_rgba(255, 255, 255);
      compared += cast[i];
    }
    bad += differing(got, want, 2, &worst);
  }
  std::printf("tiled: %zu of %zu compared pixels covered, %zu differ by more than 2/255 (worst %d)\n",
              covered, compared, bad, worst);
  EXPECT_GT(covered, compared / 4);
  EXPECT_EQ(bad, 0u);
}

// Each tile clears its pixels when it is first drawn: tiles the mesh does not reach are never
// cleared. They, and every pixel whose ray meets no tet (brute force: the ray caster's untouched
// white), must resolve to the background with no tet; a painter that drew nothing, all background.
// The picture is 4 tiles (256 x 128, volume_impl.hpp) and more each way, the mesh in its middle
// third, so its top left quarter's tile is never drawn; the ray caster sees every third pixel.
TEST(Volume, TilesNeverDrawnResolveToTheBackground) {
  test::TempDir tmp;
  const Mesh m = test::random_delaunay(tmp, 60, 21);
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = smooth_field(m);
  VolumeParams p = params_for(m);
  constexpr int W = 1040, H = 520;
  double lo[3], hi[3];
  mesh_bounds(m, lo, hi);
  const double dir[3] = {0.3, 1, -0.4}, up[3] = {0, 0, 1};
  const Camera cam = fit_camera(lo, hi, dir, up, true, 30, double(W) / H, 0.3);
  const std::vector<std::uint32_t> order = visibility_order(m, table, view_of(cam));
  std::vector<char> cast(std::size_t(W) * H, 0);
  for (int y = 0; y < H; y += 3)
    for (int x = 0; x < W; x += 3) cast[std::size_t(y) * W + std::size_t(x)] = 1;
  // White where no ray meets a tet (and where it was not cast).
  const Framebuffer want = ray_cast(m, cam, order, corner, p, W, H, &cast);
  const std::uint32_t white = pack_rgba(255, 255, 255), bg = pack_rgba(20, 90, 160);
  Framebuffer white_bg = paint(m, cam, order, corner, p, nullptr, nullptr, W, H);
  for (std::size_t i = 0; i < cast.size(); ++i)
    if (!cast[i]) white_bg.rgba[i] = white;
  EXPECT_EQ(differing(white_bg, want, 2, nullptr), 0u);
  p.background = bg;
  for (int threads : {1, 2}) {
    p.threads = threads;
    const Framebuffer got = paint(m, cam, order, corner, p, nullptr, nullptr, W, H);
    std::size_t empty = 0, wrong = 0, quarter = 0, cast_pixels = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = got.index(x, y);
        const bool in_quarter = x < W / 4 && y < H / 4;  // no tet there: its tile is never drawn
        if (in_quarter) quarter += got.id[i] == kNone && got.rgba[i] == bg;
        if (!cast[i]) continue;
        ++cast_pixels;
        if (want.rgba[i] != white) continue;
        ++empty;
        // A ray the caster left white met no tet, or only ones too thin to show: the background
        // exactly where no tet was blended.
        if (got.id[i] == kNone && got.rgba[i] != bg) ++wrong;
      }
    EXPECT_GT(empty, cast_pixels / 2);
    EXPECT_EQ(quarter, std::size_t(W / 4) * std::size_t(H / 4)) << threads << " threads";
    EXPECT_EQ(wrong, 0u) << threads << " threads";
  }
  VolumePainter nothing(m, cam, W, H, corner, p);
  Framebuffer fb;
  nothing.resolve(fb);
  EXPECT_EQ(std::count(fb.rgba.begin(), fb.rgba.end(), bg), std::ptrdiff_t(W) * H);
  EXPECT_EQ(std::count(fb.id.begin(), fb.id.end(), kNone), std::ptrdiff_t(W) * H);
}

// The sliver tet seen by `cam` (32 x 32 pixels), its corners given as pixel coordinates and depth
// (camera z): a, b, c on the top face, d behind, the face a b d nearly edge on. With near > 0 (a
// perspective camera) the near plane at that depth. Pixel (12, 16)'s ray must meet the tet (the ray
// caster says so) and the picture must be the ray caster's.
void check_sliver(const Camera& cam, const double px[4][3], double near) {
  constexpr int W = 32, H = 32;
  const Projector proj(cam, W, H);
  Mesh m;
  for (int k = 0; k < 4; ++k) {
    const double* q = px[k];
    const double x = proj.perspective ? (q[0] - proj.cx) / proj.focal * q[2] : (q[0] - proj.cx) / proj.scale;
    const double y =
        proj.perspective ? -(q[1] - proj.cy) / proj.focal * q[2] : -(q[1] - proj.cy) / proj.scale;
    for (int j = 0; j < 3; ++j)
      m.xyz.push_back(proj.eye[j] + x * proj.right[j] + y * proj.up[j] + q[2] * proj.forward[j]);
  }
  m.tet = {0, 1, 2, 3};
  m.tet_region = {1};
  for (int k = 0; k < 4; ++k) {  // the corners where they were meant to be
    double got[2];
    ASSERT_TRUE(proj.project(&m.xyz[3 * std::size_t(k)], got));
    ASSERT_NEAR(got[0], px[k][0], 1e-9);
    ASSERT_NEAR(got[1], px[k][1], 1e-9);
  }
  const std::vector<double> corner = {0.0, 0.3, 0.6, 1.2};
  VolumeParams p = params_for(m);
  p.unit_length = 4;  // 10 to 13 units: most of the way opaque
  p.near = near;
  const std::vector<std::uint32_t> one = {0};
  const Framebuffer want = ray_cast(m, cam, one, corner, p, W, H);
  ASSERT_NE(want.rgba[want.index(12, 16)], pack_rgba(255, 255, 255)) << "the ray should meet the tet";
  int worst = 0;
  const Framebuffer got = paint(m, cam, one, corner, p, nullptr, nullptr, W, H);
  EXPECT_EQ(differing(got, want, 2, &worst), 0u) << "worst " << worst;
  EXPECT_EQ(got.rgba[got.index(12, 16)], want.rgba[want.index(12, 16)]);
}

// A tet with a face seen nearly edge on: its projection a sliver 0.0024 pixels wide at a pixel
// centre (which lies 0.0008 pixels outside the top face's projection). The ray through that centre runs
// 13 units through the tet (in at the sliver face, out at the back), as a brute-force ray says, so
// the picture must show it. Rasterizing the front faces with the painter's snapped corners (1/256
// pixel) lost it: the sliver snaps flat and the centre falls on the top face's excluded edge (the
// portable path drew the flip chip's temperature at 1280x960 with a pixel 5 levels too bright so).
TEST(Volume, NearlyEdgeOnSliverKeepsItsSegment) {
  Camera cam;
  cam.perspective = false;
  cam.eye[0] = 0, cam.eye[1] = 0, cam.eye[2] = 50;
  cam.up[0] = 0, cam.up[1] = 1, cam.up[2] = 0;
  cam.ortho_height = 32;  // a pixel a world unit
  const double px[4][3] = {{4, 16.4992, 30}, {28, 16.4992, 30}, {16, 4, 30}, {12.5, 16.5016, 50}};
  check_sliver(cam, px, 0);
}

// The same sliver seen in perspective with the near plane cutting the tet (its top face before the
// plane, the corner behind the sliver beyond it): the rays start inside the tet at the plane. The
// pixel centre 0.0016 pixels from that corner's projection must keep its 10 units of segment (its
// clipped back faces rasterized with the painter's snapped corners lost it: 9 pixels off, worst 135).
TEST(Volume, NearlyEdgeOnSliverCutByTheNearPlaneKeepsItsSegment) {
  Camera cam;
  cam.eye[0] = 0, cam.eye[1] = 0, cam.eye[2] = 0;
  cam.at[0] = 0, cam.at[1] = 0, cam.at[2] = -1;
  cam.up[0] = 0, cam.up[1] = 1, cam.up[2] = 0;
  cam.fov_deg = 40;
  const double px[4][3] = {{4, 16.4992, 30}, {28, 16.4992, 30}, {16, 4, 30}, {12.5, 16.5016, 50}};
  check_sliver(cam, px, 40);
}

// A structured grid seen from its own planes: the eye in grid planes (x = 0.5, y = 0.25 and the Kuhn
// diagonal x - y = 0.25; a perspective eye), or the rays along the diagonal planes x - y = c (an
// orthographic view along (1, 1, 0), whose planes are along the rays only to within the camera
// frame's rounding). Faces in those planes are seen exactly edge on: each bounds no ray, and a ray's
// parameter at it is a ratio of rounding errors, which lost tets at some pixels and counted others
// twice (a TetGen lattice seen along (1, 1, 0): 762 pixels up to 37 levels apart between the two
// paths, each wrong somewhere). The oracle: the brute-force rays with the eye moved by 1e-5 of the
// grid off every such plane (a picture continuous in the eye moves by far less than a level).
TEST(Volume, StructuredGridSeenFromItsOwnPlanesMatchesTheRaysBeside) {
  const Mesh m = bench::cube_grid_mesh(4);  // nodes at multiples of 0.25, exact
  ASSERT_TRUE(delaunay_certificate(m).delaunay);
  const SphereTable table = compute_spheres(m);
  const std::vector<double> corner = smooth_field(m);
  const VolumeParams p = params_for(m);
  std::vector<std::uint32_t> all(m.tet_count());
  for (std::uint32_t t = 0; t < m.tet_count(); ++t) all[t] = t;
  auto camera = [](bool persp, std::array<double, 3> eye, std::array<double, 3> at,
                   std::array<double, 3> up) {
    Camera c;
    c.perspective = persp;
    std::copy(eye.begin(), eye.end(), c.eye);
    std::copy(at.begin(), at.end(), c.at);
    std::copy(up.begin(), up.end(), c.up);
    c.fov_deg = 50;
    c.ortho_height = 1.6;
    return c;
  };
  const Camera cams[] = {camera(true, {0.5, 0.25, 2}, {0.5, 0.25, 0.5}, {0, 1, 0}),
                         camera(false, {-2, -2, 0.5}, {0.5, 0.5, 0.5}, {0, 0, 1}),
                         camera(true, {-0.5, -0.75, 0.3}, {0.5, 0.25, 0.3}, {0, 0, 1}),
                         // Along z, tilted a hair (1e-8 and 2e-8 of a radian): the face planes along
                         // z are within a millionth of a radian of the rays, taken as along them (at
                         // 1e-10, as for a while, they bounded segments by ratios of rounding errors:
                         // white cracks along the grid lines, up to 224/255).
                         camera(false, {0.5, 0.5, 2}, {0.5 + 1.5e-8, 0.5 + 3e-8, 0.5}, {0, 1, 0})};
  std::size_t bad = 0, covered = 0;
  int worst = 0;
  for (const Camera& cam : cams) {
    Camera beside = cam;
    const double shift[3] = {0.37e-5, 0.61e-5, 0.23e-5};
    for (int k = 0; k < 3; ++k) {
      beside.eye[k] += shift[k];
      beside.at[k] += shift[k];
    }
    const Framebuffer want = ray_cast(m, beside, all, corner, p);
    for (std::uint32_t c : want.rgba) covered += c != pack_rgba(255, 255, 255);
    bad +=
        differing(paint(m, cam, visibility_order(m, table, view_of(cam), all), corner, p), want, 2, &worst);
  }
  std::printf("grid seen from its planes: %zu pixels covered, %zu differ by more than 2/255 (worst %d)\n",
              covered, bad, worst);
  EXPECT_GT(covered, std::size_t(kW) * kH);
  EXPECT_EQ(bad, 0u) << "worst " << worst;
}

// The eye a thousandth of an edge from a node, inside the mesh: the tets around that node have a
// corner just behind the eye, so the near plane cuts them, and the rays that start inside such a tet
// at the plane cross none of its front faces (the cut is their front). Their pixels came from the
// front faces clipped there and lost those rays (TetGen's 7^3 lattice seen from 0.001 off a node: a
// triangle of the picture 28 levels too light; here 4909 and 4034 of 10368 pixels, worst 35 and 28
// levels); the back faces clipped cover every ray that meets the tet's part beyond the plane.
// which: the Kuhn grid with the eye a thousandth of an edge from a node, the random mesh so, and
// the Kuhn grid with the eye a ten-millionth of an edge from it (its faces through the node within
// a millionth of the eye: they were taken for planes through it and left out, and the rays beside
// them counted both tets: seams of up to 31/255 along the projected edges).
TEST(Volume, EyeNextToANodeMatchesTheRayCaster) {
  constexpr int W = 48, H = 36;
  for (int which = 0; which < 3; ++which) {
    test::TempDir dir;
    const Mesh m = which != 1 ? bench::cube_grid_mesh(6) : test::random_delaunay(dir, 200, 12);
    const SphereTable table = compute_spheres(m);
    const std::vector<double> corner = smooth_field(m);
    VolumeParams p = params_for(m);
    std::vector<std::uint32_t> all(m.tet_count());
    for (std::uint32_t t = 0; t < m.tet_count(); ++t) all[t] = t;
    // The node nearest the middle of the mesh.
    double lo[3], hi[3];
    mesh_bounds(m, lo, hi);
    std::size_t node = 0;
    double best = 1e300;
    for (std::size_t k = 0; k < m.node_count(); ++k) {
      double d = 0;
      for (int j = 0; j < 3; ++j) d += std::pow(m.xyz[3 * k + std::size_t(j)] - 0.5 * (lo[j] + hi[j]), 2);
      if (d < best) best = d, node = k;
    }
    const double step = (which == 2 ? 1e-7 : 1e-3) * (hi[0] - lo[0]) / 6;  // of the grid's edge
    // The near plane (automatic: a millionth of the distance in pixels, at this picture's size nearer
    // than the node) just beyond the node, so that it cuts the tets around it: what a larger picture
    // does by itself (the lattice's 540 x 480). The rays' first 3 thousandths of an edge, which the
    // brute-force rays keep, weigh far under a level.
    p.near = 3 * step;
    const double dirs[][3] = {{3, 2, 1},     {-1, 2, 0.5},  {1, -1, -2},
                              {0.3, 0.2, 1}, {-2, -1, 0.4}, {0.5, -3, 1}};
    std::size_t bad = 0, covered = 0;
    int worst = 0, cams = 0;
    for (const auto& d : dirs) {
      if (kCameraShare > 1 && cams >= 2) break;
      Camera c;
      const double off[3] = {1, 1.3, 0.7};
      for (int k = 0; k < 3; ++k) {
        c.eye[k] = m.xyz[3 * node + std::size_t(k)] + step * off[k];
        c.at[k] = c.eye[k] + d[k];
      }
      c.up[0] = 0, c.up[1] = 0, c.up[2] = 1;
      c.fov_deg = cams % 2 ? 70 : 30;
      ++cams;
      const Framebuffer want = ray_cast(m, c, all, corner, p, W, H);
      for (std::uint32_t col : want.rgba) covered += col != pack_rgba(255, 255, 255);
      bad += differing(
          paint(m, c, visibility_order(m, table, view_of(c), all), corner, p, nullptr, nullptr, W, H), want,
          2, &worst);
    }
    std::printf(
        "%s, eye %g from a node, %d views: %zu pixels covered, %zu differ by more than 2/255 (worst %d)\n",
        which == 1 ? "random Delaunay" : "Kuhn grid", step, cams, covered, bad, worst);
    EXPECT_GT(covered, std::size_t(cams) * W * H / 2);
    EXPECT_EQ(bad, 0u) << "worst " << worst;
  }
}

// The vector path (volume_avx512.cpp: float, sixteen lanes, the thin segments from the table's grid
// cell) against the portable one (double, TetSetup::segment and composite()): this binary run twice,
// once with FOXI_PORTABLE_RASTER=1, each drawing random Delaunay pictures over several tiles (a light
// and a dense transfer function: closed-form, thin and stepped segments) and the Kuhn grid seen along
// an axis with pixel centres on its edge-on faces into a file, which must agree
// within 1/255 per channel (the float path's errors, volume_impl.hpp, are a small fraction of a
// level; rounding to 8 bits can turn that into one level, not two) with the same front tet on all but
// a few pixels (a ray that grazes a tet's edge can miss it in one arithmetic and not the other: at most
// 1 in 2000 pixels).
constexpr int kGridSide = 40;  // VectorPathMatchesThePortable's last picture, kGridSide^2 pixels

TEST(Volume, VectorPathMatchesThePortable) {
  if (const char* out = std::getenv("FOXI_VOLUME_PICTURE_OUT")) {  // the child run: draw and write
    test::TempDir dir;
    const Mesh m = test::random_delaunay(dir, 200, 10);
    const SphereTable table = compute_spheres(m);
    const std::vector<double> corner = smooth_field(m);
    std::string bytes;
    std::size_t samples = 0;
    for (double light : {1.0, 8.0, 0.05}) {
      const VolumeParams p = params_for(m, light);
      for (const Camera& cam : test::random_cameras(m, 2, 66, 300.0 / 150)) {
        const Framebuffer fb =
            paint(m, cam, visibility_order(m, table, view_of(cam)), corner, p, &samples, nullptr, 300, 150);
        for (std::size_t i = 0; i < fb.rgba.size(); ++i) {
          const std::uint32_t v[2] = {fb.rgba[i], fb.id[i]};
          bytes.append(reinterpret_cast<const char*>(v), sizeof v);
        }
      }
    }
    // The Kuhn grid seen along z, orthographic, pixel centres on its grid lines and cell diagonals
    // (pixels 0.04 wide, the lines 0.2 apart at odd multiples of 0.1 from the centre): there its
    // vertical faces are seen edge on and bound no ray, so the runs alone must give each such pixel
    // to one of the two tets beside the face (taken twice, its colour would be far off).
    {
      const Mesh grid = bench::cube_grid_mesh(5);
      const std::vector<double> grid_corner = smooth_field(grid);
      Camera cam;
      cam.perspective = false;
      cam.eye[0] = cam.at[0] = 0.5;
      cam.eye[1] = cam.at[1] = 0.5;
      cam.eye[2] = 3;
      cam.at[2] = 0.5;
      cam.up[0] = 0;
      cam.up[1] = 1;
      cam.up[2] = 0;
      cam.ortho_height = 1.6;
      const Framebuffer fb = paint(grid, cam, visibility_order(grid, compute_spheres(grid), view_of(cam)),
                                   grid_corner, params_for(grid), &samples, nullptr, kGridSide, kGridSide);
      for (std::size_t i = 0; i < fb.rgba.size(); ++i) {
        const std::uint32_t v[2] = {fb.rgba[i], fb.id[i]};
        bytes.append(reinterpret_cast<const char*>(v), sizeof v);
      }
    }
    test::write_text(out, bytes);
    std::printf("samples %zu\n", samples);
    return;
  }
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  if (!(__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx512dq")))
    GTEST_SKIP() << "no AVX-512: the painter takes the portable path only";
#else
  GTEST_SKIP() << "no vector path on this platform";
#endif
  test::TempDir dir;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::string pictures[2];
  for (int portable = 0; portable < 2; ++portable) {
    const std::filesystem::path log = dir / ("run" + std::to_string(portable)),
                                out = dir / ("picture" + std::to_string(portable));
    const int rc = test::run("FOXI_VOLUME_PICTURE_OUT='" + out.string() +
                                 "' FOXI_PORTABLE_RASTER=" + std::to_string(portable) + " '" + self +
                                 "' --gtest_filter=Volume.VectorPathMatchesThePortable",
                             log);
    ASSERT_EQ(rc, 0) << test::read_text(log);
    pictures[portable] = test::read_text(out);
  }
  ASSERT_EQ(pictures[0].size(), pictures[1].size());
  ASSERT_GT(pictures[0].size(), 0u);
  const std::size_t n = pictures[0].size() / 8;
  std::size_t ids_differ = 0, colours_differ = 0, covered = 0;
  int worst = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t v[2][2];
    for (int k = 0; k < 2; ++k) std::memcpy(v[k], pictures[k].data() + 8 * i, 8);
    // The front ids of the grid's picture are not compared: a pixel centre on an edge-on face's line
    // has two front tets, and the two paths' rules pick either.
    ids_differ += v[0][1] != v[1][1] && i < n - std::size_t(kGridSide * kGridSide);
    covered += v[1][1] != kNone;
    int d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(int((v[0][0] >> (8 * c)) & 255u) - int((v[1][0] >> (8 * c)) & 255u)));
    worst = std::max(worst, d);
    colours_differ += d > 0;
  }
  std::printf(
      "vector against portable: %zu pixels, %zu covered, %zu colours differ (worst %d/255), %zu front ids\n",
      n, covered, colours_differ, worst, ids_differ);
  EXPECT_GT(covered, n / 4);
  EXPECT_LE(worst, 1);
  EXPECT_LE(ids_differ, n / 2000);
}

TEST(Volume, SafePictureSaysWhichOrder) {
  // Certified: the power order, the same picture as the painter fed it directly.
  const Mesh grid = bench::cube_grid_mesh(4);
  const SphereTable table = compute_spheres(grid);
  const std::vector<double> corner = smooth_field(grid);
  const VolumeParams p = params_for(grid);
  const Camera cam = test::random_cameras(grid, 1, 71, double(kW) / kH)[0];
  Framebuffer fb(kW, kH);
  const VolumeReport r = draw_volume_picture(grid, table, cam, fb, {}, corner, p);
  EXPECT_TRUE(r.delaunay);
  EXPECT_TRUE(r.exact_order);
  EXPECT_EQ(r.tets, grid.tet_count());
  EXPECT_EQ(fb.rgba, paint(grid, cam, visibility_order(grid, table, view_of(cam)), corner, p).rgba);
  // Uncertified (a jittered Kuhn grid): MPVO, and the report says it is not exact.
  const Mesh jittered = bench::kuhn_grid_mesh(4, 0.15, 7);
  ASSERT_FALSE(compute_delaunay_certificate(jittered).delaunay);
  const SphereTable jt = compute_spheres(jittered);
  const VolumeReport rj = draw_volume_picture(jittered, jt, cam, fb, {}, smooth_field(jittered), p);
  EXPECT_FALSE(rj.delaunay);
  EXPECT_FALSE(rj.exact_order);
  EXPECT_EQ(rj.tets, jittered.tet_count());
}

TEST(Volume, TransferFunction) {
  VolumeParams p;
  p.unit_length = 2;
  p.opacity_curve = {{0, 0.2}, {1, 0.6}};
  EXPECT_NEAR(volume_extinction(p, -5), -std::log(0.8) / 2, 1e-15);
  EXPECT_NEAR(volume_extinction(p, 0.5), -std::log(0.6) / 2, 1e-15);
  EXPECT_NEAR(volume_extinction(p, 7), -std::log(0.4) / 2, 1e-15);
  // A constant value over the unit length accumulates exactly the curve's opacity.
  float c[3] = {255, 255, 255};
  integrate_segment(p, 0.5, 0.5, 2, c);
  const std::uint32_t col = p.scale.color(0.5);
  EXPECT_NEAR(c[0], 0.4 * double(col & 255u) + 0.6 * 255, 1e-3);
  const Mesh m = bench::cube_grid_mesh(1);
  const std::vector<double> corner(m.tet.size(), 0.0);
  Camera cam;
  p.opacity_curve = {{1, 0.2}, {0, 0.3}};
  EXPECT_THROW(VolumePainter(m, cam, 10, 10, corner, p), std::invalid_argument);
  p.opacity_curve = {{0, 1.0}};
  EXPECT_THROW(VolumePainter(m, cam, 10, 10, corner, p), std::invalid_argument);
  p.opacity_curve = {{0, 0.5}};
  p.unit_length = 0;
  EXPECT_THROW(VolumePainter(m, cam, 10, 10, corner, p), std::invalid_argument);
  // A curve whose table cannot step across it (its span not a double, or its 4096th not one): refused,
  // where it once indexed the table with a NaN (a crash).
  p.unit_length = 1;
  p.opacity_curve = {{-1e308, 0.1}, {1e308, 0.5}};
  EXPECT_THROW(VolumePainter(m, cam, 10, 10, corner, p), std::invalid_argument);
  p.opacity_curve = {{0, 0}, {3e-310, 0.5}};
  EXPECT_THROW(VolumePainter(m, cam, 10, 10, corner, p), std::invalid_argument);
  // A colour scale wider than the largest double with a usable curve: drawn (stepped, not pre-integrated).
  p.opacity_curve = {{0, 0.2}, {1, 0.6}};
  p.scale.lo = -1.5e308;
  p.scale.hi = 1.5e308;
  VolumePainter wide(m, cam, 10, 10, corner, p);
  wide.draw(std::vector<std::uint32_t>{0});
}

}  // namespace
}  // namespace foxi
