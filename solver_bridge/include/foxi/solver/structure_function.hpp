// The cumulative structure function of a thermal impedance Zth(t) (issue 18), as thermal-transient
// testers report it (JEDEC JESD51-14, T3Ster): cumulative thermal capacitance against cumulative
// thermal resistance along the heat's path from the junction, read off a Cauer RC ladder.
//
// 1. Foster fit: Zth(t) = sum_i R_i (1 - exp(-t / tau_i)) with the time constants tau_i fixed on a
//    logarithmic grid (per_decade a decade) and R_i >= 0 found by non-negative least squares
//    (Lawson-Hanson; each sample weighted by the square root of the log-time it stands for, so that
//    uniformly spaced samples do not drown the short times). The grid is a discrete time-constant
//    spectrum: resolution 1/per_decade decade, nothing faster than the first sample or slower than the
//    last can be told apart; a Zth that has not settled at the last sample gives a structure function
//    whose end is not the ambient (StructureFunction::settled says how far it still rose).
// 2. Foster -> Cauer: the Foster network's impedance Z(s) = sum R_k / (1 + s tau_k) is, for a Cauer
//    ladder with capacitances C_i at its nodes and resistances R_i between them (the last to the
//    ambient), Z(s) = (1/C_1) e1' (sI + A)^-1 e1 with A = C^-1/2 G C^-1/2 a symmetric tridiagonal
//    (Jacobi) matrix. So A's eigenvalues are 1/tau_k and the squares of its eigenvectors' first
//    components are C_1 R_k / tau_k: the Lanczos process on diag(1/tau_k) from that start vector
//    gives A, and A's entries give C_i and R_i one after the other. Long double arithmetic with full
//    reorthogonalization, rather than the polynomial continued fraction, which loses all digits
//    beyond a few stages in double.
// The library never prints; bad input throws std::invalid_argument.
#pragma once

#include <span>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

struct FosterTerm {
  double r = 0;    // K/W
  double tau = 0;  // s
};
struct CauerStage {
  double r = 0;  // K/W, from this stage's node to the next (the last: to the ambient)
  double c = 0;  // J/K, at this stage's node
};

struct FosterFitParams {
  int per_decade = 10;  // time constants a decade
  // The grid's range (s); 0: from the first sample / 30 (what is faster than the first sample
  // shows as a term that has settled by then) to the last sample * 3.
  double tau_min = 0, tau_max = 0;
};

struct FosterFit {
  std::vector<FosterTerm> terms;  // the non-zero ones, tau ascending
  double rms_error = 0;           // K/W, unweighted, over the samples
  double max_error = 0;           // K/W
};

// Zth(t) of a Foster network, K/W.
FOXI_API double foster_zth(std::span<const FosterTerm> foster, double t);

// Fits Zth (K/W) sampled at times t (s, > 0, increasing; at least 3 samples). Throws
// std::invalid_argument for sizes that differ, times not positive and increasing, non-finite values.
FOXI_API FosterFit fit_foster(std::span<const double> t, std::span<const double> zth,
                              const FosterFitParams& params = {});

// The Cauer ladder of a Foster network (terms with r > 0 and tau > 0; zero terms are dropped). Stages
// as many as the Foster terms unless the Lanczos process ends early (the rest of the spectrum carries
// no weight at the working precision). Throws std::invalid_argument for a negative or non-finite term.
FOXI_API std::vector<CauerStage> foster_to_cauer(std::span<const FosterTerm> foster);

struct StructureFunction {
  FosterFit fit;
  std::vector<CauerStage> cauer;
  // cumulative_r[i] = sum of cauer[0..i].r, cumulative_c[i] = sum of cauer[0..i].c: the point
  // (R_sum, C_sum) after stage i; C_sum(R) is cumulative_c[i] on [cumulative_r[i-1], cumulative_r[i]).
  std::vector<double> cumulative_r, cumulative_c;
  // How much Zth still rose over the last tenth (log time) of the samples, relative to its last
  // value: near 0 when the heat reached the ambient (a settled Zth), else the structure function's
  // end is cut off.
  double settled = 0;
};

// fit_foster, then foster_to_cauer, then the sums.
FOXI_API StructureFunction structure_function(std::span<const double> t, std::span<const double> zth,
                                              const FosterFitParams& params = {});

}  // namespace foxi
