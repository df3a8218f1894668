// The picture the painter fills: RGBA8 pixels, an id buffer (the tet each pixel shows, for picking,
// probing and recolouring) and, in depth-buffer mode only, a depth buffer (double: it is the test
// oracle, and float rounding alone flips grazing layers).
//
// The framebuffer owns its pixels, rows `width` apart. A host with its own RGBA buffer (its own row
// stride) has draw_picture draw the tet painter's colours straight into it, the framebuffer keeping
// the ids and shades (picture.hpp, RgbaImage, TetRasterizer::draw_into; examples/embed/field_buffer).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

// A pixel: R in bits 0-7, G 8-15, B 16-23, A 24-31.
constexpr std::uint32_t pack_rgba(std::uint32_t r, std::uint32_t g, std::uint32_t b, std::uint32_t a = 255) {
  return (r & 255u) | (g & 255u) << 8 | (b & 255u) << 16 | (a & 255u) << 24;
}

namespace detail {
// Asks the OS for 2 MB pages for the untouched buffer [p, p + bytes) (advice only; defined in the viz
// library): an image's rows lie 4 x width bytes apart, so with 4 kB pages each row a face covers
// would cost a TLB miss.
FOXI_API void advise_large_pages(void* p, std::size_t bytes);
// Room for n pixels in v, fresh memory so advised, unless v has it already.
template <class T>
inline void reserve_advised(std::vector<T>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  std::vector<T>().swap(v);
  v.reserve(n);
  advise_large_pages(v.data(), n * sizeof(T));
}
}  // namespace detail

struct Framebuffer {
  int width = 0, height = 0;
  std::vector<std::uint32_t> rgba;  // width * height, row-major, row 0 at the top
  std::vector<std::uint32_t> id;    // width * height: tet index, or kNone for background
  // width * height: the painter's shade of each pixel it drew (0-255: Lambert and edge darkening
  // together), its colour being the base colour (region or field colour) scaled by shade / 255, each
  // channel rounded; undefined where id is kNone. TetRasterizer::recolor recolours through it.
  std::vector<std::uint8_t> shade;
  std::vector<double> depth;  // width * height in depth-buffer mode, else empty; larger = nearer
  // Depth-buffer mode: the nearness slopes (per pixel in x, in y) of the face each pixel shows, 2 a
  // pixel; they decide exact depth ties as the painter's fill rule does (the rasterizer sizes it).
  std::vector<double> depth_slope;

  Framebuffer() = default;
  // A cleared framebuffer; with_depth allocates the depth buffer.
  Framebuffer(int w, int h, bool with_depth = false, std::uint32_t background = pack_rgba(255, 255, 255)) {
    resize(w, h, with_depth, background);
  }
  void resize(int w, int h, bool with_depth, std::uint32_t background = pack_rgba(255, 255, 255)) {
    width = w;
    height = h;
    detail::reserve_advised(rgba, std::size_t(w) * std::size_t(h));
    detail::reserve_advised(id, std::size_t(w) * std::size_t(h));
    detail::reserve_advised(shade, std::size_t(w) * std::size_t(h));
    rgba.assign(std::size_t(w) * std::size_t(h), background);
    id.assign(std::size_t(w) * std::size_t(h), kNone);
    shade.assign(std::size_t(w) * std::size_t(h), 0);
    if (with_depth) {
      depth.assign(std::size_t(w) * std::size_t(h), -std::numeric_limits<double>::infinity());
      depth_slope.assign(2 * depth.size(), 0.0);
    } else {
      depth.clear();
      depth_slope.clear();
    }
  }
  // Background colour everywhere, no tet, depth at infinity.
  void clear(std::uint32_t background = pack_rgba(255, 255, 255)) {
    std::fill(rgba.begin(), rgba.end(), background);
    std::fill(id.begin(), id.end(), kNone);
    std::fill(depth.begin(), depth.end(), -std::numeric_limits<double>::infinity());
  }
  std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
};

}  // namespace foxi
