// The picture options foxi render and foxi movie share: camera (--eye --at --up --fov | --dir),
// --size, --shrink, --regions, --no-edges. Parsed before the mesh is read (usage errors first),
// resolved against the mesh after.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/view_options.hpp"

namespace foxi::cli {

// Help text lines for these options.
extern const char* const kPictureOptionsHelp;

struct PictureOptions {
  int width = 0, height = 0;
  RenderParams params;   // edges, shrink
  CameraOptions camera;  // as given (view_options.hpp), fitted by resolve_picture
  std::string regions;
};

// --size WxH (1..16384 each) into width and height; UsageError otherwise (parse_image_size).
void parse_size(const std::string& size_s, int& width, int& height);

// Takes the options out of args; OptionError (view_options.hpp) for malformed ones.
PictureOptions take_picture_options(Args& args, const char* default_size);

struct Picture {
  std::vector<std::uint32_t> subset;  // empty: all tets
  Camera camera;
};

// The selected tets (UsageError if --regions selects none) and the camera fitted to them.
Picture resolve_picture(const PictureOptions& options, const Mesh& mesh);

// --deform NAME:SCALE, the deformed shape (foxi render and foxi movie).
extern const char* const kDeformOptionHelp;
struct DeformOption {
  std::string name;
  double scale = 0;
};
// Takes --deform out of args (the last colon splits, so a field name may hold one); UsageError if malformed.
std::optional<DeformOption> take_deform_option(Args& args);
// Moves mesh's nodes by the displacement (UsageError naming `path` for a field that is not one) and
// checks the moved mesh as `command` does a read one (require_usable: folded tets re-oriented, flat
// ones refused); returns the largest node movement.
double apply_deform(Mesh& mesh, const DeformOption& deform, const std::string& path, const char* command);

}  // namespace foxi::cli
