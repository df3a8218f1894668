// The one parallel layer (foxi/model/parallel.hpp): the documented slices, every index exactly once
// (counted by brute force), parts run on the pool's persistent threads (a thread_local count shows a
// pooled thread serving many calls: none is started per call), exceptions reach the caller, and a
// part may split its own work (nested calls) without waiting for a thread.
#include "foxi/model/parallel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <stdexcept>
#include <thread>
#include <vector>

namespace {

using foxi::detail::parallel_for;
using foxi::detail::parallel_for_balanced;
using foxi::detail::run_parts;

TEST(Parallel, SlicesAreTheDocumentedOnesAndCoverEachIndexOnce) {
  for (unsigned threads : {1u, 2u, 3u, 5u})
    for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}}) {
      std::vector<std::atomic<int>> hits(n);
      std::vector<std::size_t> begin(threads, n + 1), end(threads, n + 1);
      parallel_for(
          n, threads,
          [&](std::size_t b, std::size_t e, unsigned t) {
            begin[t] = b;
            end[t] = e;
            for (std::size_t i = b; i < e; ++i) ++hits[i];
          },
          0);
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << n << " " << threads << " " << i;
      if (threads > 1)
        for (unsigned t = 0; t < threads; ++t) {
          EXPECT_EQ(begin[t], n * t / threads);
          EXPECT_EQ(end[t], n * (t + 1) / threads);
        }
    }
}

TEST(Parallel, ShortLoopRunsOnTheCallingThread) {
  const std::thread::id caller = std::this_thread::get_id();
  int calls = 0;
  parallel_for(19999, 4, [&](std::size_t b, std::size_t e, unsigned t) {
    ++calls;
    EXPECT_EQ(std::this_thread::get_id(), caller);
    EXPECT_EQ(b, 0u);
    EXPECT_EQ(e, 19999u);
    EXPECT_EQ(t, 0u);
  });
  EXPECT_EQ(calls, 1);
}

thread_local int t_parts_here = 0;

TEST(Parallel, PooledThreadsServeManyCalls) {
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> most{0}, on_caller{0};
  for (int call = 0; call < 100; ++call)
    run_parts(3, [&](int part) {
      if (part == 0) {
        on_caller += std::this_thread::get_id() == caller;
        return;
      }
      EXPECT_NE(std::this_thread::get_id(), caller);
      const int here = ++t_parts_here;
      int seen = most.load();
      while (here > seen && !most.compare_exchange_weak(seen, here)) {
      }
    });
  EXPECT_EQ(on_caller.load(), 100);  // part 0 is the caller's
  // 200 pooled parts on at most a few threads: a thread started per call would count 1 each.
  EXPECT_GE(most.load(), 20);
}

TEST(Parallel, ExceptionOfAPartReachesTheCallerAfterAllParts) {
  std::atomic<int> finished{0};
  EXPECT_THROW(parallel_for(
                   100000, 4,
                   [&](std::size_t, std::size_t, unsigned t) {
                     if (t == 2) throw std::runtime_error("part 2");
                     ++finished;
                   },
                   0),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 3);
  EXPECT_THROW(run_parts(2,
                         [](int part) {
                           if (part == 0) throw std::logic_error("caller's part");
                         }),
               std::logic_error);
}

TEST(Parallel, NestedSplitsCoverEverything) {
  constexpr std::size_t kOuter = 6, kInner = 50000;
  std::vector<std::atomic<int>> hits(kOuter * kInner);
  parallel_for(
      kOuter, 3,
      [&](std::size_t b, std::size_t e, unsigned) {
        for (std::size_t o = b; o < e; ++o)
          parallel_for(kInner, 2, [&](std::size_t ib, std::size_t ie, unsigned) {
            for (std::size_t i = ib; i < ie; ++i) ++hits[o * kInner + i];
          });
      },
      0);
  EXPECT_TRUE(std::all_of(hits.begin(), hits.end(), [](const std::atomic<int>& h) { return h.load() == 1; }));
}

TEST(Parallel, BalancedCoversEachIndexOnceOnTwoParts) {
  for (std::size_t n : {std::size_t{100}, std::size_t{300001}}) {
    std::vector<std::atomic<int>> hits(n);
    std::atomic<int> bad_part{0};
    parallel_for_balanced(n, [&](std::size_t b, std::size_t e, int part) {
      bad_part += part != 0 && part != 1;
      for (std::size_t i = b; i < e; ++i) ++hits[i];
    });
    EXPECT_EQ(bad_part.load(), 0);
    EXPECT_TRUE(
        std::all_of(hits.begin(), hits.end(), [](const std::atomic<int>& h) { return h.load() == 1; }));
  }
}

}  // namespace
