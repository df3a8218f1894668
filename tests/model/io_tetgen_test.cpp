// TetGen .node/.ele/.face: checked against tetgen itself (its stdout statistics and the header lines
// of the files it writes), analytic volumes and areas of the meshed box, meshio's reader, and
// `tetgen -r` reading foxi's files.
#include "foxi/model/io_tetgen.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

// Two unit cubes side by side, [0,2]x[0,1]x[0,1], split by the facet x = 1. Facet markers:
// 1 on x = 0, 2 on x = 2, 3 on the other outer faces, 4 on the inner facet. Regions (in the
// region list): attribute 10 in x < 1 with max volume vol_left, 20 in x > 1 with vol_right.
std::string box_poly(double vol_left, double vol_right) {
  std::ostringstream s;
  s << "# two unit cubes\n12 3 0 0\n";
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) s << (k * 6 + j * 3 + i + 1) << " " << i << " " << j << " " << k << "\n";
  // node(i,j,k) = k*6 + j*3 + i + 1
  auto n = [](int i, int j, int k) { return k * 6 + j * 3 + i + 1; };
  struct F {
    int m;
    std::array<int, 4> v;
  };
  std::vector<F> f = {
      {1, {n(0, 0, 0), n(0, 1, 0), n(0, 1, 1), n(0, 0, 1)}},
      {2, {n(2, 0, 0), n(2, 1, 0), n(2, 1, 1), n(2, 0, 1)}},
      {4, {n(1, 0, 0), n(1, 1, 0), n(1, 1, 1), n(1, 0, 1)}},
  };
  for (int i = 0; i < 2; ++i) {
    f.push_back({3, {n(i, 0, 0), n(i + 1, 0, 0), n(i + 1, 1, 0), n(i, 1, 0)}});  // z = 0
    f.push_back({3, {n(i, 0, 1), n(i + 1, 0, 1), n(i + 1, 1, 1), n(i, 1, 1)}});  // z = 1
    f.push_back({3, {n(i, 0, 0), n(i + 1, 0, 0), n(i + 1, 0, 1), n(i, 0, 1)}});  // y = 0
    f.push_back({3, {n(i, 1, 0), n(i + 1, 1, 0), n(i + 1, 1, 1), n(i, 1, 1)}});  // y = 1
  }
  s << f.size() << " 1\n";
  for (const F& x : f)
    s << "1 0 " << x.m << "\n4 " << x.v[0] << " " << x.v[1] << " " << x.v[2] << " " << x.v[3] << "\n";
  s << "0\n2\n1 0.5 0.5 0.5 10 " << vol_left << "\n2 1.5 0.5 0.5 20 " << vol_right << "\n";
  return s.str();
}

// tetgen's "Mesh points: N" style statistics from its stdout.
std::map<std::string, long> tetgen_stats(const fs::path& log) {
  std::map<std::string, long> out;
  std::istringstream in(test::read_text(log));
  std::string line;
  std::regex re(R"(^\s*(Mesh [a-z ]+|Input [a-z ]+):\s+(\d+)\s*$)");
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, re)) out[m[1]] = std::stol(m[2]);
  }
  return out;
}

// The numbers on the first non-comment line of a file (a TetGen header).
std::vector<long> header_of(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    auto h = line.find('#');
    if (h != std::string::npos) line.resize(h);
    std::istringstream s(line);
    std::vector<long> v;
    long x;
    while (s >> x) v.push_back(x);
    if (!v.empty()) return v;
  }
  return {};
}

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

