// Tests of the Gmsh .msh reader and writer. Oracles: the gmsh program (meshes it generates, files it
// re-saves from ours), meshio (an independent .msh reader, run with /usr/bin/python3), analytic
// volumes, and hand-written files.
#include "foxi/model/io_gmsh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/io_error.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

const char* kPython = "/usr/bin/python3";

bool have_gmsh() { return test::have_program("gmsh"); }
bool have_meshio() { return test::run(std::string(kPython) + " -c 'import meshio' > /dev/null 2>&1") == 0; }

// Two unit boxes side by side, physical volumes 10 "left" and 20 "right", physical surfaces 5
// "bottom" (z = 0) and 6 "top" (z = 1).
const char* kTwoBoxes = R"(SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 1,1,1};
Box(2) = {1,0,0, 1,1,1};
Coherence;
Physical Volume("left", 10) = {1};
Physical Volume("right", 20) = {2};
Physical Surface("bottom", 5) = {Surface In BoundingBox{-0.1,-0.1,-0.1, 2.1,1.1,0.1}};
Physical Surface("top", 6) = {Surface In BoundingBox{-0.1,-0.1,0.9, 2.1,1.1,1.1}};
Mesh.MeshSizeMax = 0.3;
)";

double tet_volume(const Mesh& m, std::size_t t) {
  const double* a = &m.xyz[3 * m.tet[4 * t]];
  const double* b = &m.xyz[3 * m.tet[4 * t + 1]];
  const double* c = &m.xyz[3 * m.tet[4 * t + 2]];
  const double* d = &m.xyz[3 * m.tet[4 * t + 3]];
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = d[k] - a[k];
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6.0;
}

// Counts and volumes as meshio reports them for each file (one python run: meshio loads slowly),
// "key value" lines per file, keys prefixed with the file's position.
std::vector<std::map<std::string, double>> meshio_summary(const std::vector<fs::path>& files,
                                                          const TempDir& dir) {
  const fs::path script = dir / "summary.py";
  test::write_text(script, R"(import sys, meshio, numpy as np
for f in sys.argv[1:]:
  m = meshio.read(f)
  print("file 0")
  print("nodes", len(m.points))
  tets = 0; tris = 0; vol = {}
  for i, block in enumerate(m.cells):
    if block.type == "tetra":
      tets += len(block.data)
      phys = m.cell_data["gmsh:physical"][i]
      p = m.points[block.data]
      v = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0])) / 6
      for r in np.unique(phys):
        vol[int(r)] = vol.get(int(r), 0.0) + float(v[phys == r].sum())
    if block.type == "triangle":
      tris += len(block.data)
  print("tets", tets)
  print("triangles", tris)
  for r, v in vol.items():
    print("volume%d" % r, repr(v))
)");
  const fs::path out = dir / "summary.txt";
  std::string cmd = std::string(kPython) + " '" + script.string() + "'";
  for (const fs::path& f : files) cmd += " '" + f.string() + "'";
  EXPECT_EQ(test::run(cmd, out), 0) << test::read_text(out);
  std::vector<std::map<std::string, double>> r;
  std::istringstream in(test::read_text(out));
  std::string key;
  double value;
  while (in >> key >> value) {
    if (key == "file")
      r.emplace_back();
    else if (!r.empty())
      r.back()[key] = value;
  }
  r.resize(files.size());
  return r;
}

struct Variant {
  int version;
  bool binary;
  const char* gmsh_format;
};
const Variant kVariants[] = {
    {22, false, "msh22"}, {22, true, "msh22"}, {41, false, "msh41"}, {41, true, "msh41"}};

std::string label(const Variant& v) { return std::to_string(v.version) + (v.binary ? " binary" : " ascii"); }

