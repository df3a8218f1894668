// Internal to foxi's libraries: the small 3-vector arithmetic that the mesher's PLC edits, the
// structure's solids and the elastic solver share (it was written once in each). Plain
// std::array<double, 3>, no class: the callers keep their arrays.
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

}  // namespace foxi::detail
