// Writes the seed corpora of the fuzz targets into OUT/<target>/: small meshes written by foxi's own
// writers in every variant of every format (with node and cell fields), the files of tests/data/bad,
// the example PLCs and models, a list of parameter expressions, and a few encoded meshes for the
// pipeline target. Usage: fuzz_make_seeds OUT (scripts/fuzz.sh and the replay tests call it).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/io_gmsh.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/io_vtk.hpp"

namespace fs = std::filesystem;

namespace {

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_file(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

// Copies the files of `from` with one of the extensions (all if none given) into `to`.
void copy_matching(const fs::path& from, const fs::path& to,
                   const std::vector<std::string>& extensions = {}) {
  for (const auto& e : fs::directory_iterator(from)) {
    if (!e.is_regular_file()) continue;
    bool take = extensions.empty();
    for (const std::string& x : extensions) take = take || e.path().extension() == x;
    if (take) fs::copy_file(e.path(), to / e.path().filename(), fs::copy_options::overwrite_existing);
  }
}

foxi::Mesh seed_mesh(std::uint32_t n) {
  foxi::Mesh m = foxi::bench::kuhn_grid_mesh(n);
  foxi::Field temperature{"temperature", foxi::FieldLocation::node, 1, "K", {}, {}};
  for (std::size_t i = 0; i < m.node_count(); ++i) temperature.values.push_back(300 + m.xyz[3 * i]);
  foxi::Field flux{"flux", foxi::FieldLocation::cell, 3, "W/m^2", {0, 1}, {}};
  for (std::size_t i = 0; i < 2 * 3 * m.tet_count(); ++i) flux.values.push_back(double(i) * 0.5);
  m.fields = {temperature, flux};
  return m;
}

// The pipeline target's encoding (fuzz_mesh_pipeline.cpp, decode) of a lattice mesh: mode byte,
// offset, node count - 4, tet count - 1, one byte per coordinate (value + 4), 4 per tet, the view.
std::string encode_lattice(std::uint8_t mode, const std::vector<int>& xyz, const std::vector<int>& tets,
                           std::uint8_t view, std::vector<std::int8_t> eye) {
  std::string s;
  s += char(mode);
  s += char(0);
  s += char(xyz.size() / 3 - 4);
  s += char(tets.size() / 4 - 1);
  for (int c : xyz) s += char(c + 4);
  for (int v : tets) s += char(v);
  if (mode & 4)
    for (std::size_t t = 0; t < tets.size() / 4; ++t) s += char(t % 2 + 1);
  if (mode & 2)
    for (std::size_t i = 0; i < xyz.size() / 3; ++i) s += char(i % 3);
  s += char(view);
  for (std::int8_t e : eye) s += char(e);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds OUT\n");
    return 2;
  }
  const fs::path out = argv[1], data = FOXI_TEST_DATA_DIR, root = FOXI_SOURCE_DIR;
  for (const char* t : {"gmsh", "vtu", "vtk", "medit", "tetgen", "poly", "model", "expression",
                        "mesh_pipeline", "frd", "csv"})
    fs::create_directories(out / t);

  for (std::uint32_t n : {1u, 2u}) {
    const foxi::Mesh m = seed_mesh(n);
    const std::string k = "kuhn" + std::to_string(n);
    for (int version : {22, 41})
      for (bool binary : {false, true})
        foxi::write_gmsh(m,
                         out / "gmsh" / (k + "_" + std::to_string(version) + (binary ? "_bin" : "") + ".msh"),
                         {version, binary});
    const std::pair<foxi::VtuEncoding, const char*> encodings[] = {{foxi::VtuEncoding::ascii, "ascii"},
                                                                   {foxi::VtuEncoding::base64, "base64"},
                                                                   {foxi::VtuEncoding::appended_raw, "raw"},
                                                                   {foxi::VtuEncoding::zlib, "zlib"}};
    for (const auto& [encoding, name] : encodings)
      foxi::write_vtu(m, out / "vtu" / (k + "_" + name + ".vtu"), encoding);
    foxi::write_vtk_legacy(m, out / "vtk" / (k + "_ascii.vtk"), false);
    foxi::write_vtk_legacy(m, out / "vtk" / (k + "_bin.vtk"), true);
    foxi::write_medit(m, out / "medit" / (k + ".mesh"));
    const fs::path base = out / "tetgen" / k;
    foxi::write_tetgen(m, base);
    write_file(out / "tetgen" / (k + ".tetgen"), read_file(base.string() + ".node") + '\0' +
                                                     read_file(base.string() + ".ele") + '\0' +
                                                     read_file(base.string() + ".face"));
    for (const char* x : {".node", ".ele", ".face"}) fs::remove(base.string() + x);
  }
  copy_matching(data / "bad" / "gmsh", out / "gmsh");
  copy_matching(data / "bad" / "vtu", out / "vtu", {".vtu"});
  copy_matching(data / "bad" / "vtk", out / "vtk", {".vtk"});
  copy_matching(data / "bad" / "medit", out / "medit");
  // The broken TetGen sets: one input per base name (.node, .ele, .face joined by NUL bytes).
  for (const auto& e : fs::directory_iterator(data / "bad" / "tetgen")) {
    if (e.path().extension() != ".node") continue;
    fs::path base = e.path();
    base.replace_extension();
    std::string joined = read_file(e.path());
    for (const char* x : {".ele", ".face"}) {
      joined += '\0';
      if (fs::exists(base.string() + x)) joined += read_file(base.string() + x);
    }
    write_file(out / "tetgen" / (base.filename().string() + ".tetgen"), joined);
  }
  // The field importer's readers: CalculiX result files (ASCII: two steps, DISP NDTEMP STRESS ERROR,
  // elements; binary, written by ccx 2.21: C3D10 elements, DISP STRESS ERROR) and CSV tables of each key.
  copy_matching(data / "fields", out / "frd", {".frd"});
  copy_matching(data / "fields", out / "csv", {".csv", ".tsv"});
  copy_matching(root / "examples", out / "poly", {".poly"});
  copy_matching(data / "cdt", out / "poly", {".poly"});
  copy_matching(root / "models", out / "model", {".toml"});
  copy_matching(data / "cdt", out / "model", {".toml"});

  const char* expressions[] = {"4 mm",
                               "w + 2 mm",
                               "150 W/(m*K)",
                               "sqrt(w * w)",
                               "2.5um",
                               "-(w - 1 mm) / 2",
                               "min(w, 3 mm) + max(1 mm, w)",
                               "n ^ 3 * w",
                               "w ^ -2",
                               "sin(pi / n) * exp(1)",
                               "log(10) * abs(-k)",
                               "1e-3 * k * w / (2 K)",
                               "r * 2",
                               "1 mm + 300 K",
                               "((w))",
                               "3 kV / mm",
                               "20 ppm / K",
                               "1 MPa * 2 mA",
                               "cos(tan(0.5))",
                               "1e308 * 10"};
  int i = 0;
  for (const char* x : expressions) write_file(out / "expression" / ("e" + std::to_string(i++)), x);

  // Pipeline seeds: one lattice cube as 6 Kuhn tets (Delaunay, one cospherical cluster) seen in
  // perspective and orthographically, the same with regions and weights, and a non-Delaunay pair.
  std::vector<int> cube, kuhn;
  for (int c = 0; c < 8; ++c) cube.insert(cube.end(), {c & 1 ? 2 : 0, c & 2 ? 2 : 0, c & 4 ? 2 : 0});
  const int paths[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
  for (const auto& p : paths) kuhn.insert(kuhn.end(), {0, p[0], p[1], 7});
  write_file(out / "mesh_pipeline" / "cube_perspective", encode_lattice(0x00, cube, kuhn, 0, {40, -30, 20}));
  write_file(out / "mesh_pipeline" / "cube_ortho", encode_lattice(0x00, cube, kuhn, 1, {1, 2, 3}));
  write_file(out / "mesh_pipeline" / "cube_regions_mm", encode_lattice(0x14, cube, kuhn, 0, {4, 3, 50}));
  write_file(out / "mesh_pipeline" / "cube_weighted", encode_lattice(0x06, cube, kuhn, 0, {-40, 30, 20}));
  write_file(out / "mesh_pipeline" / "cube_inside", encode_lattice(0x24, cube, kuhn, 0, {8, 8, 8}));
  std::vector<int> pair = {0, 0, 0, 3, 0, 0, 0, 3, 0, 0, 0, 3, 2, 2, 2};
  write_file(out / "mesh_pipeline" / "flip_pair",
             encode_lattice(0x04, pair, {0, 1, 2, 3, 1, 2, 3, 4}, 0, {30, 20, 10}));
  std::printf("fuzz_make_seeds: wrote %s\n", out.c_str());
  return 0;
}
