// The window-free interactive view (interactive_view.hpp).
#include "foxi/viz/interactive_view.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <stdexcept>
#include <utility>

#include "foxi/model/delaunay.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/png.hpp"

namespace foxi {

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

// MPVO orders (non-Delaunay meshes) are drawn in chunks of this many tets, at least.
constexpr std::size_t kMpvoChunk = 4096;

}  // namespace

std::vector<RegionOpacity> default_xray(const Mesh& mesh, double opacity) {
  std::vector<std::pair<std::int32_t, std::size_t>> count;  // region, tets (ascending ids)
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::int32_t r = mesh.region_of(t);
    auto it = std::lower_bound(
        count.begin(), count.end(), r,
        [](const std::pair<std::int32_t, std::size_t>& c, std::int32_t id) { return c.first < id; });
    if (it == count.end() || it->first != r)
      count.insert(it, {r, 1});
    else
      ++it->second;
  }
  std::size_t smallest = 0;
  for (std::size_t i = 1; i < count.size(); ++i)
    if (count[i].second < count[smallest].second) smallest = i;
  std::vector<RegionOpacity> out;
  for (std::size_t i = 0; i < count.size(); ++i)
    if (i != smallest || count.size() == 1) out.push_back({count[i].first, opacity});
  return out;
}

VolumeParams default_volume(const Mesh& mesh, const ColorScale& scale,
                            std::span<const std::uint32_t> subset) {
  VolumeParams vp;
  vp.scale = scale;
  vp.opacity_curve = {{scale.lo, 0.02}, {scale.hi, 0.5}};
  double lo[3], hi[3];
  tets_bounds(mesh, subset, lo, hi);
  vp.unit_length = 0.1 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
  return vp;
}

InteractiveView::InteractiveView(const Mesh& mesh, const Camera& camera, int width, int height,
                                 const RenderParams& params)
    : mesh_(mesh), params_(params), camera_(camera), width_(width), height_(height) {
  if (mesh.tet_count() == 0) throw std::invalid_argument("the mesh has no tets");
  delaunay_ = safe_order_method(delaunay_certificate(mesh)) == OrderMethod::power;
  table_ = compute_spheres(mesh);
  params_.depth_buffer = !delaunay_;
  params_.undoable = delaunay_ && params.undoable;  // the painter can undraw, if asked to record
  fb_.resize(width_, height_, params_.depth_buffer);
  damage_all();
}

InteractiveView::~InteractiveView() = default;

constexpr int kDamageBand = 16;  // rows

void InteractiveView::add_damage(std::span<const PixelRect> rects) {
  damage_.resize(std::size_t((height_ + kDamageBand - 1) / kDamageBand));
  for (const PixelRect& r : rects) {
    if (r.x0 > r.x1 || r.y0 > r.y1) continue;
    for (int band = std::max(r.y0, 0) / kDamageBand; band <= std::min(r.y1, height_ - 1) / kDamageBand;
         ++band) {
      PixelRect& d = damage_[std::size_t(band)];
      const int y0 = std::max(r.y0, band * kDamageBand),
                y1 = std::min(r.y1, band * kDamageBand + kDamageBand - 1);
      d = d.x0 > d.x1
              ? PixelRect{r.x0, y0, r.x1, y1}
              : PixelRect{std::min(d.x0, r.x0), std::min(d.y0, y0), std::max(d.x1, r.x1), std::max(d.y1, y1)};
    }
  }
}

void InteractiveView::damage_all() {
  damage_.clear();
  const PixelRect all{0, 0, width_ - 1, height_ - 1};
  add_damage(std::span<const PixelRect>(&all, 1));
}

std::vector<PixelRect> InteractiveView::take_damage() {
  std::vector<PixelRect> rects;
  for (PixelRect& d : damage_) {
    if (d.x0 <= d.x1) {
      if (!rects.empty() && rects.back().x0 == d.x0 && rects.back().x1 == d.x1 && rects.back().y1 + 1 == d.y0)
        rects.back().y1 = d.y1;  // whole bands of the same extent as one
      else
        rects.push_back(d);
    }
    d = PixelRect{};
  }
  return rects;
}

