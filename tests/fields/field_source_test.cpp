// The field importer's readers. Oracles: foxi's own writers (a round trip through every .vtu, .vtk
// and .msh variant and a .pvd series keeps every value bit for bit, with its steps); CalculiX, run
// here on decks whose exact P1 answer is known (a linear temperature between two fixed faces, free
// thermal expansion: u = alpha dT x, no stress); hand-written CSV tables; and broken files, which
// must give an IoError naming the file and the line, never a crash or a partial source.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/fields.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/io_gmsh.hpp"
#include "foxi/model/io_vtk.hpp"
#include "foxi/model/mesh_io.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TransferParams by_id() {
  TransferParams p;
  p.by = MatchBy::id;
  return p;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

Mesh mesh_with_fields() {
  Mesh m = bench::kuhn_grid_mesh(3, 0.2, 4);
  Field t{"temperature", FieldLocation::node, 1, "K", {0, 0.5, 2}, {}};
  for (int s = 0; s < 3; ++s)
    for (std::size_t i = 0; i < m.node_count(); ++i) t.values.push_back(300 + (s + 1) * m.xyz[3 * i] / 3);
  t.values[7] = kNaN;
  Field u{"u", FieldLocation::node, 3, "m", {}, {}};
  for (std::size_t i = 0; i < 3 * m.node_count(); ++i) u.values.push_back(std::sin(double(i)) * 1e-6);
  Field s{"stress", FieldLocation::cell, 6, "Pa", {1, 2}, {}};
  for (std::size_t i = 0; i < 2 * 6 * m.tet_count(); ++i)
    s.values.push_back(std::exp(double(i % 97) / 7) * 1e5 / 3);
  m.fields = {t, u, s};
  return m;
}

// Reads `path` as a field source and carries it by id onto m (without its fields): every value of
// every field and step must come back bit for bit.
void expect_round_trip(const Mesh& m, const std::filesystem::path& path, bool keeps_units,
                       bool keeps_step_values) {
  SCOPED_TRACE(path.filename().string());
  const FieldSource src = read_field_source(path);
  Mesh target = m;
  target.fields.clear();
  TransferParams p;
  p.by = MatchBy::id;
  p.coordinate_tolerance = 0;  // the same coordinates, to the bit
  const TransferReport rep = transfer_fields(src, target, p);
  ASSERT_EQ(rep.fields.size(), m.fields.size());
  for (const Field& want : m.fields) {
    const Field* got = nullptr;
    for (const Field& f : rep.fields)
      if (f.name == want.name) got = &f;
    ASSERT_NE(got, nullptr) << want.name;
    EXPECT_EQ(got->location, want.location);
    EXPECT_EQ(got->components, want.components);
    EXPECT_EQ(got->step_count(), want.step_count()) << want.name;
    EXPECT_TRUE(same_bits(got->values, want.values)) << want.name;
    if (keeps_units) {
      EXPECT_EQ(got->unit, want.unit);
    }
    if (keeps_step_values && want.step_values.size() > 1) {
      EXPECT_EQ(got->step_values, want.step_values);
    }
  }
  EXPECT_EQ(rep.nan_values, 1u);  // the one NaN temperature
}

TEST(FieldSource, VtkAndGmshRoundTripsKeepEveryValueBitForBit) {
  test::TempDir dir;
  const Mesh m = mesh_with_fields();
  for (auto [enc, name] : {std::pair{VtuEncoding::appended_raw, "raw"},
                           {VtuEncoding::ascii, "ascii"},
                           {VtuEncoding::base64, "base64"},
                           {VtuEncoding::zlib, "zlib"}}) {
    write_vtu(m, dir / (std::string(name) + ".vtu"), enc);
    expect_round_trip(m, dir / (std::string(name) + ".vtu"), true, true);
  }
  for (bool binary : {true, false}) {
    const std::string vtk = binary ? "bin.vtk" : "ascii.vtk";
    write_vtk_legacy(m, dir / vtk, binary);
    expect_round_trip(m, dir / vtk, false, false);
    for (int version : {22, 41}) {
      const std::string msh = std::to_string(version) + (binary ? "bin" : "ascii") + ".msh";
      write_gmsh(m, dir / msh, {version, binary});
      expect_round_trip(m, dir / msh, false, true);
    }
  }
}