TEST(GmshRead, GmshGeneratedFilesMatchMeshioAndGeometry) {
  if (!have_gmsh() || !have_meshio()) GTEST_SKIP() << "gmsh or meshio not available";
  TempDir dir;
  test::write_text(dir / "two.geo", kTwoBoxes);
  // Mesh once, then let gmsh save the same mesh in each variant.
  ASSERT_EQ(test::run("gmsh -3 '" + (dir / "two.geo").string() + "' -format msh41 -o '" +
                          (dir / "base.msh").string() + "'",
                      dir / "gmsh.log"),
            0);
  std::vector<fs::path> files;
  for (const Variant& v : kVariants) {
    files.push_back(dir / ("two_" + std::to_string(v.version) + (v.binary ? "b" : "a") + ".msh"));
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Variant& v = kVariants[i];
    const fs::path& file = files[i];
    ASSERT_EQ(test::run("gmsh -nopopup '" + (dir / "base.msh").string() + "' -save -format " + v.gmsh_format +
                            (v.binary ? " -bin" : "") + " -o '" + file.string() + "'",
                        dir / "gmsh.log"),
              0);
  }
  const std::vector<std::map<std::string, double>> refs = meshio_summary(files, dir);
  for (std::size_t i = 0; i < files.size(); ++i) {
    const Variant& v = kVariants[i];
    const fs::path& file = files[i];
    SCOPED_TRACE(label(v));
    // The header says which variant gmsh wrote.
    const std::string text = test::read_text(file);
    ASSERT_NE(text.find(std::string(v.version == 22 ? "2.2 " : "4.1 ") + (v.binary ? "1 8" : "0 8")),
              std::string::npos);

    const Mesh m = read_gmsh(file);
    EXPECT_EQ(check_sizes(m), "");
    std::map<std::string, double> ref = refs[i];
    ASSERT_GT(ref["tets"], 100);
    EXPECT_EQ(static_cast<double>(m.node_count()), ref["nodes"]);
    EXPECT_EQ(static_cast<double>(m.tet_count()), ref["tets"]);
    EXPECT_EQ(static_cast<double>(m.bface_count()), ref["triangles"]);

    // Regions 10 and 20 with their names, each a unit box; every tet positively oriented.
    ASSERT_EQ(m.regions.size(), 2u);
    EXPECT_EQ(m.regions[0].id, 10);
    EXPECT_EQ(m.regions[0].name, "left");
    EXPECT_EQ(m.regions[1].id, 20);
    EXPECT_EQ(m.regions[1].name, "right");
    std::map<int, double> vol;
    std::size_t inverted = 0;
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      double w = tet_volume(m, t);
      inverted += w <= 0;
      vol[m.region_of(t)] += w;
    }
    EXPECT_EQ(inverted, 0u);
    EXPECT_NEAR(vol[10], 1.0, 1e-12);
    EXPECT_NEAR(vol[20], 1.0, 1e-12);
    EXPECT_NEAR(vol[10], ref["volume10"], 1e-12);
    EXPECT_NEAR(vol[20], ref["volume20"], 1e-12);

    // Boundaries: bottom (z = 0) and top (z = 1), area 2 each.
    ASSERT_EQ(m.boundaries.size(), 2u);
    EXPECT_EQ(m.boundaries[0].tag, 5);
    EXPECT_EQ(m.boundaries[0].name, "bottom");
    EXPECT_EQ(m.boundaries[1].tag, 6);
    EXPECT_EQ(m.boundaries[1].name, "top");
    std::map<int, double> area;
    for (std::size_t f = 0; f < m.bface_count(); ++f) {
      const double* a = &m.xyz[3 * m.bface[3 * f]];
      const double* b = &m.xyz[3 * m.bface[3 * f + 1]];
      const double* c = &m.xyz[3 * m.bface[3 * f + 2]];
      const double z = m.bface_tag[f] == 5 ? 0.0 : 1.0;
      EXPECT_EQ(a[2], z);
      EXPECT_EQ(b[2], z);
      EXPECT_EQ(c[2], z);
      area[m.bface_tag[f]] += std::abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) / 2;
    }
    EXPECT_NEAR(area[5], 2.0, 1e-12);
    EXPECT_NEAR(area[6], 2.0, 1e-12);
  }
}

