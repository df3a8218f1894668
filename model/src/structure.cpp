// Parts -> PLC by z slabs and footprint forests (see structure.hpp).
#include "foxi/model/structure.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "foxi/model/io_error.hpp"

namespace foxi {

namespace {

struct Footprint {
  std::vector<double> xy;  // convex, counter-clockwise
  double area = 0;
  double cx = 0, cy = 0;  // vertex centroid (inside: convex)
  std::size_t n() const { return xy.size() / 2; }
};

struct Item {
  std::size_t part;
  std::size_t fid;
  std::size_t z0, z1;  // level indices
};

double signed_dist(const Footprint& f, std::size_t e, double x, double y) {
  const std::size_t n = f.n(), j = (e + 1) % n;
  const double ax = f.xy[2 * e], ay = f.xy[2 * e + 1], bx = f.xy[2 * j], by = f.xy[2 * j + 1];
  const double len = std::hypot(bx - ax, by - ay);
  return ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) / len;
}

bool strictly_inside_pt(const Footprint& f, double x, double y, double eps) {
  for (std::size_t e = 0; e < f.n(); ++e)
    if (signed_dist(f, e, x, y) <= eps) return false;
  return true;
}

bool strictly_inside(const Footprint& a, const Footprint& b, double eps) {  // a inside b
  for (std::size_t i = 0; i < a.n(); ++i)
    if (!strictly_inside_pt(b, a.xy[2 * i], a.xy[2 * i + 1], eps)) return false;
  return true;
}

bool separated(const Footprint& a, const Footprint& b, double eps) {
  auto axis_of = [&](const Footprint& f, std::size_t e) {
    // all of the other polygon beyond edge e's line by more than eps
    const Footprint& o = &f == &a ? b : a;
    for (std::size_t i = 0; i < o.n(); ++i)
      if (signed_dist(f, e, o.xy[2 * i], o.xy[2 * i + 1]) > -eps) return false;
    return true;
  };
  for (std::size_t e = 0; e < a.n(); ++e)
    if (axis_of(a, e)) return true;
  for (std::size_t e = 0; e < b.n(); ++e)
    if (axis_of(b, e)) return true;
  return false;
}

bool same_polygon(const std::vector<double>& a, const std::vector<double>& b, double eps) {
  if (a.size() != b.size()) return false;
  const std::size_t n = a.size() / 2;
  for (std::size_t s = 0; s < n; ++s) {
    bool ok = true;
    for (std::size_t i = 0; i < n && ok; ++i) {
      const std::size_t j = (i + s) % n;
      ok = std::abs(a[2 * i] - b[2 * j]) <= eps && std::abs(a[2 * i + 1] - b[2 * j + 1]) <= eps;
    }
    if (ok) return true;
  }
  return false;
}

class Builder {
 public:
  explicit Builder(const Model& m) : m_(m) {}