std::span<const std::uint32_t> InteractiveView::current_subset() const {
  if (selecting_) return iso_subset_;
  if (stack_.empty()) return {};
  return stack_.back();
}

void InteractiveView::begin_draw() {
  // A degenerate camera (e.g. zoomed through `at`) throws here; the caller keeps the old picture.
  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<TetRasterizer> raster;
  std::unique_ptr<IsoPainter> iso_painter;
  std::unique_ptr<TranslucentSurfaces> surfaces;
  std::unique_ptr<TranslucentPainter> translucent_painter;
  std::unique_ptr<VolumePainter> volume_painter;
  if (selecting_) {
    // The iso (or selected) tets within the region of interest.
    iso_subset_.clear();
    if (stack_.empty())
      iso_subset_ = iso_tets_;
    else
      std::set_intersection(iso_tets_.begin(), iso_tets_.end(), stack_.back().begin(), stack_.back().end(),
                            std::back_inserter(iso_subset_));
  }
  // What is composited: the whole-tet subset within the region (a subset stays with compositing).
  const std::span<const std::uint32_t> region = current_subset();
  if (translucent_) {
    // The surfaces do not depend on the view: a camera move reuses them.
    if (surfaces_stale_ || !surfaces_)
      surfaces = std::make_unique<TranslucentSurfaces>(translucent_surfaces(mesh_, region, *translucent_));
    else
      surfaces = std::move(surfaces_);
    translucent_painter = std::make_unique<TranslucentPainter>(mesh_, camera_, width_, height_, *surfaces,
                                                               *translucent_, !delaunay_);
  } else if (volume_) {
    volume_painter =
        std::make_unique<VolumePainter>(mesh_, camera_, width_, height_, volume_corner_, *volume_);
  } else {
    raster = std::make_unique<TetRasterizer>(mesh_, camera_, width_, height_, params_);
    if (iso_)
      iso_painter = std::make_unique<IsoPainter>(mesh_, camera_, width_, height_, iso_->corner, iso_->params,
                                                 params_, iso_->attr);
  }
  raster_ = std::move(raster);
  iso_painter_ = std::move(iso_painter);
  surfaces_ = std::move(surfaces);
  surfaces_stale_ = false;
  translucent_painter_ = std::move(translucent_painter);
  volume_painter_ = std::move(volume_painter);
  order_.reset();
  mpvo_.clear();
  mpvo_pos_ = 0;
  const View v = view_of(camera_);
  // Translucency orders only the tets that own a surface fragment (translucent.hpp says why that is exact).
  const std::span<const std::uint32_t> to_order =
      surfaces_ ? std::span<const std::uint32_t>(surfaces_->tets) : current_subset();
  // Nothing crosses, or no surface: an empty subset would mean the whole mesh to the orders.
  const bool nothing = (selecting_ && iso_subset_.empty()) || (surfaces_ && surfaces_->tets.empty());
  if (nothing) {
  } else if (delaunay_) {
    order_.emplace(mesh_, table_, v, to_order);
  } else if (surfaces_) {
    mpvo_.assign(to_order.begin(), to_order.end());  // any order: the painter sorts each pixel's fragments
  } else {
    mpvo_ = mpvo_order(mesh_, table_, v, current_subset());
  }
  fb_.resize(width_, height_, params_.depth_buffer && !compositing());
  fb_holds_volume_ = false;
  resolve_pending_ = compositing();  // the background, when asked for
  damage_all();
  drawn_.clear();
  handed_.clear();
  shots_.clear();
  shot_at_.clear();
  shot_bytes_ = 0;
  painter_behind_ = false;
  done_ = nothing;
  undrawing_ = false;
  started_ = true;
  ++generation_;
  frame_ms_ = ms_since(t0);  // ordering set-up (MPVO: the whole order) counts
}

