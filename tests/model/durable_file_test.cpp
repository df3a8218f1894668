// Durable, all-or-nothing writes (foxi/model/durable_file.hpp) and the cleanup list of an interrupted
// run (foxi/model/cleanup.hpp). Oracles: the folder's listing, the bytes read back, process ids that
// are known to be dead (a reaped child) or alive (a sleeping child), the system calls the writer
// makes as strace records them (fsync before rename, the folder flushed after), and TetGen's own
// reader for a set written together.
#include "foxi/model/durable_file.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "foxi/model/cleanup.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/mesh.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

bool has_temp(const fs::path& dir) {
  for (const std::string& n : listing(dir))
    if (n.find(".foxi-tmp-") != std::string::npos) return true;
  return false;
}

// A process id that belonged to a process that has exited and been reaped.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

TEST(DurableFile, CommitReplacesTheTargetAndLeavesNoTemporary) {
  TempDir dir;
  const fs::path out = dir / "a.txt";
  test::write_text(out, "old");
  {
    DurableFile f(out);
    EXPECT_EQ(f.temp().parent_path(), out.parent_path());
    EXPECT_NE(f.temp().filename().string().find("a.txt.foxi-tmp-" + std::to_string(::getpid()) + "-"),
              std::string::npos)
        << f.temp();
    EXPECT_TRUE(cleanup::is_tracked(f.temp()));
    std::string big(3 << 20, 'x');  // more than the buffer: written through
    f.write("head ");
    f.write(big);
    f.write(" tail");
    f.overwrite(0, "HEAD");
    // Until commit the old file is untouched.
    EXPECT_EQ(test::read_text(out), "old");
    f.commit();
    EXPECT_FALSE(cleanup::is_tracked(f.temp()));
    EXPECT_EQ(test::read_text(out), "HEAD " + big + " tail");
  }
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"a.txt"});
}

TEST(DurableFile, AbandonedWriteRemovesItsTemporaryAndKeepsTheOldFile) {
  TempDir dir;
  const fs::path out = dir / "a.vtu";
  test::write_text(out, "old");
  {
    DurableFile f(out);
    f.write("partial");
    EXPECT_TRUE(fs::exists(f.temp()));
  }
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"a.vtu"});
  EXPECT_EQ(test::read_text(out), "old");
}

TEST(DurableFile, StaleTemporariesOfDeadWritersOnlyAreRemoved) {
  TempDir dir;
  const fs::path out = dir / "m.msh";
  const pid_t dead = dead_pid();
  // A live writer of another run: a child that sleeps until killed.
  const pid_t live = ::fork();
  if (live == 0) {
    ::pause();
    ::_exit(0);
  }
  const std::string dead_tmp = "m.msh.foxi-tmp-" + std::to_string(dead) + "-0badf00d";
  const std::string live_tmp = "m.msh.foxi-tmp-" + std::to_string(live) + "-12345678";
  const std::vector<std::string> foreign = {
      "m.msh.tmp1234abcd",                                  // the old naming: whose it is cannot be known
      "m.msh.foxi-tmp-notapid-1",                           // not foxi's pattern
      "other.msh.foxi-tmp-" + std::to_string(dead) + "-1",  // another target's
  };
  test::write_text(dir / dead_tmp, "left by a killed writer");
  test::write_text(dir / live_tmp, "being written");
  for (const auto& n : foreign) test::write_text(dir / n, "x");
  {
    DurableFile f(out);
    f.write("new");
    f.commit();
  }
  ::kill(live, SIGKILL);
  ::waitpid(live, nullptr, 0);
  const auto names = listing(dir.path());
  auto has = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) != names.end(); };
  EXPECT_FALSE(has(dead_tmp));
  EXPECT_TRUE(has(live_tmp));
  for (const auto& n : foreign) EXPECT_TRUE(has(n)) << n;
  EXPECT_EQ(test::read_text(out), "new");
  // Now its writer is gone too: the next write removes it.
  EXPECT_EQ(remove_stale_temporaries(out), 1u);
  EXPECT_FALSE(fs::exists(dir / live_tmp));
  // The whole folder's (a movie's frames): another target's temporary of a dead writer goes too,
  // names that are not foxi's stay.
  EXPECT_EQ(remove_stale_temporaries_in(dir.path()), 1u);
  EXPECT_FALSE(fs::exists(dir / foreign[2]));
  EXPECT_TRUE(fs::exists(dir / foreign[0]));
  EXPECT_TRUE(fs::exists(dir / foreign[1]));
}

