#include "foxi/viz/field_paint.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace foxi {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Component names of a vector (3), a symmetric tensor (6: xx yy zz xy yz xz) and a full one (9, row-major).
int component_index(std::string_view c, std::uint32_t n) {
  static const char* const k3[] = {"x", "y", "z"};
  static const char* const k6[] = {"xx", "yy", "zz", "xy", "yz", "xz"};
  static const char* const k9[] = {"xx", "xy", "xz", "yx", "yy", "yz", "zx", "zy", "zz"};
  if (n == 3)
    for (int i = 0; i < 3; ++i)
      if (c == k3[i]) return i;
  if (n == 6)
    for (int i = 0; i < 6; ++i)
      if (c == k6[i]) return i;
  if (n == 9)
    for (int i = 0; i < 9; ++i)
      if (c == k9[i]) return i;
  if (!c.empty() && c.size() < 4 &&
      std::all_of(c.begin(), c.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
    const int i = std::stoi(std::string(c));
    if (i >= 0 && std::uint32_t(i) < n) return i;
  }
  return -1;
}

std::string component_names(std::uint32_t n) {
  if (n == 1) return "none (a scalar)";
  if (n == 3) return "x, y, z, mag or 0..2";
  if (n == 6) return "xx, yy, zz, xy, yz, xz, vm, p1, p2, p3 or 0..5";
  if (n == 9) return "xx, xy, ..., zz, vm, p1, p2, p3 or 0..8";
  return "0.." + std::to_string(n - 1);
}

bool is_tensor(std::uint32_t n) { return n == 6 || n == 9; }

// The symmetric tensor of components c (6: xx yy zz xy yz xz; 9: row-major, its symmetric part).
struct Sym {
  double xx, yy, zz, xy, yz, xz;
};
Sym symmetric(const double* c, std::uint32_t n) {
  if (n == 6) return {c[0], c[1], c[2], c[3], c[4], c[5]};
  return {c[0], c[4], c[8], 0.5 * (c[1] + c[3]), 0.5 * (c[5] + c[7]), 0.5 * (c[2] + c[6])};
}

// The eigenvalues of a symmetric 3x3 matrix, largest first: the trigonometric solution of the
// characteristic cubic (O. K. Smith, "Eigenvalues of a symmetric 3 x 3 matrix", CACM 4(4) 1961);
// near a double eigenvalue acos loses about half the digits (1e-8 of the tensor's size).
void principal_values(const Sym& a, double out[3]) {
  const double p1 = a.xy * a.xy + a.yz * a.yz + a.xz * a.xz;
  const double q = (a.xx + a.yy + a.zz) / 3;
  if (p1 == 0) {  // diagonal
    out[0] = a.xx, out[1] = a.yy, out[2] = a.zz;
  } else {
    const double p2 = (a.xx - q) * (a.xx - q) + (a.yy - q) * (a.yy - q) + (a.zz - q) * (a.zz - q) + 2 * p1;
    const double p = std::sqrt(p2 / 6);
    // B = (A - q I) / p; r = det(B) / 2, in [-1, 1] up to rounding.
    const double bxx = (a.xx - q) / p, byy = (a.yy - q) / p, bzz = (a.zz - q) / p;
    const double bxy = a.xy / p, byz = a.yz / p, bxz = a.xz / p;
    const double det =
        bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz) + bxz * (bxy * byz - byy * bxz);
    const double r = std::clamp(det / 2, -1.0, 1.0);
    const double phi = std::acos(r) / 3, pi = 3.14159265358979323846;
    out[0] = q + 2 * p * std::cos(phi);
    out[2] = q + 2 * p * std::cos(phi + 2 * pi / 3);
    out[1] = 3 * q - out[0] - out[2];
  }
  std::sort(out, out + 3, [](double x, double y) { return x > y; });
}