void InteractiveView::composite(std::span<const std::uint32_t> batch) {
  if (translucent_painter_) {
    translucent_painter_->draw(batch);
  } else {
    volume_painter_->draw(batch);
  }
  resolve_pending_ = true;
  damage_all();  // the composite painters keep no changed rectangles
}

void InteractiveView::sync() const {
  if (!resolve_pending_) return;
  if (translucent_painter_)
    translucent_painter_->resolve(fb_);
  else if (volume_painter_)
    volume_painter_->resolve_drawn(fb_, !fb_holds_volume_);  // the tiles drawn since the last one
  fb_holds_volume_ = volume_painter_ != nullptr;
  resolve_pending_ = false;
}

const Framebuffer& InteractiveView::framebuffer() const {
  sync();
  return fb_;
}

void InteractiveView::recomposite() {
  if (translucent_painter_)
    translucent_painter_ = std::make_unique<TranslucentPainter>(mesh_, camera_, width_, height_, *surfaces_,
                                                                *translucent_, !delaunay_);
  else
    volume_painter_ =
        std::make_unique<VolumePainter>(mesh_, camera_, width_, height_, volume_corner_, *volume_);
  composite(drawn_);
}

void InteractiveView::restart() { begin_draw(); }

void InteractiveView::set_iso(const IsoDrawing* drawing, std::vector<std::uint32_t> tets) {
  translucent_.reset();
  volume_.reset();
  iso_ = drawing;
  selecting_ = drawing != nullptr;
  iso_tets_ = drawing ? std::move(tets) : std::vector<std::uint32_t>{};
  std::sort(iso_tets_.begin(), iso_tets_.end());
  iso_subset_.clear();
  begin_draw();
}

void InteractiveView::set_subset(std::optional<std::vector<std::uint32_t>> tets) {
  translucent_.reset();
  volume_.reset();
  iso_ = nullptr;
  selecting_ = tets.has_value();
  iso_tets_ = tets ? std::move(*tets) : std::vector<std::uint32_t>{};
  std::sort(iso_tets_.begin(), iso_tets_.end());
  iso_subset_.clear();
  begin_draw();
}

void InteractiveView::set_translucent(const TranslucentParams* params) {
  set_composite(params ? std::optional<TranslucentParams>(*params) : std::nullopt, std::nullopt, {});
}

void InteractiveView::set_volume(std::span<const double> corner, const VolumeParams* params) {
  set_composite(std::nullopt, params ? std::optional<VolumeParams>(*params) : std::nullopt,
                params ? corner : std::span<const double>());
}

void InteractiveView::set_composite(std::optional<TranslucentParams> translucent,
                                    std::optional<VolumeParams> volume, std::span<const double> corner) {
  // Bad settings throw from begin_draw's painters: the previous drawing is then restored.
  auto old_translucent = std::move(translucent_);
  auto old_volume = std::move(volume_);
  const std::span<const double> old_corner = volume_corner_;
  const IsoDrawing* old_iso = iso_;
  const bool old_selecting = selecting_;
  translucent_ = std::move(translucent);
  volume_ = std::move(volume);
  volume_corner_ = corner;
  // Iso polygons end; a whole-tet subset (no iso drawing) stays: its tets are what is composited.
  const bool keep_subset = selecting_ && iso_ == nullptr;
  iso_ = nullptr;
  selecting_ = keep_subset;
  surfaces_stale_ = true;
  try {
    begin_draw();
  } catch (const std::invalid_argument&) {
    translucent_ = std::move(old_translucent);
    volume_ = std::move(old_volume);
    volume_corner_ = old_corner;
    iso_ = old_iso;
    selecting_ = old_selecting;
    surfaces_stale_ = true;
    begin_draw();
    throw;
  }
  if (!keep_subset) {  // iso drawing ends
    iso_tets_.clear();
    iso_subset_.clear();
  }
}

