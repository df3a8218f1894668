// Internal: persistent threads for the two-core passes of the per-view order, so that a view starts
// no thread (starting and joining one costs tens of microseconds, and more on a loaded machine).
#pragma once

#include <functional>
#include <future>

namespace foxi::pool {

// Runs `task` on a pooled thread: an idle one, or a new one added to the pool (threads are started on
// first use and kept until the program ends, so their number is the most ever busy at once). The
// future is ready when the task has run and carries its exception, if any.
std::future<void> run_async(std::function<void()> task);

// One step of a spinning wait: a few hundred cycles, then the CPU offered to any other runnable
// thread.
void relax();

// done.get(), after spinning a little while for it to be ready (a caller whose part ended first
// would otherwise sleep and pay a wake-up; see thread_pool.cpp).
void finish(std::future<void>& done);

// Runs f(0) on the calling thread and f(1) on a pooled thread; returns when both are done (an
// exception from either is rethrown, f(1)'s after f(0) has finished).
void on_two_cores(const std::function<void(int)>& f);

}  // namespace foxi::pool