TEST(DurableFile, ConcurrentWritersOfOneProcessKeepEachOthersTemporaries) {
  TempDir dir;
  const fs::path out = dir / "x.png";
  DurableFile a(out);
  a.write("a");
  DurableFile b(out);  // must not take a's temporary for a stale one
  b.write("b");
  EXPECT_TRUE(fs::exists(a.temp()));
  a.commit();
  b.commit();
  EXPECT_EQ(test::read_text(out), "b");
  EXPECT_FALSE(has_temp(dir.path()));
}

TEST(DurableFile, FsyncBeforeRenameAndTheFolderAfter) {
  if (!test::have_program("strace")) GTEST_SKIP() << "strace is not installed";
  // The order of the system calls, recorded by strace around a small program: this test binary
  // run again with a filter, writing one file.
  // (LeakSanitizer cannot run under ptrace, so the traced run turns it off in the sanitizer build.)
  TempDir dir;
  const fs::path out = dir / "d.txt";
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  const int rc = test::run("DURABLE_FILE_TARGET='" + out.string() +
                               "' ASAN_OPTIONS=detect_leaks=0 strace -f -e "
                               "trace=openat,fsync,rename,renameat,renameat2,unlink,unlinkat -o '" +
                               (dir / "trace").string() + "' '" + self +
                               "' --gtest_filter=DurableFile.WriteOneFileForStrace",
                           dir / "log");
  ASSERT_EQ(rc, 0) << test::read_text(dir / "log");
  const std::string trace = test::read_text(dir / "trace");
  std::istringstream lines(trace);
  std::string line, tmp_fd, dir_fd;
  int step = 0;  // 1: temp opened, 2: temp fsynced, 3: renamed, 4: folder opened, 5: folder fsynced
  while (std::getline(lines, line)) {
    const auto eq = line.rfind("= ");
    const std::string result = eq == std::string::npos ? "" : line.substr(eq + 2);
    if (step == 0 && line.find("openat(") != std::string::npos &&
        line.find("d.txt.foxi-tmp-") != std::string::npos) {
      tmp_fd = result;
      step = 1;
    } else if (step == 1 && line.find("fsync(" + tmp_fd + ")") != std::string::npos) {
      step = 2;
    } else if (step == 2 && line.find("rename") != std::string::npos &&
               line.find("d.txt\"") != std::string::npos) {
      step = 3;
    } else if (step == 3 && line.find("openat(") != std::string::npos &&
               line.find("O_DIRECTORY") != std::string::npos) {
      dir_fd = result;
      step = 4;
    } else if (step == 4 && line.find("fsync(" + dir_fd + ")") != std::string::npos) {
      step = 5;
    }
  }
  EXPECT_EQ(step, 5) << trace;
  EXPECT_EQ(test::read_text(out), "durable");
}

// Not a test by itself: the program strace watches above and below.
TEST(DurableFile, WriteOneFileForStrace) {
  const char* target = std::getenv("DURABLE_FILE_TARGET");
  if (!target) GTEST_SKIP() << "run by FsyncBeforeRenameAndTheFolderAfter";
  if (std::getenv("DURABLE_FILE_SET")) {
    std::vector<DurableFile> files;
    for (const char* ext : {".node", ".ele", ".face"}) {
      files.emplace_back(std::string(target) + ext);
      files.back().write(ext);
    }
    commit_together(files, 0);
    return;
  }
  DurableFile f(target);
  f.write("durable");
  f.commit();
}

