// The software painter (seed paper, sections 6-7): tets drawn back to front in a visibility order,
// each contributing only its FRONT faces (those facing the eye), overwrite the pixels they cover, so
// no depth buffer is needed. The same rasterizer has a depth-buffer mode (z-test on the interpolated
// depth, draw order irrelevant) that serves as the test oracle: for a visibility order both give the
// same picture pixel for pixel.
//
// Faces are flat-shaded (Lambert + ambient) in a per-region colour; mesh edges are drawn by
// darkening a face's own pixels near its edges (never outside them). Both come to one shade byte a
// pixel (kept in Framebuffer::shade), the colour being the base colour scaled by shade / 255, so that a
// flat picture recolours by a lookup a pixel (recolor). Rasterization is watertight:
// vertices are snapped to fixed point (8 subpixel bits), pixels are sampled at their centres with a
// top-left fill rule, so two faces sharing an edge cover each pixel once and a shared face covers the
// same pixels from either side. No anti-aliasing. Perspective faces are clipped against a near plane
// (eyes inside the mesh); tets entirely behind it are skipped. Drawing uses several threads over
// interleaved bands of rows; each thread draws every tet in order, so the per-pixel order is kept.
// The painter walks each draw() batch front to back (reverse order) and writes only pixels not yet
// written in that batch, which is pixel for pixel the same picture as drawing back to front, but
// tets hidden behind what is already drawn cost only a test of a written-pixel mask.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"

namespace foxi {

struct FieldPaint;

struct RenderParams {
  bool depth_buffer = false;    // depth-buffer mode (the framebuffer must have a depth buffer)
  double shrink = 1;            // each tet scaled about its centroid by this factor, in (0, 1]
  bool edges = true;            // darken pixels within edge_width of a face's edges
  double edge_width = 1.0;      // pixels
  double edge_darkness = 0.65;  // 0 = invisible edges, 1 = black at the edge
  double ambient = 0.3;         // Lambert: ambient + (1 - ambient) max(0, n . light)
  double near = 0;              // perspective near-plane distance (world); 0 = automatic (tiny)
  int threads = 2;              // threads drawing interleaved bands of rows (1 or more)
  // Colour of region id r (opaque RGBA, pack_rgba) at region_colors[r] where r is in range; other
  // regions take region_color(r).
  std::vector<std::uint32_t> region_colors;
  bool undoable = false;  // painter only: record what undraw() needs (see TetRasterizer::undraw)
  // Colour by a field instead of by region (field_paint.hpp; shared, not copied: a graded paint of 1M
  // tets is 16 MB): flat, each tet's colour; graded, each face's colour interpolated per pixel from
  // its corners' positions on the scale. Lambert shading then scales the colour within
  // [shade_min, 1] (FieldPaint) instead of [ambient, 1]. Undraw repaints a face with its own tet's
  // corner positions; the vector repaint (AVX-512) is flat only, so graded undraw takes the portable one.
  std::shared_ptr<const FieldPaint> field;
};

// The colour of region `id` in the fixed palette (opaque RGBA, see pack_rgba).
FOXI_API std::uint32_t region_color(std::int32_t id);

// A rectangle of pixels, bounds included; empty when x0 > x1.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
};

struct RasterStats {
  std::size_t tets_drawn = 0;     // tets handed to draw() (skipped ones included)
  std::size_t tets_behind = 0;    // tets entirely behind the near plane
  std::size_t faces_clipped = 0;  // front faces cut by the near plane
};

// Per-frame state: the camera's projection of the mesh for one image size. The mesh is lent and must
// outlive it. Throws std::invalid_argument for a degenerate camera or bad parameters, and for an
// orthographic camera zoomed in so far that coordinates leave the fixed-point range.
class FOXI_API TetRasterizer {
 public:
  TetRasterizer(const MeshView& mesh, const Camera& camera, int width, int height,
                const RenderParams& params = {});
  ~TetRasterizer();
  TetRasterizer(TetRasterizer&&) noexcept;
  TetRasterizer& operator=(TetRasterizer&&) noexcept;

  // Draws `tets` in the given order (painter: later overwrites earlier; depth mode: nearest wins)
  // into fb, which must be width x height (with a depth buffer in depth mode). Can be called again
  // with the next batch of an order (progressive drawing). Tet indices must be < tet_count.
  void draw(Framebuffer& fb, std::span<const std::uint32_t> tets);
  // draw() with the colours written in place into a host's image instead of fb.rgba: row y of the
  // image at rows + y row_pixels (row_pixels >= width; the pixels past a row's width are never
  // written), pixels as pack_rgba makes them. fb keeps the id, shade (and depth) buffers, which must
  // be width x height, and fb.rgba is left as it is (it may be empty). Not undoable (std::logic_error:
  // undraw reads the colours back from fb).
  void draw_into(Framebuffer& fb, std::span<const std::uint32_t> tets, std::uint32_t* rows,
                 std::size_t row_pixels);