// gmsh can store parametric coordinates after the xyz of nodes on curves and surfaces (4.1): the
// same mesh (gmsh meshes deterministically) read with and without them must be the same.
TEST(GmshRead, ParametricNodesMatchPlainFile) {
  if (!have_gmsh()) GTEST_SKIP() << "gmsh not available";
  TempDir dir;
  test::write_text(dir / "two.geo", kTwoBoxes);
  const std::string geo = "'" + (dir / "two.geo").string() + "'";
  for (const char* bin : {"", " -bin"}) {
    SCOPED_TRACE(bin);
    const std::string plain_file = (dir / "plain.msh").string(), par_file = (dir / "par.msh").string();
    ASSERT_EQ(test::run("gmsh -3 " + geo + " -format msh41" + bin + " -o '" + plain_file + "'", dir / "log"),
              0);
    ASSERT_EQ(test::run("gmsh -3 " + geo + " -save_parametric -format msh41" + bin + " -o '" + par_file + "'",
                        dir / "log"),
              0);
    if (*bin == 0) {
      const std::string text = test::read_text(par_file);
      ASSERT_NE(text.find("\n2 1 1 "), std::string::npos) << "gmsh wrote no parametric surface block";
    }
    const Mesh plain = read_gmsh(plain_file);
    ASSERT_GT(plain.tet_count(), 100u);
    const Mesh m = read_gmsh(par_file);
    EXPECT_TRUE(m.xyz == plain.xyz);
    EXPECT_EQ(m.tet, plain.tet);
    EXPECT_EQ(m.tet_region, plain.tet_region);
    EXPECT_EQ(m.bface, plain.bface);
  }
}

// A surface in two physical groups ("bottom", and "outer" with all six sides): gmsh's 4.1 file lists
// both tags on the surface's entity, and its 2.2 file repeats the triangles once per group. Both read
// alike: every group holds all its triangles (the 4.1 reader kept the entity's first tag only, and
// "outer" lost the bottom's 90 of its 540 triangles; an outside probe).
TEST(GmshRead, SurfaceInTwoPhysicalGroupsIsInBoth) {
  if (!have_gmsh()) GTEST_SKIP() << "gmsh not available";
  TempDir dir;
  test::write_text(dir / "g.geo", R"(SetFactory("OpenCASCADE");
Box(1) = {0,0,0, 1,1,1};
Physical Volume("v", 1) = {1};
Physical Surface("bottom", 10) = {5};
Physical Surface("outer", 11) = {1, 2, 3, 4, 5, 6};
Mesh.CharacteristicLengthMax = 0.3;
)");
  std::map<std::string, std::map<std::int32_t, std::size_t>> count;  // variant -> tag -> triangles
  for (const char* variant : {"msh22", "msh41", "msh41 -bin"}) {
    const std::string file = (dir / "g.msh").string();
    ASSERT_EQ(
        test::run("gmsh -3 '" + (dir / "g.geo").string() + "' -format " + variant + " -o '" + file + "'",
                  dir / "log"),
        0);
    const Mesh m = read_gmsh(file);
    for (std::int32_t tag : m.bface_tag) ++count[variant][tag];
  }
  EXPECT_GT(count["msh22"][10], 0u);
  EXPECT_GT(count["msh22"][11], count["msh22"][10]);
  EXPECT_EQ(count["msh41"], count["msh22"]);
  EXPECT_EQ(count["msh41 -bin"], count["msh22"]);
}

// gmsh's second-order meshes (10-node tets, 6-node triangles) read as their corners: the same tets
// and triangles as gmsh's first-order mesh of the same geometry, in all four file variants.
TEST(GmshRead, SecondOrderElementsReadAsCorners) {
  if (!have_gmsh()) GTEST_SKIP() << "gmsh not available";
  TempDir dir;
  test::write_text(dir / "two.geo", kTwoBoxes);
  const std::string geo = "'" + (dir / "two.geo").string() + "'";
  const std::string first = (dir / "p1.msh").string();
  ASSERT_EQ(test::run("gmsh -3 " + geo + " -format msh41 -o '" + first + "'", dir / "log"), 0);
  const Mesh p1 = read_gmsh(first);
  for (const char* variant : {"msh41", "msh41 -bin", "msh22", "msh22 -bin"}) {
    SCOPED_TRACE(variant);
    const std::string file = (dir / "p2.msh").string();
    ASSERT_EQ(
        test::run("gmsh -3 -order 2 " + geo + " -format " + variant + " -o '" + file + "'", dir / "log"), 0);
    const std::string text = test::read_text(file);
    const Mesh m = read_gmsh(file);
    EXPECT_EQ(m.tet_count(), p1.tet_count());
    EXPECT_EQ(m.bface_count(), p1.bface_count());
    EXPECT_EQ(m.tet_region, p1.tet_region);
    EXPECT_GT(m.node_count(), p1.node_count());  // the mid-edge nodes, unused
    double volume = 0;
    for (std::size_t t = 0; t < m.tet_count(); ++t) volume += tet_volume(m, t);
    EXPECT_NEAR(volume, 2.0, 1e-9);  // two unit boxes, flat faces: the corner tets fill them
  }
}

