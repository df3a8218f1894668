// The painter of iso polygons (IsoPainter, isosurface.hpp): each tet's polygons drawn at its place in
// the order handed in, with the tet painter's fixed point and fill rule (raster_triangle), so that
// polygons of neighbouring tets, whose shared vertices have the same bits (iso_detail::edge_point),
// cover each pixel once. In cap mode the tets wholly above the value go to a TetRasterizer in runs
// between the cut tets, which are drawn here as their convex part above the value (front faces only).
#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include "foxi/viz/isosurface.hpp"
#include "iso_detail.hpp"
#include "raster_impl.hpp"
#include "depth_tie.hpp"

namespace foxi {

namespace {

constexpr int kMaxPoly = 10;

// A polygon vertex on its way to the screen: world, camera coordinates and the attribute (the
// scale position for graded colour).
struct Vert {
  double c[3];
  double pos;
  bool mesh_edge = false;  // the edge from this vertex to the next is (part of) a mesh edge (cap mode)
};

}  // namespace

struct IsoPainter::Impl {
  // The lent view, kept here (a caller's MeshView may be a temporary); `mesh` points at it.
  MeshView mesh_view;
  const MeshView* mesh = nullptr;
  Projector proj;
  std::span<const double> corner, attr;
  IsoParams params;
  std::vector<double> values;  // ascending
  bool depth = false;
  double near_given = 0;  // RenderParams::near
  // Cap mode's cut tets darken their faces' mesh edges as the tet painter darkens the whole tets'
  // (RenderParams edges, edge_width, edge_darkness; raster_field.cpp's rule): a pixel at distance
  // d < edge_width from a mesh edge's line is scaled by edge_base + edge_slope d.
  bool edges = false;
  double edge_width = 1, edge_base = 1, edge_slope = 0;
  double light[3] = {0, 0, -1};
  float lut[256][3] = {};
  std::optional<TetRasterizer> solid;  // cap mode: the whole tets
  std::size_t polygons = 0;
  // Undoable (RenderParams::undoable): per tet handed to draw(), in order, a step: a tet drawn here
  // with the pixels its polygons overwrote (their index, colour and id before, in writing order), or
  // a run of whole tets drawn by `solid` (its own undo keeps those).
  bool undoable = false;
  struct Step {
    bool solid = false;
    std::size_t count = 1;       // tets (a solid run's), else 1
    std::size_t save_begin = 0;  // the first saved pixel of a tet drawn here
  };
  std::vector<Step> steps;
  std::vector<std::uint32_t> saved_pixel, saved_rgba, saved_id;
  std::size_t drawn = 0;
  void begin_tet() {
    ++drawn;
    if (undoable) steps.push_back({false, 1, saved_pixel.size()});
  }
  void solid_run(Framebuffer& fb, std::span<const std::uint32_t> run) {
    solid->draw(fb, run);
    drawn += run.size();
    if (!undoable) return;
    if (!steps.empty() && steps.back().solid)
      steps.back().count += run.size();
    else
      steps.push_back({true, run.size(), 0});
  }

  Impl(const MeshView& m, const Camera& camera, int w, int h)
      : mesh_view(m), mesh(&mesh_view), proj(camera, w, h) {}

