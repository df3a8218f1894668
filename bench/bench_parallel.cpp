// The one parallel layer (foxi/model/parallel.hpp, issue 20 item 2), with its baseline in the same run:
// the cost of splitting a loop over two threads, per call.
//   spawn_for/N     a std::thread started and joined per call (what foxi::detail::parallel_for did
//                   before it ran on the pool)
//   pool_for/N      foxi::detail::parallel_for on the persistent pool
// N: 2 (an empty loop: the dispatch alone) and 20000 doubles summed (the default serial_below, the
// smallest loop that is split). Times are wall and process CPU time per call (all threads).
#include <benchmark/benchmark.h>

#include <cstddef>
#include <thread>
#include <vector>

#include "foxi/model/parallel.hpp"

namespace {

template <class Fn>
void spawn_for(std::size_t n, unsigned threads, Fn&& fn) {
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t)
    pool.emplace_back([&, t] { fn(n * t / threads, n * (t + 1) / threads, t); });
  fn(std::size_t{0}, n / threads, 0u);
  for (auto& th : pool) th.join();
}

template <bool kPool>
void run(benchmark::State& state) {
  const std::size_t n = std::size_t(state.range(0));
  std::vector<double> data(n, 1.0);
  double sums[2] = {0, 0};
  auto body = [&](std::size_t b, std::size_t e, unsigned t) {
    double s = 0;
    for (std::size_t i = b; i < e; ++i) s += data[i] * 1.0001;
    sums[t] += s;
  };
  for (auto _ : state) {
    if constexpr (kPool)
      foxi::detail::parallel_for(n, 2, body, 0);
    else
      spawn_for(n, 2, body);
    benchmark::DoNotOptimize(sums);
  }
}

void spawn_for_bench(benchmark::State& state) { run<false>(state); }
void pool_for_bench(benchmark::State& state) { run<true>(state); }

}  // namespace

BENCHMARK(spawn_for_bench)
    ->Name("spawn_for")
    ->Arg(2)
    ->Arg(20000)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(pool_for_bench)
    ->Name("pool_for")
    ->Arg(2)
    ->Arg(20000)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
