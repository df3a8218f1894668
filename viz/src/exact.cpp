#include "exact.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

namespace foxi::exact {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Q = CGAL::Exact_rational;

namespace {

K::Point_3 pt(const double* p) { return K::Point_3(p[0], p[1], p[2]); }

struct QVec {
  Q x, y, z;
};
QVec qv(const double* p) { return {Q(p[0]), Q(p[1]), Q(p[2])}; }
QVec sub(const QVec& a, const QVec& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
QVec cross(const QVec& a, const QVec& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Q dot(const QVec& a, const QVec& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
QVec scale(const QVec& a, const Q& s) { return {a.x * s, a.y * s, a.z * s}; }
QVec add(const QVec& a, const QVec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

// Exact centre offset o (relative to a) of the tet; false if flat.
bool centre_offset(const double* a, const double* b, const double* c, const double* d, const double* w,
                   QVec& A, QVec& o) {
  A = qv(a);
  QVec B = sub(qv(b), A), C = sub(qv(c), A), D = sub(qv(d), A);
  Q det = dot(B, cross(C, D));
  if (CGAL::is_zero(det)) return false;
  Q lb = dot(B, B), lc = dot(C, C), ld = dot(D, D);
  if (w != nullptr) {
    Q w0(w[0]);
    lb = lb - Q(w[1]) + w0;
    lc = lc - Q(w[2]) + w0;
    ld = ld - Q(w[3]) + w0;
  }
  QVec num = add(add(scale(cross(C, D), lb), scale(cross(D, B), lc)), scale(cross(B, C), ld));
  o = scale(num, Q(1) / (Q(2) * det));
  return true;
}

}  // namespace

bool centre(const double* a, const double* b, const double* c, const double* d, const double* w,
            double* c_out, double& s_out) {
  QVec A, o;
  if (!centre_offset(a, b, c, d, w, A, o)) return false;
  QVec cc = add(A, o);
  Q s = dot(A, A) + Q(2) * dot(A, o);
  if (w != nullptr) s = s + Q(w[0]);
  c_out[0] = CGAL::to_double(cc.x);
  c_out[1] = CGAL::to_double(cc.y);
  c_out[2] = CGAL::to_double(cc.z);
  s_out = CGAL::to_double(s);
  return true;
}

int orientation(const double* a, const double* b, const double* c, const double* p) {
  return static_cast<int>(CGAL::orientation(pt(a), pt(b), pt(c), pt(p)));
}

int orientation_at_infinity(const double* a, const double* b, const double* c, const double* v) {
  // Filter in double: |error| of n.v is below 8 eps |b-a| |c-a| |v|.
  double u1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  double u2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  double n[3] = {u1[1] * u2[2] - u1[2] * u2[1], u1[2] * u2[0] - u1[0] * u2[2], u1[0] * u2[1] - u1[1] * u2[0]};
  double dv = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
  double mag = (std::abs(u1[0]) + std::abs(u1[1]) + std::abs(u1[2])) *
               (std::abs(u2[0]) + std::abs(u2[1]) + std::abs(u2[2])) *
               (std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2]));
  if (std::abs(dv) > 1e-14 * mag) return dv > 0 ? 1 : -1;
  QVec A = qv(a);
  Q r = dot(cross(sub(qv(b), A), sub(qv(c), A)), qv(v));
  return CGAL::sign(r);
}

int in_sphere(const double* a, const double* b, const double* c, const double* d, const double* q,
              const double* w, double wq) {
  if (w == nullptr) {
    // CGAL: ON_POSITIVE_SIDE = inside for a positively oriented tet.
    return static_cast<int>(CGAL::side_of_oriented_sphere(pt(a), pt(b), pt(c), pt(d), pt(q)));
  }
  using WP = K::Weighted_point_3;
  // CGAL's power test: ON_POSITIVE_SIDE when q has negative power distance to the orthosphere.
  return static_cast<int>(CGAL::power_side_of_oriented_power_sphere(
      WP(pt(a), w[0]), WP(pt(b), w[1]), WP(pt(c), w[2]), WP(pt(d), w[3]), WP(pt(q), wq)));
}

struct PowerKey::Impl {
  Q first;   // perspective: the power; orthographic: c.d
  Q second;  // orthographic: s
};

PowerKey::PowerKey() : impl_(std::make_unique<Impl>()) {}
PowerKey::~PowerKey() = default;
PowerKey::PowerKey(PowerKey&&) noexcept = default;
PowerKey& PowerKey::operator=(PowerKey&&) noexcept = default;

void PowerKey::set(const double* a, const double* b, const double* c, const double* d, const double* w,
                   bool perspective, const double* v) {
  QVec A, o;
  Q w0 = w != nullptr ? Q(w[0]) : Q(0);
  if (!centre_offset(a, b, c, d, w, A, o)) {
    // Flat tet: a point sphere at the centroid (see spheres.hpp).
    QVec sum = add(add(qv(a), qv(b)), add(qv(c), qv(d)));
    QVec cen = scale(sum, Q(1, 4));
    A = cen;
    o = QVec{Q(0), Q(0), Q(0)};
    w0 = Q(0);
  }
  QVec V = qv(v);
  if (perspective) {
    QVec pa = sub(V, A);
    impl_->first = dot(pa, pa) - Q(2) * dot(pa, o) + w0;  // |p-c|^2 - R^2
    impl_->second = Q(0);
  } else {
    QVec cc = add(A, o);
    impl_->first = dot(cc, V);
    impl_->second = dot(A, A) + Q(2) * dot(A, o) + w0;
  }
}

int PowerKey::compare(const PowerKey& other) const {
  if (impl_->first < other.impl_->first) return -1;
  if (other.impl_->first < impl_->first) return 1;
  if (impl_->second < other.impl_->second) return -1;
  if (other.impl_->second < impl_->second) return 1;
  return 0;
}

}  // namespace foxi::exact
