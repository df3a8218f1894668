// The colour-bar legend: its ticks are 1/2/5 x 10^k multiples inside the range (display unit), sit at
// the bar row of their value, their labels never overlap, and the bar's rows show the map from the
// range's low end (bottom) to its high end (top).
#include "foxi/viz/legend.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

bool one_two_five(double step) {
  const double k = std::floor(std::log10(step) + 1e-9), m = step / std::pow(10.0, k);
  return std::abs(m - 1) < 1e-6 || std::abs(m - 2) < 1e-6 || std::abs(m - 5) < 1e-6;
}

bool overlap(const PixelRect& a, const PixelRect& b) {
  return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1;
}

TEST(Legend, TicksAreNiceInsideTheRangeAndLabelsApart) {
  const TextRenderer text(find_font_file());
  struct Case {
    double lo, hi;
    const char* si;
    const char* shown;
    bool log;
    int height;
  } cases[] = {{298.15, 358.4, "K", "degC", false, 400}, {0, 2.3e8, "Pa", "MPa", false, 300},
               {-3e-6, 4.1e-6, "m", "um", false, 250},   {1e2, 3e7, "Pa", "Pa", true, 400},
               {0.0312, 0.0318, "V", "mV", false, 160},  {-1, 1, "", "", false, 600}};
  for (const Case& c : cases) {
    ColorLegend l;
    l.title = "field";
    l.unit = *display_unit(c.si, c.shown);
    l.scale.lo = c.lo;
    l.scale.hi = c.hi;
    l.scale.log = c.log;
    const int w = legend_width(text, l);
    Framebuffer fb(w + 20, c.height);
    const LegendReport r = draw_color_legend(fb, text, l, PixelRect{10, 0, 10 + w - 1, c.height - 1});
    ASSERT_GE(r.ticks.size(), 2u) << c.lo << " " << c.hi;
    const double lo = l.unit.to_display(c.lo), hi = l.unit.to_display(c.hi);
    for (std::size_t i = 0; i < r.ticks.size(); ++i) {
      EXPECT_GE(r.ticks[i], lo - 1e-9 * std::abs(lo));
      EXPECT_LE(r.ticks[i], hi + 1e-9 * std::abs(hi));
      // The tick's row: where the bar shows its value.
      const double t = l.scale.position(l.unit.to_si(r.ticks[i]));
      EXPECT_NEAR(r.tick_rows[i], r.bar.y1 - t * (r.bar.y1 - r.bar.y0), 1.0);
      if (c.log) {
        const double k = std::floor(std::log10(r.ticks[i]) + 1e-9);
        EXPECT_TRUE(one_two_five(r.ticks[i] / std::pow(10.0, k) * std::pow(10.0, 0))) << r.ticks[i];
      } else if (i > 0) {
        const double step = r.ticks[i] - r.ticks[i - 1];
        EXPECT_TRUE(one_two_five(step)) << step;
        EXPECT_NEAR(r.ticks[i] / step, std::round(r.ticks[i] / step), 1e-6);
      }
      if (i > 0) {
        EXPECT_FALSE(overlap(r.labels[i], r.labels[i - 1])) << "labels " << i - 1 << " and " << i;
        EXPECT_LT(r.tick_rows[i], r.tick_rows[i - 1]);  // higher values higher up
      }
      EXPECT_GE(r.labels[i].x0, r.bar.x1);  // right of the bar, inside the legend
      EXPECT_LE(r.labels[i].x1, r.rect.x1);
    }
    // The bar: the bottom row shows entry 0, the top row entry 255, the rows between evenly spaced.
    for (int y = r.bar.y0; y <= r.bar.y1; ++y) {
      const double t = double(r.bar.y1 - y) / double(r.bar.y1 - r.bar.y0);
      EXPECT_EQ(fb.rgba[fb.index(r.bar.x0 + 2, y)],
                color_map_entry(l.scale.map, std::min(255, int(std::floor(t * 256)))));
    }
    EXPECT_EQ(fb.rgba[fb.index(r.bar.x0 + 2, r.bar.y1)], color_map_entry(l.scale.map, 0));
    EXPECT_EQ(fb.rgba[fb.index(r.bar.x0 + 2, r.bar.y0)], color_map_entry(l.scale.map, 255));
    // Nothing outside the area.
    for (int y = 0; y < fb.height; ++y)
      for (int x : {0, 9, w + 10, w + 19}) EXPECT_EQ(fb.rgba[fb.index(x, y)], pack_rgba(255, 255, 255));
  }
}