  // Draws a convex polygon (camera coordinates, attribute positions when graded): flat colour rgb x
  // factor, or per pixel the scale entry at the interpolated position x factor.
  void draw_polygon(Framebuffer& fb, std::uint32_t tet, Vert* v, int n, bool graded, const float rgb[3],
                    float factor, const Rows& rows = {}) {
    // Near-plane clip (perspective): keep depth >= near.
    Vert clipped[kMaxPoly];
    if (proj.perspective) {
      // The tet painter's rule (rasterizer.cpp) on the polygon's own points: at depth >= near, a point
      // no farther than dmax from the eye projects within kMaxPixel of the centre.
      double dmax = 0;
      for (int i = 0; i < n; ++i)
        dmax =
            std::max(dmax, std::sqrt(v[i].c[0] * v[i].c[0] + v[i].c[1] * v[i].c[1] + v[i].c[2] * v[i].c[2]));
      double near = std::max(near_given, dmax * proj.focal / kMaxPixel);
      if (!(near > 0)) near = 1e-300;
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const Vert& a = v[i];
        const Vert& b = v[(i + 1) % n];
        const bool ina = a.c[2] >= near, inb = b.c[2] >= near;
        if (ina && m < kMaxPoly) clipped[m++] = a;
        if (ina != inb && m < kMaxPoly) {
          const double t = (near - a.c[2]) / (b.c[2] - a.c[2]);
          Vert& o = clipped[m++];
          for (int k = 0; k < 3; ++k) o.c[k] = a.c[k] + t * (b.c[k] - a.c[k]);
          o.c[2] = near;
          o.pos = a.pos + t * (b.pos - a.pos);
          // Leaving: the next edge runs along the near plane; entering: it is the rest of a -> b.
          o.mesh_edge = ina ? false : a.mesh_edge;
        }
      }
      if (m < 3) return;
      v = clipped;
      n = m;
    }
    std::int64_t X[kMaxPoly], Y[kMaxPoly];
    double px[kMaxPoly][2], w[kMaxPoly];
    snap_polygon(
        proj, n, [&](int i) { return v[i].c; }, X, Y, px, w);
    if (rows.thread == 0) ++polygons;
    // The mesh edges' lines in pixel coordinates (from the snapped vertices): a point, a unit normal.
    int lines = 0;
    double lx[kMaxPoly], ly[kMaxPoly], lnx[kMaxPoly], lny[kMaxPoly];
    if (edges)
      for (int i = 0; i < n; ++i) {
        if (!v[i].mesh_edge) continue;
        const int j = i + 1 == n ? 0 : i + 1;
        const double ex = px[j][0] - px[i][0], ey = px[j][1] - px[i][1], len = std::hypot(ex, ey);
        if (!(len > 0)) continue;
        lx[lines] = px[i][0], ly[lines] = px[i][1], lnx[lines] = -ey / len, lny[lines] = ex / len;
        ++lines;
      }
    for_each_fan_triangle(X, Y, n, [&](const std::int64_t* TX, const std::int64_t* TY, const int* idx) {
      // Affine functions on the screen: nearness, and position x nearness (perspective-correct).
      const double x0 = px[idx[0]][0], y0 = px[idx[0]][1];
      const double ax = px[idx[1]][0] - x0, ay = px[idx[1]][1] - y0;
      const double bx = px[idx[2]][0] - x0, by = px[idx[2]][1] - y0;
      const double det = ax * by - ay * bx;
      auto plane = [&](double f0, double f1, double f2, double& fa, double& fb_) {
        fa = ((f1 - f0) * by - (f2 - f0) * ay) / det;
        fb_ = ((f2 - f0) * ax - (f1 - f0) * bx) / det;
      };
      const double w0 = w[idx[0]];
      double wa, wb;
      plane(w0, w[idx[1]], w[idx[2]], wa, wb);
      auto gval = [&](int k) { return proj.perspective ? v[idx[k]].pos * w[idx[k]] : v[idx[k]].pos; };
      const double g0 = graded ? gval(0) : 0;
      double ga = 0, gb = 0;
      if (graded) plane(g0, gval(1), gval(2), ga, gb);
      raster_triangle(TX, TY, fb.width, fb.height, rows, [&](int y, int lo, int hi) {
        const double dy = y + 0.5 - y0;
        for (int x = lo; x <= hi; ++x) {
          const double dx = x + 0.5 - x0;
          const std::size_t p = fb.index(x, y);
          const double z = w0 + wa * dx + wb * dy;
          if (depth && !depth_test(fb, p, z, wa, wb, std::abs(w0) + std::abs(wa * dx) + std::abs(wb * dy)))
            continue;
          if (undoable) {
            saved_pixel.push_back(std::uint32_t(p));
            saved_rgba.push_back(fb.rgba[p]);
            saved_id.push_back(fb.id[p]);
          }
          const float* c = rgb;
          float nan_rgb[3];
          if (graded) {
            double t = g0 + ga * dx + gb * dy;
            if (proj.perspective) t /= z;
            if (std::isnan(t)) {
              for (int k = 0; k < 3; ++k) nan_rgb[k] = float((params.scale.nan_color >> (8 * k)) & 255u);
              c = nan_rgb;
            } else {
              c = lut[int(std::clamp(t * 256, 0.0, 255.0))];
            }
          }
          float f = factor;
          if (lines > 0) {
            double d = edge_width;
            for (int k = 0; k < lines; ++k)
              d = std::min(d, std::abs((x + 0.5 - lx[k]) * lnx[k] + (y + 0.5 - ly[k]) * lny[k]));
            if (d < edge_width) f *= float(edge_base + edge_slope * d);
          }
          fb.rgba[p] = pack_rgba(std::uint32_t(c[0] * f + 0.5f), std::uint32_t(c[1] * f + 0.5f),
                                 std::uint32_t(c[2] * f + 0.5f));
          fb.id[p] = tet;
        }
      });
    });
  }

