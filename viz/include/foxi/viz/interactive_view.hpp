// An interactive view of a tet mesh, without any window: the camera, the region-of-interest stack of
// tet subsets, the progressive visibility order of the displayed set and the framebuffer it is drawn
// into (seed paper, sections 6-7). A front end (foxi-view's X11 window and script mode, a Qt widget,
// a host's own window) feeds it events -- resize, orbit, zoom, pan, push or pop a region, stop,
// undraw, pick at a pixel -- calls step(budget) from its event loop while running() and presents the
// damage rectangles of the framebuffer. It owns no loop and no thread of its own beyond the
// progressive order's sorting thread.
//
// The safe-picture rule (picture.hpp) holds here too: a mesh that passes the Delaunay certificate
// is drawn by the painter in the progressive power order (and can undraw); any other mesh in MPVO
// order, in chunks, with the depth buffer.
//
// Translucent regions and isosurfaces (translucent.hpp) and volume rendering (volume.hpp) are drawn
// progressively the same way, composited back to front in the power order (a partial picture is the
// exact picture of the far part). Undraw there: compositing ("over") cannot be taken back in
// general (an opaque fragment forgets what lay behind it), so undrawing the front-most k tets of n
// composites the first n - k again from the back, in the same order: the picture is then exactly a
// fresh draw of n - k tets, pixel for pixel (the painters' results do not depend on how the order is
// cut into batches). To make the undraw steps cheap the view keeps the resolved picture after each
// batch of the first pass (within a memory budget): a step back shows the previous batch's picture,
// and drawing on after it composites the prefix again once. Without the Delaunay
// certificate translucency sorts each pixel's fragments by depth and volume rendering composites in
// MPVO order (not exact), and neither undraws; status() says which.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/isosurface.hpp"
#include "foxi/viz/movie.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/translucent.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "foxi/viz/volume.hpp"

namespace foxi {

// The x-ray a viewer starts from (foxi-view's key x, the workbench's X-ray): every region at opacity
// `opacity` but the one with the fewest tets (a die or a bump inside a package), which stays opaque;
// a mesh of one region: that region at `opacity`. Ascending region ids.
FOXI_API std::vector<RegionOpacity> default_xray(const Mesh& mesh, double opacity = 0.3);
// The volume rendering a viewer starts from: colours on `scale`, an opacity ramp from 0.02 at
// scale.lo to 0.5 at scale.hi (dense where the field is high), accumulated over a tenth of the
// diagonal of the box of `subset` (all tets when empty: foxi render --volume's default unit length).
FOXI_API VolumeParams default_volume(const Mesh& mesh, const ColorScale& scale,
                                     std::span<const std::uint32_t> subset = {});

// What a movie of a view draws, copied from it (InteractiveView::movie_input), so that a worker
// makes the movie while the view goes on: the camera, size and painter settings, the tets shown (the
// subset within the region of interest; empty: all) and what is composited, with its corner values.
struct ViewMovie {
  Camera camera;
  int width = 1, height = 1;
  RenderParams render;
  std::vector<std::uint32_t> subset;
  std::optional<TranslucentParams> translucent;  // its corner span is re-pointed at `corner`
  std::optional<VolumeParams> volume;
  std::vector<double> corner;  // the isosurfaces' (translucent) or the field's (volume), 4 per tet
};

// The movie of the view `movie` of `mesh` (the view's mesh) that foxi movie makes with the same
// camera, size and options: opaque tets by make_movie, translucency or a volume by
// make_composite_movie (`params.render` is taken from the view). Returns the frames written. Throws
// as those do (UncertifiedMeshError, MovieCancelled, std::invalid_argument).
FOXI_API std::size_t make_view_movie(const Mesh& mesh, const ViewMovie& movie, const MovieParams& params,
                                     const std::function<void(const Framebuffer&)>& frame,
                                     const ProgressFn& progress = {});

class FOXI_API InteractiveView {
 public:
  // The mesh is lent and must outlive the viewer. Computes the Delaunay certificate and the sphere
  // table once; nothing is drawn until restart(). params.undoable: the painter records what undraw
  // needs (false: cheaper drawing, and set_undrawing refuses).
  InteractiveView(const Mesh& mesh, const Camera& camera, int width, int height,
                  const RenderParams& params = {});
  ~InteractiveView();
  InteractiveView(const InteractiveView&) = delete;
  InteractiveView& operator=(const InteractiveView&) = delete;

  // 'd': a new draw of the displayed set from the back, for the current camera (picture cleared).
  void restart();
  // Draws the next batch of the order (undrawing: takes back the front-most chunk, 1/64 of the
  // displayed set); returns false (nothing changed) when there is nothing left to do that way.
  bool step();
  // Time-sliced work for a host's event loop: steps (draw or undraw batches) until `budget` is spent
  // or nothing is left; at least one step is taken. Returns whether the picture changed.
  bool step(std::chrono::steady_clock::duration budget);
  // Draws all remaining batches.
  void finish();
  bool done() const { return done_; }

