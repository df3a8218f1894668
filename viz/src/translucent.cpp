// Translucent regions and isosurfaces (translucent.hpp): the surfaces to draw, the painter that
// blends each tet's fragments at its place in the order (with the tet painter's fixed point and fill
// rule, raster_triangle, so a surface made of many faces covers each pixel once), and the safe
// picture (power order, or per-pixel sorting without the certificate).
#include "foxi/viz/translucent.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "exact.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "raster_impl.hpp"

namespace foxi {

using namespace raster_detail;

namespace {

constexpr int kMaxPoly = 10;

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// Whether tet t's corner values cross one of the ascending `values` (IsoPainter's rule: min < v <= max).
bool crosses(const double* c, const std::vector<double>& values) {
  const double lo = std::min({c[0], c[1], c[2], c[3]}), hi = std::max({c[0], c[1], c[2], c[3]});
  if (!(lo < hi)) return false;
  return std::upper_bound(values.begin(), values.end(), lo) !=
         std::upper_bound(values.begin(), values.end(), hi);
}

std::vector<double> sorted_values(const IsoParams& iso) {
  std::vector<double> v;
  for (double x : iso.values)
    if (!std::isnan(x)) v.push_back(x);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

}  // namespace

TranslucentSurfaces translucent_surfaces(const Mesh& mesh, std::span<const std::uint32_t> subset,
                                         const TranslucentParams& params) {
  const std::size_t n = mesh.tet_count();
  auto bad_opacity = [](double a) { return !(a >= 0 && a <= 1); };
  if (bad_opacity(params.default_opacity) || bad_opacity(params.iso_opacity))
    throw std::invalid_argument("translucent: opacities must lie in [0, 1]");
  for (const RegionOpacity& r : params.region_opacity)
    if (bad_opacity(r.opacity))
      throw std::invalid_argument("translucent: region " + std::to_string(r.region) + ": opacity " +
                                  std::to_string(r.opacity) + " is not in [0, 1]");
  if (!params.corner.empty() && params.corner.size() != mesh.tet.size())
    throw std::invalid_argument("translucent: " + std::to_string(params.corner.size()) +
                                " corner values for a mesh of " + std::to_string(n) +
                                " tets (4 per tet expected)");
  TranslucentSurfaces s;
  std::vector<std::uint8_t> member(n, subset.empty() ? 1 : 0);
  for (std::uint32_t t : subset) {
    if (t >= n) throw std::invalid_argument("translucent: tet index out of range");
    member[t] = 1;
  }
  // The opacity of each region met, looked up once per run of tets of one region.
  s.opacity.assign(n, 0.0f);
  std::int32_t last_region = 0;
  float last_opacity = -1;
  for (std::size_t t = 0; t < n; ++t) {
    if (!member[t]) continue;
    const std::int32_t r = mesh.region_of(t);
    if (last_opacity < 0 || r != last_region) {
      last_region = r;
      last_opacity = float(params.default_opacity);
      for (const RegionOpacity& ro : params.region_opacity)
        if (ro.region == r) last_opacity = float(ro.opacity);
    }
    s.opacity[t] = last_opacity;
  }
  s.mask.assign(n, 0);
  if (params.regions) {
    const FaceAdjacency& adj = face_adjacency(mesh);
    for (std::size_t t = 0; t < n; ++t) {
      const float a = s.opacity[t];
      if (!(a > 0)) continue;
      std::uint8_t m = 0;
      for (int f = 0; f < 4; ++f) {
        const std::uint32_t u = adj.neighbour[4 * t + std::size_t(f)];
        const float b = u == kNone ? 0.0f : s.opacity[u / 4];
        if (!(b > 0)) {
          m |= std::uint8_t(1u << f);
          ++s.boundary_faces;
        } else if (a != b) {
          m |= std::uint8_t(16u << f);
          if (a > b) ++s.interface_faces;  // counted once, from the more opaque side
        }
      }
      s.mask[t] = m;
    }
  }
  const std::vector<double> values = sorted_values(params.iso);
  const bool iso = !params.corner.empty() && !values.empty();
  for (std::size_t t = 0; t < n; ++t) {
    const bool crossed = iso && member[t] && crosses(&params.corner[4 * t], values);
    s.iso_tets += crossed;
    if (crossed || s.mask[t] != 0) s.tets.push_back(std::uint32_t(t));
  }
  return s;
}

struct TranslucentPainter::Impl {
  const Mesh* mesh = nullptr;
  const TranslucentSurfaces* surf = nullptr;
  const FaceAdjacency* adj = nullptr;
  TranslucentParams params;
  Projector proj;
  std::vector<double> values;  // ascending isovalues
  double light[3] = {0, 0, -1};
  bool collect = false;
  int lanes = 1;
  std::vector<float> acc;            // 3 per pixel
  std::vector<std::uint32_t> front;  // per pixel: the tet of the last fragment blended
  std::vector<Fragment> frags;
  std::size_t blended = 0;
  std::vector<std::size_t> lane_blended;

