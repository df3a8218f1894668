// The volume renderer's per-tet work (volume_impl.hpp): a tet's set-up in the camera frame (its field's
// gradient, its four outward planes, the ray's planes and field linear in the pixel's x and y), its
// pixels listed (the rows' spans of its corners' projection, or of its part beyond the near plane's
// where the plane cuts it), and integrated on the portable path (where the CPU has AVX-512,
// volume_avx512.cpp finds and integrates its rows).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "volume_impl.hpp"

namespace foxi {
namespace {

// The pixel rows of a tet whose four corners q (pixel coordinates) are all in front of the eye, as
// volume_tet_avx512 finds them, one row at a time: per row y (its centre line y + 0.5 in [least,
// largest) of the corners' y) the pixel centres x + 0.5 in [lo, hi), lo and hi the least and largest
// x where the centre line meets the six segments between the corners (half-open: a centre on a face
// seen edge on, which bounds no ray, goes to one of the two tets beside it); within x0..x1, y0..y1.
// fn(y, first, last) per row with pixels.
template <class Fn>
void tet_row_spans(const double (*q)[2], int n, int x0, int x1, int y0, int y1, Fn&& fn) {
  CornerEdges e;
  if (!corner_edges(q, n, y0, y1, e)) return;
  for (int y = e.ya; y <= e.yb; ++y) {
    const double yc = y + 0.5;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < e.n; ++k)
      if (yc >= e.y0[k] && yc <= e.y1[k]) {
        // fma as the vector path's, so both find the same spans; then on a grid of 2^-15 pixel
        // (nearest), as the vector path's roundscale: where a face is seen edge on its three edges
        // are one line, and their x here differ in the last bits; the tets either side of it take
        // the least and the largest of them, so with a pixel centre on the line both could take it
        // (or neither). On the grid they agree, and the half-open rule gives it to one.
        const double x = std::nearbyint(std::fma(yc - e.y0[k], e.slope[k], e.x0[k]) * 32768.0) / 32768.0;
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    if (!(lo <= hi)) continue;  // no segment crosses the row's centre line (or not a number)
    lo = std::min(std::max(lo - 0.5, double(x0)), double(x1) + 1);
    hi = std::max(std::min(hi - 0.5, double(x1) + 1), double(x0));
    const int first = int(std::ceil(lo)), last = int(std::ceil(hi)) - 1;
    if (first <= last) fn(y, first, last);
  }
}

}  // namespace

void VolumePainter::Impl::draw_tet(std::uint32_t t, const Tile& tile, Scratch& scratch, std::size_t& count,
                                   std::size_t& fast) {
  const std::uint32_t* node = &mesh->tet[4 * std::size_t(t)];
  const double* cv = &corner[4 * std::size_t(t)];
  double P[4][3];
  for (int k = 0; k < 4; ++k) std::copy_n(&cam_xyz[3 * std::size_t(node[k])], 3, P[k]);
  double g[3], n[4][3], h[4];
  // (volume_avx512.cpp's tet_batch_avx512 does this set-up, to RowSetup, eight tets at a time for
  // the vector path: a change here is a change there; the tests compare both paths' pictures.)
  // The faces' normals n_f = (b - a) x (c - a) in kFace's winding: all outward where the tet is
  // positively oriented (det = 6 V > 0), all inward where not. The gradient of barycentric
  // coordinate i is -n_i / det with those normals (either way), so the field's is
  // -sum_i (cv[i] - cv[0]) n_i / det (the four gradients sum to zero); then the normals outward.
  for (int f = 0; f < 4; ++f) {
    const double* a = P[kFace[f][0]];
    const double* b = P[kFace[f][1]];
    const double* c = P[kFace[f][2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[f][0] = u[1] * w[2] - u[2] * w[1];
    n[f][1] = u[2] * w[0] - u[0] * w[2];
    n[f][2] = u[0] * w[1] - u[1] * w[0];
  }
  // det = (P1 - P0) . ((P2 - P0) x (P3 - P0)) = -(P1 - P0) . n_1, n_1 = (P3 - P0) x (P2 - P0).
  const double det =
      -(n[1][0] * (P[1][0] - P[0][0]) + n[1][1] * (P[1][1] - P[0][1]) + n[1][2] * (P[1][2] - P[0][2]));
  if (!(std::abs(det) > 0)) return;  // flat
  const double df1 = cv[1] - cv[0], df2 = cv[2] - cv[0], df3 = cv[3] - cv[0], inv = -1 / det;
  for (int j = 0; j < 3; ++j) g[j] = (df1 * n[1][j] + df2 * n[2][j] + df3 * n[3][j]) * inv;
  const double sign = det > 0 ? 1.0 : -1.0;
  for (int f = 0; f < 4; ++f) {
    for (double& x : n[f]) x *= sign;
    const double* a = P[kFace[f][0]];
    h[f] = n[f][0] * a[0] + n[f][1] * a[1] + n[f][2] * a[2];
  }
  TetSetup r;
  {
    const double *o0 = rays.o0, *d0 = rays.d0;
    const double ox = rays.ox, oy = rays.oy, dx = rays.dx, dy = rays.dy;
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
  // The portable path: a row's pixels one at a time, each integrated in double.
  const VolumeAcc va{{chan[0].get(), chan[1].get(), chan[2].get()}, front.get(), proj.width};
  auto add_run = [&](int y, int lo, int hi) {
    lo = std::max(lo, tile.x0);
    hi = std::min(hi, tile.x1);
    if (lo > hi) return;
    const std::size_t row = std::size_t(y) * std::size_t(proj.width);
    for (int x = lo; x <= hi; ++x) {
      double v_far, v_near, len;
      if (!r.segment(x, y, v_far, v_near, len)) continue;  // the ray misses the tet
      const std::size_t p = row + std::size_t(x);
      float c[3] = {va.c[0][p], va.c[1][p], va.c[2][p]};
      composite(*transfer, v_far, v_near, len, c, fast);
      for (int j = 0; j < 3; ++j) va.c[j][p] = c[j];
      va.front[p] = t;
      ++count;
    }
  };
  // The corners' squared distances from the eye, and the farthest (perspective; 1 orthographic):
  // the near plane's scale here, the faces' below.
  double d2[4], reach2 = 1;
  for (int k = 0; k < 4; ++k) d2[k] = P[k][0] * P[k][0] + P[k][1] * P[k][1] + P[k][2] * P[k][2];
  if (proj.perspective) reach2 = std::max({d2[0], d2[1], d2[2], d2[3]});
  // The pixels whose ray may meet the tet: the rows' spans of pixel centres inside the projection of
  // its part beyond the clipping plane (perspective: the near plane, or nearer than a millionth of
  // the farthest corner's distance in pixels, so that the projection stays within kMaxPixel of the
  // centre; the rays' parts nearer than that weigh nothing), unsnapped; the ray decides each pixel
  // (segment(): entry, from the near plane on, before exit). That part is convex, so its projection
  // is the hull of its corners' projections: the tet's four corners where all lie beyond the plane
  // (the usual case), else those beyond it and the points where its edges cross it (at most six; an
  // eye inside the tet has corners on both sides).
  // Not faces rasterized with the painter's snapped corners: where a face is seen nearly edge on, a
  // pixel centre a thousandth of a pixel inside the projection can fall outside the snapped one while
  // its ray runs a long way through the tet (a segment lost: the flip chip's temperature at 1280x960
  // had a pixel 5 levels too bright; a tet the near plane cut lost its pixels so, or those where the
  // rays start inside it at the plane, until its back faces were drawn).
  double clip = -std::numeric_limits<double>::infinity();
  if (proj.perspective) {
    clip = std::max(params.near, std::sqrt(reach2) * proj.focal / kMaxPixel);
    if (!(clip > 0)) clip = 1e-300;
  }
  double q[6][2];
  int n_q = 0, beyond = -1;  // beyond: the first corner beyond the plane
  for (int i = 0; i < 4; ++i) {
    if (P[i][2] >= clip) {
      // The node's pixel, found once per frame (NaN only where it lies at the near plane itself).
      const double* px = &node_px[2 * std::size_t(node[i])];
      if (!std::isnan(px[0])) {
        q[n_q][0] = px[0];
        q[n_q++][1] = px[1];
      } else {
        proj.camera_to_pixel(P[i], q[n_q++]);
      }
      if (beyond < 0) beyond = i;
    }
    for (int j = i + 1; j < 4; ++j)
      if ((P[i][2] >= clip) != (P[j][2] >= clip)) {
        const double u = (clip - P[i][2]) / (P[j][2] - P[i][2]);
        const double c[3] = {P[i][0] + u * (P[j][0] - P[i][0]), P[i][1] + u * (P[j][1] - P[i][1]), clip};
        proj.camera_to_pixel(c, q[n_q++]);
      }
  }
  if (beyond < 0) return;  // wholly nearer than the plane (or not a number)
  // A face's plane through the eye (perspective) or along the rays (orthographic, to a millionth of
  // a radian) bounds no segment: every ray meets it at the eye or lies in it, and which side of it
  // a pixel's ray is on is which side of its projection, a line, the pixel is on: what the spans
  // decide (half-open, so a pixel centre on the line goes to one of the two tets beside it). Its ray
  // parameter would be a ratio of rounding errors (in float on the vector path), and a pixel on
  // that line could lose its tet or get it twice. Perspective: through the eye to a millionth of the
  // nearest drawn distance of the face (its nearest corner, or its clipping plane's distance,
  // computed from the face's own corners so that both tets beside it decide alike): a projection
  // under a thousandth of a pixel wide. (With the tet's farthest corner for scale, faces through a
  // grid node 1e-7 from the eye were taken for planes through it, though near the clipping plane
  // they spread over pixels, and the rays there counted both tets: seams of up to 31/255.)
  for (int k = 0; k < 4; ++k) {
    const double nn = n[k][0] * n[k][0] + n[k][1] * n[k][1] + n[k][2] * n[k][2];
    double scale2 = 1;  // orthographic: the angle
    if (proj.perspective) {
      double lo2 = std::numeric_limits<double>::infinity(), hi2 = 0;
      for (int c = 0; c < 4; ++c)
        if (c != k) lo2 = std::min(lo2, d2[c]), hi2 = std::max(hi2, d2[c]);
      const double clip_f = std::max(params.near, std::sqrt(hi2) * proj.focal / kMaxPixel);
      scale2 = std::max(clip_f * clip_f, lo2);
    }
    const double off = proj.perspective ? h[k] : n[k][2];  // the eye's offset, or the rays'
    if (off * off <= 1e-12 * nn * scale2)
      r.ndA[k] = r.ndB[k] = r.ndC[k] = r.numA[k] = r.numB[k] = r.numC[k] = 0;
  }
#ifdef FOXI_VOLUME_AVX512
  // Corner values beyond what float holds: this tet on the portable path (volume.cpp).
  const bool float_values = !(std::abs(cv[0]) > kFloatSafe || std::abs(cv[1]) > kFloatSafe ||
                              std::abs(cv[2]) > kFloatSafe || std::abs(cv[3]) > kFloatSafe);
  if (vector_rows && float_values) {
    // The vector path decides each pixel by its ray (entry before exit), sixteen at a time in float
    // re-centred on the tet (its first point's pixel, a corner beyond the plane's depth).
    const int xr = int(std::clamp(q[0][0], double(tile.x0), double(tile.x1)));
    const int yr = int(std::clamp(q[0][1], double(tile.y0), double(tile.y1)));
    volume_tet_avx512(RowSetup(r, P[beyond][2], xr, yr), *transfer, va, q, n_q, tile.x0, tile.x1, tile.y0,
                      tile.y1, t, scratch.runs, count, fast);
    return;
  }
#endif
  tet_row_spans(q, n_q, tile.x0, tile.x1, tile.y0, tile.y1, add_run);
}

#ifdef FOXI_VOLUME_AVX512
void VolumePainter::Impl::draw_tets(const std::uint32_t* tets, int n, const Tile& tile, Scratch& scratch,
                                    std::size_t& count, std::size_t& fast) {
  TetBatch& b = scratch.batch;
  constexpr int kL = TetBatch::kLanes;
  // The corners' pixels (AoS, as corner_edges4 reads them); a lane whose corner has none (not in
  // front of the eye) goes through draw_tet.
  double q[kL][6][2];
  bool pixels[kL];
  for (int l = 0; l < kL; ++l) {
    const std::uint32_t t = tets[l < n ? l : 0];
    const std::uint32_t* node = &mesh->tet[4 * std::size_t(t)];
    const double* cv = &corner[4 * std::size_t(t)];
    bool all = true;
    for (int k = 0; k < 4; ++k) {
      const double* c = &cam_xyz[3 * std::size_t(node[k])];
      const double* px = &node_px[2 * std::size_t(node[k])];
      for (int j = 0; j < 3; ++j) b.P[k][j][l] = c[j];
      b.cv[k][l] = cv[k];
      q[l][k][0] = px[0];
      q[l][k][1] = px[1];
      all = all && !std::isnan(px[0]) && !std::isnan(px[1]) && !(std::abs(cv[k]) > kFloatSafe);
    }
    b.q0[0][l] = q[l][0][0];
    b.q0[1][l] = q[l][0][1];
    pixels[l] = all;
  }
  std::copy_n(rays.o0, 3, b.o0);
  std::copy_n(rays.d0, 3, b.d0);
  b.ox = rays.ox;
  b.oy = rays.oy;
  b.dx = rays.dx;
  b.dy = rays.dy;
  b.near = std::max(params.near, 0.0);
  b.focal = proj.focal;
  b.perspective = proj.perspective;
  b.x0 = tile.x0;
  b.x1 = tile.x1;
  b.y0 = tile.y0;
  b.y1 = tile.y1;
  tet_batch_avx512(b);
  const VolumeAcc va{{chan[0].get(), chan[1].get(), chan[2].get()}, front.get(), proj.width};
  for (int l = 0; l < n; ++l) {
    if (b.ok[l] && pixels[l])
      volume_tet_avx512(b.rs[l], *transfer, va, q[l], 4, tile.x0, tile.x1, tile.y0, tile.y1, tets[l],
                        scratch.runs, count, fast);
    else
      draw_tet(tets[l], tile, scratch, count, fast);
  }
}
#endif

}  // namespace foxi
