// Line charts (see chart.hpp). Layout, top to bottom: the title, the y axis's title (horizontal,
// above the axis: the text renderer draws no rotated text), the plot, the x tick labels, the x axis's
// title; left of the plot the y tick labels; right of it the legend. The tick count of each axis is
// the largest whose labels keep apart (x: 8 pixels between labels; y: a line's height).
#include "foxi/viz/chart.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "foxi/viz/colormap.hpp"
#include "foxi/viz/legend.hpp"

namespace foxi {

namespace {

std::string axis_title(const ChartAxis& a) {
  if (a.unit.empty()) return a.label;
  return a.label.empty() ? "(" + a.unit + ")" : a.label + " (" + a.unit + ")";
}

// The range of an axis: the one given, else the data's (non-finite values, and values <= 0 on a log
// axis, left out).
std::pair<double, double> data_range(const Chart& c, bool x_axis) {
  const ChartAxis& a = x_axis ? c.x : c.y;
  if (std::isfinite(a.lo) && std::isfinite(a.hi)) {
    if (!(a.lo < a.hi) || (a.log && !(a.lo > 0)))
      throw std::invalid_argument("chart: the " + std::string(x_axis ? "x" : "y") + " axis's range [" +
                                  std::to_string(a.lo) + ", " + std::to_string(a.hi) + "] is empty" +
                                  (a.log ? " or not positive (log axis)" : ""));
    return {a.lo, a.hi};
  }
  double lo = INFINITY, hi = -INFINITY;
  for (const ChartSeries& s : c.series)
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double u = s.x[i], v = s.y[i];
      if (!std::isfinite(u) || !std::isfinite(v) || (c.x.log && u <= 0) || (c.y.log && v <= 0)) continue;
      const double w = x_axis ? u : v;
      lo = std::min(lo, w);
      hi = std::max(hi, w);
    }
  if (!(lo <= hi)) {
    if (a.log &&
        std::any_of(c.series.begin(), c.series.end(), [](const ChartSeries& s) { return !s.x.empty(); }))
      throw std::invalid_argument("chart: the " + std::string(x_axis ? "x" : "y") +
                                  " axis is logarithmic and no point has a positive value there");
    lo = a.log ? 1 : 0, hi = a.log ? 10 : 1;  // no data: an empty frame
  }
  if (std::isfinite(a.lo)) lo = a.lo;
  if (std::isfinite(a.hi)) hi = a.hi;
  // One value, or values that differ by round-off alone (300 K and 300 K + 1e-13: ticks 1e-14 apart
  // at 3e16 steps from 0, where ++ on a double no longer counts, filled memory until it ran out; an
  // outside probe): a range around their middle.
  if (hi - lo <= 1e-9 * std::max(std::abs(lo), std::abs(hi))) {
    lo = hi = 0.5 * (lo + hi);
    const double d = lo == 0 ? 1 : std::abs(lo) * 0.1;
    if (a.log)
      lo /= 2, hi *= 2;
    else
      lo -= d, hi += d;
  }
  if (!(lo < hi)) throw std::invalid_argument("chart: an axis's range is empty");
  return {lo, hi};
}

struct AxisTicks {
  double lo = 0, hi = 1;
  std::vector<double> ticks;
  double step = 0;  // linear: the tick step; log: 0 (labels in %g form)
};

// Ticks with at most n of them inside [lo, hi] and the range widened to the enclosing tick multiples
// (linear) or decades (log) unless `fixed`.
AxisTicks ticks_for(double lo, double hi, int n, bool log, bool fixed) {
  AxisTicks t;
  if (log) {
    t.lo = fixed ? lo : std::pow(10.0, std::floor(std::log10(lo) + 1e-9));
    t.hi = fixed ? hi : std::pow(10.0, std::ceil(std::log10(hi) - 1e-9));
    if (t.lo == t.hi) t.hi = t.lo * 10;
    t.ticks = axis_ticks(t.lo, t.hi, n, true);
    return t;
  }
  if (fixed) {
    t.lo = lo, t.hi = hi, t.ticks = axis_ticks(lo, hi, n, false);
    t.step = t.ticks.size() > 1 ? t.ticks[1] - t.ticks[0] : hi - lo;
    return t;
  }
  // The smallest 1/2/5 x 10^k step whose multiples enclosing [lo, hi] are at most n (n >= 2: one
  // exists, the step of at least hi - lo gives two or three; three when lo and hi straddle a
  // multiple, so the search goes on to the step that gives two).
  const double raw = (hi - lo) / std::max(1, n - 1);
  for (int k = int(std::floor(std::log10(raw))) - 1; t.step == 0; ++k)
    for (const double m : {1.0, 2.0, 5.0}) {
      const double s = m * std::pow(10.0, k);
      if (std::ceil(hi / s - 1e-9) - std::floor(lo / s + 1e-9) + 1 <= n) {
        t.step = s;
        break;
      }
    }
  const double step = t.step;
  const double first = std::floor(lo / step + 1e-9), last = std::ceil(hi / step - 1e-9);
  // Counted, not stepped: at most n + 1 ticks whatever the doubles do.
  const int count = last - first >= 0 && last - first <= n ? int(last - first) : std::max(n - 1, 1);
  for (int j = 0; j <= count; ++j) {
    double v = (first + j) * step;
    if (std::abs(v) < step * 1e-9) v = 0;
    t.ticks.push_back(v);
  }
  t.lo = t.ticks.front(), t.hi = t.ticks.back();
  return t;
}

void fill(Framebuffer& fb, PixelRect r, std::uint32_t c) {
  for (int y = std::max(r.y0, 0); y <= std::min(r.y1, fb.height - 1); ++y)
    for (int x = std::max(r.x0, 0); x <= std::min(r.x1, fb.width - 1); ++x) fb.rgba[fb.index(x, y)] = c;
}

// A straight segment from (x0, y0) to (x1, y1) (pixel centres, not rounded), clipped to `clip`
// (Liang-Barsky), stamped as a width x width square at each step of one pixel along it.
void segment(Framebuffer& fb, double x0, double y0, double x1, double y1, PixelRect clip, int width,
             std::uint32_t c) {
  double t0 = 0, t1 = 1;
  const double dx = x1 - x0, dy = y1 - y0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {x0 - clip.x0, clip.x1 - x0, y0 - clip.y0, clip.y1 - y0};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return;
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0)
      t0 = std::max(t0, r);
    else
      t1 = std::min(t1, r);
  }
  if (t0 > t1) return;
  const double ax = x0 + t0 * dx, ay = y0 + t0 * dy, bx = x0 + t1 * dx, by = y0 + t1 * dy;
  const int n = std::max(1, int(std::ceil(std::max(std::abs(bx - ax), std::abs(by - ay)))));
  // At each point along the segment, the pixels whose centres lie within half the width of it in x
  // and y: a square around the exact point, so no pixel is farther than (width / 2) sqrt 2 from the line.
  const double h = width / 2.0;
  for (int k = 0; k <= n; ++k) {
    const double fx = ax + (bx - ax) * k / n, fy = ay + (by - ay) * k / n;
    for (int v = int(std::ceil(fy - h)); v <= int(std::floor(fy + h)); ++v)
      for (int u = int(std::ceil(fx - h)); u <= int(std::floor(fx + h)); ++u)
        if (u >= clip.x0 && u <= clip.x1 && v >= clip.y0 && v <= clip.y1) fb.rgba[fb.index(u, v)] = c;
  }
}

}  // namespace

