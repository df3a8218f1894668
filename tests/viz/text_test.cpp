// FreeType text: the font is found on the system (not in the source tree), glyph ink lands in the box
// measure() predicts and nowhere else, scales with the size, and blends the colour asked for.
#include "foxi/viz/text.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace foxi {
namespace {

struct Ink {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1, count = 0;
};

Ink ink_of(const Framebuffer& fb, std::uint32_t background) {
  Ink k;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if (fb.rgba[fb.index(x, y)] != background) {
        k.x0 = std::min(k.x0, x);
        k.y0 = std::min(k.y0, y);
        k.x1 = std::max(k.x1, x);
        k.y1 = std::max(k.y1, y);
        ++k.count;
      }
  return k;
}

TEST(Text, FontComesFromTheSystem) {
  const std::string file = find_font_file();
  EXPECT_TRUE(std::filesystem::is_regular_file(file)) << file;
  EXPECT_EQ(std::filesystem::path(file).filename(), "DejaVuSans.ttf");
  EXPECT_EQ(file.find(FOXI_TEST_DATA_DIR), std::string::npos);
  EXPECT_THROW(find_font_file("No Such Font Family 42"), FontError);
  EXPECT_THROW(TextRenderer("/nonexistent/font.ttf"), FontError);
}

TEST(Text, GlyphInkLiesInTheMeasuredBox) {
  const TextRenderer text(find_font_file());
  const std::uint32_t white = pack_rgba(255, 255, 255);
  for (int size : {10, 14, 24}) {
    for (const char* s : {"Hg", "temperature (°C)", "-12.5", "µm MPa"}) {
      Framebuffer fb(400, 80);
      const int x = 20, base = 50;
      const TextExtent e = text.measure(s, size);
      const PixelRect r = text.draw(fb, s, x, base, size);
      const Ink k = ink_of(fb, white);
      ASSERT_GT(k.count, 0) << s;
      EXPECT_EQ(k.x0, r.x0);
      EXPECT_EQ(k.x1, r.x1);
      EXPECT_EQ(k.y0, r.y0);
      EXPECT_EQ(k.y1, r.y1);
      // Ink between the pen's start and end (a glyph may overhang by a pixel or two), within ascent/descent.
      EXPECT_GE(k.x0, x - 2) << s;
      EXPECT_LE(k.x1, x + e.advance + 1) << s;
      EXPECT_EQ(k.y0, base - e.ascent) << s;
      EXPECT_EQ(k.y1, base + e.descent - 1) << s;
      // Cap height of DejaVu Sans is 0.73 em: the ink rises about that far.
      EXPECT_NEAR(double(e.ascent), 0.73 * size, 0.15 * size + 1) << s;
    }
  }
}

TEST(Text, BlendsTheColourAndClipsAtTheImage) {
  const TextRenderer text(find_font_file());
  Framebuffer fb(60, 30, false, pack_rgba(0, 0, 0));
  text.draw(fb, "IIII", 2, 25, 20, pack_rgba(255, 0, 0));
  int full = 0;
  for (std::uint32_t p : fb.rgba) {
    EXPECT_EQ((p >> 8) & 255u, 0u);   // no green
    EXPECT_EQ((p >> 16) & 255u, 0u);  // no blue
    full += (p & 255u) == 255u;
  }
  EXPECT_GT(full, 4 * 10);  // the stems of I are solid red (a column of a cap height each at least)
  // Off the image: nothing drawn, nothing out of bounds.
  Framebuffer small(10, 10);
  const PixelRect r = text.draw(small, "Hello", -500, -500, 14);
  EXPECT_GT(r.x0, r.x1);
}

}  // namespace
}  // namespace foxi