double tri_area(const Mesh& m, std::size_t f) {
  const double* p0 = &m.xyz[3 * m.bface[3 * f]];
  const double* p1 = &m.xyz[3 * m.bface[3 * f + 1]];
  const double* p2 = &m.xyz[3 * m.bface[3 * f + 2]];
  double a[3], b[3];
  for (int i = 0; i < 3; ++i) {
    a[i] = p1[i] - p0[i];
    b[i] = p2[i] - p0[i];
  }
  double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

bool have_tools() { return test::have_program("tetgen"); }

// Runs tetgen on the box in `dir`; returns its statistics. `switches` like "-pqAa".
std::map<std::string, long> mesh_box(const TempDir& dir, const std::string& switches, double vl = 0.01,
                                     double vr = 0.05) {
  test::write_text(dir / "box.poly", box_poly(vl, vr));
  int rc =
      test::run("cd '" + dir.path().string() + "' && tetgen " + switches + " box.poly", dir / "tetgen.log");
  EXPECT_EQ(rc, 0) << test::read_text(dir / "tetgen.log");
  return tetgen_stats(dir / "tetgen.log");
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.xyz.size(), b.xyz.size());
  EXPECT_EQ(0, std::memcmp(a.xyz.data(), b.xyz.data(), a.xyz.size() * sizeof(double)));
  EXPECT_EQ(a.tet, b.tet);
  EXPECT_EQ(a.tet_region, b.tet_region);
  EXPECT_EQ(a.bface, b.bface);
  EXPECT_EQ(a.bface_tag, b.bface_tag);
}

TEST(TetgenOracle, CountsRegionsMarkersMatchTetgen) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  TempDir dir;
  auto stats = mesh_box(dir, "-pqAa");
  Mesh m = read_tetgen(dir / "box.1");
  ASSERT_GT(stats["Mesh tetrahedra"], 0);
  EXPECT_EQ(static_cast<long>(m.node_count()), stats["Mesh points"]);
  EXPECT_EQ(static_cast<long>(m.tet_count()), stats["Mesh tetrahedra"]);
  EXPECT_EQ(static_cast<long>(m.bface_count()), stats["Mesh faces on facets"]);
  EXPECT_EQ(static_cast<long>(m.node_count()), header_of(dir / "box.1.node").at(0));
  EXPECT_EQ(static_cast<long>(m.tet_count()), header_of(dir / "box.1.ele").at(0));
  EXPECT_EQ(static_cast<long>(m.bface_count()), header_of(dir / "box.1.face").at(0));

  // Regions: volumes of the two unit cubes; boundary markers: areas of the facets.
  std::map<int, double> volume, area;
  for (std::size_t t = 0; t < m.tet_count(); ++t) volume[m.region_of(t)] += std::abs(det(m, t)) / 6;
  for (std::size_t f = 0; f < m.bface_count(); ++f) area[m.bface_tag[f]] += tri_area(m, f);
  ASSERT_EQ(volume.size(), 2u);
  EXPECT_NEAR(volume[10], 1.0, 1e-12);
  EXPECT_NEAR(volume[20], 1.0, 1e-12);
  ASSERT_EQ(area.size(), 4u);
  EXPECT_NEAR(area[1], 1.0, 1e-12);
  EXPECT_NEAR(area[2], 1.0, 1e-12);
  EXPECT_NEAR(area[3], 8.0, 1e-12);
  EXPECT_NEAR(area[4], 1.0, 1e-12);
  // Every tet of region 10 lies in x <= 1: region attributes belong to the right tets.
  for (std::size_t t = 0; t < m.tet_count(); ++t)
    for (int c = 0; c < 4; ++c) {
      double x = m.xyz[3 * m.tet[4 * t + c]];
      if (m.region_of(t) == 10)
        EXPECT_LE(x, 1.0);
      else
        EXPECT_GE(x, 1.0);
    }
  // The region and boundary lists name the ids present.
  ASSERT_EQ(m.regions.size(), 2u);
  EXPECT_EQ(m.regions[0].id, 10);
  EXPECT_EQ(m.regions[1].id, 20);
  EXPECT_EQ(m.boundaries.size(), 4u);
  EXPECT_TRUE(check_sizes(m).empty());
}

