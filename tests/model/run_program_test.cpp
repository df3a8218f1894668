// foxi::run_program, the one child-process runner: a program's exit status and its output files, a
// program that cannot be run, and a Cancel (keep_going false) that kills a running child at once,
// reaps it and leaves no process behind.
#include "foxi/model/run_program.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>

#include "test_util.hpp"

namespace {

TEST(RunProgram, ExitStatusAndOutput) {
  foxi::test::TempDir dir;
  const auto out = dir.path() / "out.txt";
  EXPECT_EQ(foxi::run_program({"/bin/sh", "-c", "echo hello; echo oops >&2; exit 3"}, out.string()), 3);
  EXPECT_EQ(foxi::test::read_text(out), "hello\noops\n");
  const auto only = dir.path() / "stdout.txt";
  EXPECT_EQ(foxi::run_program({"/bin/sh", "-c", "echo a; echo b >&2"}, out.string(), only.string()), 0);
  EXPECT_EQ(foxi::test::read_text(only), "a\n");
  EXPECT_EQ(foxi::test::read_text(out), "b\n");
  EXPECT_EQ(foxi::run_program({"foxi-no-such-program-here"}), 127);
  EXPECT_EQ(foxi::run_program({"/bin/sh", "-c", "kill -9 $$"}), -1) << "died on a signal";
  // keep_going always true: the same as without it
  EXPECT_EQ(foxi::run_program({"/bin/sh", "-c", "sleep 0.1; exit 4"}, {}, {}, [] { return true; }), 4);
}

TEST(RunProgram, CancelKillsTheChild) {
  foxi::test::TempDir dir;
  const auto pid_file = dir.path() / "pid";
  const auto t0 = std::chrono::steady_clock::now();
  int asked = 0;
  // The child writes its process id and sleeps 30 s; the caller says stop once it has started.
  const int status = foxi::run_program(
      {"/bin/sh", "-c", "echo $$ > '" + pid_file.string() + "'; exec sleep 30"}, {}, {}, [&] {
        ++asked;
        return !std::filesystem::exists(pid_file) || std::filesystem::file_size(pid_file) == 0;
      });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(status, foxi::kProgramCancelled);
  EXPECT_LT(seconds, 10.0) << "killed, not waited for";
  EXPECT_GE(asked, 1);
  const pid_t child = std::stoi(foxi::test::read_text(pid_file));
  EXPECT_NE(::kill(child, 0), 0) << "the child is gone (reaped)";
}

}  // namespace