TEST(FieldSource, PvdSeriesIsOneFieldWithSteps) {
  test::TempDir dir;
  Mesh m = bench::kuhn_grid_mesh(2, 0.2, 4);
  std::vector<double> all;
  std::string pvd =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
  const double times[] = {0, 0.25, 1e-3 / 3};
  for (int s = 0; s < 3; ++s) {
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    for (std::size_t i = 0; i < m.node_count(); ++i) t.values.push_back(300 + s + m.xyz[3 * i] / 7);
    all.insert(all.end(), t.values.begin(), t.values.end());
    m.fields = {t};
    const std::string file = "series_" + std::to_string(s) + ".vtu";
    write_vtu(m, dir / file);
    char ts[64];
    std::snprintf(ts, sizeof ts, "%.17g", times[s]);
    pvd += std::string("    <DataSet timestep=\"") + ts + "\" part=\"0\" file=\"" + file + "\"/>\n";
  }
  pvd += "  </Collection>\n</VTKFile>\n";
  test::write_text(dir / "series.pvd", pvd);
  const FieldSource src = read_field_source(dir / "series.pvd");
  ASSERT_EQ(src.mesh.fields.size(), 1u);
  const Field& f = src.mesh.fields[0];
  // In timestep order, as ParaView reads a collection (the file lists the third step second in time).
  EXPECT_EQ(f.step_values, (std::vector<double>{times[0], times[2], times[1]}));
  const std::size_t n = m.node_count();
  std::vector<double> in_time_order(all.begin(), all.begin() + std::ptrdiff_t(n));
  in_time_order.insert(in_time_order.end(), all.begin() + std::ptrdiff_t(2 * n), all.end());
  in_time_order.insert(in_time_order.end(), all.begin() + std::ptrdiff_t(n),
                       all.begin() + std::ptrdiff_t(2 * n));
  EXPECT_TRUE(same_bits(f.values, in_time_order));
  EXPECT_EQ(f.unit, "K");
  // A data set over another mesh, and a missing file: refused, naming the line of the collection.
  write_vtu(bench::kuhn_grid_mesh(3, 0.2, 4), dir / "series_2.vtu");
  try {
    read_field_source(dir / "series.pvd");
    ADD_FAILURE() << "a series over two meshes was read";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 6u) << e.what();
  }
  std::filesystem::remove(dir / "series_1.vtu");
  EXPECT_THROW(read_field_source(dir / "series.pvd"), IoError);
}

// Writes a deck over mesh m (C3D4, node i = i + 1) with `body` after the element and material cards.
void write_deck(const Mesh& m, const std::filesystem::path& path, const std::string& body) {
  std::string s = "*NODE, NSET=NALL\n";
  char line[160];
  for (std::size_t i = 0; i < m.node_count(); ++i) {
    std::snprintf(line, sizeof line, "%zu, %.17g, %.17g, %.17g\n", i + 1, m.xyz[3 * i], m.xyz[3 * i + 1],
                  m.xyz[3 * i + 2]);
    s += line;
  }
  s += "*ELEMENT, TYPE=C3D4, ELSET=EALL\n";
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    std::snprintf(line, sizeof line, "%zu, %u, %u, %u, %u\n", t + 1, m.tet[4 * t] + 1, m.tet[4 * t + 1] + 1,
                  m.tet[4 * t + 2] + 1, m.tet[4 * t + 3] + 1);
    s += line;
  }
  s += "*MATERIAL, NAME=M\n*CONDUCTIVITY\n50\n*ELASTIC\n1e9, 0.3\n*EXPANSION\n1e-5\n"
       "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n" +
       body;
  test::write_text(path, s);
}

// The ids (1-based) of the nodes with coordinate k equal to v.
std::string nodes_at(const Mesh& m, int k, double v, const std::string& rest) {
  std::string s;
  for (std::size_t i = 0; i < m.node_count(); ++i)
    if (m.xyz[3 * i + k] == v) s += std::to_string(i + 1) + rest + "\n";
  return s;
}

