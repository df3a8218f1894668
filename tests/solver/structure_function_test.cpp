// The structure function recovered from a known Cauer RC ladder: its Zth(t) computed exactly (the
// generalized eigenproblem G v = lambda C v of the ladder's conductance and capacitance matrices,
// Eigen's dense solver) and checked against an independent time integration of C dT/dt = -G T + P e1;
// Foster -> Cauer of the exact Foster network gives the ladder back to 1e-6; the whole chain from
// sampled Zth (NNLS fit, then Cauer) gives the total resistance to 0.5 % and the cumulative
// capacitance in the middle of each stage's resistance to 10 % (4 % seen).
#include "foxi/solver/structure_function.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace foxi {
namespace {

struct Ladder {
  std::vector<double> r, c;  // stage i: C_i at node i, R_i from node i to node i+1 (the last to ambient)
};

Eigen::MatrixXd conductance(const Ladder& l) {
  const auto n = Eigen::Index(l.r.size());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double gi = 1 / l.r[std::size_t(i)];
    g(i, i) += gi;
    if (i + 1 < n) {
      g(i + 1, i + 1) += gi;
      g(i, i + 1) -= gi;
      g(i + 1, i) -= gi;
    }
  }
  return g;
}

// Zth(t) = e1' T(t) for a unit step of power into node 1: Foster terms from G v = lambda C v with
// v' C v = 1, R_k = v_1k^2 / lambda_k, tau_k = 1 / lambda_k.
std::vector<FosterTerm> exact_foster(const Ladder& l) {
  const Eigen::MatrixXd g = conductance(l);
  const Eigen::MatrixXd c = Eigen::VectorXd::Map(l.c.data(), Eigen::Index(l.c.size())).asDiagonal();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(g, c);
  std::vector<FosterTerm> f;
  for (Eigen::Index k = 0; k < g.rows(); ++k) {
    const double lambda = es.eigenvalues()[k], v = es.eigenvectors()(0, k);
    f.push_back({v * v / lambda, 1 / lambda});
  }
  return f;
}

// The junction's temperature rise by backward Euler with tiny steps (independent of the eigensolver).
double integrate_zth(const Ladder& l, double t_end, int steps) {
  const Eigen::MatrixXd g = conductance(l);
  const auto n = g.rows();
  const double dt = t_end / steps;
  Eigen::MatrixXd m = g;
  for (Eigen::Index i = 0; i < n; ++i) m(i, i) += l.c[std::size_t(i)] / dt;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(m);
  Eigen::VectorXd temp = Eigen::VectorXd::Zero(n), rhs(n);
  for (int s = 0; s < steps; ++s) {
    for (Eigen::Index i = 0; i < n; ++i) rhs[i] = l.c[std::size_t(i)] / dt * temp[i] + (i == 0 ? 1.0 : 0.0);
    temp = lu.solve(rhs);
  }
  return temp[0];
}

// Stage time constants about 50 x apart, like die, attach, spreader, heat sink.
const Ladder kLadder{{0.2, 0.5, 1.0, 2.0}, {1e-4, 2e-3, 5e-2, 1.0}};

TEST(StructureFunction, ExactFosterOfTheLadderMatchesATimeIntegration) {
  const std::vector<FosterTerm> f = exact_foster(kLadder);
  double total = 0;
  for (const FosterTerm& t : f) total += t.r;
  EXPECT_NEAR(total, 3.7, 1e-9);  // Zth(infinity) = sum of the ladder's R
  // Backward Euler is first order: steps fine enough for 1e-3 relative.
  for (double t : {1e-4, 3e-3, 0.1, 2.0}) {
    const int steps = 20000;
    EXPECT_NEAR(foster_zth(f, t), integrate_zth(kLadder, t, steps), 2e-3 * foster_zth(f, t)) << t;
  }
}

