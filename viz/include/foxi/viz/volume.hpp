// Direct volume rendering of a field by projected tetrahedra, composited in the exact visibility order
// (issue 23 item 2). Each tet's linear field is integrated along every pixel's ray through it: the
// pixels whose centres lie in the tet's projection (unsnapped: the rows' spans of its corners'
// convex hull), and per pixel the entry and exit
// of the ray (the tet's four planes, in double), the field at both ends (linear in the tet, so linear
// along the ray) and the emission-absorption integral over that segment give a colour and an opacity,
// blended over what the farther tets left. The transfer function is a colour scale (colormap.hpp) and an
// opacity curve: opacity a(v) is what a ray accumulates through `unit_length` of constant value v, so
// the extinction is tau(v) = -ln(1 - a(v)) / unit_length (per world unit). integrate_segment evaluates
// the integral with the segment cut into steps of at most 1/64 of the colour scale and an optical
// depth of at most 1/4 each (midpoint rule in the value; each step's colour and extinction constant),
// at most 256. The painter, with a linear colour scale, pre-integrates instead: tabulated
// antiderivatives of tau and of the tau-weighted colour over the value give a segment's opacity (to
// the tables' accuracy) and its colour within 1/4 of a level more (pieces where one would not do;
// volume.cpp says why); with a log scale it steps.
//
// Why the order makes it exact: each pixel's ray meets tets in interior-disjoint segments, and the power
// order of a Delaunay mesh puts the farther of any two tets one ray meets first (seed paper, Theorem
// 1), so the segments are composited far to near, which is the volume-rendering integral of the whole
// ray. Progressive: drawn batch by batch, the picture so far is the exact picture of the far part.
// A tet the near plane cuts (an eye inside it or next to it): the spans of its part beyond the plane,
// each ray's segment starting at the plane.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/colormap.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi {

struct OpacityPoint {
  double value = 0;
  double opacity = 0;  // in [0, 1); the painter takes at most 0.999999 (volume_extinction clamps)
};

struct VolumeParams {
  ColorScale scale;                         // the colour of value v: scale.color(v)
  std::vector<OpacityPoint> opacity_curve;  // ascending values, linear between, constant beyond the ends
  double unit_length = 1;                   // world length over which opacity a(v) accumulates (> 0)
  double near = 0;                          // perspective near plane (world); 0 = automatic (tiny)
  int threads = 2;
  std::uint32_t background = pack_rgba(255, 255, 255);
};

// The extinction per world unit at value v (the curve's opacity turned into tau, see above).
FOXI_API double volume_extinction(const VolumeParams& params, double v);

// The emission-absorption integral over one segment of a ray, back end first: the field goes linearly
// from v_far to v_near over `length` world units; blends it over c (3 floats, 0..255) with the steps
// described above. What the painter does per pixel and tet.
FOXI_API void integrate_segment(const VolumeParams& params, double v_far, double v_near, double length,
                                float c[3]);

class FOXI_API VolumePainter {
 public:
  // corner: 4 values per tet (lent). Throws std::invalid_argument for a degenerate camera, sizes that
  // do not match, an opacity curve not ascending or with opacities outside [0, 1), unit_length <= 0.
  VolumePainter(const Mesh& mesh, const Camera& camera, int width, int height, std::span<const double> corner,
                const VolumeParams& params);
  ~VolumePainter();
  VolumePainter(VolumePainter&&) noexcept;
  VolumePainter& operator=(VolumePainter&&) noexcept;

  // Composites the tets in the order given (back to front); batch after batch.
  void draw(std::span<const std::uint32_t> tets);
  // The picture so far into fb (resized, no depth buffer): colours rounded to 8 bits, ids the nearest
  // tet blended at each pixel (kNone where none).
  void resolve(Framebuffer& fb) const;
  // The same, but only the screen tiles drawn since the last resolve_drawn: fb must hold the picture
  // that call left (an interactive view's framebuffer, resolved after each step). The first call,
  // `whole`, or a framebuffer of another size resolves everything.
  void resolve_drawn(Framebuffer& fb, bool whole = false);
  std::size_t samples() const;         // pixel segments integrated
  std::size_t pre_integrated() const;  // of those, the ones taken in closed form (see volume.cpp)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct VolumeReport {
  bool delaunay = false;
  bool exact_order = false;       // composited in the power order (else MPVO's, with cycles broken)
  std::size_t cycles_broken = 0;  // MPVO only
  std::size_t tets = 0, samples = 0;
  double certificate_ms = 0, order_ms = 0, draw_ms = 0;
};

// The safe volume picture: a mesh with the Delaunay certificate composited in the power order of
// `subset` (empty: all tets); any other mesh cannot be composited exactly by this painter: it is
// composited in MPVO order (face adjacency, cycles broken at the largest power key), which is right
// where MPVO's order is a visibility order and wrong along rays through the cycles it broke, and the
// report says so. fb keeps its size.
FOXI_API VolumeReport draw_volume_picture(const Mesh& mesh, const SphereTable& table, const Camera& camera,
                                          Framebuffer& fb, std::span<const std::uint32_t> subset,
                                          std::span<const double> corner, const VolumeParams& params);

}  // namespace foxi