  // Camera-frame direction of world direction d.
  void to_camera_dir(const double d[3], double out[3]) const {
    out[0] = d[0] * proj.right[0] + d[1] * proj.right[1] + d[2] * proj.right[2];
    out[1] = d[0] * proj.up[0] + d[1] * proj.up[1] + d[2] * proj.up[2];
    out[2] = d[0] * proj.forward[0] + d[1] * proj.forward[1] + d[2] * proj.forward[2];
  }
  // Whether world normal n at camera point c faces the eye.
  bool faces_eye(const double n[3], const double c[3]) const {
    double nc[3];
    to_camera_dir(n, nc);
    return proj.perspective ? nc[0] * c[0] + nc[1] * c[1] + nc[2] * c[2] < 0 : nc[2] < 0;
  }
  // Lambert factor in [shade_min, 1] of a face whose normal n (world) faces the eye.
  float shade(const double n[3], const double c[3]) const {
    double nc[3];
    to_camera_dir(n, nc);
    const double len = std::sqrt(nc[0] * nc[0] + nc[1] * nc[1] + nc[2] * nc[2]);
    if (!(len > 0)) return float(params.shade_min);
    double s = (nc[0] * light[0] + nc[1] * light[1] + nc[2] * light[2]) / len;
    if (!faces_eye(n, c)) s = -s;
    return float(std::clamp(params.shade_min + (1 - params.shade_min) * std::max(0.0, s), 0.0, 1.0));
  }

  void entry_rgb(double value, float rgb[3]) const {
    const std::uint32_t col = params.scale.color(value);
    for (int k = 0; k < 3; ++k) rgb[k] = float((col >> (8 * k)) & 255u);
  }

  // The polygons of tet t for the isovalues it crosses, far to near.
  void draw_surfaces(Framebuffer& fb, std::uint32_t t, const Rows& rows) {
    const double* c = &corner[4 * std::size_t(t)];
    const double lo = std::min({c[0], c[1], c[2], c[3]}), hi = std::max({c[0], c[1], c[2], c[3]});
    if (!(lo < hi)) return;
    auto first = std::upper_bound(values.begin(), values.end(), lo);  // v > lo
    auto last = std::upper_bound(values.begin(), values.end(), hi);   // v <= hi
    if (first == last) return;
    const double* a = attr.empty() ? nullptr : &attr[4 * std::size_t(t)];
    // Levels of one linear field are parallel planes: if the eye sees their hot side the higher
    // values are nearer, so ascending values go far to near; else descending. (An eye between two
    // of them sees them on disjoint pixels: their order does not matter.)
    IsoPolygon p = iso_polygon(*mesh, t, c, *first, a);
    Vert v0;
    proj.to_camera(p.xyz[0], v0.c);
    const bool ascending = faces_eye(p.hot, v0.c);
    const std::ptrdiff_t n = last - first;
    for (std::ptrdiff_t k = 0; k < n; ++k) {
      const double value = ascending ? first[k] : first[n - 1 - k];
      if (k > 0 || !ascending) p = iso_polygon(*mesh, t, c, value, a);
      if (p.count == 0) continue;
      Vert v[4];
      for (int i = 0; i < p.count; ++i) {
        proj.to_camera(p.xyz[i], v[i].c);
        v[i].pos = a != nullptr ? params.scale.position(p.attr[i]) : 0;
      }
      float rgb[3] = {0, 0, 0};
      if (a == nullptr) entry_rgb(value, rgb);
      float f = shade(p.hot, v[0].c);
      if (!faces_eye(p.hot, v[0].c)) f *= float(params.cold_side);
      draw_polygon(fb, t, v, p.count, a != nullptr, rgb, f, rows);
    }
  }

