#include "composite_options.hpp"

#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>

#include "foxi/viz/camera.hpp"
#include "foxi/viz/view_options.hpp"

namespace foxi::cli {

const char* const kCompositeOptionsHelp =
    "  --region-opacity REGION=a,...  translucent regions (an \"x-ray\" view): REGION a region id or\n"
    "                  name, a its opacity from 0 (left out) to 1 (opaque; regions not listed). Drawn\n"
    "                  are the faces between regions of different opacity and the outer boundary of\n"
    "                  what is drawn, one layer each (the picture does not depend on the mesh\n"
    "                  density), blended back to front in the power order of the tets that own them,\n"
    "                  which is exact for a Delaunay mesh. A mesh without the certificate has no such\n"
    "                  order: its fragments are collected and sorted per pixel by depth instead (said\n"
    "                  so; memory grows with the fragments). With --iso, the isosurfaces translucent\n"
    "                  inside. Not with --threshold, --clip, --slice, --shrink, --markers; a field\n"
    "                  colours only the isosurfaces\n"
    "  --iso-opacity a every isosurface of --iso translucent with opacity a, all nested ones seen at\n"
    "                  once (with --region-opacity inside the translucent regions, else alone)\n"
    "  --volume NAME[:C]  a volume rendering of the field (as --field takes it; --cmap, --range,\n"
    "                  --units, --step, --legend apply): the emission-absorption integral of the\n"
    "                  field, linear in each tet, along every pixel's ray, tets composited back to\n"
    "                  front in the power order (exact for a Delaunay mesh; another mesh is\n"
    "                  composited in MPVO order, not exact, and a note says so). Colour: the colour\n"
    "                  map; opacity: --opacity-curve v0:a0,... (values in display units, ascending;\n"
    "                  a in [0, 0.999999]: the opacity a ray gains through --opacity-length L world units "
    "of\n"
    "                  that value, L by default a tenth of the drawn box's diagonal), linear between\n"
    "                  the points, constant beyond. Not with the other drawing options\n";

CompositeOptions take_composite_options(Args& args) {
  CompositeOptions o;
  o.volume = args.option("--volume");
  // Args are rebuilt below, which forgets what was taken: a second --volume would read as unknown.
  if (args.has_option("--volume")) throw UsageError("option --volume given twice (give it once)");
  if (!o.volume.empty()) {
    if (args.has_option("--field")) throw UsageError("--volume NAME names the field: leave out --field");
    std::vector<std::string> rest = args.remaining();
    rest.insert(rest.end(), {"--field", o.volume});
    args = Args(std::move(rest));
  }
  const std::string curve = args.option("--opacity-curve"), length = args.option("--opacity-length");
  o.region_opacity = args.option("--region-opacity");
  const std::string iso_opacity = args.option("--iso-opacity");
  if (!iso_opacity.empty()) {
    o.has_iso_opacity = true;
    o.iso_opacity = parse_opacity(iso_opacity, "--iso-opacity");
    if (!(o.iso_opacity > 0)) throw UsageError("--iso-opacity 0 draws the isosurfaces invisible: give a > 0");
  }
  if (o.volume_on() != !curve.empty() || (!length.empty() && !o.volume_on()))
    throw UsageError("--volume NAME and --opacity-curve v0:a0,... go together (--opacity-length with them)");
  if (o.volume_on()) {
    o.curve = parse_opacity_curve(curve);
    if (!length.empty()) {
      char* end = nullptr;
      o.opacity_length = std::strtod(length.c_str(), &end);
      if (*end != 0 || !(o.opacity_length > 0) || !std::isfinite(o.opacity_length))
        throw UsageError("--opacity-length takes a positive length (world units), not '" + length + "'");
    }
  }
  return o;
}

void check_composite_options(const CompositeOptions& o, const FieldOptions& field, const IsoOptions& iso,
                             double shrink) {
  if (o.has_iso_opacity && iso.iso.empty())
    throw UsageError("--iso-opacity makes the isosurfaces of --iso translucent: give --iso");
  if (o.translucent() && (iso.has_threshold || iso.clip || iso.slice || shrink != 1 || field.markers))
    throw UsageError(
        "--region-opacity and --iso-opacity draw the whole picture translucent: leave out --threshold, "
        "--clip, --slice, --shrink and --markers");
  if (o.volume_on() && (o.translucent() || iso.any() || shrink != 1 || field.markers))
    throw UsageError(
        "--volume draws the field alone: leave out --region-opacity, --iso-opacity, --iso, --threshold, "
        "--clip, --slice, --shrink and --markers");
  if (o.translucent() && !field.spec.empty() && iso.iso.empty())
    throw UsageError(
        "translucent regions are drawn in their regions' colours: --field serves only --iso there "
        "(give --iso v1,... --iso-opacity a, or leave out --field)");
}

namespace {

std::string number(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

TranslucentParams translucent_params(const CompositeOptions& o, const Mesh& mesh, const RenderParams& render,
                                     const IsoPicture& iso, double scale) {
  TranslucentParams tp;
  if (!o.region_opacity.empty()) tp.region_opacity = parse_region_opacity(mesh, o.region_opacity);
  tp.regions = !o.region_opacity.empty();
  tp.region_colors = render.region_colors;
  for (RegionOpacity& r : tp.region_opacity) {
    r.opacity *= scale;
    if (!(r.opacity <= 1))
      throw UsageError("region " + std::to_string(r.region) + "'s opacity times " + number(scale) + " is " +
                       number(r.opacity) + ", more than 1 (opaque)");
  }
  if (iso.corner && !iso.params.values.empty()) {
    tp.corner = *iso.corner;  // shared: lives as long as iso
    tp.iso = iso.params;
    tp.iso_opacity = o.iso_opacity * scale;
    if (!(tp.iso_opacity <= 1))
      throw UsageError("--iso-opacity times " + number(scale) + " is " + number(tp.iso_opacity) +
                       ", more than 1 (opaque)");
  }
  return tp;
}

VolumeParams volume_params(const CompositeOptions& o, const Mesh& mesh, const FieldPicture& field,
                           std::span<const std::uint32_t> subset, double scale) {
  VolumeParams vp;
  vp.scale = field.legend.scale;
  for (const OpacityPoint& p : o.curve) {
    vp.opacity_curve.push_back({field.legend.unit.to_si(p.value), p.opacity * scale});
    if (!(vp.opacity_curve.back().opacity <= 0.999999))  // as parse_opacity_curve
      throw UsageError("--opacity-curve: opacity " + number(p.opacity) + " times " + number(scale) + " is " +
                       number(p.opacity * scale) + ", above 0.999999");
    const std::size_t n = vp.opacity_curve.size();
    if (n > 1 && !(vp.opacity_curve[n - 1].value > vp.opacity_curve[n - 2].value))
      throw UsageError("--opacity-curve: the values " + number(o.curve[n - 2].value) + " and " +
                       number(p.value) + " " + field.legend.unit.symbol + " are the same in SI (" +
                       number(vp.opacity_curve[n - 1].value) + " " + field.choice.field->unit +
                       "): give values further apart");
  }
  if (vp.opacity_curve.size() > 1) {  // as the painter needs (volume.hpp)
    const double span = vp.opacity_curve.back().value - vp.opacity_curve.front().value;
    if (!std::isfinite(span) || !std::isfinite(4096 / span))
      throw UsageError("--opacity-curve: its values span " + number(span) + " " + field.choice.field->unit +
                       " in SI: give a span between 1e-290 and 1e308");
  }
  double lo[3], hi[3];
  tets_bounds(mesh, subset, lo, hi);
  vp.unit_length = o.opacity_length > 0 ? o.opacity_length
                                        : 0.1 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) +
                                                          (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                                          (hi[2] - lo[2]) * (hi[2] - lo[2]));
  return vp;
}

}  // namespace foxi::cli
