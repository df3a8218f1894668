// TetGen and Medit ASCII throughput on kuhn_grid_mesh(57) (1.1M tets, 195k nodes), in MB/s of text.
// Baselines in the same binary: reading the bytes from disk (read_file) and a bare whitespace scan
// of the same text, so the parser's cost reads off as a ratio.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "io_util.hpp"

namespace {

namespace fs = std::filesystem;

struct Files {
  fs::path dir;
  std::string node, ele, face, medit;
  foxi::Mesh mesh;
  Files() {
    dir = fs::temp_directory_path() / "foxi-bench-io-tetgen";
    fs::create_directories(dir);
    mesh = foxi::bench::kuhn_grid_mesh(57);
    foxi::write_tetgen(mesh, dir / "k");
    foxi::write_medit(mesh, dir / "k.mesh");
    node = foxi::io::read_file(dir / "k.node");
    ele = foxi::io::read_file(dir / "k.ele");
    face = foxi::io::read_file(dir / "k.face");
    medit = foxi::io::read_file(dir / "k.mesh");
  }
  ~Files() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::size_t tetgen_bytes() const { return node.size() + ele.size() + face.size(); }
};

Files& files() {
  static Files f;
  return f;
}

void BM_TetgenParse(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) {
    foxi::Mesh m = foxi::parse_tetgen(f.node, f.ele, f.face, "k");
    benchmark::DoNotOptimize(m.tet.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.tetgen_bytes()));
  state.counters["tets/s"] = benchmark::Counter(static_cast<double>(state.iterations() * f.mesh.tet_count()),
                                                benchmark::Counter::kIsRate);
}

void BM_TetgenRead(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) {
    foxi::Mesh m = foxi::read_tetgen(f.dir / "k");
    benchmark::DoNotOptimize(m.tet.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.tetgen_bytes()));
}

void BM_TetgenWrite(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) foxi::write_tetgen(f.mesh, f.dir / "w");
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.tetgen_bytes()));
}

void BM_MeditParse(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) {
    foxi::Mesh m = foxi::parse_medit(f.medit, "k.mesh");
    benchmark::DoNotOptimize(m.tet.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.medit.size()));
}

void BM_MeditWrite(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) foxi::write_medit(f.mesh, f.dir / "w.mesh");
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.medit.size()));
}

// Baseline: bytes from disk only.
void BM_BaselineReadFile(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) {
    std::string a = foxi::io::read_file(f.dir / "k.node"), b = foxi::io::read_file(f.dir / "k.ele"),
                c = foxi::io::read_file(f.dir / "k.face");
    benchmark::DoNotOptimize(a.data());
    benchmark::DoNotOptimize(b.data());
    benchmark::DoNotOptimize(c.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.tetgen_bytes()));
}

// Baseline: counting tokens in the same text (the least any text parser must do).
void BM_BaselineTokenScan(benchmark::State& state) {
  Files& f = files();
  for (auto _ : state) {
    std::size_t tokens = 0;
    for (const std::string* s : {&f.node, &f.ele, &f.face}) {
      bool in = false;
      for (char c : *s) {
        bool space = c == ' ' || c == '\n' || c == '\t' || c == '\r';
        tokens += !space && !in;
        in = !space;
      }
    }
    benchmark::DoNotOptimize(tokens);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * f.tetgen_bytes()));
}

BENCHMARK(BM_TetgenParse)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TetgenRead)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TetgenWrite)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeditParse)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeditWrite)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineReadFile)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineTokenScan)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