TEST(FieldSource, CalculixFrdHasTheAnalyticValues) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  test::TempDir dir;
  const Mesh m = bench::kuhn_grid_mesh(3, 0.2, 6);
  // Heat: T = 300 on x = 0, 400 then 500 on x = 1, insulated elsewhere: T = 300 + 100 x, then
  // 300 + 200 x, which P1 tets reproduce exactly.
  write_deck(m, dir / "heat.inp",
             "*STEP\n*HEAT TRANSFER, STEADY STATE\n*BOUNDARY\n" + nodes_at(m, 0, 0, ", 11, 11, 300") +
                 nodes_at(m, 0, 1, ", 11, 11, 400") + "*NODE FILE\nNT\n*END STEP\n" +
                 "*STEP\n*HEAT TRANSFER, STEADY STATE\n*BOUNDARY\n" + nodes_at(m, 0, 1, ", 11, 11, 500") +
                 "*NODE FILE\nNT\n*END STEP\n");
  // Free thermal expansion by 100 K with alpha 1e-5, held statically determinate at three corners:
  // u = 1e-3 (x, y, z), no stress.
  const auto corner = [&](double x, double y) {
    for (std::size_t i = 0; i < m.node_count(); ++i)
      if (m.xyz[3 * i] == x && m.xyz[3 * i + 1] == y && m.xyz[3 * i + 2] == 0) return std::to_string(i + 1);
    return std::string("?");
  };
  write_deck(m, dir / "expand.inp",
             "*INITIAL CONDITIONS, TYPE=TEMPERATURE\nNALL, 300\n*STEP\n*STATIC\n*BOUNDARY\n" + corner(0, 0) +
                 ", 1, 3, 0\n" + corner(1, 0) + ", 2, 3, 0\n" + corner(0, 1) +
                 ", 3, 3, 0\n*TEMPERATURE\nNALL, 400\n*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n");
  for (const char* job : {"heat", "expand"}) {
    const int rc =
        test::run("cd '" + dir.path().string() + "' && OMP_NUM_THREADS=1 ccx -i " + job, dir / "ccx.log");
    ASSERT_EQ(rc, 0) << test::read_text(dir / "ccx.log");
  }
  const FieldSource heat = read_field_source(dir / "heat.frd");
  EXPECT_EQ(heat.key, SourceKey::node_id);
  EXPECT_EQ(heat.mesh.node_count(), m.node_count());
  EXPECT_EQ(heat.mesh.tet_count(), m.tet_count());
  const Field* nt = heat.mesh.find_field("NDTEMP");
  ASSERT_NE(nt, nullptr);
  ASSERT_EQ(nt->step_count(), 2u);
  EXPECT_EQ(nt->step_values, (std::vector<double>{1, 2}));
  // Onto the mesh by id (coordinates checked to the .frd's 6 digits): the analytic values.
  Mesh target = m;
  TransferParams p;
  p.by = MatchBy::id;
  const TransferReport rep = transfer_fields(heat, target, p);
  const Field& t = rep.fields[0];
  const std::size_t n = m.node_count();
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(t.values[i], 300 + 100 * m.xyz[3 * i], 5e-6 * 400) << "node " << i + 1;
    EXPECT_NEAR(t.values[n + i], 300 + 200 * m.xyz[3 * i], 5e-6 * 500) << "node " << i + 1;
  }
  EXPECT_EQ(rep.nan_values, 0u);

  const FieldSource expand = read_field_source(dir / "expand.frd");
  const Field* u = expand.mesh.find_field("DISP");
  const Field* s = expand.mesh.find_field("STRESS");
  ASSERT_NE(u, nullptr);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(u->components, 3u);  // D1 D2 D3; "ALL" is computed by the reader, not in the file
  EXPECT_EQ(s->components, 6u);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k =
        std::find(expand.node_id.begin(), expand.node_id.end(), i + 1) - expand.node_id.begin();
    ASSERT_LT(k, n);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(u->values[3 * k + c], 1e-3 * m.xyz[3 * i + c], 1e-8) << "node " << i + 1;
    for (int c = 0; c < 6; ++c)
      EXPECT_NEAR(s->values[6 * k + c], 0, 1.0) << "node " << i + 1;  // E alpha dT = 1e6 Pa
  }
}

// True when the file's node block header carries a binary format flag (2 or 3): the comparisons below
// must not quietly compare an ASCII file with itself.
bool frd_is_binary(const std::string& bytes) {
  const std::size_t at = bytes.find("    2C");
  if (at == std::string::npos) return false;
  const std::size_t eol = bytes.find('\n', at);
  const std::string head = bytes.substr(at, eol - at);
  const std::size_t last = head.find_last_not_of(' ');
  return last != std::string::npos && (head[last] == '2' || head[last] == '3');
}

