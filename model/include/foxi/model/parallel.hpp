// Internal to foxi's libraries (not an entry point for hosts): the one place for splitting a loop
// over threads. `threads` means the same everywhere: the number of threads to use, 0 for all the
// hardware has (thread_count); a loop shorter than its `serial_below` runs on the calling thread.
//   parallel_for           contiguous slices, one per thread, the same split every time (a pass
//                          that must see the parts of an earlier one gets the same ranges).
//   parallel_for_balanced  two threads taking chunks in turn, for loops whose cost is bunched in
//                          some part of the range (exact recomputations, say).
// The per-view passes of the visibility order use viz's persistent pool instead (a view starts no
// thread: viz/src/order_geometry.hpp, viz/src/thread_pool.hpp).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace foxi::detail {

inline unsigned thread_count(unsigned requested) {
  unsigned n = requested ? requested : std::thread::hardware_concurrency();
  return std::max(1u, n);
}

// Calls fn(begin, end, thread) on `threads` contiguous slices of [0, n); serial when n is small.
template <class Fn>
void parallel_for(std::size_t n, unsigned threads, Fn&& fn, std::size_t serial_below = 20000) {
  if (threads <= 1 || n < serial_below) {
    fn(std::size_t{0}, n, 0u);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t)
    pool.emplace_back([&, t] { fn(n * t / threads, n * (t + 1) / threads, t); });
  fn(std::size_t{0}, n / threads, 0u);
  for (auto& th : pool) th.join();
}

// Runs f(begin, end, part) over [0, n) on both cores (part 0 or 1: the thread), in chunks taken
// in turn, so that the costly exact recomputations, bunched in some part of the mesh, do not leave
// one core idle.
template <class F>
void parallel_for_balanced(std::size_t n, F f) {
  if (n < 20000) {
    f(std::size_t{0}, n, 0);
    return;
  }
  const std::size_t chunk = std::max<std::size_t>(4096, n / 256);
  std::atomic<std::size_t> next{0};
  auto work = [&](int part) {
    for (std::size_t b = next.fetch_add(chunk); b < n; b = next.fetch_add(chunk))
      f(b, std::min(n, b + chunk), part);
  };
  std::thread other([&] { work(1); });
  work(0);
  other.join();
}

}  // namespace foxi::detail
