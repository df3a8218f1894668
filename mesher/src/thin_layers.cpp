#include "foxi/mesher/thin_layers.hpp"

#include <algorithm>
#include <cmath>

#include "plc_edit.hpp"

namespace foxi {

namespace {

using detail::cross;
using detail::dot;
using detail::Vec;

Vec unit(const Vec& a) {
  const double n = std::sqrt(dot(a, a));
  return {a[0] / n, a[1] / n, a[2] / n};
}

struct FacetPlane {
  Vec normal{};  // unit, sign canonical (largest component positive) so parallel facets agree
  double offset = 0, u_lo = 0, u_hi = 0, v_lo = 0, v_hi = 0;
};

// A frame (u, v) in the plane of a canonical normal, the same for all parallel facets.
void plane_frame(const Vec& n, Vec& u, Vec& v) {
  std::size_t k = 0;
  for (std::size_t i = 1; i < 3; ++i)
    if (std::abs(n[i]) < std::abs(n[k])) k = i;
  Vec e{0, 0, 0};
  e[k] = 1;
  u = unit(cross(n, e));
  v = cross(n, u);
}

}  // namespace

bool ThinLayer::contains(const double* p) const {
  const Vec q{p[0], p[1], p[2]};
  const double h = dot(normal, q), a = dot(u, q), b = dot(v, q);
  return h >= lo - tolerance && h <= hi + tolerance && a >= u_lo - tolerance && a <= u_hi + tolerance &&
         b >= v_lo - tolerance && b <= v_hi + tolerance;
}

std::vector<ThinLayer> find_thin_layers(const Plc& plc, double min_aspect, double min_area) {
  std::vector<ThinLayer> layers;
  if (!(min_aspect > 0) || plc.point_count() == 0) return layers;
  Vec lo{plc.points[0], plc.points[1], plc.points[2]}, hi = lo;
  for (std::size_t i = 0; i < plc.point_count(); ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], plc.points[3 * i + k]);
      hi[k] = std::max(hi[k], plc.points[3 * i + k]);
    }
  const double diag = std::sqrt(detail::norm2(detail::sub(hi, lo)));
  const double tol = 1e-9 * diag;
  auto point = [&](std::uint32_t i) { return detail::at(plc.points, i); };

  std::vector<FacetPlane> planes;
  for (std::size_t f = 0; f < plc.facet_count(); ++f) {
    // Newell normal of the facet's polygons (all coplanar in a valid PLC).
    Vec n{0, 0, 0};
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
      const std::uint32_t b = plc.polygon_vertex_begin[g], e = plc.polygon_vertex_begin[g + 1];
      detail::add_newell_normal(plc.points, &plc.polygon_vertices[b], e - b, n);
    }
    const double nn = std::sqrt(dot(n, n));
    if (!(nn > tol * tol)) continue;
    n = {n[0] / nn, n[1] / nn, n[2] / nn};
    std::size_t big = 0;
    for (std::size_t k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[big])) big = k;
    if (n[big] < 0) n = {-n[0], -n[1], -n[2]};
    Vec u, v;
    plane_frame(n, u, v);
    FacetPlane fp;
    fp.normal = n;
    bool first = true, flat = true;
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g)
      for (std::uint32_t i = plc.polygon_vertex_begin[g]; i < plc.polygon_vertex_begin[g + 1]; ++i) {
        const Vec p = point(plc.polygon_vertices[i]);
        const double h = dot(n, p), a = dot(u, p), b = dot(v, p);
        if (first) {
          fp.offset = h;
          fp.u_lo = fp.u_hi = a;
          fp.v_lo = fp.v_hi = b;
          first = false;
        }
        flat = flat && std::abs(h - fp.offset) <= 1e3 * tol;
        fp.u_lo = std::min(fp.u_lo, a);
        fp.u_hi = std::max(fp.u_hi, a);
        fp.v_lo = std::min(fp.v_lo, b);
        fp.v_hi = std::max(fp.v_hi, b);
      }
    if (!first && flat) planes.push_back(fp);
  }

  for (std::size_t i = 0; i < planes.size(); ++i)
    for (std::size_t j = i + 1; j < planes.size(); ++j) {
      const FacetPlane &a = planes[i], &b = planes[j];
      if (dot(a.normal, b.normal) < 1 - 1e-12) continue;
      const double gap = std::abs(a.offset - b.offset);
      if (!(gap > 1e3 * tol)) continue;
      const double u0 = std::max(a.u_lo, b.u_lo), u1 = std::min(a.u_hi, b.u_hi);
      const double v0 = std::max(a.v_lo, b.v_lo), v1 = std::min(a.v_hi, b.v_hi);
      if (u1 - u0 < min_aspect * gap || v1 - v0 < min_aspect * gap ||
          (u1 - u0) * (v1 - v0) < min_area * gap * gap)
        continue;
      ThinLayer l;
      l.normal = a.normal;
      plane_frame(l.normal, l.u, l.v);
      l.lo = std::min(a.offset, b.offset);
      l.hi = std::max(a.offset, b.offset);
      l.u_lo = u0;
      l.u_hi = u1;
      l.v_lo = v0;
      l.v_hi = v1;
      l.tolerance = 1e-6 * gap + 1e3 * tol;
      layers.push_back(l);
    }

  // Drop layers inside others (the same slab is found from several facet pairs).
  auto inside = [](const ThinLayer& a, const ThinLayer& b) {  // a within b
    return dot(a.normal, b.normal) >= 1 - 1e-12 && a.lo >= b.lo - b.tolerance && a.hi <= b.hi + b.tolerance &&
           a.u_lo >= b.u_lo - b.tolerance && a.u_hi <= b.u_hi + b.tolerance &&
           a.v_lo >= b.v_lo - b.tolerance && a.v_hi <= b.v_hi + b.tolerance;
  };
  std::vector<ThinLayer> kept;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    bool dropped = false;
    for (std::size_t j = 0; j < layers.size() && !dropped; ++j)
      if (j != i && inside(layers[i], layers[j]) && (!inside(layers[j], layers[i]) || j < i)) dropped = true;
    if (!dropped) kept.push_back(layers[i]);
  }
  return kept;
}

bool tet_in_thin_layer(const Mesh& mesh, std::size_t t, const std::vector<ThinLayer>& layers) {
  const std::uint32_t* v = &mesh.tet[4 * t];
  for (const ThinLayer& l : layers)
    if (l.contains(&mesh.xyz[3 * v[0]]) && l.contains(&mesh.xyz[3 * v[1]]) &&
        l.contains(&mesh.xyz[3 * v[2]]) && l.contains(&mesh.xyz[3 * v[3]]))
      return true;
  return false;
}

}  // namespace foxi