void InteractiveView::set_field(std::shared_ptr<const FieldPaint> field) {
  // A finished picture of whole tets is recoloured through its id and shade buffers (a few ms at 1M
  // tets, where drawing again takes a few hundred) when that is exact, undraw records included
  // (TetRasterizer::recolor); else drawn again from the back.
  if (raster_ && started_ && done_ && !undrawing_ && iso_ == nullptr && !drawn_.empty() &&
      raster_->recolors_by_shade(field.get())) {
    const auto t0 = std::chrono::steady_clock::now();
    raster_->recolor(fb_, field);  // a paint of another mesh throws here, nothing changed
    fb_holds_volume_ = false;
    params_.field = std::move(field);
    damage_all();
    step_ms_ = ms_since(t0);
    return;
  }
  params_.field = std::move(field);
  begin_draw();
}

bool InteractiveView::step() {
  const auto t0 = std::chrono::steady_clock::now();
  if (undrawing_) {
    std::size_t count = std::max<std::size_t>(1, total() / 64);
    if (compositing() && !shot_at_.empty() && drawn_.size() <= shot_at_.back()) {
      // Back to the previous batch's picture (or to nothing before the first).
      const auto it = std::lower_bound(shot_at_.begin(), shot_at_.end(), drawn_.size());
      count = drawn_.size() - (it == shot_at_.begin() ? 0 : *(it - 1));
    }
    const std::size_t n = undraw(count);
    step_ms_ = ms_since(t0);
    frame_ms_ += step_ms_;
    return n > 0;
  }
  if (done_) return false;
  std::span<const std::uint32_t> batch;
  bool first_pass = false;               // a batch of the order drawn for the first time (not drawing on)
  if (drawn_.size() < handed_.size()) {  // drawing on after an undraw: the order is known
    const std::size_t n = std::min(handed_.size() - drawn_.size(), std::max<std::size_t>(1, total() / 64));
    batch = std::span<const std::uint32_t>(handed_).subspan(drawn_.size(), n);
  } else if (order_) {
    // Compositing takes the order's batches (a few thousand tets) by 1/64 of the displayed set: each
    // painter draw bins its tets to the screen tiles on both threads, fixed costs a 1M-tet volume
    // would otherwise pay some 250 times a frame.
    const std::size_t want = compositing() ? std::max<std::size_t>(1, total() / 64) : 1;
    const std::size_t start = handed_.size();
    do {
      const std::span<const std::uint32_t> next = order_->next();
      if (next.empty()) break;
      handed_.insert(handed_.end(), next.begin(), next.end());
    } while (handed_.size() - start < want);
    first_pass = true;
    batch = std::span<const std::uint32_t>(handed_).subspan(start);
  } else {
    std::size_t n = std::min(mpvo_.size() - mpvo_pos_, std::max(kMpvoChunk, mpvo_.size() / 64));
    batch = std::span<const std::uint32_t>(mpvo_).subspan(mpvo_pos_, n);
    mpvo_pos_ += n;
  }
  if (batch.empty()) {
    done_ = true;
    step_ms_ = ms_since(t0);
    frame_ms_ += step_ms_;
    return false;
  }
  if (compositing()) {
    if (painter_behind_) recomposite();  // fb_ showed a shot: the painter catches up first
    painter_behind_ = false;
    composite(batch);
  } else if (iso_painter_) {
    iso_painter_->draw(fb_, batch);
    damage_all();  // the iso painter keeps no changed rectangles
  } else {
    raster_->draw(fb_, batch);
    add_damage(raster_->changed_rects());
  }
  drawn_.insert(drawn_.end(), batch.begin(), batch.end());
  const std::size_t shot = fb_.rgba.size() * 9;  // colour, id and shade per pixel
  if (compositing() && delaunay_ && first_pass && shot_bytes_ + shot <= kShotBudget) {
    sync();
    shots_.push_back(fb_);
    shot_at_.push_back(drawn_.size());
    shot_bytes_ += shot;
  }
  step_ms_ = ms_since(t0);
  frame_ms_ += step_ms_;
  if (drawn_.size() >= total()) {
    done_ = true;
    order_.reset();  // stops its sorting thread
  }
  return true;
}

