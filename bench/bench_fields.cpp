// The field importer: location transfer of a node field between two ~1M-tet meshes of one box
// (kuhn_grid_mesh(57), 1.1M tets, 195k nodes, onto kuhn_grid_mesh(55) with other jitter, 1.0M tets,
// 175k nodes), with scipy's LinearNDInterpolator on the same points as the baseline in the same run
// (its Delaunay triangulation of the source points and the evaluation, timed inside Python); and
// the ASCII .frd reader's throughput on a 1.1M-tet result file (nodes, C3D4 elements, NDTEMP, DISP,
// STRESS, written as ccx writes them) next to the .vtu reader's on the same mesh and fields (ASCII
// and appended raw), files in page cache.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/fields.hpp"
#include "foxi/model/io_vtk.hpp"

namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("foxi-bench-fields-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path operator/(const std::string& n) const { return path / n; }
};

double linear(const double* p) { return 300 + 20 * p[0] - 30 * p[1] + 5 * p[2]; }

struct Data {
  TempDir dir;
  foxi::FieldSource source;
  foxi::Mesh target = foxi::bench::kuhn_grid_mesh(55, 0.3, 2);
  Data() {
    source.path = "source";
    source.format = "vtu";
    source.mesh = foxi::bench::kuhn_grid_mesh(57, 0.1, 1);
    foxi::Mesh& m = source.mesh;
    foxi::Field t{"T", foxi::FieldLocation::node, 1, "K", {}, {}};
    foxi::Field u{"U", foxi::FieldLocation::node, 3, "m", {}, {}};
    foxi::Field s{"S", foxi::FieldLocation::node, 6, "Pa", {}, {}};
    for (std::size_t i = 0; i < m.node_count(); ++i) {
      t.values.push_back(linear(&m.xyz[3 * i]));
      for (int k = 0; k < 3; ++k) u.values.push_back(1e-4 * std::sin(double(3 * i + k)));
      for (int k = 0; k < 6; ++k) s.values.push_back(1e7 * std::cos(double(6 * i + k)));
    }
    m.fields = {t, u, s};
    write_frd(dir / "big.frd");
    foxi::write_vtu(m, dir / "ascii.vtu", foxi::VtuEncoding::ascii);
    foxi::write_vtu(m, dir / "raw.vtu", foxi::VtuEncoding::appended_raw);
    // Raw doubles for the Python baseline: source points, values, target points.
    auto dump = [&](const std::string& name, const std::vector<double>& v) {
      std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen((dir / name).c_str(), "wb"), std::fclose);
      std::fwrite(v.data(), sizeof(double), v.size(), f.get());
    };
    dump("src_xyz.bin", m.xyz);
    dump("src_t.bin", t.values);
    dump("tgt_xyz.bin", target.xyz);
  }
  // ccx's long ASCII format: I10 ids, E12.5 values.
  void write_frd(const fs::path& p) const {
    const foxi::Mesh& m = source.mesh;
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(p.c_str(), "w"), std::fclose);
    std::fprintf(f.get(), "    1C\n    1UPGM               CalculiX\n");
    std::fprintf(f.get(), "    2C%30zu%37d\n", m.node_count(), 1);
    for (std::size_t i = 0; i < m.node_count(); ++i)
      std::fprintf(f.get(), " -1%10zu%12.5E%12.5E%12.5E\n", i + 1, m.xyz[3 * i], m.xyz[3 * i + 1],
                   m.xyz[3 * i + 2]);
    std::fprintf(f.get(), " -3\n    3C%30zu%37d\n", m.tet_count(), 1);
    for (std::size_t t = 0; t < m.tet_count(); ++t)
      std::fprintf(f.get(), " -1%10zu%5d%5d%5d\n -2%10u%10u%10u%10u\n", t + 1, 3, 0, 1, m.tet[4 * t] + 1,
                   m.tet[4 * t + 1] + 1, m.tet[4 * t + 2] + 1, m.tet[4 * t + 3] + 1);
    std::fprintf(f.get(), " -3\n");
    const char* names[] = {"NDTEMP", "DISP", "STRESS"};
    const char* comps[3][6] = {{"T"}, {"D1", "D2", "D3"}, {"SXX", "SYY", "SZZ", "SXY", "SYZ", "SZX"}};
    for (int b = 0; b < 3; ++b) {
      const foxi::Field& fld = m.fields[b];
      std::fprintf(f.get(), "    1PSTEP%25d%12d%12d\n", b + 1, 1, 1);
      std::fprintf(f.get(), "  100CL  101 1.000000000%12zu                     0    1           1\n",
                   m.node_count());
      std::fprintf(f.get(), " -4  %-8s%5u    1\n", names[b], fld.components);
      for (unsigned c = 0; c < fld.components; ++c)
        std::fprintf(f.get(), " -5  %-8s%5d%5d%5u%5d\n", comps[b][c], 1, 1, c + 1, 0);
      for (std::size_t i = 0; i < m.node_count(); ++i) {
        std::fprintf(f.get(), " -1%10zu", i + 1);
        for (unsigned c = 0; c < fld.components; ++c)
          std::fprintf(f.get(), "%12.5E", fld.values[i * fld.components + c]);
        std::fputc('\n', f.get());
      }
      std::fprintf(f.get(), " -3\n");
    }
    std::fprintf(f.get(), " 9999\n");
  }
};

