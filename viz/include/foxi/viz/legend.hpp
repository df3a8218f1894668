// A colour-bar legend drawn into a picture (issue 17): the field's name and display unit, a vertical
// bar of the colour map from the range's low end (bottom) to its high end (top), ticks at 1/2/5 x 10^k
// of the display unit with labels that never overlap, the range and the map's name.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/text.hpp"

namespace foxi {

struct ColorLegend {
  std::string title;  // the field ("temperature")
  DisplayUnit unit;   // ticks and range are shown in it
  ColorScale scale;   // SI, as the picture uses it
  // Values marked on the bar (SI; the isovalues of a picture): a dark line across the bar with a pointer
  // at its left; values outside the range are left out.
  std::vector<double> marks;
};

struct LegendParams {
  int font_px = 14;    // label size (the title is the same size)
  int bar_width = 18;  // pixels
  int margin = 10;     // around the legend's contents
  std::uint32_t text_color = pack_rgba(0, 0, 0);
  std::uint32_t background = pack_rgba(255, 255, 255);
};

struct LegendReport {
  std::vector<double> ticks;      // the tick values, display unit, ascending
  std::vector<int> tick_rows;     // the row of each tick on the bar
  std::vector<PixelRect> labels;  // each tick label's ink box
  PixelRect bar;                  // the bar's pixels
  std::vector<int> mark_rows;     // the row of each mark drawn (ColorLegend::marks in the range), in order
  PixelRect rect;                 // all the legend drew (its area)
};

// The height a legend needs at least (pixels) at these parameters: a bar two labels high.
FOXI_API int legend_min_height(const LegendParams& params = {});

// The width a legend needs (pixels) at these parameters.
FOXI_API int legend_width(const TextRenderer& text, const ColorLegend& legend,
                          const LegendParams& params = {});

// Draws the legend into `area` of fb (filled with the background first; area inside the image and at
// least legend_width wide). Throws std::invalid_argument if the area is too small for a bar.
FOXI_API LegendReport draw_color_legend(Framebuffer& fb, const TextRenderer& text, const ColorLegend& legend,
                                        PixelRect area, const LegendParams& params = {});

// A one-line caption in a picture's top-left corner (a movie frame's time or swept value: "t = 12.5 s"):
// `text` drawn with its pen at (params.margin, params.margin + the font's ascent of "Ag"), params.font_px
// high, in params.text_color, over the pixels there (no background: the mesh is fitted inside margins).
// Returns the pixels it may have changed. Empty text draws nothing.
FOXI_API PixelRect draw_caption(Framebuffer& fb, const TextRenderer& text, std::string_view caption,
                                const LegendParams& params = {});

// A tick label: the value with as many decimals as the step between ticks needs (%g beyond 1e6 or
// below 1e-3 in magnitude).
FOXI_API std::string tick_label(double value, double step);

}  // namespace foxi
