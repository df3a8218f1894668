// Line charts drawn into a picture (issue 18): several series of (x, y) points joined by lines and/or
// marked, linear or logarithmic axes with ticks at 1/2/5 x 10^k (nice_ticks, as the colour legend),
// labels that never overlap, axis titles with units, a chart title and a legend of the series; text by
// FreeType (text.hpp). Written to PNG with write_png (png.hpp).
//
// The axes: a range not given is the data's, widened to the enclosing tick multiples (linear) or
// decades (log), so that the first and last ticks sit on the frame. A log axis shows only positive
// values: points with a value <= 0 on a log axis, and non-finite points, are left out (a line breaks
// there) and counted in the report. Lines are straight in the picture between consecutive points (so
// on a log axis they are straight in log space), clipped to the plot's frame, 2 pixels wide, in one
// solid colour (no blending: a test finds a series' pixels by its colour).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/text.hpp"

namespace foxi {

struct ChartAxis {
  std::string label;  // "time"
  std::string unit;   // "s": shown as "time (s)"; empty: no unit
  bool log = false;
  // The range shown; NaN: from the data (see above). Both given: exactly this range.
  double lo = std::numeric_limits<double>::quiet_NaN(), hi = std::numeric_limits<double>::quiet_NaN();
};

struct ChartSeries {
  std::string name;          // in the legend; a chart whose series are all unnamed has no legend
  std::vector<double> x, y;  // the same length
  std::uint32_t color = 0;   // 0: the palette's colour for the series' index (chart_color)
  bool line = true;          // join consecutive points
  bool markers = false;      // a filled square of 2 * marker_radius + 1 pixels at each point
  int marker_radius = 3;
};

struct Chart {
  std::string title;
  ChartAxis x, y;
  std::vector<ChartSeries> series;
};

struct ChartParams {
  int font_px = 13;    // tick labels, axis titles, legend; the title is 1.25 times as large
  int margin = 10;     // around the chart's contents
  int line_width = 2;  // pixels
  std::uint32_t text_color = pack_rgba(0, 0, 0);
  std::uint32_t frame_color = pack_rgba(60, 60, 60);
  std::uint32_t grid_color = pack_rgba(225, 225, 225);
  std::uint32_t background = pack_rgba(255, 255, 255);
};

// What draw_chart drew, and its axis mapping (for tests, and for hosts that pick points).
struct ChartReport {
  PixelRect plot;                                 // the frame's inside: the data's pixels
  double x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;  // the axes' ranges (data units)
  bool x_log = false, y_log = false;
  std::vector<double> x_ticks, y_ticks;  // ascending
  std::vector<int> x_tick_columns, y_tick_rows;
  std::vector<PixelRect> x_labels, y_labels;  // each tick label's ink box
  // markers[s][i]: the pixel centre of series s's point i, or {-1, -1} when it was left out
  std::vector<std::vector<std::pair<int, int>>> points;
  std::size_t left_out = 0;  // points not shown (non-finite, <= 0 on a log axis)
  PixelRect legend;          // empty (x0 > x1) when no legend was drawn

  // The picture's column (x) and row (y) of a data value, not rounded: the frame's left column is
  // x_lo, its right column x_hi; the bottom row y_lo, the top row y_hi.
  double column(double x) const { return plot.x0 + fraction(x, x_lo, x_hi, x_log) * (plot.x1 - plot.x0); }
  double row(double y) const { return plot.y1 - fraction(y, y_lo, y_hi, y_log) * (plot.y1 - plot.y0); }
  static double fraction(double v, double lo, double hi, bool log) {
    return log ? (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : (v - lo) / (hi - lo);
  }
};

// The palette's colour for series i (ten distinct colours, then again).
FOXI_API std::uint32_t chart_color(std::size_t i);

// The ticks of an axis from lo to hi with at most max_ticks of them: linear, the multiples of the
// smallest 1/2/5 x 10^k step that gives at most max_ticks in [lo, hi]; log, 1/2/5 x 10^k or decades
// (nice_ticks). Empty when lo >= hi, a value is not finite, or (log) lo <= 0.
FOXI_API std::vector<double> axis_ticks(double lo, double hi, int max_ticks, bool log);

// Draws the chart into `area` of fb (filled with the background first). Throws std::invalid_argument
// when the area is too small for a plot (about 12 labels high and wide), a series' x and y differ in
// length, a given range is empty or (log) not positive, or a log axis has no positive value.
FOXI_API ChartReport draw_chart(Framebuffer& fb, const TextRenderer& text, const Chart& chart, PixelRect area,
                                const ChartParams& params = {});

}  // namespace foxi