// The scalar of one entity's components c[0..n).
double scalar_of(const FieldScalar& s, const double* c, std::uint32_t n) {
  switch (s.kind) {
    case FieldScalar::Kind::component:
      return c[s.component];
    case FieldScalar::Kind::magnitude: {
      double q = 0;
      for (std::uint32_t i = 0; i < n; ++i) q += c[i] * c[i];
      return std::sqrt(q);
    }
    case FieldScalar::Kind::von_mises: {
      const Sym a = symmetric(c, n);
      return std::sqrt(0.5 * ((a.xx - a.yy) * (a.xx - a.yy) + (a.yy - a.zz) * (a.yy - a.zz) +
                              (a.zz - a.xx) * (a.zz - a.xx)) +
                       3 * (a.xy * a.xy + a.yz * a.yz + a.xz * a.xz));
    }
    case FieldScalar::Kind::principal: {
      double v[3];
      principal_values(symmetric(c, n), v);
      return v[s.component];
    }
  }
  return kNaN;
}

std::span<const double> step_values(const Mesh& mesh, const Field& f, std::size_t step) {
  if (step >= f.step_count())
    throw FieldSelectError("field '" + f.name + "' has " + std::to_string(f.step_count()) +
                           " step(s), not step " + std::to_string(step));
  return f.step(step, field_entity_count(mesh, f));
}

double tet_volume(const MeshView& mesh, std::size_t t) {
  const std::uint32_t* v = &mesh.tet[4 * t];
  const double* p0 = &mesh.xyz[3 * std::size_t(v[0])];
  double a[3][3];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) a[k][j] = mesh.xyz[3 * std::size_t(v[k + 1]) + std::size_t(j)] - p0[j];
  return std::abs(a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                  a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                  a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) /
         6;
}

// The scalar `pick` of the per-region, volume-weighted mean at each tet corner of a cell field of
// n components a tet (v: n per tet), so that values never blend across a material interface.
std::vector<double> cell_to_corners(const MeshView& mesh, std::span<const double> v, std::uint32_t n,
                                    const FieldScalar& pick) {
  std::vector<double> out(4 * mesh.tet_count());
  std::map<std::int32_t, std::uint32_t> region_index;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) region_index.emplace(mesh.region_of(t), 0);
  std::uint32_t r = 0;
  for (auto& [id, index] : region_index) index = r++;
  // Accumulators per (region, node) pair; a node touches few regions, so index pairs sparsely.
  std::vector<std::uint32_t> slot_of(4 * mesh.tet_count());
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> slot;
  std::vector<double> sum, weight;
  std::vector<std::uint32_t> tet_region_index(mesh.tet_count());
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) tet_region_index[t] = region_index[mesh.region_of(t)];
  if (region_index.size() == 1) {
    for (std::size_t i = 0; i < slot_of.size(); ++i) slot_of[i] = mesh.tet[i];
    sum.assign(mesh.node_count() * n, 0.0);
    weight.assign(mesh.node_count(), 0.0);
  } else {
    for (std::size_t i = 0; i < slot_of.size(); ++i) {
      auto [it, fresh] =
          slot.emplace(std::make_pair(tet_region_index[i / 4], mesh.tet[i]), std::uint32_t(weight.size()));
      if (fresh) weight.push_back(0);
      slot_of[i] = it->second;
    }
    sum.assign(weight.size() * n, 0.0);
  }
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const double w = tet_volume(mesh, t);
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t s = slot_of[4 * t + std::size_t(k)];
      weight[s] += w;
      for (std::uint32_t i = 0; i < n; ++i) sum[std::size_t(s) * n + i] += w * v[t * n + i];
    }
  }
  std::vector<double> scalar(weight.size());
  for (std::size_t s = 0; s < weight.size(); ++s) {
    for (std::uint32_t i = 0; i < n; ++i) sum[s * n + i] = weight[s] > 0 ? sum[s * n + i] / weight[s] : kNaN;
    scalar[s] = scalar_of(pick, &sum[s * n], n);
  }
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = scalar[slot_of[i]];
  return out;
}

}  // namespace

