// Internal to foxi's libraries (not an entry point for hosts): the one place for splitting work over
// threads, on one pool of persistent threads (model/src/thread_pool.cpp), so that no call starts a
// thread (starting and joining one costs tens of microseconds, more on a loaded machine, and the
// viewer's per-view passes and undraw steps hand work over every few hundred microseconds).
// `threads` means the same everywhere: the number of threads to use, 0 for all the hardware has
// (thread_count); a loop shorter than its `serial_below` runs on the calling thread.
//   run_parts              f(0) on the calling thread, f(1), ..., f(parts - 1) on pooled threads.
//   parallel_for           contiguous slices, one per thread, the same split every time (a pass
//                          that must see the parts of an earlier one gets the same ranges).
//   parallel_for_balanced  two threads taking chunks in turn, for loops whose cost is bunched in
//                          some part of the range (exact recomputations, say).
//   run_async, finish      one task on a pooled thread, and the wait for it (a worker that runs on
//                          while the caller does something else: the progressive order's).
// A part may itself split its work: the pool then grows (it holds as many threads as were ever busy
// at once), so nested calls never wait for a thread.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <future>
#include <thread>
#include <vector>

#include "foxi/api.hpp"

namespace foxi::detail {

inline unsigned thread_count(unsigned requested) {
  unsigned n = requested ? requested : std::thread::hardware_concurrency();
  return std::max(1u, n);
}

// Runs `task` on a pooled thread: an idle one, or a new one added to the pool (threads are started on
// first use and kept until the program ends). The future is ready when the task has run and carries
// its exception, if any.
FOXI_API std::future<void> run_async(std::function<void()> task);

// One step of a spinning wait: a few hundred cycles, then the CPU offered to any other runnable
// thread.
FOXI_API void relax();

// done.get(), after spinning a little while for it to be ready (a caller whose part ended first
// would otherwise sleep and pay a wake-up; see thread_pool.cpp).
FOXI_API void finish(std::future<void>& done);

// Runs f(0), ..., f(parts - 1): f(0) on the calling thread, the others on pooled threads; returns
// when all are done, rethrowing the first exception. not_started() is called if f(0) will not run
// because a part could not be handed to a thread (parts already running may be waiting for f(0): it
// must let them go).
template <class F, class G>
void run_parts(int parts, F&& f, G&& not_started) {
  std::vector<std::future<void>> others;
  std::exception_ptr error;
  bool posted = false;
  try {
    others.reserve(std::size_t(std::max(parts - 1, 0)));
    for (int k = 1; k < parts; ++k) others.push_back(run_async([&f, k] { f(k); }));
    posted = true;
    f(0);
  } catch (...) {
    error = std::current_exception();
    if (!posted) not_started();
  }
  for (auto& other : others) {
    try {
      finish(other);
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

// The same when no part waits for another.
template <class F>
void run_parts(int parts, F&& f) {
  run_parts(parts, f, [] {});
}

// Calls fn(begin, end, thread) on `threads` contiguous slices of [0, n) (slice t is
// [n t / threads, n (t + 1) / threads)); serial when n is small.
template <class Fn>
void parallel_for(std::size_t n, unsigned threads, Fn&& fn, std::size_t serial_below = 20000) {
  if (threads <= 1 || n < serial_below) {
    fn(std::size_t{0}, n, 0u);
    return;
  }
  run_parts(int(threads), [&](int part) {
    const auto t = unsigned(part);
    fn(n * t / threads, n * (t + 1) / threads, t);
  });
}

// Runs f(begin, end, part) over [0, n) on two threads (part 0 or 1: the thread), in chunks taken
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
  run_parts(2, [&](int part) {
    for (std::size_t b = next.fetch_add(chunk); b < n; b = next.fetch_add(chunk))
      f(b, std::min(n, b + chunk), part);
  });
}

}  // namespace foxi::detail
