// The field-colouring options foxi render and foxi movie share (--field NAME[:component] --cmap
// --range --log --graded --legend --units --step): parsed before the mesh is read, resolved against it
// after into a FieldPaint for the rasterizer and a colour-bar legend beside the picture.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "cli.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/legend.hpp"
#include "foxi/viz/text.hpp"

namespace foxi::cli {

extern const char* const kFieldOptionsHelp;

struct FieldOptions {
  std::string spec;  // NAME[:component]; empty: region colours (the other options are then refused)
  ColorMapId map = ColorMapId::viridis;
  bool has_range = false;
  double range[2] = {0, 0};  // --range, display units
  bool log = false, graded = false, legend = true;
  bool markers = false;  // --markers: mark the drawn maximum and minimum, with their values
  std::string units;     // --units; empty: the field's usual display unit (°C for K, MPa for Pa, ...)
  long step = -1;        // --step; -1: the last
  // A colour range in SI that replaces --range and the automatic one (a movie's range, fixed over
  // its time steps, is found in SI: converting it to a display unit and back would not round-trip).
  bool has_si_range = false;
  double si_range[2] = {0, 0};
  // The automatic range (and the NaN count) from the tets' corner values even when flat: set by the
  // commands for pictures that show the field as it varies inside a tet (a volume rendering,
  // translucent isosurfaces), whose colours reach the nodes' values, not just the centroids'.
  bool corner_range = false;
};

// Takes the options out of args; UsageError for malformed ones.
FieldOptions take_field_options(Args& args);

struct FieldPicture {
  FieldChoice choice;
  std::size_t step = 0;
  std::shared_ptr<const FieldPaint> paint;
  ColorLegend legend;
  double data_lo = 0, data_hi = 0;  // the drawn values' range, SI (NaN, NaN if none is finite)
  std::size_t no_value = 0;         // drawn values that are NaN
  bool range_widened = false;       // a constant field: the automatic range was widened around it
  bool range_centred = false;       // coolwarm, both signs: the automatic range made symmetric about 0
  // Where the drawn maximum and minimum are (world; graded: a node, flat: a tet's centroid), and the
  // tets that show them: a pixel showing one of these tets at the point's projection shows the point.
  double max_at[3] = {0, 0, 0}, min_at[3] = {0, 0, 0};
  std::vector<std::uint32_t> max_tets, min_tets;
};

// The field's paint for the tets of `subset` (all when empty); UsageError naming `path` and what it
// has for a field, component, step or unit that is not there, or a log scale without positive values.
FieldPicture resolve_field(const FieldOptions& options, const Mesh& mesh,
                           std::span<const std::uint32_t> subset, const std::string& path);

// Marks the drawn maximum and minimum in `scene` (drawn with `camera`): a ring at the point and its
// value, where the point shows (a pixel within 1 of its projection shows one of its tets); returns
// for each whether it showed.
struct MarkerReport {
  bool max_shown = false, min_shown = false;
};
MarkerReport draw_extreme_markers(Framebuffer& scene, const Camera& camera, const TextRenderer& text,
                                  const FieldPicture& field);

// The legend panel's width for a width x height picture; UsageError if the picture is too narrow
// (under 64 pixels left for the mesh) or too low (legend_min_height) for it.
int legend_panel(const TextRenderer& text, const FieldPicture& field, int width, int height);
// The picture `scene` with the legend in a panel of `panel` pixels at its right: the result is
// scene.width + panel wide (id kNone in the panel). Callers draw the mesh panel pixels narrower than
// the picture asked for.
Framebuffer with_legend(const Framebuffer& scene, const TextRenderer& text, const FieldPicture& field,
                        int panel);

}  // namespace foxi::cli