TEST(StructureFunction, FosterToCauerGivesTheLadderBack) {
  for (const Ladder& l : {kLadder, Ladder{{1.0}, {0.5}},
                          Ladder{{0.1, 0.3, 0.2, 0.6, 1.5, 0.4}, {1e-5, 1e-4, 3e-3, 1e-2, 0.2, 4.0}}}) {
    const std::vector<CauerStage> cauer = foster_to_cauer(exact_foster(l));
    ASSERT_EQ(cauer.size(), l.r.size());
    for (std::size_t i = 0; i < cauer.size(); ++i) {
      EXPECT_NEAR(cauer[i].r, l.r[i], 1e-6 * l.r[i]) << "stage " << i;
      EXPECT_NEAR(cauer[i].c, l.c[i], 1e-6 * l.c[i]) << "stage " << i;
    }
  }
  // A single Foster term is a single Cauer stage: R, C = tau / R.
  const std::vector<FosterTerm> one{{2.0, 0.5}};
  const auto c = foster_to_cauer(one);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].r, 2.0, 1e-12);
  EXPECT_NEAR(c[0].c, 0.25, 1e-12);
  const std::vector<FosterTerm> bad{{-1.0, 0.5}};
  EXPECT_THROW(foster_to_cauer(bad), std::invalid_argument);
}

// C_sum at cumulative resistance x: the staircase of structure_function.hpp.
double c_sum_at(const StructureFunction& s, double x) {
  for (std::size_t i = 0; i < s.cumulative_r.size(); ++i)
    if (x < s.cumulative_r[i]) return s.cumulative_c[i];
  return s.cumulative_c.empty() ? 0 : s.cumulative_c.back();
}

void expect_recovered(const StructureFunction& s, const Ladder& l, double r_tol, double c_tol) {
  double total = 0, cum_c = 0, start = 0;
  for (double r : l.r) total += r;
  ASSERT_FALSE(s.cumulative_r.empty());
  EXPECT_NEAR(s.cumulative_r.back(), total, r_tol * total);
  for (std::size_t i = 0; i < l.r.size(); ++i) {
    cum_c += l.c[i];
    const double mid = start + l.r[i] / 2;
    EXPECT_NEAR(c_sum_at(s, mid), cum_c, c_tol * cum_c) << "stage " << i << " at R_sum " << mid;
    if (std::getenv("FOXI_TEST_VERBOSE"))
      std::printf("stage %zu: C_sum %.4g, recovered %.4g\n", i, cum_c, c_sum_at(s, mid));
    start += l.r[i];
  }
}

TEST(StructureFunction, RecoveredFromSampledZth) {
  const std::vector<FosterTerm> f = exact_foster(kLadder);
  // Log-spaced samples, 20 a decade, from well below the fastest to well beyond the slowest stage.
  std::vector<double> t, z;
  for (int i = 0; i <= 20 * 10; ++i) {
    t.push_back(1e-7 * std::pow(10.0, i / 20.0));
    z.push_back(foster_zth(f, t.back()));
  }
  const StructureFunction s = structure_function(t, z);
  EXPECT_LT(s.fit.max_error, 1e-3 * 3.7);
  EXPECT_LT(std::abs(s.settled), 1e-6);
  expect_recovered(s, kLadder, 5e-3, 0.10);
  // Uniform steps, as the transient solver writes them (dt = 1e-5 s up to 20 s: 2e6 samples would be
  // too many for the test; 1e-4 s steps from 1e-4 s), and a Zth that has settled.
  std::vector<double> tu, zu;
  for (int i = 1; i <= 200000; i += (i < 1000 ? 1 : 97)) {
    tu.push_back(1e-4 * i);
    zu.push_back(foster_zth(f, tu.back()));
  }
  const StructureFunction su = structure_function(tu, zu);
  EXPECT_LT(su.fit.max_error, 1e-3 * 3.7);
  // The first stage (tau ~ 2e-5 s) is faster than the first sample: only its sum is seen.
  double total = 3.7;
  EXPECT_NEAR(su.cumulative_r.back(), total, 5e-3 * total);
  // Cut off before the last stage settles: the rise is reported.
  std::vector<double> tc(t.begin(), t.begin() + 20 * 6), zc(z.begin(), z.begin() + 20 * 6);
  EXPECT_GT(structure_function(tc, zc).settled, 0.01);
  EXPECT_THROW(structure_function(std::vector<double>{1, 2}, std::vector<double>{1, 2}),
               std::invalid_argument);
  EXPECT_THROW(structure_function(std::vector<double>{1, 1, 2}, std::vector<double>{1, 2, 3}),
               std::invalid_argument);
}

}  // namespace
}  // namespace foxi
