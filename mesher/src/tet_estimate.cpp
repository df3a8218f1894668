// The tet count of a mesh before it is made (tet_estimate.hpp).
#include "foxi/mesher/tet_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "foxi/mesher/size_field.hpp"

namespace foxi {

namespace {

constexpr double kTetsPerBoundVolume = 2;  // tets per (region volume / volume bound), measured
constexpr double kTetsPerPoint = 5;        // tets per PLC point without a size bound

double tet_volume(const double* a, const double* b, const double* c, const double* d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
               w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return std::abs(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                  u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6;
}

}  // namespace

double estimate_tet_count(const Plc& plc, const MeshParams& params, std::span<const double> region_volume) {
  const double global = params.max_volume > 0 ? params.max_volume : 0;
  double sized = 0;
  // volume bounds: per region where its volume is known, else the bounding box under one bound
  std::map<std::int32_t, double> bound;  // region id -> its volume bound (0: none)
  for (const RegionSeed& s : plc.regions) {
    double b = global;
    if (s.max_volume > 0) b = b > 0 ? std::min(b, s.max_volume) : s.max_volume;
    auto [it, fresh] = bound.emplace(s.id, b);
    if (!fresh && b > 0) it->second = it->second > 0 ? std::min(it->second, b) : b;
  }
  if (!region_volume.empty()) {
    for (const auto& [id, b] : bound)
      if (b > 0 && id >= 1 && static_cast<std::size_t>(id) <= region_volume.size())
        sized += kTetsPerBoundVolume * region_volume[static_cast<std::size_t>(id - 1)] / b;
  } else {
    double b = global;
    if (b == 0 && !bound.empty() &&
        std::all_of(bound.begin(), bound.end(), [](auto& x) { return x.second > 0; }))
      for (const auto& x : bound) b = std::max(b, x.second);
    if (b > 0 && plc.point_count() > 0) {
      double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
      for (std::size_t i = 0; i < plc.points.size(); ++i)
        lo[i % 3] = std::min(lo[i % 3], plc.points[i]), hi[i % 3] = std::max(hi[i % 3], plc.points[i]);
      sized = kTetsPerBoundVolume * (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) / b;
    }
  }
  // a sizing function: its background tets, each at the regular tet's volume of its mean size
  if (params.size_field != nullptr && !params.size_field->empty()) {
    const SizeField& f = *params.size_field;
    double field = 0;
    for (std::size_t t = 0; t + 3 < f.tet.size(); t += 4) {
      const double* p[4];
      double h = 0;
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t n = f.tet[t + static_cast<std::size_t>(k)];
        p[k] = &f.xyz[3 * std::size_t{n}];
        h += 0.25 * f.size[n];
      }
      double v = regular_tet_volume(h);
      if (global > 0) v = std::min(v, global);
      if (v > 0) field += kTetsPerBoundVolume * tet_volume(p[0], p[1], p[2], p[3]) / v;
    }
    sized = std::max(sized, field);
  }
  const double est = std::max(sized, kTetsPerPoint * static_cast<double>(plc.point_count()));
  return std::isfinite(est) ? est : INFINITY;
}

double estimate_box_tet_count(const Plc& plc, std::span<const RefinementBox> boxes) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i < plc.points.size(); ++i)
    lo[i % 3] = std::min(lo[i % 3], plc.points[i]), hi[i % 3] = std::max(hi[i % 3], plc.points[i]);
  double tets = 0;
  for (const RefinementBox& b : boxes) {
    double v = 1;  // the box's part of the bounding box
    for (int k = 0; k < 3; ++k) v *= std::max(0.0, std::min(hi[k], b.hi[k]) - std::max(lo[k], b.lo[k]));
    if (v > 0) tets += kTetsPerBoundVolume * v / regular_tet_volume(b.size);
  }
  return std::isfinite(tets) ? tets : INFINITY;
}

}  // namespace foxi
