// Reading Gmsh .msh 4.1 files (binary and ASCII) of a 1.1M-tet mesh: foxi against the gmsh program
// loading the same file, in the same run.
//
// The files are written once to a temporary folder (or to $FOXI_BENCH_DIR, kept, if set) and read
// from the page cache. gmsh is timed as a whole process running `gmsh -nopopup FILE -parse_and_exit`
// (open the file, i.e. read the mesh, then exit), as CPU time of the process minus its start-up CPU
// time, measured on a one-tet file with the same command; the benchmark checks that gmsh's log
// reports the right node count.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <sys/time.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/io_gmsh.hpp"

namespace {

namespace fs = std::filesystem;

// (tests/test_util.hpp needs the test targets' definitions, so the few helpers needed live here.)
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("foxi-bench-" + std::to_string(rd()) + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

int run(const std::string& cmd) { return std::system(cmd.c_str()); }

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct Files {
  std::optional<TempDir> tmp;
  fs::path dir, binary, ascii, tiny;
  std::size_t tets = 0, nodes = 0;
  double gmsh_startup = 0;  // seconds
  bool have_gmsh = false;
};

// CPU time (user + system) of a child process running `cmd`, in seconds. CPU time, like the CPU time
// Google Benchmark reports for foxi's reader, is what a shared, loaded machine measures reliably;
// gmsh runs single-threaded (-nt 1), so its CPU time is its reading time.
double seconds_of(const std::string& cmd) {
  rusage before{}, after{};
  getrusage(RUSAGE_CHILDREN, &before);
  run(cmd);
  getrusage(RUSAGE_CHILDREN, &after);
  auto sec = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return sec(after.ru_utime) - sec(before.ru_utime) + sec(after.ru_stime) - sec(before.ru_stime);
}

std::string gmsh_command(const fs::path& file, const fs::path& log) {
  return "gmsh -nopopup -nt 1 '" + file.string() + "' -parse_and_exit > '" + log.string() + "' 2>&1";
}

void setup(Files& r) {
  {
    if (const char* d = std::getenv("FOXI_BENCH_DIR")) {
      r.dir = d;
      fs::create_directories(r.dir);
    } else {
      r.tmp.emplace();
      r.dir = r.tmp->path();
    }
    const foxi::Mesh m = foxi::bench::kuhn_grid_mesh(57);
    r.tets = m.tet_count();
    r.nodes = m.node_count();
    r.binary = r.dir / "kuhn57_bin.msh";
    r.ascii = r.dir / "kuhn57_ascii.msh";
    r.tiny = r.dir / "tiny.msh";
    foxi::write_gmsh(m, r.binary, {41, true});
    foxi::write_gmsh(m, r.ascii, {41, false});
    foxi::write_gmsh(foxi::bench::kuhn_grid_mesh(1), r.tiny, {41, false});
    r.have_gmsh = run("command -v gmsh > /dev/null 2>&1") == 0;
    if (r.have_gmsh) {
      std::vector<double> t;
      for (int i = 0; i < 5; ++i) t.push_back(seconds_of(gmsh_command(r.tiny, r.dir / "tiny.log")));
      std::sort(t.begin(), t.end());
      r.gmsh_startup = t[2];
    }
  }
}

Files& files() {
  static Files f;
  static const bool ready = (setup(f), true);
  (void)ready;
  return f;
}

void set_counters(benchmark::State& state, std::size_t bytes, std::size_t tets) {
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.counters["ns_per_tet"] =
      benchmark::Counter(static_cast<double>(tets) * 1e-9,
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["tets"] = static_cast<double>(tets);
}

void BM_FoxiRead(benchmark::State& state, bool binary) {
  Files& f = files();
  const fs::path& file = binary ? f.binary : f.ascii;
  for (auto _ : state) {
    foxi::Mesh m = foxi::read_gmsh(file);
    if (m.tet_count() != f.tets || m.node_count() != f.nodes) state.SkipWithError("wrong counts");
    benchmark::DoNotOptimize(m.tet.data());
  }
  set_counters(state, fs::file_size(file), f.tets);
}

// gmsh's own reader: the whole process time minus its start-up on a one-tet file.
void BM_GmshProgramRead(benchmark::State& state, bool binary) {
  Files& f = files();
  if (!f.have_gmsh) {
    state.SkipWithError("gmsh not found");
    return;
  }
  const fs::path& file = binary ? f.binary : f.ascii;
  const fs::path log = f.dir / "gmsh.log";
  for (auto _ : state) {
    double t = seconds_of(gmsh_command(file, log));
    state.SetIterationTime(std::max(t - f.gmsh_startup, 1e-6));
  }
  // Check that gmsh really read the mesh: its log names the node and element counts.
  const std::string text = read_text(log);
  if (text.find(std::to_string(f.nodes) + " nodes") == std::string::npos) {
    state.SkipWithError(("gmsh did not report reading the nodes: " + text.substr(0, 300)).c_str());
  }
  state.counters["gmsh_startup_s"] = f.gmsh_startup;
  set_counters(state, fs::file_size(file), f.tets);
}

BENCHMARK_CAPTURE(BM_FoxiRead, binary41, true)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_FoxiRead, ascii41, false)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_GmshProgramRead, binary41, true)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);
BENCHMARK_CAPTURE(BM_GmshProgramRead, ascii41, false)
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime()
    ->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