// A small two-region grid with fields: a node scalar with 2 steps (one value NaN = not listed),
// a 3-component cell vector and a 6-component cell tensor.
Mesh mesh_with_fields() {
  Mesh m = bench::kuhn_grid_mesh(3);
  m.tet_region[5] = 7;  // a third region, interleaved, with no name
  m.regions.push_back({0, "unused region", kNone});
  const std::size_t nn = m.node_count(), nt = m.tet_count();
  Field s{"temperature", FieldLocation::node, 1, "K", {0.0, 0.25}, {}};
  for (std::size_t st = 0; st < 2; ++st)
    for (std::size_t i = 0; i < nn; ++i)
      s.values.push_back(std::sin(1.0 + static_cast<double>(i) + 0.1 * static_cast<double>(st)) * 1e3);
  s.values[3] = std::numeric_limits<double>::quiet_NaN();
  Field v{"velocity", FieldLocation::cell, 3, "", {1.5}, {}};
  for (std::size_t i = 0; i < 3 * nt; ++i) v.values.push_back(std::cos(0.3 * static_cast<double>(i)) / 7);
  Field t{"stress", FieldLocation::cell, 6, "", {}, {}};
  for (std::size_t i = 0; i < 6 * nt; ++i)
    t.values.push_back(std::exp(-0.01 * static_cast<double>(i)) * 1e-9);
  m.fields = {s, v, t};
  return m;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::isnan(a[i]) && std::isnan(b[i])) continue;
    if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0) return false;
  }
  return true;
}

TEST(GmshWrite, RoundTripAllVariantsBitExact) {
  const Mesh m = mesh_with_fields();
  TempDir dir;
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(label(v));
    const fs::path file = dir / "rt.msh";
    write_gmsh(m, file, {v.version, v.binary});
    const Mesh r = read_gmsh(file);
    EXPECT_EQ(check_sizes(r), "");
    EXPECT_TRUE(same_bits(r.xyz, m.xyz));
    EXPECT_EQ(r.tet, m.tet);
    EXPECT_EQ(r.tet_region, m.tet_region);
    EXPECT_EQ(r.bface, m.bface);
    EXPECT_EQ(r.bface_tag, m.bface_tag);
    ASSERT_EQ(r.regions.size(), 3u);  // ids present in tets: 1, 2, 7 (region 0 has no tets)
    EXPECT_EQ(r.find_region(1)->name, "lower");
    EXPECT_EQ(r.find_region(2)->name, "upper");
    EXPECT_EQ(r.find_region(7)->name, "");
    ASSERT_EQ(r.boundaries.size(), 6u);
    for (const Boundary& b : m.boundaries) EXPECT_EQ(r.find_boundary(b.tag)->name, b.name);
    ASSERT_EQ(r.fields.size(), 3u);
    for (const Field& f : m.fields) {
      const Field* g = r.find_field(f.name);
      ASSERT_NE(g, nullptr) << f.name;
      EXPECT_EQ(g->location, f.location);
      EXPECT_EQ(g->components, f.components);
      EXPECT_EQ(g->step_count(), f.step_count());
      EXPECT_TRUE(same_bits(g->values, f.values)) << f.name;
    }
    EXPECT_EQ(r.find_field("temperature")->step_values, (std::vector<double>{0.0, 0.25}));
    EXPECT_TRUE(std::isnan(r.find_field("temperature")->values[3]));
  }
}

// Counts nodes and tets of an ASCII .msh 2.2 file (a parser independent of foxi's).
void count_msh22(const std::string& text, std::size_t* nodes, std::size_t* tets) {
  std::istringstream in(text);
  std::string line;
  *nodes = *tets = 0;
  while (std::getline(in, line)) {
    if (line.rfind("$Nodes", 0) == 0) {
      std::getline(in, line);
      *nodes = std::stoul(line);
    } else if (line.rfind("$Elements", 0) == 0) {
      std::getline(in, line);
      std::size_t n = std::stoul(line);
      for (std::size_t i = 0; i < n && std::getline(in, line); ++i) {
        std::istringstream l(line);
        int num, type;
        l >> num >> type;
        *tets += type == 4;
      }
    }
  }
}

