// The safe picture (picture.hpp): the certificate picks the order method and the drawing mode.
#include "foxi/viz/picture.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "foxi/viz/depth_stop.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi {

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

std::vector<std::uint32_t> safe_order(const MeshView& mesh, const SphereTable& table, const View& view,
                                      std::span<const std::uint32_t> subset, OrderMethod* method,
                                      std::size_t* cycles) {
  const OrderMethod use = safe_order_method(delaunay_certificate(mesh));
  if (method) *method = use;
  if (use == OrderMethod::power) {
    if (cycles) *cycles = 0;
    return visibility_order(mesh, table, view, subset);
  }
  std::size_t broken = 0;
  std::vector<std::uint32_t> order = mpvo_order(mesh, table, view, subset, &broken);
  if (cycles) *cycles = broken;
  return order;
}

namespace {

// Sizes fb's id, shade (and depth) buffers for a picture whose colours go to a host's image: as
// Framebuffer::resize, less the colours (fb.rgba is emptied, its memory kept).
void resize_without_colours(Framebuffer& fb, bool with_depth) {
  const std::size_t n = std::size_t(fb.width) * std::size_t(fb.height);
  detail::reserve_advised(fb.id, n);
  detail::reserve_advised(fb.shade, n);
  fb.rgba.clear();
  fb.id.assign(n, kNone);
  fb.shade.assign(n, 0);
  if (with_depth) {
    fb.depth.assign(n, -std::numeric_limits<double>::infinity());
    fb.depth_slope.assign(2 * n, 0.0);
  } else {
    fb.depth.clear();
    fb.depth_slope.clear();
  }
}

// draw_picture into fb, or, with `rows` (row_pixels apart), with the tet painter's colours drawn in
// place there (the rows cleared to white first; fb then holds no colours).
PictureReport draw_picture_at(const MeshView& mesh, const SphereTable& table, const Camera& camera,
                              Framebuffer& fb, const PictureParams& params, std::uint32_t* rows,
                              std::size_t row_pixels) {
  if (!(params.stop_fraction >= 0 && params.stop_fraction <= 1))
    throw std::invalid_argument("draw_picture: the stop fraction must lie in [0, 1]");
  if (std::isnan(params.stop_depth)) throw std::invalid_argument("draw_picture: the stop depth is NaN");
  if (fb.width < 1 || fb.height < 1) throw std::invalid_argument("draw_picture: the framebuffer is empty");
  if (table.tet_count() != mesh.tet_count())
    throw std::invalid_argument("draw_picture: the sphere table belongs to another mesh");
  PictureReport report;
  auto t0 = std::chrono::steady_clock::now();
  report.delaunay = delaunay_certificate(mesh).delaunay;  // cached on the mesh after the first call
  report.certificate_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  const bool none = params.subset_exact && params.subset.empty();
  const std::vector<std::uint32_t> order =
      none ? std::vector<std::uint32_t>()
           : safe_order(mesh, table, view_of(camera), params.subset, &report.method, &report.cycles_broken);
  report.order_ms = ms_since(t0);
  report.tets_ordered = order.size();
  std::size_t count =
      std::min(order.size(), std::size_t(std::floor(params.stop_fraction * double(order.size()) + 1e-9)));
  if (params.stop_depth > -std::numeric_limits<double>::infinity())
    count = std::min(count, count_deeper(table, camera, order, params.stop_depth));
  report.tets_drawn = count;
  report.last_drawn = count > 0 ? order[count - 1] : kNone;

  RenderParams rp = params.render;
  rp.undoable = false;
  // Without the certificate the power order may put a tet behind one it hides: only the depth
  // buffer makes such a picture right.
  rp.depth_buffer = params.render.depth_buffer || !report.delaunay;
  report.depth_buffer = rp.depth_buffer;
  t0 = std::chrono::steady_clock::now();
  if (rows != nullptr) {
    resize_without_colours(fb, rp.depth_buffer);
    for (int y = 0; y < fb.height; ++y)
      std::fill_n(rows + std::size_t(y) * row_pixels, fb.width, pack_rgba(255, 255, 255));
  } else {
    fb.resize(fb.width, fb.height, rp.depth_buffer);
  }
  if (params.iso != nullptr) {  // each tet's iso polygons (or slice) at its place in the order
    IsoPainter painter(mesh, camera, fb.width, fb.height, params.iso->corner, params.iso->params, rp,
                       params.iso->attr);
    painter.draw(fb, std::span<const std::uint32_t>(order).first(count));
  } else {
    TetRasterizer raster(mesh, camera, fb.width, fb.height, rp);
    const auto tets = std::span<const std::uint32_t>(order).first(count);
    if (rows != nullptr)
      raster.draw_into(fb, tets, rows, row_pixels);
    else
      raster.draw(fb, tets);
    report.raster = raster.stats();
  }
  report.draw_ms = ms_since(t0);
  return report;
}

}  // namespace