bool InteractiveView::set_undrawing(bool on) {
  // Compositing undraws by compositing again (no record needed), but only in the exact order.
  if (on && !(compositing() ? delaunay_ : params_.undoable)) return false;
  undrawing_ = on;
  return true;
}

std::size_t InteractiveView::undraw(std::size_t count) {
  if (compositing()) {
    // Not invertible: the first drawn_.size() - n tets composited again from the back (exact).
    if (!delaunay_) return 0;
    const std::size_t n = std::min(count, drawn_.size());
    if (n == 0) return 0;
    drawn_.resize(drawn_.size() - n);
    const auto it = std::lower_bound(shot_at_.begin(), shot_at_.end(), drawn_.size());
    if (it != shot_at_.end() && *it == drawn_.size()) {
      fb_ = shots_[std::size_t(it - shot_at_.begin())];  // that prefix's picture, as drawn
      fb_holds_volume_ = false;
      resolve_pending_ = false;  // the painter holds more: not resolved until it catches up
      damage_all();
      painter_behind_ = true;
    } else {
      recomposite();
      painter_behind_ = false;
    }
    done_ = false;
    return n;
  }
  if (!params_.undoable || !raster_) return 0;
  const std::size_t n = std::min(count, drawn_.size());
  if (iso_painter_) {
    iso_painter_->undraw(fb_, n);
    damage_all();
  } else {
    raster_->undraw(fb_, n);
    add_damage(raster_->changed_rects());
  }
  drawn_.resize(drawn_.size() - n);
  if (n > 0) done_ = false;
  return n;
}

bool InteractiveView::step(std::chrono::steady_clock::duration budget) {
  const auto end = std::chrono::steady_clock::now() + budget;
  bool changed = false;
  do {
    if (!step()) break;
    changed = true;
  } while (std::chrono::steady_clock::now() < end);
  return changed;
}

std::uint32_t InteractiveView::pick(int x, int y) const {
  sync();
  if (x < 0 || y < 0 || x >= fb_.width || y >= fb_.height) return kNone;
  return fb_.id[fb_.index(x, y)];
}

void InteractiveView::finish() {
  while (step()) {
  }
}

std::vector<std::uint32_t> InteractiveView::shown_tets() const {
  if (selecting_) {
    if (stack_.empty()) return iso_tets_;
    std::vector<std::uint32_t> out;
    std::set_intersection(iso_tets_.begin(), iso_tets_.end(), stack_.back().begin(), stack_.back().end(),
                          std::back_inserter(out));
    return out;
  }
  return stack_.empty() ? std::vector<std::uint32_t>() : stack_.back();
}

ViewMovie InteractiveView::movie_input() const {
  if (iso_ != nullptr)
    throw std::invalid_argument(
        "a movie turns the camera around whole tets, translucency or a volume rendering (as foxi movie "
        "--mode rotate): turn the isosurface or slice off first (foxi movie --sweep iso makes an "
        "isosurface movie)");
  ViewMovie m;
  m.camera = camera_;
  m.width = width_;
  m.height = height_;
  m.render = params_;
  m.subset = shown_tets();
  if (translucent_) {
    m.translucent = *translucent_;
    m.corner.assign(translucent_->corner.begin(), translucent_->corner.end());
  } else if (volume_) {
    m.volume = *volume_;
    m.corner.assign(volume_corner_.begin(), volume_corner_.end());
  }
  return m;
}

std::size_t make_view_movie(const Mesh& mesh, const ViewMovie& movie, const MovieParams& params,
                            const std::function<void(const Framebuffer&)>& frame,
                            const ProgressFn& progress) {
  const SphereTable table = compute_spheres(mesh);
  if (movie.translucent || movie.volume) {
    CompositeMovieParams cp;
    cp.movie = params;
    cp.translucent = movie.translucent;
    if (cp.translucent && !cp.translucent->corner.empty()) cp.translucent->corner = movie.corner;
    cp.volume = movie.volume;
    if (movie.volume) cp.corner = movie.corner;
    return make_composite_movie(mesh, table, movie.camera, movie.width, movie.height, movie.subset, cp, frame,
                                progress)
        .frames;
  }
  MovieParams mp = params;
  mp.render = movie.render;
  return make_movie(mesh, table, movie.camera, movie.width, movie.height, movie.subset, mp, frame, progress)
      .frames;
}

