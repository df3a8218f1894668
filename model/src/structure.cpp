// Parts -> PLC by z slabs and planar arrangements (see structure.hpp).
//
// Every part is a set of vertical prisms. The z values of all prism tops and bottoms cut space into
// slabs. In slab k, the footprint edges of the prisms active there form a planar arrangement A_k
// (CGAL Arrangement_2, exact constructions, so touching and crossing footprints are split where they
// meet); every bounded face of A_k is owned by the last part whose prism covers it. At level z, the
// arrangement of the edges of both neighbouring slabs gives the horizontal facets: a face whose owner
// below differs from its owner above becomes a facet (outer boundary, inner boundaries with a hole
// point each). An edge of A_k whose two faces have different owners becomes a vertical facet; its
// bottom and top edges carry every vertex that the level arrangements put on them, so all facets meet
// along whole segments (a conforming PLC).
#include "foxi/model/structure.hpp"

#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "foxi/model/io_error.hpp"

namespace foxi {

namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Traits = CGAL::Arr_segment_traits_2<K>;
using Arr = CGAL::Arrangement_2<Traits>;
using Pt = K::Point_2;

struct Item {
  std::size_t part;
  const Prism* prism;
  std::size_t z0, z1;  // level indices
};

bool inside_polygon(const std::vector<double>& xy, double x, double y) {  // convex, counter-clockwise
  const std::size_t n = xy.size() / 2;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const double c =
        (xy[2 * j] - xy[2 * i]) * (y - xy[2 * i + 1]) - (xy[2 * j + 1] - xy[2 * i + 1]) * (x - xy[2 * i]);
    if (!(c > 0)) return false;
  }
  return true;
}

// A planar arrangement of the footprint edges of some prisms, with a point inside each bounded face.
struct Plane {
  Arr arr;
  std::map<Arr::Face_const_handle, std::pair<double, double>> inner;  // a point inside each bounded face
  std::map<Arr::Face_const_handle, double> area;                      // of each bounded face
  std::vector<std::pair<double, double>> vertices;                    // all vertices, sorted
};

double to_d(const K::FT& v) { return CGAL::to_double(v); }

template <class Circ>
void ccb_points(Circ c, std::vector<std::pair<double, double>>& out) {
  Circ e = c;
  do {
    out.emplace_back(to_d(e->source()->point().x()), to_d(e->source()->point().y()));
  } while (++e != c);
}

double ring_area(const std::vector<std::pair<double, double>>& r) {
  double a = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const auto& p = r[i];
    const auto& q = r[(i + 1) % r.size()];
    a += p.first * q.second - q.first * p.second;
  }
  return 0.5 * a;
}

void build_plane(Plane& pl, const std::vector<const Prism*>& prisms) {
  std::vector<Traits::X_monotone_curve_2> segs;
  for (const Prism* p : prisms) {
    const std::size_t n = p->xy.size() / 2;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      segs.emplace_back(Pt(p->xy[2 * i], p->xy[2 * i + 1]), Pt(p->xy[2 * j], p->xy[2 * j + 1]));
    }
  }
  CGAL::insert(pl.arr, segs.begin(), segs.end());
  for (auto v = pl.arr.vertices_begin(); v != pl.arr.vertices_end(); ++v)
    pl.vertices.emplace_back(to_d(v->point().x()), to_d(v->point().y()));
  std::sort(pl.vertices.begin(), pl.vertices.end());
  for (auto f = pl.arr.faces_begin(); f != pl.arr.faces_end(); ++f) {
    if (f->is_unbounded()) continue;
    // rings: the outer boundary and the inner ones, as double polygons
    std::vector<std::vector<std::pair<double, double>>> rings(1);
    ccb_points(f->outer_ccb(), rings[0]);
    double area = ring_area(rings[0]);
    for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h) {
      rings.emplace_back();
      ccb_points(*h, rings.back());
      area += ring_area(rings.back());  // inner rings run clockwise: negative
    }
    pl.area[f] = area;
    // a point inside: from the middle of the longest outer edge, halfway to the nearest boundary
    // crossed by the inward normal (the face lies left of its outer boundary)
    const auto& o = rings[0];
    std::size_t best = 0;
    double best_len = -1;
    for (std::size_t i = 0; i < o.size(); ++i) {
      const auto& p = o[i];
      const auto& q = o[(i + 1) % o.size()];
      const double len = std::hypot(q.first - p.first, q.second - p.second);
      if (len > best_len) best_len = len, best = i;
    }
    const auto& p = o[best];
    const auto& q = o[(best + 1) % o.size()];
    const double mx = 0.5 * (p.first + q.first), my = 0.5 * (p.second + q.second);
    const double nx = -(q.second - p.second) / best_len, ny = (q.first - p.first) / best_len;
    double tmin = 1e300;
    for (std::size_t r = 0; r < rings.size(); ++r)
      for (std::size_t i = 0; i < rings[r].size(); ++i) {
        if (r == 0 && i == best) continue;
        const auto& a = rings[r][i];
        const auto& b = rings[r][(i + 1) % rings[r].size()];
        // solve m + t n = a + s (b - a)
        const double dx = b.first - a.first, dy = b.second - a.second;
        const double den = nx * (-dy) - ny * (-dx);
        if (den == 0) continue;
        const double rx = a.first - mx, ry = a.second - my;
        const double t = (rx * (-dy) - ry * (-dx)) / den;
        const double s = (nx * ry - ny * rx) / den;
        if (t > 1e-12 * best_len && s >= -1e-12 && s <= 1 + 1e-12) tmin = std::min(tmin, t);
      }
    if (tmin > 1e299) tmin = best_len;  // cannot happen for a closed face; keep a finite point
    pl.inner[f] = {mx + 0.5 * tmin * nx, my + 0.5 * tmin * ny};
  }
}

