#include "thread_pool.hpp"

#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace foxi::pool {

namespace {

// One pooled thread: it sleeps on its own condition variable until handed a task.
struct Slot {
  std::mutex mu;
  std::condition_variable cv;
  std::function<void()> task;
  std::promise<void> done;
  bool has_task = false, stop = false;
  std::thread thread;
};

class Pool {
 public:
  ~Pool() {
    for (auto& s : slots_) {
      {
        std::lock_guard<std::mutex> g(s->mu);
        s->stop = true;
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
    }
    slot->cv.notify_one();
    return done;
  }

 private:
  void loop(Slot& s) {
    for (;;) {
      std::function<void()> task;
      std::promise<void> done;
      {
        std::unique_lock<std::mutex> lock(s.mu);
        s.cv.wait(lock, [&s] { return s.has_task || s.stop; });
        if (!s.has_task) return;
        task = std::move(s.task);
        done = std::move(s.done);
        s.has_task = false;
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
      if (error) done.set_exception(error);
      else done.set_value();
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

std::future<void> run_async(std::function<void()> task) { return the_pool().run(std::move(task)); }

void on_two_cores(const std::function<void(int)>& f) {
  std::future<void> other = run_async([&f] { f(1); });
  try {
    f(0);
  } catch (...) {
    other.wait();
    throw;
  }
  other.get();
}

}  // namespace foxi::pool
