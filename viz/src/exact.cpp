#include "exact.hpp"

#include <cmath>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>
#include <CGAL/Gmpzf.h>
#include <CGAL/Interval_nt.h>

#include <type_traits>

namespace foxi::exact {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Q = CGAL::Exact_rational;

namespace {

K::Point_3 pt(const double* p) { return K::Point_3(p[0], p[1], p[2]); }

// 3-vectors over the number types below: rationals, intervals, exact binary floats.
template <class T>
struct V3 {
  T x, y, z;
};
template <class T>
V3<T> vec(const double* p) {
  return {T(p[0]), T(p[1]), T(p[2])};
}
template <class T>
V3<T> sub(const V3<T>& a, const V3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
V3<T> add(const V3<T>& a, const V3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
T dot(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
V3<T> scale(const V3<T>& a, const std::type_identity_t<T>& s) {  // s may be an expression template
  return {a.x * s, a.y * s, a.z * s};
}
using QVec = V3<Q>;
QVec qv(const double* p) { return vec<Q>(p); }

// Exact centre offset o (relative to a) of the tet; false if flat.
bool centre_offset(const double* a, const double* b, const double* c, const double* d, const double* w,
                   QVec& A, QVec& o) {
  // A NaN or infinity has no exact value (GMP raises SIGFPE converting it): no sphere, like a flat tet.
  for (const double* p : {a, b, c, d})
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) return false;
  if (w != nullptr &&
      !(std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]) && std::isfinite(w[3])))
    return false;
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

namespace {

// The key in interval arithmetic (the caller holds the rounding mode upward): the same formulas as
// PowerKey's exact ones. False when the tet's determinant may be zero (the exact path decides
// whether it is flat).
using I = CGAL::Interval_nt<false>;
using IVec = V3<I>;
IVec iv(const double* p) { return vec<I>(p); }

bool interval_key(const double* a, const double* b, const double* c, const double* d, const double* w,
                  bool perspective, const double* v, I& first, I& second) {
  const IVec A = iv(a), B = sub(iv(b), A), C = sub(iv(c), A), D = sub(iv(d), A);
  const I det = dot(B, cross(C, D));
  if (!(det.inf() > 0 || det.sup() < 0)) return false;
  I lb = dot(B, B), lc = dot(C, C), ld = dot(D, D), w0(0);
  if (w != nullptr) {
    w0 = I(w[0]);
    lb = lb - I(w[1]) + w0;
    lc = lc - I(w[2]) + w0;
    ld = ld - I(w[3]) + w0;
  }
  const IVec num = add(add(scale(cross(C, D), lb), scale(cross(D, B), lc)), scale(cross(B, C), ld));
  const IVec o = scale(num, I(1) / (I(2) * det));
  const IVec V = iv(v);
  if (perspective) {
    const IVec pa = sub(V, A);
    first = dot(pa, pa) - I(2) * dot(pa, o) + w0;
    second = I(0);
  } else {
    first = dot(add(A, o), V);
    second = dot(A, A) + I(2) * dot(A, o) + w0;
  }
  return true;
}

// -1, 0, +1 as a < b, a == b, a > b when the intervals decide it; 2 when they do not.
int interval_compare(const I& a, const I& b) {
  if (a.sup() < b.inf()) return -1;
  if (b.sup() < a.inf()) return 1;
  if (a.is_point() && b.is_point()) return 0;  // overlapping points: equal
  return 2;
}

}  // namespace

// Near ties are re-compared in interval arithmetic first (a few hundred flops); only when the
// intervals of two keys overlap (equal spheres: the tets of a faceted ball whose four corners lie on
// the ball) is the key computed exactly, as a fraction n / d of exact binary floats (Gmpzf: products
// and sums without the gcds of rationals, which made a bga view 2 us per tet).
using Z = CGAL::Gmpzf;
using ZVec = V3<Z>;
namespace {
ZVec zv(const double* p) { return vec<Z>(p); }

// n / d with d > 0.
struct Fraction {
  Z n, d;
};
Fraction fraction(Z n, Z d) {
  if (CGAL::is_negative(d)) return {-n, -d};
  return {std::move(n), std::move(d)};
}
int compare_fractions(const Fraction& a, const Fraction& b) {
  const Z l = a.n * b.d, r = b.n * a.d;
  return l < r ? -1 : (r < l ? 1 : 0);
}
}  // namespace

struct PowerKey::Impl {
  double p[4][3]{};
  double w[4]{};
  bool weighted = false, perspective = false;
  double v[3]{};
  bool filtered = false;  // the intervals below hold the key
  I first_i, second_i;
  bool exact = false;  // the fractions below hold the key
  Fraction first;      // perspective: the power; orthographic: c.d
  Fraction second;     // orthographic: s

  void make_exact();
};

PowerKey::PowerKey() : impl_(std::make_unique<Impl>()) {}
PowerKey::~PowerKey() = default;
PowerKey::PowerKey(PowerKey&&) noexcept = default;
PowerKey& PowerKey::operator=(PowerKey&&) noexcept = default;

void PowerKey::set(const double* a, const double* b, const double* c, const double* d, const double* w,
                   bool perspective, const double* v) {
  Impl& k = *impl_;
  for (int i = 0; i < 3; ++i) {
    k.p[0][i] = a[i];
    k.p[1][i] = b[i];
    k.p[2][i] = c[i];
    k.p[3][i] = d[i];
    k.v[i] = v[i];
  }
  k.weighted = w != nullptr;
  for (int i = 0; i < 4; ++i) k.w[i] = w != nullptr ? w[i] : 0;
  k.perspective = perspective;
  k.exact = false;
  CGAL::Protect_FPU_rounding<true> upward;
  k.filtered = interval_key(a, b, c, d, w, perspective, v, k.first_i, k.second_i);
}

// The formulas of interval_key over the common denominator det: with o = num / (2 det),
// perspective |p-a|^2 - 2 (p-a).o + w0 = (|p-a|^2 det - (p-a).num + w0 det) / det; orthographic
// (a + o).v = (2 det a.v + num.v) / (2 det) and |a|^2 + 2 a.o + w0 = (|a|^2 det + a.num + w0 det) / det.
// A flat tet is a point sphere at its centroid g = sum / 4 (see spheres.hpp), without weight.
void PowerKey::Impl::make_exact() {
  if (exact) return;
  exact = true;
  const ZVec A = zv(p[0]), B = sub(zv(p[1]), A), C = sub(zv(p[2]), A), D = sub(zv(p[3]), A), V = zv(v);
  const Z det = dot(B, cross(C, D));
  if (CGAL::is_zero(det)) {
    const ZVec sum = add(add(A, zv(p[1])), add(zv(p[2]), zv(p[3])));
    if (perspective) {
      const ZVec d4 = sub(scale(V, Z(4)), sum);  // 4 (p - g)
      first = fraction(dot(d4, d4), Z(16));
      second = fraction(Z(0), Z(1));
    } else {
      first = fraction(dot(sum, V), Z(4));
      second = fraction(dot(sum, sum), Z(16));
    }
    return;
  }
  Z lb = dot(B, B), lc = dot(C, C), ld = dot(D, D), w0(0);
  if (weighted) {
    w0 = Z(w[0]);
    lb = lb - Z(w[1]) + w0;
    lc = lc - Z(w[2]) + w0;
    ld = ld - Z(w[3]) + w0;
  }
  const ZVec num = add(add(scale(cross(C, D), lb), scale(cross(D, B), lc)), scale(cross(B, C), ld));
  if (perspective) {
    const ZVec pa = sub(V, A);
    first = fraction(dot(pa, pa) * det - dot(pa, num) + w0 * det, det);
    second = fraction(Z(0), Z(1));
  } else {
    first = fraction(Z(2) * det * dot(A, V) + dot(num, V), Z(2) * det);
    second = fraction(dot(A, A) * det + dot(A, num) + w0 * det, det);
  }
}

int PowerKey::compare(const PowerKey& other) const {
  Impl &x = *impl_, &y = *other.impl_;
  if (x.filtered && y.filtered) {
    int c = interval_compare(x.first_i, y.first_i);
    if (c == 0) c = interval_compare(x.second_i, y.second_i);
    if (c != 2) return c;
  }
  x.make_exact();
  y.make_exact();
  const int c = compare_fractions(x.first, y.first);
  return c != 0 ? c : compare_fractions(x.second, y.second);
}

}  // namespace foxi::exact
