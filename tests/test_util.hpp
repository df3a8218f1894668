// Helpers for the tests: temporary folders, running outside programs (gmsh, tetgen, the foxi CLI).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace foxi::test {

// Wall-time bounds in tests are set for the Release build; the sanitizer build (Debug with
// AddressSanitizer and UndefinedBehaviorSanitizer) runs several times slower, so a bound is
// multiplied by this there. A hang is still caught: the bounds stay far below "minutes".
#if defined(__SANITIZE_ADDRESS__)
constexpr double kTimeScale = 20;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr double kTimeScale = 20;
#else
constexpr double kTimeScale = 1;
#endif
#else
constexpr double kTimeScale = 1;
#endif

// A fresh empty folder under the system temp folder, removed with everything in it at scope exit.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("foxi-test-" + std::to_string(rd()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs a shell command; returns its exit status (0 = success). Output goes to `log` if given.
inline int run(const std::string& command, const std::filesystem::path& log = {}) {
  std::string cmd = command;
  if (!log.empty()) cmd += " > '" + log.string() + "' 2>&1";
  int status = std::system(cmd.c_str());
  if (status == -1) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

// True if an outside program is on PATH.
inline bool have_program(const std::string& name) {
  return run("command -v " + name + " > /dev/null 2>&1") == 0;
}

inline std::string data_dir() { return FOXI_TEST_DATA_DIR; }
inline std::string cli_path() { return FOXI_CLI_PATH; }
inline std::string models_dir() { return data_dir() + "/../../models/"; }

// Runs the foxi program with `args` (already quoted as needed); output to `log`.
inline int run_cli(const std::string& args, const std::filesystem::path& log) {
  return run("'" + cli_path() + "' " + args, log);
}

}  // namespace foxi::test
