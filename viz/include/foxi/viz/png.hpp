// PNG files of a framebuffer's pixels (libpng).
#pragma once

#include <filesystem>

#include "foxi/api.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/viz/framebuffer.hpp"

namespace foxi {

// Writes fb.rgba as an 8-bit RGBA PNG. The file appears complete or not at all and is on disk when
// this returns (a DurableFile, foxi/model/durable_file.hpp). Throws std::runtime_error (IoError for
// the file itself) with the reason on failure.
FOXI_API void write_png(const std::filesystem::path& path, const Framebuffer& fb);
// The same into `file`, finished (on disk, closed) but not committed: for sets of files that are
// committed together (a movie's frames).
FOXI_API void write_png(DurableFile& file, const Framebuffer& fb);

// Reads a PNG (any format libpng converts) into fb.rgba (8-bit RGBA); id is set to kNone and depth
// emptied. Throws std::runtime_error on failure.
FOXI_API Framebuffer read_png(const std::filesystem::path& path);

}  // namespace foxi
