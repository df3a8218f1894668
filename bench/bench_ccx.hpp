// CalculiX (ccx) as a baseline in a Google Benchmark: the deck is written into a fresh temp folder,
// each iteration runs `ccx -i JOB` there and reports the wall time of ccx alone (manual time), and
// the counter peak_rss_MB gives the largest resident set of the children (ccx) so far.
#pragma once

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

namespace foxi::bench {

// Peak resident set in MB of this process (RUSAGE_SELF) or of its finished children (RUSAGE_CHILDREN).
inline double peak_rss_mb(int who) {
  rusage u{};
  getrusage(who, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // KiB on Linux
}

// CPU seconds of the whole process (all threads) so far: the figure to compare on a loaded machine.
inline double process_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// write_deck(path) writes JOB.inp; skipped (with `why`) when ccx is missing or `enabled` is false.
template <class WriteDeck>
void time_ccx(benchmark::State& state, const std::string& job, WriteDeck&& write_deck, bool enabled,
              const char* why) {
  if (!enabled || std::system("command -v ccx > /dev/null 2>&1") != 0) {
    state.SkipWithError(why);
    return;
  }
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("foxi-bench-ccx-" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  write_deck(dir / (job + ".inp"));
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = std::system(("cd '" + dir.string() + "' && ccx -i " + job + " > ccx.log 2>&1").c_str());
    const auto t1 = std::chrono::steady_clock::now();
    if (rc != 0) state.SkipWithError("ccx failed");
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  state.counters["peak_rss_MB"] = peak_rss_mb(RUSAGE_CHILDREN);
  std::filesystem::remove_all(dir);
}

}  // namespace foxi::bench