TEST(GmshWrite, GmshLoadsFoxiFiles) {
  if (!have_gmsh()) GTEST_SKIP() << "gmsh not available";
  const Mesh m = mesh_with_fields();
  TempDir dir;
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(label(v));
    const fs::path file = dir / "foxi.msh", out = dir / "gmsh.msh", log = dir / "gmsh.log";
    fs::remove(out);
    write_gmsh(m, file, {v.version, v.binary});
    EXPECT_EQ(test::run("gmsh -nopopup '" + file.string() + "' -save_all -save -format msh22 -o '" +
                            out.string() + "'",
                        log),
              0);
    const std::string log_text = test::read_text(log);
    EXPECT_EQ(log_text.find("Error"), std::string::npos) << log_text;
    std::size_t nodes = 0, tets = 0;
    count_msh22(test::read_text(out), &nodes, &tets);
    EXPECT_EQ(nodes, m.node_count());
    EXPECT_EQ(tets, m.tet_count());

    // gmsh also loads the fields as views: the temperature (2 steps) with the same extreme values.
    const fs::path geo = dir / "views.geo";
    test::write_text(geo,
                     "Merge \"" + file.string() +
                         "\";\nPrintf(\"views %g steps %g min %.17g max %.17g\", PostProcessing.NbViews, "
                         "View[0].NbTimeStep, View[0].Min, View[0].Max);\n");
    EXPECT_EQ(test::run("gmsh -nopopup '" + geo.string() + "' -parse_and_exit", log), 0);
    const std::string views = test::read_text(log);
    const std::size_t at = views.find("views ");
    ASSERT_NE(at, std::string::npos) << views;
    std::istringstream in(views.substr(at));
    std::string w1, w2, w3, w4;
    double nviews = 0, steps = 0, lo = 0, hi = 0;
    in >> w1 >> nviews >> w2 >> steps >> w3 >> lo >> w4 >> hi;
    EXPECT_EQ(nviews, 3);
    EXPECT_EQ(steps, 2);
    double want_lo = INFINITY, want_hi = -INFINITY;
    for (double x : m.fields[0].values) {
      if (std::isnan(x)) continue;
      want_lo = std::min(want_lo, x);
      want_hi = std::max(want_hi, x);
    }
    EXPECT_EQ(lo, want_lo);
    EXPECT_EQ(hi, want_hi);
  }
}

TEST(GmshRead, MeshioWrittenFieldsMatch) {
  if (!have_meshio()) GTEST_SKIP() << "meshio not available";
  TempDir dir;
  // Two tets sharing a face; node field x + 2y + 3z, cell vector (i, 10 i, 100 i) for cell i; written
  // by meshio in 2.2 and 4.1, ASCII and binary (one python run).
  test::write_text(dir / "write.py", R"(import sys, meshio, numpy as np
p = np.array([[0,0,0],[1,0,0],[0,1,0],[0,0,1],[1,1,1]], float)
c = [('tetra', np.array([[0,1,2,3],[1,2,3,4]]))]
m = meshio.Mesh(p, c, point_data={'lin': p @ [1.0, 2.0, 3.0]},
  cell_data={'vec': [np.array([[1.0,10,100],[2,20,200]])],
  'gmsh:physical': [np.array([3, 4])], 'gmsh:geometrical': [np.array([1, 2])]})
for fmt in ['gmsh22', 'gmsh']:
  for binary in [False, True]:
    meshio.write(sys.argv[1] + '/%s_%d.msh' % (fmt, binary), m, file_format=fmt, binary=binary)
)");
  ASSERT_EQ(
      test::run(std::string(kPython) + " '" + (dir / "write.py").string() + "' '" + dir.path().string() + "'",
                dir / "py.log"),
      0)
      << test::read_text(dir / "py.log");
  for (const char* fmt : {"gmsh22", "gmsh"}) {
    for (int binary : {0, 1}) {
      SCOPED_TRACE(std::string(fmt) + (binary ? " binary" : " ascii"));
      const Mesh m = read_gmsh(dir / (std::string(fmt) + "_" + std::to_string(binary) + ".msh"));
      ASSERT_EQ(m.node_count(), 5u);
      ASSERT_EQ(m.tet_count(), 2u);
      // 2.2 carries the physical tag per element; meshio's 4.1 has no $Entities: region 0.
      const bool v22 = std::string(fmt) == "gmsh22";
      EXPECT_EQ(m.region_of(0), v22 ? 3 : 0);
      EXPECT_EQ(m.region_of(1), v22 ? 4 : 0);
      const Field* lin = m.find_field("lin");
      ASSERT_NE(lin, nullptr);
      EXPECT_EQ(lin->location, FieldLocation::node);
      ASSERT_EQ(lin->values.size(), 5u);
      for (std::size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(lin->values[i], m.xyz[3 * i] + 2 * m.xyz[3 * i + 1] + 3 * m.xyz[3 * i + 2]);
      }
      const Field* vec = m.find_field("vec");
      ASSERT_NE(vec, nullptr);
      EXPECT_EQ(vec->location, FieldLocation::cell);
      EXPECT_EQ(vec->components, 3u);
      EXPECT_EQ(vec->values, (std::vector<double>{1, 10, 100, 2, 20, 200}));
    }
  }
}