  // Cap mode, a tet the lowest value cuts: the front faces of its part above the value.
  void draw_cut(Framebuffer& fb, std::uint32_t t) {
    const double* c = &corner[4 * std::size_t(t)];
    const double v = values.front();
    const std::uint32_t* n = &mesh->tet[4 * std::size_t(t)];
    for (int f = 0; f < 4; ++f) {
      // Face f clipped to values >= v: its corners above v and the crossing points of its edges.
      Vert poly[kMaxPoly];
      double world[kMaxPoly][3];
      int m = 0;
      for (int i = 0; i < 3; ++i) {
        const int a = kFace[f][i], b = kFace[f][(i + 1) % 3];
        // Mesh edges: from a corner above v along its face edge (to the next corner or to the
        // crossing), and from a crossing toward a corner above; not along the cut (crossing to crossing).
        if (c[a] >= v) {
          for (int k = 0; k < 3; ++k) world[m][k] = mesh->xyz[3 * std::size_t(n[a]) + std::size_t(k)];
          poly[m].mesh_edge = true;
          poly[m++].pos = params.scale.position(c[a]);
        }
        if ((c[a] >= v) != (c[b] >= v)) {
          double dummy;
          iso_detail::edge_point(*mesh, t, c, v, a, b, nullptr, world[m], &dummy);
          poly[m].mesh_edge = !(c[a] >= v);
          poly[m++].pos = params.scale.position(v);
        }
      }
      if (m < 3) continue;
      // Outward normal of the tet face (kFace winds outward for a positively oriented tet).
      const double* p0 = &mesh->xyz[3 * std::size_t(n[kFace[f][0]])];
      const double* p1 = &mesh->xyz[3 * std::size_t(n[kFace[f][1]])];
      const double* p2 = &mesh->xyz[3 * std::size_t(n[kFace[f][2]])];
      double u[3], w[3], nn[3];
      for (int k = 0; k < 3; ++k) u[k] = p1[k] - p0[k], w[k] = p2[k] - p0[k];
      nn[0] = u[1] * w[2] - u[2] * w[1];
      nn[1] = u[2] * w[0] - u[0] * w[2];
      nn[2] = u[0] * w[1] - u[1] * w[0];
      for (int i = 0; i < m; ++i) proj.to_camera(world[i], poly[i].c);
      if (!faces_eye(nn, poly[0].c)) continue;
      draw_polygon(fb, t, poly, m, true, nullptr, shade(nn, poly[0].c));
    }
    // The cut face: outward from the part above v is toward decreasing values.
    const IsoPolygon p = iso_polygon(*mesh, t, c, v);
    if (p.count == 0) return;
    const double out[3] = {-p.hot[0], -p.hot[1], -p.hot[2]};
    Vert vv[4];
    for (int i = 0; i < p.count; ++i) proj.to_camera(p.xyz[i], vv[i].c), vv[i].pos = 0;
    if (!faces_eye(out, vv[0].c)) return;
    float rgb[3];
    entry_rgb(v, rgb);
    draw_polygon(fb, t, vv, p.count, false, rgb, shade(out, vv[0].c));
  }
};

IsoPainter::IsoPainter(const MeshView& mesh, const Camera& camera, int width, int height,
                       std::span<const double> corner, const IsoParams& params,
                       const RenderParams& tet_params, std::span<const double> attr)
    : impl_(std::make_unique<Impl>(mesh, camera, width, height)) {
  Impl& s = *impl_;
  if (corner.size() != mesh.tet.size())
    throw std::invalid_argument("isosurface: " + std::to_string(corner.size()) +
                                " corner values for a mesh of " + std::to_string(mesh.tet_count()) +
                                " tets (4 per tet expected)");
  if (!attr.empty() && attr.size() != mesh.tet.size())
    throw std::invalid_argument("isosurface: " + std::to_string(attr.size()) +
                                " attribute values (4 per tet expected)");
  if (!(params.shade_min >= 0 && params.shade_min <= 1) || !(params.cold_side >= 0 && params.cold_side <= 1))
    throw std::invalid_argument("isosurface: shade_min and cold_side must be in [0, 1]");
  s.corner = corner;
  s.attr = attr;
  s.params = params;
  for (double v : params.values)
    if (!std::isnan(v)) s.values.push_back(v);
  std::sort(s.values.begin(), s.values.end());
  s.values.erase(std::unique(s.values.begin(), s.values.end()), s.values.end());
  s.depth = tet_params.depth_buffer;
  s.undoable = tet_params.undoable;
  if (s.undoable && s.depth)
    throw std::invalid_argument("isosurface: undoable drawing is the painter's, not the depth buffer's");
  const double l[3] = {-0.3, 0.45, -1};  // the tet painter's light (rasterizer.cpp)
  const double ln = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  for (int k = 0; k < 3; ++k) s.light[k] = l[k] / ln;
  for (int i = 0; i < 256; ++i) {
    const std::uint32_t e = color_map_entry(params.scale.map, i);
    for (int k = 0; k < 3; ++k) s.lut[i][k] = float((e >> (8 * k)) & 255u);
  }
  // Cap mode draws whole tets with the tet painter (its setup projects every node); the polygons alone
  // need no per-mesh setup, so a new isovalue or view costs only the tets it crosses: their near plane
  // is chosen per polygon (draw_polygon).
  s.near_given = tet_params.near;
  s.edges = params.cap && tet_params.edges && tet_params.edge_width > 0;
  s.edge_width = tet_params.edge_width;
  s.edge_base = 1 - tet_params.edge_darkness;
  s.edge_slope = s.edges ? tet_params.edge_darkness / tet_params.edge_width : 0;
  if (params.cap) s.solid.emplace(mesh, camera, width, height, tet_params);
}