  Structure build() {
    collect();
    check_relations();
    const std::size_t L = levels_.size();
    // slab k is [levels_[k], levels_[k+1]]
    std::vector<std::vector<std::size_t>> active(L ? L - 1 : 0);
    for (std::size_t i = 0; i < items_.size(); ++i)
      for (std::size_t k = items_[i].z0; k < items_[i].z1; ++k) active[k].push_back(i);
    s_.part_volume.assign(m_.parts.size(), 0);

    // horizontal facets at each level
    for (std::size_t z = 0; z < L; ++z) {
      static const std::vector<std::size_t> kEmpty;
      const auto& below = z > 0 ? active[z - 1] : kEmpty;
      const auto& above = z + 1 < L ? active[z] : kEmpty;
      std::vector<std::size_t> polys = fids(below, above);
      const Forest forest = make_forest(polys);
      for (std::size_t f : polys) {
        const long lb = label(f, below), la = label(f, above);
        if (lb == la) continue;
        const std::vector<std::size_t>& kids = forest.children.at(f);
        std::string name = lb < 0   ? m_.parts[la].name + ".bottom"
                           : la < 0 ? m_.parts[lb].name + ".top"
                                    : interface_name(lb, la);
        const std::int32_t marker = marker_of(name);
        double area = fp_[f].area;
        s_.plc.facet_polygon_begin.push_back(s_.plc.facet_polygon_begin.back());
        add_polygon(f, z);
        for (std::size_t c : kids) {
          add_polygon(c, z);
          s_.plc.facet_holes.insert(s_.plc.facet_holes.end(), {fp_[c].cx, fp_[c].cy, levels_[z]});
          area -= fp_[c].area;
        }
        s_.plc.facet_marker.push_back(marker);
        s_.plc.facet_hole_begin.push_back(static_cast<std::uint32_t>(s_.plc.facet_holes.size() / 3));
        s_.boundary_area[marker - 1] += area;
      }
    }

    // walls and region seeds, slab by slab; walls run over consecutive slabs with the same owners
    struct Run {
      std::size_t z0;
      long in, out;
    };
    std::map<std::size_t, Run> open;  // fid -> run
    for (std::size_t k = 0; k + 1 < L; ++k) {
      std::vector<std::size_t> polys = fids(active[k], {});
      const Forest forest = make_forest(polys);
      std::map<std::size_t, Run> next;
      for (std::size_t f : polys) {
        const long in = label(f, active[k]);
        const long par = forest.parent.at(f);
        const long out = par < 0 ? -1 : label(static_cast<std::size_t>(par), active[k]);
        // the cell "f minus its children" belongs to `in`: its volume, and a region seed where the
        // owner differs from the surrounding one (else the cell is connected to the surrounding cell)
        const std::vector<std::size_t>& kids = forest.children.at(f);
        double area = fp_[f].area;
        for (std::size_t c : kids) area -= fp_[c].area;
        if (in >= 0) s_.part_volume[in] += area * (levels_[k + 1] - levels_[k]);
        if (in >= 0 && in != out) add_seed(f, kids, k, in);
        if (in == out) continue;
        auto it = open.find(f);
        if (it != open.end() && it->second.in == in && it->second.out == out) {
          next[f] = it->second;
          open.erase(it);
        } else {
          next[f] = Run{k, in, out};
        }
      }
      for (auto& [f, r] : open) emit_walls(f, r.z0, k, r.in, r.out);
      open = std::move(next);
    }
    for (auto& [f, r] : open) emit_walls(f, r.z0, L - 1, r.in, r.out);

    for (std::size_t p = 0; p < m_.parts.size(); ++p)
      if (!(s_.part_volume[p] > 0))
        throw IoError(m_.file, m_.parts[p].line, IoError::kNoOffset,
                      "part '" + m_.parts[p].name + "' is carved away entirely by later parts");
    return std::move(s_);
  }

 private:
  void collect() {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (const Part& p : m_.parts)
      for (const Prism& q : p.prisms) {
        for (std::size_t i = 0; i < q.xy.size(); ++i) {
          lo[i % 2] = std::min(lo[i % 2], q.xy[i]);
          hi[i % 2] = std::max(hi[i % 2], q.xy[i]);
        }
        lo[2] = std::min(lo[2], q.z0);
        hi[2] = std::max(hi[2], q.z1);
      }
    const double diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    eps_ = std::max(1e-9 * diag, 1e-300);
    std::vector<double> zs;
    for (const Part& p : m_.parts)
      for (const Prism& q : p.prisms) zs.insert(zs.end(), {q.z0, q.z1});
    std::sort(zs.begin(), zs.end());
    for (double z : zs)
      if (levels_.empty() || z - levels_.back() > eps_) levels_.push_back(z);
    auto level = [&](double z) {
      auto it = std::lower_bound(levels_.begin(), levels_.end(), z - eps_);
      return static_cast<std::size_t>(it - levels_.begin());
    };
    for (std::size_t pi = 0; pi < m_.parts.size(); ++pi)
      for (const Prism& q : m_.parts[pi].prisms) {
        std::size_t fid = fp_.size();
        for (std::size_t f = 0; f < fp_.size(); ++f)
          if (same_polygon(fp_[f].xy, q.xy, eps_)) fid = f;
        if (fid == fp_.size()) {
          Footprint f;
          f.xy = q.xy;
          f.area = q.area();
          for (std::size_t i = 0; i < f.n(); ++i) f.cx += f.xy[2 * i] / static_cast<double>(f.n());
          for (std::size_t i = 0; i < f.n(); ++i) f.cy += f.xy[2 * i + 1] / static_cast<double>(f.n());
          fp_.push_back(std::move(f));
        }
        items_.push_back(Item{pi, fid, level(q.z0), level(q.z1)});
      }
    contains_.assign(fp_.size() * fp_.size(), 0);
  }

