// SIGINT, SIGTERM and SIGHUP at random moments of foxi mesh, solve, render, movie and convert: the exit
// status is 0 (the run finished first) or 130 (SIGINT) / 143 (SIGTERM) / 129 (SIGHUP), no process of the run
// is left (the TetGen/CGAL children and ffmpeg included), no temporary file is left, and each output is
// either absent or complete and valid (read back by foxi's readers and libpng; a TetGen set is all three
// files or none; numbered movie frames are all there or none).
//
// The delays are drawn from a seeded generator (the seed is printed, FOXI_SIGNAL_SEED repeats a
// run), uniform over the time a whole run takes on this machine, measured first.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <fcntl.h>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using foxi::test::TempDir;
namespace test = foxi::test;
using Clock = std::chrono::steady_clock;

struct Outcome {
  int status = -1;  // exit status, or -1 if it did not exit normally
  double seconds = 0;
  std::string log;
};

// Starts foxi with `args` (OUT replaced by `out_dir`), sends `sig` after `delay` (none if sig == 0),
// and waits (at most 120 s; then it is killed and the test fails).
Outcome run_foxi(const std::vector<std::string>& args, const fs::path& log, int sig, double delay) {
  std::vector<std::string> argv = {test::cli_path()};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  const auto t0 = Clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execv(cargv[0], cargv.data());
    ::_exit(127);
  }
  // The delay counts from the moment foxi has blocked SIGINT and SIGTERM (its stop handling, first
  // thing in main; /proc shows the main thread's mask): before that no file and no child exists,
  // and the signal's default action (death by the signal) is all there is to see.
  if (sig != 0) {
    const std::string status_file = "/proc/" + std::to_string(pid) + "/status";
    for (int i = 0; i < 5000; ++i) {
      const std::string st = test::read_text(status_file);
      const auto at = st.find("SigBlk:");
      if (st.empty() ||
          (at != std::string::npos && (std::stoull(st.substr(at + 7), nullptr, 16) & 0x4002) == 0x4002))
        break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  const auto t_ready = Clock::now();
  Outcome o;
  bool sent = sig == 0;
  int ws = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &ws, WNOHANG);
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    if (r == pid) {
      o.seconds = s;
      break;
    }
    if (!sent && std::chrono::duration<double>(Clock::now() - t_ready).count() >= delay) {
      ::kill(pid, sig);
      sent = true;
    }
    if (s > 120) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &ws, 0);
      ADD_FAILURE() << "foxi did not stop within 120 s";
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  o.status = WIFEXITED(ws) ? WEXITSTATUS(ws) : -1;
  o.log = test::read_text(log);
  return o;
}

// Processes (not zombies) whose command line mentions `marker`: forked children of foxi keep its
// arguments, and ffmpeg names the run's temporary file.
std::vector<std::string> processes_mentioning(const std::string& marker) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmd = test::read_text(e.path() / "cmdline");
    for (char& c : cmd)
      if (c == 0) c = ' ';
    if (cmd.find(marker) == std::string::npos) continue;
    const std::string stat = test::read_text(e.path() / "stat");
    if (stat.find(") Z") != std::string::npos) continue;
    found.push_back(name + ": " + cmd);
  }
  return found;
}

std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.find(".foxi-tmp-") != std::string::npos || n.find(".tmp") != std::string::npos)
      found.push_back(e.path().string());
  }
  return found;
}

// One kind of run: its arguments (with OUT for the trial's folder) and the check of its output,
// which returns "" if the output is absent or complete and valid, and whether it exists.
struct Case {
  std::string name;
  std::vector<std::string> args;
  std::function<std::string(const fs::path& out_dir, bool& exists)> check;
};

std::vector<std::string> with_out(const std::vector<std::string>& args, const fs::path& dir) {
  std::vector<std::string> r;
  for (std::string a : args) {
    const auto at = a.find("OUT");
    if (at != std::string::npos) a.replace(at, 3, dir.string());
    r.push_back(a);
  }
  return r;
}