IsoPainter::~IsoPainter() = default;
IsoPainter::IsoPainter(IsoPainter&&) noexcept = default;
IsoPainter& IsoPainter::operator=(IsoPainter&&) noexcept = default;

void IsoPainter::draw(Framebuffer& fb, std::span<const std::uint32_t> tets) {
  Impl& s = *impl_;
  if (fb.width != s.proj.width || fb.height != s.proj.height)
    throw std::invalid_argument("isosurface: framebuffer size differs from the painter's");
  if (s.depth && fb.depth.size() != fb.rgba.size())
    throw std::invalid_argument("isosurface: depth-buffer mode needs a framebuffer with a depth buffer");
  if (s.depth) ensure_depth_slopes(fb);
  for (std::uint32_t t : tets)
    if (t >= s.mesh->tet_count()) throw std::invalid_argument("isosurface: tet index out of range");
  if (s.values.empty()) {  // nothing to draw; the tets still count as drawn (undraw)
    for (std::size_t i = 0; i < tets.size(); ++i) s.begin_tet();
    return;
  }
  if (!s.params.cap) {
    // One thread: splitting the rows between two (the tet painter's bands) doubled the CPU time for
    // no gain in wall time (bench_iso, 1%: each thread repeats every polygon's setup, which costs
    // more than its pixels).
    {
      const Rows rows;
      // The tets of a visibility order lie all over memory: fetch a tet's corner values and nodes
      // a few tets ahead (its node indices further ahead still), or each tet waits on ~6 misses.
      const std::size_t n = tets.size();
      for (std::size_t i = 0; i < n; ++i) {
        if (i + 16 < n) {
          __builtin_prefetch(&s.corner[4 * std::size_t(tets[i + 16])]);
          __builtin_prefetch(&s.mesh->tet[4 * std::size_t(tets[i + 16])]);
        }
        if (i + 8 < n) {
          const std::uint32_t* nv = &s.mesh->tet[4 * std::size_t(tets[i + 8])];
          for (int k = 0; k < 4; ++k) __builtin_prefetch(&s.mesh->xyz[3 * std::size_t(nv[k])]);
        }
        s.begin_tet();
        s.draw_surfaces(fb, tets[i], rows);
      }
    }
    return;
  }
  // Runs of whole tets go to the tet painter; each cut tet is drawn here in between.
  const double v = s.values.front();
  std::size_t run = 0;
  for (std::size_t i = 0; i < tets.size(); ++i) {
    const double* c = &s.corner[4 * std::size_t(tets[i])];
    const double lo = std::min({c[0], c[1], c[2], c[3]});
    if (lo >= v) continue;  // whole (a NaN corner compares false: cut, drawn by its finite part)
    if (i > run) s.solid_run(fb, tets.subspan(run, i - run));
    run = i + 1;
    s.begin_tet();
    if (std::max({c[0], c[1], c[2], c[3]}) >= v) s.draw_cut(fb, tets[i]);
  }
  if (tets.size() > run) s.solid_run(fb, tets.subspan(run));
}

void IsoPainter::undraw(Framebuffer& fb, std::size_t count) {
  Impl& s = *impl_;
  if (!s.undoable) throw std::logic_error("isosurface: undraw needs RenderParams::undoable");
  if (count > s.drawn)
    throw std::out_of_range("isosurface: undraw of " + std::to_string(count) + " tets, " +
                            std::to_string(s.drawn) + " drawn");
  while (count > 0) {
    Impl::Step& st = s.steps.back();
    if (st.solid) {
      const std::size_t m = std::min(count, st.count);
      s.solid->undraw(fb, m);
      st.count -= m;
      count -= m;
      s.drawn -= m;
      if (st.count == 0) s.steps.pop_back();
      continue;
    }
    // Restored in reverse writing order: each pixel ends as it was before the tet's first write.
    for (std::size_t i = s.saved_pixel.size(); i-- > st.save_begin;) {
      fb.rgba[s.saved_pixel[i]] = s.saved_rgba[i];
      fb.id[s.saved_pixel[i]] = s.saved_id[i];
    }
    s.saved_pixel.resize(st.save_begin);
    s.saved_rgba.resize(st.save_begin);
    s.saved_id.resize(st.save_begin);
    s.steps.pop_back();
    --count;
    --s.drawn;
  }
}

std::size_t IsoPainter::drawn_tets() const { return impl_->drawn; }

std::size_t IsoPainter::polygons_drawn() const { return impl_->polygons; }

}  // namespace foxi
