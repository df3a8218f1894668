// The order in which foxi sweep starts its runs (cmd_sweep.cpp). Times are seconds on one clock
// that the caller reads (the sweep: since its start), so that a test can drive it with made-up run
// lengths.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

namespace foxi::cli {

// The longest run first, so that the last runs to start are short and the cores stay busy to the
// end (the flip chip's runs range from 0.7 to 1.5 times the default's, and started smallest first
// the largest ran alone at the end). A run's length is not known before it runs: it is predicted
// from the runs already started, weighted by 1 / (their distance in the grid of parameter values, in
// steps): a finished run by its length, a running one by its time so far (a lower bound) where that
// is more than the finished runs predict for it. Before anything is known the runs start from both
// ends of the grid. This changes nothing but the wall time: each run is its own process, its row is
// written in grid order. Past kPredicted runs they start in grid order: a prediction costs a pass
// over the started runs per waiting run, and over hundreds of runs the tail matters little.
class RunOrder {
 public:
  static constexpr std::size_t kPredicted = 256;
  // `index(run)`: the run's place in the grid (one index per varied parameter).
  RunOrder(std::size_t total, const std::function<std::vector<std::size_t>(std::size_t)>& index)
      : total_(total), seconds_(total, -1), start_(total, 0), started_(total, false) {
    if (total_ <= kPredicted)
      for (std::size_t run = 0; run < total_; ++run) index_.push_back(index(run));
  }

  // The next run to start at time `now`, or `total` when every run has started.
  std::size_t next(double now) {
    if (started_count_ == total_) return total_;
    std::size_t pick = total_;
    if (total_ > kPredicted) {
      pick = first_unstarted();
    } else if (started_count_ < 2) {                // (one finished run predicts the same length for all)
      pick = started_count_ == 0 ? total_ - 1 : 0;  // the two ends
      if (started_[pick]) pick = first_unstarted();
    } else {
      double longest = -1;
      for (std::size_t run = 0; run < total_; ++run) {
        if (started_[run]) continue;
        const double predicted = predict(run, &now);
        // Ties (to rounding: one finished run predicts its own length everywhere, in weights of
        // 1/3 and 1/2 that round differently) go to the first run in the grid.
        if (predicted > longest * (1 + 1e-9)) longest = predicted, pick = run;
      }
    }
    started_[pick] = true;
    start_[pick] = now;
    ++started_count_;
    return pick;
  }
  // Run `run` (started by next()) ended at time `now`.
  void finished(std::size_t run, double now) {
    seconds_[run] = now - start_[run];
    ++finished_count_;
  }

 private:
  std::size_t first_unstarted() {
    while (cursor_ < total_ && started_[cursor_]) ++cursor_;
    return cursor_;
  }
  std::size_t distance(std::size_t a, std::size_t b) const {
    std::size_t d = 0;
    for (std::size_t i = 0; i < index_[a].size(); ++i)
      d += index_[a][i] > index_[b][i] ? index_[a][i] - index_[b][i] : index_[b][i] - index_[a][i];
    return d;
  }
  // The 1 / distance weighted mean length of the finished runs (and, with `now`, of the running ones:
  // each the longer of its time so far and its own prediction from the finished runs, as a run that
  // has just started says nothing yet).
  double predict(std::size_t run, const double* now) const {
    double sum = 0, weight = 0;
    for (std::size_t other = 0; other < total_; ++other) {
      if (!started_[other] || other == run || (seconds_[other] < 0 && now == nullptr)) continue;
      const double length =
          seconds_[other] >= 0 ? seconds_[other] : std::max(*now - start_[other], predict(other, nullptr));
      const double w = 1 / double(distance(run, other));
      sum += length * w, weight += w;
    }
    return weight > 0 ? sum / weight : 0;
  }

  std::size_t total_;
  std::vector<std::vector<std::size_t>> index_;  // each run's place in the grid (up to kPredicted runs)
  std::vector<double> seconds_;                  // a finished run's length, else -1
  std::vector<double> start_;
  std::vector<bool> started_;
  std::size_t started_count_ = 0, finished_count_ = 0;
  std::size_t cursor_ = 0;  // no run before it is waiting
};

}  // namespace foxi::cli
