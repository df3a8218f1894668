// The front ends' picture options read from text (view_options.hpp).
#include "foxi/viz/view_options.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <random>
#include <string>

namespace foxi {

namespace {

void triple(std::string_view s, const char* what, double out[3]) {
  const std::vector<double> v = parse_number_list(s, what);
  if (v.size() != 3) throw OptionError(std::string(what) + " takes x,y,z");
  for (int k = 0; k < 3; ++k) out[k] = v[std::size_t(k)];
}

}  // namespace

std::vector<double> parse_number_list(std::string_view text, std::string_view what) {
  const std::string s(text);
  std::vector<double> v;
  std::size_t pos = 0;
  while (pos <= s.size()) {
    const std::size_t comma = s.find(',', pos);
    const std::string part = s.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    char* end = nullptr;
    const double x = std::strtod(part.c_str(), &end);
    if (part.empty() || end != part.c_str() + part.size() || !std::isfinite(x))
      throw OptionError(std::string(what) + " takes comma-separated numbers, not '" + s + "'");
    v.push_back(x);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return v;
}

CameraOptions parse_camera_options(std::string_view eye, std::string_view at, std::string_view up,
                                   std::string_view fov, std::string_view dir) {
  if (!dir.empty() && (!eye.empty() || !fov.empty()))
    throw OptionError("--dir (orthographic) cannot be combined with --eye or --fov");
  CameraOptions o;
  if ((o.has_up = !up.empty())) triple(up, "--up", o.up);
  if ((o.has_at = !at.empty())) triple(at, "--at", o.at);
  if ((o.has_eye = !eye.empty())) triple(eye, "--eye", o.eye);
  if ((o.has_dir = !dir.empty())) {
    triple(dir, "--dir", o.dir);
    if (o.dir[0] == 0 && o.dir[1] == 0 && o.dir[2] == 0) throw OptionError("--dir takes a nonzero x,y,z");
  }
  if (!fov.empty()) {
    const std::string f(fov);
    char* end = nullptr;
    o.fov_deg = std::strtod(f.c_str(), &end);
    if (*end != 0 || !(o.fov_deg > 0 && o.fov_deg < 180))
      throw OptionError("--fov takes degrees in (0, 180)");
  }
  return o;
}

Camera camera_for(const CameraOptions& o, const double lo[3], const double hi[3], double aspect) {
  // A direction's length does not matter: scaled to a largest component of 1, so that 1e-300,0,1e-300
  // is a direction (its square underflowed to zero).
  double dir[3] = {o.dir[0], o.dir[1], o.dir[2]};
  const double largest = std::max({std::abs(dir[0]), std::abs(dir[1]), std::abs(dir[2])});
  if (o.has_dir && largest > 0 && std::isfinite(largest))
    for (double& d : dir) d /= largest;
  const Camera c = camera_from_options(lo, hi, aspect, o.has_eye ? o.eye : nullptr, o.has_at ? o.at : nullptr,
                                       o.has_up ? o.up : nullptr, o.fov_deg, o.has_dir ? dir : nullptr);
  // What a projection refuses later as "degenerate", said here with the options' names.
  const double d[3] = {c.at[0] - c.eye[0], c.at[1] - c.eye[1], c.at[2] - c.eye[2]};
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (!o.has_dir && dd == 0)
    throw OptionError(o.has_at
                          ? "--eye is the point --at looks at: give two different points"
                          : "--eye is the centre of the drawn box, which --at defaults to: give --at (the "
                            "point to look at)");
  if (!std::isfinite(dd))
    throw OptionError("--eye and --at are too far apart (" + std::to_string(std::hypot(d[0], d[1], d[2])) +
                      ") to project with doubles: bring the eye nearer");
  const double r[3] = {d[1] * c.up[2] - d[2] * c.up[1], d[2] * c.up[0] - d[0] * c.up[2],
                       d[0] * c.up[1] - d[1] * c.up[0]};
  if (o.has_up && !(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] > 0))
    throw OptionError("--up is parallel to the view direction: give another");
  return c;
}

std::vector<std::string> split_option_values(std::vector<std::string> args) {
  std::vector<std::string> out;
  bool passing = false;
  for (std::string& a : args) {
    const std::size_t eq = a.find('=');
    if (!passing && a.size() > 2 && a[0] == '-' && a[1] == '-' && eq != std::string::npos && eq > 2) {
      out.push_back(a.substr(0, eq));
      out.push_back(a.substr(eq + 1));
    } else {
      out.push_back(std::move(a));
    }
    passing = passing || out.back() == "--";
  }
  return out;
}

ImageSize parse_image_size(std::string_view text) {
  const std::string size(text);
  const std::size_t x = size.find('x');
  char* e1 = nullptr;
  char* e2 = nullptr;
  const std::string w = size.substr(0, x), h = x == std::string::npos ? "" : size.substr(x + 1);
  const long lw = std::strtol(w.c_str(), &e1, 10), lh = std::strtol(h.c_str(), &e2, 10);
  if (x == std::string::npos || w.empty() || h.empty() || *e1 != 0 || *e2 != 0 || lw < 1 || lh < 1 ||
      lw > 16384 || lh > 16384)
    throw OptionError("--size takes WxH with 1 <= W, H <= 16384, not '" + size + "'");
  return {int(lw), int(lh)};
}

double parse_shrink(std::string_view text) {
  const std::string s(text);
  char* end = nullptr;
  const double f = std::strtod(s.c_str(), &end);
  if (*end != 0 || !(f > 0 && f <= 1)) throw OptionError("--shrink takes a factor in (0, 1]");
  return f;
}

std::vector<std::uint32_t> tets_of_regions(const Mesh& mesh, std::string_view ids_text,
                                           std::string_view what) {
  const std::vector<double> ids = parse_number_list(ids_text, what);
  std::vector<std::uint32_t> out;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t)
    for (double id : ids)
      if (mesh.region_of(t) == static_cast<std::int32_t>(id)) {
        out.push_back(static_cast<std::uint32_t>(t));
        break;
      }
  return out;
}

