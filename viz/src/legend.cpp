#include "foxi/viz/legend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace foxi {

namespace {

std::string range_line(const ColorLegend& l) {
  const double lo = l.unit.to_display(l.scale.lo), hi = l.unit.to_display(l.scale.hi);
  const double step = std::abs(hi - lo) / 100;
  return tick_label(lo, step) + " to " + tick_label(hi, step) +
         (l.unit.symbol.empty() ? "" : " " + l.unit.symbol);
}

std::string map_line(const ColorLegend& l) {
  return std::string(color_map_name(l.scale.map)) + (l.scale.log ? ", log scale" : "");
}

std::string title_line(const ColorLegend& l) {
  return l.title + (l.unit.symbol.empty() ? "" : " (" + l.unit.symbol + ")");
}

// The ticks (display values) for a bar of bar_h rows whose labels are at most line_h high: the most
// (finest step) whose neighbours lie at least line_h + 2 rows apart, so labels never overlap, and
// at most 11 and one per two label heights of bar, so that they stay readable.
std::vector<double> legend_ticks(const ColorLegend& l, int bar_h, int line_h) {
  double lo = l.unit.to_display(l.scale.lo), hi = l.unit.to_display(l.scale.hi);
  if (lo > hi) std::swap(lo, hi);
  const bool log = l.scale.log && lo > 0;
  auto apart = [&](const std::vector<double>& t) {
    for (std::size_t i = 1; i < t.size(); ++i)
      if (std::abs(l.scale.position(l.unit.to_si(t[i])) - l.scale.position(l.unit.to_si(t[i - 1]))) *
              (bar_h - 1) <
          line_h + 2)
        return false;
    return true;
  };
  const int readable = std::max(2, std::min(11, bar_h / (2 * line_h)));
  std::vector<double> best;
  for (int n = readable; n >= 2 && best.size() < 2; --n) {
    std::vector<double> t = nice_ticks(lo, hi, n, log);
    if (apart(t) && t.size() > best.size()) best = t;
  }
  // A short bar: finer steps, as long as labels stay apart, rather than a single tick.
  for (int n = readable + 1; n <= std::max(2, bar_h / 4) && best.size() < 2; ++n) {
    std::vector<double> t = nice_ticks(lo, hi, n, log);
    if (apart(t) && t.size() > best.size()) best = t;
  }
  return best;
}

}  // namespace

PixelRect draw_caption(Framebuffer& fb, const TextRenderer& text, std::string_view caption,
                       const LegendParams& params) {
  if (caption.empty()) return {};
  // The baseline from a fixed string's ascent, so that captions of different text sit on one line.
  const int ascent = text.measure("Ag", params.font_px).ascent;
  return text.draw(fb, caption, params.margin, params.margin + ascent, params.font_px, params.text_color);
}

std::string tick_label(double value, double step) {
  char buf[64];
  const double a = std::abs(value);
  if (value == 0) return "0";
  if (a >= 1e6 || a < 1e-3 || !(step > 0)) {
    std::snprintf(buf, sizeof buf, "%.3g", value);
  } else {
    const int decimals = std::clamp(int(-std::floor(std::log10(step) + 1e-9)), 0, 6);
    std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  }
  return buf;
}

int legend_min_height(const LegendParams& p) {
  const int fs = p.font_px, line = fs + fs / 2;
  // As draw_color_legend lays it out: title, bar (2 labels high at least), range and map lines.
  return (p.margin + fs + line / 2 + fs / 2) + 2 * fs + (p.margin + 2 * line + fs / 2);
}

int legend_width(const TextRenderer& text, const ColorLegend& l, const LegendParams& p) {
  const int fs = p.font_px;
  int w = std::max({text.measure(title_line(l), fs).advance, text.measure(range_line(l), fs).advance,
                    text.measure(map_line(l), fs).advance});
  // Tick labels: the widest that the range's ends could need, at the finest step.
  const double lo = l.unit.to_display(l.scale.lo), hi = l.unit.to_display(l.scale.hi);
  const std::vector<double> t =
      nice_ticks(std::min(lo, hi), std::max(lo, hi), 12, l.scale.log && std::min(lo, hi) > 0);
  const double step = t.size() > 1 ? t[1] - t[0] : std::abs(hi - lo);
  int label = 0;
  for (double v : t) label = std::max(label, text.measure(tick_label(v, step), fs).advance);
  label = std::max({label, text.measure(tick_label(lo, step), fs).advance,
                    text.measure(tick_label(hi, step), fs).advance});
  w = std::max(w, p.bar_width + 6 + label);
  return w + 2 * p.margin;
}

