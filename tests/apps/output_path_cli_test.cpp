// Every foxi command that writes checks its output path before the work: a missing folder, a
// folder given as the output, or a path through a regular file fails at once (before a mesh of
// minutes is made), naming the path and the reason, and leaves nothing behind.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;
using foxi::test::TempDir;
namespace test = foxi::test;

struct CliRun {
  int status;
  double seconds;
  std::string log;
};

CliRun run(const std::string& args, const fs::path& log) {
  const auto t0 = std::chrono::steady_clock::now();
  const int status = test::run_cli(args, log);
  return {status, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
          test::read_text(log)};
}

TEST(OutputPathCli, UnwritableOutputsFailBeforeTheWork) {
  TempDir dir;
  const std::string model = test::models_dir() + "die_on_substrate.toml";
  // A small mesh to read.
  ASSERT_EQ(test::run_cli("mesh '" + model + "' --max-size 1mm -o '" + (dir / "m.vtu").string() + "'",
                          dir / "setup.log"),
            0)
      << test::read_text(dir / "setup.log");
  // Folders named like the outputs.
  for (const char* ext : {".vtu", ".msh", ".png", ".gif", ".poly"})
    fs::create_directories(dir / (std::string("folder") + ext));
  test::write_text(dir / "file", "x");
  const std::string m = "'" + (dir / "m.vtu").string() + "'";
  struct Bad {
    std::string out;
    const char* reason;
  };
  const std::vector<Bad> bad = {
      {(dir / "missing" / "o").string(), "does not exist"},
      {(dir / "folder").string(), "is a folder"},
      {(dir / "file" / "o").string(), "is not a folder"},
  };
  for (const Bad& b : bad) {
    const std::string q = "'" + b.out;
    // The commands, each with an output of the right kind at b.out (a suffix added after the name).
    const std::vector<std::string> commands = {
        // Meshing at 0.05 mm takes minutes: the check must come first.
        "mesh '" + model + "' --max-size 0.05mm -o " + q + ".vtu'",
        "convert " + m + " " + q + ".msh'",
        "solve " + m + " --physics thermal --fix substrate.bottom=300 --power die=1 -o " + q + ".vtu'",
        "render " + m + " -o " + q + ".png'",
        "movie " + m + " --frames 2 -o " + q + ".gif'",
        "model plc '" + model + "' -o " + q + ".poly'",
    };
    for (const std::string& c : commands) {
      SCOPED_TRACE(c);
      const CliRun r = run(c, dir / "log.txt");
      EXPECT_NE(r.status, 0) << r.log;
      EXPECT_NE(r.status, 2) << "not a usage error: " << r.log;
      EXPECT_NE(r.log.find(b.reason), std::string::npos) << r.log;
      EXPECT_LT(r.seconds, 20.0 * test::kTimeScale) << "the path was checked after the work";
      EXPECT_EQ(r.log.find("delaunay:"), std::string::npos) << r.log;
    }
  }
  // Nothing was written anywhere but the setup mesh and its log.
  std::vector<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir.path()))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"file", "folder.gif", "folder.msh", "folder.png", "folder.poly",
                                             "folder.vtu", "log.txt", "m.vtu", "setup.log"}));
}

}  // namespace