// The set's system calls as strace records them: the old marker (.node) is removed before anything
// is renamed, and the new one is renamed after the .ele and the .face, each step flushed.
TEST(DurableFile, SetMarkerGoesFirstAndComesLast) {
  if (!test::have_program("strace")) GTEST_SKIP() << "strace is not installed";
  TempDir dir;
  const fs::path base = dir / "s";
  for (const char* ext : {".node", ".ele", ".face"}) test::write_text(dir / (std::string("s") + ext), "old");
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  const int rc = test::run("DURABLE_FILE_SET=1 DURABLE_FILE_TARGET='" + base.string() +
                               "' ASAN_OPTIONS=detect_leaks=0 strace -f -e "
                               "trace=fsync,rename,renameat,renameat2,unlink,unlinkat -o '" +
                               (dir / "trace").string() + "' '" + self +
                               "' --gtest_filter=DurableFile.WriteOneFileForStrace",
                           dir / "log");
  ASSERT_EQ(rc, 0) << test::read_text(dir / "log");
  const std::string trace = test::read_text(dir / "trace");
  std::istringstream lines(trace);
  std::string line;
  std::vector<std::string> events;  // "unlink node", "rename ele", "fsync", ...
  while (std::getline(lines, line)) {
    for (const char* ext : {"node", "ele", "face"}) {
      const std::string target = "s." + std::string(ext) + "\"";  // the target, not a temporary
      if (line.find(target) == std::string::npos) continue;
      if (line.find("unlink") != std::string::npos) events.push_back(std::string("unlink ") + ext);
      if (line.find("rename") != std::string::npos) events.push_back(std::string("rename ") + ext);
    }
    if (line.find("fsync(") != std::string::npos && !events.empty() && events.back() != "fsync")
      events.push_back("fsync");
  }
  const std::vector<std::string> expected = {"unlink node", "fsync",       "rename ele", "rename face",
                                             "fsync",       "rename node", "fsync"};
  EXPECT_EQ(events, expected) << trace;
  for (const char* ext : {".node", ".ele", ".face"})
    EXPECT_EQ(test::read_text(dir / (std::string("s") + ext)), ext);
}

Mesh two_tets() {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  m.tet = {0, 1, 2, 3, 1, 2, 3, 4};
  m.tet_region = {1, 2};
  m.bface = {0, 1, 2};
  m.bface_tag = {7};
  return m;
}

TEST(DurableFile, TetgenSetIsCommittedTogether) {
  TempDir dir;
  const fs::path base = dir / "box";
  write_tetgen(two_tets(), base);
  Mesh changed = two_tets();
  changed.xyz[0] = -1;
  write_tetgen(changed, base);
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"box.ele", "box.face", "box.node"}));
  const Mesh back = read_tetgen(base);
  EXPECT_EQ(back.xyz, changed.xyz);
  EXPECT_EQ(back.tet, changed.tet);
  EXPECT_EQ(back.bface_tag, changed.bface_tag);
}

TEST(DurableFile, FailedSetLeavesNoMixedSet) {
  TempDir dir;
  const fs::path base = dir / "box";
  write_tetgen(two_tets(), base);
  // The .face cannot be replaced (a folder with something in it took its name): the set must not
  // end up with the new .node beside the old .face, nor with temporaries.
  fs::remove(dir / "box.face");
  fs::create_directories(dir / "box.face" / "inside");
  Mesh changed = two_tets();
  changed.xyz[0] = -1;
  EXPECT_THROW(write_tetgen(changed, base), IoError);
  EXPECT_FALSE(fs::exists(dir / "box.node"));  // the marker: the set reads as absent
  EXPECT_FALSE(has_temp(dir.path()));
  EXPECT_THROW(read_tetgen(base), IoError);
}

TEST(DurableFile, SetCommitReplacesAnOldMarker) {
  TempDir dir;
  std::vector<DurableFile> files;
  for (const char* n : {"s.node", "s.ele", "s.face"}) {
    files.emplace_back(dir / n);
    files.back().write(n);
  }
  test::write_text(dir / "s.node", "old node");
  commit_together(files, 0);
  for (const char* n : {"s.node", "s.ele", "s.face"}) EXPECT_EQ(test::read_text(dir / n), n);
  EXPECT_FALSE(has_temp(dir.path()));
}