std::vector<std::uint32_t> parse_subset(const Mesh& mesh, std::string_view spec_text, unsigned seed) {
  const std::string spec(spec_text);
  const std::size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : spec.substr(colon + 1);
  std::vector<std::uint32_t> subset;
  if (kind == "regions") {
    subset = tets_of_regions(mesh, rest, "--subset regions:");
  } else if (kind == "random") {
    const double f = parse_number_list(rest, "--subset random:")[0];
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    for (std::size_t t = 0; t < mesh.tet_count(); ++t)
      if (u(rng) < f) subset.push_back(static_cast<std::uint32_t>(t));
  } else if (kind == "box") {
    const std::vector<double> b = parse_number_list(rest, "--subset box:");
    if (b.size() != 6) throw OptionError("--subset box: takes x0,y0,z0,x1,y1,z1");
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      double c[3] = {0, 0, 0};
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j)
          c[j] += 0.25 * mesh.xyz[3 * std::size_t(mesh.tet[4 * t + std::size_t(k)]) + std::size_t(j)];
      bool in = true;
      for (int j = 0; j < 3; ++j) in = in && c[j] >= b[std::size_t(j)] && c[j] <= b[3 + std::size_t(j)];
      if (in) subset.push_back(static_cast<std::uint32_t>(t));
    }
  } else {
    throw OptionError("--subset takes regions:..., random:... or box:...");
  }
  if (subset.empty()) throw OptionError("the subset '" + spec + "' selects no tets");
  return subset;
}

double parse_opacity(std::string_view text, std::string_view what) {
  const std::string s(text);
  char* end = nullptr;
  const double a = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !(a >= 0 && a <= 1))
    throw OptionError(std::string(what) + " takes an opacity from 0 (invisible) to 1 (opaque), not '" + s +
                      "'");
  return a;
}

std::vector<RegionOpacity> parse_region_opacity(const Mesh& mesh, std::string_view text) {
  std::vector<RegionOpacity> out;
  const std::string s(text);
  std::size_t pos = 0;
  while (pos <= s.size()) {
    const std::size_t comma = s.find(',', pos);
    const std::string part = s.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    // The last '=' splits, so a region name may hold one.
    const std::size_t eq = part.rfind('=');
    if (eq == std::string::npos || eq == 0)
      throw OptionError(
          "--region-opacity takes REGION=a,... (a region id or name and an opacity in [0, 1]), not '" + part +
          "'");
    const std::string key = part.substr(0, eq);
    const std::optional<std::int32_t> id = region_id_of(mesh, key);
    // A number no tet carries would leave the picture opaque in silence.
    bool present = false;
    for (std::size_t t = 0; id && t < mesh.tet_count() && !present; ++t) present = mesh.region_of(t) == *id;
    if (!id || !present) {
      std::vector<std::int32_t> ids;
      for (std::size_t t = 0; t < mesh.tet_count(); ++t) ids.push_back(mesh.region_of(t));
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      std::string there;
      for (std::size_t i = 0; i < ids.size() && i < 20; ++i) {
        there += (i ? ", " : "") + std::to_string(ids[i]);
        for (const Region& r : mesh.regions)
          if (r.id == ids[i] && !r.name.empty()) there += " (" + r.name + ")";
      }
      if (ids.size() > 20) there += ", ...";
      throw OptionError("--region-opacity: the mesh has no region '" + key +
                        "' (its tets' regions: " + there + ")");
    }
    for (const RegionOpacity& r : out)
      if (r.region == *id) throw OptionError("--region-opacity: region '" + key + "' given twice");
    out.push_back({*id, parse_opacity(part.substr(eq + 1), "--region-opacity " + key + "=")});
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

std::vector<OpacityPoint> parse_opacity_curve(std::string_view text) {
  std::vector<OpacityPoint> out;
  const std::string s(text);
  std::size_t pos = 0;
  auto number = [](const std::string& part, double& x) {
    char* end = nullptr;
    x = std::strtod(part.c_str(), &end);
    return !part.empty() && end == part.c_str() + part.size() && std::isfinite(x);
  };
  while (pos <= s.size()) {
    const std::size_t comma = s.find(',', pos);
    const std::string part = s.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    const std::size_t colon = part.find(':');
    OpacityPoint p;
    if (colon == std::string::npos || !number(part.substr(0, colon), p.value) ||
        !number(part.substr(colon + 1), p.opacity))
      throw OptionError("--opacity-curve takes v0:a0,v1:a1,... (values and opacities), not '" + part + "'");
    // The painter's extinction holds opacities up to 0.999999 (volume_extinction clamps there): a
    // nearer 1 would be drawn as that in silence.
    if (!(p.opacity >= 0 && p.opacity <= 0.999999))
      throw OptionError("--opacity-curve: opacity " + part.substr(colon + 1) +
                        " is not in [0, 0.999999] (a ray through the opacity length keeps at least a "
                        "millionth of the light)");
    if (!out.empty() && !(p.value > out.back().value))
      throw OptionError("--opacity-curve: the values must increase ('" + part + "')");
    out.push_back(p);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

}  // namespace foxi
