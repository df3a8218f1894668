#include "signals.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/wait.h>
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

int run_program(const std::vector<std::string>& argv, const std::string& output,
                const std::string& stdout_to) {
  if (argv.empty()) return -1;
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::fflush(nullptr);
  const pid_t pid = cleanup::fork_tracked();
  if (pid < 0) return -1;
  if (pid == 0) {
    // The stop signals stay blocked: foxi kills this child itself when it stops.
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, 0);
    if (!output.empty()) {
      const int out = ::open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
      if (out < 0) ::_exit(127);
      ::dup2(out, 1);
      ::dup2(out, 2);
    }
    if (!stdout_to.empty()) {
      const int out = ::open(stdout_to.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
      if (out < 0) ::_exit(127);
      ::dup2(out, 1);
    }
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  // Waited for without the lock (the program may run for minutes), then reaped with it: an interrupt
  // never kills a process id that was already reaped and could be reused.
  int ws = 0;
  siginfo_t info{};
  while (::waitid(P_PID, id_t(pid), &info, WEXITED | WNOWAIT) != 0 && errno == EINTR) {
  }
  cleanup::with_lock([&] {
    while (::waitpid(pid, &ws, 0) < 0 && errno == EINTR) {
    }
    cleanup::untrack_child(pid);
  });
  if (!WIFEXITED(ws)) return -1;
  return WEXITSTATUS(ws);
}

}  // namespace foxi::cli