  Impl(const Mesh& m, const Camera& camera, int w, int h) : mesh(&m), proj(camera, w, h) {}

  std::uint32_t region_rgb(std::uint32_t t) const {
    const std::int32_t r = mesh->region_of(t);
    return r >= 0 && std::size_t(r) < params.region_colors.size() ? params.region_colors[std::size_t(r)]
                                                                  : region_color(r);
  }

  // Blends (or collects) a convex polygon in camera coordinates with colour rgb and opacity alpha.
  void polygon(const double (*in)[3], int n, std::uint32_t tet, int face, const float rgb[3], float alpha,
               const Rows& rows, std::size_t& count) {
    double v[kMaxPoly][3];
    n = clip_near(proj, params.near, in, n, v);
    if (n == 0) return;
    std::int64_t X[kMaxPoly], Y[kMaxPoly];
    double px[kMaxPoly][2], w[kMaxPoly];
    snap_polygon(
        proj, n, [&](int i) { return v[i]; }, X, Y, px, w);
    const int width = proj.width;
    for_each_fan_triangle(X, Y, n, [&](const std::int64_t* TX, const std::int64_t* TY, const int* idx) {
      if (collect) {
        // Nearness as an affine function of the screen (perspective-correct: 1/z is affine there).
        const double x0 = px[idx[0]][0], y0 = px[idx[0]][1];
        const double ax = px[idx[1]][0] - x0, ay = px[idx[1]][1] - y0;
        const double bx = px[idx[2]][0] - x0, by = px[idx[2]][1] - y0;
        const double det = ax * by - ay * bx;
        const double w0 = w[idx[0]], w1 = w[idx[1]], w2 = w[idx[2]];
        const double wa = ((w1 - w0) * by - (w2 - w0) * ay) / det,
                     wb = ((w2 - w0) * ax - (w1 - w0) * bx) / det;
        raster_triangle(TX, TY, width, proj.height, rows, [&](int y, int lo, int hi) {
          for (int x = lo; x <= hi; ++x) {
            Fragment f;
            f.pixel = std::uint32_t(std::size_t(y) * std::size_t(width) + std::size_t(x));
            f.tet = tet;
            f.face = std::int8_t(face);
            f.depth = float(w0 + wa * (x + 0.5 - x0) + wb * (y + 0.5 - y0));
            std::copy(rgb, rgb + 3, f.rgb);
            f.alpha = alpha;
            if (frags.size() >= params.max_fragments)
              throw TooManyFragments(
                  "translucent: more than " + std::to_string(params.max_fragments) + " fragments (" +
                  std::to_string(params.max_fragments * sizeof(Fragment) >> 20) +
                  " MiB) to sort per pixel (a mesh without the Delaunay certificate has no order to "
                  "blend them in): draw a smaller picture, or fewer translucent regions or isosurfaces");
            frags.push_back(f);
          }
        });
      } else {
        raster_triangle(TX, TY, width, proj.height, rows, [&](int y, int lo, int hi) {
          const std::size_t row = std::size_t(y) * std::size_t(width);
          float* c = &acc[3 * (row + std::size_t(lo))];
          for (int x = lo; x <= hi; ++x, c += 3) blend_over(c, rgb, alpha);
          std::fill(front.begin() + std::ptrdiff_t(row) + lo, front.begin() + std::ptrdiff_t(row) + hi + 1,
                    tet);
          count += std::size_t(hi - lo + 1);
        });
      }
    });
  }

  // Lambert factor of a face whose normal (camera frame, any length) points to the eye's side.
  double lambert(const double nc[3], double ambient) const {
    const double len = std::sqrt(nc[0] * nc[0] + nc[1] * nc[1] + nc[2] * nc[2]);
    const double s = len > 0 ? (nc[0] * light[0] + nc[1] * light[1] + nc[2] * light[2]) / len : 0;
    return std::clamp(ambient + (1 - ambient) * std::max(0.0, s), 0.0, 1.0);
  }