TEST(Legend, TickLabelsHaveTheDecimalsOfTheStep) {
  EXPECT_EQ(tick_label(25, 5), "25");
  EXPECT_EQ(tick_label(25.5, 0.5), "25.5");
  EXPECT_EQ(tick_label(0.02, 0.01), "0.02");
  EXPECT_EQ(tick_label(0, 0.01), "0");
  EXPECT_EQ(tick_label(2e7, 1e7), "2e+07");
}

TEST(Legend, TooSmallAnAreaIsRefused) {
  const TextRenderer text(find_font_file());
  ColorLegend l;
  l.title = "t";
  Framebuffer fb(100, 40);
  EXPECT_THROW(draw_color_legend(fb, text, l, PixelRect{0, 0, 99, 39}), std::invalid_argument);
  // legend_min_height is exactly what a bar needs.
  const int h = legend_min_height(), w = legend_width(text, l);
  Framebuffer tall(w, h);
  EXPECT_NO_THROW(draw_color_legend(tall, text, l, PixelRect{0, 0, w - 1, h - 1}));
  Framebuffer low(w, h - 1);
  EXPECT_THROW(draw_color_legend(low, text, l, PixelRect{0, 0, w - 1, h - 2}), std::invalid_argument);
}

TEST(Legend, MarksCrossTheBarAtTheirValuesRow) {
  const TextRenderer text(find_font_file());
  ColorLegend l;
  l.title = "temperature";
  l.unit = *display_unit("K", "degC");
  l.scale.lo = 300;
  l.scale.hi = 380;
  l.marks = {320, 350.5, 290, 379};  // 290 is outside the range: left out
  const int w = legend_width(text, l);
  Framebuffer fb(w, 400);
  const LegendReport r = draw_color_legend(fb, text, l, PixelRect{0, 0, w - 1, 399});
  ASSERT_EQ(r.mark_rows.size(), 3u);
  const double in_range[3] = {320, 350.5, 379};
  for (int i = 0; i < 3; ++i) {
    // The row a mark crosses is the bar's row of the value's colour, within one row.
    const double t = l.scale.position(in_range[i]);
    EXPECT_NEAR(r.mark_rows[std::size_t(i)], r.bar.y1 - t * (r.bar.y1 - r.bar.y0), 1.0);
    for (int x = r.bar.x0; x <= r.bar.x1; ++x)
      EXPECT_EQ(fb.rgba[fb.index(x, r.mark_rows[std::size_t(i)])], pack_rgba(0, 0, 0));
    EXPECT_EQ(fb.rgba[fb.index(r.bar.x0 - 2, r.mark_rows[std::size_t(i)])],
              pack_rgba(0, 0, 0));  // the pointer
  }
  // Rows away from marks and ticks keep the map's colour.
  int plain = 0;
  for (int y = r.bar.y0; y <= r.bar.y1; ++y) {
    bool near_mark = false;
    for (int m : r.mark_rows) near_mark |= std::abs(m - y) <= 3;
    if (!near_mark &&
        fb.rgba[fb.index(r.bar.x0, y)] == l.scale.color_at(double(r.bar.y1 - y) / (r.bar.y1 - r.bar.y0)))
      ++plain;
  }
  EXPECT_GT(plain, (r.bar.y1 - r.bar.y0) * 3 / 4);
}

}  // namespace
}  // namespace foxi