TEST(DurableFile, OutputPathIsCheckedBeforeWork) {
  TempDir dir;
  EXPECT_NO_THROW(check_output_path(dir / "new.vtu"));
  EXPECT_THROW(check_output_path(dir / "missing" / "new.vtu"), IoError);
  fs::create_directories(dir / "sub");
  EXPECT_THROW(check_output_path(dir / "sub"), IoError);
  test::write_text(dir / "file", "x");
  EXPECT_THROW(check_output_path(dir / "file" / "new.vtu"), IoError);
  try {
    check_output_path(dir / "missing" / "new.vtu");
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

// cleanup::interrupt in a process of its own (it keeps the list locked for good): the temporaries
// are removed and the tracked child is killed, while a committed file stays.
TEST(Cleanup, InterruptKillsChildrenAndRemovesTemporaries) {
  TempDir dir;
  int pipefd[2];
  ASSERT_EQ(::pipe(pipefd), 0);
  const pid_t runner = ::fork();
  if (runner == 0) {
    ::close(pipefd[0]);
    DurableFile done(dir / "done.txt");
    done.write("complete");
    done.commit();
    DurableFile pending(dir / "pending.txt");  // never destroyed: _exit below
    pending.write("half");
    const pid_t child = cleanup::fork_tracked();
    if (child == 0) {
      for (;;) ::pause();
    }
    cleanup::interrupt();
    // Killed and reaped by interrupt(): the id names no process of ours any more (not even a zombie).
    const bool reaped = ::kill(child, 0) != 0 && errno == ESRCH;
    const char verdict = reaped ? 'R' : 'A';
    if (::write(pipefd[1], &verdict, 1) != 1) ::_exit(3);
    ::_exit(0);
  }
  ::close(pipefd[1]);
  char verdict = 0;
  while (::read(pipefd[0], &verdict, 1) < 0 && errno == EINTR) {
  }
  ::close(pipefd[0]);
  int ws = 0;
  ::waitpid(runner, &ws, 0);
  ASSERT_TRUE(WIFEXITED(ws) && WEXITSTATUS(ws) == 0);
  EXPECT_EQ(verdict, 'R') << "the tracked child was not killed and reaped";
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"done.txt"});
  EXPECT_EQ(test::read_text(dir / "done.txt"), "complete");
}

// A tracked child dies with its parent even when the parent is killed outright (PR_SET_PDEATHSIG).
TEST(Cleanup, TrackedChildDiesWithItsParent) {
  int pipefd[2];
  ASSERT_EQ(::pipe(pipefd), 0);
  const pid_t parent = ::fork();
  if (parent == 0) {
    ::close(pipefd[0]);
    const pid_t child = cleanup::fork_tracked();
    if (child == 0) {
      for (;;) ::pause();
    }
    const std::string pid = std::to_string(child) + "\n";
    if (::write(pipefd[1], pid.data(), pid.size()) < 0) ::_exit(3);
    for (;;) ::pause();
  }
  ::close(pipefd[1]);
  char buf[32] = {};
  ssize_t n = 0, got = 0;
  while ((n = ::read(pipefd[0], buf + got, sizeof buf - 1 - std::size_t(got))) > 0 &&
         buf[got + n - 1] != '\n')
    got += n;
  ::close(pipefd[0]);
  const pid_t child = pid_t(std::atoi(buf));
  ASSERT_GT(child, 0);
  ASSERT_EQ(::kill(child, 0), 0);
  ::kill(parent, SIGKILL);
  ::waitpid(parent, nullptr, 0);
  // The orphan is killed by the kernel; it may stay a zombie until its new parent reaps it.
  bool gone = false;
  for (int i = 0; i < 200 && !gone; ++i) {
    const std::string stat = test::read_text("/proc/" + std::to_string(child) + "/stat");
    gone = stat.empty() || stat.find(") Z") != std::string::npos;
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(gone) << "the child " << child << " outlived its killed parent";
}

}  // namespace
}  // namespace foxi
