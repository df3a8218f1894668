#include "child_process.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "foxi/mesher/tetgen_mesher.hpp"  // MesherError
#include "foxi/model/cleanup.hpp"

namespace foxi::detail {

namespace {

bool send(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

// Reaped and forgotten with the cleanup list locked: an interrupt never kills a process id that was
// already reaped (and could be reused), nor misses a live child.
void reap(pid_t pid, int* wstatus) {
  int ws = 0;
  cleanup::with_lock([&] {
    while (::waitpid(pid, &ws, 0) < 0 && errno == EINTR) {
    }
    cleanup::untrack_child(pid);
  });
  if (wstatus) *wstatus = ws;
}

// The child's reply: a code (0 = result follows; else a MesherError code and its message follows).
[[noreturn]] void child_main(int fd, const std::function<std::vector<char>()>& work) {
  std::int32_t code = 0;
  std::vector<char> body;
  try {
    body = work();
  } catch (const MesherError& e) {
    code = e.tetgen_code() == 0 ? 2 : e.tetgen_code();
    body.assign(e.what(), e.what() + std::strlen(e.what()));
  } catch (const std::exception& e) {
    code = 2;
    body.assign(e.what(), e.what() + std::strlen(e.what()));
  } catch (...) {
    code = 2;
  }
  const bool ok = send(fd, &code, sizeof code) && send(fd, body.data(), body.size());
  ::close(fd);
  ::_exit(ok ? 0 : 3);
}

}  // namespace

std::vector<char> run_in_child(const std::function<std::vector<char>()>& work, const ProgressFn& progress,
                               const std::string& stage, const std::string& what) {
  int fds[2];
  if (::pipe(fds) != 0) throw MesherError(1, std::string("cannot create a pipe: ") + std::strerror(errno));
  std::fflush(nullptr);
  // Tracked (foxi/model/cleanup.hpp): a program stopped by a signal kills it, and it dies with
  // its parent even if the parent is killed outright.
  const pid_t pid = cleanup::fork_tracked();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw MesherError(1, "cannot start " + what + ": " + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], work);
  }
  ::close(fds[1]);
  std::vector<char> reply;
  char chunk[1 << 16];
  for (;;) {
    pollfd pfd{fds[0], POLLIN, 0};
    const int ready = ::poll(&pfd, 1, 100);
    if (ready == 0 || (ready < 0 && errno == EINTR)) {
      if (progress && !progress(stage, -1.0)) {
        ::kill(pid, SIGKILL);
        ::close(fds[0]);
        reap(pid, nullptr);
        throw MesherCancelled("meshing cancelled");
      }
      continue;
    }
    const ssize_t n = ::read(fds[0], chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    reply.insert(reply.end(), chunk, chunk + n);
  }
  ::close(fds[0]);
  int wstatus = 0;
  reap(pid, &wstatus);
  std::int32_t code = 0;
  if (reply.size() < sizeof code) {
    if (WIFSIGNALED(wstatus))
      throw MesherError(2, what + " crashed (signal " + std::to_string(WTERMSIG(wstatus)) + ") on this PLC");
    throw MesherError(2, what + " stopped without a result");
  }
  std::memcpy(&code, reply.data(), sizeof code);
  reply.erase(reply.begin(), reply.begin() + sizeof code);
  if (code != 0)
    throw_mesher_error(code, reply.empty() ? what + " failed" : std::string(reply.begin(), reply.end()));
  if (WIFSIGNALED(wstatus) || (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) != 0))
    throw MesherError(2, what + "'s result was cut short");
  return reply;
}

}  // namespace foxi::detail