// The finding stated in io_tetgen.cpp: TetGen's .ele corners are in foxi's positive order.
TEST(TetgenOracle, OrientationMatchesFoxi) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  for (const char* sw : {"-pqAa", "-pA", "-pqAaY"}) {
    TempDir dir;
    mesh_box(dir, sw, 0.002, 0.02);
    Mesh m = read_tetgen(dir / "box.1");
    ASSERT_GT(m.tet_count(), 0u);
    std::size_t positive = 0;
    double total = 0;
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      double d = det(m, t);
      positive += d > 0;
      total += d / 6;
    }
    EXPECT_EQ(positive, m.tet_count()) << sw;
    EXPECT_NEAR(total, 2.0, 1e-12) << sw;  // analytic volume of the box, signed sum
  }
}

TEST(TetgenOracle, ZeroBasedOutputReadsTheSame) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  TempDir dir;
  auto stats = mesh_box(dir, "-pqAaz");
  EXPECT_EQ(header_of(dir / "box.1.node").size(), 4u);
  // tetgen -z numbers from 0: the first node line starts with 0.
  std::ifstream in(dir / "box.1.node");
  std::string line;
  std::getline(in, line);
  long first = -1;
  in >> first;
  ASSERT_EQ(first, 0);
  Mesh m = read_tetgen(dir / "box.1");
  EXPECT_EQ(static_cast<long>(m.node_count()), stats["Mesh points"]);
  EXPECT_EQ(static_cast<long>(m.tet_count()), stats["Mesh tetrahedra"]);
  EXPECT_EQ(static_cast<long>(m.bface_count()), stats["Mesh faces on facets"]);
  double total = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    EXPECT_GT(det(m, t), 0);
    total += det(m, t) / 6;
  }
  EXPECT_NEAR(total, 2.0, 1e-12);
}

TEST(TetgenOracle, SecondOrderTetsKeepTheirCorners) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  TempDir dir;
  auto stats = mesh_box(dir, "-pqAao2");
  ASSERT_EQ(header_of(dir / "box.1.ele").at(1), 10);
  Mesh m = read_tetgen(dir / "box.1");
  EXPECT_EQ(static_cast<long>(m.node_count()), header_of(dir / "box.1.node").at(0));
  EXPECT_EQ(static_cast<long>(m.tet_count()), stats["Mesh tetrahedra"]);
  EXPECT_EQ(static_cast<long>(m.bface_count()), header_of(dir / "box.1.face").at(0));
  double total = 0;
  std::map<int, double> area;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    EXPECT_GT(det(m, t), 0);
    total += det(m, t) / 6;
  }
  for (std::size_t f = 0; f < m.bface_count(); ++f) area[m.bface_tag[f]] += tri_area(m, f);
  EXPECT_NEAR(total, 2.0, 1e-12);
  EXPECT_NEAR(area[3], 8.0, 1e-12);
}

// tetgen -nn writes each face's two adjacent tets after its marker (its documented .face format):
// the faces read the same as without -nn, also with second-order faces (-o2); -nn was refused
// ("unexpected '0' after the face's values"; an outside probe).
TEST(TetgenOracle, AdjacentTetColumnsOfNnAreRead) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  for (const char* order : {"", "o2"}) {
    TempDir plain_dir, nn_dir;
    mesh_box(plain_dir, std::string("-pqAa") + order);
    mesh_box(nn_dir, std::string("-pqAann") + order);
    const Mesh plain = read_tetgen(plain_dir / "box.1"), nn = read_tetgen(nn_dir / "box.1");
    EXPECT_EQ(header_of(nn_dir / "box.1.face").at(0), header_of(plain_dir / "box.1.face").at(0));
    EXPECT_EQ(nn.bface, plain.bface) << order;
    EXPECT_EQ(nn.bface_tag, plain.bface_tag) << order;
    EXPECT_EQ(nn.tet, plain.tet) << order;
  }
}