class Builder {
 public:
  explicit Builder(const Model& m) : m_(m) {}

  Structure build() {
    collect();
    const std::size_t L = levels_.size();
    std::vector<std::vector<std::size_t>> active(L ? L - 1 : 0);
    for (std::size_t i = 0; i < items_.size(); ++i)
      for (std::size_t k = items_[i].z0; k < items_[i].z1; ++k) active[k].push_back(i);
    s_.part_volume.assign(m_.parts.size(), 0);

    // the level arrangements (edges of both neighbouring slabs) and their horizontal facets
    static const std::vector<std::size_t> kEmpty;
    std::vector<Plane> level(L);
    for (std::size_t z = 0; z < L; ++z) {
      const auto& below = z > 0 ? active[z - 1] : kEmpty;
      const auto& above = z + 1 < L ? active[z] : kEmpty;
      std::vector<const Prism*> prisms;
      for (std::size_t i : below) prisms.push_back(items_[i].prism);
      for (std::size_t i : above) prisms.push_back(items_[i].prism);
      Plane& pl = level[z];
      build_plane(pl, prisms);
      for (auto f = pl.arr.faces_begin(); f != pl.arr.faces_end(); ++f) {
        if (f->is_unbounded()) continue;
        const auto [x, y] = pl.inner.at(f);
        const long lb = label(x, y, below), la = label(x, y, above);
        if (lb == la) continue;
        const std::string name = lb < 0   ? part_name(la) + ".bottom"
                                 : la < 0 ? part_name(lb) + ".top"
                                          : interface_name(lb, la);
        const std::int32_t marker = marker_of(name);
        s_.plc.facet_polygon_begin.push_back(s_.plc.facet_polygon_begin.back());
        add_ccb(f->outer_ccb(), z);
        for (auto h = f->inner_ccbs_begin(); h != f->inner_ccbs_end(); ++h) {
          add_ccb(*h, z);
          // hole points: inside each face across this inner boundary (several where the boundary
          // pinches, e.g. around two footprints that touch at a corner)
          std::vector<Arr::Face_const_handle> across;
          auto e = *h;
          do {
            const Arr::Face_const_handle t = e->twin()->face();
            if (t != f && std::find(across.begin(), across.end(), t) == across.end()) across.push_back(t);
          } while (++e != *h);
          for (const auto& t : across) {
            const auto hp = pl.inner.at(t);
            s_.plc.facet_holes.insert(s_.plc.facet_holes.end(), {hp.first, hp.second, levels_[z]});
          }
        }
        s_.plc.facet_marker.push_back(marker);
        s_.plc.facet_hole_begin.push_back(static_cast<std::uint32_t>(s_.plc.facet_holes.size() / 3));
        s_.boundary_area[static_cast<std::size_t>(marker - 1)] += pl.area.at(f);
      }
    }

    // the slab arrangements: owners, volumes, region seeds and walls
    for (std::size_t k = 0; k + 1 < L; ++k) {
      std::vector<const Prism*> prisms;
      for (std::size_t i : active[k]) prisms.push_back(items_[i].prism);
      Plane pl;
      build_plane(pl, prisms);
      const double dz = levels_[k + 1] - levels_[k];
      std::map<Arr::Face_const_handle, long> owner;
      for (auto f = pl.arr.faces_begin(); f != pl.arr.faces_end(); ++f) {
        if (f->is_unbounded()) {
          owner[f] = -1;
          continue;
        }
        const auto [x, y] = pl.inner.at(f);
        const long o = label(x, y, active[k]);
        owner[f] = o;
        if (o < 0) continue;
        s_.part_volume[static_cast<std::size_t>(o)] += pl.area.at(f) * dz;
        RegionSeed seed;
        seed.point[0] = x;
        seed.point[1] = y;
        seed.point[2] = 0.5 * (levels_[k] + levels_[k + 1]);
        seed.id = static_cast<std::int32_t>(o + 1);
        s_.plc.regions.push_back(seed);
      }
      for (auto e = pl.arr.edges_begin(); e != pl.arr.edges_end(); ++e) {
        const long a = owner.at(e->face()), b = owner.at(e->twin()->face());
        if (a == b) continue;
        const std::string name = a < 0   ? part_name(b) + ".side"
                                 : b < 0 ? part_name(a) + ".side"
                                         : interface_name(a, b);
        const std::int32_t marker = marker_of(name);
        const double px = to_d(e->source()->point().x()), py = to_d(e->source()->point().y());
        const double qx = to_d(e->target()->point().x()), qy = to_d(e->target()->point().y());
        // bottom p -> q with the level-k vertices on it, top q -> p with the level-(k+1) ones
        std::vector<std::uint32_t> poly;
        for (const auto& v : on_segment(level[k], px, py, qx, qy))
          poly.push_back(point(v.first, v.second, k));
        const auto top = on_segment(level[k + 1], qx, qy, px, py);
        for (const auto& v : top) poly.push_back(point(v.first, v.second, k + 1));
        s_.plc.facet_polygon_begin.push_back(s_.plc.facet_polygon_begin.back() + 1);
        s_.plc.polygon_vertices.insert(s_.plc.polygon_vertices.end(), poly.begin(), poly.end());
        s_.plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(s_.plc.polygon_vertices.size()));
        s_.plc.facet_marker.push_back(marker);
        s_.plc.facet_hole_begin.push_back(s_.plc.facet_hole_begin.back());
        s_.boundary_area[static_cast<std::size_t>(marker - 1)] += std::hypot(qx - px, qy - py) * dz;
      }
    }

