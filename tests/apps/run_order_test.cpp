// The order foxi sweep starts its runs in (apps/foxi/run_order.hpp), driven by made-up run lengths on
// a simulated clock: every run starts once, and the sweep's makespan on 2 workers is compared with
// the best possible one (a brute-force search over every split of the runs between the workers) and
// with starting the runs in grid order.
#include "../../apps/foxi/run_order.hpp"  // an app header: the test includes it by its path

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace foxi::cli {
namespace {

std::vector<std::size_t> one_dimension(std::size_t run) { return {run}; }

// The time `jobs` workers take over runs of the given lengths when each free worker starts the run
// `pick(now)` names (total when none is left); `finished(run, now)` hears of each end.
template <typename Pick, typename Finished>
double makespan(const std::vector<double>& length, int jobs, Pick pick, Finished finished) {
  std::vector<double> free_at(jobs, 0);
  std::vector<std::pair<double, std::size_t>> running;  // end, run
  std::vector<int> starts(length.size(), 0);
  double now = 0, last = 0;
  for (int w = 0; w < jobs; ++w) {
    const std::size_t run = pick(now);
    if (run < length.size()) running.emplace_back(now + length[run], run), ++starts[run];
  }
  while (!running.empty()) {
    const auto first = std::min_element(running.begin(), running.end());
    now = first->first;
    const std::size_t done = first->second;
    running.erase(first);
    finished(done, now);
    last = std::max(last, now);
    const std::size_t run = pick(now);
    if (run < length.size()) running.emplace_back(now + length[run], run), ++starts[run];
  }
  for (std::size_t r = 0; r < length.size(); ++r) EXPECT_EQ(starts[r], 1) << "run " << r;
  return last;
}

double with_run_order(const std::vector<double>& length, int jobs) {
  RunOrder order(length.size(), one_dimension);
  return makespan(
      length, jobs, [&](double now) { return order.next(now); },
      [&](std::size_t run, double now) { order.finished(run, now); });
}

double in_grid_order(const std::vector<double>& length, int jobs) {
  std::size_t next = 0;
  return makespan(
      length, jobs, [&](double) { return next < length.size() ? next++ : length.size(); },
      [](std::size_t, double) {});
}

// The best 2-worker makespan: every split of the runs between the two.
double best_of_two(const std::vector<double>& length) {
  const double total = std::accumulate(length.begin(), length.end(), 0.0);
  double best = total;
  for (unsigned mask = 0; mask < (1u << length.size()); ++mask) {
    double a = 0;
    for (std::size_t r = 0; r < length.size(); ++r)
      if (mask & (1u << r)) a += length[r];
    best = std::min(best, std::max(a, total - a));
  }
  return best;
}

TEST(RunOrder, LongestRunsFirstOnAGrowingSweep) {
  // The flip chip's 7-point die_w sweep: run lengths in proportion to its tet counts.
  const std::vector<double> growing{10.8, 12.2, 13.6, 15.5, 18.9, 21.3, 23.9};
  const double best = best_of_two(growing), ours = with_run_order(growing, 2),
               grid = in_grid_order(growing, 2);
  EXPECT_LE(ours, 1.05 * best) << "best " << best << ", grid order " << grid;
  EXPECT_GT(grid, 1.10 * best);  // what the order saves: the largest run no longer ends alone
  std::vector<double> shrinking(growing.rbegin(), growing.rend());
  EXPECT_LE(with_run_order(shrinking, 2), 1.05 * best_of_two(shrinking));
  // One long run anywhere: nothing predicts it, but no worker waits while runs do (Graham's bound
  // for list scheduling on 2 workers: total / 2 + longest / 2).
  for (std::size_t at = 0; at < 7; ++at) {
    std::vector<double> one_long(7, 5.0);
    one_long[at] = 30;
    EXPECT_LE(with_run_order(one_long, 2), (60.0 + 30.0) / 2) << "long run at " << at;
  }
  // Random lengths, 2 and 3 workers: the same bound, total / jobs + longest (1 - 1 / jobs).
  unsigned seed = 12345;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> length(1 + trial % 13);
    for (double& l : length) l = 1 + double((seed = seed * 1103515245u + 12345u) >> 16 & 1023) / 64;
    const double total = std::accumulate(length.begin(), length.end(), 0.0);
    const double longest = *std::max_element(length.begin(), length.end());
    for (int jobs : {2, 3})
      EXPECT_LE(with_run_order(length, jobs), total / jobs + longest * (1 - 1.0 / jobs) + 1e-9)
          << "trial " << trial;
  }
}

TEST(RunOrder, EqualRunsAndEdgeCases) {
  EXPECT_DOUBLE_EQ(with_run_order(std::vector<double>(7, 1.0), 2), 4.0);  // 7 equal runs, 2 workers
  EXPECT_DOUBLE_EQ(with_run_order(std::vector<double>(1, 3.0), 4), 3.0);  // more workers than runs
  EXPECT_DOUBLE_EQ(with_run_order(std::vector<double>(5, 1.0), 1), 5.0);  // one worker
  // The two ends of the grid start first.
  RunOrder order(5, one_dimension);
  EXPECT_EQ(order.next(0), 4u);
  EXPECT_EQ(order.next(0), 0u);
  // A grid of two parameters (3 x 4): every run starts once, then none is left.
  RunOrder grid(12, [](std::size_t run) { return std::vector<std::size_t>{run / 4, run % 4}; });
  std::vector<int> seen(12, 0);
  for (int k = 0; k < 12; ++k) {
    const std::size_t run = grid.next(k);
    ASSERT_LT(run, 12u);
    ++seen[run];
    grid.finished(run, k + 0.5 + 0.1 * double(run));
  }
  EXPECT_EQ(grid.next(20), 12u);
  EXPECT_EQ(seen, std::vector<int>(12, 1));
  // Past kPredicted runs: grid order.
  RunOrder many(RunOrder::kPredicted + 1, one_dimension);
  for (std::size_t k = 0; k <= RunOrder::kPredicted; ++k) EXPECT_EQ(many.next(0), k);
  EXPECT_EQ(many.next(0), RunOrder::kPredicted + 1);
}

}  // namespace
}  // namespace foxi::cli
