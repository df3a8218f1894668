// Model diagnostics (diagnostics.hpp): part groups from the structure's interfaces, overhangs from
// its horizontal facets, fixed values from the model's conditions.
#include "foxi/model/diagnostics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "plc_geometry.hpp"

namespace foxi {

namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

struct UnionFind {
  std::vector<std::size_t> up;
  explicit UnionFind(std::size_t n) : up(n) { std::iota(up.begin(), up.end(), std::size_t{0}); }
  std::size_t find(std::size_t a) {
    while (up[a] != a) a = up[a] = up[up[a]];
    return a;
  }
  void join(std::size_t a, std::size_t b) { up[find(a)] = find(b); }
};

// What a boundary name says: a part's outer face ("P.top", "P.bottom", "P.side"), an interface
// ("A/B"), or neither (a [surfaces] selector).
struct NameInfo {
  std::size_t a = kNone, b = kNone;  // parts: a only for a face, a and b for an interface
  bool bottom = false;               // "P.bottom"
};

struct Poly2 {
  std::vector<double> xy;  // 2 per vertex
};

// The shoelace area of a polygon in xy (positive counter-clockwise), as a prism's footprint.
double signed_area(std::vector<double> xy) {
  Prism p;
  p.xy = std::move(xy);
  return p.area();
}

// Andrew's monotone chain: the counter-clockwise convex hull of the points (2 doubles each).
std::vector<double> convex_hull(std::vector<double> pts) {
  const std::size_t n = pts.size() / 2;
  std::vector<std::pair<double, double>> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = {pts[2 * i], pts[2 * i + 1]};
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return {};
  auto cross = [](const auto& o, const auto& a, const auto& b) {
    return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
  };
  std::vector<std::pair<double, double>> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  std::vector<double> out;
  for (const auto& [x, y] : h) out.insert(out.end(), {x, y});
  return out;
}

// Sutherland-Hodgman: `poly` (any simple polygon) clipped by the convex counter-clockwise `hull`;
// the result's shoelace area is the area of the intersection.
std::vector<double> clip(std::vector<double> poly, const std::vector<double>& hull) {
  const std::size_t m = hull.size() / 2;
  for (std::size_t e = 0; e < m && !poly.empty(); ++e) {
    const double ax = hull[2 * e], ay = hull[2 * e + 1];
    const double bx = hull[2 * ((e + 1) % m)], by = hull[2 * ((e + 1) % m) + 1];
    auto side = [&](double x, double y) { return (bx - ax) * (y - ay) - (by - ay) * (x - ax); };
    std::vector<double> out;
    const std::size_t n = poly.size() / 2;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      const double px = poly[2 * i], py = poly[2 * i + 1], qx = poly[2 * j], qy = poly[2 * j + 1];
      const double sp = side(px, py), sq = side(qx, qy);
      if (sp >= 0) out.insert(out.end(), {px, py});
      if ((sp >= 0) != (sq >= 0)) {
        const double t = sp / (sp - sq);
        out.insert(out.end(), {px + t * (qx - px), py + t * (qy - py)});
      }
    }
    poly = std::move(out);
  }
  return poly;
}

class Diagnoser {
 public:
  Diagnoser(const Model& m, const Structure& s, const DiagnosticsParams& p) : m_(m), s_(s), p_(p) {
    names_.resize(s.boundary_names.size());
    for (std::size_t b = 0; b < names_.size(); ++b) names_[b] = parse(s.boundary_names[b]);
  }

  ModelDiagnostics run() {
    ModelDiagnostics d;
    isolated(d);
    overhangs(d);
    for (Physics ph : {Physics::thermal, Physics::electrostatic, Physics::current, Physics::thermal_stress})
      unfixed(ph, d);
    return d;
  }

 private:
  std::size_t part_index(std::string_view name) const {
    for (std::size_t i = 0; i < m_.parts.size(); ++i)
      if (m_.parts[i].name == name) return i;
    return kNone;
  }

  NameInfo parse(const std::string& name) const {
    NameInfo info;
    // an interface: some '/' splits the name into two part names (part names may hold '/' or '.')
    for (std::size_t at = name.find('/'); at != std::string::npos; at = name.find('/', at + 1)) {
      const std::size_t a = part_index(std::string_view(name).substr(0, at));
      const std::size_t b = part_index(std::string_view(name).substr(at + 1));
      if (a != kNone && b != kNone) return {a, b, false};
    }
    for (const char* face : {".top", ".bottom", ".side"}) {
      const std::size_t n = std::char_traits<char>::length(face);
      if (name.size() > n && name.compare(name.size() - n, n, face) == 0) {
        const std::size_t a = part_index(std::string_view(name).substr(0, name.size() - n));
        if (a != kNone) return {a, kNone, std::string_view(face) == ".bottom"};
      }
    }
    return info;
  }