std::size_t InteractiveView::total() const {
  if (surfaces_) return surfaces_->tets.size();
  if (selecting_) return iso_subset_.size();
  if (!stack_.empty()) return stack_.back().size();
  return mesh_.tet_count();
}

bool InteractiveView::push_region() {
  if (drawn_.empty() || translucent_) return false;
  std::vector<std::uint32_t> subset = drawn_;
  std::sort(subset.begin(), subset.end());
  stack_.push_back(std::move(subset));
  surfaces_stale_ = true;
  begin_draw();
  return true;
}

bool InteractiveView::pop_region() {
  if (stack_.empty()) return false;
  stack_.pop_back();
  surfaces_stale_ = true;
  begin_draw();
  return true;
}

void InteractiveView::set_camera(const Camera& camera) {
  const Camera old = camera_;
  camera_ = camera;
  try {
    begin_draw();
  } catch (const std::invalid_argument&) {
    camera_ = old;  // a degenerate camera: keep the previous one
    begin_draw();
  }
}

void InteractiveView::orbit(double yaw_deg, double pitch_deg) {
  set_camera(foxi::orbit(camera_, yaw_deg, pitch_deg));
}
void InteractiveView::zoom(double factor) { set_camera(foxi::zoom(camera_, factor)); }
void InteractiveView::pan(double dx, double dy) { set_camera(foxi::pan(camera_, dx, dy)); }

void InteractiveView::resize(int width, int height) {
  width_ = std::max(1, width);
  height_ = std::max(1, height);
  begin_draw();
}

std::string InteractiveView::status() const {
  char buf[512];
  const std::size_t n = drawn_.size(), t = total();
  const char* state = undrawing_ ? (n == 0 ? "undrawn" : "undrawing") : done_ ? "drawn" : "drawing";
  std::snprintf(buf, sizeof buf, "%s %zu / %zu tets (%.1f%%), %.1f ms, %.2f ms/frame%s, region %zu%s", state,
                n, t, t ? 100.0 * double(n) / double(t) : 0.0, frame_ms_, step_ms_,
                started_ && !running_ && (undrawing_ ? n > 0 : !done_) ? " [stopped]" : "", stack_.size(),
                !delaunay_ && !compositing() ? "  NOT Delaunay: depth-buffer drawing" : "");
  std::string s = buf;
  if (translucent_) {
    // Translucent regions are the x-ray; isosurfaces alone are not.
    s += translucent_->regions ? ", x-ray" : ", translucent isosurfaces";
    s += delaunay_ ? " composited exactly (power order)"
                   : " NOT Delaunay: fragments sorted per pixel by depth (no exact order; no undraw)";
  }
  if (volume_)
    s += delaunay_ ? ", volume composited exactly (power order)"
                   : ", volume NOT Delaunay: composited in MPVO order, NOT exact (no undraw)";
  return s;
}

std::string InteractiveView::camera_options() const {
  char buf[512];
  if (camera_.perspective)
    std::snprintf(buf, sizeof buf,
                  "--eye %.17g,%.17g,%.17g --at %.17g,%.17g,%.17g --up %.17g,%.17g,%.17g --fov %.17g",
                  camera_.eye[0], camera_.eye[1], camera_.eye[2], camera_.at[0], camera_.at[1], camera_.at[2],
                  camera_.up[0], camera_.up[1], camera_.up[2], camera_.fov_deg);
  else
    std::snprintf(buf, sizeof buf, "--dir %.17g,%.17g,%.17g", camera_.at[0] - camera_.eye[0],
                  camera_.at[1] - camera_.eye[1], camera_.at[2] - camera_.eye[2]);
  return buf;
}

void InteractiveView::save_png(const std::filesystem::path& path) const { write_png(path, framebuffer()); }

}  // namespace foxi