PictureReport draw_picture(const MeshView& mesh, const SphereTable& table, const Camera& camera,
                           Framebuffer& fb, const PictureParams& params) {
  return draw_picture_at(mesh, table, camera, fb, params, nullptr, 0);
}

void copy_rgba(const Framebuffer& fb, const RgbaImage& image) {
  if (image.pixels == nullptr) throw std::invalid_argument("copy_rgba: the image has no pixels");
  if (image.width != fb.width || image.height != fb.height)
    throw std::invalid_argument("copy_rgba: the image is " + std::to_string(image.width) + " x " +
                                std::to_string(image.height) + ", the framebuffer " +
                                std::to_string(fb.width) + " x " + std::to_string(fb.height));
  if (image.stride < 4 * std::size_t(image.width))
    throw std::invalid_argument("copy_rgba: a stride of " + std::to_string(image.stride) +
                                " bytes is below 4 x the width " + std::to_string(image.width));
  const std::size_t row = std::size_t(fb.width);
  for (int y = 0; y < fb.height; ++y) {
    const std::uint32_t* from = fb.rgba.data() + std::size_t(y) * row;
    std::uint8_t* to = image.pixels + std::size_t(y) * image.stride;
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(to, from, row * 4);  // pack_rgba's R in the low byte: R, G, B, A in memory
    } else {
      for (std::size_t x = 0; x < row; ++x)
        for (int k = 0; k < 4; ++k) to[4 * x + std::size_t(k)] = std::uint8_t(from[x] >> (8 * k));
    }
  }
}

PictureReport draw_picture(const MeshView& mesh, const SphereTable& table, const Camera& camera,
                           const RgbaImage& image, Framebuffer& scratch, const PictureParams& params) {
  if (image.pixels == nullptr || image.width < 1 || image.height < 1)
    throw std::invalid_argument("draw_picture: the image is empty");
  if (image.stride < 4 * std::size_t(image.width))
    throw std::invalid_argument("draw_picture: a stride of " + std::to_string(image.stride) +
                                " bytes is below 4 x the width " + std::to_string(image.width));
  scratch.width = image.width;  // draw_picture sizes the buffers to these
  scratch.height = image.height;
  // In place where a row is whole uint32 pixels in pack_rgba's byte order (little-endian, the image
  // and its stride 4-byte aligned) and the tet painter draws; else drawn in scratch and copied.
  const bool in_place = std::endian::native == std::endian::little && params.iso == nullptr &&
                        image.stride % 4 == 0 &&
                        reinterpret_cast<std::uintptr_t>(image.pixels) % alignof(std::uint32_t) == 0;
  if (in_place)
    return draw_picture_at(mesh, table, camera, scratch, params,
                           reinterpret_cast<std::uint32_t*>(image.pixels), image.stride / 4);
  const PictureReport report = draw_picture(mesh, table, camera, scratch, params);
  copy_rgba(scratch, image);
  return report;
}

}  // namespace foxi