  std::int32_t own_marker(std::size_t f) const {
    return s_.facet_own_marker.size() == s_.plc.facet_count() ? s_.facet_own_marker[f]
                                                              : s_.plc.facet_marker[f];
  }
  const NameInfo* own_info(std::size_t f) const {
    const std::int32_t m = own_marker(f);
    return m >= 1 && static_cast<std::size_t>(m) <= names_.size() ? &names_[static_cast<std::size_t>(m - 1)]
                                                                  : nullptr;
  }

  // The parts a condition's surface lies on: the part of a face, both parts of an interface, the
  // parts whose faces a [surfaces] selector took.
  std::vector<std::size_t> parts_of_surface(const std::string& surface) const {
    std::vector<std::size_t> parts;
    for (std::size_t b = 0; b < names_.size(); ++b) {
      if (s_.boundary_names[b] != surface) continue;
      if (names_[b].a != kNone) {
        parts.push_back(names_[b].a);
        if (names_[b].b != kNone) parts.push_back(names_[b].b);
        continue;
      }
      for (std::size_t f = 0; f < s_.plc.facet_count(); ++f)
        if (s_.plc.facet_marker[f] == static_cast<std::int32_t>(b + 1))
          if (const NameInfo* o = own_info(f); o && o->a != kNone) {
            parts.push_back(o->a);
            if (o->b != kNone) parts.push_back(o->b);
          }
    }
    return parts;
  }

  // Groups of parts joined by interfaces of positive area, among the parts `carries` keeps.
  UnionFind groups(const std::vector<bool>& carries) const {
    UnionFind uf(m_.parts.size());
    for (std::size_t b = 0; b < names_.size(); ++b) {
      const NameInfo& n = names_[b];
      if (n.a != kNone && n.b != kNone && b < s_.boundary_area.size() && s_.boundary_area[b] > 0 &&
          carries[n.a] && carries[n.b])
        uf.join(n.a, n.b);
    }
    return uf;
  }

  // The groups as lists of parts in file order, each with its volume.
  struct Group {
    std::vector<std::size_t> parts;
    double volume = 0;
  };
  std::vector<Group> collect(UnionFind& uf, const std::vector<bool>& carries) const {
    std::vector<Group> out;
    std::vector<std::size_t> slot(m_.parts.size(), kNone);
    for (std::size_t p = 0; p < m_.parts.size(); ++p) {
      if (!carries[p]) continue;
      const std::size_t r = uf.find(p);
      if (slot[r] == kNone) {
        slot[r] = out.size();
        out.emplace_back();
      }
      Group& g = out[slot[r]];
      g.parts.push_back(p);
      if (p < s_.part_volume.size()) g.volume += s_.part_volume[p];
    }
    return out;
  }

  std::vector<std::string> names_of(const std::vector<std::size_t>& parts) const {
    std::vector<std::string> out;
    for (std::size_t p : parts) out.push_back(m_.parts[p].name);
    return out;
  }

  ModelWarning group_warning(ModelWarningKind kind, Physics ph, const Group& g) const {
    ModelWarning w;
    w.kind = kind;
    w.physics = ph;
    w.parts = names_of(g.parts);
    w.volume = g.volume;
    return w;
  }

  void isolated(ModelDiagnostics& d) const {
    const std::vector<bool> all(m_.parts.size(), true);
    UnionFind uf = groups(all);
    const std::vector<Group> g = collect(uf, all);
    if (g.size() < 2) return;
    std::size_t largest = 0;
    for (std::size_t i = 1; i < g.size(); ++i)
      if (g[i].volume > g[largest].volume) largest = i;
    for (std::size_t i = 0; i < g.size(); ++i)
      if (i != largest)
        d.warnings.push_back(group_warning(ModelWarningKind::isolated, Physics::thermal, g[i]));
  }