  // Space: the front end keeps stepping while running.
  bool running() const { return running_ && (undrawing_ ? !drawn_.empty() : !done_); }
  void set_running(bool on) { running_ = on; }
  // 'u': undraw (front to back, the seed paper's undraw: each frame equals drawing fewer tets from
  // scratch) or, set to false, draw on again from where the undraw stopped. Returns false (nothing
  // changes) for meshes drawn with the depth buffer, which cannot undraw, or without undoable
  // (translucent and volume drawing need not record anything: they undraw on any certified mesh).
  bool set_undrawing(bool on);
  bool undrawing() const { return undrawing_; }
  // Undraws up to `count` tets at once (the script's u:N); returns how many.
  std::size_t undraw(std::size_t count);

  // 'r': the tets drawn so far become the displayed set (pushed on the stack), redrawn from the back.
  // Returns false (nothing changes) when no tet has been drawn, and with translucent drawing (its
  // drawn tets are the surfaces' owners, not a part of the volume).
  bool push_region();
  // 'b': back to the previous displayed set; false at the bottom (the whole mesh).
  bool pop_region();
  std::size_t region_depth() const { return stack_.size(); }

  // Camera moves; each restarts the draw.
  void orbit(double yaw_deg, double pitch_deg);
  void zoom(double factor);
  void pan(double dx, double dy);
  void set_camera(const Camera& camera);
  void resize(int width, int height);

  // The tet shown at pixel (x, y) (row 0 at the top), kNone for the background or outside the image.
  std::uint32_t pick(int x, int y) const;
  // The factor the tets are drawn shrunk by (RenderParams::shrink): pixel_point_in_tet takes it, so
  // that the point under a pixel is the true point, not where the ray meets the unshrunk tet.
  double shrink() const { return params_.shrink; }
  // The painter's settings (the field paint, colours, shrink): what a movie of this view draws with.
  const RenderParams& params() const { return params_; }
  // The tets drawn without the ones a camera hides: the whole-tet subset (set_subset) within the
  // region on top of the stack, sorted; empty: all tets (a movie's or a one-call picture's subset).
  // Not meaningful with iso drawing (its polygons are not whole tets).
  std::vector<std::uint32_t> shown_tets() const;
  // The view as a movie draws it (see ViewMovie). Throws std::invalid_argument with iso drawing (iso
  // polygons or a slice: foxi movie turns the camera around whole tets, translucency or a volume).
  ViewMovie movie_input() const;
  // Iso polygons instead of whole tets (isosurface.hpp; the isovalue's surfaces, or in cap mode the
  // solid above it): `drawing` the IsoPainter's inputs (lent with its spans: they must outlive the
  // view or the next set_iso), `tets` the tets it crosses (cap mode: reaches; TetIntervals gives
  // them), narrowed by the region stack. Null: whole tets again. Redraws from the back.
  void set_iso(const IsoDrawing* drawing, std::vector<std::uint32_t> tets);
  bool iso() const { return iso_ != nullptr; }
  // Whole tets, only `tets` (a threshold or clip: field_selection.hpp; empty: none drawn), narrowed by
  // the region stack; nullopt: all tets again. Ends iso drawing. Redraws from the back.
  void set_subset(std::optional<std::vector<std::uint32_t>> tets);
  // Colours by `field` (null: by region) from now on: the same camera and regions, redrawn from the
  // back; a finished picture of whole tets in flat colours is recoloured instead where that gives the
  // same pixels (TetRasterizer::recolors_by_shade), generation() unchanged.
  void set_field(std::shared_ptr<const FieldPaint> field);
  const std::shared_ptr<const FieldPaint>& field() const { return params_.field; }
  // Translucent regions and isosurfaces ("x-ray", translucent.hpp) of the region on top of the stack
  // instead of opaque tets: the params are copied, their corner values lent (they must outlive the
  // view or the next call). Null: opaque tets again. A whole-tet subset (set_subset) stays: only its
  // tets are drawn translucent (foxi render --regions with --region-opacity); iso drawing and volume
  // rendering end. Redraws from the back. Throws std::invalid_argument (from translucent_surfaces)
  // for bad opacities, the previous picture kept.
  void set_translucent(const TranslucentParams* params);
  // A volume rendering of the field with `corner` values (4 per tet, lent as above) of the region on
  // top of the stack (volume.hpp), within the whole-tet subset as above. Null params: opaque tets
  // again. Ends iso and translucent drawing; redraws from the back. Throws std::invalid_argument
  // (from VolumePainter) for bad params.
  void set_volume(std::span<const double> corner, const VolumeParams* params);
  bool translucent() const { return translucent_.has_value(); }
  bool volume() const { return volume_.has_value(); }
  // Translucent or volume drawing composited in the exact (power) order: false without the certificate.
  bool composite_exact() const { return delaunay_; }

