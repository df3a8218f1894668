// Medit .mesh: checked against files gmsh writes (two physical volumes), meshio's reading of the same
// files and of foxi's, and analytic volumes of the meshed boxes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "foxi/model/io_medit.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/mesh.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

double det(const Mesh& m, std::size_t t) {
  const double* p[4];
  for (int c = 0; c < 4; ++c) p[c] = &m.xyz[3 * m.tet[4 * t + c]];
  double a[3], b[3], d[3];
  for (int i = 0; i < 3; ++i) {
    a[i] = p[1][i] - p[0][i];
    b[i] = p[2][i] - p[0][i];
    d[i] = p[3][i] - p[0][i];
  }
  return a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) +
         a[2] * (b[0] * d[1] - b[1] * d[0]);
}

bool have_meshio() { return test::run("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") == 0; }

// meshio's view of a Medit file: points, tets, triangles, and tets per ref ("ref:count" pairs).
struct MeshioCounts {
  long points = -1, tets = -1, triangles = -1;
  std::map<long, long> tets_per_ref;
  std::map<long, long> tris_per_ref;
};

MeshioCounts meshio_counts(const TempDir& dir, const fs::path& file) {
  std::string py =
      "import meshio, numpy as np\n"
      "m = meshio.read('" +
      file.string() +
      "', file_format='medit')\n"
      "def block(kind):\n"
      "    for i, c in enumerate(m.cells):\n"
      "        if c.type == kind: return c.data, m.cell_data['medit:ref'][i]\n"
      "    return np.zeros((0, 4), int), np.zeros(0, int)\n"
      "t, tr = block('tetra'); f, fr = block('triangle')\n"
      "with open('" +
      (dir / "counts.out").string() +
      "', 'w') as o:\n"
      "    print(len(m.points), len(t), len(f), file=o)\n"
      "    for r in np.unique(tr): print('T', r, int((tr == r).sum()), file=o)\n"
      "    for r in np.unique(fr): print('F', r, int((fr == r).sum()), file=o)\n";
  test::write_text(dir / "counts.py", py);
  MeshioCounts out;
  int rc = test::run("/usr/bin/python3 '" + (dir / "counts.py").string() + "'", dir / "counts.log");
  EXPECT_EQ(rc, 0) << test::read_text(dir / "counts.log");
  std::istringstream in(test::read_text(dir / "counts.out"));
  in >> out.points >> out.tets >> out.triangles;
  std::string kind;
  long ref, count;
  while (in >> kind >> ref >> count) (kind == "T" ? out.tets_per_ref : out.tris_per_ref)[ref] = count;
  return out;
}

void expect_matches_meshio(const Mesh& m, const MeshioCounts& c) {
  EXPECT_EQ(static_cast<long>(m.node_count()), c.points);
  EXPECT_EQ(static_cast<long>(m.tet_count()), c.tets);
  EXPECT_EQ(static_cast<long>(m.bface_count()), c.triangles);
  std::map<long, long> tets, tris;
  for (std::size_t t = 0; t < m.tet_count(); ++t) ++tets[m.region_of(t)];
  for (std::int32_t tag : m.bface_tag) ++tris[tag];
  EXPECT_EQ(tets, c.tets_per_ref);
  EXPECT_EQ(tris, c.tris_per_ref);
}

// Two unit boxes side by side as physical volumes 7 and 9; physical surface 3 (x = 0) and curve 5,
// so that gmsh writes Edges too. Refs are the physical tags (Mesh.SaveElementTagType 2).
fs::path gmsh_two_boxes(const TempDir& dir) {
  test::write_text(dir / "two.geo",
                   "SetFactory(\"OpenCASCADE\");\n"
                   "Box(1) = {0,0,0, 1,1,1};\nBox(2) = {1,0,0, 1,1,1};\nCoherence;\n"
                   "Physical Volume(7) = {1};\nPhysical Volume(9) = {2};\n"
                   "Physical Surface(3) = {1};\nPhysical Curve(5) = {1, 2};\n"
                   "Mesh.CharacteristicLengthMax = 0.3;\n");
  int rc = test::run("cd '" + dir.path().string() +
                         "' && gmsh -3 two.geo -format mesh -setnumber Mesh.SaveElementTagType 2 -o two.mesh",
                     dir / "gmsh.log");
  EXPECT_EQ(rc, 0) << test::read_text(dir / "gmsh.log");
  return dir / "two.mesh";
}