LegendReport draw_color_legend(Framebuffer& fb, const TextRenderer& text, const ColorLegend& l,
                               PixelRect area, const LegendParams& p) {
  area.x0 = std::max(area.x0, 0);
  area.y0 = std::max(area.y0, 0);
  area.x1 = std::min(area.x1, fb.width - 1);
  area.y1 = std::min(area.y1, fb.height - 1);
  const int fs = p.font_px, line = fs + fs / 2;
  LegendReport r;
  r.rect = area;
  for (int y = area.y0; y <= area.y1; ++y)
    for (int x = area.x0; x <= area.x1; ++x) fb.rgba[fb.index(x, y)] = p.background;
  const int x = area.x0 + p.margin;
  int y = area.y0 + p.margin + fs;
  text.draw(fb, title_line(l), x, y, fs, p.text_color);
  // Bar: from a line below the title to two lines above the bottom (range, map), with half a label
  // of room above and below for the end ticks' labels.
  const int bar_top = y + line / 2 + fs / 2, bar_bottom = area.y1 - p.margin - 2 * line - fs / 2;
  const int bar_h = bar_bottom - bar_top + 1;
  if (bar_h < 2 * fs || area.x1 - area.x0 + 1 < p.bar_width + 2 * p.margin)
    throw std::invalid_argument("legend: the area is too small for a colour bar");
  r.bar = PixelRect{x, bar_top, x + p.bar_width - 1, bar_bottom};
  for (int row = bar_top; row <= bar_bottom; ++row) {
    const double t = double(bar_bottom - row) / double(bar_h - 1);  // 0 at the bottom row, 1 at the top
    const std::uint32_t c = l.scale.color_at(t);
    for (int k = r.bar.x0; k <= r.bar.x1; ++k) fb.rgba[fb.index(k, row)] = c;
  }
  const std::uint32_t frame = pack_rgba(80, 80, 80);
  for (int k = r.bar.x0 - 1; k <= r.bar.x1 + 1; ++k) {
    fb.rgba[fb.index(k, bar_top - 1)] = frame;
    fb.rgba[fb.index(k, bar_bottom + 1)] = frame;
  }
  for (int row = bar_top - 1; row <= bar_bottom + 1; ++row) {
    fb.rgba[fb.index(r.bar.x0 - 1, row)] = frame;
    fb.rgba[fb.index(r.bar.x1 + 1, row)] = frame;
  }
  r.ticks = legend_ticks(l, bar_h, fs);
  // Log ticks span decades: each label in %g form (step 0).
  const double step = l.scale.log          ? 0
                      : r.ticks.size() > 1 ? r.ticks[1] - r.ticks[0]
                                           : std::abs(l.scale.hi - l.scale.lo);
  for (double v : r.ticks) {
    const double t = l.scale.position(l.unit.to_si(v));
    const int row = bar_bottom - int(std::lround(t * double(bar_h - 1)));
    r.tick_rows.push_back(row);
    for (int k = r.bar.x1 - 3; k <= r.bar.x1 + 4; ++k) fb.rgba[fb.index(k, row)] = p.text_color;
    const std::string s = tick_label(v, step);
    const TextExtent e = text.measure(s, fs);
    // The label centred on its tick: baseline half the digits' height below it.
    r.labels.push_back(text.draw(fb, s, r.bar.x1 + 7, row + (e.ascent + 1) / 2, fs, p.text_color));
  }
  // Marks: a line across the bar and a pointer in the margin at its left, at the value's row (the
  // bar's row of position t is the one that shows t's colour).
  for (double v : l.marks) {
    const double t = l.scale.position(v);
    if (!(t >= 0 && t <= 1)) continue;
    const int row = bar_bottom - int(std::lround(t * double(bar_h - 1)));
    r.mark_rows.push_back(row);
    for (int k = r.bar.x0; k <= r.bar.x1; ++k) fb.rgba[fb.index(k, row)] = p.text_color;
    for (int dy = -3; dy <= 3; ++dy) {
      const int yy = row + dy;
      if (yy < area.y0 || yy > area.y1) continue;
      for (int k = r.bar.x0 - 2 - (3 - std::abs(dy)); k <= r.bar.x0 - 2; ++k)
        if (k >= area.x0) fb.rgba[fb.index(k, yy)] = p.text_color;
    }
  }
  y = bar_bottom + fs / 2 + line;
  text.draw(fb, range_line(l), x, y, fs, p.text_color);
  text.draw(fb, map_line(l), x, y + line, fs, pack_rgba(90, 90, 90));
  return r;
}

}  // namespace foxi
