// Translucent regions and isosurfaces composited exactly (issue 23 item 1): an "x-ray" picture in
// which each region (material) has an opacity and several isosurfaces are drawn translucent at once.
//
// What is drawn (a surface model, not an absorption per unit length): the faces between regions of
// different opacity and the outer boundary of the drawn set (the subset less the regions of opacity
// 0), one fragment per such face and pixel, so the picture does not depend on the mesh density; and
// each tet's iso polygons. A face between two drawn regions shows the more opaque one's colour with
// its opacity; a boundary face its own region's. Faces between regions of equal opacity are not
// drawn. Fragments are blended back to front with "over" (C = a c + (1 - a) C, per channel in float,
// starting from the background) and rounded to 8 bits once at the end (resolve).
//
// Why compositing in the tets' visibility order is exact. Each fragment belongs to one tet: a face
// between two drawn tets to the tet behind it (the face is that tet's front face, where a ray enters
// it), a boundary face to its only drawn tet (a front or a back face), an iso polygon to the tet it
// lies in. Along the ray of one pixel, a fragment of tet T lies in T's segment [entry, exit] of the
// ray (an entry-face fragment at its start, a back-face one at its end, iso polygons within). Two
// tets have interior-disjoint segments, so if a fragment of Ta is nearer than one of Tb, Ta's
// segment is in front of Tb's: Ta precedes Tb along the ray, and for a Delaunay mesh the power
// order puts Tb first (seed paper, Theorem 1: it holds for any two tets one ray meets, adjacent or
// not, hence for any subset, non-convex and with the eye inside). Within one tet the painter draws
// its back faces, then its iso polygons far to near (the levels of a linear field are parallel
// planes), then its front faces: their order along every ray. So every pixel receives its fragments
// in the order of their depth, which is what sorting them would give; only fragments at exactly
// one depth (a ray through an edge or a vertex) may come in either order, and there the order is
// not defined by the geometry either. The tets that own no fragment need not be ordered at all: the
// argument holds for the order of any subset, so only the tets with a face or a polygon to draw are
// ordered (surface_tets), not the whole mesh.
//
// Meshes without the Delaunay certificate have no such order: draw_translucent_picture then does not
// composite in an order but collects every pixel's fragments and sorts them by their interpolated
// depth (an A-buffer: exact up to depth rounding, but memory and time grow with the fragments), and
// says so in its report.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/spheres.hpp"

