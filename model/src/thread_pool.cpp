// The persistent pool behind foxi/model/parallel.hpp: run_async, relax, finish.
#include "foxi/model/parallel.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <sched.h>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace foxi::detail {

namespace {

// How long a thread spins for the next task, or a caller for its part's end, before sleeping: waking
// a sleeping thread costs tens of microseconds (more on a virtual machine, whose idle CPU must be
// woken too), paid twice per call, and a viewer's frames (undraw steps above all) hand work to the
// pool every few hundred microseconds. The spin yields the CPU to any other runnable thread.
constexpr auto kSpin = std::chrono::microseconds(300);

// Spins until ready() or kSpin has passed; returns ready().
template <class Ready>
bool spin_for(Ready&& ready) {
  const auto until = std::chrono::steady_clock::now() + kSpin;
  for (int i = 0;; ++i) {
    if (ready()) return true;
    if ((i & 7) == 7 && std::chrono::steady_clock::now() >= until) return ready();
    relax();
  }
}

// One pooled thread: it sleeps on its own condition variable until handed a task.
struct Slot {
  std::mutex mu;
  std::condition_variable cv;
  std::function<void()> task;
  std::promise<void> done;
  bool has_task = false, stop = false;
  std::atomic<bool> posted{false};  // has_task or stop, for the spin before sleeping
  std::thread thread;
};

class Pool {
 public:
  ~Pool() {
    for (auto& s : slots_) {
      {
        std::lock_guard<std::mutex> g(s->mu);
        s->stop = true;
        s->posted.store(true, std::memory_order_release);
      }
      s->cv.notify_one();
      s->thread.join();
    }
  }

  std::future<void> run(std::function<void()> f) {
    std::promise<void> promise;
    std::future<void> done = promise.get_future();
    Slot* slot = nullptr;
    {
      std::lock_guard<std::mutex> g(mu_);
      if (!idle_.empty()) {
        slot = idle_.back();
        idle_.pop_back();
      } else {
        slots_.push_back(std::make_unique<Slot>());
        slot = slots_.back().get();
        slot->thread = std::thread([this, slot] { loop(*slot); });
      }
    }
    {
      std::lock_guard<std::mutex> g(slot->mu);
      slot->task = std::move(f);
      slot->done = std::move(promise);
      slot->has_task = true;
      slot->posted.store(true, std::memory_order_release);
    }
    slot->cv.notify_one();
    return done;
  }

 private:
  void loop(Slot& s) {
    for (;;) {
      std::function<void()> task;
      std::promise<void> done;
      spin_for([&s] { return s.posted.load(std::memory_order_acquire); });
      {
        std::unique_lock<std::mutex> lock(s.mu);
        s.cv.wait(lock, [&s] { return s.has_task || s.stop; });
        if (!s.has_task) return;
        task = std::move(s.task);
        done = std::move(s.done);
        s.has_task = false;
        s.posted.store(s.stop, std::memory_order_relaxed);
      }
      std::exception_ptr error;
      try {
        task();
      } catch (...) {
        error = std::current_exception();
      }
      // Idle again before the caller hears of it, so that its next call finds this thread free; the
      // task object goes first (its captures may refer to the caller's frame).
      task = {};
      {
        std::lock_guard<std::mutex> g(mu_);
        idle_.push_back(&s);
      }
      if (error)
        done.set_exception(error);
      else
        done.set_value();
    }
  }

  std::mutex mu_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<Slot*> idle_;
};

Pool& the_pool() {
  static Pool pool;
  return pool;
}

}  // namespace

void relax() {
#if defined(__x86_64__) || defined(__i386__)
  for (int i = 0; i < 16; ++i) _mm_pause();
#endif
  sched_yield();
}

std::future<void> run_async(std::function<void()> task) { return the_pool().run(std::move(task)); }

void finish(std::future<void>& done) {
  spin_for([&done] { return done.wait_for(std::chrono::seconds(0)) == std::future_status::ready; });
  done.get();
}

}  // namespace foxi::detail
