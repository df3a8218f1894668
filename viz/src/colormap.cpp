#include "foxi/viz/colormap.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "colormap_tables.hpp"

namespace foxi {

namespace {

const std::uint8_t (*table(ColorMapId map))[3] {
  switch (map) {
    case ColorMapId::cividis:
      return detail::kCividisTable;
    case ColorMapId::coolwarm:
      return detail::kCoolwarmTable;
    case ColorMapId::rainbow:
      return detail::kRainbowTable;
    case ColorMapId::viridis:
      break;
  }
  return detail::kViridisTable;
}

}  // namespace

std::optional<ColorMapId> parse_color_map(std::string_view name) {
  for (ColorMapId m : {ColorMapId::viridis, ColorMapId::cividis, ColorMapId::coolwarm, ColorMapId::rainbow})
    if (name == color_map_name(m)) return m;
  return std::nullopt;
}

const char* color_map_name(ColorMapId map) {
  switch (map) {
    case ColorMapId::cividis:
      return "cividis";
    case ColorMapId::coolwarm:
      return "coolwarm";
    case ColorMapId::rainbow:
      return "rainbow";
    case ColorMapId::viridis:
      break;
  }
  return "viridis";
}

std::uint32_t color_map_entry(ColorMapId map, int i) {
  const std::uint8_t* c = table(map)[std::clamp(i, 0, 255)];
  return pack_rgba(c[0], c[1], c[2]);
}

double ColorScale::position(double v) const {
  if (log) {
    if (!(v > 0)) return std::numeric_limits<double>::quiet_NaN();
    return (std::log(v) - std::log(lo)) / (std::log(hi) - std::log(lo));
  }
  const double span = hi - lo;
  if (std::isfinite(span)) return (v - lo) / span;
  // A range wider than the largest double (-1e308 to 1e308): halved, so the difference is finite.
  return (0.5 * v - 0.5 * lo) / (0.5 * hi - 0.5 * lo);
}

std::uint32_t ColorScale::color_at(double t) const {
  if (std::isnan(t)) return nan_color;
  return color_map_entry(map, int(std::clamp(std::floor(t * 256), 0.0, 255.0)));
}

double ColorScale::value_at(double t) const {
  if (log) return std::exp(std::log(lo) + t * (std::log(hi) - std::log(lo)));
  return std::isfinite(hi - lo) ? lo + t * (hi - lo) : 2 * (0.5 * lo + t * (0.5 * hi - 0.5 * lo));
}

std::vector<double> nice_ticks(double lo, double hi, int max_ticks, bool log) {
  std::vector<double> ticks;
  if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi) || max_ticks < 2) return ticks;
  if (log) {
    if (!(lo > 0)) return ticks;
    const int k0 = int(std::floor(std::log10(lo))), k1 = int(std::ceil(std::log10(hi)));
    // 1-2-5 in each decade if they fit, else the decades, every n-th if need be.
    for (const double m : {1.0, 2.0, 5.0})
      for (int k = k0; k <= k1; ++k) {
        const double v = m * std::pow(10.0, k);
        if (v >= lo * (1 - 1e-12) && v <= hi * (1 + 1e-12)) ticks.push_back(v);
      }
    std::sort(ticks.begin(), ticks.end());
    if (int(ticks.size()) <= max_ticks) return ticks;
    for (int every = 1; every <= k1 - k0 + 1; ++every) {
      ticks.clear();
      for (int k = k0; k <= k1; ++k) {
        const double v = std::pow(10.0, k);
        if (k % every == 0 && v >= lo * (1 - 1e-12) && v <= hi * (1 + 1e-12)) ticks.push_back(v);
      }
      if (int(ticks.size()) <= max_ticks) return ticks;
    }
    return ticks;
  }
  // The step: the smallest 1/2/5 x 10^k with at most max_ticks multiples in [lo, hi].
  const double raw = (hi - lo) / (max_ticks - 1);
  if (!std::isfinite(raw) || !(raw > 0)) return ticks;  // a range wider than the largest double: no ticks
  double step = 0;
  for (int k = int(std::floor(std::log10(raw))) - 1; step == 0; ++k) {
    for (const double m : {1.0, 2.0, 5.0}) {
      const double s = m * std::pow(10.0, k);
      const double first = std::ceil(lo / s - 1e-9), last = std::floor(hi / s + 1e-9);
      if (last - first + 1 <= max_ticks) {
        step = s;
        break;
      }
    }
  }
  const double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
  for (double i = first; i <= last; ++i) {
    // i * step, with a multiple of step that is exactly zero shown as 0 (not 1e-17).
    double v = i * step;
    if (std::abs(v) < step * 1e-9) v = 0;
    ticks.push_back(std::clamp(v, lo, hi));
  }
  return ticks;
}

}  // namespace foxi