  const Camera& camera() const { return camera_; }
  // The picture so far. Compositing resolves the painter's picture into it here, when it is asked
  // for (not after every batch: at 1920x1080 a resolve costs more than a batch of a 1M-tet volume).
  const Framebuffer& framebuffer() const;
  // The parts of the framebuffer changed since the last call, as disjoint rectangles in row order
  // (all of it after a draw restarts or a resize; none if nothing changed): what a display must
  // update. Per band of 16 rows, the box of what the draw and undraw steps changed there.
  std::vector<PixelRect> take_damage();
  // The tets drawn in the current draw, in drawing order.
  const std::vector<std::uint32_t>& drawn() const { return drawn_; }
  std::size_t total() const;  // tets in the current draw's order
  bool delaunay() const { return delaunay_; }
  // Milliseconds spent on the current draw so far (ordering and drawing; time stopped not counted).
  double frame_ms() const { return frame_ms_; }
  // Milliseconds of the last step (one frame of the progressive draw or undraw).
  double step_ms() const { return step_ms_; }
  // Counts draws started (restart, camera moves, regions); a front end reports each completed draw once.
  std::size_t generation() const { return generation_; }
  const Mesh& mesh() const { return mesh_; }
  // "drawn 1234 / 5000 tets (24.7%), 12.3 ms, 0.8 ms/frame, region 1, ..." for the status line
  // (first word drawing, drawn, undrawing or undrawn).
  std::string status() const;
  // The camera as foxi render options (--eye/--at/--up/--fov or --dir), exact (%.17g).
  std::string camera_options() const;

  void save_png(const std::filesystem::path& path) const;

 private:
  void begin_draw();
  std::span<const std::uint32_t> current_subset() const;

  const Mesh& mesh_;
  RenderParams params_;
  bool delaunay_ = false;
  SphereTable table_;
  Camera camera_;
  int width_, height_;
  std::vector<std::vector<std::uint32_t>> stack_;  // region-of-interest subsets; empty = whole mesh
  std::optional<ProgressiveOrder> order_;          // Delaunay: the progressive power order
  std::vector<std::uint32_t> mpvo_;                // otherwise: the MPVO order, drawn in chunks
  std::size_t mpvo_pos_ = 0;
  std::unique_ptr<TetRasterizer> raster_;
  const IsoDrawing* iso_ = nullptr;
  bool selecting_ = false;                 // set_iso or set_subset: only iso_tets_ are drawn
  std::vector<std::uint32_t> iso_tets_;    // sorted
  std::vector<std::uint32_t> iso_subset_;  // iso_tets_ within the region on top of the stack
  std::unique_ptr<IsoPainter> iso_painter_;
  // Compositing (set_translucent, set_volume): the settings, the surfaces and the painter of this draw.
  bool compositing() const { return translucent_ || volume_; }
  void composite(std::span<const std::uint32_t> batch);
  void recomposite();  // a fresh painter with drawn_ composited again (undraw)
  void set_composite(std::optional<TranslucentParams> translucent, std::optional<VolumeParams> volume,
                     std::span<const double> corner);
  std::optional<TranslucentParams> translucent_;
  std::optional<VolumeParams> volume_;
  std::span<const double> volume_corner_;
  std::unique_ptr<TranslucentSurfaces> surfaces_;  // lent to the painter: a stable address
  bool surfaces_stale_ = true;                     // the params or the region changed
  std::unique_ptr<TranslucentPainter> translucent_painter_;
  std::unique_ptr<VolumePainter> volume_painter_;
  // Compositing's undraw, made cheap: the resolved picture after each batch of the first pass (it is
  // exactly the picture of that prefix, so showing it is an exact undraw), while they fit in
  // kShotBudget bytes; shot_at_[i] the tets drawn then (ascending). Undraw steps go back batch by
  // batch to these pictures; other counts, and drawing on after them, composite the prefix again.
  static constexpr std::size_t kShotBudget = std::size_t(128) << 20;
  std::vector<Framebuffer> shots_;
  std::vector<std::size_t> shot_at_;
  std::size_t shot_bytes_ = 0;
  bool painter_behind_ = false;  // fb_ shows a shot: the painter holds more than drawn_
  // Compositing: the painter holds batches fb_ does not show yet; sync() resolves them into fb_
  // (framebuffer(), pick(), save_png(), a shot), so a step costs the batch, not a resolve.
  mutable bool resolve_pending_ = false;
  // fb_ holds the volume painter's last resolve (VolumePainter::resolve_drawn then resolves only the
  // tiles drawn since); false once anything else writes fb_ (a kept undraw picture, a resize).
  mutable bool fb_holds_volume_ = false;
  void sync() const;
  mutable Framebuffer fb_;
  std::vector<PixelRect> damage_;  // see take_damage: per band of 16 rows (x0 > x1: none)
  void add_damage(std::span<const PixelRect> rects);
  void damage_all();
  std::vector<std::uint32_t> drawn_;   // the prefix of handed_ on the screen
  std::vector<std::uint32_t> handed_;  // the order as far as it has been handed out
  bool done_ = true, running_ = true, started_ = false, undrawing_ = false;
  double frame_ms_ = 0, step_ms_ = 0;
  std::size_t generation_ = 0;
};

}  // namespace foxi