TEST(TetgenOracle, TetgenReadsFoxiFiles) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  TempDir dir;
  mesh_box(dir, "-pqAa");
  Mesh m = read_tetgen(dir / "box.1");
  write_tetgen(m, dir / "foxi");
  // tetgen -r reconstructs the mesh from foxi's .node/.ele (and .face), writes foxi.1.*.
  int rc = test::run("cd '" + dir.path().string() + "' && tetgen -rV foxi", dir / "r.log");
  ASSERT_EQ(rc, 0) << test::read_text(dir / "r.log");
  auto stats = tetgen_stats(dir / "r.log");
  EXPECT_EQ(stats["Input points"], static_cast<long>(m.node_count()));
  EXPECT_EQ(stats["Input tetrahedra"], static_cast<long>(m.tet_count()));
  EXPECT_EQ(stats["Mesh tetrahedra"], static_cast<long>(m.tet_count()));
  Mesh again = read_tetgen(dir / "foxi.1");
  EXPECT_EQ(again.tet_count(), m.tet_count());
  EXPECT_EQ(again.regions.size(), 2u);
  // And refining foxi's mesh (-rq) works too.
  rc = test::run("cd '" + dir.path().string() + "' && tetgen -rqa0.005 foxi", dir / "rq.log");
  ASSERT_EQ(rc, 0) << test::read_text(dir / "rq.log");
  EXPECT_GT(tetgen_stats(dir / "rq.log")["Mesh tetrahedra"], static_cast<long>(m.tet_count()));
}

TEST(TetgenOracle, MeshioReadsFoxiFiles) {
  if (!have_tools() || test::run("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "tetgen or meshio not installed";
  }
  TempDir dir;
  mesh_box(dir, "-pqAa");
  Mesh m = read_tetgen(dir / "box.1");
  write_tetgen(m, dir / "foxi");
  std::string py =
      "import meshio, numpy as np\n"
      "m = meshio.read('" +
      (dir / "foxi.node").string() +
      "', file_format='tetgen')\n"
      "t = m.cells_dict['tetra']; p = m.points\n"
      "a, b, c, d = (p[t[:, i]] for i in range(4))\n"
      "v = np.einsum('ij,ij->i', np.cross(b - a, c - a), d - a) / 6\n"
      "r = m.cell_data['tetgen:ref'][0]\n"
      "print(len(p), len(t), int((r == 10).sum()), int((r == 20).sum()), repr(v.sum()), int((v > "
      "0).sum()))\n";
  test::write_text(dir / "check.py", py);
  ASSERT_EQ(test::run("/usr/bin/python3 '" + (dir / "check.py").string() + "'", dir / "py.log"), 0)
      << test::read_text(dir / "py.log");
  std::istringstream out(test::read_text(dir / "py.log"));
  long np_ = 0, nt = 0, r10 = 0, r20 = 0, npos = 0;
  double vol = 0;
  out >> np_ >> nt >> r10 >> r20 >> vol >> npos;
  EXPECT_EQ(np_, static_cast<long>(m.node_count()));
  EXPECT_EQ(nt, static_cast<long>(m.tet_count()));
  long f10 = 0, f20 = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) (m.region_of(t) == 10 ? f10 : f20)++;
  EXPECT_EQ(r10, f10);
  EXPECT_EQ(r20, f20);
  EXPECT_NEAR(vol, 2.0, 1e-12);
  EXPECT_EQ(npos, nt);
}