const char* kSparse22 = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
1
3 4 "solid"
$EndPhysicalNames
$Comments
anything $Nodes here is skipped
$EndComments
$Nodes
5
100 0 0 0
7 1 0 0
30 0 1 0
2000 0 0 1
5 1 1 1
$EndNodes
$Elements
4
9 15 2 0 1 7
10 1 2 0 1 7 30
11 4 2 4 1 100 7 30 2000
12 4 2 4 1 7 30 5 2000
$EndElements
$NodeData
1
"t"
1
0.5
3
0
1
2
2000 4.5
7 -1
$EndNodeData
)";

TEST(GmshRead, SparseNodeTags22) {
  const Mesh m = parse_gmsh(kSparse22, "sparse22.msh");
  ASSERT_EQ(m.node_count(), 5u);
  ASSERT_EQ(m.tet_count(), 2u);
  // Dense indices in file order: 100->0, 7->1, 30->2, 2000->3, 5->4.
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3, 1, 2, 4, 3}));
  EXPECT_EQ(m.bface_count(), 0u);  // points and lines are skipped
  EXPECT_NEAR(tet_volume(m, 0), 1.0 / 6, 1e-15);
  ASSERT_EQ(m.regions.size(), 1u);
  EXPECT_EQ(m.regions[0].name, "solid");
  const Field* f = m.find_field("t");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->step_values, std::vector<double>{0.5});
  EXPECT_EQ(f->values[3], 4.5);
  EXPECT_EQ(f->values[1], -1);
  EXPECT_TRUE(std::isnan(f->values[0]));
}

const char* kSparse41 = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 0 1 2
3 0 0 0 1 1 0 1 9 0
1 0 0 0 1 1 1 1 11 1 3
2 0 0 0 1 1 1 0 0
$EndEntities
$Nodes
2 5 7 1000000000000
3 1 0 3
1000000000000
7
30
0 0 0
1 0 0
0 1 0
3 2 0 2
2000
9
0 0 1
1 1 1
$EndNodes
$Elements
3 4 1 4
2 3 2 1
1 1000000000000 7 30
3 1 4 2
2 1000000000000 7 30 2000
3 7 30 9 2000
3 2 15 1
4 9
$EndElements
$ElementData
1
"e"
0
3
0
1
3
3 30.5
1 -2
2 20.5
$EndElementData
)";

// One physical tag named twice, differently (an outside probe: the last name won in silence): refused
// at the second name's line. The same name twice is read.
TEST(GmshRead, PhysicalTagNamedTwiceIsRefused) {
  std::string twice = kSparse22;
  const std::string names = "1\n3 4 \"solid\"\n";
  twice.replace(twice.find(names), names.size(), "2\n3 4 \"solid\"\n3 4 \"other\"\n");
  try {
    parse_gmsh(twice, "twice.msh");
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 7u) << e.what();
    EXPECT_NE(std::string(e.what()).find("physical volume 4 is named twice: 'solid' and 'other'"),
              std::string::npos)
        << e.what();
  }
  std::string same = kSparse22;
  same.replace(same.find(names), names.size(), "2\n3 4 \"solid\"\n3 4 \"solid\"\n");
  EXPECT_EQ(parse_gmsh(same, "same.msh").tet_count(), 2u);
}

