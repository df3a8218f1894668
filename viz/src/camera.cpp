#include "foxi/viz/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "foxi/model/vec3.hpp"

namespace foxi {

namespace {

constexpr double kPi = 3.14159265358979323846;

using detail::cross;  // foxi/model/vec3.hpp, on the camera's double[3]
using detail::dot;
using detail::norm;
using detail::normalize;

// Orthonormal right, up, forward of a camera; false if degenerate.
bool basis(const Camera& c, double right[3], double up[3], double fwd[3]) {
  for (int k = 0; k < 3; ++k) fwd[k] = c.at[k] - c.eye[k];
  if (!normalize(fwd)) return false;
  cross(fwd, c.up, right);
  double un = norm(c.up);
  if (!(norm(right) > 1e-9 * un) || !normalize(right)) return false;
  cross(right, fwd, up);
  return normalize(up);
}

// The coordinate axis least aligned with d: the up of a view along the default up. Ties go to y,
// then z, then x, so that a view straight down (along z) has +y up: the plan view of a drawing.
int least_aligned_axis(const double d[3]) {
  int axis = 1;
  for (int k : {2, 0})
    if (std::abs(d[k]) < std::abs(d[axis])) axis = k;
  return axis;
}

// Rotates v about the unit axis by angle (radians), Rodrigues' formula.
void rotate(double v[3], const double axis[3], double angle) {
  double c = std::cos(angle), s = std::sin(angle), kv[3], d = dot(axis, v);
  cross(axis, v, kv);
  for (int k = 0; k < 3; ++k) v[k] = v[k] * c + kv[k] * s + axis[k] * d * (1 - c);
}

}  // namespace

void mesh_bounds(const MeshView& mesh, double lo[3], double hi[3]) {
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  auto add = [&](std::size_t n) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.xyz[3 * n + k]);
      hi[k] = std::max(hi[k], mesh.xyz[3 * n + k]);
    }
  };
  if (mesh.tet.empty()) {
    for (std::size_t n = 0; n < mesh.node_count(); ++n) add(n);
  } else {
    for (std::uint32_t n : mesh.tet)
      if (n < mesh.node_count()) add(n);
  }
}

void tets_bounds(const MeshView& mesh, std::span<const std::uint32_t> subset, double lo[3], double hi[3]) {
  if (subset.empty()) {
    mesh_bounds(mesh, lo, hi);
    return;
  }
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (std::uint32_t t : subset)
    for (int v = 0; v < 4; ++v)
      for (int k = 0; k < 3; ++k) {
        const double x = mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(t) + v]) + k];
        lo[k] = std::min(lo[k], x);
        hi[k] = std::max(hi[k], x);
      }
}

