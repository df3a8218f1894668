// Foster fit (NNLS, Lawson-Hanson) and Foster -> Cauer (Lanczos) of structure_function.hpp.
#include "foxi/solver/structure_function.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace foxi {

namespace {

// min ||A x - b|| over x >= 0 (Lawson and Hanson, "Solving Least Squares Problems", ch. 23): the
// passive set grows by the column of the largest gradient; each subproblem is solved by QR on the
// passive columns (not the normal equations: exponential columns are nearly dependent).
Eigen::VectorXd nnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  const Eigen::Index n = a.cols();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(std::size_t(n), false);
  const double tol = 1e-12 * std::max(1.0, a.norm() * b.norm());
  for (int outer = 0; outer < 3 * n + 10; ++outer) {
    const Eigen::VectorXd w = a.transpose() * (b - a * x);
    Eigen::Index j = -1;
    for (Eigen::Index i = 0; i < n; ++i)
      if (!passive[std::size_t(i)] && w[i] > tol && (j < 0 || w[i] > w[j])) j = i;
    if (j < 0) break;
    passive[std::size_t(j)] = true;
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      std::vector<Eigen::Index> p;
      for (Eigen::Index i = 0; i < n; ++i)
        if (passive[std::size_t(i)]) p.push_back(i);
      Eigen::MatrixXd ap(a.rows(), Eigen::Index(p.size()));
      for (std::size_t k = 0; k < p.size(); ++k) ap.col(Eigen::Index(k)) = a.col(p[k]);
      const Eigen::VectorXd sp = ap.colPivHouseholderQr().solve(b);
      Eigen::VectorXd s = Eigen::VectorXd::Zero(n);
      for (std::size_t k = 0; k < p.size(); ++k) s[p[k]] = sp[Eigen::Index(k)];
      bool positive = true;
      for (Eigen::Index i : p) positive = positive && s[i] > 0;
      if (positive) {
        x = s;
        break;
      }
      // Step from x towards s as far as x stays >= 0; the variables that reach 0 leave the set.
      double alpha = 1;
      for (Eigen::Index i : p)
        if (s[i] <= 0) alpha = std::min(alpha, x[i] / (x[i] - s[i]));
      x += alpha * (s - x);
      for (Eigen::Index i : p)
        if (x[i] <= 1e-15 * std::max(1.0, x.cwiseAbs().maxCoeff())) {
          x[i] = 0;
          passive[std::size_t(i)] = false;
        }
    }
  }
  return x;
}

void check_samples(std::span<const double> t, std::span<const double> z) {
  if (t.size() != z.size())
    throw std::invalid_argument("Zth fit: " + std::to_string(t.size()) + " times and " +
                                std::to_string(z.size()) + " values");
  if (t.size() < 3) throw std::invalid_argument("Zth fit: needs at least 3 samples");
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || !std::isfinite(z[i]))
      throw std::invalid_argument("Zth fit: sample " + std::to_string(i) + " is not finite");
    if (!(t[i] > 0) || (i > 0 && !(t[i] > t[i - 1])))
      throw std::invalid_argument("Zth fit: the times must be positive and increasing (sample " +
                                  std::to_string(i) + ")");
  }
}

}  // namespace

double foster_zth(std::span<const FosterTerm> foster, double t) {
  double z = 0;
  for (const FosterTerm& f : foster) z += f.r * -std::expm1(-t / f.tau);
  return z;
}

FosterFit fit_foster(std::span<const double> t, std::span<const double> z, const FosterFitParams& p) {
  check_samples(t, z);
  if (p.per_decade < 1 || p.per_decade > 100)
    throw std::invalid_argument("Zth fit: per_decade must be 1 to 100");
  const double lo = p.tau_min > 0 ? p.tau_min : t.front() / 30, hi = p.tau_max > 0 ? p.tau_max : t.back() * 3;
  if (!(lo < hi)) throw std::invalid_argument("Zth fit: the time-constant range is empty");
  const int count = std::max(2, int(std::ceil(std::log10(hi / lo) * p.per_decade)) + 1);
  std::vector<double> tau(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) tau[std::size_t(i)] = lo * std::pow(hi / lo, double(i) / (count - 1));
  // Weights: the square root of each sample's share of log time (half the log-distance to each
  // neighbour), so the fit is least squares over log time.
  const std::size_t m = t.size();
  Eigen::MatrixXd a(static_cast<Eigen::Index>(m), count);
  Eigen::VectorXd b(static_cast<Eigen::Index>(m));
  for (std::size_t n = 0; n < m; ++n) {
    const double left = n > 0 ? std::log(t[n] / t[n - 1]) : std::log(t[1] / t[0]);
    const double right = n + 1 < m ? std::log(t[n + 1] / t[n]) : left;
    const double w = std::sqrt(0.5 * (left + right));
    for (int i = 0; i < count; ++i) a(Eigen::Index(n), i) = w * -std::expm1(-t[n] / tau[std::size_t(i)]);
    b[Eigen::Index(n)] = w * z[n];
  }
  const Eigen::VectorXd r = nnls(a, b);
  FosterFit fit;
  for (int i = 0; i < count; ++i)
    if (r[i] > 0) fit.terms.push_back({r[i], tau[std::size_t(i)]});
  double sq = 0;
  for (std::size_t n = 0; n < m; ++n) {
    const double e = foster_zth(fit.terms, t[n]) - z[n];
    sq += e * e;
    fit.max_error = std::max(fit.max_error, std::abs(e));
  }
  fit.rms_error = std::sqrt(sq / double(m));
  return fit;
}

