// foxi::qt::ViewWidget: see view_widget.hpp.
#include "foxi/qt/view_widget.hpp"

#include <QImage>
#include <QMouseEvent>
#include <QPaintEvent>
#include <QPainter>
#include <QTimer>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <optional>
#include <utility>

#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/interactive_view.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/view_options.hpp"

namespace foxi::qt {

struct ViewWidget::Impl {
  std::shared_ptr<const Mesh> mesh;
  std::unique_ptr<InteractiveView> view;
  QTimer timer;
  std::chrono::milliseconds slice{8};
  bool camera_default = true;         // never moved by the user: re-fitted to a new aspect on resize
  std::optional<std::size_t> target;  // following a fraction: the tet count to reach
  std::vector<double> probe;
  QString probe_unit;
  QPoint last;  // the last mouse position of a drag
  // The field tools: the source they select by, the selection and what it resolved to (the view
  // borrows `drawing`'s spans, which borrow `picked`'s values: both live until the next selection).
  struct Source {
    FieldChoice choice;
    std::size_t step = 0;
    ColorScale scale;
    std::shared_ptr<IsoCache> cache;
    ColorScale volume_scale;
  };
  std::optional<Source> source;
  std::vector<std::uint32_t> base;  // the regions shown (empty: all)
  FieldSelection selection;
  std::unique_ptr<TetSelection> picked;
  std::unique_ptr<IsoDrawing> drawing;
  std::vector<double> volume_corner;  // lent to the view while it draws the volume
  // What is composited (a host's check boxes show it): at most one of the two.
  bool xray = false, volume = false;
  bool volume_pending = false;  // a new view: the volume comes back with the next field source
  bool shown_xray = false, shown_volume = false;  // as composite_changed last said
  TranslucentParams xray_params;                  // the x-ray as drawn (its iso corner values lent by picked)
  void reset_selection() {
    selection = {};
    drawing.reset();
    picked.reset();
  }
};

namespace {

// False, with the reason when the caller asks for it.
bool refuse(QString* error, const QString& why) {
  if (error) *error = why;
  return false;
}

// foxi render's camera for the mesh's bounds and this aspect (view_options.hpp: the same rule).
Camera default_camera(const Mesh& mesh, int width, int height) {
  double lo[3], hi[3];
  mesh_bounds(mesh, lo, hi);
  return camera_for(CameraOptions{}, lo, hi, double(width) / double(height));
}

}  // namespace

ViewWidget::ViewWidget(QWidget* parent) : QWidget(parent), d_(std::make_unique<Impl>()) {
  setMouseTracking(true);
  setMinimumSize(64, 48);
  setAttribute(Qt::WA_OpaquePaintEvent);
  setFocusPolicy(Qt::StrongFocus);
  // A zero-interval timer runs whenever the event loop is idle: one slice of painter work per
  // event-loop pass, so input and repaints are served between slices.
  d_->timer.setInterval(0);
  connect(&d_->timer, &QTimer::timeout, this, &ViewWidget::tick);
}

ViewWidget::~ViewWidget() = default;

int ViewWidget::device(int logical) const {
  return std::max(1, int(std::lround(logical * devicePixelRatioF())));
}

std::unique_ptr<InteractiveView> make_view(const Mesh& mesh, const RenderParams& params, int width,
                                           int height, const Camera* camera) {
  const int w = std::max(1, width), h = std::max(1, height);
  return std::make_unique<InteractiveView>(mesh, camera ? *camera : default_camera(mesh, w, h), w, h, params);
}

void ViewWidget::set_mesh(std::shared_ptr<const Mesh> mesh, const RenderParams& params, bool keep_camera) {
  const bool keep = keep_camera && d_->view;
  const Camera cam = keep ? d_->view->camera() : Camera{};
  auto view = make_view(*mesh, params, device(width()), device(height()), keep ? &cam : nullptr);
  if (!keep) d_->camera_default = true;
  set_view(std::move(mesh), std::move(view));
}

void ViewWidget::set_view(std::shared_ptr<const Mesh> mesh, std::unique_ptr<InteractiveView> view) {
  // The old view goes before the mesh it was lent (and the selection it borrowed).
  d_->view = std::move(view);
  d_->source.reset();
  d_->base.clear();
  d_->reset_selection();
  d_->mesh = std::move(mesh);
  d_->target.reset();
  d_->probe.clear();
  // The x-ray needs nothing but the mesh: it stays. The volume needs the new field source.
  d_->volume_pending = d_->volume;
  d_->volume = false;
  if (d_->view && (d_->view->framebuffer().width != device(width()) ||
                   d_->view->framebuffer().height != device(height())))
    d_->view->resize(device(width()), device(height()));
  // A new view draws all tets opaque already: only the x-ray has to be put on it (each set-up of the
  // view is a begin_draw on this thread, so none is spent for nothing).
  if (d_->view && d_->xray && !apply(nullptr)) {
    d_->xray = false;  // default opacities the painter refuses cannot happen; opaque then, said so
    apply(nullptr);
  }
  say_composite();
  draw();
}

void ViewWidget::clear() {
  d_->timer.stop();
  d_->view.reset();
  d_->source.reset();
  d_->base.clear();
  d_->reset_selection();
  d_->mesh.reset();
  d_->probe.clear();
  d_->xray = d_->volume = d_->volume_pending = false;
  if (d_->shown_xray || d_->shown_volume) {
    d_->shown_xray = d_->shown_volume = false;
    emit composite_changed(false, false);
  }
  update();
  emit status_changed(status_text());
}

bool ViewWidget::has_view() const { return d_->view != nullptr; }
InteractiveView* ViewWidget::view() { return d_->view.get(); }
const InteractiveView* ViewWidget::view() const { return d_->view.get(); }
std::shared_ptr<const Mesh> ViewWidget::mesh() const { return d_->mesh; }
const Camera* ViewWidget::camera() const { return d_->view ? &d_->view->camera() : nullptr; }

void ViewWidget::set_probe_values(std::vector<double> tet_values, QString unit) {
  d_->probe = std::move(tet_values);
  d_->probe_unit = std::move(unit);
}

QString ViewWidget::probe_text(int x, int y) const {
  if (!d_->view) return {};
  const std::uint32_t t = d_->view->pick(x, y);
  if (t == kNone) return {};
  const Mesh& m = *d_->mesh;
  QString text = QString("tet %1").arg(t);
  if (!m.tet_region.empty()) {
    const std::int32_t r = m.tet_region[t];
    QString name = QString::number(r);
    for (const Region& reg : m.regions)
      if (reg.id == r && !reg.name.empty()) name = QString::fromStdString(reg.name);
    text += ", region " + name;
  }
  if (t < d_->probe.size()) {
    const double v = d_->probe[t];
    text +=
        std::isfinite(v) ? QString(", %1 %2").arg(v, 0, 'g', 6).arg(d_->probe_unit) : QString(", no value");
  }
  return text;
}

void ViewWidget::set_field_source(FieldChoice choice, std::size_t step, ColorScale scale,
                                  std::shared_ptr<IsoCache> cache, std::optional<ColorScale> volume_scale) {
  const bool redraw = d_->selection.any() || d_->volume_pending || d_->volume;
  d_->reset_selection();
  d_->source = Impl::Source{std::move(choice), step, scale, std::move(cache), volume_scale.value_or(scale)};
  if (d_->volume_pending) d_->volume = true;
  d_->volume_pending = false;
  if (d_->view && redraw) {
    if (!apply(nullptr)) {
      d_->volume = false;
      apply(nullptr);
    }
    draw();
  }
}

bool ViewWidget::apply(QString* error) {
  InteractiveView& v = *d_->view;
  const std::optional<std::vector<std::uint32_t>> base =
      d_->base.empty() ? std::nullopt : std::optional(d_->base);
  try {
    if (d_->volume && d_->source) {
      // foxi render --volume's picture with default_volume's curve: the regions shown, the field alone.
      v.set_subset(base);
      std::vector<double> corner = tet_corner_values(*d_->mesh, d_->source->choice, d_->source->step);
      const VolumeParams vp = default_volume(*d_->mesh, d_->source->volume_scale, d_->base);
      v.set_volume(corner, &vp);
      d_->volume_corner = std::move(corner);  // the buffer moves with it: the view's span stays valid
    } else if (d_->xray) {
      // foxi render --region-opacity (default_xray's) [--regions] [--iso v,... --iso-opacity 0.5].
      v.set_subset(base);
      TranslucentParams tp;
      tp.region_opacity = default_xray(*d_->mesh);
      if (d_->picked && d_->picked->polygons && d_->picked->corner) {
        tp.corner = *d_->picked->corner;  // lent: picked lives until the next selection
        tp.iso = d_->picked->params;
        tp.iso_opacity = 0.5;
      }
      v.set_translucent(&tp);
      d_->xray_params = tp;
    } else if (d_->picked && d_->picked->polygons) {
      auto drawing = std::make_unique<IsoDrawing>(d_->picked->drawing());
      v.set_iso(drawing.get(), d_->picked->subset);
      d_->drawing = std::move(drawing);  // the view now borrows the new drawing: the old one may go
    } else {
      v.set_subset(d_->picked ? std::optional(d_->picked->subset) : base);
    }
  } catch (const std::exception& e) {
    if (error) *error = QString::fromStdString(e.what());
    return false;
  }
  if (!(d_->picked && d_->picked->polygons && !d_->xray)) d_->drawing.reset();
  say_composite();
  return true;
}

void ViewWidget::say_composite() {
  const bool x = d_->view && d_->xray && d_->view->translucent();
  const bool vol = d_->view && d_->volume && d_->view->volume();
  if (x != d_->shown_xray || vol != d_->shown_volume) {
    d_->shown_xray = x;
    d_->shown_volume = vol;
    emit composite_changed(x, vol);
  }
}

bool ViewWidget::set_selection(const FieldSelection& selection, QString* error) {
  if (!d_->view) return refuse(error, tr("no mesh shown"));
  std::unique_ptr<TetSelection> picked;
  if (selection.any()) {
    if (!d_->source)
      return refuse(error,
                    tr("colour by a field first: the isosurface, threshold, clip and slice select by it"));
    if (d_->volume)
      return refuse(
          error,
          tr("the volume rendering draws the field alone (foxi render --volume takes no --iso, --threshold, "
             "--clip or --slice): turn the volume off first"));
    if (d_->xray && (selection.threshold || selection.clip || selection.slice))
      return refuse(
          error,
          tr("the x-ray draws whole regions translucent, with isosurfaces inside (foxi render "
             "--region-opacity takes --iso, not --threshold, --clip or --slice): turn the x-ray off first"));
    try {
      const Impl::Source& s = *d_->source;
      picked = std::make_unique<TetSelection>(
          select_field_tets(selection, *d_->mesh, s.choice, s.step, s.scale, d_->base, s.cache.get()));
    } catch (const std::exception& e) {
      return refuse(error, QString::fromStdString(e.what()));
    }
  }
  // The old selection lives until the view has let go of it (apply), then goes.
  std::unique_ptr<TetSelection> old_picked = std::exchange(d_->picked, std::move(picked));
  std::unique_ptr<IsoDrawing> old_drawing = std::move(d_->drawing);
  const FieldSelection old_selection = std::exchange(d_->selection, selection);
  if (!apply(error)) {
    d_->picked = std::move(old_picked);
    d_->drawing = std::move(old_drawing);
    d_->selection = old_selection;
    apply(nullptr);
    return false;
  }
  draw();
  return true;
}

void ViewWidget::set_base(std::vector<std::uint32_t> tets) {
  d_->base = std::move(tets);
  if (!d_->view) return;
  const FieldSelection s = d_->selection;
  if (!set_selection(s)) set_selection({});
}

const FieldSelection& ViewWidget::selection() const { return d_->selection; }

bool ViewWidget::set_xray(bool on, QString* error) {
  if (!d_->view) return refuse(error, tr("no mesh shown"));
  const FieldSelection& s = d_->selection;
  if (on && (s.threshold || s.clip || s.slice))
    return refuse(
        error, tr("the x-ray draws whole regions translucent (foxi render --region-opacity takes --iso, not "
                  "--threshold, --clip or --slice): turn the threshold, clip and slice off first"));
  return set_composite(on, on ? false : d_->volume, error);
}

bool ViewWidget::set_volume(bool on, QString* error) {
  if (!d_->view) return refuse(error, tr("no mesh shown"));
  if (on && !d_->source) return refuse(error, tr("colour by a field first: the volume rendering shows it"));
  if (on && d_->selection.any())
    return refuse(
        error,
        tr("the volume rendering draws the field alone (foxi render --volume takes no --iso, --threshold, "
           "--clip or --slice): turn the isosurface, threshold, clip and slice off first"));
  return set_composite(on ? false : d_->xray, on, error);
}

bool ViewWidget::set_composite(bool xray, bool volume, QString* error) {
  const bool old_xray = d_->xray, old_volume = d_->volume;
  d_->xray = xray;
  d_->volume = volume;
  d_->volume_pending = false;
  if (!apply(error)) {
    d_->xray = old_xray;
    d_->volume = old_volume;
    apply(nullptr);
    return false;
  }
  draw();
  return true;
}

bool ViewWidget::xray() const { return d_->shown_xray; }
bool ViewWidget::volume() const { return d_->shown_volume; }
const TranslucentParams* ViewWidget::xray_params() const {
  return d_->shown_xray ? &d_->xray_params : nullptr;
}

std::size_t ViewWidget::selected_tets() const {
  if (d_->picked) return d_->picked->subset.size();
  if (!d_->base.empty()) return d_->base.size();
  return d_->mesh ? d_->mesh->tet_count() : 0;
}

void ViewWidget::set_time_slice(std::chrono::milliseconds slice) {
  d_->slice = std::max(slice, std::chrono::milliseconds(1));
}

double ViewWidget::fraction_drawn() const {
  if (!d_->view || d_->view->total() == 0) return 0;
  return double(d_->view->drawn().size()) / double(d_->view->total());
}

QString ViewWidget::status_text() const {
  if (!d_->view) return tr("no mesh");
  QString s = QString::fromStdString(d_->view->status());
  s += d_->view->delaunay() ? tr("  |  power order, Delaunay certified")
                            : tr("  |  MPVO order + depth buffer, certificate failed");
  return s;
}

bool ViewWidget::save_picture(const QString& path, QString* error) const {
  if (!d_->view) {
    if (error) *error = tr("no picture to save");
    return false;
  }
  try {
    d_->view->save_png(path.toStdString());
    return true;
  } catch (const std::exception& e) {
    if (error) *error = QString::fromStdString(e.what());
    return false;
  }
}

std::string ViewWidget::camera_options() const {
  return d_->view ? d_->view->camera_options() : std::string();
}

bool ViewWidget::busy() const { return d_->view && (d_->target || d_->view->running()); }

void ViewWidget::kick() {
  if (busy() && !d_->timer.isActive()) d_->timer.start();
}

void ViewWidget::draw() {
  if (!d_->view) return;
  d_->target.reset();
  d_->view->restart();
  d_->view->set_running(true);
  present();
  kick();
}

void ViewWidget::stop() {
  if (!d_->view) return;
  d_->target.reset();
  d_->view->set_running(false);
  d_->timer.stop();
  emit status_changed(status_text());
}

void ViewWidget::resume() {
  if (!d_->view) return;
  d_->view->set_running(true);
  kick();
}

void ViewWidget::step_once() {
  if (!d_->view) return;
  d_->target.reset();
  d_->view->set_running(false);
  d_->timer.stop();
  d_->view->step();
  present();
}

void ViewWidget::undraw() {
  if (!d_->view) return;
  d_->target.reset();
  if (!d_->view->set_undrawing(!d_->view->undrawing())) return;  // depth-buffer drawing: no undraw
  d_->view->set_running(true);
  kick();
  emit status_changed(status_text());
}

void ViewWidget::finish_now() {
  if (!d_->view) return;
  d_->target.reset();
  d_->view->set_undrawing(false);
  d_->view->finish();
  d_->timer.stop();
  present();
  emit draw_finished();
}

void ViewWidget::set_fraction(double f) {
  if (!d_->view) return;
  f = std::clamp(f, 0.0, 1.0);
  d_->target = std::size_t(std::llround(f * double(d_->view->total())));
  d_->view->set_running(false);
  kick();
}

bool ViewWidget::push_region(QString* error) {
  if (!d_->view) return false;
  if (d_->xray) {
    if (error)
      *error =
          tr("a region of interest is the far part of the opaque tets drawn: turn the x-ray off, draw (or "
             "undraw) to the part you want and press Region; the x-ray then shows that region");
    return false;
  }
  const std::vector<std::uint32_t> region = d_->view->drawn();  // what becomes the displayed set
  if (!d_->view->push_region()) {
    if (error) *error = tr("nothing drawn yet: draw the part that is to become the region first");
    return false;
  }
  // The camera re-framed on the region: the same direction and up, fitted to the region's bounds.
  double lo[3], hi[3];
  tets_bounds(*d_->mesh, region, lo, hi);
  const Camera& c = d_->view->camera();
  const double dir[3] = {c.at[0] - c.eye[0], c.at[1] - c.eye[1], c.at[2] - c.eye[2]};
  d_->camera_default = false;
  d_->view->set_camera(fit_camera(lo, hi, dir, c.up, c.perspective, c.fov_deg,
                                  double(std::max(1, width())) / double(std::max(1, height()))));
  draw();
  return true;
}

bool ViewWidget::pop_region() {
  if (!d_->view || !d_->view->pop_region()) return false;
  draw();
  return true;
}

void ViewWidget::tick() {
  InteractiveView* v = d_->view.get();
  if (!v) {
    d_->timer.stop();
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  if (d_->target) {
    const std::size_t goal = *d_->target;
    while (std::chrono::steady_clock::now() - start < d_->slice) {
      const std::size_t n = v->drawn().size();
      if (n < goal) {
        if (v->undrawing()) v->set_undrawing(false);
        if (v->done() && n == v->total()) break;
        if (!v->step()) {
          if (v->done()) break;
        }
        // A batch may overshoot the goal: take the excess back (painter only).
        if (v->drawn().size() > goal && v->set_undrawing(true)) {
          v->undraw(v->drawn().size() - goal);
          v->set_undrawing(false);
        }
      } else if (n > goal) {
        if (v->set_undrawing(true)) {
          v->undraw(std::min<std::size_t>(n - goal, std::max<std::size_t>(1, v->total() / 64)));
          v->set_undrawing(false);
        } else {
          // Depth-buffer drawing cannot take tets back: draw again from the back to the goal.
          v->restart();
          v->set_running(false);
        }
      } else {
        break;
      }
    }
    const std::size_t n = v->drawn().size();
    if (n == goal || (n < goal && v->done())) d_->target.reset();
  } else if (v->running()) {
    v->step(d_->slice);
  }
  present();
  if (!busy()) {
    d_->timer.stop();
    if (v->done() && !v->undrawing()) emit draw_finished();
  }
}

void ViewWidget::present() {
  if (!d_->view) return;
  const qreal ratio = devicePixelRatioF();
  for (const PixelRect& r : d_->view->take_damage()) {  // device pixels to the widget's (rounded out)
    const int x0 = int(std::floor(r.x0 / ratio)), y0 = int(std::floor(r.y0 / ratio));
    update(QRect(x0, y0, int(std::ceil((r.x1 + 1) / ratio)) - x0, int(std::ceil((r.y1 + 1) / ratio)) - y0));
  }
  emit status_changed(status_text());
  emit fraction_changed(fraction_drawn());
}

void ViewWidget::paintEvent(QPaintEvent* event) {
  QPainter p(this);
  if (!d_->view) {
    p.fillRect(event->rect(), Qt::white);
    return;
  }
  const Framebuffer& fb = d_->view->framebuffer();
  // pack_rgba is R, G, B, A in memory order: QImage's RGBA8888. No copy: the image wraps the pixels.
  const QImage image(reinterpret_cast<const uchar*>(fb.rgba.data()), fb.width, fb.height, fb.width * 4,
                     QImage::Format_RGBA8888);
  p.fillRect(event->rect(), Qt::white);
  // High-DPI: the framebuffer has the widget's device pixels, drawn 1:1 (not a scaled-up picture)
  const qreal ratio = devicePixelRatioF();
  const QRect r = event->rect();
  p.drawImage(QRectF(r), image, QRectF(r.x() * ratio, r.y() * ratio, r.width() * ratio, r.height() * ratio));
}

void ViewWidget::resizeEvent(QResizeEvent* event) {
  QWidget::resizeEvent(event);
  if (!d_->view) return;
  const int w = device(width()), h = device(height());
  d_->view->resize(w, h);
  if (d_->camera_default) d_->view->set_camera(default_camera(*d_->mesh, w, h));
  draw();
}

void ViewWidget::mousePressEvent(QMouseEvent* event) { d_->last = event->pos(); }

void ViewWidget::mouseMoveEvent(QMouseEvent* event) {
  if (!d_->view) return;
  if (event->buttons() == Qt::NoButton) {
    const qreal ratio = devicePixelRatioF();  // the framebuffer's pixels are device pixels
    emit probe_changed(probe_text(int(event->pos().x() * ratio), int(event->pos().y() * ratio)));
    return;
  }
  const QPoint delta = event->pos() - d_->last;
  d_->last = event->pos();
  if (delta.isNull()) return;
  const double h = std::max(1, height());
  d_->camera_default = false;
  if ((event->buttons() & Qt::MiddleButton) ||
      ((event->buttons() & Qt::LeftButton) && (event->modifiers() & Qt::ShiftModifier))) {
    d_->view->pan(-delta.x() / h, delta.y() / h);
  } else if (event->buttons() & Qt::LeftButton) {
    d_->view->orbit(-0.4 * delta.x(), -0.4 * delta.y());
  } else if (event->buttons() & Qt::RightButton) {
    d_->view->zoom(std::pow(1.01, -delta.y()));
  }
  d_->view->set_running(true);
  present();
  kick();
}

void ViewWidget::mouseReleaseEvent(QMouseEvent*) {}

void ViewWidget::wheelEvent(QWheelEvent* event) {
  if (!d_->view) return;
  d_->camera_default = false;
  d_->view->zoom(std::pow(1.1, event->angleDelta().y() / 120.0));
  d_->view->set_running(true);
  present();
  kick();
}

}  // namespace foxi::qt
