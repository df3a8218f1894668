// foxi-view's window-free core: see viewer.hpp.
#include "viewer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "foxi/model/delaunay.hpp"
#include "foxi/viz/png.hpp"

namespace foxi::view {

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

std::vector<double> numbers(const std::string& s, const char* what) {
  std::vector<double> v;
  std::size_t pos = 0;
  while (pos <= s.size()) {
    std::size_t comma = s.find(',', pos);
    if (comma == std::string::npos) comma = s.size();
    std::string item = s.substr(pos, comma - pos);
    char* end = nullptr;
    double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != 0 || !std::isfinite(x))
      throw std::invalid_argument(std::string(what) + " takes comma-separated numbers, not '" + s + "'");
    v.push_back(x);
    pos = comma + 1;
  }
  return v;
}

void triple(const std::string& s, const char* what, double out[3]) {
  auto v = numbers(s, what);
  if (v.size() != 3) throw std::invalid_argument(std::string(what) + " takes x,y,z");
  for (int k = 0; k < 3; ++k) out[k] = v[k];
}

// MPVO orders (non-Delaunay meshes) are drawn in chunks of this many tets, at least.
constexpr std::size_t kMpvoChunk = 4096;

}  // namespace

Camera default_camera(const Mesh& mesh, int width, int height, const std::string& eye_s,
                      const std::string& at_s, const std::string& up_s, const std::string& fov_s,
                      const std::string& dir_s) {
  // The same rules as foxi render (camera_from_options), so both give the same picture.
  if (!dir_s.empty() && (!eye_s.empty() || !fov_s.empty()))
    throw std::invalid_argument("--dir (orthographic) cannot be combined with --eye or --fov");
  double lo[3], hi[3];
  mesh_bounds(mesh, lo, hi);
  const double aspect = double(width) / height;
  double up[3], at[3], eye[3], dir[3];
  if (!up_s.empty()) triple(up_s, "--up", up);
  if (!at_s.empty()) triple(at_s, "--at", at);
  if (!eye_s.empty()) triple(eye_s, "--eye", eye);
  if (!dir_s.empty()) {
    triple(dir_s, "--dir", dir);
    if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0) throw std::invalid_argument("--dir takes a nonzero x,y,z");
  }
  double fov = 0;
  if (!fov_s.empty()) {
    char* end = nullptr;
    fov = std::strtod(fov_s.c_str(), &end);
    if (*end != 0 || !(fov > 0 && fov < 180)) throw std::invalid_argument("--fov takes degrees in (0, 180)");
  }
  return camera_from_options(lo, hi, aspect, eye_s.empty() ? nullptr : eye, at_s.empty() ? nullptr : at,
                             up_s.empty() ? nullptr : up, fov, dir_s.empty() ? nullptr : dir);
}

Viewer::Viewer(const Mesh& mesh, const Camera& camera, int width, int height, const RenderParams& params)
    : mesh_(mesh), params_(params), camera_(camera), width_(width), height_(height) {
  if (mesh.tet_count() == 0) throw std::invalid_argument("the mesh has no tets");
  delaunay_ = delaunay_certificate(mesh).delaunay;
  table_ = compute_spheres(mesh);
  params_.depth_buffer = !delaunay_;
  params_.undoable = delaunay_ && params.undoable;  // the painter can undraw, if asked to record
  fb_.resize(width_, height_, params_.depth_buffer);
  damage_all();
}

Viewer::~Viewer() = default;

constexpr int kDamageBand = 16;  // rows

void Viewer::add_damage(std::span<const PixelRect> rects) {
  damage_.resize(std::size_t((height_ + kDamageBand - 1) / kDamageBand));
  for (const PixelRect& r : rects) {
    if (r.x0 > r.x1 || r.y0 > r.y1) continue;
    for (int band = std::max(r.y0, 0) / kDamageBand; band <= std::min(r.y1, height_ - 1) / kDamageBand; ++band) {
      PixelRect& d = damage_[std::size_t(band)];
      const int y0 = std::max(r.y0, band * kDamageBand), y1 = std::min(r.y1, band * kDamageBand + kDamageBand - 1);
      d = d.x0 > d.x1 ? PixelRect{r.x0, y0, r.x1, y1}
                      : PixelRect{std::min(d.x0, r.x0), std::min(d.y0, y0), std::max(d.x1, r.x1), std::max(d.y1, y1)};
    }
  }
}

