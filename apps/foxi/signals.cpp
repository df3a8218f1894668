#include "signals.hpp"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "exit_codes.hpp"
#include "foxi/model/cleanup.hpp"

namespace foxi::cli {

namespace {

std::atomic<bool> g_stopping{false};

sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);  // the terminal went away: stop as cleanly as on SIGTERM
  return set;
}

// Registered with atexit: main returned (or exit() was called) while the signal thread is stopping
// the program; it ends the process with the right status.
extern "C" void wait_for_stop() {
  if (!g_stopping.load()) return;
  for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
}

}  // namespace

void handle_stop_signals(const std::string& program) {
  const sigset_t set = stop_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  // A reader of the output that went away (foxi solve ... | head -1) killed the run by SIGPIPE with
  // its temporaries left and its -o file lost (an outside probe): blocked, a write to the closed pipe
  // fails instead (the printed lines are lost, the files are written).
  sigset_t pipe;
  sigemptyset(&pipe);
  sigaddset(&pipe, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe, nullptr);
  std::atexit(wait_for_stop);
  std::thread([program, set] {
    int sig = 0;
    while (sigwait(&set, &sig) != 0) {
    }
    g_stopping = true;
    const char* name = sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "SIGINT (Ctrl-C)";
    std::fprintf(stderr, "\n%s: stopped by %s; helper processes killed, unfinished files removed\n",
                 program.c_str(), name);
    cleanup::interrupt();
    std::fflush(stderr);
    ::_exit(sig == SIGTERM ? kExitTerminated : sig == SIGHUP ? kExitHangup : kExitInterrupted);
  }).detach();
}

}  // namespace foxi::cli