Data& data() {
  static Data d;
  return d;
}

void transfer_by_location(benchmark::State& state) {
  Data& d = data();
  foxi::TransferParams p;
  p.names = {"T"};
  p.threads = static_cast<unsigned>(state.range(0));
  double worst = 0;
  std::size_t outside = 0;
  for (auto _ : state) {
    const foxi::TransferReport r = foxi::transfer_fields(d.source, d.target, p);
    outside = r.nodes_outside;
    worst = 0;
    for (std::size_t i = 0; i < d.target.node_count(); ++i)
      worst = std::max(worst, std::abs(r.fields[0].values[i] - linear(&d.target.xyz[3 * i])));
  }
  if (outside != 0 || !(worst < 1e-9)) state.SkipWithError("the transfer of a linear field is not exact");
  state.counters["source_tets"] = double(d.source.mesh.tet_count());
  state.counters["target_nodes"] = double(d.target.node_count());
  state.counters["ns_per_node"] =
      benchmark::Counter(double(d.target.node_count()),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["max_error"] = worst;
}
BENCHMARK(transfer_by_location)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// scipy.interpolate.LinearNDInterpolator(source points, T)(target points), timed inside Python.
void transfer_scipy(benchmark::State& state) {
  Data& d = data();
  const std::string cmd = "cd '" + d.dir.path.string() +
                          "' && /usr/bin/python3 -c \"import time, numpy as np; from scipy.interpolate "
                          "import LinearNDInterpolator as L; "
                          "s = np.fromfile('src_xyz.bin').reshape(-1, 3); v = np.fromfile('src_t.bin'); q = "
                          "np.fromfile('tgt_xyz.bin').reshape(-1, 3); "
                          "t = time.perf_counter(); r = L(s, v)(q); t = time.perf_counter() - t; "
                          "e = np.nanmax(np.abs(r - (300 + 20 * q[:, 0] - 30 * q[:, 1] + 5 * q[:, 2]))); "
                          "print(t, e)\" 2>/dev/null";
  double err = -1;
  for (auto _ : state) {
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
    double seconds = -1;
    if (!pipe || std::fscanf(pipe.get(), "%lf %lf", &seconds, &err) != 2 || seconds <= 0) {
      state.SkipWithError("scipy failed (is /usr/bin/python3 with scipy installed?)");
      break;
    }
    state.SetIterationTime(seconds);
  }
  state.counters["max_error"] = err;
  state.counters["ns_per_node"] =
      benchmark::Counter(double(d.target.node_count()),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(transfer_scipy)->Unit(benchmark::kMillisecond)->UseManualTime()->Iterations(1);

void read_source(benchmark::State& state, const char* name) {
  Data& d = data();
  const fs::path p = d.dir / name;
  std::size_t fields = 0;
  for (auto _ : state) {
    const foxi::FieldSource s = foxi::read_field_source(p);
    fields = s.mesh.fields.size();
    benchmark::DoNotOptimize(s.mesh.xyz.data());
  }
  if (fields != 3) state.SkipWithError("not the 3 fields written");
  const auto bytes = static_cast<std::int64_t>(fs::file_size(p));
  state.SetBytesProcessed(bytes * state.iterations());
  state.counters["file_MB"] = double(bytes) / 1e6;
}
BENCHMARK_CAPTURE(read_source, frd_ascii, "big.frd")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(read_source, vtu_ascii, "ascii.vtu")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);
BENCHMARK_CAPTURE(read_source, vtu_appended_raw, "raw.vtu")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2);

}  // namespace

BENCHMARK_MAIN();