TEST(MeditOracle, GmshFileMatchesMeshioAndAnalyticVolumes) {
  if (!test::have_program("gmsh") || !have_meshio()) GTEST_SKIP() << "gmsh or meshio not installed";
  TempDir dir;
  fs::path file = gmsh_two_boxes(dir);
  ASSERT_NE(test::read_text(file).find("Edges"), std::string::npos) << "gmsh wrote no Edges to skip";
  Mesh m = read_medit(file);
  MeshioCounts c = meshio_counts(dir, file);
  ASSERT_GT(c.tets, 0);
  expect_matches_meshio(m, c);
  // Physical volumes 7 and 9 are the unit boxes [0,1]^3 and [1,2]x[0,1]^2; every tet of gmsh's
  // Medit export is positively oriented in foxi's convention.
  std::map<int, double> volume;
  std::size_t positive = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    volume[m.region_of(t)] += det(m, t) / 6;
    positive += det(m, t) > 0;
  }
  EXPECT_EQ(positive, m.tet_count());
  ASSERT_EQ(volume.size(), 2u);
  EXPECT_NEAR(volume[7], 1.0, 1e-12);
  EXPECT_NEAR(volume[9], 1.0, 1e-12);
  ASSERT_EQ(m.regions.size(), 2u);
  EXPECT_EQ(m.regions[0].id, 7);
  EXPECT_EQ(m.regions[1].id, 9);
  // Surface 3 is the face x = 0.
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    EXPECT_EQ(m.bface_tag[f], 3);
    for (int c3 = 0; c3 < 3; ++c3) EXPECT_EQ(m.xyz[3 * m.bface[3 * f + c3]], 0.0);
  }
}

TEST(MeditOracle, MeshioReadsFoxiFiles) {
  if (!test::have_program("gmsh") || !have_meshio()) GTEST_SKIP() << "gmsh or meshio not installed";
  TempDir dir;
  Mesh m = read_medit(gmsh_two_boxes(dir));
  write_medit(m, dir / "foxi.mesh");
  expect_matches_meshio(m, meshio_counts(dir, dir / "foxi.mesh"));
  // Coordinates and connectivity as meshio reads them: exactly foxi's.
  std::string py =
      "import meshio, numpy as np\n"
      "a = meshio.read('" +
      (dir / "foxi.mesh").string() +
      "')\n"
      "b = meshio.read('" +
      (dir / "two.mesh").string() +
      "')\n"
      "print(int(np.array_equal(a.points, b.points)), int(np.array_equal(a.cells_dict['tetra'], "
      "b.cells_dict['tetra'])), a.points.dtype)\n";
  test::write_text(dir / "cmp.py", py);
  ASSERT_EQ(test::run("/usr/bin/python3 '" + (dir / "cmp.py").string() + "'", dir / "cmp.log"), 0)
      << test::read_text(dir / "cmp.log");
  EXPECT_EQ(test::read_text(dir / "cmp.log"), "1 1 float64\n");
}

// A file with the keywords foxi skips, read by meshio in canonical spelling; foxi must read the same
// content in any case, with comments, CRLF line ends and numbers spread over lines.
TEST(MeditOracle, SkippedKeywordsAndSpellingMatchMeshio) {
  if (!have_meshio()) GTEST_SKIP() << "meshio not installed";
  TempDir dir;
  const std::string canonical =
      "MeshVersionFormatted 2\nDimension 3\n"
      "Vertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n1 1 1 1\n"
      "Corners\n2\n1\n2\n"
      "Normals\n2\n1 0 0\n0 1 0\n"
      "NormalAtVertices\n2\n1 1\n2 2\n"
      "RequiredVertices\n1\n3\n"
      "Ridges\n1\n1\n"
      "Edges\n2\n1 2 4\n2 3 4\n"
      "Triangles\n2\n1 2 3 11\n1 2 4 12\n"
      "Tetrahedra\n2\n1 2 3 4 5\n2 3 4 5 6\n"
      "End\n";
  test::write_text(dir / "c.mesh", canonical);
  MeshioCounts c = meshio_counts(dir, dir / "c.mesh");
  ASSERT_EQ(c.tets, 2);
  Mesh a = read_medit(dir / "c.mesh");
  expect_matches_meshio(a, c);
  std::string odd;
  for (char ch : canonical) {
    if (ch == '\n')
      odd += " # note\r\n";
    else
      odd += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  }
  Mesh b = parse_medit(odd, "odd");
  expect_matches_meshio(b, c);
  EXPECT_EQ(a.tet, b.tet);
  EXPECT_EQ(a.xyz, b.xyz);
  EXPECT_EQ(a.bface, b.bface);
}