// `bin` (a binary .frd) holds what `ascii` (the same results in ASCII) holds: the same node ids with
// the same coordinates, the same tets, and each of `names`' values at each step. The ASCII file prints
// 6 significant digits (E12.5), the binary one float32 values and float64 coordinates, so they agree
// to 5e-6 of each value (a field's own largest value for values near zero).
void expect_same_results(const FieldSource& bin, const FieldSource& ascii,
                         const std::vector<std::string>& names) {
  ASSERT_EQ(bin.node_id.size(), ascii.node_id.size());
  std::vector<std::size_t> to_ascii(bin.node_id.size());
  for (std::size_t i = 0; i < bin.node_id.size(); ++i) {
    const auto it = std::find(ascii.node_id.begin(), ascii.node_id.end(), bin.node_id[i]);
    ASSERT_NE(it, ascii.node_id.end()) << "node " << bin.node_id[i];
    to_ascii[i] = static_cast<std::size_t>(it - ascii.node_id.begin());
    for (int c = 0; c < 3; ++c) {
      const double a = ascii.mesh.xyz[3 * to_ascii[i] + c], b = bin.mesh.xyz[3 * i + c];
      EXPECT_NEAR(b, a, 5e-6 * std::max(1.0, std::abs(a))) << "node " << bin.node_id[i];
    }
  }
  ASSERT_EQ(bin.mesh.tet.size(), ascii.mesh.tet.size());
  for (std::size_t k = 0; k < bin.mesh.tet.size(); ++k)
    EXPECT_EQ(ascii.node_id[to_ascii[bin.mesh.tet[k]]], ascii.node_id[ascii.mesh.tet[k]])
        << "tet corner " << k;
  for (const std::string& name : names) {
    const Field* fb = bin.mesh.find_field(name);
    const Field* fa = ascii.mesh.find_field(name);
    ASSERT_NE(fb, nullptr) << name;
    ASSERT_NE(fa, nullptr) << name;
    ASSERT_EQ(fb->components, fa->components) << name;
    ASSERT_EQ(fb->step_values, fa->step_values) << name;
    ASSERT_EQ(fb->values.size(), fa->values.size()) << name;
    double scale = 0;
    for (double v : fa->values) scale = std::max(scale, std::abs(v));
    const std::size_t n = bin.node_id.size(), nc = fb->components;
    std::size_t compared = 0;
    for (std::size_t s = 0; s < fb->step_count(); ++s)
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t c = 0; c < nc; ++c) {
          const double b = fb->values[(s * n + i) * nc + c];
          const double a = fa->values[(s * n + to_ascii[i]) * nc + c];
          ASSERT_EQ(std::isnan(a), std::isnan(b)) << name << " node " << bin.node_id[i];
          if (std::isnan(a)) continue;
          EXPECT_NEAR(b, a, 5e-6 * std::max(std::abs(a), 1e-6 * scale))
              << name << " step " << s << " node " << bin.node_id[i] << " component " << c;
          ++compared;
        }
    EXPECT_GT(compared, 0u) << name;
  }
}

// A binary .frd written by another program: CalculiX 2.21 (github.com/wr1/frd2vtu's test files, see
// tests/data/fields/README.md), against the ASCII file Debian's ccx 2.20 writes from the same deck.
TEST(FieldSource, BinaryFrdFromCalculix221) {
  const std::string dir = test::data_dir() + "/fields/";
  const std::string bytes = test::read_text(dir + "ccx221_beam10psmooth_binary.frd");
  ASSERT_TRUE(frd_is_binary(bytes));
  const FieldSource bin = read_field_source(dir + "ccx221_beam10psmooth_binary.frd");
  const FieldSource ascii = read_field_source(dir + "ccx220_beam10psmooth_ascii.frd");
  ASSERT_FALSE(frd_is_binary(test::read_text(dir + "ccx220_beam10psmooth_ascii.frd")));
  EXPECT_EQ(bin.node_id.size(), 90u);
  EXPECT_EQ(bin.mesh.tet_count(), 31u);  // C3D10 elements, their corners
  expect_same_results(bin, ascii, {"DISP", "STRESS"});
  // 2.21 also writes the error estimate ccx 2.20 leaves out for this deck: one component per node, all
  // of them given, and small (the load is uniform pressure on a straight beam).
  const Field* err = bin.mesh.find_field("ERROR");
  ASSERT_NE(err, nullptr);
  EXPECT_EQ(err->components, 1u);
  EXPECT_EQ(err->values.size(), bin.node_id.size());
  for (double v : err->values) EXPECT_TRUE(std::isfinite(v) && v >= 0 && v < 1e-6) << v;
}