  // +1 if face f of tet t faces the eye (the eye on its outer side), -1 if it faces away, 0 edge-on:
  // exact, so the two tets of a face always agree which of them it is a front face of.
  int facing(const std::uint32_t* node, int f) const {
    const double* a = &mesh->xyz[3 * std::size_t(node[kFace[f][0]])];
    const double* b = &mesh->xyz[3 * std::size_t(node[kFace[f][1]])];
    const double* c = &mesh->xyz[3 * std::size_t(node[kFace[f][2]])];
    if (proj.perspective) return exact::orientation(a, b, c, proj.eye);
    const double back[3] = {-proj.forward[0], -proj.forward[1], -proj.forward[2]};
    return exact::orientation_at_infinity(a, b, c, back);
  }

  void draw_face(std::uint32_t t, const double (*cam)[3], int f, bool front_face, bool interface,
                 const Rows& rows, std::size_t& count) {
    std::uint32_t owner = t;  // whose colour the face shows
    float alpha = surf->opacity[t];
    if (interface) {
      const std::uint32_t u = adj->neighbour[4 * std::size_t(t) + std::size_t(f)] / 4;
      if (surf->opacity[u] > alpha) owner = u, alpha = surf->opacity[u];
    }
    const double* p[3] = {cam[kFace[f][0]], cam[kFace[f][1]], cam[kFace[f][2]]};
    const double poly[3][3] = {
        {p[0][0], p[0][1], p[0][2]}, {p[1][0], p[1][1], p[1][2]}, {p[2][0], p[2][1], p[2][2]}};
    // Outward normal in the camera frame: the frame is a mirror of the world, so it is -(b-a)x(c-a).
    const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double w[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    double nc[3] = {-(u[1] * w[2] - u[2] * w[1]), -(u[2] * w[0] - u[0] * w[2]), -(u[0] * w[1] - u[1] * w[0])};
    if (!front_face)
      for (double& x : nc) x = -x;
    const float shade = float(lambert(nc, params.ambient));
    const std::uint32_t base = region_rgb(owner);
    const float rgb[3] = {float(base & 255u) * shade, float((base >> 8) & 255u) * shade,
                          float((base >> 16) & 255u) * shade};
    polygon(poly, 3, t, f, rgb, alpha, rows, count);
  }

  void draw_iso(std::uint32_t t, const Rows& rows, std::size_t& count) {
    const double* c = &params.corner[4 * std::size_t(t)];
    const double lo = std::min({c[0], c[1], c[2], c[3]}), hi = std::max({c[0], c[1], c[2], c[3]});
    if (!(lo < hi)) return;
    auto first = std::upper_bound(values.begin(), values.end(), lo);
    auto last = std::upper_bound(values.begin(), values.end(), hi);
    if (first == last) return;
    // Levels of one linear field are parallel planes: ascending values go far to near when the eye
    // sees their hot side (the side of increasing value), descending otherwise.
    IsoPolygon p = iso_polygon(*mesh, t, c, *first);
    double c0[3];
    proj.to_camera(p.xyz[0], c0);
    double hot[3];
    to_camera_dir(p.hot, hot);
    const bool ascending =
        proj.perspective ? hot[0] * c0[0] + hot[1] * c0[1] + hot[2] * c0[2] < 0 : hot[2] < 0;
    // The normal toward the eye: the hot direction if the eye sees the hot side (ascending).
    double toward_eye[3];
    for (int k = 0; k < 3; ++k) toward_eye[k] = ascending ? hot[k] : -hot[k];
    double shade = lambert(toward_eye, params.iso.shade_min);
    if (!ascending) shade *= params.iso.cold_side;
    const std::ptrdiff_t n = last - first;
    for (std::ptrdiff_t k = 0; k < n; ++k) {
      const std::ptrdiff_t i = ascending ? k : n - 1 - k;
      const double value = first[i];
      if (k > 0 || !ascending) p = iso_polygon(*mesh, t, c, value);
      if (p.count == 0) continue;
      double v[4][3];
      for (int j = 0; j < p.count; ++j) proj.to_camera(p.xyz[j], v[j]);
      const std::uint32_t col = params.iso.scale.color(value);
      const float rgb[3] = {float(col & 255u) * float(shade), float((col >> 8) & 255u) * float(shade),
                            float((col >> 16) & 255u) * float(shade)};
      polygon(v, p.count, t, -1 - int(first - values.begin() + i), rgb, float(params.iso_opacity), rows,
              count);
    }
  }

  void to_camera_dir(const double d[3], double out[3]) const {
    out[0] = d[0] * proj.right[0] + d[1] * proj.right[1] + d[2] * proj.right[2];
    out[1] = d[0] * proj.up[0] + d[1] * proj.up[1] + d[2] * proj.up[2];
    out[2] = d[0] * proj.forward[0] + d[1] * proj.forward[1] + d[2] * proj.forward[2];
  }

  // One tet's fragments in their order along every ray: back faces, iso polygons far to near, front faces.
  void draw_tet(std::uint32_t t, const Rows& rows, std::size_t& count) {
    const std::uint8_t m = surf->mask[t];
    const bool iso = !values.empty() && !params.corner.empty();
    if (m == 0 && !iso) return;
    const std::uint32_t* node = &mesh->tet[4 * std::size_t(t)];
    double cam[4][3];
    int face_dir[4] = {0, 0, 0, 0};
    if (m != 0) {
      for (int k = 0; k < 4; ++k) proj.to_camera(&mesh->xyz[3 * std::size_t(node[k])], cam[k]);
      for (int f = 0; f < 4; ++f)
        if (m & (0x11u << f)) face_dir[f] = facing(node, f);
      for (int f = 0; f < 4; ++f)  // back faces: boundary faces only (an interface is drawn from behind)
        if ((m & (1u << f)) && face_dir[f] < 0) draw_face(t, cam, f, false, false, rows, count);
    }
    if (iso) draw_iso(t, rows, count);
    for (int f = 0; f < 4; ++f)
      if ((m & (0x11u << f)) && face_dir[f] > 0)
        draw_face(t, cam, f, true, (m & (1u << f)) == 0, rows, count);
  }
};

TranslucentPainter::TranslucentPainter(const Mesh& mesh, const Camera& camera, int width, int height,
                                       const TranslucentSurfaces& surfaces, const TranslucentParams& params,
                                       bool collect)
    : impl_(std::make_unique<Impl>(mesh, camera, width, height)) {
  Impl& s = *impl_;
  if (surfaces.mask.size() != mesh.tet_count() || surfaces.opacity.size() != mesh.tet_count())
    throw std::invalid_argument("translucent: the surfaces belong to another mesh");
  if (!params.corner.empty() && params.corner.size() != mesh.tet.size())
    throw std::invalid_argument("translucent: corner values of the wrong size");
  if (!(params.iso.shade_min >= 0 && params.iso.shade_min <= 1) ||
      !(params.iso.cold_side >= 0 && params.iso.cold_side <= 1))
    throw std::invalid_argument("translucent: shade_min and cold_side must be in [0, 1]");
  if (!(params.ambient >= 0 && params.ambient <= 1))
    throw std::invalid_argument("translucent: ambient must be in [0, 1]");
  s.surf = &surfaces;
  s.adj = &face_adjacency(mesh);
  s.params = params;
  s.values = sorted_values(params.iso);
  s.collect = collect;
  const double l[3] = {-0.3, 0.45, -1};  // the tet painter's light (rasterizer.cpp)
  const double ln = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  for (int k = 0; k < 3; ++k) s.light[k] = l[k] / ln;
  s.lanes = collect ? 1 : std::clamp(params.threads, 1, std::max(1, height >> kBandShift));
  s.lane_blended.assign(std::size_t(s.lanes), 0);
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  if (!collect) {
    s.acc.resize(3 * pixels);
    const float bg[3] = {float(params.background & 255u), float((params.background >> 8) & 255u),
                         float((params.background >> 16) & 255u)};
    for (std::size_t p = 0; p < pixels; ++p) std::copy(bg, bg + 3, &s.acc[3 * p]);
    s.front.assign(pixels, kNone);
  }
}

TranslucentPainter::~TranslucentPainter() = default;
TranslucentPainter::TranslucentPainter(TranslucentPainter&&) noexcept = default;
TranslucentPainter& TranslucentPainter::operator=(TranslucentPainter&&) noexcept = default;

void TranslucentPainter::draw(std::span<const std::uint32_t> tets) {
  Impl& s = *impl_;
  for (std::uint32_t t : tets)
    if (t >= s.mesh->tet_count()) throw std::invalid_argument("translucent: tet index out of range");
  run_parts(s.lanes, [&](int lane) {
    const Rows rows{lane, s.lanes};
    std::size_t count = 0;
    for (std::uint32_t t : tets) s.draw_tet(t, rows, count);
    s.lane_blended[std::size_t(lane)] += count;
  });
}

void TranslucentPainter::resolve(Framebuffer& fb) {
  Impl& s = *impl_;
  const int w = s.proj.width, h = s.proj.height;
  fb.resize(w, h, false, s.params.background);
  const std::size_t pixels = std::size_t(w) * std::size_t(h);
  auto to8 = [](float c) { return std::uint32_t(std::clamp(c, 0.0f, 255.0f) + 0.5f); };
  if (!s.collect) {
    for (std::size_t p = 0; p < pixels; ++p) {
      fb.rgba[p] = pack_rgba(to8(s.acc[3 * p]), to8(s.acc[3 * p + 1]), to8(s.acc[3 * p + 2]));
      fb.id[p] = s.front[p];
    }
    return;
  }
  // Per pixel, the fragments far to near by their depth (stable: exact ties keep the drawing order).
  std::vector<std::uint32_t> start(pixels + 1, 0);
  for (const Fragment& f : s.frags) ++start[f.pixel + 1];
  for (std::size_t p = 0; p < pixels; ++p) start[p + 1] += start[p];
  std::vector<std::uint32_t> slot(start.begin(), start.end() - 1), by_pixel(s.frags.size());
  for (std::size_t i = 0; i < s.frags.size(); ++i) by_pixel[slot[s.frags[i].pixel]++] = std::uint32_t(i);
  const float bg[3] = {float(s.params.background & 255u), float((s.params.background >> 8) & 255u),
                       float((s.params.background >> 16) & 255u)};
  for (std::size_t p = 0; p < pixels; ++p) {
    if (start[p] == start[p + 1]) continue;
    auto b = by_pixel.begin() + start[p], e = by_pixel.begin() + start[p + 1];
    std::stable_sort(b, e,
                     [&](std::uint32_t i, std::uint32_t j) { return s.frags[i].depth < s.frags[j].depth; });
    float c[3] = {bg[0], bg[1], bg[2]};
    for (auto it = b; it != e; ++it) blend_over(c, s.frags[*it].rgb, s.frags[*it].alpha);
    fb.rgba[p] = pack_rgba(to8(c[0]), to8(c[1]), to8(c[2]));
    fb.id[p] = s.frags[*(e - 1)].tet;
  }
}

const std::vector<Fragment>& TranslucentPainter::fragments() const { return impl_->frags; }

std::size_t TranslucentPainter::fragment_count() const {
  if (impl_->collect) return impl_->frags.size();
  std::size_t n = 0;
  for (std::size_t c : impl_->lane_blended) n += c;
  return n;
}

TranslucentReport draw_translucent_picture(const Mesh& mesh, const SphereTable& table, const Camera& camera,
                                           Framebuffer& fb, std::span<const std::uint32_t> subset,
                                           const TranslucentParams& params) {
  if (fb.width < 1 || fb.height < 1)
    throw std::invalid_argument("draw_translucent_picture: the framebuffer is empty");
  if (table.tet_count() != mesh.tet_count())
    throw std::invalid_argument("draw_translucent_picture: the sphere table belongs to another mesh");
  TranslucentReport report;
  auto t0 = std::chrono::steady_clock::now();
  report.delaunay = delaunay_certificate(mesh).delaunay;
  report.certificate_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  const TranslucentSurfaces surfaces = translucent_surfaces(mesh, subset, params);
  report.surfaces_ms = ms_since(t0);
  report.tets_ordered = surfaces.tets.size();
  report.exact_order = report.delaunay;
  t0 = std::chrono::steady_clock::now();
  // An empty span would order the whole mesh: no surface tets, nothing to order.
  std::vector<std::uint32_t> order;
  if (!surfaces.tets.empty()) {
    if (report.delaunay)
      order = visibility_order(mesh, table, view_of(camera), surfaces.tets);
    else
      order = surfaces.tets;  // any order: the fragments are sorted per pixel
  }
  report.order_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  TranslucentPainter painter(mesh, camera, fb.width, fb.height, surfaces, params, !report.delaunay);
  painter.draw(order);
  painter.resolve(fb);
  report.fragments = painter.fragment_count();
  report.draw_ms = ms_since(t0);
  return report;
}

}  // namespace foxi