// meshio writes 0-based TetGen files with comments before the headers: an outside writer.
TEST(TetgenOracle, ReadsMeshioWrittenFiles) {
  if (test::run("/usr/bin/python3 -c 'import meshio' > /dev/null 2>&1") != 0) GTEST_SKIP() << "no meshio";
  TempDir dir;
  std::string py =
      "import meshio, numpy as np\n"
      "p = np.array([[0,0,0],[1,0,0],[0,1,0],[0,0,1],[1,1,1]], dtype=float) * 0.1\n"
      "t = np.array([[0,1,2,3],[1,2,3,4]])\n"
      "m = meshio.Mesh(p, [('tetra', t)], cell_data={'tetgen:ref': [np.array([3, 5])]})\n"
      "meshio.write('" +
      (dir / "mio.node").string() + "', m, file_format='tetgen')\n";
  test::write_text(dir / "w.py", py);
  ASSERT_EQ(test::run("/usr/bin/python3 '" + (dir / "w.py").string() + "'", dir / "py.log"), 0)
      << test::read_text(dir / "py.log");
  Mesh m = read_tetgen(dir / "mio");
  ASSERT_EQ(m.node_count(), 5u);
  ASSERT_EQ(m.tet_count(), 2u);
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3, 1, 2, 3, 4}));
  EXPECT_EQ(m.tet_region, (std::vector<std::int32_t>{3, 5}));
  EXPECT_EQ(m.xyz[3 * 4], 0.1);
  EXPECT_EQ(m.bface_count(), 0u);
}

// A mesh with awkward doubles: shortest round-trip text must give the same bits back.
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
  std::mt19937_64 rng(7);
  for (int i = 0; i < 40; ++i) {
    for (int c = 0; c < 3; ++c) {
      double v = vals[(i * 3 + c) % 12];
      if (i >= 12) v = std::ldexp(static_cast<double>(rng() >> 11), -53) * (i - 20);
      m.xyz.push_back(v);
    }
  }
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

TEST(TetgenRoundTrip, BitForBit) {
  TempDir dir;
  Mesh m = awkward_mesh();
  write_tetgen(m, dir / "a");
  Mesh r = read_tetgen(dir / "a");
  expect_same_mesh(m, r);
  write_tetgen(r, dir / "b");
  for (const char* ext : {".node", ".ele", ".face"}) {
    EXPECT_EQ(test::read_text(dir / (std::string("a") + ext)),
              test::read_text(dir / (std::string("b") + ext)));
  }
  // No temporaries are left next to the files.
  std::size_t files = 0;
  for (auto& e : fs::directory_iterator(dir.path())) files += e.is_regular_file();
  EXPECT_EQ(files, 6u);
}

TEST(TetgenRoundTrip, TetgenOutputRewritesIdentically) {
  if (!have_tools()) GTEST_SKIP() << "tetgen not installed";
  TempDir dir;
  mesh_box(dir, "-pqAa");
  Mesh m = read_tetgen(dir / "box.1");
  write_tetgen(m, dir / "w");
  Mesh r = read_tetgen(dir / "w");
  expect_same_mesh(m, r);
  // Coordinates as tetgen printed them (%.17g-like) read the same through foxi's text.
  EXPECT_TRUE(check_sizes(r).empty());
}

TEST(TetgenRoundTrip, NoRegionsStaysNoRegions) {
  TempDir dir;
  Mesh m = awkward_mesh();
  m.tet_region.clear();
  write_tetgen(m, dir / "a");
  EXPECT_EQ(header_of(dir / "a.ele"), (std::vector<long>{static_cast<long>(m.tet_count()), 4, 0}));
  Mesh r = read_tetgen(dir / "a");
  expect_same_mesh(m, r);
  EXPECT_TRUE(r.regions.empty());
}

TEST(TetgenRead, FaceFileIsOptional) {
  TempDir dir;
  Mesh m = awkward_mesh();
  write_tetgen(m, dir / "a");
  fs::remove(dir / "a.face");
  Mesh r = read_tetgen(dir / "a");
  EXPECT_EQ(r.tet, m.tet);
  EXPECT_EQ(r.bface_count(), 0u);
}

TEST(TetgenRead, MissingEleNamesTheFile) {
  TempDir dir;
  write_tetgen(awkward_mesh(), dir / "a");
  fs::remove(dir / "a.ele");
  try {
    read_tetgen(dir / "a");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.file(), (dir / "a.ele").string());
    EXPECT_NE(e.reason().find("cannot open"), std::string::npos) << e.what();
  }
}