// Debian's ccx 2.20 writes binary too, for *NODE OUTPUT / *ELEMENT OUTPUT (not *NODE FILE): the same
// decks both ways give the same nodes, tets and values, over two steps and scalar, vector and tensor
// fields, and the analytic temperatures.
TEST(FieldSource, BinaryFrdFromCcxAgreesWithAscii) {
  if (!test::have_program("ccx")) GTEST_SKIP() << "ccx not installed";
  test::TempDir dir;
  const Mesh m = bench::kuhn_grid_mesh(3, 0.2, 7);
  const std::string heat = "*STEP\n*HEAT TRANSFER, STEADY STATE\n*BOUNDARY\n" +
                           nodes_at(m, 0, 0, ", 11, 11, 300") + nodes_at(m, 0, 1, ", 11, 11, 400") +
                           "*NODE FILE\nNT\n*EL FILE\nHFL\n*END STEP\n" +
                           "*STEP\n*HEAT TRANSFER, STEADY STATE\n*BOUNDARY\n" +
                           nodes_at(m, 0, 1, ", 11, 11, 500") + "*NODE FILE\nNT\n*EL FILE\nHFL\n*END STEP\n";
  const std::string load = "*STEP\n*STATIC\n*BOUNDARY\n" + nodes_at(m, 2, 0, ", 1, 3, 0") + "*BOUNDARY\n" +
                           nodes_at(m, 2, 1, ", 3, 3, 0.01") + "*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n";
  const auto binary = [](std::string deck) {
    for (const auto& [from, to] :
         {std::pair<std::string, std::string>{"*NODE FILE", "*NODE OUTPUT"}, {"*EL FILE", "*ELEMENT OUTPUT"}})
      for (std::size_t at; (at = deck.find(from)) != std::string::npos;) deck.replace(at, from.size(), to);
    return deck;
  };
  write_deck(m, dir / "heat_a.inp", heat);
  write_deck(m, dir / "heat_b.inp", binary(heat));
  write_deck(m, dir / "load_a.inp", load);
  write_deck(m, dir / "load_b.inp", binary(load));
  for (const char* job : {"heat_a", "heat_b", "load_a", "load_b"}) {
    const int rc =
        test::run("cd '" + dir.path().string() + "' && OMP_NUM_THREADS=1 ccx -i " + job, dir / "ccx.log");
    ASSERT_EQ(rc, 0) << test::read_text(dir / "ccx.log");
  }
  ASSERT_TRUE(frd_is_binary(test::read_text(dir / "heat_b.frd")));
  ASSERT_TRUE(frd_is_binary(test::read_text(dir / "load_b.frd")));
  ASSERT_FALSE(frd_is_binary(test::read_text(dir / "heat_a.frd")));
  const FieldSource heat_bin = read_field_source(dir / "heat_b.frd");
  expect_same_results(heat_bin, read_field_source(dir / "heat_a.frd"), {"NDTEMP", "FLUX"});
  expect_same_results(read_field_source(dir / "load_b.frd"), read_field_source(dir / "load_a.frd"),
                      {"DISP", "STRESS"});
  // The binary temperatures are the analytic ones (float32: 6e-8 relative).
  EXPECT_EQ(heat_bin.mesh.tet_count(), m.tet_count());
  const Field* nt = heat_bin.mesh.find_field("NDTEMP");
  ASSERT_NE(nt, nullptr);
  ASSERT_EQ(nt->step_count(), 2u);
  const std::size_t n = m.node_count();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = heat_bin.node_id[k] - 1;
    EXPECT_NEAR(nt->values[k], 300 + 100 * m.xyz[3 * i], 1e-4) << "node " << i + 1;
    EXPECT_NEAR(nt->values[n + k], 300 + 200 * m.xyz[3 * i], 1e-4) << "node " << i + 1;
  }
}

