// The painter's face setup (TetRasterizer::Impl, raster_impl.hpp): flat shading, edge lines and their
// exactness in double, and near-plane clipping of a face into a polygon.
#include "raster_impl.hpp"

namespace foxi {

// The flat shade of tet `tet`'s face whose corners are `v` (camera frame) in outward order, node[j]
// the node of v[j]: its region's colour, Lambert + ambient. The normal is computed from the corners
// in ascending node order (its sign from the permutation's parity), so the two tets sharing a face
// get the same bits, each side with its sign: undraw shades a kept neighbour's face from the
// undrawn tet's own corners, as drawing the neighbour did.
FaceShade TetRasterizer::Impl::face_shade(std::uint32_t tet, const double* const v[3],
                                          const std::uint32_t node[3]) const {
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
  // A field's colour keeps its hue and at least shade_min of its lightness (FieldPaint).
  const double ambient = field != nullptr ? field->shade_min : params.ambient;
  double intensity = ambient + (1 - ambient) * std::max(0.0, lambert);
  intensity = std::clamp(intensity, 0.0, 1.0);
  const std::int32_t region = mesh->region_of(tet);
  std::uint32_t base = field != nullptr ? (field->graded ? pack_rgba(255, 255, 255) : field->tet_color[tet])
                       : region >= 0 && std::size_t(region) < params.region_colors.size()
                           ? params.region_colors[std::size_t(region)]
                           : region_color(region);
  FaceShade sh;
  sh.base = base;
  sh.level = intensity * 255;
  sh.shade = shade_of(sh.level, 1);
  sh.color = shade_color(base, sh.shade);
  return sh;
}

inline TetRasterizer::Impl::EdgeLine TetRasterizer::Impl::edge_line(const PolyVertex& a,
                                                                    const PolyVertex& b) {
  const std::int64_t ex = b.X - a.X, ey = b.Y - a.Y;
  return EdgeLine{-ey * kOne, ex * kOne, ex * (kHalf - a.Y) - ey * (kHalf - a.X),
                  std::sqrt(double(ex) * double(ex) + double(ey) * double(ey))};
}

// Whether the line ea x + eb y + ec is below 2^52 in magnitude on the whole image (see
// FaceSetup::exact_double).
inline bool TetRasterizer::Impl::exact_in_double(std::int64_t ea, std::int64_t eb, std::int64_t ec) const {
  return std::abs(double(ea)) * proj.width + std::abs(double(eb)) * proj.height + std::abs(double(ec)) <
         0x1p52;
}

// A face of tet `tet` in shade sh.
inline void TetRasterizer::Impl::set_shade(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh) {
  fs.tet = tet;
  fs.color = sh.color;
  fs.base = sh.base;
  fs.level = sh.level;
  fs.shade = sh.shade;
}

#ifdef FOXI_AVX512_REPAINT
// What repaint_triangle_avx512 reads of setup_face's work for triangle poly (the shade, and the
// three edge lines in double), false if it does not apply (an edge of no length, or a line not
// exact in double).
bool TetRasterizer::Impl::setup_repaint(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh,
                                        const PolyVertex* poly) const {
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
void TetRasterizer::Impl::setup_face(FaceSetup& fs, std::uint32_t tet, const double* const v[3],
                                     const std::uint32_t node[3], const PolyVertex* poly, int n) const {
  setup_face(fs, tet, face_shade(tet, v, node), poly, n);
}

// The same with the shade known.
void TetRasterizer::Impl::setup_face(FaceSetup& fs, std::uint32_t tet, const FaceShade& sh,
                                     const PolyVertex* poly, int n) const {
  set_shade(fs, tet, sh);
  fs.graded = field != nullptr && field->graded;
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
  for (int k = 0; k < fs.lines; ++k)
    fs.exact_double = fs.exact_double && exact_in_double(fs.ea[k], fs.eb[k], fs.ec[k]);
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

// The polygon of face f of tet t (corners from `corners`) as drawn when it faces the eye: front
// (back = false) for t itself, back (back = true) the same face seen from the other side, which is
// exactly the polygon the neighbour across it draws as its front face (same vertices, same
// orientation, same pixels under the fill rule). Returns its vertex count (3, or 4 when the near
// plane cuts it) with positive area, or 0 when the face is not of the asked side or covers nothing.
// *clipped is set when the near plane cuts a face of the asked side.
int TetRasterizer::Impl::face_polygon(const TetCorners& k, int f, bool back, PolyVertex* poly, bool* clipped,
                                      const float* pos_given) const {
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
    const float* pos = pos_given != nullptr ? pos_given : corner_positions(tv);
    for (int i = 0; i < 3; ++i) {
      poly[i].X = X[order[i]];
      poly[i].Y = Y[order[i]];
      poly[i].w = nearness(c[order[i]]);
      poly[i].mesh_edge = true;
      poly[i].pos = pos != nullptr ? pos[order[i]] : 0.0f;
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
      if (const float* pos = pos_given != nullptr ? pos_given : corner_positions(tv))
        out.pos = float(pos[lo] + tt * (pos[hi] - pos[lo]));
      std::uint8_t dummy;
      project_camera(out.c, out.X, out.Y, dummy);
    };
    if (pin) {
      poly[n].X = X[pi];
      poly[n].Y = Y[pi];
      poly[n].w = nearness(c[pi]);
      poly[n].mesh_edge = true;
      if (const float* pos = pos_given != nullptr ? pos_given : corner_positions(tv)) poly[n].pos = pos[pi];
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

}  // namespace foxi