TEST(GmshRead, SparseNodeTags41) {
  const Mesh m = parse_gmsh(kSparse41, "sparse41.msh");
  ASSERT_EQ(m.node_count(), 5u);
  ASSERT_EQ(m.tet_count(), 2u);
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3, 1, 2, 4, 3}));
  EXPECT_NEAR(tet_volume(m, 0), 1.0 / 6, 1e-15);
  EXPECT_EQ(m.tet_region, (std::vector<std::int32_t>{11, 11}));  // volume entity 1 -> physical 11
  ASSERT_EQ(m.bface_count(), 1u);
  EXPECT_EQ(m.bface_tag[0], 9);  // surface entity 3 -> physical 9
  const Field* f = m.find_field("e");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->location, FieldLocation::cell);
  EXPECT_EQ(f->values, (std::vector<double>{20.5, 30.5}));  // element 1 is the triangle: ignored
}

// Every file of the corpus of broken files must fail with an IoError naming the file, a place in
// it, and the reason; files named *.accepted.msh must be read.
TEST(GmshRead, BadCorpusGivesLocatedErrors) {
  const fs::path corpus = fs::path(test::data_dir()) / "bad" / "gmsh";
  const std::map<std::string, std::string> reasons = {
      {"truncated.msh", "unexpected end of file"},
      {"wrong_node_count.msh", "expected node tag, found '$EndNodes'"},
      {"huge_count.msh", "declares 1000000000000 nodes but the file has only"},
      {"node_out_of_range.msh", "node 7, which is not defined"},
      {"non_numeric.msh", "expected y coordinate, found 'abc'"},
      {"unknown_element_type.msh", "unsupported element type 5 (8-node hexahedron)"},
      {"empty.msh", "empty file"},
      {"wrong_endianness_flag.msh", "bad endianness check"},
      {"byte_swapped.msh", "byte-swapped"},
      {"binary_truncated.msh", "file ends inside"},
      {"wrong_element_count_41.msh", "header declares 2 elements but the blocks hold 1"},
      // Found by fuzzing: a binary 4.1 node block of 0 nodes passed null pointers to memcpy
      // (UBSan; the replay test fuzz.gmsh runs it under the sanitizers).
      {"empty_node_block_binary.msh", "expected '$EndNodes', found"},
  };
  std::size_t seen = 0;
  for (const auto& entry : fs::directory_iterator(corpus)) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    if (name.find(".accepted.") != std::string::npos) continue;
    ++seen;
    auto it = reasons.find(name);
    ASSERT_NE(it, reasons.end()) << "corpus file without an expected reason";
    try {
      read_gmsh(entry.path());
      ADD_FAILURE() << "no error";
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(entry.path().string()), std::string::npos) << what;
      EXPECT_TRUE(e.line() > 0 || e.byte_offset() != IoError::kNoOffset) << what;
      EXPECT_NE(what.find(it->second), std::string::npos) << what;
    }
  }
  EXPECT_EQ(seen, reasons.size());
}

TEST(GmshRead, ErrorLinesPointAtTheProblem) {
  const fs::path corpus = fs::path(test::data_dir()) / "bad" / "gmsh";
  try {
    read_gmsh(corpus / "non_numeric.msh");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 7u);  // "2 1 abc 0"
  }
  try {
    read_gmsh(corpus / "unknown_element_type.msh");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.line(), 13u);  // the element line
  }
}

TEST(GmshRead, MixedLineEndingsRead) {
  const fs::path file = fs::path(test::data_dir()) / "bad" / "gmsh" / "crlf_mixed.accepted.msh";
  const std::string text = test::read_text(file);
  ASSERT_NE(text.find("\r\n"), std::string::npos) << "the corpus file lost its CR LF line ends";
  ASSERT_NE(text.find("0\n"), std::string::npos);
  const Mesh m = read_gmsh(file);
  EXPECT_EQ(m.node_count(), 4u);
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_NEAR(tet_volume(m, 0), 1.0 / 6, 1e-15);
}

TEST(GmshRead, NanCoordinateIsLeftToValidation) {
  const Mesh m = read_gmsh(fs::path(test::data_dir()) / "bad" / "gmsh" / "nan_coordinate.accepted.msh");
  ASSERT_EQ(m.node_count(), 4u);
  EXPECT_TRUE(std::isnan(m.xyz[7]));
  EXPECT_EQ(m.xyz[6], 0.0);
}

TEST(GmshWrite, InconsistentMeshLeavesNoFile) {
  Mesh m = bench::kuhn_grid_mesh(1);
  TempDir dir;
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(label(v));
    // Drop the last node: the tets then name a node that does not exist.
    Mesh fewer = m;
    fewer.xyz.resize(fewer.xyz.size() - 3);
    EXPECT_THROW(write_gmsh(fewer, dir / "b.msh", {v.version, v.binary}), IoError);
    EXPECT_FALSE(fs::exists(dir / "b.msh"));  // a failed write leaves nothing behind
  }
}

