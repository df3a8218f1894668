// Pixel-for-pixel comparison of two pictures of the same size (the painter against its oracles).
#pragma once

#include <cstddef>

#include "foxi/viz/framebuffer.hpp"

namespace foxi::test {

struct PictureDiff {
  std::size_t differing = 0;  // pixels whose colour or tet differ
  std::size_t shown = 0;      // pixels of `b` (the reference) that show a tet
};

inline PictureDiff compare_pictures(const Framebuffer& a, const Framebuffer& b) {
  PictureDiff d;
  for (std::size_t i = 0; i < a.rgba.size(); ++i) {
    d.differing += a.rgba[i] != b.rgba[i] || a.id[i] != b.id[i];
    d.shown += b.id[i] != kNone;
  }
  return d;
}

}  // namespace foxi::test
