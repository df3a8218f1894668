// FreeType text (see text.hpp): UTF-8 decoded to code points, glyphs rendered 8-bit anti-aliased
// (FT_LOAD_RENDER), placed with the font's advances and kerning, blended over the pixels.
#include "foxi/viz/text.hpp"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <filesystem>
#include <vector>

namespace foxi {

namespace {

// The code points of UTF-8 text; a malformed byte reads as U+FFFD.
std::vector<char32_t> decode_utf8(std::string_view s) {
  std::vector<char32_t> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto b = static_cast<unsigned char>(s[i]);
    int len = b < 0x80 ? 1 : (b >> 5) == 6 ? 2 : (b >> 4) == 14 ? 3 : (b >> 3) == 30 ? 4 : 0;
    if (len == 0 || i + std::size_t(len) > s.size()) {
      out.push_back(0xFFFD);
      ++i;
      continue;
    }
    char32_t c = len == 1 ? b : len == 2 ? (b & 0x1F) : len == 3 ? (b & 0x0F) : (b & 0x07);
    bool ok = true;
    for (int k = 1; k < len; ++k) {
      const auto t = static_cast<unsigned char>(s[i + std::size_t(k)]);
      ok = ok && (t >> 6) == 2;
      c = (c << 6) | (t & 0x3F);
    }
    out.push_back(ok ? c : 0xFFFD);
    i += ok ? std::size_t(len) : 1;
  }
  return out;
}

constexpr const char* kDebianDejaVu = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

}  // namespace

std::string find_font_file(std::string_view family) {
  std::string found;
  if (FcInit()) {
    FcPattern* pattern = FcPatternCreate();
    const std::string fam(family);
    FcPatternAddString(pattern, FC_FAMILY, reinterpret_cast<const FcChar8*>(fam.c_str()));
    FcPatternAddInteger(pattern, FC_WEIGHT, FC_WEIGHT_REGULAR);
    FcPatternAddInteger(pattern, FC_SLANT, FC_SLANT_ROMAN);
    FcConfigSubstitute(nullptr, pattern, FcMatchPattern);
    FcDefaultSubstitute(pattern);
    FcResult result = FcResultNoMatch;
    FcPattern* match = FcFontMatch(nullptr, pattern, &result);
    if (match != nullptr) {
      FcChar8* file = nullptr;
      FcChar8* got = nullptr;
      // fontconfig always answers with some font: take it only if it is the family asked for.
      if (FcPatternGetString(match, FC_FAMILY, 0, &got) == FcResultMatch &&
          std::string_view(reinterpret_cast<const char*>(got)) == family &&
          FcPatternGetString(match, FC_FILE, 0, &file) == FcResultMatch)
        found = reinterpret_cast<const char*>(file);
      FcPatternDestroy(match);
    }
    FcPatternDestroy(pattern);
  }
  if (!found.empty()) return found;
  std::error_code ec;
  if (family == "DejaVu Sans" && std::filesystem::is_regular_file(kDebianDejaVu, ec)) return kDebianDejaVu;
  throw FontError("no font '" + std::string(family) +
                  "' installed (fontconfig found none; install the Debian package fonts-dejavu-core)");
}

struct TextRenderer::Impl {
  FT_Library library = nullptr;
  FT_Face face = nullptr;
  std::string file;
  ~Impl() {
    if (face != nullptr) FT_Done_Face(face);
    if (library != nullptr) FT_Done_FreeType(library);
  }

  // Calls fn(glyph slot, pen x) for each glyph of text at `size`, pen x in pixels from the start;
  // returns the final advance.
  template <class Fn>
  int layout(std::string_view text, int size, Fn&& fn) const {
    if (FT_Set_Pixel_Sizes(face, 0, FT_UInt(std::max(1, size))) != 0)
      throw FontError(file + ": cannot set a pixel size of " + std::to_string(size));
    long pen = 0;  // 26.6 fixed point
    FT_UInt previous = 0;
    for (char32_t c : decode_utf8(text)) {
      const FT_UInt glyph = FT_Get_Char_Index(face, FT_ULong(c));
      if (previous != 0 && glyph != 0 && FT_HAS_KERNING(face)) {
        FT_Vector kern;
        if (FT_Get_Kerning(face, previous, glyph, FT_KERNING_DEFAULT, &kern) == 0) pen += kern.x;
      }
      if (FT_Load_Glyph(face, glyph, FT_LOAD_RENDER) != 0)
        throw FontError(file + ": cannot render glyph U+" + std::to_string(std::uint32_t(c)));
      fn(face->glyph, int((pen + 32) >> 6));
      pen += face->glyph->advance.x;
      previous = glyph;
    }
    return int((pen + 32) >> 6);
  }
};

TextRenderer::TextRenderer(const std::string& font_file) : impl_(std::make_unique<Impl>()) {
  impl_->file = font_file;
  if (FT_Init_FreeType(&impl_->library) != 0) throw FontError("FreeType failed to start");
  if (FT_New_Face(impl_->library, font_file.c_str(), 0, &impl_->face) != 0)
    throw FontError(font_file + ": FreeType cannot read it as a font");
}

TextRenderer::~TextRenderer() = default;
TextRenderer::TextRenderer(TextRenderer&&) noexcept = default;
TextRenderer& TextRenderer::operator=(TextRenderer&&) noexcept = default;

const std::string& TextRenderer::font_file() const { return impl_->file; }

TextExtent TextRenderer::measure(std::string_view text, int pixel_size) const {
  TextExtent e;
  e.advance = impl_->layout(text, pixel_size, [&](FT_GlyphSlot g, int) {
    if (g->bitmap.rows == 0) return;
    e.ascent = std::max(e.ascent, g->bitmap_top);
    e.descent = std::max(e.descent, int(g->bitmap.rows) - g->bitmap_top);
  });
  return e;
}

PixelRect TextRenderer::draw(Framebuffer& fb, std::string_view text, int x, int baseline_y, int pixel_size,
                             std::uint32_t color) const {
  PixelRect box{fb.width, fb.height, -1, -1};
  const std::uint32_t cr = color & 255u, cg = (color >> 8) & 255u, cb = (color >> 16) & 255u;
  impl_->layout(text, pixel_size, [&](FT_GlyphSlot g, int pen) {
    const FT_Bitmap& bm = g->bitmap;
    if (bm.pixel_mode != FT_PIXEL_MODE_GRAY) return;
    const int gx = x + pen + g->bitmap_left, gy = baseline_y - g->bitmap_top;
    for (int r = 0; r < int(bm.rows); ++r) {
      const int y = gy + r;
      if (y < 0 || y >= fb.height) continue;
      for (int c = 0; c < int(bm.width); ++c) {
        const int px = gx + c;
        if (px < 0 || px >= fb.width) continue;
        const std::uint32_t a = bm.buffer[r * bm.pitch + c];
        if (a == 0) continue;
        std::uint32_t& p = fb.rgba[fb.index(px, y)];
        auto mix = [a](std::uint32_t fg, std::uint32_t bg) { return (fg * a + bg * (255 - a) + 127) / 255; };
        p = pack_rgba(mix(cr, p & 255u), mix(cg, (p >> 8) & 255u), mix(cb, (p >> 16) & 255u),
                      (p >> 24) & 255u);
        box.x0 = std::min(box.x0, px);
        box.y0 = std::min(box.y0, y);
        box.x1 = std::max(box.x1, px);
        box.y1 = std::max(box.y1, y);
      }
    }
  });
  if (box.x0 > box.x1) return PixelRect{};
  return box;
}

}  // namespace foxi