Camera fit_camera(const double lo[3], const double hi[3], const double dir[3], const double up[3],
                  bool perspective, double fov_deg, double aspect, double fill) {
  Camera cam;
  cam.perspective = perspective;
  cam.fov_deg = fov_deg;
  double d[3] = {dir[0], dir[1], dir[2]};
  if (!normalize(d)) throw std::invalid_argument("fit_camera: the view direction is zero");
  double centre[3], radius = 0;
  for (int k = 0; k < 3; ++k) {
    centre[k] = 0.5 * (lo[k] + hi[k]);
    radius += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
  }
  radius = std::sqrt(radius);
  if (!std::isfinite(radius)) throw std::invalid_argument("fit_camera: empty or non-finite bounds");
  if (radius == 0) radius = 1;
  if (!(fill > 0) || fill > 1) fill = 0.95;
  if (!(aspect > 0)) aspect = 1;
  // Up: as given unless (nearly) parallel to the direction; then the axis least aligned with it.
  double u[3] = {up[0], up[1], up[2]}, r[3];
  cross(d, u, r);
  if (!(norm(r) > 1e-6 * norm(u))) {
    u[0] = u[1] = u[2] = 0;
    u[least_aligned_axis(d)] = 1;
  }
  for (int k = 0; k < 3; ++k) {
    cam.at[k] = centre[k];
    cam.up[k] = u[k];
  }
  // Fit the 8 corners of the box (camera frame relative to the centre): each needs the eye far
  // enough that it projects inside `fill` of the half-width and half-height.
  double rr[3], uu[3];
  cross(d, u, rr);
  normalize(rr);
  cross(rr, d, uu);
  const double half_v = 0.5 * fov_deg * kPi / 180;
  double dist = 0, need_h = 0;
  if (perspective && !(fov_deg > 0 && fov_deg < 180))
    throw std::invalid_argument("fit_camera: fov must be in (0, 180) degrees");
  const double tan_v = std::tan(half_v) * fill, tan_h = std::tan(half_v) * aspect * fill;
  for (int corner = 0; corner < 8; ++corner) {
    double p[3];
    for (int k = 0; k < 3; ++k) p[k] = ((corner >> k) & 1 ? hi[k] : lo[k]) - centre[k];
    const double x = std::abs(dot(p, rr)), y = std::abs(dot(p, uu)), z = dot(p, d);
    if (perspective) dist = std::max({dist, x / tan_h - z, y / tan_v - z});
    need_h = std::max({need_h, 2 * y / fill, 2 * x / (aspect * fill)});
  }
  if (perspective) {
    dist = std::max(dist, 1.05 * radius);  // the eye stays outside the bounding sphere
  } else {
    dist = 2 * radius;
    cam.ortho_height = need_h > 0 ? need_h : 2 * radius;
  }
  for (int k = 0; k < 3; ++k) cam.eye[k] = centre[k] - dist * d[k];
  return cam;
}

Camera orbit(const Camera& camera, double yaw_deg, double pitch_deg) {
  Camera c = camera;
  double r[3], u[3], f[3];
  if (!basis(c, r, u, f)) throw std::invalid_argument("orbit: degenerate camera");
  double v[3];
  for (int k = 0; k < 3; ++k) v[k] = c.eye[k] - c.at[k];
  double axis_up[3] = {c.up[0], c.up[1], c.up[2]};
  normalize(axis_up);
  rotate(v, axis_up, yaw_deg * kPi / 180);
  rotate(r, axis_up, yaw_deg * kPi / 180);
  rotate(v, r, pitch_deg * kPi / 180);
  rotate(u, r, pitch_deg * kPi / 180);
  for (int k = 0; k < 3; ++k) {
    c.eye[k] = c.at[k] + v[k];
    c.up[k] = u[k];
  }
  return c;
}

Camera pan(const Camera& camera, double dx, double dy) {
  Camera c = camera;
  double r[3], u[3], f[3];
  if (!basis(c, r, u, f)) throw std::invalid_argument("pan: degenerate camera");
  double h;
  if (c.perspective) {
    double dist[3] = {c.at[0] - c.eye[0], c.at[1] - c.eye[1], c.at[2] - c.eye[2]};
    h = 2 * norm(dist) * std::tan(0.5 * c.fov_deg * kPi / 180);
  } else {
    h = c.ortho_height;
  }
  for (int k = 0; k < 3; ++k) {
    double m = h * (dx * r[k] + dy * u[k]);
    c.eye[k] += m;
    c.at[k] += m;
  }
  return c;
}

Camera zoom(const Camera& camera, double factor) {
  if (!(factor > 0) || !std::isfinite(factor)) throw std::invalid_argument("zoom: factor must be positive");
  Camera c = camera;
  if (c.perspective) {
    for (int k = 0; k < 3; ++k) c.eye[k] = c.at[k] + (c.eye[k] - c.at[k]) / factor;
  } else {
    c.ortho_height /= factor;
  }
  return c;
}

