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
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
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
  for (std::size_t i = 0; i < 2 * 6 * m.tet_count(); ++i) s.values.push_back(std::exp(double(i % 97) / 7) * 1e5 / 3);
  m.fields = {t, u, s};
  return m;
}

// Reads `path` as a field source and carries it by id onto m (without its fields): every value of
// every field and step must come back bit for bit.
void expect_round_trip(const Mesh& m, const std::filesystem::path& path, bool keeps_units, bool keeps_step_values) {
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
  for (auto [enc, name] : {std::pair{VtuEncoding::appended_raw, "raw"}, {VtuEncoding::ascii, "ascii"},
                           {VtuEncoding::base64, "base64"}, {VtuEncoding::zlib, "zlib"}}) {
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
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
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
  EXPECT_EQ(f.step_values, std::vector<double>(std::begin(times), std::end(times)));
  EXPECT_TRUE(same_bits(f.values, all));
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
    std::snprintf(line, sizeof line, "%zu, %.17g, %.17g, %.17g\n", i + 1, m.xyz[3 * i], m.xyz[3 * i + 1], m.xyz[3 * i + 2]);
    s += line;
  }
  s += "*ELEMENT, TYPE=C3D4, ELSET=EALL\n";
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    std::snprintf(line, sizeof line, "%zu, %u, %u, %u, %u\n", t + 1, m.tet[4 * t] + 1, m.tet[4 * t + 1] + 1,
                  m.tet[4 * t + 2] + 1, m.tet[4 * t + 3] + 1);
    s += line;
  }
  s += "*MATERIAL, NAME=M\n*CONDUCTIVITY\n50\n*ELASTIC\n1e9, 0.3\n*EXPANSION\n1e-5\n"
       "*SOLID SECTION, ELSET=EALL, MATERIAL=M\n" + body;
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
    const int rc = test::run("cd '" + dir.path().string() + "' && OMP_NUM_THREADS=1 ccx -i " + job, dir / "ccx.log");
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
    const std::size_t k = std::find(expand.node_id.begin(), expand.node_id.end(), i + 1) - expand.node_id.begin();
    ASSERT_LT(k, n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(u->values[3 * k + c], 1e-3 * m.xyz[3 * i + c], 1e-8) << "node " << i + 1;
    for (int c = 0; c < 6; ++c) EXPECT_NEAR(s->values[6 * k + c], 0, 1.0) << "node " << i + 1;  // E alpha dT = 1e6 Pa
  }
}

// Broken .frd files: every truncation, a garbled number, a binary block, an unknown node.
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
  std::string binary = good;
  binary.replace(binary.find("1\n -1         1 0.0"), 1, "2");
  EXPECT_EQ(line_of_error(binary), 2u);
  try {
    parse_frd_source(binary, "bad.frd");
  } catch (const IoError& e) {
    EXPECT_NE(e.reason().find("binary"), std::string::npos) << e.what();
  }
  std::string short_record = good;
  short_record.replace(short_record.find(" 1.00000E+00 0.00000E+00 0.00000E+00"), 36, " 1.00000E+00");
  EXPECT_EQ(line_of_error(short_record), 4u);
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