  // A horizontal facet: its height, its polygons projected on xy (the first the outline, the others
  // holes, as the structure builders write them) and its area.
  struct Flat {
    std::size_t facet = 0;
    double z = 0;
    std::vector<Poly2> rings;
  };
  bool flat(std::size_t f, Flat& out) const {
    const Plc& plc = s_.plc;
    const std::uint32_t p0 = plc.facet_polygon_begin[f];
    double n[3];
    polygon_normal(plc, p0, n);
    const std::uint32_t b = plc.polygon_vertex_begin[p0];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0) || std::abs(n[2]) < (1 - 1e-9) * len) return false;
    out.facet = f;
    out.z = plc.points[3 * std::size_t{plc.polygon_vertices[b]} + 2];
    out.rings.clear();
    for (std::uint32_t p = p0; p < plc.facet_polygon_begin[f + 1]; ++p) {
      Poly2& r = out.rings.emplace_back();
      for (std::uint32_t i = plc.polygon_vertex_begin[p]; i < plc.polygon_vertex_begin[p + 1]; ++i) {
        const double* x = &plc.points[3 * std::size_t{plc.polygon_vertices[i]}];
        r.xy.insert(r.xy.end(), {x[0], x[1]});
      }
    }
    return true;
  }
  static double area(const Flat& f) {
    double a = 0;
    for (std::size_t r = 0; r < f.rings.size(); ++r)
      a += (r == 0 ? 1 : -1) * std::abs(signed_area(f.rings[r].xy));
    return a;
  }
  static double area_inside(const Flat& f, const std::vector<double>& hull) {
    double a = 0;
    for (std::size_t r = 0; r < f.rings.size(); ++r)
      a += (r == 0 ? 1 : -1) * std::abs(signed_area(clip(f.rings[r].xy, hull)));
    return a;
  }

  void overhangs(ModelDiagnostics& d) const {
    const Plc& plc = s_.plc;
    double span = 0;
    for (double c : plc.points) span = std::max(span, std::abs(c));
    const double tol = 1e-9 * std::max(span, 1e-300);
    // each part's height range over the facets it bounds
    std::vector<double> lo(m_.parts.size(), 1e300), hi(m_.parts.size(), -1e300);
    for (std::size_t f = 0; f < plc.facet_count(); ++f) {
      const NameInfo* o = own_info(f);
      if (!o || o->a == kNone) continue;
      for (std::uint32_t p = plc.facet_polygon_begin[f]; p < plc.facet_polygon_begin[f + 1]; ++p)
        for (std::uint32_t i = plc.polygon_vertex_begin[p]; i < plc.polygon_vertex_begin[p + 1]; ++i) {
          const double z = plc.points[3 * std::size_t{plc.polygon_vertices[i]} + 2];
          for (std::size_t q : {o->a, o->b})
            if (q != kNone) lo[q] = std::min(lo[q], z), hi[q] = std::max(hi[q], z);
        }
    }
    std::vector<Flat> flats;
    for (std::size_t f = 0; f < plc.facet_count(); ++f)
      if (Flat x; own_info(f) && own_info(f)->a != kNone && flat(f, x)) flats.push_back(std::move(x));

    for (std::size_t part = 0; part < m_.parts.size(); ++part) {
      // the heights of the part's exposed bottom
      std::vector<double> levels;
      for (const Flat& x : flats)
        if (const NameInfo* o = own_info(x.facet); o->a == part && o->bottom) levels.push_back(x.z);
      std::sort(levels.begin(), levels.end());
      levels.erase(
          std::unique(levels.begin(), levels.end(), [&](double a, double b) { return b - a <= tol; }),
          levels.end());
      for (double z : levels) {
        double exposed = 0, supported = 0, outside = 0;
        std::vector<double> contact;
        std::vector<bool> below(m_.parts.size(), false);
        std::vector<const Flat*> bottom;
        for (const Flat& x : flats) {
          if (std::abs(x.z - z) > tol) continue;
          const NameInfo* o = own_info(x.facet);
          if (o->a == part && o->bottom) {
            bottom.push_back(&x);
            exposed += area(x);
            continue;
          }
          if (o->b == kNone || (o->a != part && o->b != part)) continue;
          const std::size_t q = o->a == part ? o->b : o->a;
          // the other part lies below this contact: the part rests on it here
          if (!(lo[q] < z - tol && hi[part] > z + tol)) continue;
          below[q] = true;
          supported += area(x);
          for (const Poly2& r : x.rings) contact.insert(contact.end(), r.xy.begin(), r.xy.end());
        }
        const std::vector<double> hull = convex_hull(contact);
        if (hull.empty()) continue;  // resting on nothing at this height: not an overhang
        for (const Flat* x : bottom) outside += std::max(0.0, area(*x) - area_inside(*x, hull));
        const double whole = exposed + supported;
        if (!(whole > 0) || !(outside > p_.min_overhang_fraction * whole)) continue;
        ModelWarning w;
        w.kind = ModelWarningKind::overhang;
        w.parts = {m_.parts[part].name};
        for (std::size_t q = 0; q < below.size(); ++q)
          if (below[q]) w.supports.push_back(m_.parts[q].name);
        w.z = z;
        w.area = outside;
        w.fraction = outside / whole;
        d.warnings.push_back(std::move(w));
      }
    }
  }

  bool carries(const Part& part, Physics ph) const {
    for (const Material& mat : m_.materials) {
      if (mat.name != part.material) continue;
      const double v = ph == Physics::thermal         ? mat.thermal_conductivity
                       : ph == Physics::electrostatic ? mat.relative_permittivity
                       : ph == Physics::current       ? mat.electrical_conductivity
                                                      : mat.youngs_modulus;
      return v > 0;  // NaN (unset) carries nothing
    }
    return false;
  }

  // A condition of `ph` (condition_applies: a voltage may be for one electric physics only) that
  // fixes a value there.
  static bool fixes(const BoundaryCondition& c, Physics ph) {
    if (!condition_applies(c, ph)) return false;
    switch (ph) {
      case Physics::thermal:
        return c.kind == ConditionKind::temperature || c.kind == ConditionKind::convection;
      case Physics::electrostatic:
      case Physics::current:
        return c.kind == ConditionKind::voltage;
      case Physics::thermal_stress:
        return c.kind == ConditionKind::displacement || c.kind == ConditionKind::sliding;
    }
    return false;
  }

  void unfixed(Physics ph, ModelDiagnostics& d) const {
    bool any = false;
    for (const BoundaryCondition& c : m_.conditions) any = any || fixes(c, ph);
    if (!any) return;  // not ready at all: check_physics says so
    std::vector<bool> on(m_.parts.size());
    for (std::size_t p = 0; p < on.size(); ++p) on[p] = carries(m_.parts[p], ph);
    UnionFind uf = groups(on);
    std::vector<bool> fixed(m_.parts.size(), false);  // by group root
    for (const BoundaryCondition& c : m_.conditions)
      if (fixes(c, ph))
        for (const std::string& surface : c.surfaces)
          for (std::size_t p : parts_of_surface(surface))
            if (on[p]) fixed[uf.find(p)] = true;
    for (const Group& g : collect(uf, on))
      if (!fixed[uf.find(g.parts[0])])
        d.warnings.push_back(group_warning(ModelWarningKind::no_fixed_value, ph, g));
  }

  const Model& m_;
  const Structure& s_;
  const DiagnosticsParams& p_;
  std::vector<NameInfo> names_;
};

