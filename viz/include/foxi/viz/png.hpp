// PNG files of a framebuffer's pixels (libpng).
#pragma once

#include <filesystem>

#include "foxi/viz/framebuffer.hpp"

namespace foxi {

// Writes fb.rgba as an 8-bit RGBA PNG. The file appears complete or not at all: it is written to a
// temporary file beside `path`, then renamed. Throws std::runtime_error with the reason on failure.
void write_png(const std::filesystem::path& path, const Framebuffer& fb);

// Reads a PNG (any format libpng converts) into fb.rgba (8-bit RGBA); id is set to kNone and depth
// emptied. Throws std::runtime_error on failure.
Framebuffer read_png(const std::filesystem::path& path);

}  // namespace foxi