Projector::Projector(const Camera& camera, int w, int h)
    : perspective(camera.perspective), width(w), height(h) {
  if (w < 1 || h < 1) throw std::invalid_argument("camera: image size must be at least 1x1");
  if (!basis(camera, right, up, forward))
    throw std::invalid_argument("camera: degenerate (eye equals at, or up parallel to the view direction)");
  for (int k = 0; k < 3; ++k) eye[k] = camera.eye[k];
  cx = 0.5 * w;
  cy = 0.5 * h;
  if (perspective) {
    if (!(camera.fov_deg > 0 && camera.fov_deg < 180))
      throw std::invalid_argument("camera: fov must be in (0, 180) degrees, not " +
                                  std::to_string(camera.fov_deg));
    focal = 0.5 * h / std::tan(0.5 * camera.fov_deg * kPi / 180);
  } else {
    if (!(camera.ortho_height > 0) || !std::isfinite(camera.ortho_height))
      throw std::invalid_argument("camera: orthographic height must be positive");
    scale = h / camera.ortho_height;
  }
}

void Projector::to_camera(const double p[3], double c[3]) const {
  double d[3] = {p[0] - eye[0], p[1] - eye[1], p[2] - eye[2]};
  c[0] = dot(d, right);
  c[1] = dot(d, up);
  c[2] = dot(d, forward);
}

void Projector::camera_to_pixel(const double c[3], double px[2]) const {
  if (perspective) {
    px[0] = cx + focal * c[0] / c[2];
    px[1] = cy - focal * c[1] / c[2];
  } else {
    px[0] = cx + scale * c[0];
    px[1] = cy - scale * c[1];
  }
}

bool Projector::project(const double p[3], double px[2], double* depth) const {
  double c[3];
  to_camera(p, c);
  if (depth != nullptr) *depth = c[2];
  if (perspective && !(c[2] > 0)) return false;
  camera_to_pixel(c, px);
  return true;
}

View view_of(const Camera& camera) {
  if (camera.perspective) return View::at(camera.eye[0], camera.eye[1], camera.eye[2]);
  return View::along(camera.at[0] - camera.eye[0], camera.at[1] - camera.eye[1],
                     camera.at[2] - camera.eye[2]);
}

Camera camera_from_options(const double lo[3], const double hi[3], double aspect, const double* eye,
                           const double* at, const double* up_given, double fov_deg, const double* dir) {
  const double up[3] = {up_given ? up_given[0] : 0.0, up_given ? up_given[1] : 0.0,
                        up_given ? up_given[2] : 1.0};
  Camera camera;
  if (dir != nullptr) {
    camera = fit_camera(lo, hi, dir, up, false, 30, aspect);
    if (at != nullptr) {
      for (int k = 0; k < 3; ++k) {
        camera.eye[k] += at[k] - camera.at[k];
        camera.at[k] = at[k];
      }
    }
    return camera;
  }
  const double fov = fov_deg > 0 ? fov_deg : 30;
  const double oblique[3] = {-1.0, 1.6, -0.9};  // from front-right, above
  camera = fit_camera(lo, hi, oblique, up, true, fov, aspect);
  const double centre[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  const double fitted_eye[3] = {camera.eye[0], camera.eye[1], camera.eye[2]};
  if (at != nullptr)
    for (int k = 0; k < 3; ++k) camera.at[k] = at[k];
  if (eye != nullptr) {
    for (int k = 0; k < 3; ++k) camera.eye[k] = eye[k];
  } else if (at != nullptr) {
    for (int k = 0; k < 3; ++k) camera.eye[k] = camera.at[k] + (fitted_eye[k] - centre[k]);
  }
  for (int k = 0; k < 3; ++k) camera.up[k] = up[k];
  // A default up (+z) along the given eye-to-target line (looking straight down or up) would be a
  // degenerate camera: take the axis least aligned with the line instead, as fit_camera does. An up
  // the user gave is kept, and Projector refuses it if it is parallel.
  double line[3] = {camera.at[0] - camera.eye[0], camera.at[1] - camera.eye[1], camera.at[2] - camera.eye[2]},
         r[3];
  cross(line, camera.up, r);
  if (up_given == nullptr && norm(line) > 0 && !(norm(r) > 1e-6 * norm(line))) {
    camera.up[0] = camera.up[1] = camera.up[2] = 0;
    camera.up[least_aligned_axis(line)] = 1;
  }
  return camera;
}

namespace {

// Barycentric coordinates of q in the tet with corners c (4 x 3): b[0] = 1 - b[1] - b[2] - b[3].
bool barycentric(const double c[4][3], const double q[3], double b[4]) {
  double e[3][3], r[3];
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) e[j][k] = c[j + 1][k] - c[0][k];
    r[k] = q[k] - c[0][k];
  }
  // Cramer's rule on the columns e[0], e[1], e[2].
  auto det = [](const double* a, const double* b2, const double* c2) {
    return a[0] * (b2[1] * c2[2] - b2[2] * c2[1]) - a[1] * (b2[0] * c2[2] - b2[2] * c2[0]) +
           a[2] * (b2[0] * c2[1] - b2[1] * c2[0]);
  };
  const double d = det(e[0], e[1], e[2]);
  if (!(d != 0) || !std::isfinite(d)) return false;
  b[1] = det(r, e[1], e[2]) / d;
  b[2] = det(e[0], r, e[2]) / d;
  b[3] = det(e[0], e[1], r) / d;
  b[0] = 1 - b[1] - b[2] - b[3];
  return true;
}

}  // namespace