TEST(TetgenRead, CommentsBlankLinesAndMixedLineEnds) {
  const std::string node =
      "# header comment\r\n\n  4 3 1 1  # four nodes\r\n"
      "1 0 0 0 7.5 1\n\r\n# a comment line\n2 1 0 0 0 1\r3 0 1 0 0 0 # trailing\r\n4 0 0 1 0 0";
  const std::string ele = "1 4 2\r\n# c\n\n1 1 2 3 4 2.4 99\r\n";
  const std::string face = "2 1\n1 1 2 3 -5\r\n2 1 2 4 6 # end";
  Mesh m = parse_tetgen(node, ele, face, "mem");
  ASSERT_EQ(m.node_count(), 4u);
  EXPECT_EQ(m.xyz, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(m.tet_region, (std::vector<std::int32_t>{2}));  // 2.4 rounds to 2
  EXPECT_EQ(m.bface, (std::vector<std::uint32_t>{0, 1, 2, 0, 1, 3}));
  EXPECT_EQ(m.bface_tag, (std::vector<std::int32_t>{-5, 6}));
}

// Bad corpus: each case names the file that must be blamed, the line and a word of the reason.
struct BadCase {
  const char* base;
  const char* blamed_ext;
  std::uint64_t line;
  const char* reason_has;
};

TEST(TetgenRead, BadCorpusFailsWithLocatedErrors) {
  const BadCase cases[] = {
      {"truncated", ".ele", 4, "end of file"},
      {"count_too_small", ".node", 6, "more data"},
      {"count_too_large", ".ele", 5, "end of file"},
      {"huge_count", ".node", 1, "bytes left"},
      {"huge_tets", ".ele", 2, "bytes left"},
      {"index_out_of_range", ".ele", 2, "out of range"},
      {"index_zero_in_one_based", ".face", 3, "out of range"},
      {"non_numeric", ".node", 3, "expected y coordinate, found 'abc'"},
      {"nan_coordinate", ".node", 4, "non-finite"},
      {"empty_node", ".node", 1, "empty file"},
      {"empty_ele", ".ele", 1, "empty file"},
      {"empty_face", ".face", 1, "empty file"},
      {"dim2", ".node", 1, "dimension is 2"},
      {"first_index_5", ".node", 2, "not 0 or 1"},
      {"gap_in_numbering", ".node", 4, "consecutively"},
      {"missing_ele", ".ele", 0, "cannot open"},
      {"short_line", ".ele", 2, "line ends early"},
      {"extra_token", ".face", 2, "unexpected '9'"},
      {"eight_node_tets", ".ele", 1, "expected 4 or 10"},
      {"region_overflow", ".ele", 2, "32-bit"},
      {"negative_count", ".face", 1, "negative"},
  };
  const fs::path dir = fs::path(test::data_dir()) / "bad" / "tetgen";
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.base);
    const fs::path base = dir / c.base;
    ASSERT_TRUE(fs::exists(fs::path(base.string() + ".node"))) << "corpus file missing";
    try {
      read_tetgen(base);
      ADD_FAILURE() << "no error";
    } catch (const IoError& e) {
      EXPECT_EQ(e.file(), base.string() + c.blamed_ext) << e.what();
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_NE(e.reason().find(c.reason_has), std::string::npos) << e.what();
    }
  }
}

TEST(TetgenRead, CrlfCorpusFileReads) {
  const fs::path base = fs::path(test::data_dir()) / "bad" / "tetgen" / "mixed_crlf";
  Mesh m = read_tetgen(base);
  EXPECT_EQ(m.node_count(), 5u);
  EXPECT_EQ(m.tet_count(), 2u);
  EXPECT_EQ(m.bface_count(), 2u);
  for (std::size_t t = 0; t < m.tet_count(); ++t) EXPECT_GT(det(m, t), 0);
}

