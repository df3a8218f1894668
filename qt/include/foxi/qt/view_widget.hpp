// foxi::qt: a QWidget showing a tet mesh drawn by the painter (foxi::InteractiveView,
// viz/interactive_view.hpp) progressively, in time slices from a QTimer so that the GUI thread never
// stalls: a draw runs batch by batch, each slice a few milliseconds, and the widget repaints only
// the damaged rectangles. Mouse: left-drag orbits, middle-drag (or shift + left) pans, right-drag or
// the wheel zooms; each move restarts the draw from the back. Draw / Stop / Step / Undraw as slots,
// and a target fraction (a slider): the picture follows it both ways, drawing or undrawing (the
// seed paper's interaction). The safe-picture rule holds (picture.hpp): a mesh that fails the
// Delaunay certificate is drawn in MPVO order with the depth buffer and cannot undraw (the widget
// then redraws up to a lower fraction instead).
#pragma once

#include <QString>
#include <QWidget>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/viz/field_selection.hpp"
#include "foxi/viz/translucent.hpp"

namespace foxi {
struct Mesh;
struct Camera;
struct RenderParams;
class InteractiveView;
}  // namespace foxi

namespace foxi::qt {

// The view of `mesh` for a width x height widget, with `camera`, or when null foxi render's default
// camera for the mesh's bounds (view_options.hpp): what set_mesh builds. Safe on any thread (a host
// builds it on a worker for a large mesh and hands it to ViewWidget::set_view).
FOXI_API std::unique_ptr<InteractiveView> make_view(const Mesh& mesh, const RenderParams& params, int width,
                                                    int height, const Camera* camera = nullptr);

class FOXI_API ViewWidget : public QWidget {
  Q_OBJECT

 public:
  explicit ViewWidget(QWidget* parent = nullptr);
  ~ViewWidget() override;

  // Shows `mesh` (kept alive while shown) with `params`: builds the view (the Delaunay certificate
  // and the sphere table: O(n log n), so a host with a large mesh builds the view on a worker
  // thread with make_view and hands it to set_view). keep_camera: the current camera stays (a
  // remesh of the same model); otherwise the default camera for the mesh's bounds, as foxi render's.
  void set_mesh(std::shared_ptr<const Mesh> mesh, const RenderParams& params, bool keep_camera = false);
  // A view built elsewhere (any thread) for `mesh`, which it must be the view of; starts drawing.
  void set_view(std::shared_ptr<const Mesh> mesh, std::unique_ptr<InteractiveView> view);
  // Forgets the mesh (a blank widget).
  void clear();

  bool has_view() const;
  InteractiveView* view();
  const InteractiveView* view() const;
  std::shared_ptr<const Mesh> mesh() const;
  // The current camera, or null without a view.
  const Camera* camera() const;

  // Values per tet shown under the mouse pointer (the tet's value as its colour shows it), with
  // their unit; empty: the region and tet only.
  void set_probe_values(std::vector<double> tet_values, QString unit);
  // The text for the tet at framebuffer pixel (x, y) (device pixels: the widget's pixels times its
  // devicePixelRatio, 1 but on high-DPI screens): "tet 12, region die, 45.2 °C" (empty: background).
  QString probe_text(int x, int y) const;

