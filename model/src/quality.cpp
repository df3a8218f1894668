// Tet shape quality: radius-edge ratio and minimum dihedral angle, in double.
#include "foxi/model/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "foxi/model/vec3.hpp"

namespace foxi {
namespace {

using V3 = detail::Vec3;  // foxi/model/vec3.hpp
using detail::cross;
using detail::dot;
using detail::norm;
using detail::sub;

void add(Stat& s, double v, std::size_t i) {
  if (i == 0) s.min = s.max = v;
  s.min = std::min(s.min, v);
  s.max = std::max(s.max, v);
  s.mean += v;  // divided by the count at the end
}

}  // namespace

TetQuality tet_quality(const double* p0, const double* p1, const double* p2, const double* p3) {
  TetQuality q;
  const double* p[4] = {p0, p1, p2, p3};
  const V3 B = sub(p1, p0), C = sub(p2, p0), D = sub(p3, p0);
  const double det = dot(B, cross(C, D));
  q.volume = det / 6;
  double lmin = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) lmin = std::min(lmin, norm(sub(p[j], p[i])));
  if (det == 0 || !(lmin > 0)) {
    q.radius_edge = std::numeric_limits<double>::infinity();
    q.min_dihedral_deg = 0;
    return q;
  }
  // Circumcentre relative to p0: x = (|B|^2 C x D + |C|^2 D x B + |D|^2 B x C) / (2 B . C x D).
  const V3 cd = cross(C, D), db = cross(D, B), bc = cross(B, C);
  const double lb = dot(B, B), lc = dot(C, C), ld = dot(D, D);
  const V3 num = {lb * cd[0] + lc * db[0] + ld * bc[0], lb * cd[1] + lc * db[1] + ld * bc[1],
                  lb * cd[2] + lc * db[2] + ld * bc[2]};
  q.radius_edge = norm(num) / (2 * std::abs(det)) / lmin;

  // Outward area normals of the faces (face k is opposite vertex k); the dihedral angle at the edge
  // shared by faces k and l is pi minus the angle between their outward normals.
  V3 n[4];
  for (int k = 0; k < 4; ++k) {
    const double* a = p[(k + 1) % 4];
    const double* b = p[(k + 2) % 4];
    const double* c = p[(k + 3) % 4];
    n[k] = cross(sub(b, a), sub(c, a));
    if (dot(n[k], sub(p[k], a)) > 0) n[k] = {-n[k][0], -n[k][1], -n[k][2]};
  }
  double amin = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) {
      // atan2 of |n_k x n_l| and -n_k . n_l: accurate for angles near 0 and pi.
      const double a = std::atan2(norm(cross(n[k], n[l])), -dot(n[k], n[l]));
      amin = std::min(amin, a);
    }
  q.min_dihedral_deg = amin * 180 / std::numbers::pi;
  return q;
}

QualitySummary summarize_quality(const Mesh& mesh) {
  QualitySummary s;
  const std::size_t nv = mesh.node_count();
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    if (v[0] >= nv || v[1] >= nv || v[2] >= nv || v[3] >= nv) continue;  // see validate()
    const TetQuality q =
        tet_quality(&mesh.xyz[3 * v[0]], &mesh.xyz[3 * v[1]], &mesh.xyz[3 * v[2]], &mesh.xyz[3 * v[3]]);
    add(s.volume, q.volume, s.tets);
    add(s.radius_edge, q.radius_edge, s.tets);
    add(s.min_dihedral_deg, q.min_dihedral_deg, s.tets);
    s.total_volume += std::abs(q.volume);
    if (q.min_dihedral_deg < 5) ++s.slivers;
    ++s.tets;
  }
  if (s.tets > 0) {
    const double n = static_cast<double>(s.tets);
    s.volume.mean /= n;
    s.radius_edge.mean /= n;
    s.min_dihedral_deg.mean /= n;
  }
  return s;
}

}  // namespace foxi
