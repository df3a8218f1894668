// The picture options the foxi front ends share, read from text: the camera (--eye --at --up --fov |
// --dir), the image size (--size WxH), the shrink factor and a subset of tets (regions:, box:,
// random:). foxi render, foxi movie, foxi order and foxi-view read them here, so that the same
// options give the same picture; a host that offers the same options may too. Errors are
// OptionError, whose message names the option as the front ends spell it.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi {

// A malformed option value; what() names the option and says what it takes.
struct FOXI_API OptionError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// "a,b,c": finite numbers separated by commas (at least one); `what` names the option in the error.
FOXI_API std::vector<double> parse_number_list(std::string_view text, std::string_view what);

// The camera as given: each part present or not (fitted to the bounds later).
struct CameraOptions {
  bool has_eye = false, has_at = false, has_up = false, has_dir = false;
  double eye[3] = {0, 0, 0}, at[3] = {0, 0, 0}, up[3] = {0, 0, 1}, dir[3] = {0, 0, 1};
  double fov_deg = 0;  // 0: the default (30 degrees)
};

// The texts of --eye, --at, --up, --fov and --dir (empty: not given). OptionError for a malformed
// one, --dir with --eye or --fov, a zero --dir, a --fov outside (0, 180).
FOXI_API CameraOptions parse_camera_options(std::string_view eye, std::string_view at, std::string_view up,
                                            std::string_view fov, std::string_view dir);

// The camera of these options fitted to the box [lo, hi] for an image of width/height `aspect`
// (camera_from_options: what is not given is fitted).
FOXI_API Camera camera_for(const CameraOptions& options, const double lo[3], const double hi[3],
                           double aspect);

// The arguments with each --name=value as --name value (GNU style), up to a bare "--" (what follows
// it is another program's): how foxi, foxi-view and the workbench read their options.
FOXI_API std::vector<std::string> split_option_values(std::vector<std::string> args);

// "WxH" with 1 <= W, H <= 16384 (--size).
struct ImageSize {
  int width = 0, height = 0;
};
FOXI_API ImageSize parse_image_size(std::string_view text);

// A shrink factor in (0, 1] (--shrink).
FOXI_API double parse_shrink(std::string_view text);

// The tets of the listed region ids, in index order (each once); `what` names the option in the
// error for a list that is not numbers.
FOXI_API std::vector<std::uint32_t> tets_of_regions(const Mesh& mesh, std::string_view ids,
                                                    std::string_view what);

// A subset of tets from "regions:1,3" (those region ids), "random:F" (each tet with probability F,
// drawn with std::mt19937(seed)) or "box:x0,y0,z0,x1,y1,z1" (tets whose centroid lies in the box),
// in index order; OptionError (naming --subset) for another form or a subset with no tets.
FOXI_API std::vector<std::uint32_t> parse_subset(const Mesh& mesh, std::string_view spec, unsigned seed);

// An opacity in [0, 1] (--iso-opacity); `what` names the option in the error.
FOXI_API double parse_opacity(std::string_view text, std::string_view what);

// "REGION=a,REGION=a,...": each REGION a region id or name of the mesh (region_id_of) and a an opacity
// in [0, 1] (--region-opacity); OptionError for a malformed entry, an unknown name, a region given twice.
FOXI_API std::vector<RegionOpacity> parse_region_opacity(const Mesh& mesh, std::string_view text);

// "v0:a0,v1:a1,...": values (as given; the caller converts units) strictly increasing, opacities in
// [0, 1) (--opacity-curve); OptionError otherwise.
FOXI_API std::vector<OpacityPoint> parse_opacity_curve(std::string_view text);

}  // namespace foxi
