// Line charts: the ticks against a brute-force search of the 1/2/5 x 10^k steps, the tick columns and
// rows where the axis mapping puts their values, a known line's pixels on the line that the mapping
// gives (linear and log axes), markers at their points, the legend beside the plot.
#include "foxi/viz/chart.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// Every 1/2/5 x 10^k step from 1e-20 up, ascending.
std::vector<double> all_steps() {
  std::vector<double> s;
  for (int k = -20; k <= 20; ++k)
    for (double m : {1.0, 2.0, 5.0}) s.push_back(m * std::pow(10.0, k));
  return s;
}

// The oracle of a linear axis: the multiples of the smallest step with at most n multiples in [lo, hi].
std::vector<double> brute_linear_ticks(double lo, double hi, int n) {
  for (double s : all_steps()) {
    if ((hi - lo) / s > 1000) continue;  // surely more than n (and i * s would overflow)
    std::vector<double> t;
    for (long long i = (long long)std::ceil(lo / s - 1e-9); i <= (long long)std::floor(hi / s + 1e-9); ++i) {
      t.push_back(double(i) * s);
      if (int(t.size()) > n) break;
    }
    if (int(t.size()) <= n) return t;
  }
  return {};
}

TEST(Chart, AxisTicksAreTheBruteForceSteps) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> mag(-6, 6), u(0, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::pow(10.0, mag(rng));
    double lo = (u(rng) * 2 - 1) * scale, hi = lo + u(rng) * scale * (u(rng) < 0.3 ? 0.01 : 1);
    if (!(lo < hi)) continue;
    const int n = 2 + trial % 11;
    const std::vector<double> got = axis_ticks(lo, hi, n, false), want = brute_linear_ticks(lo, hi, n);
    ASSERT_EQ(got.size(), want.size()) << lo << " " << hi << " n=" << n;
    const double step = want.size() > 1 ? want[1] - want[0] : hi - lo;
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-6 * step) << lo << " " << hi;
  }
  // Log: every 1/2/5 x 10^k inside, when they are at most n.
  for (auto [lo, hi] : {std::pair{1e-6, 3e-3}, std::pair{0.7, 40.0}, std::pair{2e3, 9e4}}) {
    std::vector<double> want;
    for (int k = -8; k <= 6; ++k)
      for (double m : {1.0, 2.0, 5.0}) {
        const double v = m * std::pow(10.0, k);
        if (v >= lo && v <= hi) want.push_back(v);
      }
    std::sort(want.begin(), want.end());
    const std::vector<double> got = axis_ticks(lo, hi, 20, true);
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-12 * want[i]);
  }
  EXPECT_TRUE(axis_ticks(-1, 10, 5, true).empty());
  EXPECT_TRUE(axis_ticks(3, 3, 5, false).empty());
}

bool overlap(const PixelRect& a, const PixelRect& b) {
  return a.x0 <= b.x1 && b.x0 <= a.x1 && a.y0 <= b.y1 && b.y0 <= a.y1;
}

// The distance of pixel (x, y) from the line through (ax, ay) and (bx, by).
double distance(double x, double y, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  return std::abs(dy * (x - ax) - dx * (y - ay)) / std::hypot(dx, dy);
}

// Checks that the pixels of `color` inside the plot lie within 1.5 pixels (a 2-pixel line's half
// width times sqrt 2, the stamp's corner) of the straight line that
// the mapping gives between (x0, y0) and (x1, y1) (data units), and that every column between them
// has one.
void expect_line(const Framebuffer& fb, const ChartReport& r, std::uint32_t color, double x0, double y0,
                 double x1, double y1) {
  const double ax = r.column(x0), ay = r.row(y0), bx = r.column(x1), by = r.row(y1);
  int found = 0;
  for (int y = r.plot.y0; y <= r.plot.y1; ++y)
    for (int x = r.plot.x0; x <= r.plot.x1; ++x)
      if (fb.rgba[fb.index(x, y)] == color) {
        ++found;
        EXPECT_LE(distance(x, y, ax, ay, bx, by), 1.5) << "pixel " << x << "," << y;
      }
  for (int x = int(std::ceil(std::min(ax, bx))) + 1; x < int(std::floor(std::max(ax, bx))); ++x) {
    bool any = false;
    for (int y = r.plot.y0; y <= r.plot.y1 && !any; ++y) any = fb.rgba[fb.index(x, y)] == color;
    EXPECT_TRUE(any) << "column " << x << " has no pixel of the line";
  }
  EXPECT_GT(found, 100);
}

