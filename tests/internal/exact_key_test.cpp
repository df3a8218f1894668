// The exact power keys that resolve near ties (viz/src/exact.hpp), against keys computed here from
// first principles with rationals: the sphere from the linear system 2 (v_i - v_0) . c = |v_i|^2 -
// |v_0|^2 - (w_i - w_0), then |p - c|^2 - R^2 (perspective) or (c.d, |c|^2 - R^2) (orthographic), and
// a flat tet's centroid as a point sphere. Random tets (decided by the interval filter), exactly
// cospherical tets (the corners of a box: equal keys, the exact path), one-ulp perturbations of them
// (different keys closer than any float can tell), flat and weighted tets.
#include "exact.hpp"

#include <gtest/gtest.h>

#include <CGAL/Exact_rational.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace foxi {
namespace {

using Q = CGAL::Exact_rational;
using P = std::array<double, 3>;

struct Tet {
  std::array<P, 4> v;
  std::array<double, 4> w{};
  bool weighted = false;
};

// (first, second) of the key, lexicographic; perspective: second = 0.
std::pair<Q, Q> oracle(const Tet& t, bool perspective, const P& x) {
  Q m[3][3], r[3];
  for (int i = 0; i < 3; ++i) {
    Q n2i = 0, n20 = 0;
    for (int k = 0; k < 3; ++k) {
      m[i][k] = Q(2) * (Q(t.v[i + 1][k]) - Q(t.v[0][k]));
      n2i += Q(t.v[i + 1][k]) * Q(t.v[i + 1][k]);
      n20 += Q(t.v[0][k]) * Q(t.v[0][k]);
    }
    r[i] = n2i - n20 - (Q(t.w[i + 1]) - Q(t.w[0]));
  }
  auto det3 = [](Q a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  const Q d = det3(m);
  Q c[3], r2;
  if (CGAL::is_zero(d)) {  // flat: the centroid, radius 0
    for (int k = 0; k < 3; ++k) c[k] = (Q(t.v[0][k]) + Q(t.v[1][k]) + Q(t.v[2][k]) + Q(t.v[3][k])) / Q(4);
    r2 = 0;
  } else {
    for (int k = 0; k < 3; ++k) {  // Cramer
      Q mk[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) mk[i][j] = j == k ? r[i] : m[i][j];
      c[k] = det3(mk) / d;
    }
    r2 = -Q(t.w[0]);
    for (int k = 0; k < 3; ++k) r2 += (Q(t.v[0][k]) - c[k]) * (Q(t.v[0][k]) - c[k]);
  }
  if (perspective) {
    Q pw = -r2;
    for (int k = 0; k < 3; ++k) pw += (Q(x[k]) - c[k]) * (Q(x[k]) - c[k]);
    return {pw, Q(0)};
  }
  Q cd = 0, s = -r2;
  for (int k = 0; k < 3; ++k) {
    cd += c[k] * Q(x[k]);
    s += c[k] * c[k];
  }
  return {cd, s};
}

int oracle_compare(const Tet& a, const Tet& b, bool perspective, const P& x) {
  const auto ka = oracle(a, perspective, x), kb = oracle(b, perspective, x);
  if (ka < kb) return -1;
  if (kb < ka) return 1;
  return 0;
}

int foxi_compare(const Tet& a, const Tet& b, bool perspective, const P& x) {
  exact::PowerKey ka, kb;
  ka.set(a.v[0].data(), a.v[1].data(), a.v[2].data(), a.v[3].data(), a.weighted ? a.w.data() : nullptr,
         perspective, x.data());
  kb.set(b.v[0].data(), b.v[1].data(), b.v[2].data(), b.v[3].data(), b.weighted ? b.w.data() : nullptr,
         perspective, x.data());
  return ka.compare(kb);
}

void expect_agree(const std::vector<Tet>& tets, std::mt19937& rng, int views, int* ties = nullptr) {
  std::uniform_real_distribution<double> u(-3, 3);
  for (int view = 0; view < views; ++view) {
    const bool perspective = view % 2 == 0;
    const P x{u(rng), u(rng), u(rng)};
    for (std::size_t i = 0; i < tets.size(); ++i)
      for (std::size_t j = i + 1; j < tets.size(); ++j) {
        const int expect = oracle_compare(tets[i], tets[j], perspective, x);
        ASSERT_EQ(foxi_compare(tets[i], tets[j], perspective, x), expect)
            << "tets " << i << ", " << j << (perspective ? " eye " : " dir ") << x[0] << " " << x[1] << " "
            << x[2];
        ASSERT_EQ(foxi_compare(tets[j], tets[i], perspective, x), -expect);
        if (ties && expect == 0) ++*ties;
      }
  }
}

TEST(ExactKey, RandomTetsAgreeWithRationalKeys) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Tet> tets(24);
  for (Tet& t : tets)
    for (P& p : t.v) p = {u(rng), u(rng), u(rng)};
  expect_agree(tets, rng, 8);
}

TEST(ExactKey, CospherialCornersTieAndOneUlpApartDoNot) {
  // Tets on the corners of a 1 x 2 x 3 box share its circumsphere: equal keys from every point.
  const double X = 0.1, Y = 0.7, Z = 0.3;
  std::vector<P> corner;
  for (int i = 0; i < 8; ++i)
    corner.push_back({X + (i & 1), Y + 2.0 * ((i >> 1) & 1), Z + 3.0 * ((i >> 2) & 1)});
  std::vector<Tet> tets;
  for (const auto& q : std::vector<std::array<int, 4>>{
           {0, 1, 2, 4}, {7, 6, 5, 3}, {1, 2, 4, 7}, {0, 3, 5, 6}, {0, 1, 3, 5}}) {
    Tet t;
    for (int k = 0; k < 4; ++k) t.v[std::size_t(k)] = corner[std::size_t(q[std::size_t(k)])];
    tets.push_back(t);
  }
  // The same tets with one corner moved by one ulp: spheres that differ below any float key's resolution.
  for (std::size_t i = 0; i < 5; ++i) {
    Tet t = tets[i];
    t.v[0][i % 3] = std::nextafter(t.v[0][i % 3], 10.0);
    tets.push_back(t);
  }
  std::mt19937 rng(3);
  int ties = 0;
  expect_agree(tets, rng, 12, &ties);
  EXPECT_GE(ties, 12 * 10);  // the five cospherical tets tie pairwise in every view
}

TEST(ExactKey, FlatAndWeightedTets) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Tet> tets;
  for (int i = 0; i < 6; ++i) {  // flat: four points in the plane z = i / 8
    Tet t;
    for (P& p : t.v) p = {u(rng), u(rng), i / 8.0};
    tets.push_back(t);
  }
  for (int i = 0; i < 10; ++i) {  // weighted (orthospheres), weights up to a quarter of the spread squared
    Tet t;
    for (P& p : t.v) p = {u(rng), u(rng), u(rng)};
    for (double& w : t.w) w = 0.25 * u(rng);
    t.weighted = true;
    tets.push_back(t);
  }
  expect_agree(tets, rng, 10);
}

}  // namespace
}  // namespace foxi
