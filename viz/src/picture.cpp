// The safe picture (picture.hpp): the certificate picks the order method and the drawing mode.
#include "foxi/viz/picture.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "foxi/viz/depth_stop.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi {

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

std::vector<std::uint32_t> safe_order(const Mesh& mesh, const SphereTable& table, const View& view,
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

PictureReport draw_picture(const Mesh& mesh, const SphereTable& table, const Camera& camera, Framebuffer& fb,
                           const PictureParams& params) {
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
  fb.resize(fb.width, fb.height, rp.depth_buffer);
  if (params.iso != nullptr) {  // each tet's iso polygons (or slice) at its place in the order
    IsoPainter painter(mesh, camera, fb.width, fb.height, params.iso->corner, params.iso->params, rp,
                       params.iso->attr);
    painter.draw(fb, std::span<const std::uint32_t>(order).first(count));
  } else {
    TetRasterizer raster(mesh, camera, fb.width, fb.height, rp);
    raster.draw(fb, std::span<const std::uint32_t>(order).first(count));
    report.raster = raster.stats();
  }
  report.draw_ms = ms_since(t0);
  return report;
}

}  // namespace foxi
