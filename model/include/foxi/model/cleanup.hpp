// What an interrupted run must not leave behind: temporary files and folders, and helper processes.
//
// foxi's writers record their temporaries here while they exist, and the mesher records the child
// processes it runs TetGen and CGAL in. A program that stops on a signal calls interrupt() from an
// ordinary thread (the foxi CLI waits for SIGINT/SIGTERM in a thread of its own) and then exits:
// interrupt() kills the children, removes the temporaries, and keeps the list locked, so nothing is
// created, renamed into place or forked after it; whatever was renamed before it is complete.
// An embedding program that never calls interrupt() pays one mutex per file and per child.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <string>

#include "foxi/api.hpp"

namespace foxi::cleanup {

// Runs fn with the list locked. A temporary is created and recorded, or renamed into place and
// forgotten, inside one such call, so that interrupt() sees it either before or after, never half.
FOXI_API void with_lock(const std::function<void()>& fn);

// Records a temporary file (folder = false) or a folder removed with its contents (folder = true).
FOXI_API void track(const std::filesystem::path& path, bool folder = false);
// Forgets it (renamed into place, or removed by its owner).
FOXI_API void untrack(const std::filesystem::path& path);
FOXI_API bool is_tracked(const std::filesystem::path& path);

// fork() with the list locked, the child's process id recorded in the parent. In the child (which
// returns 0 and must not use this list) the kernel is asked to kill it when the parent dies
// (PR_SET_PDEATHSIG), so that not even a SIGKILL of the parent leaves it running on its own.
// Returns -1 with errno set when fork fails.
FOXI_API pid_t fork_tracked();
// Forgets a child once it has been reaped.
FOXI_API void untrack_child(pid_t pid);

// Kills (SIGKILL) and reaps every recorded child, removes every recorded temporary, and returns
// with the list still locked for good: the caller exits next. Not async-signal-safe: call it from
// a thread, not from a signal handler.
FOXI_API void interrupt();

// A fresh folder under the system's temporary folder (TMPDIR), named PREFIX-XXXXXX (mkdtemp), recorded
// here while it exists, so that interrupt() removes it with its contents. The destructor removes it
// unless keep() was called (then it is forgotten, and stays for the user to look into). Throws IoError
// naming the template when it cannot be made.
class FOXI_API TemporaryFolder {
 public:
  explicit TemporaryFolder(const std::string& prefix);
  ~TemporaryFolder();
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  void keep() { keep_ = true; }
  bool kept() const { return keep_; }

 private:
  std::filesystem::path path_;
  bool keep_ = false;
};

}  // namespace foxi::cleanup