// Broken binary .frd files: every truncation and absurd counts give an IoError naming the file and
// the byte offset, with no allocation sized by the counts.
TEST(FieldSource, BrokenBinaryFrdFilesNameTheOffset) {
  const std::string good = test::read_text(test::data_dir() + "/fields/ccx221_beam10psmooth_binary.frd");
  const std::size_t nodes_at = good.find("    2C");
  const std::size_t first_binary = good.find('\n', nodes_at) + 1;
  ASSERT_NO_THROW(parse_frd_source(good, "ok.frd"));
  for (std::size_t cut = 0; cut + 5 < good.size(); cut += (cut < first_binary ? 7 : 1)) {
    try {
      parse_frd_source(good.substr(0, cut), "cut.frd");
      ADD_FAILURE() << "a binary .frd cut at byte " << cut << " was read";
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), "cut.frd");
      // Where: a block's header line (its count does not fit), or a byte offset inside the file.
      EXPECT_TRUE(cut == 0 || e.line() > 0 || e.byte_offset() <= cut)
          << e.what() << " (cut at " << cut << ")";
    }
  }
  const auto reason = [](const std::string& text) -> std::string {
    try {
      parse_frd_source(text, "bad.frd");
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), "bad.frd");
      return e.reason();
    }
    return "read";
  };
  // Absurd node, element and result counts: refused against the bytes left, before reserving.
  for (const char* header : {"    2C", "    3C", "  100C"}) {
    std::string huge = good;
    const std::size_t at = huge.find(header);
    const std::size_t col = std::string(header) == "  100C" ? 24 : 6;
    const std::size_t width = std::string(header) == "  100C" ? 12 : 30;
    std::string count(width, ' ');
    count.replace(width - 10, 10, "2000000000");
    huge.replace(at + col, width, count);
    EXPECT_NE(reason(huge).find("bytes left"), std::string::npos) << header << ": " << reason(huge);
  }
  // An element that names a node the file does not have; a result record of an unknown node.
  std::string unknown = good;
  const std::size_t elements = unknown.find('\n', unknown.find("    3C")) + 1;
  unknown.replace(elements + 16, 4, std::string("\x39\x30\x00\x00", 4));  // first corner: node 12345
  EXPECT_NE(reason(unknown).find("12345"), std::string::npos) << reason(unknown);
  std::string stranger = good;
  const std::size_t values = stranger.find('\n', stranger.find(" -5  ALL")) + 1;
  stranger.replace(values, 4, std::string("\x39\x30\x00\x00", 4));
  EXPECT_NE(reason(stranger).find("12345"), std::string::npos) << reason(stranger);
  // A result header asking for float64 values: refused by name, not read as float32.
  std::string doubles = good;
  const std::size_t step = doubles.find("  100C");
  doubles[doubles.find('\n', step) - 1] = '3';
  EXPECT_NE(reason(doubles).find("format 3"), std::string::npos) << reason(doubles);
}

