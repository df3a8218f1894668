#include "iso_options.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

namespace foxi::cli {

const char* const kIsoOptionsHelp =
    "  --iso v1,v2,... isosurfaces of the field at these values (display units), found through an\n"
    "                  interval tree of the tets' value ranges and drawn at their tets' places in the\n"
    "                  visibility order: by default the solid where the field is >= the lowest value,\n"
    "                  cut at that isosurface (the tets it cuts drawn as their part above it; --graded\n"
    "                  suits it); the legend marks the values\n"
    "  --iso-only      the isosurfaces alone, every value, two-sided: the side toward higher values in\n"
    "                  the value's colour, the other side darker\n"
    "  --threshold a,b only the tets whose value (at the centroid; a cell field's own) is in [a, b]\n"
    "  --clip px,py,pz,nx,ny,nz  crinkle clip: only the whole tets whose centroid lies behind the plane\n"
    "                  (n points to the part cut away)\n"
    "  --slice px,py,pz,nx,ny,nz the plane's cut through the mesh, coloured by the field (both sides)\n"
    "  These combine with each other and with --regions (the tets must satisfy all): a slice with\n"
    "  --threshold or --clip is the plane's cut through the tets they keep. --slice and --iso do not\n"
    "  combine (both are the polygons drawn); all need --field.\n";

namespace {

Plane parse_plane(const std::string& s, const char* what) {
  const std::vector<double> v = parse_numbers(s, what);
  if (v.size() != 6)
    throw UsageError(std::string(what) + " takes px,py,pz,nx,ny,nz (a point and a normal), not '" + s + "'");
  Plane p;
  for (int k = 0; k < 3; ++k) p.p[k] = v[std::size_t(k)], p.n[k] = v[std::size_t(k) + 3];
  if (!(p.n[0] * p.n[0] + p.n[1] * p.n[1] + p.n[2] * p.n[2] > 0))
    throw UsageError(std::string(what) + ": the normal must not be zero ('" + s + "')");
  for (double x : v)
    if (!std::isfinite(x)) throw UsageError(std::string(what) + " takes finite numbers, not '" + s + "'");
  return p;
}

}  // namespace

IsoOptions take_iso_options(Args& args, const FieldOptions& field) {
  IsoOptions o;
  const std::string iso = args.option("--iso"), threshold = args.option("--threshold"),
                    clip = args.option("--clip"), slice = args.option("--slice");
  o.iso_only = args.flag("--iso-only");
  if (!iso.empty()) {
    o.iso = parse_numbers(iso, "--iso");
    if (o.iso.empty()) throw UsageError("--iso takes values v1,v2,...");
    for (double v : o.iso)
      if (!std::isfinite(v)) throw UsageError("--iso takes finite values, not '" + iso + "'");
  }
  if (o.iso_only && o.iso.empty())
    throw UsageError("--iso-only draws the isosurfaces of --iso v1,v2,...: give --iso");
  if (!threshold.empty()) {
    const std::vector<double> r = parse_numbers(threshold, "--threshold");
    if (r.size() != 2 || !(r[0] <= r[1]))
      throw UsageError("--threshold takes a,b with a <= b, not '" + threshold + "'");
    o.has_threshold = true;
    o.threshold[0] = r[0];
    o.threshold[1] = r[1];
  }
  if (!clip.empty()) o.clip = parse_plane(clip, "--clip");
  if (!slice.empty()) o.slice = parse_plane(slice, "--slice");
  if (o.any() && field.spec.empty())
    throw UsageError(
        "--iso, --threshold, --clip and --slice select by a field or draw it: give --field NAME");
  if (o.slice && !o.iso.empty())
    throw UsageError(
        "--slice and --iso both draw polygons, one kind a picture: give one (a slice combines with "
        "--threshold and --clip)");
  return o;
}

std::optional<std::pair<double, double>> iso_values_outside(const IsoPicture& iso,
                                                            std::vector<double>& outside) {
  outside.clear();
  if (iso.iso_si.empty() || !iso.corner) return std::nullopt;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : *iso.corner)
    if (!std::isnan(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  for (double v : iso.iso_si)
    if (!(v >= lo && v <= hi)) outside.push_back(v);
  if (!(lo <= hi)) return std::nullopt;
  return std::pair{lo, hi};
}

void warn_iso_outside(const IsoPicture& iso, const FieldPicture& field) {
  std::vector<double> outside;
  const auto range = iso_values_outside(iso, outside);
  if (outside.empty()) return;
  const DisplayUnit& u = field.legend.unit;
  const std::string unit = u.symbol.empty() ? "" : " " + u.symbol;
  std::string values;
  for (double v : outside) {
    char b[64];
    std::snprintf(b, sizeof b, "%s%.6g", values.empty() ? "" : ", ", u.to_display(v));
    values += b;
  }
  char r[160];
  if (range)
    std::snprintf(r, sizeof r, "the field's values %.6g to %.6g%s", u.to_display(range->first),
                  u.to_display(range->second), unit.c_str());
  else
    std::snprintf(r, sizeof r, "the field, which has no finite value");
  std::printf("warning     --iso %s%s lies outside %s: no isosurface there\n", values.c_str(), unit.c_str(),
              r);
}

IsoPicture resolve_iso(const IsoOptions& options, const Mesh& mesh, const FieldPicture& field,
                       std::span<const std::uint32_t> base, IsoCache* cache) {
  // The options are in the field's display unit; the library's rule takes SI.
  const DisplayUnit& unit = field.legend.unit;
  FieldSelection s;
  for (double v : options.iso) s.iso.push_back(unit.to_si(v));
  s.iso_only = options.iso_only;
  if (options.has_threshold)
    s.threshold = {unit.to_si(options.threshold[0]), unit.to_si(options.threshold[1])};
  s.clip = options.clip;
  s.slice = options.slice;
  return select_field_tets(s, mesh, field.choice, field.step, field.legend.scale, base, cache);
}

}  // namespace foxi::cli
