// One safe picture of a mesh in one call: the rule "a mesh that passes the Delaunay certificate is
// drawn by the painter in the power order (no depth buffer, seed paper Theorem 1); any other mesh has
// no guaranteed visibility order and is drawn in MPVO order with the depth buffer" lives here, so the
// CLI, the viewer and a host program draw alike. The MPVO order still puts the far part first, so a
// stop takes the far part of an uncertified mesh too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/view.hpp"

namespace foxi {

struct IsoDrawing;  // isosurface.hpp

// How a back-to-front order was made.
enum class OrderMethod : std::uint8_t {
  power,  // the power-function visibility order (a visibility order for a certified mesh)
  mpvo,   // MPVO's face-adjacency sort seeded by the power order (cycles broken, reported)
};

// The order method a mesh with this certificate is drawn with: power when it is Delaunay (or
// regular), MPVO otherwise.
inline OrderMethod safe_order_method(const DelaunayCertificate& cert) {
  return cert.delaunay ? OrderMethod::power : OrderMethod::mpvo;
}

// The back-to-front order of `subset` (empty: all tets) seen from `view` by the method the mesh's
// (cached) certificate calls for; the method used and the MPVO cycles broken are stored where asked.
FOXI_API std::vector<std::uint32_t> safe_order(const MeshView& mesh, const SphereTable& table,
                                               const View& view, std::span<const std::uint32_t> subset = {},
                                               OrderMethod* method = nullptr, std::size_t* cycles = nullptr);

struct PictureParams {
  // Colours, edges, shrink, field, threads. render.depth_buffer = true asks for the depth buffer
  // on a certified mesh too (the oracle); an uncertified mesh always gets it. undoable is ignored.
  RenderParams render;
  std::span<const std::uint32_t> subset;  // tets to draw (each at most once); empty: all
  // The subset is the selection even when empty: an empty one then orders and draws nothing (a
  // threshold or an isovalue that selects no tet).
  bool subset_exact = false;
  // Iso polygons or a slice (isosurface.hpp) instead of whole tets: the ordered tets are handed to an
  // IsoPainter with these inputs (lent, must outlive the call); null: the tet painter.
  const IsoDrawing* iso = nullptr;
  // Draw only the first floor(stop_fraction n + 1e-9) tets of the back-to-front order of n tets, in [0, 1].
  double stop_fraction = 1;
  // And stop before the first tet whose depth (depth_stop.hpp) is below this; -infinity: no depth stop.
  double stop_depth = -std::numeric_limits<double>::infinity();
};

struct PictureReport {
  bool delaunay = false;  // the mesh passed the certificate
  OrderMethod method = OrderMethod::power;
  bool depth_buffer = false;         // drawn with the depth buffer (uncertified, or asked for)
  std::size_t tets_ordered = 0;      // the tets selected (the subset, or all)
  std::size_t tets_drawn = 0;        // the prefix of the order drawn (after the stops)
  std::size_t cycles_broken = 0;     // MPVO only
  std::uint32_t last_drawn = kNone;  // the last tet drawn (the nearest), kNone if none
  RasterStats raster;                // tets behind the eye, faces clipped
  double certificate_ms = 0;         // 0 when the mesh's certificate was already cached
  double order_ms = 0, draw_ms = 0;
};

// Draws the picture into fb: fb keeps its width and height (both >= 1) and is cleared to white, with a
// depth buffer exactly when the depth buffer is used. Throws std::invalid_argument for a stop
// fraction outside [0, 1], a NaN stop depth, an empty framebuffer, a table of another mesh, and what
// TetRasterizer throws (degenerate camera).
FOXI_API PictureReport draw_picture(const MeshView& mesh, const SphereTable& table, const Camera& camera,
                                    Framebuffer& fb, const PictureParams& params = {});

// A host's own RGBA8 image (a window's back buffer, a texture upload buffer): row 0 (the top) at
// `pixels`, rows `stride` bytes apart (stride >= 4 * width; the bytes past a row's 4 * width are the
// host's padding and are never written), each pixel 4 bytes R, G, B, A. Lent.
struct RgbaImage {
  std::uint8_t* pixels = nullptr;
  int width = 0, height = 0;
  std::size_t stride = 0;  // bytes
};

// Copies fb's colours into `image` (the same width and height), row by row. Throws
// std::invalid_argument for a null image, other sizes, or a stride below 4 * width.
FOXI_API void copy_rgba(const Framebuffer& fb, const RgbaImage& image);

// draw_picture into a host's image. `scratch` is a framebuffer the host keeps (its memory is reused
// from one picture to the next): it is resized to the image and its id buffer then says which tet
// each pixel shows, for picking. The tet painter writes its colours in place, straight into the
// image's rows (one multiply a row: TetRasterizer::draw_into), when the image's rows are whole
// uint32 pixels: `pixels` and `stride` multiples of 4 bytes (on a little-endian machine, where
// pack_rgba's pixels are R, G, B, A in memory); scratch.rgba is then left empty. Otherwise, and for
// an isosurface or slice (params.iso: the IsoPainter draws into a framebuffer only), the picture is
// drawn into scratch and its colours copied into the image (copy_rgba, one pass over the pixels).
// In place saves that pass and 4 bytes a pixel of scratch memory, and costs the painter nothing
// measurable although the host's rows get no large-page advice: the painter with its colours into a
// 1920x1080 host image, 0.97M tets, 24 views, median CPU 243.5 ms in place against 243.1 ms drawn
// and copied (2-core machine under load; bench_render's picture_into_image gives the same within its
// noise). Throws as both.
FOXI_API PictureReport draw_picture(const MeshView& mesh, const SphereTable& table, const Camera& camera,
                                    const RgbaImage& image, Framebuffer& scratch,
                                    const PictureParams& params = {});

}  // namespace foxi