// Broken .frd files: every truncation, a garbled number, a binary flag on ASCII records, an unknown node.
TEST(FieldSource, BrokenFrdFilesNameTheLine) {
  const std::string good =
      "    1C\n    2C                             2                                     1\n"
      " -1         1 0.00000E+00 0.00000E+00 0.00000E+00\n -1         2 1.00000E+00 0.00000E+00 0.00000E+00\n"
      " -3\n  100CL  101 1.000000000           2                     0    1           1\n"
      " -4  NDTEMP      1    1\n -5  T           1    1    0    0\n -1         1 3.10000E+02\n"
      " -1         2 3.20000E+02\n -3\n 9999\n";
  const FieldSource ok = parse_frd_source(good, "ok.frd");
  ASSERT_EQ(ok.mesh.fields.size(), 1u);
  EXPECT_EQ(ok.mesh.fields[0].values, (std::vector<double>{310, 320}));
  for (std::size_t cut = 0; cut + 6 < good.size(); ++cut) {
    try {
      parse_frd_source(good.substr(0, cut), "cut.frd");
      ADD_FAILURE() << "a .frd cut at byte " << cut << " was read";
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), "cut.frd");
    }
  }
  auto line_of_error = [](const std::string& text) -> std::uint64_t {
    try {
      parse_frd_source(text, "bad.frd");
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.frd"), std::string::npos);
      return e.line();
    }
    return 0;
  };
  std::string garbled = good;
  garbled.replace(garbled.find("3.20000E+02"), 11, "3.2x000E+02");
  EXPECT_EQ(line_of_error(garbled), 10u);
  std::string unknown = good;
  unknown.replace(unknown.find(" -1         2 3.2"), 13, " -1         9");
  EXPECT_EQ(line_of_error(unknown), 10u);
  // A binary flag over ASCII records: the records are read as binary and refused (never a crash).
  std::string binary = good;
  binary.replace(binary.find("1\n -1         1 0.0"), 1, "2");
  EXPECT_THROW(parse_frd_source(binary, "bad.frd"), IoError);
  std::string short_record = good;
  short_record.replace(short_record.find(" 1.00000E+00 0.00000E+00 0.00000E+00"), 36, " 1.00000E+00");
  EXPECT_EQ(line_of_error(short_record), 4u);
  // A block whose every component is flagged as not in the file (iexist 1, columns 34-38) would be a
  // field of 0 components: refused at its component line.
  std::string all_computed = good;
  all_computed.replace(all_computed.find(" -5  T           1    1    0    0"), 33,
                       " -5  T           1    1    0    0    1");
  EXPECT_EQ(line_of_error(all_computed), 8u);
  // The fuzz input that found it (a mutated ccx file, tests/data/bad/fuzz/frd/zero_components).
  try {
    read_frd_source(test::data_dir() + "/bad/fuzz/frd/zero_components");
    ADD_FAILURE() << "zero_components was read";
  } catch (const IoError& e) {
    EXPECT_NE(e.reason().find("0 component"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zero_components"), std::string::npos) << e.what();
    EXPECT_GT(e.line(), 0u);
  }
}

// A block of a few lines stands for every node, so a small file can ask for much memory: the
// values all blocks keep are bounded by the file (FrdLimits). A file of 400 nodes and blocks of 64
// components whose lines list no node: within a budget of 100,000 values the first 3 blocks fit
// (25,600 values each) and the fourth is refused, naming its line; the default budget reads it all
// with NaN for the missing values. (The outside case: 200,000 nodes and 400 such blocks, 11 MB, took
// 13 GB before this bound and ended in "out of memory".)
TEST(FieldSource, FrdMemoryIsBoundedByTheFile) {
  std::string text = "    1C\n    2C                           400                                     1\n";
  char line[96];
  for (int i = 1; i <= 400; ++i) {
    std::snprintf(line, sizeof line, " -1%10d%12.5E%12.5E%12.5E\n", i, i * 1e-3, 0.0, 0.0);
    text += line;
  }
  text += " -3\n";
  std::vector<std::uint64_t> block_line;
  std::uint64_t lines = 403;
  for (int b = 0; b < 5; ++b) {
    text +=
        "  100CL  101 1.000000000         400                     0    1           1\n -4  BIG        64    "
        "1\n";
    block_line.push_back(lines + 2);
    for (int c = 0; c < 64; ++c) {
      std::snprintf(line, sizeof line, " -5  C%-2d         1    1    0    0\n", c);
      text += line;
    }
    text += " -3\n";
    lines += 67;
  }
  text += " 9999\n";
  const FieldSource all = parse_frd_source(text, "big.frd");
  ASSERT_EQ(all.mesh.fields.size(), 1u);
  EXPECT_EQ(all.mesh.fields[0].step_values.size(), 5u);
  EXPECT_EQ(all.mesh.fields[0].values.size(), 5u * 400 * 64);
  EXPECT_TRUE(std::isnan(all.mesh.fields[0].values.back()));
  FrdLimits small;
  small.min_values = 100000;
  small.values_per_byte = 0;
  try {
    parse_frd_source(text, "big.frd", small);
    ADD_FAILURE() << "a file past its value budget was read";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), block_line[3]) << e.what();
    EXPECT_NE(e.reason().find("BIG"), std::string::npos) << e.what();
    EXPECT_NE(e.reason().find("at most 100000"), std::string::npos) << e.what();
  }
  small.values_per_byte = 16;  // the file's bytes (about 46 KB) allow 16 values a byte: all of it
  EXPECT_EQ(parse_frd_source(text, "big.frd", small).mesh.fields[0].step_values.size(), 5u);
}

