// .vtu read and write throughput on kuhn_grid_mesh(57) (1.1M tets, 195k nodes), files in page
// cache. Baseline in the same run: meshio reading the same files (its read alone, timed inside
// Python), so foxi/meshio ratios read off one run.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/io_vtk.hpp"

namespace {

namespace fs = std::filesystem;

// A temporary folder removed at exit.
struct TempDir {
  fs::path path = fs::temp_directory_path() / ("foxi-bench-vtu-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path operator/(const std::string& n) const { return path / n; }
};

struct Files {
  foxi::Mesh mesh = foxi::bench::kuhn_grid_mesh(57);
  TempDir dir;
  fs::path path(foxi::VtuEncoding e) const {
    static const char* names[] = {"ascii.vtu", "base64.vtu", "raw.vtu", "zlib.vtu"};
    return dir / names[static_cast<int>(e)];
  }
  Files() {
    for (auto e : {foxi::VtuEncoding::appended_raw, foxi::VtuEncoding::zlib, foxi::VtuEncoding::ascii})
      foxi::write_vtu(mesh, path(e), e);
  }
};

Files& files() {
  static Files f;
  return f;
}

const char* encoding_name(foxi::VtuEncoding e) {
  switch (e) {
    case foxi::VtuEncoding::ascii:
      return "ascii";
    case foxi::VtuEncoding::base64:
      return "base64";
    case foxi::VtuEncoding::appended_raw:
      return "appended_raw";
    case foxi::VtuEncoding::zlib:
      return "zlib";
  }
  return "?";
}

void read_foxi(benchmark::State& state, foxi::VtuEncoding e) {
  Files& f = files();
  const fs::path p = f.path(e);
  const auto bytes = static_cast<std::int64_t>(fs::file_size(p));
  std::size_t tets = 0;
  for (auto _ : state) {
    foxi::Mesh m = foxi::read_vtu(p);
    tets = m.tet_count();
    benchmark::DoNotOptimize(m.xyz.data());
  }
  if (tets != f.mesh.tet_count()) state.SkipWithError("wrong tet count");
  state.SetBytesProcessed(bytes * state.iterations());
  state.counters["ns_per_tet"] = benchmark::Counter(
      static_cast<double>(tets), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
  state.SetLabel(encoding_name(e));
}

void write_foxi(benchmark::State& state, foxi::VtuEncoding e) {
  Files& f = files();
  const fs::path p = f.dir / "write.vtu";
  for (auto _ : state) foxi::write_vtu(f.mesh, p, e);
  const auto bytes = static_cast<std::int64_t>(fs::file_size(p));
  state.SetBytesProcessed(bytes * state.iterations());
  state.counters["ns_per_tet"] =
      benchmark::Counter(static_cast<double>(f.mesh.tet_count()),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(encoding_name(e));
}

// meshio.read timed inside Python (interpreter start and imports excluded).
void read_meshio(benchmark::State& state, foxi::VtuEncoding e) {
  Files& f = files();
  const fs::path p = f.path(e);
  const auto bytes = static_cast<std::int64_t>(fs::file_size(p));
  const std::string cmd =
      "/usr/bin/python3 -c \"import time, meshio; t = time.perf_counter(); m = meshio.read('" + p.string() +
      "'); t = time.perf_counter() - t; print(t, sum(len(c.data) for c in m.cells if c.type == 'tetra'))\" "
      "2>/dev/null";
  for (auto _ : state) {
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
    double seconds = -1, tets = 0;
    if (!pipe || std::fscanf(pipe.get(), "%lf %lf", &seconds, &tets) != 2 || seconds <= 0 ||
        tets != static_cast<double>(f.mesh.tet_count())) {
      state.SkipWithError("meshio failed (is /usr/bin/python3 with meshio installed?)");
      break;
    }
    state.SetIterationTime(seconds);
  }
  state.SetBytesProcessed(bytes * state.iterations());
  state.counters["ns_per_tet"] =
      benchmark::Counter(static_cast<double>(f.mesh.tet_count()),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(encoding_name(e));
}

using foxi::VtuEncoding;
BENCHMARK_CAPTURE(read_foxi, appended_raw, VtuEncoding::appended_raw)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_foxi, zlib, VtuEncoding::zlib)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_foxi, ascii, VtuEncoding::ascii)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(write_foxi, appended_raw, VtuEncoding::appended_raw)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(write_foxi, zlib, VtuEncoding::zlib)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(write_foxi, ascii, VtuEncoding::ascii)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);
BENCHMARK_CAPTURE(read_meshio, appended_raw, VtuEncoding::appended_raw)
    ->UseManualTime()
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_meshio, zlib, VtuEncoding::zlib)
    ->UseManualTime()
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_meshio, ascii, VtuEncoding::ascii)
    ->UseManualTime()
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
