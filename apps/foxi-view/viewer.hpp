// The state machine of foxi-view, without any window: the camera, the region-of-interest stack of
// tet subsets, the progressive visibility order of the displayed set and the framebuffer it is drawn
// into. The Xlib front end (x11_window.cpp) and the headless script mode (script.cpp) drive the same
// object, so tests can run it without a display.
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

#include "foxi/model/mesh.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi::view {

class Viewer {
 public:
  // The mesh is lent and must outlive the viewer. Computes the Delaunay certificate and the sphere
  // table once; nothing is drawn until restart(). params.undoable: the painter records what undraw
  // needs (false: cheaper drawing, and set_undrawing refuses).
  Viewer(const Mesh& mesh, const Camera& camera, int width, int height, const RenderParams& params = {});
  ~Viewer();

  // 'd': a new draw of the displayed set from the back, for the current camera (picture cleared).
  void restart();
  // Draws the next batch of the order (undrawing: takes back the front-most chunk, 1/64 of the
  // displayed set); returns false (nothing changed) when there is nothing left to do that way.
  bool step();
  // Draws all remaining batches.
  void finish();
  bool done() const { return done_; }

  // Space: the front end keeps stepping while running.
  bool running() const { return running_ && (undrawing_ ? !drawn_.empty() : !done_); }
  void set_running(bool on) { running_ = on; }
  // 'u': undraw (front to back, the seed paper's undraw: each frame equals drawing fewer tets from
  // scratch) or, set to false, draw on again from where the undraw stopped. Returns false (nothing
  // changes) for meshes drawn with the depth buffer, which cannot undraw, or without undoable.
  bool set_undrawing(bool on);
  bool undrawing() const { return undrawing_; }
  // Undraws up to `count` tets at once (the script's u:N); returns how many.
  std::size_t undraw(std::size_t count);

  // 'r': the tets drawn so far become the displayed set (pushed on the stack), redrawn from the back.
  // Returns false (nothing changes) when no tet has been drawn.
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

  const Camera& camera() const { return camera_; }
  const Framebuffer& framebuffer() const { return fb_; }
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
  Framebuffer fb_;
  std::vector<PixelRect> damage_;  // see take_damage: per band of 16 rows (x0 > x1: none)
  void add_damage(std::span<const PixelRect> rects);
  void damage_all();
  std::vector<std::uint32_t> drawn_;    // the prefix of handed_ on the screen
  std::vector<std::uint32_t> handed_;   // the order as far as it has been handed out
  bool done_ = true, running_ = true, started_ = false, undrawing_ = false;
  double frame_ms_ = 0, step_ms_ = 0;
  std::size_t generation_ = 0;
};

// The camera foxi render uses for the same options: --dir x,y,z (orthographic), or perspective with
// --eye/--at/--up/--fov, the missing parts fitted (an oblique view of the whole mesh). Empty strings
// for absent options. Throws std::invalid_argument on bad values.
Camera default_camera(const Mesh& mesh, int width, int height, const std::string& eye, const std::string& at,
                      const std::string& up, const std::string& fov, const std::string& dir);

// Runs a script of whitespace-separated commands on the viewer (the headless mode):
//   d            restart and draw to completion      c      restart without drawing
//   n            draw one batch                      f      finish the current draw
//   r / b        push the drawn tets as region / back up   (each restarts without drawing)
//   orbit:Y,P    orbit by yaw, pitch degrees         zoom:F  zoom by F       pan:X,Y  pan
//   s            save the picture as PREFIX-NNN.png (and with dump, PREFIX-NNN.ids: the id buffer as
//                little-endian uint32, and PREFIX-NNN.tets: the drawn tets, one a line)
// Prints one line per save ("saved NAME ...") on stdout. Throws std::invalid_argument on a bad command.
void run_script(Viewer& viewer, const std::string& script, const std::string& prefix, bool dump);

// Saves the picture under the next free name PREFIX-NNN.png; prints "saved NAME camera ..." and
// returns the path. With dump, also writes the id buffer and the drawn tets beside it.
std::filesystem::path save_next(const Viewer& viewer, const std::string& prefix, bool dump);

}  // namespace foxi::view