std::vector<CauerStage> foster_to_cauer(std::span<const FosterTerm> foster) {
  using real = long double;
  std::vector<FosterTerm> f;
  for (const FosterTerm& term : foster) {
    if (!std::isfinite(term.r) || !std::isfinite(term.tau) || term.r < 0 || term.tau < 0)
      throw std::invalid_argument("Foster to Cauer: a term with R = " + std::to_string(term.r) +
                                  " K/W, tau = " + std::to_string(term.tau) + " s");
    if (term.r > 0 && term.tau > 0) f.push_back(term);
  }
  std::sort(f.begin(), f.end(), [](const FosterTerm& a, const FosterTerm& b) { return a.tau < b.tau; });
  const std::size_t n = f.size();
  std::vector<CauerStage> out;
  if (n == 0) return out;
  // A's eigenvalues 1/tau_k, start vector q_k = sqrt(C1 R_k / tau_k) with C1 = 1 / sum(R_k / tau_k).
  std::vector<real> lambda(n), q0(n);
  real sum = 0;
  for (std::size_t k = 0; k < n; ++k) {
    lambda[k] = 1 / real(f[k].tau);
    sum += real(f[k].r) / real(f[k].tau);
  }
  const real c1 = 1 / sum;
  for (std::size_t k = 0; k < n; ++k) q0[k] = std::sqrt(c1 * real(f[k].r) / real(f[k].tau));
  // Lanczos with full reorthogonalization (twice): alpha (diagonal), beta (off-diagonal) of A.
  std::vector<std::vector<real>> qs{q0};
  std::vector<real> alpha, beta;
  const real scale = *std::max_element(lambda.begin(), lambda.end());
  for (std::size_t j = 0; j < n; ++j) {
    const std::vector<real>& q = qs[j];
    std::vector<real> v(n);
    real a = 0;
    for (std::size_t k = 0; k < n; ++k) {
      v[k] = lambda[k] * q[k];
      a += q[k] * v[k];
    }
    alpha.push_back(a);
    if (j + 1 == n) break;
    for (int pass = 0; pass < 2; ++pass)
      for (const std::vector<real>& u : qs) {
        real d = 0;
        for (std::size_t k = 0; k < n; ++k) d += u[k] * v[k];
        for (std::size_t k = 0; k < n; ++k) v[k] -= d * u[k];
      }
    real norm = 0;
    for (real x : v) norm += x * x;
    norm = std::sqrt(norm);
    // The rest of the spectrum is invisible from the junction (its weight below the precision).
    if (norm <= scale * 1e-15L) break;
    beta.push_back(norm);
    for (real& x : v) x /= norm;
    qs.push_back(std::move(v));
  }
  // The ladder from A: A_11 = 1/(R1 C1); A_i,i+1 = -1/(R_i sqrt(C_i C_i+1));
  // A_ii = (1/R_i-1 + 1/R_i) / C_i.
  real c = c1, inv_r_prev = 0;
  for (std::size_t i = 0; i < alpha.size(); ++i) {
    const real inv_r = alpha[i] * c - inv_r_prev;
    // A stage that comes out non-positive: rounding has eaten the digits; the ladder ends before it.
    if (!(inv_r > 0) || !(c > 0)) break;
    out.push_back({double(1 / inv_r), double(c)});
    if (i < beta.size()) {
      const real r = 1 / inv_r;
      c = 1 / (r * r * beta[i] * beta[i] * c);
      inv_r_prev = inv_r;
    }
  }
  return out;
}

StructureFunction structure_function(std::span<const double> t, std::span<const double> z,
                                     const FosterFitParams& p) {
  StructureFunction s;
  s.fit = fit_foster(t, z, p);
  s.cauer = foster_to_cauer(s.fit.terms);
  double r = 0, c = 0;
  for (const CauerStage& st : s.cauer) {
    r += st.r;
    c += st.c;
    s.cumulative_r.push_back(r);
    s.cumulative_c.push_back(c);
  }
  // The rise over the last tenth of the samples' log-time span.
  const double t90 = t.front() * std::pow(t.back() / t.front(), 0.9);
  std::size_t k = 0;
  while (k + 1 < t.size() && t[k + 1] <= t90) ++k;
  s.settled = z.back() != 0 ? (z.back() - z[k]) / std::abs(z.back()) : 0;
  return s;
}

}  // namespace foxi