  void check_relations() {
    const std::size_t nf = fp_.size();
    std::vector<std::int8_t> rel(nf * nf, -2);  // -2 unknown, 0 apart, 1 row contains column, -1 bad
    for (std::size_t i = 0; i < items_.size(); ++i)
      for (std::size_t j = i + 1; j < items_.size(); ++j) {
        const Item &a = items_[i], &b = items_[j];
        if (a.fid == b.fid || a.z1 < b.z0 || b.z1 < a.z0) continue;
        std::int8_t& r = rel[a.fid * nf + b.fid];
        if (r == -2) {
          if (strictly_inside(fp_[b.fid], fp_[a.fid], eps_)) {
            contains_[a.fid * nf + b.fid] = 1;
            r = 1;
          } else if (strictly_inside(fp_[a.fid], fp_[b.fid], eps_)) {
            contains_[b.fid * nf + a.fid] = 1;
            r = 1;
          } else if (separated(fp_[a.fid], fp_[b.fid], eps_)) {
            r = 0;
          } else {
            r = -1;
          }
        }
        if (r == -1)
          throw IoError(m_.file, m_.parts[b.part].line, IoError::kNoOffset,
                        (a.part == b.part
                             ? "items of part '" + m_.parts[a.part].name + "'"
                             : "parts '" + m_.parts[a.part].name + "' and '" + m_.parts[b.part].name + "'") +
                            " overlap partially or touch side by side; supported: footprints equal, one "
                            "strictly inside the other, or apart (general booleans are not implemented)");
      }
  }

  bool contains(std::size_t a, std::size_t b) const { return contains_[a * fp_.size() + b] != 0; }

