// Colour maps against the published maps' own values (end points and midpoints quoted in their papers
// and data files), lightness order of the sequential maps, scale positions, and the colour-bar ticks
// against a brute-force search over 1/2/5 x 10^k steps.
#include "foxi/viz/colormap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace foxi {
namespace {

std::uint32_t rgb(int r, int g, int b) {
  return pack_rgba(std::uint32_t(r), std::uint32_t(g), std::uint32_t(b));
}

// Relative luminance (Rec. 709 on linearized sRGB).
double luminance(std::uint32_t c) {
  auto lin = [](double v) {
    v /= 255;
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  };
  return 0.2126 * lin(c & 255u) + 0.7152 * lin((c >> 8) & 255u) + 0.0722 * lin((c >> 16) & 255u);
}

TEST(ColorMap, EndsAreThePublishedColours) {
  // viridis #440154 .. #fde725 (matplotlib's documentation); cividis (0, 0.1351, 0.3048) .. (0.9957,
  // 0.9093, 0.2178) from Nunez et al.'s table; Moreland's cool-warm (59, 76, 192) .. (180, 4, 38);
  // Turbo (0.18995, 0.07176, 0.23217) .. (0.47960, 0.01583, 0.01055) from Google's table.
  EXPECT_EQ(color_map_entry(ColorMapId::viridis, 0), rgb(0x44, 0x01, 0x54));
  EXPECT_EQ(color_map_entry(ColorMapId::viridis, 255), rgb(0xfd, 0xe7, 0x25));
  EXPECT_EQ(color_map_entry(ColorMapId::cividis, 0), rgb(0, 34, 78));
  EXPECT_EQ(color_map_entry(ColorMapId::cividis, 255), rgb(254, 232, 56));
  EXPECT_EQ(color_map_entry(ColorMapId::coolwarm, 0), rgb(59, 76, 192));
  EXPECT_EQ(color_map_entry(ColorMapId::coolwarm, 255), rgb(180, 4, 38));
  EXPECT_EQ(color_map_entry(ColorMapId::rainbow, 0), rgb(48, 18, 59));
  EXPECT_EQ(color_map_entry(ColorMapId::rainbow, 255), rgb(122, 4, 3));
  // viridis's middle, #21918c (matplotlib's documentation: the map at 0.5).
  const std::uint32_t mid = color_map_entry(ColorMapId::viridis, 128);
  EXPECT_NEAR(int(mid & 255u), 0x21, 1);
  EXPECT_NEAR(int((mid >> 8) & 255u), 0x91, 1);
  EXPECT_NEAR(int((mid >> 16) & 255u), 0x8c, 1);
}

TEST(ColorMap, SequentialMapsGrowInLightnessAndCoolwarmPeaksInTheMiddle) {
  for (ColorMapId m : {ColorMapId::viridis, ColorMapId::cividis})
    for (int i = 1; i < 256; ++i)
      EXPECT_GE(luminance(color_map_entry(m, i)) + 1e-3, luminance(color_map_entry(m, i - 1)))
          << color_map_name(m) << i;
  int brightest = 0;
  for (int i = 1; i < 256; ++i)
    if (luminance(color_map_entry(ColorMapId::coolwarm, i)) >
        luminance(color_map_entry(ColorMapId::coolwarm, brightest)))
      brightest = i;
  EXPECT_NEAR(brightest, 128, 8);
}

TEST(ColorMap, NamesRoundTrip) {
  for (ColorMapId m : {ColorMapId::viridis, ColorMapId::cividis, ColorMapId::coolwarm, ColorMapId::rainbow})
    EXPECT_EQ(parse_color_map(color_map_name(m)), m);
  EXPECT_FALSE(parse_color_map("jet").has_value());
}

TEST(ColorScale, ValuesPickTheirEntry) {
  ColorScale s;
  s.lo = 300;
  s.hi = 356;
  EXPECT_EQ(s.color(300), color_map_entry(s.map, 0));
  EXPECT_EQ(s.color(356), color_map_entry(s.map, 255));
  EXPECT_EQ(s.color(1e9), color_map_entry(s.map, 255));  // clamped
  EXPECT_EQ(s.color(-1e9), color_map_entry(s.map, 0));
  EXPECT_EQ(s.color(std::nan("")), s.nan_color);
  // Entry i covers [lo + i w, lo + (i + 1) w), w = range / 256.
  const double w = 56.0 / 256;
  for (int i = 0; i < 256; i += 17) EXPECT_EQ(s.color(300 + (i + 0.5) * w), color_map_entry(s.map, i));
  EXPECT_NEAR(s.value_at(s.position(321.5)), 321.5, 1e-12);
  s.log = true;
  s.lo = 1e3;
  s.hi = 1e9;
  EXPECT_NEAR(s.position(1e6), 0.5, 1e-12);
  EXPECT_EQ(s.color(0), s.nan_color);
  EXPECT_EQ(s.color(-5), s.nan_color);
}

// A range wider than the largest double (its width overflows to infinity): positions still run 0 to
// 1 across it (every value was once the lowest colour), and no ticks rather than NaN ones.
TEST(ColorScale, RangeWiderThanTheLargestDouble) {
  ColorScale s;
  s.lo = -1.5e308;
  s.hi = 1.5e308;
  EXPECT_DOUBLE_EQ(s.position(0), 0.5);
  EXPECT_DOUBLE_EQ(s.position(s.hi), 1.0);
  EXPECT_DOUBLE_EQ(s.position(s.lo), 0.0);
  EXPECT_DOUBLE_EQ(s.position(0.75e308), 0.75);
  EXPECT_EQ(s.color(0), color_map_entry(s.map, 128));
  EXPECT_DOUBLE_EQ(s.value_at(0.75), 0.75e308);
  for (double t : nice_ticks(s.lo, s.hi, 8)) EXPECT_TRUE(std::isfinite(t));
}

// Whether v is an integer multiple of step (to rounding).
bool multiple(double v, double step) { return std::abs(v / step - std::round(v / step)) < 1e-6; }

TEST(NiceTicks, SmallestOneTwoFiveStepWithinTheCount) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3, 3), e(-6, 6);
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::pow(10.0, e(rng));
    double lo = u(rng) * scale, hi = u(rng) * scale;
    if (lo > hi) std::swap(lo, hi);
    if (!(hi - lo > 1e-9 * scale)) continue;
    const int most = 2 + int(rng() % 10);
    const std::vector<double> t = nice_ticks(lo, hi, most);
    // Brute force: the smallest step m 10^k (m in 1, 2, 5) with at most `most` multiples in range.
    double best = 0;
    std::size_t best_count = 0;
    for (int k = -30; k <= 30 && best == 0; ++k)
      for (double m : {1.0, 2.0, 5.0}) {
        const double s = m * std::pow(10.0, k);
        const double n = std::floor(hi / s + 1e-9) - std::ceil(lo / s - 1e-9) + 1;
        if (n <= most) {
          best = s;
          best_count = std::size_t(n);
          break;
        }
      }
    ASSERT_EQ(t.size(), best_count) << lo << " " << hi << " " << most;
    for (std::size_t i = 0; i < t.size(); ++i) {
      EXPECT_GE(t[i], lo);
      EXPECT_LE(t[i], hi);
      EXPECT_TRUE(multiple(t[i], best) || t[i] == 0) << t[i] << " step " << best;
      if (i > 0) {
        EXPECT_NEAR(t[i] - t[i - 1], best, best * 1e-6);
      }
    }
  }
}

TEST(NiceTicks, LogTicksAreOneTwoFivePowersOfTen) {
  const std::vector<double> t = nice_ticks(3e2, 4e4, 20, true);
  const std::vector<double> want = {5e2, 1e3, 2e3, 5e3, 1e4, 2e4};
  ASSERT_EQ(t.size(), want.size());
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(t[i], want[i], want[i] * 1e-12);
  const std::vector<double> d = nice_ticks(1e-3, 1e9, 5, true);  // 13 decades: thinned
  EXPECT_LE(d.size(), 5u);
  EXPECT_GE(d.size(), 2u);
  for (double v : d) EXPECT_NEAR(std::log10(v), std::round(std::log10(v)), 1e-9);
  EXPECT_TRUE(nice_ticks(1, 1, 5).empty());
  EXPECT_TRUE(nice_ticks(-1, 5, 5, true).empty());
}

}  // namespace
}  // namespace foxi