FieldChoice choose_field(const Mesh& mesh, std::string_view spec) {
  const std::size_t colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const std::string_view comp = colon == std::string_view::npos ? std::string_view() : spec.substr(colon + 1);
  FieldChoice c;
  c.field = mesh.find_field(name);
  if (c.field == nullptr) {
    std::string there;
    for (const Field& f : mesh.fields) there += (there.empty() ? "" : ", ") + f.name;
    throw FieldSelectError("no field '" + std::string(name) + "' in the mesh (" +
                           (there.empty() ? std::string("it has no fields") : "it has: " + there) + ")");
  }
  const std::uint32_t n = c.field->components;
  c.label = std::string(name);
  if (n == 0) throw FieldSelectError("field '" + c.field->name + "' has no components");
  if (colon != std::string_view::npos && comp.empty())
    throw FieldSelectError(
        "'" + std::string(spec) + "' names no component after the colon: give " + c.field->name +
        (n == 1 ? std::string(" alone (a scalar)")
                : " alone or " + c.field->name + ":COMPONENT (" + component_names(n) + ")"));
  if (comp.empty()) {
    if (n == 3) {
      c.scalar.kind = FieldScalar::Kind::magnitude;
      c.label += ", magnitude";
    } else if (is_tensor(n)) {
      c.scalar.kind = FieldScalar::Kind::von_mises;
      c.label += ", von Mises";
    } else if (n != 1) {
      throw FieldSelectError("field '" + c.field->name + "' has " + std::to_string(n) +
                             " components: choose one as " + c.field->name + ":COMPONENT (" +
                             component_names(n) + ")");
    }
    return c;
  }
  if (comp == "mag" && n == 3) {
    c.scalar.kind = FieldScalar::Kind::magnitude;
    c.label += ", magnitude";
    return c;
  }
  if ((comp == "vm" || comp == "von_mises") && is_tensor(n)) {
    c.scalar.kind = FieldScalar::Kind::von_mises;
    c.label += ", von Mises";
    return c;
  }
  if ((comp == "p1" || comp == "p2" || comp == "p3") && is_tensor(n)) {
    c.scalar.kind = FieldScalar::Kind::principal;
    c.scalar.component = std::uint32_t(comp[1] - '1');
    c.label += comp == "p1"   ? ", largest principal value"
               : comp == "p2" ? ", middle principal value"
                              : ", smallest principal value";
    return c;
  }
  const int i = component_index(comp, n);
  if (i < 0)
    throw FieldSelectError("field '" + c.field->name + "' has no component '" + std::string(comp) +
                           "' (it has " + component_names(n) + ")");
  c.scalar.component = std::uint32_t(i);
  c.label += " " + std::string(comp);
  return c;
}

std::vector<double> field_scalar_values(const Mesh& mesh, const FieldChoice& choice, std::size_t step) {
  const Field& f = *choice.field;
  const std::span<const double> v = step_values(mesh, f, step);
  const std::size_t count = field_entity_count(mesh, f);
  std::vector<double> out(count);
  for (std::size_t e = 0; e < count; ++e)
    out[e] = scalar_of(choice.scalar, &v[e * f.components], f.components);
  return out;
}

namespace {

// An infinite value is no value to colour, cut or integrate (an isosurface through one would sit at
// the finite end of every edge): NaN, the no-value grey, counted as such.
std::vector<double> no_infinities(std::vector<double> v) {
  for (double& x : v)
    if (std::isinf(x)) x = std::numeric_limits<double>::quiet_NaN();
  return v;
}

}  // namespace