std::string quoted_list(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i)
    s += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + ("'" + names[i] + "'");
  return s;
}

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

}  // namespace

ModelDiagnostics diagnose_model(const Model& model, const Structure& structure,
                                const DiagnosticsParams& params) {
  return Diagnoser(model, structure, params).run();
}

std::vector<ModelWarning> warnings_for(const ModelDiagnostics& d, Physics physics) {
  std::vector<ModelWarning> out;
  for (const ModelWarning& w : d.warnings)
    if (w.kind != ModelWarningKind::no_fixed_value || w.physics == physics) out.push_back(w);
  return out;
}

std::string describe(const ModelWarning& w, const Model& model) {
  const double s = model.length_scale;
  const std::string u = model.length_unit;
  const std::string who = (w.parts.size() == 1 ? "part " : "parts ") + quoted_list(w.parts);
  const std::string vol = format("%.4g ", w.volume / (s * s * s)) + u + "^3";
  switch (w.kind) {
    case ModelWarningKind::isolated:
      return who + (w.parts.size() == 1 ? " touches" : " touch") + " no other part (" + vol +
             "; an edge or a point of contact is none): no heat, current or force passes between " +
             (w.parts.size() == 1 ? "it" : "them") + " and the rest of the model";
    case ModelWarningKind::overhang:
      return who + " overhangs what it sits on (" + quoted_list(w.supports) +
             ") at z = " + format("%.6g ", w.z / s) + u + ": " + format("%.4g ", w.area / (s * s)) + u +
             "^2 (" + format("%.3g%%", 100 * w.fraction) +
             ") of its bottom there lies beyond the contact, exposed (insulated unless a condition is on it)";
    case ModelWarningKind::no_fixed_value: {
      const char* what = w.physics == Physics::thermal          ? "temperature or convection"
                         : w.physics == Physics::thermal_stress ? "displacement or sliding"
                                                                : "voltage or ground";
      return std::string(physics_name(w.physics)) + ": " + who + " (" + vol +
             (w.parts.size() == 1 ? ") has" : ", joined by interfaces) have") +
             " no path to a fixed value: no " + what + " condition on any of " +
             (w.parts.size() == 1 ? "its" : "their") +
             " boundaries, so the solution there is fixed only up to a " +
             (w.physics == Physics::thermal_stress ? "rigid motion" : "constant");
    }
  }
  return {};
}

}  // namespace foxi
