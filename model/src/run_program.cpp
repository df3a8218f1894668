#include "foxi/model/run_program.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <thread>

#include "foxi/model/cleanup.hpp"

namespace foxi {

int run_program(const std::vector<std::string>& argv, const std::string& output, const std::string& stdout_to,
                const std::function<bool()>& keep_going) {
  if (argv.empty()) return -1;
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::fflush(nullptr);
  const pid_t pid = cleanup::fork_tracked();
  if (pid < 0) return -1;
  if (pid == 0) {
    // The stop signals stay as the caller had them (the foxi CLI blocks them: it kills this child itself).
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
  // never kills a process id that was already reaped and could be reused. Until it is reaped here the
  // id stays this child's (a zombie at worst), so a Cancel's kill cannot hit another process either.
  bool cancelled = false;
  siginfo_t info{};
  if (keep_going) {
    for (;;) {
      info.si_pid = 0;
      const int rc = ::waitid(P_PID, id_t(pid), &info, WEXITED | WNOWAIT | WNOHANG);
      if (rc == 0 && info.si_pid != 0) break;  // ended
      if (rc != 0 && errno != EINTR) break;
      if (!keep_going()) {
        ::kill(pid, SIGKILL);
        cancelled = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  } else {
    while (::waitid(P_PID, id_t(pid), &info, WEXITED | WNOWAIT) != 0 && errno == EINTR) {
    }
  }
  int ws = 0;
  cleanup::with_lock([&] {
    while (::waitpid(pid, &ws, 0) < 0 && errno == EINTR) {
    }
    cleanup::untrack_child(pid);
  });
  if (cancelled) return kProgramCancelled;
  if (!WIFEXITED(ws)) return -1;
  return WEXITSTATUS(ws);
}

}  // namespace foxi