TEST(Chart, TicksSitWhereTheMappingSaysAndLabelsKeepApart) {
  const TextRenderer text(find_font_file());
  Chart c;
  c.title = "a title";
  c.x = {"length", "mm"};
  c.y = {"temperature", "degC"};
  c.series.push_back({"", {0.3, 2.0, 7.3}, {-3.2, 5.0, 12.6}});
  for (int w : {300, 640, 1200}) {
    Framebuffer fb(w + 20, 400);
    const ChartReport r = draw_chart(fb, text, c, PixelRect{10, 0, w + 9, 399});
    for (auto [ticks, lo, hi, data_lo, data_hi] : {std::tuple{r.x_ticks, r.x_lo, r.x_hi, 0.3, 7.3},
                                                   std::tuple{r.y_ticks, r.y_lo, r.y_hi, -3.2, 12.6}}) {
      ASSERT_GE(ticks.size(), 2u);
      const double step = ticks[1] - ticks[0];
      const double k = std::floor(std::log10(step) + 1e-9), m = step / std::pow(10.0, k);
      EXPECT_TRUE(std::abs(m - 1) < 1e-9 || std::abs(m - 2) < 1e-9 || std::abs(m - 5) < 1e-9) << step;
      for (std::size_t i = 1; i < ticks.size(); ++i) EXPECT_NEAR(ticks[i] - ticks[i - 1], step, 1e-9 * step);
      for (double t : ticks) EXPECT_NEAR(t / step, std::round(t / step), 1e-9);
      // The range: the data widened to the enclosing tick multiples.
      EXPECT_DOUBLE_EQ(ticks.front(), lo);
      EXPECT_DOUBLE_EQ(ticks.back(), hi);
      EXPECT_LE(lo, data_lo);
      EXPECT_GE(hi, data_hi);
      EXPECT_GT(lo + step, data_lo);
      EXPECT_LT(hi - step, data_hi);
    }
    for (std::size_t i = 0; i < r.x_ticks.size(); ++i) {
      EXPECT_EQ(r.x_tick_columns[i], std::lround(r.plot.x0 + (r.x_ticks[i] - r.x_lo) / (r.x_hi - r.x_lo) *
                                                                 (r.plot.x1 - r.plot.x0)));
      if (i > 0) {
        EXPECT_FALSE(overlap(r.x_labels[i], r.x_labels[i - 1])) << w;
      }
      EXPECT_GT(r.x_labels[i].y0, r.plot.y1);  // below the plot
    }
    EXPECT_EQ(r.x_tick_columns.front(), r.plot.x0);
    EXPECT_EQ(r.x_tick_columns.back(), r.plot.x1);
    for (std::size_t i = 0; i < r.y_ticks.size(); ++i) {
      EXPECT_EQ(r.y_tick_rows[i], std::lround(r.plot.y1 - (r.y_ticks[i] - r.y_lo) / (r.y_hi - r.y_lo) *
                                                              (r.plot.y1 - r.plot.y0)));
      if (i > 0) {
        EXPECT_FALSE(overlap(r.y_labels[i], r.y_labels[i - 1]));
      }
      EXPECT_LT(r.y_labels[i].x1, r.plot.x0);  // left of the plot
      EXPECT_GE(r.y_labels[i].x0, 10);         // inside the area
    }
    // A wider chart has at least as many x ticks.
    EXPECT_GE(r.x_ticks.size(), 2u);
    // Nothing drawn outside the area.
    for (int y = 0; y < fb.height; ++y)
      for (int x : {0, 9, w + 10, w + 19}) EXPECT_EQ(fb.rgba[fb.index(x, y)], pack_rgba(255, 255, 255));
  }
}