    for (std::size_t p = 0; p < m_.parts.size(); ++p)
      if (!(s_.part_volume[p] > 0))
        throw IoError(m_.file, m_.parts[p].line, IoError::kNoOffset,
                      "part '" + m_.parts[p].name + "' is carved away entirely by later parts");
    return std::move(s_);
  }

 private:
  void collect() {
    double lo = 1e300, hi = -1e300, span = 0;
    for (const Part& p : m_.parts)
      for (const Prism& q : p.prisms) {
        lo = std::min(lo, q.z0);
        hi = std::max(hi, q.z1);
        for (double c : q.xy) span = std::max(span, std::abs(c));
      }
    eps_ = std::max(1e-9 * std::max(hi - lo, span), 1e-300);
    std::vector<double> zs;
    for (const Part& p : m_.parts)
      for (const Prism& q : p.prisms) zs.insert(zs.end(), {q.z0, q.z1});
    std::sort(zs.begin(), zs.end());
    for (double z : zs)
      if (levels_.empty() || z - levels_.back() > eps_) levels_.push_back(z);
    auto level = [&](double z) {
      return static_cast<std::size_t>(std::lower_bound(levels_.begin(), levels_.end(), z - eps_) -
                                      levels_.begin());
    };
    for (std::size_t pi = 0; pi < m_.parts.size(); ++pi)
      for (const Prism& q : m_.parts[pi].prisms) items_.push_back(Item{pi, &q, level(q.z0), level(q.z1)});
  }

  // the last part among `act` whose prism covers (x, y); -1 if none
  long label(double x, double y, const std::vector<std::size_t>& act) const {
    long best = -1;
    for (std::size_t i : act)
      if (static_cast<long>(items_[i].part) > best && inside_polygon(items_[i].prism->xy, x, y))
        best = static_cast<long>(items_[i].part);
    return best;
  }

  // the vertices of `pl` on the segment p -> q, in order from p to q (p and q included)
  static std::vector<std::pair<double, double>> on_segment(const Plane& pl, double px, double py, double qx,
                                                           double qy) {
    const double len2 = (qx - px) * (qx - px) + (qy - py) * (qy - py);
    const double tol = 1e-9 * std::sqrt(len2);
    std::vector<std::pair<double, std::pair<double, double>>> hits;
    const double xlo = std::min(px, qx) - tol, xhi = std::max(px, qx) + tol;
    auto it = std::lower_bound(pl.vertices.begin(), pl.vertices.end(), std::make_pair(xlo, -1e300));
    for (; it != pl.vertices.end() && it->first <= xhi; ++it) {
      const double vx = it->first, vy = it->second;
      if (vy < std::min(py, qy) - tol || vy > std::max(py, qy) + tol) continue;
      const double cross = (qx - px) * (vy - py) - (qy - py) * (vx - px);
      if (std::abs(cross) > tol * std::sqrt(len2)) continue;
      const double t = ((vx - px) * (qx - px) + (vy - py) * (qy - py)) / len2;
      hits.push_back({t, {vx, vy}});
    }
    std::sort(hits.begin(), hits.end());
    std::vector<std::pair<double, double>> out;
    for (auto& h : hits) out.push_back(h.second);
    return out;
  }

  std::string part_name(long p) const { return m_.parts[static_cast<std::size_t>(p)].name; }
  std::string interface_name(long a, long b) const {
    if (a > b) std::swap(a, b);
    return part_name(a) + "/" + part_name(b);
  }

  std::int32_t marker_of(const std::string& name) {
    for (std::size_t i = 0; i < s_.boundary_names.size(); ++i)
      if (s_.boundary_names[i] == name) return static_cast<std::int32_t>(i + 1);
    s_.boundary_names.push_back(name);
    s_.boundary_area.push_back(0);
    return static_cast<std::int32_t>(s_.boundary_names.size());
  }

  std::uint32_t point(double x, double y, std::size_t z) {
    auto key = std::make_tuple(x, y, z);
    auto it = points_.find(key);
    if (it != points_.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(s_.plc.point_count());
    s_.plc.points.insert(s_.plc.points.end(), {x, y, levels_[z]});
    points_.emplace(key, id);
    return id;
  }

  template <class Circ>
  void add_ccb(Circ c, std::size_t z) {
    Circ e = c;
    do {
      s_.plc.polygon_vertices.push_back(
          point(to_d(e->source()->point().x()), to_d(e->source()->point().y()), z));
    } while (++e != c);
    s_.plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(s_.plc.polygon_vertices.size()));
    ++s_.plc.facet_polygon_begin.back();
  }

  const Model& m_;
  Structure s_;
  double eps_ = 0;
  std::vector<double> levels_;
  std::vector<Item> items_;
  std::map<std::tuple<double, double, std::size_t>, std::uint32_t> points_;
};

}  // namespace

Structure build_structure(const Model& model) { return Builder(model).build(); }
void name_mesh(const Model& model, const Structure& structure, Mesh& mesh) {
  mesh.materials.clear();
  for (const Material& m : model.materials) mesh.materials.push_back(m);
  for (std::size_t p = 0; p < model.parts.size(); ++p) {
    const auto id = static_cast<std::int32_t>(p + 1);
    Region* r = nullptr;
    for (Region& x : mesh.regions)
      if (x.id == id) r = &x;
    if (r == nullptr) r = &mesh.regions.emplace_back();
    r->id = id;
    r->name = model.parts[p].name;
    for (std::size_t i = 0; i < model.materials.size(); ++i)
      if (model.materials[i].name == model.parts[p].material) r->material = static_cast<std::uint32_t>(i);
  }
  for (std::size_t b = 0; b < structure.boundary_names.size(); ++b) {
    const auto tag = static_cast<std::int32_t>(b + 1);
    Boundary* x = nullptr;
    for (Boundary& y : mesh.boundaries)
      if (y.tag == tag) x = &y;
    if (x == nullptr) x = &mesh.boundaries.emplace_back();
    x->tag = tag;
    x->name = structure.boundary_names[b];
  }
}

}  // namespace foxi