namespace foxi {

struct RegionOpacity {
  std::int32_t region = 0;
  double opacity = 1;  // in [0, 1]; 0 leaves the region out
};

struct TranslucentParams {
  std::vector<RegionOpacity> region_opacity;  // regions not listed have default_opacity
  double default_opacity = 1;
  bool regions = true;  // draw the region surfaces (false: the isosurfaces alone)
  // Colour of region r as in RenderParams (region_colors[r] where in range, else region_color(r)).
  std::vector<std::uint32_t> region_colors;
  double ambient = 0.3;  // Lambert as the tet painter: ambient + (1 - ambient) max(0, n . light)
  // Isosurfaces: 4 values per tet (lent; empty: none) and the isovalues with their colours
  // (iso.values, iso.scale; shade_min and cold_side as IsoPainter; cap is not drawn), each polygon
  // with opacity iso_opacity.
  std::span<const double> corner;
  IsoParams iso;
  double iso_opacity = 0.5;
  double near = 0;  // perspective near-plane distance (world); 0 = automatic (tiny)
  int threads = 2;  // threads blending interleaved bands of rows
  std::uint32_t background = pack_rgba(255, 255, 255);
  // Collect mode (no Delaunay certificate: fragments sorted per pixel) keeps every fragment, 32 bytes
  // each: at most this many (64M, 2 GiB) before draw throws TooManyFragments.
  std::size_t max_fragments = std::size_t(1) << 26;
};

// Collect mode's fragments would exceed TranslucentParams::max_fragments.
struct FOXI_API TooManyFragments : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The view-independent part: which faces of which tets are drawn. Build once per mesh, subset and
// opacities; a turning camera reuses it.
struct TranslucentSurfaces {
  // Per tet: bit f (0..3) face f is on the outer boundary of the drawn set (drawn by this tet in
  // every view); bit 4 + f: face f lies between this drawn tet and a drawn tet of different opacity
  // (drawn by whichever of the two is behind it in the view: this one where it faces the eye).
  std::vector<std::uint8_t> mask;
  std::vector<float> opacity;       // per tet: its region's opacity (0 outside the drawn set)
  std::vector<std::uint32_t> tets;  // the tets with a face or an iso polygon to draw: the ones to order
  std::size_t boundary_faces = 0;   // faces on the outer boundary of the drawn set
  std::size_t interface_faces = 0;  // faces between drawn regions of different opacity
  std::size_t iso_tets = 0;         // tets some isovalue crosses
};

// subset: the tets that may be drawn (empty: all). Throws std::invalid_argument for an opacity
// outside [0, 1] (or NaN), corner values of the wrong size, a tet index out of range.
FOXI_API TranslucentSurfaces translucent_surfaces(const Mesh& mesh, std::span<const std::uint32_t> subset,
                                                  const TranslucentParams& params);

// One fragment (collect mode): a face's or polygon's sample at a pixel centre.
struct Fragment {
  std::uint32_t pixel = 0;  // y * width + x
  std::uint32_t tet = 0;
  std::int8_t face = 0;  // the tet's face 0..3, or -1 - k for the k-th isovalue (ascending)
  float depth = 0;  // nearness interpolated on the screen (1/z perspective, -z orthographic): larger = nearer
  float rgb[3] = {0, 0, 0};
  float alpha = 0;
};

// Blends fragments over the colour c (3 floats) in the given order: the arithmetic of the painter.
inline void blend_over(float c[3], const float rgb[3], float alpha) {
  for (int k = 0; k < 3; ++k) c[k] = rgb[k] * alpha + c[k] * (1 - alpha);
}

class FOXI_API TranslucentPainter {
 public:
  // surfaces and the mesh (and params.corner) are lent and must outlive it. collect: record the
  // fragments (fragments()) instead of blending them (one thread). Throws std::invalid_argument for
  // a degenerate camera, surfaces of another mesh.
  TranslucentPainter(const Mesh& mesh, const Camera& camera, int width, int height,
                     const TranslucentSurfaces& surfaces, const TranslucentParams& params,
                     bool collect = false);
  ~TranslucentPainter();
  TranslucentPainter(TranslucentPainter&&) noexcept;
  TranslucentPainter& operator=(TranslucentPainter&&) noexcept;

  // Blends the fragments of `tets`, in the order given (back to front), over what is drawn; may be
  // called batch after batch (a partial picture is the exact picture of the far part). Tets outside
  // surfaces.tets draw nothing. Collect mode: TooManyFragments past params.max_fragments.
  void draw(std::span<const std::uint32_t> tets);
  // The picture so far into fb (resized to the painter's size, no depth buffer): colours rounded to
  // 8 bits, ids the tet of each pixel's nearest fragment (kNone where none). Collect mode: the
  // fragments sorted per pixel by depth (sort_fragments) and blended.
  void resolve(Framebuffer& fb);
  const std::vector<Fragment>& fragments() const;  // collect mode: in drawing order
  std::size_t fragment_count() const;              // fragments blended or collected

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct TranslucentReport {
  bool delaunay = false;
  bool exact_order = false;      // composited in the power order (else fragments sorted per pixel)
  std::size_t tets_ordered = 0;  // surfaces.tets
  std::size_t fragments = 0;
  double certificate_ms = 0, surfaces_ms = 0, order_ms = 0, draw_ms = 0;
};

// The safe translucent picture: a mesh with the Delaunay certificate composited in the power order of
// the surface tets; any other mesh by per-pixel sorting of its fragments (see above). fb keeps its size.
FOXI_API TranslucentReport draw_translucent_picture(const Mesh& mesh, const SphereTable& table,
                                                    const Camera& camera, Framebuffer& fb,
                                                    std::span<const std::uint32_t> subset,
                                                    const TranslucentParams& params);

}  // namespace foxi