// Every prefix of each file either reads or throws IoError: never a crash or another exception.
TEST(TetgenRead, TruncationSweepNeverCrashes) {
  TempDir dir;
  Mesh m = awkward_mesh();
  write_tetgen(m, dir / "a");
  const std::string node = test::read_text(dir / "a.node"), ele = test::read_text(dir / "a.ele"),
                    face = test::read_text(dir / "a.face");
  std::size_t ok = 0, failed = 0;
  auto attempt = [&](std::string_view n, std::string_view e, std::string_view f) {
    try {
      Mesh r = parse_tetgen(n, e, f, "cut");
      EXPECT_TRUE(check_sizes(r).empty());
      for (std::uint32_t i : r.tet) EXPECT_LT(i, r.node_count());
      ++ok;
    } catch (const IoError& err) {
      EXPECT_FALSE(err.reason().empty());
      ++failed;
    }
  };
  for (std::size_t k = 0; k < node.size(); ++k) attempt(std::string_view(node).substr(0, k), ele, face);
  for (std::size_t k = 0; k < ele.size(); ++k) attempt(node, std::string_view(ele).substr(0, k), face);
  for (std::size_t k = 1; k < face.size(); ++k) attempt(node, ele, std::string_view(face).substr(0, k));
  EXPECT_GT(failed, 0u);
  attempt(node, ele, face);
  EXPECT_GT(ok, 0u);
}

// Every byte replaced by a few troublesome characters: reads or throws IoError, indices in range.
TEST(TetgenRead, ByteMutationSweepNeverCrashes) {
  TempDir dir;
  write_tetgen(awkward_mesh(), dir / "a");
  std::string files[3] = {test::read_text(dir / "a.node"), test::read_text(dir / "a.ele"),
                          test::read_text(dir / "a.face")};
  const char subst[] = {'#', '\n', '\r', '-', '9', 'e', '.', ' ', '\0', 'x'};
  std::size_t failed = 0;
  for (int which = 0; which < 3; ++which) {
    for (std::size_t k = 0; k < files[which].size(); ++k) {
      for (char c : subst) {
        std::string f[3] = {files[0], files[1], files[2]};
        f[which][k] = c;
        try {
          Mesh r = parse_tetgen(f[0], f[1], f[2], "mut");
          ASSERT_TRUE(check_sizes(r).empty());
          for (std::uint32_t i : r.tet) ASSERT_LT(i, r.node_count());
          for (std::uint32_t i : r.bface) ASSERT_LT(i, r.node_count());
          for (double x : r.xyz) ASSERT_TRUE(std::isfinite(x));
        } catch (const IoError&) {
          ++failed;
        }
      }
    }
  }
  EXPECT_GT(failed, 0u);
}

TEST(TetgenWrite, FailedWriteLeavesNoFiles) {
  TempDir dir;
  // a.face is a folder holding a file: the last rename fails, and the .node and .ele must go too.
  fs::create_directories(dir / "a.face" / "x");
  EXPECT_THROW(write_tetgen(awkward_mesh(), dir / "a"), IoError);
  EXPECT_FALSE(fs::exists(dir / "a.node"));
  EXPECT_FALSE(fs::exists(dir / "a.ele"));
  std::size_t entries = 0;
  for (auto& e : fs::directory_iterator(dir.path())) (void)e, ++entries;
  EXPECT_EQ(entries, 1u);  // only the folder a.face
  // A folder that does not exist: nothing is written anywhere.
  EXPECT_THROW(write_tetgen(awkward_mesh(), dir / "no" / "such" / "a"), IoError);
}

TEST(TetgenWrite, RefusesInconsistentMesh) {
  TempDir dir;
  Mesh m = awkward_mesh();
  m.tet[5] = 1000;
  EXPECT_THROW(write_tetgen(m, dir / "a"), IoError);
  EXPECT_FALSE(fs::exists(dir / "a.node"));
}

}  // namespace
}  // namespace foxi
