// The tets a field picture draws: see field_selection.hpp. Moved from foxi render's option handling
// (apps/foxi/iso_options.cpp) so that the workbench's view selects by the same rule.
#include "foxi/viz/field_selection.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace foxi {

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// Keeps the tets of `set` that `keep` marks.
void intersect(std::vector<std::uint32_t>& set, const std::vector<std::uint8_t>& keep) {
  set.erase(std::remove_if(set.begin(), set.end(), [&](std::uint32_t t) { return keep[t] == 0; }), set.end());
}

}  // namespace

IsoDrawing TetSelection::drawing() const {
  IsoDrawing d;
  if (corner) d.corner = *corner;
  if (attr) d.attr = *attr;
  d.params = params;
  return d;
}

IsoCache make_iso_cache(const Mesh& mesh, const FieldChoice& choice, std::size_t step) {
  IsoCache c;
  c.corner = std::make_shared<const std::vector<double>>(tet_corner_values(mesh, choice, step));
  c.centroid = tet_centroid_values(mesh, choice, step);
  c.tree = std::make_shared<const TetIntervals>(*c.corner);
  return c;
}

TetSelection select_field_tets(const FieldSelection& options, const Mesh& mesh, const FieldChoice& choice,
                               std::size_t step, const ColorScale& scale, std::span<const std::uint32_t> base,
                               IsoCache* cache) {
  if (options.slice && !options.iso.empty())
    throw std::invalid_argument(
        "field selection: a slice and isovalues are both the polygons drawn: give one");
  TetSelection r;
  IsoCache local;
  IsoCache& c = cache ? *cache : local;
  const std::size_t n = mesh.tet_count();
  // Membership of the tets selected so far (all, or base), built only when something narrows it: an
  // isovalue alone over all tets then costs its query, not a pass over the mesh.
  const bool narrows = !base.empty() || options.threshold || options.clip;
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
      c.corner = std::make_shared<const std::vector<double>>(tet_corner_values(mesh, choice, step));
    return c.corner;
  };
  if (options.threshold) {
    if (c.centroid.empty()) c.centroid = tet_centroid_values(mesh, choice, step);
    const auto [a, b] = *options.threshold;
    narrow(threshold_tets(c.centroid, std::min(a, b), std::max(a, b)));
  }
  if (options.clip) narrow(clip_tets(mesh, *options.clip));
  r.params.scale = scale;
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
    r.iso_si = options.iso;
    r.params.values = r.iso_si;
    r.params.cap = !options.iso_only;
    auto t0 = std::chrono::steady_clock::now();
    if (!c.tree) {
      c.tree = std::make_shared<const TetIntervals>(*r.corner);
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

}  // namespace foxi
