// foxi movie --sweep (issue 17 item 7): field movies whose every frame is the picture foxi render
// draws with the same options and the frame's value: an isovalue sweep (the interval tree built once,
// each frame ordering and drawing only the tets its isovalue crosses or reaches), a growing threshold,
// or the steps of a field with several (one colour range over all of them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "field_options.hpp"
#include "iso_options.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi::cli {

struct Sweep {
  enum class Kind { none, iso, threshold, steps } kind = Kind::none;
  double a = 0, b = 0;  // iso and threshold: from a to b, display units
};

// "" (none), "iso:a,b", "threshold:a,b" (a < b) or "steps"; UsageError otherwise.
Sweep parse_sweep(const std::string& text);
// UsageError for options a sweep (or its absence) does not combine with.
void check_sweep_options(const Sweep& sweep, const FieldOptions& field, const IsoOptions& iso);

// Frame k's value of n: a + (b - a) k / (n - 1), b exactly at the end.
double sweep_value(const Sweep& sweep, int k, int n);

struct SweepRange {
  double lo = 0, hi = 0;  // SI: the union of the steps' colour ranges (or --range)
  std::size_t steps = 1;
};
// The colour range of every step of the field together, as resolve_field would choose it for each.
SweepRange fixed_step_range(const FieldOptions& options, const Mesh& mesh,
                            std::span<const std::uint32_t> subset, const std::string& path);

struct SweepInputs {
  const Mesh& mesh;
  const SphereTable& table;
  const Camera& camera;
  int width, height;                    // the scene, without the legend's panel
  const RenderParams& render;           // edges, shrink (the field's paint is set per frame)
  std::span<const std::uint32_t> base;  // --regions (empty: all)
  const FieldOptions& field_options;    // steps: resolved again per step (with the fixed range)
  const FieldPicture& field;            // iso, threshold: the field as resolved once
  const IsoOptions& iso_options;        // --threshold, --clip (and --iso, --slice with steps)
  Sweep sweep;
  bool iso_only = false;
  int frames = 48;        // iso, threshold
  std::size_t steps = 1;  // steps
  const std::string& path;
};

struct SweepStats {
  std::size_t frames = 0;
  std::vector<double> values;                      // each frame's value, display units (steps: step index)
  std::vector<std::size_t> crossing, drawn;        // per frame: tets crossed (iso), tets drawn
  double build_ms = 0, query_ms = 0, draw_ms = 0;  // the interval tree (once), queries and drawing in all
  bool depth_buffer = false;                       // some frame drawn with the depth buffer (uncertified)
  std::string unit;                                // the display unit's symbol
  std::vector<double> step_values;                 // steps: the field's step times
};

// Frame k's caption: "t = 12.5 s" (steps with times; "step 3 of 5" without), "iso 32 °C", or
// "threshold 30 to 50 °C" (display units).
std::string sweep_caption(const Sweep& sweep, const SweepStats& stats, std::size_t k);

// Draws the frames in order and hands each, with the field picture its legend shows and its caption
// (sweep_caption), to `frame`.
SweepStats run_sweep(
    const SweepInputs& in,
    const std::function<void(const Framebuffer&, const FieldPicture&, const std::string&)>& frame);

// The sweep's lines of the report.
void print_sweep(const SweepStats& stats, const Sweep& sweep, const FieldPicture& field);

}  // namespace foxi::cli