Mesh awkward_mesh() {
  Mesh m;
  const double vals[] = {0.1,
                         0.2 + 0.1,
                         -0.0,
                         1e-300,
                         5e-324,
                         1.7976931348623157e308,
                         -123456.789e-7,
                         1.0 / 3.0,
                         2.0 / 3.0,
                         3.0e10,
                         -2.5,
                         4.9406564584124654e-320};
  std::mt19937_64 rng(11);
  for (int i = 0; i < 40; ++i)
    for (int c = 0; c < 3; ++c)
      m.xyz.push_back(i < 12 ? vals[(i * 3 + c) % 12]
                             : std::ldexp(static_cast<double>(rng() >> 11), -53) * (i - 20));
  for (std::uint32_t t = 0; t + 3 < 40; t += 2) {
    m.tet.insert(m.tet.end(), {t, t + 1, t + 2, t + 3});
    m.tet_region.push_back(static_cast<std::int32_t>(t) - 20);
  }
  for (std::uint32_t f = 0; f + 2 < 40; f += 5) {
    m.bface.insert(m.bface.end(), {f, f + 2, f + 1});
    m.bface_tag.push_back(static_cast<std::int32_t>(f % 3) - 1);
  }
  m.bface_tag.back() = 2147483647;
  m.tet_region.back() = -2147483647 - 1;
  return m;
}

TEST(MeditRoundTrip, BitForBit) {
  TempDir dir;
  Mesh m = awkward_mesh();
  write_medit(m, dir / "a.mesh");
  Mesh r = read_medit(dir / "a.mesh");
  ASSERT_EQ(r.xyz.size(), m.xyz.size());
  EXPECT_EQ(0, std::memcmp(r.xyz.data(), m.xyz.data(), m.xyz.size() * sizeof(double)));
  EXPECT_EQ(r.tet, m.tet);
  EXPECT_EQ(r.tet_region, m.tet_region);
  EXPECT_EQ(r.bface, m.bface);
  EXPECT_EQ(r.bface_tag, m.bface_tag);
  write_medit(r, dir / "b.mesh");
  EXPECT_EQ(test::read_text(dir / "a.mesh"), test::read_text(dir / "b.mesh"));
  std::size_t files = 0;
  for (auto& e : fs::directory_iterator(dir.path())) (void)e, ++files;
  EXPECT_EQ(files, 2u);  // no temporaries left behind
}

TEST(MeditRoundTrip, TetgenMeshThroughMedit) {
  // The same mesh through both formats of this file gives the same arrays.
  TempDir dir;
  Mesh m = awkward_mesh();
  write_tetgen(m, dir / "t");
  write_medit(read_tetgen(dir / "t"), dir / "t.mesh");
  Mesh r = read_medit(dir / "t.mesh");
  EXPECT_EQ(0, std::memcmp(r.xyz.data(), m.xyz.data(), m.xyz.size() * sizeof(double)));
  EXPECT_EQ(r.tet, m.tet);
  EXPECT_EQ(r.tet_region, m.tet_region);
}

struct BadCase {
  const char* file;
  std::uint64_t line;
  const char* reason_has;
};

