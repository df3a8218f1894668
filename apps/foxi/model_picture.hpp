// Pictures of models for foxi model show and foxi demo: the mesh of a model cut open and drawn by
// the painter (viz), each part in its material's colour.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/viz/model_picture.hpp"
#include "model_run.hpp"

namespace foxi::cli {

struct ModelPictureParams {
  int width = 1280, height = 960;
  ModelView view = ModelView::exploded;
  // A field of the mesh to colour by (e.g. "temperature") instead of the materials: graded facets, a
  // colour-bar legend at the right, no shrinking (the interior view shows the field cut open).
  std::string field;
};

struct ModelPicture {
  std::size_t tets_drawn = 0;
  double field_lo = 0, field_hi = 0;  // with a field: its colour range, display unit
  std::string field_unit;             // with a field: the display unit
  bool delaunay = false;  // painter in the power order; otherwise MPVO order with the depth buffer
  std::vector<std::uint32_t> part_color;  // 1 per part
};

// Renders `m.mesh` seen obliquely from the front (-y), above and to the right, to the PNG `path`:
// by the painter in the power order when the drawn mesh is Delaunay (cut, whole), else in MPVO order
// with the depth buffer (an exploded mesh is not one Delaunay mesh).
ModelPicture render_model_picture(const MeshedModel& m, const std::string& path,
                                  const ModelPictureParams& params = {});

// Prints "  PART  material  colour #rrggbb" lines, the picture's legend.
void print_legend(const MeshedModel& m, const ModelPicture& picture);

}  // namespace foxi::cli