TEST(FieldSource, CsvTables) {
  const FieldSource a = parse_csv_source(
      "# exported\n\"id\";temperature [K];u:0 [m];u:1 [m];u:2 [m];q_x;q_y;q_z\n"
      "3;300.5;1e-3;2e-3;3e-3;1;2;3\n1;;0;0;0;4;5;6\n2;nan;0.1;0.2;0.3;7;8;9\n",
      "a.csv");
  EXPECT_EQ(a.key, SourceKey::node_id);
  EXPECT_EQ(a.node_id, (std::vector<std::uint64_t>{3, 1, 2}));
  ASSERT_EQ(a.mesh.fields.size(), 3u);
  EXPECT_EQ(a.mesh.fields[0].name, "temperature");
  EXPECT_EQ(a.mesh.fields[0].unit, "K");
  EXPECT_EQ(a.mesh.fields[0].values[0], 300.5);
  EXPECT_TRUE(std::isnan(a.mesh.fields[0].values[1]) && std::isnan(a.mesh.fields[0].values[2]));
  EXPECT_EQ(a.mesh.fields[1].components, 3u);
  EXPECT_EQ(a.mesh.fields[1].unit, "m");
  EXPECT_EQ(a.mesh.fields[2].values, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  // Onto a 4-node mesh by id: node 4 has no row (NaN, counted); an id beyond the mesh is refused.
  Mesh tiny;
  tiny.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  tiny.tet = {0, 1, 2, 3};
  TransferParams p;
  p.by = MatchBy::id;
  p.names = {"q"};
  const TransferReport rep = transfer_fields(a, tiny, p);
  EXPECT_EQ(rep.nodes_missing, 1u);
  EXPECT_EQ(std::vector<double>(rep.fields[0].values.begin(), rep.fields[0].values.begin() + 9),
            (std::vector<double>{4, 5, 6, 7, 8, 9, 1, 2, 3}));
  EXPECT_EQ(rep.nan_values, 3u);
  const FieldSource far = parse_csv_source("id,t\n5,1\n", "far.csv");
  EXPECT_THROW(transfer_fields(far, tiny, by_id()), FieldError);
  // Keyed by coordinates (ParaView's Points:k), in any column order; a point at no node is refused.
  const FieldSource c = parse_csv_source("t,Points:2,Points:0,Points:1\n7,0,1,0\n8,1,0,0\n", "c.csv");
  EXPECT_EQ(c.key, SourceKey::coordinates);
  EXPECT_EQ(c.mesh.xyz, (std::vector<double>{1, 0, 0, 0, 0, 1}));
  const TransferReport cr = transfer_fields(c, tiny, by_id());
  EXPECT_EQ(cr.fields[0].values[1], 7);
  EXPECT_EQ(cr.fields[0].values[3], 8);
  EXPECT_EQ(cr.nodes_missing, 2u);
  EXPECT_THROW(transfer_fields(parse_csv_source("x,y,z,t\n0.5,0.5,0.5,1\n", "off.csv"), tiny, by_id()),
               FieldError);
  // Cell rows.
  const FieldSource e = parse_csv_source("cell,heat [W/m^3]\n1,5e6\n", "e.csv");
  EXPECT_EQ(transfer_fields(e, tiny, by_id()).fields[0].values, std::vector<double>{5e6});
}

TEST(FieldSource, BrokenCsvTablesNameTheLineAndTheReason) {
  auto error = [](const std::string& text) -> std::pair<std::uint64_t, std::string> {
    try {
      parse_csv_source(text, "bad.csv");
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), "bad.csv");
      return {e.line(), e.reason()};
    }
    return {0, "read"};
  };
  const auto has = [](const std::pair<std::uint64_t, std::string>& e, const char* word) {
    return e.second.find(word) != std::string::npos;
  };
  auto e = error("id,t\n1,3\n2,abc\n");
  EXPECT_EQ(e.first, 3u);
  EXPECT_TRUE(has(e, "abc")) << e.second;
  e = error("id,u:0,u:2\n1,1,2\n");
  EXPECT_EQ(e.first, 1u);
  EXPECT_TRUE(has(e, "component 1")) << e.second;
  e = error("id,t\n1,2,3\n");
  EXPECT_EQ(e.first, 2u);
  EXPECT_TRUE(has(e, "3 cells")) << e.second;
  e = error("id,t\n1,2\n1,3\n");
  EXPECT_EQ(e.first, 3u);
  EXPECT_TRUE(has(e, "twice")) << e.second;
  e = error("t,s\n1,2\n");
  EXPECT_TRUE(has(e, "key")) << e.second;
  e = error("x,y,t\n1,2,3\n");
  EXPECT_TRUE(has(e, "coordinates")) << e.second;
  e = error("id,t\n-1,2\n");
  EXPECT_EQ(e.first, 2u);
  e = error("id,t\n");
  EXPECT_TRUE(has(e, "no rows")) << e.second;
  e = error("");
  EXPECT_TRUE(has(e, "header")) << e.second;
}

}  // namespace
}  // namespace foxi