TEST(Chart, AKnownLineLandsWhereTheAxisMappingSays) {
  const TextRenderer text(find_font_file());
  const std::uint32_t red = pack_rgba(255, 0, 0);
  Chart c;
  c.x = {"x", "s"};
  c.y = {"y", "K"};
  ChartSeries s{"", {}, {}, red};
  for (int i = 0; i <= 40; ++i) {
    s.x.push_back(0.25 * i);
    s.y.push_back(2 * (0.25 * i) + 1);
  }
  c.series.push_back(s);
  Framebuffer fb(640, 420);
  const ChartReport r = draw_chart(fb, text, c, PixelRect{0, 0, 639, 419});
  expect_line(fb, r, red, 0, 1, 10, 21);
  // Fixed ranges that cut the line: clipped to the frame, still on the mapping's line.
  c.x.lo = 2, c.x.hi = 6, c.y.lo = 0, c.y.hi = 10;
  fb.clear();
  const ChartReport q = draw_chart(fb, text, c, PixelRect{0, 0, 639, 419});
  EXPECT_EQ(q.x_lo, 2);
  EXPECT_EQ(q.y_hi, 10);
  expect_line(fb, q, red, 2, 5, 4.5, 10);
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if (fb.rgba[fb.index(x, y)] == red) {
        EXPECT_GE(x, q.plot.x0);
        EXPECT_LE(x, q.plot.x1);
        EXPECT_GE(y, q.plot.y0);
        EXPECT_LE(y, q.plot.y1);
      }
}

// Values that differ by round-off alone (a junction at 300 K and 300 K + 1e-13 after a run of 1e-20 s;
// an outside probe): the axis is a range around them, as for one value, with a few ticks (ticks 1e-14
// apart were stepped from 3e16, where ++ on a double stops counting, until memory ran out).
TEST(Chart, ValuesApartByRoundOffGetARangeAroundThem) {
  const TextRenderer text(find_font_file());
  Chart c;
  c.x = {"time", "s"};
  c.y = {"Tj", "K"};
  c.series.push_back({"", {0, 1e-20}, {300, 300 + 1e-13}, pack_rgba(255, 0, 0)});
  Framebuffer fb(640, 420);
  const ChartReport r = draw_chart(fb, text, c, PixelRect{0, 0, 639, 419});
  EXPECT_LT(r.y_lo, 300);
  EXPECT_GT(r.y_hi, 300 + 1e-13);
  EXPECT_GE(r.y_ticks.size(), 2u);
  EXPECT_LE(r.y_ticks.size(), 12u);
}