// Cuts valid files at many lengths: each prefix gives an IoError or a consistent mesh, never a crash
// (run under ASan: the prefix is copied to a buffer of exactly its size).
TEST(GmshRead, TruncationSweep) {
  Mesh m = bench::kuhn_grid_mesh(1);
  Field f{"f", FieldLocation::node, 1, "", {0.0}, {}};
  for (std::size_t i = 0; i < m.node_count(); ++i) f.values.push_back(0.5 * static_cast<double>(i));
  m.fields.push_back(f);
  TempDir dir;
  std::vector<std::string> files;
  for (const Variant& v : kVariants) {
    write_gmsh(m, dir / "a.msh", {v.version, v.binary});
    files.push_back(test::read_text(dir / "a.msh"));
  }
  files.push_back(kSparse22);
  files.push_back(kSparse41);
  std::size_t errors = 0, meshes = 0;
  for (const std::string& full : files) {
    for (std::size_t len = 0; len <= full.size(); ++len) {
      std::unique_ptr<char[]> buf(new char[len + 1]);
      std::memcpy(buf.get(), full.data(), len);
      try {
        Mesh r = parse_gmsh(std::string_view(buf.get(), len), "cut.msh");
        ++meshes;
        EXPECT_EQ(check_sizes(r), "");
        for (std::uint32_t v : r.tet) ASSERT_LT(v, r.node_count());
        for (std::uint32_t v : r.bface) ASSERT_LT(v, r.node_count());
      } catch (const IoError& e) {
        ++errors;
        EXPECT_EQ(e.file(), "cut.msh");
      }
    }
  }
  EXPECT_GT(errors, 1000u);
  EXPECT_GT(meshes, 0u);  // the full files at least
}

// Random byte corruptions of valid files (fixed seed): IoError or a consistent mesh, never a crash.
TEST(GmshRead, RandomCorruptionNeverCrashes) {
  Mesh m = bench::kuhn_grid_mesh(1);
  Field f{"f", FieldLocation::cell, 3, "", {0.0}, {}};
  for (std::size_t i = 0; i < 3 * m.tet_count(); ++i) f.values.push_back(0.25 * static_cast<double>(i));
  m.fields.push_back(f);
  TempDir dir;
  std::mt19937 rng(7);
  std::size_t errors = 0;
  for (const Variant& v : kVariants) {
    write_gmsh(m, dir / "a.msh", {v.version, v.binary});
    const std::string full = test::read_text(dir / "a.msh");
    for (int trial = 0; trial < 500; ++trial) {
      std::string bytes = full;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) {
        const char pool[] = "0123456789 -+.e\n$x";
        char c = rng() % 2 ? static_cast<char>(rng()) : pool[rng() % (sizeof pool - 1)];
        bytes[rng() % bytes.size()] = c;
      }
      std::unique_ptr<char[]> buf(new char[bytes.size()]);
      std::memcpy(buf.get(), bytes.data(), bytes.size());
      try {
        Mesh r = parse_gmsh(std::string_view(buf.get(), bytes.size()), "mutated.msh");
        EXPECT_EQ(check_sizes(r), "");
        for (std::uint32_t x : r.tet) ASSERT_LT(x, r.node_count());
        for (std::uint32_t x : r.bface) ASSERT_LT(x, r.node_count());
      } catch (const IoError&) {
        ++errors;
      }
    }
  }
  EXPECT_GT(errors, 400u);
}

TEST(GmshRead, HugeCountsInBinaryAreRejectedBeforeAllocating) {
  Mesh m = bench::kuhn_grid_mesh(1);
  TempDir dir;
  write_gmsh(m, dir / "a.msh", {41, true});
  std::string bytes = test::read_text(dir / "a.msh");
  // The $Nodes header of 4.1 binary: 4 size_t after "$Nodes\n"; set numNodes to 10^12.
  const std::size_t at = bytes.find("$Nodes\n") + 7 + 8;
  const std::uint64_t huge = 1000000000000ull;
  std::memcpy(&bytes[at], &huge, 8);
  try {
    parse_gmsh(bytes, "huge.msh");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.byte_offset(), at);
    EXPECT_NE(std::string(e.what()).find("declares 1000000000000 nodes"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace foxi
