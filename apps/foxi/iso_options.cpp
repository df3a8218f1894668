#include "iso_options.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

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
    "  These combine with each other and with --regions (the tets must satisfy all), except --slice,\n"
    "  which is drawn alone; all need --field.\n";

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

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// Keeps the tets of `set` that `keep` marks.
void intersect(std::vector<std::uint32_t>& set, const std::vector<std::uint8_t>& keep) {
  set.erase(std::remove_if(set.begin(), set.end(), [&](std::uint32_t t) { return keep[t] == 0; }), set.end());
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
  if (o.iso_only && o.iso.empty()) throw UsageError("--iso-only draws the isosurfaces of --iso v1,v2,...: give --iso");
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
    throw UsageError("--iso, --threshold, --clip and --slice select by a field or draw it: give --field NAME");
  if (o.slice && (!o.iso.empty() || o.has_threshold || o.clip))
    throw UsageError("--slice is drawn alone: leave out --iso, --threshold and --clip");
  return o;
}

IsoDrawing IsoPicture::drawing() const {
  IsoDrawing d;
  if (corner) d.corner = *corner;
  if (attr) d.attr = *attr;
  d.params = params;
  return d;
}

IsoPicture resolve_iso(const IsoOptions& options, const Mesh& mesh, const FieldPicture& field,
                       std::span<const std::uint32_t> base, IsoCache* cache) {
  IsoPicture r;
  IsoCache local;
  IsoCache& c = cache ? *cache : local;
  const std::size_t n = mesh.tet_count();
  const DisplayUnit& unit = field.legend.unit;
  // Membership of the tets selected so far (all, or base), built only when something narrows it: an
  // isovalue alone over all tets then costs its query, not a pass over the mesh.
  const bool narrows = !base.empty() || options.has_threshold || options.clip;
  std::vector<std::uint8_t> keep;
  if (narrows) {
    keep.assign(n, base.empty() ? 1 : 0);
    for (std::uint32_t t : base) keep[t] = 1;
  }
  auto narrow = [&](const std::vector<std::uint32_t>& set) {
    std::vector<std::uint8_t> in(n, 0);
    for (std::uint32_t t : set) in[t] = 1;
    for (std::size_t t = 0; t < n; ++t) keep[t] &= in[t];
  };
  auto corners = [&] {
    if (!c.corner)
      c.corner = std::make_shared<const std::vector<double>>(tet_corner_values(mesh, field.choice, field.step));
    return c.corner;
  };
  if (options.has_threshold) {
    if (c.centroid.empty()) c.centroid = tet_centroid_values(mesh, field.choice, field.step);
    narrow(threshold_tets(c.centroid, std::min(unit.to_si(options.threshold[0]), unit.to_si(options.threshold[1])),
                          std::max(unit.to_si(options.threshold[0]), unit.to_si(options.threshold[1]))));
  }
  if (options.clip) narrow(clip_tets(mesh, *options.clip));
  r.params.scale = field.legend.scale;
  if (options.slice) {
    r.polygons = true;
    const auto plane = std::make_shared<const std::vector<double>>(plane_corner_values(mesh, *options.slice));
    r.corner = plane;
    r.attr = corners();
    r.params.values = {0};
    r.params.cold_side = 1;
    const auto t0 = std::chrono::steady_clock::now();
    r.subset = crossing_scan(*plane, 0);  // one plane, one pass: no tree to amortise
    r.query_ms = ms_since(t0);
    if (narrows) intersect(r.subset, keep);
    r.crossing = r.subset.size();
  } else if (!options.iso.empty()) {
    r.polygons = true;
    r.corner = corners();
    for (double v : options.iso) r.iso_si.push_back(unit.to_si(v));
    r.params.values = r.iso_si;
    r.params.cap = !options.iso_only;
    auto t0 = std::chrono::steady_clock::now();
    if (!c.tree) {
      c.tree = std::make_unique<TetIntervals>(*r.corner);
      r.build_ms = ms_since(t0);
    }
    t0 = std::chrono::steady_clock::now();
    c.tree->crossing_any(r.iso_si, r.subset);
    r.crossing = r.subset.size();
    if (r.params.cap) {
      r.subset.clear();
      c.tree->reaching(*std::min_element(r.iso_si.begin(), r.iso_si.end()), r.subset);
    }
    r.query_ms = ms_since(t0);
    if (narrows) intersect(r.subset, keep);
  } else {
    for (std::size_t t = 0; t < n; ++t)
      if (!narrows || keep[t]) r.subset.push_back(std::uint32_t(t));
  }
  r.empty = r.subset.empty();
  return r;
}

}  // namespace foxi::cli