TEST(Chart, LogAxes) {
  const TextRenderer text(find_font_file());
  const std::uint32_t red = pack_rgba(255, 0, 0);
  Chart c;
  c.x = {"time", "s", true};
  c.y = {"Zth", "K/W", true};
  ChartSeries s{"y = x^2", {}, {}, red};
  for (int i = 0; i <= 50; ++i) {
    const double x = std::pow(10.0, -3 + 0.1 * i);  // 1e-3 .. 1e2
    s.x.push_back(x);
    s.y.push_back(x * x);
  }
  s.x.push_back(-1);  // left out on a log axis
  s.y.push_back(1);
  s.x.push_back(1);
  s.y.push_back(0);
  c.series.push_back(s);
  Framebuffer fb(700, 450);
  const ChartReport r = draw_chart(fb, text, c, PixelRect{0, 0, 699, 449});
  EXPECT_EQ(r.left_out, 2u);
  EXPECT_NEAR(r.x_lo, 1e-3, 1e-15);
  EXPECT_NEAR(r.x_hi, 1e2, 1e-10);
  EXPECT_NEAR(r.y_lo, 1e-6, 1e-18);
  EXPECT_NEAR(r.y_hi, 1e4, 1e-8);
  // Ticks at 1/2/5 x 10^k, at the row of their logarithm.
  for (std::size_t i = 0; i < r.x_ticks.size(); ++i) {
    const double k = std::floor(std::log10(r.x_ticks[i]) + 1e-9), m = r.x_ticks[i] / std::pow(10.0, k);
    EXPECT_TRUE(std::abs(m - 1) < 1e-9 || std::abs(m - 2) < 1e-9 || std::abs(m - 5) < 1e-9) << r.x_ticks[i];
    EXPECT_EQ(r.x_tick_columns[i],
              std::lround(r.plot.x0 + (std::log10(r.x_ticks[i]) + 3) / 5 * (r.plot.x1 - r.plot.x0)));
    if (i > 0) {
      EXPECT_FALSE(overlap(r.x_labels[i], r.x_labels[i - 1]));
    }
  }
  for (std::size_t i = 0; i < r.y_ticks.size(); ++i)
    EXPECT_EQ(r.y_tick_rows[i],
              std::lround(r.plot.y1 - (std::log10(r.y_ticks[i]) + 6) / 10 * (r.plot.y1 - r.plot.y0)));
  // y = x^2 is straight on log-log axes: the line from (1e-3, 1e-6) to (1e2, 1e4), the frame's diagonal.
  EXPECT_NEAR(r.column(1e-3), r.plot.x0, 1e-9);
  EXPECT_NEAR(r.row(1e4), r.plot.y0, 1e-9);
  expect_line(fb, r, red, 1e-3, 1e-6, 1e2, 1e4);
  // The legend: right of the plot, inside the picture.
  EXPECT_GT(r.legend.x0, r.plot.x1);
  EXPECT_LT(r.legend.x1, fb.width);
  // A log axis with nothing positive on it is refused.
  Chart bad;
  bad.y.log = true;
  bad.series.push_back({"", {1, 2}, {0, -1}});
  EXPECT_THROW(draw_chart(fb, text, bad, PixelRect{0, 0, 699, 449}), std::invalid_argument);
}

TEST(Chart, MarkersAtTheirPointsAndBadInputRefused) {
  const TextRenderer text(find_font_file());
  Chart c;
  c.x = {"die width", "mm"};
  c.y = {"Tmax", "K"};
  c.series.push_back({"a", {2, 3, 4, 5}, {310, 305, 302, 300.5}, pack_rgba(0, 0, 255), true, true});
  c.series.push_back({"b", {2, 3, 4, 5}, {320, 312, NAN, 301}, pack_rgba(0, 160, 0), false, true});
  Framebuffer fb(600, 400);
  const ChartReport r = draw_chart(fb, text, c, PixelRect{0, 0, 599, 399});
  ASSERT_EQ(r.points.size(), 2u);
  EXPECT_EQ(r.left_out, 1u);
  EXPECT_EQ(r.points[1][2], std::make_pair(-1, -1));
  for (std::size_t s = 0; s < 2; ++s)
    for (std::size_t i = 0; i < 4; ++i) {
      const auto [x, y] = r.points[s][i];
      if (x < 0) continue;
      EXPECT_EQ(x, std::lround(r.column(c.series[s].x[i])));
      EXPECT_EQ(y, std::lround(r.row(c.series[s].y[i])));
      // The marker: a 7 x 7 square of the series' colour around the point.
      for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) EXPECT_EQ(fb.rgba[fb.index(x + dx, y + dy)], c.series[s].color);
    }
  EXPECT_FALSE(overlap(r.legend, r.plot));
  c.series[0].y.pop_back();
  EXPECT_THROW(draw_chart(fb, text, c, PixelRect{0, 0, 599, 399}), std::invalid_argument);
  c.series[0].y.push_back(1);
  EXPECT_THROW(draw_chart(fb, text, c, PixelRect{0, 0, 99, 60}), std::invalid_argument);
  c.x.lo = 3, c.x.hi = 3;
  EXPECT_THROW(draw_chart(fb, text, c, PixelRect{0, 0, 599, 399}), std::invalid_argument);
  if (const char* dir = std::getenv("FOXI_TEST_KEEP")) {
    c.x.lo = c.x.hi = NAN;
    fb.clear();
    draw_chart(fb, text, c, PixelRect{0, 0, 599, 399});
    write_png(std::string(dir) + "/chart_markers.png", fb);
  }
}

}  // namespace
}  // namespace foxi