TEST(MeditRead, BadCorpusFailsWithLocatedErrors) {
  const BadCase cases[] = {
      {"truncated.mesh", 14, "end of file"},
      {"wrong_count.mesh", 9, "unknown keyword '1'"},
      {"huge_count.mesh", 4, "bytes left"},
      {"index_out_of_range.mesh", 12, "vertex 6 is out of range"},
      {"index_zero.mesh", 13, "vertex 0 is out of range"},
      {"non_numeric.mesh", 6, "expected y coordinate, found 'abc'"},
      {"nan_coordinate.mesh", 6, "non-finite"},
      {"empty.mesh", 1, "empty file"},
      {"unknown_keyword.mesh", 10, "unknown keyword 'Foo'"},
      {"dim2.mesh", 2, "dimension is 2"},
      {"hexahedra.mesh", 10, "not supported"},
      {"elements_before_vertices_out_of_range.mesh", 3, "vertex 9 is out of range"},
      {"bad_version.mesh", 1, "version 7"},
      {"negative_count.mesh", 11, "negative"},
  };
  const fs::path dir = fs::path(test::data_dir()) / "bad" / "medit";
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.file);
    const fs::path file = dir / c.file;
    ASSERT_TRUE(fs::exists(file)) << "corpus file missing";
    try {
      read_medit(file);
      ADD_FAILURE() << "no error";
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), file.string()) << e.what();
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_NE(e.reason().find(c.reason_has), std::string::npos) << e.what();
    }
  }
}

TEST(MeditRead, MixedLineEndsAndLowercaseRead) {
  Mesh m = read_medit(fs::path(test::data_dir()) / "bad" / "medit" / "mixed_crlf.mesh");
  EXPECT_EQ(m.node_count(), 5u);
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3, 1, 2, 3, 4}));
  EXPECT_EQ(m.tet_region, (std::vector<std::int32_t>{1, 2}));
  EXPECT_EQ(m.bface_tag, (std::vector<std::int32_t>{7}));
  EXPECT_EQ(m.xyz[3 * 4 + 2], 1.0);
}

TEST(MeditRead, MissingFileNamesIt) {
  TempDir dir;
  try {
    read_medit(dir / "none.mesh");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), (dir / "none.mesh").string());
  }
}

TEST(MeditRead, TruncationSweepNeverCrashes) {
  TempDir dir;
  write_medit(awkward_mesh(), dir / "a.mesh");
  const std::string text = test::read_text(dir / "a.mesh");
  std::size_t ok = 0, failed = 0;
  for (std::size_t k = 0; k <= text.size(); ++k) {
    try {
      Mesh r = parse_medit(std::string_view(text).substr(0, k), "cut");
      EXPECT_TRUE(check_sizes(r).empty());
      for (std::uint32_t i : r.tet) ASSERT_LT(i, r.node_count());
      for (std::uint32_t i : r.bface) ASSERT_LT(i, r.node_count());
      ++ok;
    } catch (const IoError& e) {
      EXPECT_FALSE(e.reason().empty());
      ++failed;
    }
  }
  EXPECT_GT(failed, text.size() / 2);
  EXPECT_GT(ok, 0u);
}

TEST(MeditRead, ByteMutationSweepNeverCrashes) {
  TempDir dir;
  write_medit(awkward_mesh(), dir / "a.mesh");
  const std::string text = test::read_text(dir / "a.mesh");
  const char subst[] = {'#', '\n', '\r', '-', '9', 'e', '.', ' ', '\0', 'x'};
  std::size_t failed = 0;
  for (std::size_t k = 0; k < text.size(); ++k) {
    for (char c : subst) {
      std::string t = text;
      t[k] = c;
      try {
        Mesh r = parse_medit(t, "mut");
        ASSERT_TRUE(check_sizes(r).empty());
        for (std::uint32_t i : r.tet) ASSERT_LT(i, r.node_count());
        for (std::uint32_t i : r.bface) ASSERT_LT(i, r.node_count());
        for (double x : r.xyz) ASSERT_TRUE(std::isfinite(x));
      } catch (const IoError&) {
        ++failed;
      }
    }
  }
  EXPECT_GT(failed, 0u);
}

TEST(MeditWrite, FailedWriteLeavesNothing) {
  TempDir dir;
  fs::create_directories(dir / "a.mesh" / "x");
  EXPECT_THROW(write_medit(awkward_mesh(), dir / "a.mesh"), IoError);
  std::size_t entries = 0;
  for (auto& e : fs::directory_iterator(dir.path())) (void)e, ++entries;
  EXPECT_EQ(entries, 1u);
  Mesh bad = awkward_mesh();
  bad.xyz[7] = std::nan("");
  EXPECT_THROW(write_medit(bad, dir / "b.mesh"), IoError);
  EXPECT_FALSE(fs::exists(dir / "b.mesh"));
}

}  // namespace
}  // namespace foxi