void Viewer::damage_all() {
  damage_.clear();
  const PixelRect all{0, 0, width_ - 1, height_ - 1};
  add_damage(std::span<const PixelRect>(&all, 1));
}

std::vector<PixelRect> Viewer::take_damage() {
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

std::span<const std::uint32_t> Viewer::current_subset() const {
  if (stack_.empty()) return {};
  return stack_.back();
}

void Viewer::begin_draw() {
  // A degenerate camera (e.g. zoomed through `at`) throws here; the caller keeps the old picture.
  const auto t0 = std::chrono::steady_clock::now();
  auto raster = std::make_unique<TetRasterizer>(mesh_, camera_, width_, height_, params_);
  raster_ = std::move(raster);
  order_.reset();
  mpvo_.clear();
  mpvo_pos_ = 0;
  const View v = view_of(camera_);
  if (delaunay_)
    order_.emplace(mesh_, table_, v, current_subset());
  else
    mpvo_ = mpvo_order(mesh_, table_, v, current_subset());
  fb_.resize(width_, height_, params_.depth_buffer);
  damage_all();
  drawn_.clear();
  handed_.clear();
  done_ = false;
  undrawing_ = false;
  started_ = true;
  ++generation_;
  frame_ms_ = ms_since(t0);  // ordering set-up (MPVO: the whole order) counts
}

void Viewer::restart() { begin_draw(); }

bool Viewer::step() {
  const auto t0 = std::chrono::steady_clock::now();
  if (undrawing_) {
    const std::size_t n = undraw(std::max<std::size_t>(1, total() / 64));
    step_ms_ = ms_since(t0);
    frame_ms_ += step_ms_;
    return n > 0;
  }
  if (done_) return false;
  std::span<const std::uint32_t> batch;
  if (drawn_.size() < handed_.size()) {  // drawing on after an undraw: the order is known
    const std::size_t n = std::min(handed_.size() - drawn_.size(), std::max<std::size_t>(1, total() / 64));
    batch = std::span<const std::uint32_t>(handed_).subspan(drawn_.size(), n);
  } else if (order_) {
    batch = order_->next();
    handed_.insert(handed_.end(), batch.begin(), batch.end());
    batch = std::span<const std::uint32_t>(handed_).last(batch.size());
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
  raster_->draw(fb_, batch);
  add_damage(raster_->changed_rects());
  drawn_.insert(drawn_.end(), batch.begin(), batch.end());
  step_ms_ = ms_since(t0);
  frame_ms_ += step_ms_;
  if (drawn_.size() >= total()) {
    done_ = true;
    order_.reset();  // stops its sorting thread
  }
  return true;
}

bool Viewer::set_undrawing(bool on) {
  if (on && !params_.undoable) return false;
  undrawing_ = on;
  return true;
}

std::size_t Viewer::undraw(std::size_t count) {
  if (!params_.undoable || !raster_) return 0;
  const std::size_t n = std::min(count, drawn_.size());
  raster_->undraw(fb_, n);
  add_damage(raster_->changed_rects());
  drawn_.resize(drawn_.size() - n);
  if (n > 0) done_ = false;
  return n;
}

void Viewer::finish() {
  while (step()) {
  }
}

std::size_t Viewer::total() const {
  if (!stack_.empty()) return stack_.back().size();
  return mesh_.tet_count();
}

bool Viewer::push_region() {
  if (drawn_.empty()) return false;
  std::vector<std::uint32_t> subset = drawn_;
  std::sort(subset.begin(), subset.end());
  stack_.push_back(std::move(subset));
  begin_draw();
  return true;
}

bool Viewer::pop_region() {
  if (stack_.empty()) return false;
  stack_.pop_back();
  begin_draw();
  return true;
}

void Viewer::set_camera(const Camera& camera) {
  const Camera old = camera_;
  camera_ = camera;
  try {
    begin_draw();
  } catch (const std::invalid_argument&) {
    camera_ = old;  // a degenerate camera: keep the previous one
    begin_draw();
  }
}

void Viewer::orbit(double yaw_deg, double pitch_deg) { set_camera(foxi::orbit(camera_, yaw_deg, pitch_deg)); }
void Viewer::zoom(double factor) { set_camera(foxi::zoom(camera_, factor)); }
void Viewer::pan(double dx, double dy) { set_camera(foxi::pan(camera_, dx, dy)); }

void Viewer::resize(int width, int height) {
  width_ = std::max(1, width);
  height_ = std::max(1, height);
  begin_draw();
}

std::string Viewer::status() const {
  char buf[256];
  const std::size_t n = drawn_.size(), t = total();
  const char* state = undrawing_ ? (n == 0 ? "undrawn" : "undrawing") : done_ ? "drawn" : "drawing";
  std::snprintf(buf, sizeof buf, "%s %zu / %zu tets (%.1f%%), %.1f ms, %.2f ms/frame%s, region %zu%s", state, n,
                t, t ? 100.0 * double(n) / double(t) : 0.0, frame_ms_, step_ms_,
                started_ && !running_ && (undrawing_ ? n > 0 : !done_) ? " [stopped]" : "", stack_.size(),
                delaunay_ ? "" : "  NOT Delaunay: depth-buffer drawing");
  return buf;
}

std::string Viewer::camera_options() const {
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

void Viewer::save_png(const std::filesystem::path& path) const { write_png(path, fb_); }

std::filesystem::path save_next(const Viewer& viewer, const std::string& prefix, bool dump) {
  std::string base;
  for (int i = 1;; ++i) {
    char num[16];
    std::snprintf(num, sizeof num, "-%03d", i);
    base = prefix + num;
    if (!std::filesystem::exists(base + ".png")) break;
  }
  const std::filesystem::path png = base + ".png";
  viewer.save_png(png);
  if (dump) {
    const Framebuffer& fb = viewer.framebuffer();
    std::ofstream ids(base + ".ids", std::ios::binary);
    for (std::uint32_t id : fb.id) {
      unsigned char b[4] = {static_cast<unsigned char>(id), static_cast<unsigned char>(id >> 8),
                            static_cast<unsigned char>(id >> 16), static_cast<unsigned char>(id >> 24)};
      ids.write(reinterpret_cast<const char*>(b), 4);
    }
    std::ofstream tets(base + ".tets");
    for (std::uint32_t t : viewer.drawn()) tets << t << '\n';
    if (!ids || !tets) throw std::runtime_error("cannot write " + base + ".ids/.tets");
  }
  std::printf("saved %s  %s  (%s)\n", png.c_str(), viewer.status().c_str(), viewer.camera_options().c_str());
  std::fflush(stdout);
  return png;
}

void run_script(Viewer& viewer, const std::string& script, const std::string& prefix, bool dump) {
  std::istringstream in(script);
  std::string cmd;
  while (in >> cmd) {
    const std::size_t colon = cmd.find(':');
    const std::string name = cmd.substr(0, colon),
                      arg = colon == std::string::npos ? "" : cmd.substr(colon + 1);
    auto args = [&](std::size_t count) {
      auto v = numbers(arg, name.c_str());
      if (v.size() != count)
        throw std::invalid_argument("script command '" + cmd + "' takes " + std::to_string(count) +
                                    " numbers");
      return v;
    };
    if (cmd == "d") {
      viewer.restart();
      viewer.finish();
    } else if (cmd == "c") {
      viewer.restart();
    } else if (cmd == "n") {
      viewer.step();
    } else if (cmd == "f") {
      viewer.set_undrawing(false);
      viewer.finish();
    } else if (name == "u") {
      if (!viewer.set_undrawing(true)) throw std::invalid_argument("script: 'u' needs the painter (a Delaunay mesh) and no --no-undo");
      if (arg.empty()) {
        while (viewer.step()) {
        }
      } else {
        const double k = args(1)[0];
        if (!(k >= 0 && k == std::floor(k))) throw std::invalid_argument("u:N takes a whole number of tets");
        viewer.undraw(std::size_t(k));
      }
    } else if (cmd == "r") {
      if (!viewer.push_region()) throw std::invalid_argument("script: 'r' with no tets drawn");
    } else if (cmd == "b") {
      viewer.pop_region();
    } else if (cmd == "s") {
      save_next(viewer, prefix, dump);
    } else if (name == "orbit") {
      auto v = args(2);
      viewer.orbit(v[0], v[1]);
    } else if (name == "zoom") {
      auto v = args(1);
      if (!(v[0] > 0)) throw std::invalid_argument("zoom takes a factor > 0");
      viewer.zoom(v[0]);
    } else if (name == "pan") {
      auto v = args(2);
      viewer.pan(v[0], v[1]);
    } else {
      throw std::invalid_argument("unknown script command '" + cmd +
                                  "' (d c n f u u:N r b s orbit:Y,P zoom:F pan:X,Y)");
    }
  }
}

}  // namespace foxi::view