  std::vector<std::size_t> fids(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) const {
    std::vector<std::size_t> out;
    for (std::size_t i : a) out.push_back(items_[i].fid);
    for (std::size_t i : b) out.push_back(items_[i].fid);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // the last part among `act` whose footprint is f or contains f; -1 if none
  long label(std::size_t f, const std::vector<std::size_t>& act) const {
    long best = -1;
    for (std::size_t i : act)
      if (items_[i].fid == f || contains(items_[i].fid, f))
        best = std::max(best, static_cast<long>(items_[i].part));
    return best;
  }

  // The containment forest of a set of footprints: each one's smallest container (-1: none), and
  // the footprints each one contains directly.
  struct Forest {
    std::map<std::size_t, long> parent;
    std::map<std::size_t, std::vector<std::size_t>> children;
  };
  Forest make_forest(const std::vector<std::size_t>& polys) const {
    Forest forest;
    for (std::size_t f : polys) {
      long best = -1;
      for (std::size_t g : polys)
        if (contains(g, f) && (best < 0 || fp_[g].area < fp_[static_cast<std::size_t>(best)].area))
          best = static_cast<long>(g);
      forest.parent[f] = best;
      forest.children[f];
      if (best >= 0) forest.children[static_cast<std::size_t>(best)].push_back(f);
    }
    return forest;
  }

  std::string interface_name(long a, long b) const {
    if (a > b) std::swap(a, b);
    return m_.parts[static_cast<std::size_t>(a)].name + "/" + m_.parts[static_cast<std::size_t>(b)].name;
  }

  std::int32_t marker_of(const std::string& name) {
    for (std::size_t i = 0; i < s_.boundary_names.size(); ++i)
      if (s_.boundary_names[i] == name) return static_cast<std::int32_t>(i + 1);
    s_.boundary_names.push_back(name);
    s_.boundary_area.push_back(0);
    return static_cast<std::int32_t>(s_.boundary_names.size());
  }

  std::uint32_t point(std::size_t f, std::size_t v, std::size_t z) {
    auto key = std::make_tuple(f, v, z);
    auto it = points_.find(key);
    if (it != points_.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(s_.plc.point_count());
    s_.plc.points.insert(s_.plc.points.end(), {fp_[f].xy[2 * v], fp_[f].xy[2 * v + 1], levels_[z]});
    points_.emplace(key, id);
    return id;
  }

  void add_polygon(std::size_t f, std::size_t z) {
    for (std::size_t v = 0; v < fp_[f].n(); ++v) s_.plc.polygon_vertices.push_back(point(f, v, z));
    s_.plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(s_.plc.polygon_vertices.size()));
    ++s_.plc.facet_polygon_begin.back();
  }

  void emit_walls(std::size_t f, std::size_t z0, std::size_t z1, long in, long out) {
    const std::string name =
        out < 0  ? m_.parts[static_cast<std::size_t>(in)].name + ".side"
        : in < 0 ? m_.parts[static_cast<std::size_t>(out)].name + ".side"  // an empty hole's wall
                 : interface_name(in, out);
    const std::int32_t marker = marker_of(name);
    const Footprint& fp = fp_[f];
    for (std::size_t e = 0; e < fp.n(); ++e) {
      const std::size_t j = (e + 1) % fp.n();
      s_.plc.add_facet({point(f, e, z0), point(f, j, z0), point(f, j, z1), point(f, e, z1)}, marker);
      s_.boundary_area[marker - 1] +=
          std::hypot(fp.xy[2 * j] - fp.xy[2 * e], fp.xy[2 * j + 1] - fp.xy[2 * e + 1]) *
          (levels_[z1] - levels_[z0]);
    }
  }

  void add_seed(std::size_t f, const std::vector<std::size_t>& kids, std::size_t k, long part) {
    const Footprint& fp = fp_[f];
    auto free = [&](double x, double y) {
      if (!strictly_inside_pt(fp, x, y, 0)) return false;
      for (std::size_t c : kids)
        if (strictly_inside_pt(fp_[c], x, y, -eps_)) return false;
      return true;
    };
    double px = fp.cx, py = fp.cy;
    bool found = free(px, py);
    for (double t : {0.02, 0.002, 1e-4})
      for (std::size_t v = 0; v < fp.n() && !found; ++v) {
        px = fp.xy[2 * v] + t * (fp.cx - fp.xy[2 * v]);
        py = fp.xy[2 * v + 1] + t * (fp.cy - fp.xy[2 * v + 1]);
        found = free(px, py);
      }
    RegionSeed seed;
    seed.point[0] = px;
    seed.point[1] = py;
    seed.point[2] = 0.5 * (levels_[k] + levels_[k + 1]);
    seed.id = static_cast<std::int32_t>(part + 1);
    s_.plc.regions.push_back(seed);
  }

  const Model& m_;
  Structure s_;
  double eps_ = 0;
  std::vector<double> levels_;
  std::vector<Footprint> fp_;
  std::vector<Item> items_;
  std::vector<std::uint8_t> contains_;
  std::map<std::tuple<std::size_t, std::size_t, std::size_t>, std::uint32_t> points_;
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
