// Colour maps and scales: a field value -> an opaque RGBA colour (pack_rgba), through one of four
// 256-entry tables tabulated from the published maps (their sources: scripts/gen_colormaps.py), on a
// linear or logarithmic range, with a "no value" colour for NaN; and the ticks of a colour bar.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/viz/framebuffer.hpp"

namespace foxi {

// viridis and cividis: perceptually uniform, sequential (cividis also for colour-vision deficiency);
// coolwarm: diverging (Moreland), for signed values about a centre; rainbow: Turbo, for those who ask.
enum class ColorMapId : std::uint8_t { viridis, cividis, coolwarm, rainbow };

// The map named `name` ("viridis", "cividis", "coolwarm", "rainbow"), or nothing.
FOXI_API std::optional<ColorMapId> parse_color_map(std::string_view name);
FOXI_API const char* color_map_name(ColorMapId map);
// Entry i (0..255, clamped) of the map, opaque.
FOXI_API std::uint32_t color_map_entry(ColorMapId map, int i);

struct FOXI_API ColorScale {
  ColorMapId map = ColorMapId::viridis;
  double lo = 0, hi = 1;  // the values of the first and last entry's outer edges (lo < hi; log: 0 < lo)
  bool log = false;       // entries evenly spaced in log(value)
  std::uint32_t nan_color = pack_rgba(150, 150, 150);  // "no value": NaN, and values <= 0 on a log scale

  // Where v lies on the scale: 0 at lo, 1 at hi (outside [0, 1] for values outside the range), NaN for
  // no value. Entry floor(256 t) clamped to 0..255 shows it: a colour maps back to its value within one
  // entry, 1/256 of the range.
  double position(double v) const;
  // The colour of position t (position()), the NaN colour for NaN.
  std::uint32_t color_at(double t) const;
  std::uint32_t color(double v) const { return color_at(position(v)); }
  // The value at position t (inverse of position()).
  double value_at(double t) const;
};

// Colour-bar ticks: values inside [lo, hi] (lo < hi), multiples of one step 1, 2 or 5 x 10^k, the
// smallest step giving at most max_ticks (>= 2) of them; ascending. Log (0 < lo): the values
// {1, 2, 5} x 10^k inside the range, thinned to decades and then to every n-th decade if there
// are more than max_ticks. Empty for a bad range.
FOXI_API std::vector<double> nice_ticks(double lo, double hi, int max_ticks, bool log = false);

}  // namespace foxi