  // Undoable mode (RenderParams::undoable; the seed paper's undrawing, section 6.2). draw() keeps the tets
  // drawn so far (each tet at most once, else std::invalid_argument) and saves, for each tet with a back
  // face not shared with an earlier-drawn tet (mesh boundary, subset boundary, shrunk tets), the pixels that
  // face covers as they were just before the tet was drawn. It walks each batch front to back like the
  // painter (on its threads, each keeping the saved pixels of its own bands of rows), the saved values being
  // filled in by the farther tets met later in the walk. undraw(fb, k) takes back the last k drawn tets:
  // each tet's back faces are repainted as the earlier neighbour's front face, or restored from its saved
  // pixels (all of them for a tet the near plane cuts, and those within 2/256 pixel of a face seen
  // exactly edge on, where a tet drawn between the two can cover the shared face after snapping); the k tets
  // are walked back to front writing each pixel once (the farthest undrawn tet over a pixel decides it), each
  // thread in its own range of rows (batches of 256 tets or more), skipping by their pixel boxes (kept from
  // drawing) the tets hidden behind farther undrawn ones, and reading the mesh only for the others, a few
  // tets ahead; more than 2^16 tets go in parts of 2^16 (last first). For a visibility order, fb (colours and
  // ids) is then pixel for pixel the picture of the remaining tets drawn from scratch; fb must not be changed
  // in between. Cost is proportional to the undrawn tets and their pixels, not to the mesh. Throws
  // std::logic_error if not undoable, std::out_of_range if k exceeds the tets drawn. Undoable images are at
  // most 32767 pixels wide and high (else the constructor throws std::invalid_argument).
  void undraw(Framebuffer& fb, std::size_t count);
  std::span<const std::uint32_t> drawn_tets() const;  // undoable: the tets drawn, in order
  std::size_t saved_pixels() const;                   // undoable: pixels held for undraw
  std::size_t undo_bytes() const;  // undoable: memory held for undraw (bytes; saved pixels 13 each,
                                   // 14 per drawn tet (its index, pixel box and repaint reach), 4 and a bit
                                   // per mesh tet, per-image buffers of 13 bytes and 2 bits a pixel)
  // Holds every pixel the last draw() or undraw() call changed (a display need present only these;
  // empty before the first call and after an empty one): the union of the pixel boxes of the tets it
  // drew or undrew, the whole image if the near plane cuts one of them.
  PixelRect changed_rect() const;
  // The same more tightly: disjoint rectangles in row order, inside changed_rect(), whose union holds
  // every pixel the last call changed (a display may update just these). After undraw(), per band of
  // 16 rows the x-extent of the undrawn tets' pixel boxes there (about 60% of changed_rect's area
  // for 1% steps of a 1M-tet view); after draw(), changed_rect() alone; none when it is empty.
  std::span<const PixelRect> changed_rects() const;
  // Undoable: forgets the tets drawn (call after clearing fb to start a new picture).
  void forget_drawn();

  // Recolours the picture in fb by another field paint (null: region colours) without drawing it
  // again. fb is then pixel for pixel what drawing the same tets with `field` gives (fb must be this
  // rasterizer's picture, ids and shades unchanged since). Two ways (recolors_by_shade says which):
  // flat colours (a flat paint, or region colours) in the shading band of the current paint (its
  // shade_min, or params.ambient for region colours) go through the shade buffer (Framebuffer::shade),
  // one lookup a pixel (~5 ms at 1920x1080); undoable, the pixels saved for undraw are recoloured
  // too, so undraw then gives the remaining tets in the new colours. Otherwise (graded facets,
  // another band) the tets the id buffer shows are found, and each one's front faces are rasterized
  // anew in the new colours, writing only the pixels whose id is that tet: a pass over the ids plus
  // the shown tets and their pixels, not the mesh; the pixels saved for undraw keep the old colours.
  // Later draw() calls use the new paint. Throws std::invalid_argument for a paint of another mesh
  // (the old paint is kept) or a framebuffer of another size.
  void recolor(Framebuffer& fb, std::shared_ptr<const FieldPaint> field);
  // Whether recolor(fb, field) takes the shade buffer's way (given fb has a shade buffer).
  bool recolors_by_shade(const FieldPaint* field) const;

  const RasterStats& stats() const;
  const Projector& projector() const;
  double near_plane() const;  // the near-plane distance in use (perspective)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A convenience: a fresh framebuffer (background white) with `tets` drawn in order.
FOXI_API Framebuffer render_tets(const MeshView& mesh, const Camera& camera, int width, int height,
                                 std::span<const std::uint32_t> tets, const RenderParams& params = {});

// The pixels covered by one triangle under the rasterizer's fill rule (for tests): vertices in
// fixed point (pixel coordinate * 256, rounded), either winding; returns y * width + x of every
// covered pixel of the width x height image, in row order. A zero-area triangle covers nothing.
FOXI_API std::vector<std::uint32_t> triangle_coverage(const std::int64_t x[3], const std::int64_t y[3],
                                                      int width, int height);

}  // namespace foxi
