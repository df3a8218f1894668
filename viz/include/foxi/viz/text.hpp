// Text in pictures, drawn with FreeType from a font installed on the system (DejaVu Sans of the Debian
// package fonts-dejavu-core, found through fontconfig), anti-aliased and blended into a framebuffer.
// The reusable piece of the legends and charts: measure a string, draw it at a baseline.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "foxi/api.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"

namespace foxi {

// No usable font, or FreeType failed: the message says which file and why.
struct FOXI_API FontError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The file of the installed font matching `family` (fontconfig; an exact family match only), else
// the Debian path of fonts-dejavu-core's DejaVuSans.ttf if it exists. Throws FontError if neither.
FOXI_API std::string find_font_file(std::string_view family = "DejaVu Sans");

// A string's extent at a size, in pixels: from the pen's start, advance to the pen's end; ascent
// above and descent below the baseline (both >= 0) of the glyphs' ink.
struct TextExtent {
  int advance = 0, ascent = 0, descent = 0;
};

// One font face, loaded once. Not thread-safe (FreeType's face is shared state): one per thread.
class FOXI_API TextRenderer {
 public:
  // Loads the font file; throws FontError naming it if FreeType cannot.
  explicit TextRenderer(const std::string& font_file);
  ~TextRenderer();
  TextRenderer(TextRenderer&&) noexcept;
  TextRenderer& operator=(TextRenderer&&) noexcept;

  // The extent of UTF-8 `text` at `pixel_size` (the font's em in pixels), with kerning.
  TextExtent measure(std::string_view text, int pixel_size) const;
  // Draws `text` with its pen starting at (x, baseline_y), each glyph's coverage blended over fb's
  // pixels in `color` (clipped to the image; id and depth untouched). Returns the pixels it may
  // have changed (the ink's box, clipped).
  PixelRect draw(Framebuffer& fb, std::string_view text, int x, int baseline_y, int pixel_size,
                 std::uint32_t color = pack_rgba(0, 0, 0)) const;
  const std::string& font_file() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace foxi