std::vector<double> tet_centroid_values(const Mesh& mesh, const FieldChoice& choice, std::size_t step) {
  const Field& f = *choice.field;
  if (f.location == FieldLocation::cell) return no_infinities(field_scalar_values(mesh, choice, step));
  const std::span<const double> v = step_values(mesh, f, step);
  const std::uint32_t n = f.components;
  std::vector<double> out(mesh.tet_count()), c(n);
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    std::fill(c.begin(), c.end(), 0.0);
    for (int k = 0; k < 4; ++k) {
      const double* p = &v[std::size_t(mesh.tet[4 * t + std::size_t(k)]) * n];
      for (std::uint32_t i = 0; i < n; ++i) c[i] += 0.25 * p[i];
    }
    out[t] = scalar_of(choice.scalar, c.data(), n);
  }
  return no_infinities(std::move(out));
}

double field_value_in_tet(const Mesh& mesh, const FieldChoice& choice, std::size_t t, const double bary[4],
                          std::size_t step) {
  const Field& f = *choice.field;
  const std::span<const double> v = step_values(mesh, f, step);
  const std::uint32_t n = f.components;
  if (f.location == FieldLocation::cell) return scalar_of(choice.scalar, &v[t * n], n);
  std::vector<double> c(n, 0.0);
  for (int k = 0; k < 4; ++k) {
    const double* p = &v[std::size_t(mesh.tet[4 * t + std::size_t(k)]) * n];
    for (std::uint32_t i = 0; i < n; ++i) c[i] += bary[k] * p[i];
  }
  return scalar_of(choice.scalar, c.data(), n);
}

double deform_by_field(Mesh& mesh, std::string_view name, double scale, long step) {
  const Field* f = mesh.find_field(name);
  if (!f) {
    std::string have;
    for (const Field& g : mesh.fields)
      if (g.location == FieldLocation::node && g.components == 3) have += (have.empty() ? "" : ", ") + g.name;
    throw FieldSelectError("no field '" + std::string(name) + "' to deform by (3-component node fields: " +
                           (have.empty() ? "none" : have) + ")");
  }
  if (f->location != FieldLocation::node || f->components != 3)
    throw FieldSelectError("field '" + f->name +
                           "' is not a displacement: deforming needs a node field of 3 components, it is a " +
                           (f->location == FieldLocation::node ? "node" : "cell") + " field of " +
                           std::to_string(f->components));
  if (!std::isfinite(scale)) throw FieldSelectError("the deformation scale must be a finite number");
  const std::size_t s = step < 0 ? f->step_count() - 1 : std::size_t(step);
  const std::span<const double> u = step_values(mesh, *f, s);
  for (std::size_t i = 0; i < u.size(); ++i)
    if (std::isnan(u[i]))
      throw FieldSelectError("field '" + f->name + "' has no value (NaN) at node " +
                             std::to_string(i / 3 + 1) + ": that node cannot be moved");
  double largest = 0;
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = scale * u[3 * n + std::size_t(k)];
      mesh.xyz[3 * n + std::size_t(k)] += d;
      d2 += d * d;
    }
    largest = std::max(largest, std::sqrt(d2));
  }
  invalidate_derived(mesh);
  return largest;
}

std::vector<double> tet_corner_values(const Mesh& mesh, const FieldChoice& choice, std::size_t step) {
  const Field& f = *choice.field;
  std::vector<double> out(4 * mesh.tet_count());
  if (f.location == FieldLocation::node) {
    const std::vector<double> nodal = field_scalar_values(mesh, choice, step);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = nodal[mesh.tet[i]];
    return no_infinities(std::move(out));
  }
  // Cell field: per region, volume-weighted mean of the components of the region's tets at each node.
  return no_infinities(cell_to_corners(mesh, step_values(mesh, f, step), f.components, choice.scalar));
}

