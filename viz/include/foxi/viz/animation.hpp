// Animated picture files written frame by frame (movies of the painter, seed paper section 6.1):
// animated PNG (APNG: acTL / fcTL / fdAT chunks written here with zlib, since libpng has no APNG
// support; each frame after the first stores only the rectangle that changed) and GIF (giflib, a
// median-cut palette per frame). Frames must all have the writer's size; only RGB is stored.
//
// A file appears complete or not at all: frames go to a temporary file beside the target, renamed
// by finish(). A writer destroyed without finish() removes the temporary file. Errors throw
// std::runtime_error naming the file and the reason.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "foxi/api.hpp"
#include "foxi/viz/framebuffer.hpp"

namespace foxi {

struct AnimationParams {
  int width = 0, height = 0;  // frame size in pixels (>= 1)
  double fps = 12;            // frames per second (> 0; GIF rounds the delay to 1/100 s)
  int loops = 0;              // times to play; 0 = forever
};

class FOXI_API AnimationWriter {
 public:
  virtual ~AnimationWriter() = default;
  // Appends a frame (fb.rgba of width x height; alpha ignored).
  virtual void add(const Framebuffer& fb) = 0;
  // Completes the file and renames it into place; at least one frame is needed.
  virtual void finish() = 0;
  virtual int frames() const = 0;
};

// APNG (.apng or .png; readers without APNG support show the first frame).
FOXI_API std::unique_ptr<AnimationWriter> open_apng(const std::filesystem::path& path,
                                                    const AnimationParams& params);
// GIF89a with a NETSCAPE2.0 loop extension.
FOXI_API std::unique_ptr<AnimationWriter> open_gif(const std::filesystem::path& path,
                                                   const AnimationParams& params);

// Numbered PNG frames: `pattern` a file name with one printf integer conversion (%d or %0Nd, N < 100)
// and no other '%' (frame_pattern), frame k written as frame_name(pattern, k). The frames appear
// together at finish() (DurableFile temporaries committed together); the folder must exist.
FOXI_API std::unique_ptr<AnimationWriter> open_png_frames(const std::string& pattern,
                                                          const AnimationParams& params);
// Whether `pattern` holds exactly one %d or %0Nd and no other '%'.
FOXI_API bool frame_pattern(const std::string& pattern);
// Frame k's file name (pattern checked by frame_pattern).
FOXI_API std::string frame_name(const std::string& pattern, std::size_t k);

}  // namespace foxi
