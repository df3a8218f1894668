// Pictures of a model's parts (foxi model show, foxi demo, the workbench's model panel): the mesh of a
// model, each region (part) in its material's colour, seen obliquely from the front, above and to the
// right, whole, exploded (each part lifted) or cut open. One drawing, so that every front end shows
// the same picture of the same mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/framebuffer.hpp"

namespace foxi {

struct FieldPaint;  // field_paint.hpp

enum class ModelView : std::uint8_t {
  exploded,  // each part lifted in z by its index times a gap: every part shows whole
  cut,       // only tets with centroids at y >= the middle: the inside shows (jagged at the cut)
  whole,     // the mesh as it is
  interior,  // the far 60 % of the visibility order, each tet shrunk to 85 % (the paper's view inside)
};

// What a view draws of a mesh: the mesh itself or its exploded copy, and the tets drawn (empty: all).
// A field to colour by is resolved on mesh() and subset (an exploded copy has no fields).
struct FOXI_API ModelScene {
  ModelScene(const Mesh& source, ModelView view);
  const Mesh& mesh() const { return view == ModelView::exploded ? exploded : *source; }
  const Mesh* source;
  ModelView view;
  Mesh exploded;                      // the exploded view's copy, else empty
  std::vector<std::uint32_t> subset;  // the cut view's tets, else empty
};

// The colour of each region id (index: id; ids without a region grey): the material_color
// (palette.hpp) of the region's material, by the material's name and its index in mesh.materials.
FOXI_API std::vector<std::uint32_t> model_region_colors(const Mesh& mesh);

struct ModelPictureReport {
  std::size_t tets_drawn = 0;
  bool delaunay = false;  // painter in the power order; otherwise MPVO order with the depth buffer
};

// Draws `scene` into fb (its size; cleared to white) with `region_colors` (model_region_colors), or
// with `field` (graded facets resolved on scene.mesh(), no shrinking) when it is given: by the
// painter in the power order when the drawn mesh is Delaunay (cut, whole), else in MPVO order with
// the depth buffer (an exploded mesh is not one Delaunay mesh).
FOXI_API ModelPictureReport draw_model_picture(const ModelScene& scene,
                                               const std::vector<std::uint32_t>& region_colors,
                                               Framebuffer& fb,
                                               std::shared_ptr<const FieldPaint> field = nullptr);

}  // namespace foxi