std::vector<double> node_corner_values(const MeshView& mesh, std::span<const double> node_values) {
  if (node_values.size() != mesh.node_count())
    throw std::invalid_argument("node_corner_values: " + std::to_string(node_values.size()) +
                                " values for a mesh of " + std::to_string(mesh.node_count()) + " nodes");
  std::vector<double> out(mesh.tet.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = node_values[mesh.tet[i]];
  return out;
}

std::vector<double> cell_corner_values(const MeshView& mesh, std::span<const double> cell_values) {
  if (cell_values.size() != mesh.tet_count())
    throw std::invalid_argument("cell_corner_values: " + std::to_string(cell_values.size()) +
                                " values for a mesh of " + std::to_string(mesh.tet_count()) + " tets");
  return cell_to_corners(mesh, cell_values, 1, FieldScalar{});
}

std::optional<DisplayUnit> display_unit(std::string_view si, std::string_view d) {
  struct Conv {
    const char* si;
    const char* name;
    const char* symbol;
    double factor, offset;
  };
  static const Conv kConv[] = {
      {"K", "degC", "°C", 1, 273.15}, {"K", "°C", "°C", 1, 273.15},  {"K", "C", "°C", 1, 273.15},
      {"Pa", "kPa", "kPa", 1e-3, 0},  {"Pa", "MPa", "MPa", 1e-6, 0}, {"Pa", "GPa", "GPa", 1e-9, 0},
      {"m", "mm", "mm", 1e3, 0},      {"m", "um", "µm", 1e6, 0},     {"m", "µm", "µm", 1e6, 0},
      {"m", "nm", "nm", 1e9, 0},      {"V", "mV", "mV", 1e3, 0},     {"V", "kV", "kV", 1e-3, 0},
      {"W", "mW", "mW", 1e3, 0},
  };
  if (d == si) return DisplayUnit{std::string(si), 1, 0};
  for (const Conv& c : kConv)
    if (si == c.si && d == c.name) return DisplayUnit{c.symbol, c.factor, c.offset};
  return std::nullopt;
}

DisplayUnit default_display_unit(std::string_view si, double max_abs) {
  if (si == "K") return *display_unit(si, "degC");
  if (si == "Pa") return *display_unit(si, "MPa");
  if (si == "m") return *display_unit(si, "um");
  if (si == "V" && max_abs < 1) return *display_unit(si, "mV");
  return DisplayUnit{std::string(si), 1, 0};
}

FieldPaint flat_field_paint(std::span<const double> tet_values, const ColorScale& scale) {
  FieldPaint p;
  p.scale = scale;
  p.tet_color.resize(tet_values.size());
  for (std::size_t t = 0; t < tet_values.size(); ++t) p.tet_color[t] = scale.color(tet_values[t]);
  return p;
}

FieldPaint graded_field_paint(std::span<const double> corner_values, const ColorScale& scale) {
  FieldPaint p;
  p.scale = scale;
  p.graded = true;
  p.corner_position.resize(corner_values.size());
  for (std::size_t i = 0; i < corner_values.size(); ++i)
    p.corner_position[i] = float(scale.position(corner_values[i]));
  return p;
}

std::pair<double, double> finite_range(std::span<const double> values, bool positive_only) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (std::isfinite(v) && (!positive_only || v > 0)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  if (lo > hi) return {kNaN, kNaN};
  return {lo, hi};
}

std::optional<AutoScale> automatic_scale(std::span<const double> values, ColorMapId map, bool log) {
  auto [lo, hi] = finite_range(values, log);
  if (std::isnan(lo)) return std::nullopt;
  AutoScale a;
  if (!(lo < hi)) {  // a constant: a range around it, so it shows mid-map
    const double d = lo != 0 ? std::abs(lo) * (log ? 0.5 : 0.01) : 1;
    lo -= d;
    hi += d;
    a.widened = true;
  }
  // A diverging map shows signed values about zero: its centre (white) at 0.
  if (map == ColorMapId::coolwarm && !log && lo < 0 && hi > 0) {
    hi = std::max(-lo, hi);
    lo = -hi;
    a.centred = true;
  }
  a.scale.map = map;
  a.scale.log = log;
  a.scale.lo = lo;
  a.scale.hi = hi;
  return a;
}

}  // namespace foxi