  // The field tools (isosurface, threshold, clip) select by `choice` at `step`, its isosurfaces
  // coloured on `scale`; `cache` is make_iso_cache's for them (O(n log n): a host builds it on a
  // worker). Lifts the current selection. The view must show the mesh the choice belongs to.
  // volume_scale: the volume's colours and default opacity curve (default: `scale`).
  void set_field_source(FieldChoice choice, std::size_t step, ColorScale scale,
                        std::shared_ptr<IsoCache> cache,
                        std::optional<ColorScale> volume_scale = std::nullopt);
  // Draws what `selection` selects (field_selection.hpp, the rule of foxi render's --iso, --iso-only,
  // --threshold, --clip and --slice: the same picture for the same camera), redrawn from the back; an
  // empty selection draws all tets again. Costs the interval tree's query and, for a threshold, clip
  // or slice, a pass over the tets. With the x-ray on, isovalues are drawn as translucent
  // isosurfaces inside the translucent regions (foxi render --region-opacity ... --iso v,...
  // --iso-opacity 0.5). False (nothing changes) with the reason in `error`: no view or no field
  // source, a clip or slice plane with a zero normal, a slice with isovalues, what foxi render does
  // not draw either: a threshold, clip or slice with the x-ray, any selection with the volume.
  bool set_selection(const FieldSelection& selection, QString* error = nullptr);
  const FieldSelection& selection() const;
  // The tets shown without a selection and that a selection narrows: those of the regions shown
  // (foxi render --regions); empty: all. Redraws from the back; kept until the next view.
  void set_base(std::vector<std::uint32_t> tets);
  // The tets the current selection draws (0 for none), or the whole mesh's count without one.
  std::size_t selected_tets() const;
  // Translucency and volume rendering (issue 23; InteractiveView::set_translucent, set_volume),
  // composited exactly in the power order and undoable: the "x-ray" (every region translucent but the
  // one with the fewest tets: default_xray), or a volume rendering of the field source's field on its
  // scale (default_volume); off: opaque tets again. One at a time: turning one on turns the other
  // off. Both draw the regions shown (set_base) within the region of interest, as foxi render
  // --regions does with --region-opacity or --volume. The x-ray stays across new views (a recolour,
  // a remesh); the volume follows the next field source after a new view (set_field_source), and is
  // off while there is none. composite_changed says each change of what is drawn. False (nothing
  // changes) with the reason in `error`: no view; for the volume no field source or a selection; for
  // the x-ray a threshold, clip or slice (foxi render does not combine them either).
  bool set_xray(bool on, QString* error = nullptr);
  bool set_volume(bool on, QString* error = nullptr);
  bool xray() const;
  bool volume() const;
  // The x-ray's parameters as drawn now (default_xray's opacities; the selection's isosurfaces at
  // opacity 0.5), or null when the x-ray is off: what foxi render --region-opacity draws the same from.
  const TranslucentParams* xray_params() const;

  // Milliseconds of painter work per timer slice (default 8).
  void set_time_slice(std::chrono::milliseconds slice);

  // The fraction of the displayed set drawn, in [0, 1].
  double fraction_drawn() const;
  // "drawn 1234 / 5000 tets (24.7%), 12.3 ms, 0.8 ms/frame, ... | power order, Delaunay certified".
  QString status_text() const;
  // The view's framebuffer as a PNG (exactly what foxi render draws for the same mesh, paint and
  // camera); false with the reason in `error`.
  bool save_picture(const QString& path, QString* error = nullptr) const;
  // The camera as foxi render options (--eye ... --at ... --up ... --fov ...), exact.
  std::string camera_options() const;
  // Whether the painter still has work (drawing, undrawing or following a fraction).
  bool busy() const;

 public slots:
  void draw();        // a new draw from the back
  void stop();        // pause (the picture stays)
  void resume();      // go on drawing (or undrawing)
  void step_once();   // one batch, then paused
  void undraw();      // undraw front to back (again: draw on)
  void finish_now();  // draw all that is left, at once (blocking: for scripts and tests)
  // The picture follows the fraction `f` of the displayed set: draws on or undraws to it.
  void set_fraction(double f);
  // The drawn tets become the displayed set, camera re-framed on them. False (nothing changes) with
  // the reason in `error`: nothing drawn, or the x-ray on (its drawn tets are the surfaces' owners,
  // not a part of the volume: push the region with the x-ray off; the x-ray then shows it).
  bool push_region(QString* error = nullptr);
  bool pop_region();

 signals:
  void status_changed(const QString& text);
  void probe_changed(const QString& text);
  void fraction_changed(double fraction);
  void draw_finished();
  // What is drawn changed between opaque, x-ray and volume (a host's check boxes follow it).
  void composite_changed(bool xray, bool volume);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void resizeEvent(QResizeEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

 private:
  // A length in the widget's pixels as device pixels (at least 1): the framebuffer is drawn at the
  // screen's own resolution on high-DPI screens, not scaled up.
  int device(int logical) const;
  void tick();
  void kick();  // the timer on, if there is work
  void present();
  // Puts the widget's state on the view: the selection, or the x-ray or volume over the base; says a
  // change of the composite state. False with the reason when the painter refuses (state kept).
  bool apply(QString* error);
  // The x-ray and volume flags set and applied (set_xray, set_volume: after their own checks); on a
  // refusal the old flags come back.
  bool set_composite(bool xray, bool volume, QString* error);
  void say_composite();  // composite_changed, when what is drawn differs from what it last said
  struct Impl;
  std::unique_ptr<Impl> d_;
};

}  // namespace foxi::qt