std::uint32_t chart_color(std::size_t i) {
  // Tableau's ten: distinct for the colour-blind in most pairs, and dark enough on white.
  static constexpr std::array<std::uint32_t, 10> palette{
      pack_rgba(31, 119, 180),  pack_rgba(255, 127, 14), pack_rgba(44, 160, 44),   pack_rgba(214, 39, 40),
      pack_rgba(148, 103, 189), pack_rgba(140, 86, 75),  pack_rgba(227, 119, 194), pack_rgba(127, 127, 127),
      pack_rgba(188, 189, 34),  pack_rgba(23, 190, 207)};
  return palette[i % palette.size()];
}

std::vector<double> axis_ticks(double lo, double hi, int max_ticks, bool log) {
  return nice_ticks(lo, hi, max_ticks, log);
}

ChartReport draw_chart(Framebuffer& fb, const TextRenderer& text, const Chart& c, PixelRect area,
                       const ChartParams& p) {
  for (const ChartSeries& s : c.series)
    if (s.x.size() != s.y.size())
      throw std::invalid_argument("chart: series '" + s.name + "' has " + std::to_string(s.x.size()) +
                                  " x values and " + std::to_string(s.y.size()) + " y values");
  area.x0 = std::max(area.x0, 0);
  area.y0 = std::max(area.y0, 0);
  area.x1 = std::min(area.x1, fb.width - 1);
  area.y1 = std::min(area.y1, fb.height - 1);
  const int fs = p.font_px, line = fs + fs / 2, title_fs = fs + fs / 4;
  const auto [xl, xh] = data_range(c, true);
  const auto [yl, yh] = data_range(c, false);
  const bool x_fixed = std::isfinite(c.x.lo) && std::isfinite(c.x.hi),
             y_fixed = std::isfinite(c.y.lo) && std::isfinite(c.y.hi);

  ChartReport r;
  r.x_log = c.x.log, r.y_log = c.y.log;
  fill(fb, area, p.background);

  // Vertical layout.
  int y = area.y0 + p.margin;
  if (!c.title.empty()) y += title_fs + line / 3;
  const std::string ytitle = axis_title(c.y), xtitle = axis_title(c.x);
  const int ytitle_baseline = y + fs;
  y += fs + fs;  // the y axis's title and a gap above the top tick label
  r.plot.y0 = y;
  r.plot.y1 = area.y1 - p.margin - (xtitle.empty() ? 0 : line) - line - 4;
  if (r.plot.y1 - r.plot.y0 < 4 * fs)
    throw std::invalid_argument("chart: the area is too small for a plot (" +
                                std::to_string(area.y1 - area.y0 + 1) + " pixels high)");
  // y ticks: the most that keep a line's height between labels.
  const int plot_h = r.plot.y1 - r.plot.y0;
  AxisTicks yt;
  for (int n = std::max(2, std::min(11, plot_h / (2 * fs))); n >= 2; --n) {
    yt = ticks_for(yl, yh, n, c.y.log, y_fixed);
    bool apart = true;
    for (std::size_t i = 1; i < yt.ticks.size(); ++i)
      if (std::abs(ChartReport::fraction(yt.ticks[i], yt.lo, yt.hi, c.y.log) -
                   ChartReport::fraction(yt.ticks[i - 1], yt.lo, yt.hi, c.y.log)) *
              plot_h <
          line)
        apart = false;
    if (apart) break;
  }
  std::vector<std::string> ylabels;
  int ylabel_w = 0;
  for (double v : yt.ticks) {
    ylabels.push_back(tick_label(v, c.y.log ? 0 : yt.step));
    ylabel_w = std::max(ylabel_w, text.measure(ylabels.back(), fs).advance);
  }

  // Horizontal layout: the y labels, the plot, the legend.
  r.plot.x0 = area.x0 + p.margin + ylabel_w + 6;
  const bool legend =
      std::any_of(c.series.begin(), c.series.end(), [](const ChartSeries& s) { return !s.name.empty(); });
  int legend_w = 0;
  if (legend) {
    for (const ChartSeries& s : c.series) legend_w = std::max(legend_w, text.measure(s.name, fs).advance);
    legend_w += 28 + 2 * 6;  // a sample line of 22 pixels, gaps, the box's padding
  }
  // Half the widest x label may stick out right of the plot: room for it in the margin.
  const int right_room = std::max(p.margin, text.measure(tick_label(xh, 0), fs).advance / 2 + 2);
  r.plot.x1 = area.x1 - right_room - (legend ? legend_w + p.margin : 0);
  if (r.plot.x1 - r.plot.x0 < 6 * fs)
    throw std::invalid_argument("chart: the area is too small for a plot (" +
                                std::to_string(area.x1 - area.x0 + 1) + " pixels wide)");
  const int plot_w = r.plot.x1 - r.plot.x0;
  AxisTicks xt;
  std::vector<std::string> xlabels;
  for (int n = std::max(2, std::min(15, plot_w / (3 * fs))); n >= 2; --n) {
    xt = ticks_for(xl, xh, n, c.x.log, x_fixed);
    xlabels.clear();
    bool apart = true;
    double last_right = -INFINITY;
    for (double v : xt.ticks) {
      xlabels.push_back(tick_label(v, c.x.log ? 0 : xt.step));
      const int w = text.measure(xlabels.back(), fs).advance;
      const double col = r.plot.x0 + ChartReport::fraction(v, xt.lo, xt.hi, c.x.log) * plot_w;
      if (col - w / 2.0 < last_right + 8) apart = false;
      last_right = col + w / 2.0;
    }
    if (apart) break;
  }
  r.x_lo = xt.lo, r.x_hi = xt.hi, r.y_lo = yt.lo, r.y_hi = yt.hi;
  r.x_ticks = xt.ticks, r.y_ticks = yt.ticks;

  // Grid, frame, ticks and their labels.
  for (double v : r.y_ticks) {
    const int row = int(std::lround(r.row(v)));
    r.y_tick_rows.push_back(row);
    fill(fb, PixelRect{r.plot.x0, row, r.plot.x1, row}, p.grid_color);
  }
  for (double v : r.x_ticks) {
    const int col = int(std::lround(r.column(v)));
    r.x_tick_columns.push_back(col);
    fill(fb, PixelRect{col, r.plot.y0, col, r.plot.y1}, p.grid_color);
  }
  fill(fb, PixelRect{r.plot.x0 - 1, r.plot.y0 - 1, r.plot.x1 + 1, r.plot.y0 - 1}, p.frame_color);
  fill(fb, PixelRect{r.plot.x0 - 1, r.plot.y1 + 1, r.plot.x1 + 1, r.plot.y1 + 1}, p.frame_color);
  fill(fb, PixelRect{r.plot.x0 - 1, r.plot.y0 - 1, r.plot.x0 - 1, r.plot.y1 + 1}, p.frame_color);
  fill(fb, PixelRect{r.plot.x1 + 1, r.plot.y0 - 1, r.plot.x1 + 1, r.plot.y1 + 1}, p.frame_color);
  for (std::size_t i = 0; i < r.y_ticks.size(); ++i) {
    const int row = r.y_tick_rows[i];
    fill(fb, PixelRect{r.plot.x0 - 5, row, r.plot.x0 - 2, row}, p.frame_color);
    const TextExtent e = text.measure(ylabels[i], fs);
    r.y_labels.push_back(
        text.draw(fb, ylabels[i], r.plot.x0 - 6 - e.advance, row + (e.ascent + 1) / 2, fs, p.text_color));
  }
  const int xlabel_baseline = r.plot.y1 + 5 + fs;
  for (std::size_t i = 0; i < r.x_ticks.size(); ++i) {
    const int col = r.x_tick_columns[i];
    fill(fb, PixelRect{col, r.plot.y1 + 2, col, r.plot.y1 + 5}, p.frame_color);
    const TextExtent e = text.measure(xlabels[i], fs);
    r.x_labels.push_back(text.draw(fb, xlabels[i], col - e.advance / 2, xlabel_baseline, fs, p.text_color));
  }
  if (!c.title.empty()) {
    const TextExtent e = text.measure(c.title, title_fs);
    text.draw(fb, c.title, std::max(area.x0 + p.margin, (r.plot.x0 + r.plot.x1) / 2 - e.advance / 2),
              area.y0 + p.margin + title_fs, title_fs, p.text_color);
  }
  if (!ytitle.empty()) text.draw(fb, ytitle, area.x0 + p.margin, ytitle_baseline, fs, p.text_color);
  if (!xtitle.empty()) {
    const TextExtent e = text.measure(xtitle, fs);
    text.draw(fb, xtitle, (r.plot.x0 + r.plot.x1) / 2 - e.advance / 2, xlabel_baseline + line, fs,
              p.text_color);
  }

  // The series: lines first, markers over them.
  r.points.resize(c.series.size());
  for (std::size_t si = 0; si < c.series.size(); ++si) {
    const ChartSeries& s = c.series[si];
    auto& pts = r.points[si];
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double u = s.x[i], v = s.y[i];
      if (!std::isfinite(u) || !std::isfinite(v) || (c.x.log && u <= 0) || (c.y.log && v <= 0)) {
        pts.emplace_back(-1, -1);
        ++r.left_out;
      } else {
        pts.emplace_back(int(std::lround(r.column(u))), int(std::lround(r.row(v))));
      }
    }
  }
  for (std::size_t si = 0; si < c.series.size(); ++si) {
    const ChartSeries& s = c.series[si];
    if (!s.line) continue;
    const std::uint32_t color = s.color != 0 ? s.color : chart_color(si);
    for (std::size_t i = 1; i < s.x.size(); ++i) {
      if (r.points[si][i].first < 0 || r.points[si][i - 1].first < 0) continue;
      segment(fb, r.column(s.x[i - 1]), r.row(s.y[i - 1]), r.column(s.x[i]), r.row(s.y[i]), r.plot,
              p.line_width, color);
    }
  }
  for (std::size_t si = 0; si < c.series.size(); ++si) {
    const ChartSeries& s = c.series[si];
    if (!s.markers) continue;
    const std::uint32_t color = s.color != 0 ? s.color : chart_color(si);
    for (const auto& [px, py] : r.points[si]) {
      if (px < 0) continue;
      const int m = s.marker_radius;
      // Whole, also on the frame: the plot keeps at least the margin to the area's edges.
      fill(fb, PixelRect{px - m, py - m, px + m, py + m}, color);
    }
  }

  // The legend: right of the plot, a sample of each series' line (and marker) and its name.
  if (legend) {
    const int x0 = r.plot.x1 + right_room + p.margin, row0 = r.plot.y0;
    r.legend = PixelRect{x0, row0, x0 + legend_w - 1, row0 + int(c.series.size()) * line + 8};
    for (std::size_t si = 0; si < c.series.size(); ++si) {
      const ChartSeries& s = c.series[si];
      const std::uint32_t color = s.color != 0 ? s.color : chart_color(si);
      const int mid = row0 + 4 + int(si) * line + line / 2;
      if (s.line)
        fill(fb, PixelRect{x0 + 6, mid - p.line_width / 2, x0 + 27, mid + (p.line_width - 1) / 2}, color);
      if (s.markers) fill(fb, PixelRect{x0 + 14, mid - 3, x0 + 20, mid + 3}, color);
      const TextExtent e = text.measure(s.name, fs);
      text.draw(fb, s.name, x0 + 34, mid + (e.ascent + 1) / 2, fs, p.text_color);
    }
    for (int k = r.legend.x0; k <= r.legend.x1; ++k)
      for (int row : {r.legend.y0, r.legend.y1})
        if (k < fb.width && row < fb.height) fb.rgba[fb.index(k, row)] = p.grid_color;
  }
  return r;
}

}  // namespace foxi