bool pixel_point_in_tet(const MeshView& mesh, const Camera& camera, int width, int height, std::uint32_t t,
                        int x, int y, double bary[4], double shrink) {
  if (t >= mesh.tet_count()) return false;
  Projector p = [&] {
    try {
      return Projector(camera, width, height);
    } catch (const std::invalid_argument&) {
      return Projector(Camera{}, 1, 1);
    }
  }();
  if (p.width != width) return false;  // degenerate camera
  // The ray through the pixel's centre, in world coordinates (camera_to_pixel inverted).
  const double u = x + 0.5 - p.cx, v = p.cy - (y + 0.5);
  double o[3], d[3];
  for (int k = 0; k < 3; ++k) {
    if (p.perspective) {
      o[k] = p.eye[k];
      d[k] = p.right[k] * u / p.focal + p.up[k] * v / p.focal + p.forward[k];
    } else {
      o[k] = p.eye[k] + p.right[k] * u / p.scale + p.up[k] * v / p.scale;
      d[k] = p.forward[k];
    }
  }
  double c[4][3];
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k)
      c[i][k] = mesh.xyz[3 * std::size_t(mesh.tet[4 * std::size_t(t) + std::size_t(i)]) + std::size_t(k)];
  if (shrink != 1) {  // the tet as drawn: scaled about its centroid, as the rasterizer does
    for (int k = 0; k < 3; ++k) {
      const double centre = 0.25 * (c[0][k] + c[1][k] + c[2][k] + c[3][k]);
      for (int i = 0; i < 4; ++i) c[i][k] = centre + shrink * (c[i][k] - centre);
    }
  }
  const double od[3] = {o[0] + d[0], o[1] + d[1], o[2] + d[2]};
  double b0[4], b1[4];
  if (!barycentric(c, o, b0) || !barycentric(c, od, b1)) return false;
  // Inside where every b_i(s) = b0_i + s (b1_i - b0_i) >= 0: an interval of s; the entry is its start.
  double lo = p.perspective ? 0.0 : -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    const double db = b1[i] - b0[i];
    if (db > 0) lo = std::max(lo, -b0[i] / db);
    if (db < 0) hi = std::min(hi, -b0[i] / db);
  }
  if (p.perspective && hi < 0) return false;  // behind the eye
  double s = lo;
  if (!(lo <= hi))
    s = std::isfinite(hi) && std::isfinite(lo) ? 0.5 * (lo + hi) : (std::isfinite(hi) ? hi : lo);
  if (!std::isfinite(s)) return false;
  double sum = 0;
  for (int i = 0; i < 4; ++i) {
    bary[i] = std::max(0.0, b0[i] + s * (b1[i] - b0[i]));
    sum += bary[i];
  }
  if (!(sum > 0)) return false;
  for (int i = 0; i < 4; ++i) bary[i] /= sum;
  return true;
}

}  // namespace foxi