std::string mesh_ok(const fs::path& path, bool& exists, const char* field = nullptr) {
  exists = fs::exists(path);
  if (!exists) return "";
  try {
    const foxi::Mesh m = foxi::read_mesh(path);
    if (m.tet_count() == 0) return path.string() + ": no tets";
    if (field) {
      bool has = false;
      for (const auto& f : m.fields) has = has || f.name == field;
      if (!has) return path.string() + ": no field " + field;
    }
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

std::string png_ok(const fs::path& path, bool& exists, int w, int h) {
  exists = fs::exists(path);
  if (!exists) return "";
  try {
    const foxi::Framebuffer fb = foxi::read_png(path);
    if (fb.width != w || fb.height != h) return path.string() + ": wrong size";
  } catch (const std::exception& e) {
    return e.what();
  }
  // The file ends with the IEND chunk (an APNG too: its frames come before it).
  const std::string bytes = test::read_text(path);
  if (bytes.size() < 12 || bytes.compare(bytes.size() - 8, 4, "IEND") != 0)
    return path.string() + ": no IEND at the end";
  return "";
}

class SignalsCliSlow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    // A mesh (212k tets) big enough that solving, drawing and converting it take a noticeable time
    // (a second or so each on a shared 2-core machine).
    const int rc =
        test::run_cli("mesh '" + test::models_dir() + "die_on_substrate.toml' --max-size 0.2mm -o '" +
                          (dir_->path() / "big.vtu").string() + "'",
                      dir_->path() / "setup.log");
    ASSERT_EQ(rc, 0) << test::read_text(dir_->path() / "setup.log");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path big() { return dir_->path() / "big.vtu"; }

  // Runs `c` once to time it, then `trials` times with SIGINT, SIGTERM or SIGHUP (in turn) after a
  // random delay up to 1.2 times that time.
  void trials(const Case& c, int count) {
    std::uint64_t seed = std::random_device{}();
    if (const char* s = std::getenv("FOXI_SIGNAL_SEED")) seed = std::strtoull(s, nullptr, 10);
    std::mt19937_64 rng(seed);
    const fs::path timing = dir_->path() / (c.name + "-timing");
    fs::create_directories(timing);
    const Outcome full = run_foxi(with_out(c.args, timing), dir_->path() / (c.name + "-timing.log"), 0, 0);
    ASSERT_EQ(full.status, 0) << full.log;
    bool exists = false;
    ASSERT_EQ(c.check(timing, exists), "");
    ASSERT_TRUE(exists) << c.name << ": a finished run wrote nothing";
    std::uniform_real_distribution<double> delay(0.0, 1.2 * full.seconds);
    int stopped = 0;
    for (int k = 0; k < count; ++k) {
      const int sig = k % 3 == 0 ? SIGINT : k % 3 == 1 ? SIGTERM : SIGHUP;
      const char* sig_name = sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "SIGHUP";
      const double d = delay(rng);
      SCOPED_TRACE(c.name + " trial " + std::to_string(k) + ": " + sig_name + " after " + std::to_string(d) +
                   " s of " + std::to_string(full.seconds) + " s, seed " + std::to_string(seed));
      const fs::path out = dir_->path() / (c.name + "-" + std::to_string(k));
      fs::create_directories(out);
      const Outcome o =
          run_foxi(with_out(c.args, out), dir_->path() / (c.name + "-" + std::to_string(k) + ".log"), sig, d);
      const int stop_status = 128 + sig;
      EXPECT_TRUE(o.status == 0 || o.status == stop_status) << "exit status " << o.status << "\n" << o.log;
      if (o.status == stop_status) {
        ++stopped;
        EXPECT_NE(o.log.find(std::string("stopped by ") + sig_name), std::string::npos) << o.log;
      }
      EXPECT_EQ(processes_mentioning(out.string()), std::vector<std::string>{});
      EXPECT_EQ(leftovers(out), std::vector<std::string>{});
      bool wrote = false;
      EXPECT_EQ(c.check(out, wrote), "");
      if (o.status == 0) {
        EXPECT_TRUE(wrote) << "exit status 0 without the output";
      }
    }
    std::printf("%s: %d trials, %d stopped by the signal, %d finished first (a whole run %.2f s)\n",
                c.name.c_str(), count, stopped, count - stopped, full.seconds);
  }

  static TempDir* dir_;
};

TempDir* SignalsCliSlow::dir_ = nullptr;

constexpr int kTrials = 6;

TEST_F(SignalsCliSlow, Mesh) {
  trials({"mesh",
          {"mesh", test::models_dir() + "die_on_substrate.toml", "--max-size", "0.3mm", "-o", "OUT/m.vtu"},
          [](const fs::path& d, bool& e) { return mesh_ok(d / "m.vtu", e); }},
         kTrials);
}

TEST_F(SignalsCliSlow, MeshToTetgenSet) {
  trials({"mesh-tetgen",
          {"mesh", test::models_dir() + "die_on_substrate.toml", "--max-size", "0.3mm", "-o", "OUT/m.node"},
          [](const fs::path& d, bool& e) {
            const int n =
                int(fs::exists(d / "m.node")) + int(fs::exists(d / "m.ele")) + int(fs::exists(d / "m.face"));
            if (n != 0 && n != 3)
              return std::string("a partial TetGen set: ") + std::to_string(n) + " of 3 files";
            return mesh_ok(d / "m.node", e);
          }},
         kTrials);
}

TEST_F(SignalsCliSlow, Solve) {
  trials({"solve",
          {"solve", big().string(), "--physics", "thermal", "--fix", "substrate.bottom=300", "--power",
           "die=1", "-o", "OUT/s.vtu"},
          [](const fs::path& d, bool& e) { return mesh_ok(d / "s.vtu", e, "temperature"); }},
         kTrials);
}

TEST_F(SignalsCliSlow, Render) {
  trials({"render",
          {"render", big().string(), "--size", "1600x1200", "-o", "OUT/r.png"},
          [](const fs::path& d, bool& e) { return png_ok(d / "r.png", e, 1600, 1200); }},
         kTrials);
}

TEST_F(SignalsCliSlow, Convert) {
  trials({"convert",
          {"convert", big().string(), "OUT/c.vtu", "--vtu-encoding", "ascii"},
          [](const fs::path& d, bool& e) { return mesh_ok(d / "c.vtu", e); }},
         kTrials);
}

TEST_F(SignalsCliSlow, ConvertToTetgenSet) {
  trials({"convert-tetgen",
          {"convert", big().string(), "OUT/c.node"},
          [](const fs::path& d, bool& e) {
            const int n =
                int(fs::exists(d / "c.node")) + int(fs::exists(d / "c.ele")) + int(fs::exists(d / "c.face"));
            if (n != 0 && n != 3)
              return std::string("a partial TetGen set: ") + std::to_string(n) + " of 3 files";
            return mesh_ok(d / "c.node", e);
          }},
         kTrials);
}

TEST_F(SignalsCliSlow, MovieApng) {
  trials({"movie-apng",
          {"movie", big().string(), "--frames", "12", "--size", "320x240", "-o", "OUT/mv.apng"},
          [](const fs::path& d, bool& e) { return png_ok(d / "mv.apng", e, 320, 240); }},
         kTrials);
}

TEST_F(SignalsCliSlow, MovieFrames) {
  trials({"movie-frames",
          {"movie", big().string(), "--frames", "12", "--size", "320x240", "-o", "OUT/f/frame_%03d.png"},
          [](const fs::path& d, bool& e) {
            e = fs::exists(d / "f");
            if (!e) return std::string();
            int n = 0;
            for (const auto& x : fs::directory_iterator(d / "f")) {
              (void)x;
              ++n;
            }
            if (n != 12) return "a partial set of frames: " + std::to_string(n) + " of 12";
            bool ex = false;
            return png_ok(d / "f" / "frame_011.png", ex, 320, 240);
          }},
         kTrials);
}

// A reader of foxi's output that goes away (foxi solve ... | head -1): SIGPIPE killed the run, its -o
// file lost and a transient's temporaries left (an outside probe). The run goes on, its files are
// written, its status is its own.
TEST(SignalsCli, ClosedPipeOnStdoutDoesNotStopTheRun) {
  test::TempDir dir;
  const std::string cmd = "bash -c \"'" + test::cli_path() + "' solve '" + test::models_dir() +
                          "die_on_substrate.toml' -o '" + (dir / "t.vtu").string() +
                          "' | head -c 1 > /dev/null; exit \\${PIPESTATUS[0]}\"";
  EXPECT_EQ(test::run(cmd, dir / "log"), 0) << test::read_text(dir / "log");
  EXPECT_TRUE(fs::exists(dir / "t.vtu"));
}

TEST_F(SignalsCliSlow, MovieMp4) {
  if (!test::have_program("ffmpeg")) GTEST_SKIP() << "ffmpeg is not installed";
  trials({"movie-mp4",
          {"movie", big().string(), "--frames", "12", "--size", "320x240", "-o", "OUT/mv.mp4"},
          [](const fs::path& d, bool& e) {
            e = fs::exists(d / "mv.mp4");
            if (!e) return std::string();
            const std::string b = test::read_text(d / "mv.mp4");
            if (b.size() < 1000 || b.compare(4, 4, "ftyp") != 0) return std::string("not a complete MP4");
            return std::string();
          }},
         kTrials);
}

}  // namespace
