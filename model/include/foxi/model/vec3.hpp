// Internal to foxi's libraries: the small 3-vector arithmetic that the mesher's PLC edits, the
// structure's solids, the elastic solver, tet quality and the camera share (it was written once in
// each). Plain std::array<double, 3>, no class: the callers keep their arrays; the same operations
// on raw double[3] (points read in place from Mesh::xyz, the camera's fields) below.
#pragma once

#include <array>
#include <cmath>

namespace foxi::detail {

using Vec3 = std::array<double, 3>;

inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm2(const Vec3& a) { return dot(a, a); }
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// On raw double[3]: a - b as a Vec3, and dot, cross (into r), length, normalize in place (false, and
// a unchanged, for a zero or non-finite length).
inline Vec3 sub(const double* a, const double* b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline void cross(const double* a, const double* b, double* r) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}
inline double norm(const double* a) { return std::sqrt(dot(a, a)); }
inline bool normalize(double* a) {
  const double n = norm(a);
  if (!(n > 0) || !std::isfinite(n)) return false;
  for (int k = 0; k < 3; ++k) a[k] /= n;
  return true;
}

}  // namespace foxi::detail
