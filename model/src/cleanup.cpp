#include "foxi/model/cleanup.hpp"

#include <stdlib.h>

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <mutex>
#include <set>
#include <string>
#include <system_error>

#include "foxi/model/io_error.hpp"

namespace foxi::cleanup {

namespace {

struct Registry {
  // Recursive: with_lock's function may track and untrack.
  std::recursive_mutex mutex;
  std::set<std::string> files, folders;
  std::set<pid_t> children;
};

// Never destroyed: interrupt() may run while exit() destroys static objects.
Registry& registry() {
  static Registry* r = new Registry;
  return *r;
}

}  // namespace

void with_lock(const std::function<void()>& fn) {
  std::lock_guard lock(registry().mutex);
  fn();
}

void track(const std::filesystem::path& path, bool folder) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  (folder ? r.folders : r.files).insert(path.string());
}

void untrack(const std::filesystem::path& path) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.files.erase(path.string());
  r.folders.erase(path.string());
}

bool is_tracked(const std::filesystem::path& path) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  if (r.files.count(path.string()) > 0 || r.folders.count(path.string()) > 0) return true;
  // The same path spelt another way: a folder's listing says ./out.mp4.foxi-tmp-... for the
  // out.mp4.foxi-tmp-... tracked (a stale-temporary sweep removed a live movie's frames so).
  const std::filesystem::path want = path.lexically_normal();
  for (const auto* set : {&r.files, &r.folders})
    for (const std::string& p : *set)
      if (std::filesystem::path(p).lexically_normal() == want) return true;
  return false;
}

pid_t fork_tracked() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    // The parent may have died between fork() and prctl(): then nobody would kill this child.
    if (::getppid() != parent) ::_exit(1);
    return 0;
  }
  if (pid > 0) r.children.insert(pid);
  return pid;
}

void untrack_child(pid_t pid) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.children.erase(pid);
}

void interrupt() {
  Registry& r = registry();
  r.mutex.lock();  // never unlocked: the program exits next
  // Children first: a helper (ffmpeg) could otherwise create a file again after it is removed.
  for (const pid_t pid : r.children) ::kill(pid, SIGKILL);
  for (const pid_t pid : r.children) {
    // ECHILD: the owning thread reaped it first.
    while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
  }
  std::error_code ec;
  for (const std::string& f : r.files) std::filesystem::remove(f, ec);
  for (const std::string& d : r.folders) std::filesystem::remove_all(d, ec);
}

TemporaryFolder::TemporaryFolder(const std::string& prefix) {
  std::string tmpl = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
  // Made and recorded under the lock: an interrupt() sees it either not yet made or recorded.
  with_lock([&] {
    if (::mkdtemp(tmpl.data()) == nullptr) return;
    path_ = tmpl;
    track(path_, true);
  });
  if (path_.empty()) throw IoError(tmpl, 0, IoError::kNoOffset, "cannot create the work folder");
}

TemporaryFolder::~TemporaryFolder() {
  with_lock([&] {
    std::error_code ec;
    if (!keep_) std::filesystem::remove_all(path_, ec);
    untrack(path_);
  });
}

}  // namespace foxi::cleanup
