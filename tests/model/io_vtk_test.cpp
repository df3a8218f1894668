// VTK .vtu and legacy .vtk: checked against files written by meshio (every encoding it has), by a
// small Python writer of the XML spec's appended layouts (raw/base64, zlib blocks, UInt32/UInt64
// headers, both byte orders), by gmsh (legacy .vtk), against meshio reading foxi's files, foxi's own
// round trips (bit for bit), and a corpus of malformed files plus truncation and byte-flip sweeps.
#include "foxi/model/io_vtk.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using Values = std::map<std::string, std::vector<double>>;

const char* kPython = "/usr/bin/python3";

bool have_meshio() {
  static const int ok = test::run(std::string(kPython) + " -c 'import meshio, numpy' > /dev/null 2>&1");
  return ok == 0;
}

// Runs a python script; its stdout lines "key|v1 v2 ..." become a map key -> values.
Values run_python(const TempDir& dir, const std::string& script, const std::string& args) {
  fs::path py = dir / "script.py", out = dir / "script.out";
  test::write_text(py, script);
  int rc = test::run(std::string(kPython) + " '" + py.string() + "' " + args + " > '" + out.string() +
                     "' 2> '" + (dir / "script.err").string() + "'");
  EXPECT_EQ(rc, 0) << test::read_text(dir / "script.err");
  Values v;
  std::istringstream in(test::read_text(out));
  std::string line;
  while (std::getline(in, line)) {
    std::size_t bar = line.find('|');
    if (bar == std::string::npos) continue;
    std::vector<double>& d = v[line.substr(0, bar)];
    std::istringstream vs(line.substr(bar + 1));
    std::string tok;
    while (vs >> tok) d.push_back(std::strtod(tok.c_str(), nullptr));
  }
  return v;
}

template <class T>
std::vector<double> as_doubles(const std::vector<T>& v) {
  return std::vector<double>(v.begin(), v.end());
}

// Exact (rel = 0) or relative comparison of two value lists.
void expect_values(const std::vector<double>& got, const std::vector<double>& want, double rel,
                   const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (rel == 0) {
      ASSERT_EQ(got[i], want[i]) << what << " [" << i << "]";
    } else {
      ASSERT_NEAR(got[i], want[i], rel * (1 + std::abs(want[i]))) << what << " [" << i << "]";
    }
  }
}

const Field* field(const Mesh& m, const std::string& name) {
  const Field* f = m.find_field(name);
  EXPECT_NE(f, nullptr) << "no field " << name;
  return f;
}

// The test mesh, made in Python: a jittered cube split into 6 tets, 3 triangles, 2 lines and a
// vertex, point data T (scalar), u (vector), ids (int), cell data gmsh:physical and stress (6).
constexpr const char* kMeshioScript = R"PY(
import sys, base64, zlib, numpy as np, meshio
d = sys.argv[1]
rng = np.random.default_rng(7)
pts = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)], float)
pts += rng.uniform(-0.1, 0.1, (8, 3))
pts = np.vstack([pts, [[0.5, 0.5, 1.5]]])
tets = np.array([[0,1,3,7],[0,1,5,7],[0,2,3,7],[0,2,6,7],[0,4,5,7],[0,4,6,7]])
tris = np.array([[0,1,3],[0,3,2],[4,5,7]])
lines = np.array([[0,1],[1,3]])
verts = np.array([[8]])
cells = [("tetra", tets), ("triangle", tris), ("line", lines), ("vertex", verts)]
T = rng.uniform(-1, 1, 9); U = rng.uniform(-1, 1, (9, 3)); ids = np.arange(9, dtype=np.int32) * 3
phys = [np.array([1,1,2,2,2,1], np.int32), np.array([11,12,13], np.int32),
        np.array([0,0], np.int32), np.array([0], np.int32)]
S = [rng.uniform(-1, 1, (len(c[1]), 6)) for c in cells]
def mk():
    return meshio.Mesh(pts, cells, point_data={"T": T, "u": U, "ids": ids},
                       cell_data={"gmsh:physical": phys, "stress": S})
meshio.write(f"{d}/ascii.vtu", mk(), binary=False)
meshio.write(f"{d}/b64.vtu", mk(), binary=True, compression=None)
meshio.write(f"{d}/zlib.vtu", mk(), binary=True, compression="zlib")
meshio.write(f"{d}/b64_u64.vtu", mk(), binary=True, compression=None, header_type="UInt64")
meshio.write(f"{d}/zlib_u64.vtu", mk(), binary=True, compression="zlib", header_type="UInt64")
meshio.write(f"{d}/v51_ascii.vtk", mk(), binary=False)
meshio.write(f"{d}/v51_bin.vtk", mk(), binary=True)
meshio.write(f"{d}/v42_ascii.vtk", mk(), file_format="vtk42", binary=False)
meshio.write(f"{d}/v42_bin.vtk", mk(), file_format="vtk42", binary=True)

# Appended layouts written here from the XML spec: Float32 points, Int64 connectivity, Int32
# offsets, UInt8 types, Int16 CellEntityIds, Float64 T, Float32 u.
ncell = 12
conn = np.concatenate([tets.ravel(), tris.ravel(), lines.ravel(), verts.ravel()])
offs = np.cumsum([4]*6 + [3]*3 + [2]*2 + [1])
types = np.array([10]*6 + [5]*3 + [3]*2 + [1], np.uint8)
reg = np.concatenate(phys).astype(np.int16)
def appended(path, enc, comp, htype, order, bs=20):
    h = np.dtype(htype.lower()).newbyteorder(order)
    arrays = [("Points", "Float32", 3, pts.astype(np.float32)), ("connectivity", "Int64", 1, conn.astype(np.int64)),
              ("offsets", "Int32", 1, offs.astype(np.int32)), ("types", "UInt8", 1, types),
              ("CellEntityIds", "Int16", 1, reg), ("T", "Float64", 1, T), ("u", "Float32", 3, U.astype(np.float32))]
    blob = b"" if enc == "raw" else ""
    tags = {}
    for name, t, nc, a in arrays:
        data = a.astype(a.dtype.newbyteorder(order)).tobytes()
        if comp:
            chunks = [data[i:i+bs] for i in range(0, len(data), bs)]
            z = [zlib.compress(c) for c in chunks]
            hdr = np.array([len(chunks), bs, len(chunks[-1])] + [len(c) for c in z], h).tobytes()
            parts = [hdr, b"".join(z)]
        else:
            parts = [np.array([len(data)], h).tobytes(), data]
        off = len(blob)
        if enc == "raw":
            blob += b"".join(parts)
        else:
            blob += "".join(base64.b64encode(p).decode() for p in parts)
        nca = f' NumberOfComponents="{nc}"' if nc != 1 else ""
        tags[name] = f'<DataArray type="{t}" Name="{name}"{nca} format="appended" offset="{off}"/>'
    x = (f'<?xml version="1.0"?>\r\n<VTKFile type="UnstructuredGrid" version="1.0" '
         f'byte_order="{"LittleEndian" if order == "<" else "BigEndian"}" header_type="{htype}"'
         + (' compressor="vtkZLibDataCompressor"' if comp else "") + '>\n<UnstructuredGrid>\n'
         f'<Piece NumberOfPoints="9" NumberOfCells="{ncell}">\n<Points>{tags["Points"]}</Points>\r\n'
         f'<Cells>{tags["connectivity"]}{tags["offsets"]}{tags["types"]}</Cells>\n'
         f'<PointData>{tags["T"]}{tags["u"]}</PointData><CellData>{tags["CellEntityIds"]}</CellData>\n'
         f'</Piece>\n</UnstructuredGrid>\n<AppendedData encoding="{enc}">\n_')
    with open(path, "wb") as f:
        f.write(x.encode())
        f.write(blob if enc == "raw" else blob.encode())
        f.write(b"\n</AppendedData>\n</VTKFile>\n")
appended(f"{d}/app_raw.vtu", "raw", False, "UInt32", "<")
appended(f"{d}/app_raw_be.vtu", "raw", False, "UInt64", ">")
appended(f"{d}/app_b64.vtu", "base64", False, "UInt32", "<")
appended(f"{d}/app_zraw.vtu", "raw", True, "UInt64", "<")
appended(f"{d}/app_zraw_be.vtu", "raw", True, "UInt32", ">")
appended(f"{d}/app_zb64.vtu", "base64", True, "UInt32", "<")

def out(k, a): print(k + "|" + " ".join(repr(float(x)) for x in np.asarray(a).reshape(-1)))
out("points", pts); out("points32", pts.astype(np.float32)); out("tets", tets); out("tris", tris)
out("region", phys[0]); out("tags", phys[1]); out("T", T); out("u", U); out("u32", U.astype(np.float32))
out("ids", ids); out("stress", S[0])
)PY";

struct Oracle {
  TempDir dir;
  Values v;
};

const Oracle& meshio_files() {
  static Oracle* o = [] {
    auto* x = new Oracle;
    x->v = run_python(x->dir, kMeshioScript, "'" + x->dir.path().string() + "'");
    return x;
  }();
  return *o;
}

void expect_test_mesh(const Mesh& m, const Values& v, double rel, bool with_ids_and_stress,
                      const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(m.node_count(), 9u);
  EXPECT_EQ(m.tet_count(), 6u);
  EXPECT_EQ(m.bface_count(), 3u);
  expect_values(m.xyz, v.at("points"), rel, "points");
  expect_values(as_doubles(m.tet), v.at("tets"), 0, "tets");
  expect_values(as_doubles(m.bface), v.at("tris"), 0, "triangles");
  expect_values(as_doubles(m.tet_region), v.at("region"), 0, "region");
  expect_values(as_doubles(m.bface_tag), v.at("tags"), 0, "boundary tags");
  ASSERT_EQ(m.regions.size(), 2u);
  EXPECT_EQ(m.regions[0].id, 1);
  EXPECT_EQ(m.regions[1].id, 2);
  EXPECT_EQ(m.boundaries.size(), 3u);
  if (const Field* f = field(m, "T")) {
    EXPECT_EQ(f->location, FieldLocation::node);
    expect_values(f->values, v.at("T"), rel, "T");
  }
  if (const Field* f = field(m, "u")) {
    EXPECT_EQ(f->components, 3u);
    expect_values(f->values, v.at("u"), rel, "u");
  }
  if (with_ids_and_stress) {
    if (const Field* f = field(m, "ids")) expect_values(f->values, v.at("ids"), 0, "ids");
    if (const Field* f = field(m, "stress")) {
      EXPECT_EQ(f->location, FieldLocation::cell);
      EXPECT_EQ(f->components, 6u);
      expect_values(f->values, v.at("stress"), rel, "stress (tet cells only)");
    }
    EXPECT_EQ(m.fields.size(), 4u);
  }
  EXPECT_EQ(check_sizes(m), "");
}

TEST(VtuRead, MeshioEveryEncoding) {
  if (!have_meshio()) GTEST_SKIP() << "no meshio";
  const Oracle& o = meshio_files();
  for (const char* name : {"b64.vtu", "zlib.vtu", "b64_u64.vtu", "zlib_u64.vtu"})
    expect_test_mesh(read_vtu(o.dir / name), o.v, 0, true, name);
  // meshio's ASCII writes 12 significant digits.
  expect_test_mesh(read_vtu(o.dir / "ascii.vtu"), o.v, 1e-11, true, "ascii.vtu");
}

TEST(VtuRead, AppendedLayoutsFromTheSpec) {
  if (!have_meshio()) GTEST_SKIP() << "no meshio";
  const Oracle& o = meshio_files();
  Values v = o.v;
  v["points"] = v["points32"];
  v["u"] = v["u32"];
  for (const char* name :
       {"app_raw.vtu", "app_raw_be.vtu", "app_b64.vtu", "app_zraw.vtu", "app_zraw_be.vtu", "app_zb64.vtu"}) {
    Mesh m = read_vtu(o.dir / name);
    expect_test_mesh(m, v, 0, false, name);
    EXPECT_EQ(m.fields.size(), 2u) << name;
  }
}

TEST(VtkLegacyRead, MeshioAsciiAndBinary51And42) {
  if (!have_meshio()) GTEST_SKIP() << "no meshio";
  const Oracle& o = meshio_files();
  for (const char* name : {"v51_bin.vtk", "v42_bin.vtk"})
    expect_test_mesh(read_vtk_legacy(o.dir / name), o.v, 0, true, name);
  for (const char* name : {"v51_ascii.vtk", "v42_ascii.vtk"})
    expect_test_mesh(read_vtk_legacy(o.dir / name), o.v, 1e-15, true, name);
}

// meshio writes quadratic tets (VTK 24) and triangles (22); foxi reads their corners.
TEST(VtuRead, QuadraticCellsReadAsCorners) {
  if (!have_meshio()) GTEST_SKIP() << "no meshio";
  TempDir dir;
  const std::string script = R"(
import sys, meshio, numpy as np
c = np.array([[0,0,0],[2,0,0],[0,3,0],[0,0,4]], dtype=float)
e = [(0,1),(1,2),(2,0),(0,3),(1,3),(2,3)]  # VTK's mid-edge order
pts = np.vstack([c] + [0.5 * (c[a] + c[b]) for a, b in e])
m = meshio.Mesh(pts, [("tetra10", np.array([list(range(10))])), ("triangle6", np.array([[0, 1, 2, 4, 5, 6]]))])
d = sys.argv[1]
meshio.write(d + "/q.vtu", m)
meshio.write(d + "/q.vtk", m, binary=True)
print("corners|", " ".join(repr(x) for x in c.flatten()))
)";
  Values want = run_python(dir, script, "'" + dir.path().string() + "'");
  ASSERT_EQ(want["corners"].size(), 12u);
  for (const char* name : {"q.vtu", "q.vtk"}) {
    SCOPED_TRACE(name);
    const Mesh m = read_mesh(dir / name);
    ASSERT_EQ(m.tet_count(), 1u);
    ASSERT_EQ(m.bface_count(), 1u);
    EXPECT_EQ(m.node_count(), 10u);  // the mid-edge points stay, unused
    std::vector<double> corners;
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) corners.push_back(m.xyz[3 * m.tet[k] + j]);
    EXPECT_EQ(corners, want["corners"]);
    EXPECT_EQ(std::vector<std::uint32_t>(m.bface.begin(), m.bface.end()),
              (std::vector<std::uint32_t>{0, 1, 2}));
  }
}

TEST(VtuRead, MultiplePiecesConcatenate) {
  // Two pieces, local numbering each; the second piece's indices are shifted by the first's nodes.
  // The first piece's points carry an InformationKey child, as ParaView writes them.
  std::string piece1 =
      "<Piece NumberOfPoints=\"4\" NumberOfCells=\"2\"><Points><DataArray type=\"Float64\" "
      "NumberOfComponents=\"3\" format=\"ascii\" RangeMin=\"0\" RangeMax=\"1\">\n"
      "<InformationKey name=\"L2_NORM_RANGE\" location=\"vtkDataArray\" length=\"2\">"
      "<Value index=\"0\">\n0\n</Value><Value index=\"1\">\n1\n</Value></InformationKey>\n"
      "0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points>"
      "<Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 0 1 2"
      "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4 7</DataArray>"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10 5</DataArray></Cells>"
      "<PointData><DataArray type=\"Float32\" Name=\"p\" format=\"ascii\">1 2 3 4</DataArray>"
      "</PointData><CellData><DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">7 3"
      "</DataArray></CellData></Piece>\n";
  std::string piece2 =
      "<Piece NumberOfPoints=\"5\" NumberOfCells=\"2\"><Points><DataArray type=\"Float64\" "
      "NumberOfComponents=\"3\" format=\"ascii\">5 0 0 6 0 0 5 1 0 5 0 1 9 9 9</DataArray></Points>"
      "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">4 0 1 2 3"
      "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">1 5</DataArray>"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">1 10</DataArray></Cells>"
      "<PointData><DataArray type=\"Float32\" Name=\"p\" format=\"ascii\">5 6 7 8 9</DataArray>"
      "</PointData><CellData><DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">0 8"
      "</DataArray></CellData></Piece>\n";
  std::string text = "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>\r\n" + piece1 + piece2 +
                     "</UnstructuredGrid></VTKFile>\n";
  Mesh m = parse_vtu(text, "pieces.vtu");
  ASSERT_EQ(m.node_count(), 9u);
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(m.bface, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(m.tet_region, (std::vector<std::int32_t>{7, 8}));
  EXPECT_EQ(m.bface_tag, (std::vector<std::int32_t>{3}));
  ASSERT_NE(m.find_field("p"), nullptr);
  EXPECT_EQ(m.find_field("p")->values, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(m.xyz[3 * 8], 9.0);
}

// A mesh with every kind of data foxi keeps.
Mesh rich_mesh() {
  Mesh m = bench::kuhn_grid_mesh(2, 0.2, 3);
  m.regions[0].name = "lower part";
  m.regions[1].name = "up;per=&<\"";
  m.boundaries[0].name = "inlet";
  // Two regions of one material (a name that needs escaping, one property not set); a third region,
  // if any, without one.
  Material cu;
  cu.name = "copper|OFHC; 99%=";
  cu.thermal_conductivity = 401;
  cu.electrical_conductivity = 5.8e7;
  cu.youngs_modulus = 1.1e11;
  cu.poisson_ratio = 0.34;
  cu.thermal_expansion = 1.7e-5 / 3;  // not a short decimal
  cu.density = 8960;                  // specific_heat left unset
  m.materials = {cu};
  m.regions[0].material = 0;
  m.regions[1].material = 0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  Field t{"temperature", FieldLocation::node, 1, "K", {0.0, 0.5, 1.25}, {}};
  t.values.resize(3 * m.node_count());
  for (double& x : t.values) x = u(rng);
  t.values[5] = 1e-310;  // subnormal
  t.values[6] = -0.0;
  Field v{"flux", FieldLocation::cell, 3, "W/m^2", {}, {}};
  v.values.resize(3 * m.tet_count());
  for (double& x : v.values) x = u(rng) / 7;
  Field s{"stress tensor", FieldLocation::cell, 6, "Pa", {}, {}};
  s.values.resize(6 * m.tet_count());
  for (double& x : s.values) x = u(rng) * 1e6 / 3;
  m.fields = {t, v, s};
  m.weight.resize(m.node_count());
  for (double& w : m.weight) w = u(rng) * 1e-6;
  return m;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * 8) == 0);
}

void expect_same_mesh(const Mesh& a, const Mesh& b, bool names) {
  EXPECT_TRUE(same_bits(a.xyz, b.xyz));
  EXPECT_EQ(a.tet, b.tet);
  EXPECT_EQ(a.tet_region, b.tet_region);
  EXPECT_EQ(a.bface, b.bface);
  EXPECT_EQ(a.bface_tag, b.bface_tag);
  EXPECT_TRUE(same_bits(a.weight, b.weight));
  ASSERT_EQ(a.regions.size(), b.regions.size());
  for (std::size_t i = 0; i < a.regions.size(); ++i) {
    EXPECT_EQ(a.regions[i].id, b.regions[i].id);
    if (names) {
      EXPECT_EQ(a.regions[i].name, b.regions[i].name);
      // The same material (as a value: the reader numbers them in the order it meets them).
      const bool has = a.regions[i].material < a.materials.size();
      ASSERT_EQ(has, b.regions[i].material < b.materials.size()) << "region " << a.regions[i].id;
      if (!has) continue;
      const Material &x = a.materials[a.regions[i].material], &y = b.materials[b.regions[i].material];
      EXPECT_EQ(x.name, y.name);
      EXPECT_TRUE(
          same_bits({x.thermal_conductivity, x.electrical_conductivity, x.relative_permittivity,
                     x.youngs_modulus, x.poisson_ratio, x.thermal_expansion, x.density, x.specific_heat},
                    {y.thermal_conductivity, y.electrical_conductivity, y.relative_permittivity,
                     y.youngs_modulus, y.poisson_ratio, y.thermal_expansion, y.density, y.specific_heat}));
    }
  }
  if (names) {
    EXPECT_EQ(a.materials.size(), b.materials.size());  // regions of one material share it
  }
  ASSERT_EQ(a.boundaries.size(), b.boundaries.size());
  for (std::size_t i = 0; i < a.boundaries.size(); ++i) {
    EXPECT_EQ(a.boundaries[i].tag, b.boundaries[i].tag);
    if (names) {
      EXPECT_EQ(a.boundaries[i].name, b.boundaries[i].name);
    }
  }
  ASSERT_EQ(a.fields.size(), b.fields.size());
  for (std::size_t i = 0; i < a.fields.size(); ++i) {
    const Field &x = a.fields[i], &y = b.fields[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.location, y.location);
    EXPECT_EQ(x.components, y.components);
    EXPECT_EQ(x.step_count(), y.step_count());
    EXPECT_TRUE(same_bits(x.values, y.values)) << x.name;
    if (names) {
      EXPECT_EQ(x.unit, y.unit);
      EXPECT_TRUE(same_bits(x.step_values, y.step_values)) << x.name;
    }
  }
}

TEST(VtuWrite, RoundTripEveryEncodingBitForBit) {
  TempDir dir;
  Mesh m = rich_mesh();
  for (VtuEncoding e :
       {VtuEncoding::ascii, VtuEncoding::base64, VtuEncoding::appended_raw, VtuEncoding::zlib}) {
    SCOPED_TRACE(static_cast<int>(e));
    fs::path p = dir / ("rt" + std::to_string(static_cast<int>(e)) + ".vtu");
    write_vtu(m, p, e);
    Mesh r = read_vtu(p);
    expect_same_mesh(m, r, true);
  }
  // Nothing but the files themselves is left (no temporaries).
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 4);
}

TEST(VtuWrite, EmptyAndBareMeshesRoundTrip) {
  TempDir dir;
  Mesh empty;
  Mesh bare;  // one tet, no regions, no boundary, no fields
  bare.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  bare.tet = {0, 1, 2, 3};
  for (const Mesh* m : {&empty, &bare}) {
    for (VtuEncoding e :
         {VtuEncoding::ascii, VtuEncoding::base64, VtuEncoding::appended_raw, VtuEncoding::zlib}) {
      write_vtu(*m, dir / "m.vtu", e);
      Mesh r = read_vtu(dir / "m.vtu");
      expect_same_mesh(*m, r, true);
      EXPECT_TRUE(r.tet_region.empty());
    }
    for (bool binary : {false, true}) {
      write_vtk_legacy(*m, dir / "m.vtk", binary);
      expect_same_mesh(*m, read_vtk_legacy(dir / "m.vtk"), true);
    }
  }
}

TEST(VtkLegacyWrite, RoundTripAsciiAndBinaryBitForBit) {
  TempDir dir;
  Mesh m = rich_mesh();
  for (bool binary : {false, true}) {
    fs::path p = dir / (binary ? "b.vtk" : "a.vtk");
    write_vtk_legacy(m, p, binary);
    Mesh r = read_vtk_legacy(p);
    expect_same_mesh(m, r, false);
    // Legacy keeps no step values: steps are numbered.
    ASSERT_FALSE(r.fields.empty());
    EXPECT_EQ(r.fields[0].step_values, (std::vector<double>{0, 1, 2}));
  }
}

// A field without a name wrote "SCALARS" lines no reader takes back (an outside probe): the legacy
// writer refuses it, naming the field, and writes nothing; .vtu keeps it.
TEST(VtkLegacyWrite, FieldWithoutANameIsRefused) {
  TempDir dir;
  Mesh m = rich_mesh();
  ASSERT_FALSE(m.fields.empty());
  m.fields[0].name.clear();
  try {
    write_vtk_legacy(m, dir / "n.vtk", false);
    ADD_FAILURE() << "written";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("field 1 has no name"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "n.vtk"));
  write_vtu(m, dir / "n.vtu");
  EXPECT_EQ(read_vtu(dir / "n.vtu").fields.size(), m.fields.size());
}

// VTK's own legacy reader (python3-vtk9, what ParaView uses) reads foxi's ASCII file whole: the
// boundary triangles' rows of a cell field were written "nan", at which VTK's ASCII reader stopped
// and lost every array after it (an outside probe). They are 0 in ASCII now (NaN in binary).
TEST(VtkLegacyWrite, VtksReaderReadsTheAsciiFileWhole) {
  TempDir dir;
  Mesh m = rich_mesh();
  ASSERT_GT(m.bface_count(), 0u);
  write_vtk_legacy(m, dir / "a.vtk", false);
  EXPECT_EQ(test::read_text(dir / "a.vtk").find("nan"), std::string::npos);
  if (test::run(std::string(kPython) + " -c 'import vtk' > /dev/null 2>&1") == 0) {
    const Values v = run_python(dir, R"PY(
import sys, vtk
r = vtk.vtkUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update(); g = r.GetOutput()
print("counts|%d %d %d %d" % (g.GetNumberOfPoints(), g.GetNumberOfCells(), g.GetPointData().GetNumberOfArrays(),
                              g.GetCellData().GetNumberOfArrays()))
)PY",
                                "'" + (dir / "a.vtk").string() + "'");
    ASSERT_EQ(v.count("counts"), 1u);
    const std::vector<double>& c = v.at("counts");
    EXPECT_EQ(c[0], double(m.node_count()));
    EXPECT_EQ(c[1], double(m.tet_count() + m.bface_count()));
    std::size_t point_arrays = m.weight.empty() ? 0 : 1, cell_arrays = 1;  // region
    for (const Field& f : m.fields)
      (f.location == FieldLocation::cell ? cell_arrays : point_arrays) += f.step_count();
    EXPECT_EQ(c[2], double(point_arrays));
    EXPECT_EQ(c[3], double(cell_arrays));
  }
  // A field's own NaN (an imported field's "no value") is written "nan" and read back by foxi.
  Mesh holes = m;
  holes.fields[0].values[0] = std::nan("");
  write_vtk_legacy(holes, dir / "h.vtk", false);
  EXPECT_TRUE(std::isnan(read_vtk_legacy(dir / "h.vtk").fields[0].values[0]));
}

// meshio reads foxi's files: every point/cell array compared value for value.
constexpr const char* kMeshioReadScript = R"PY(
import sys, numpy as np, meshio
for path in sys.argv[1:]:
    m = meshio.read(path)
    tag = path.rsplit("/", 1)[-1]
    def out(k, a): print(tag + " " + k + "|" + " ".join(repr(float(x)) for x in np.asarray(a).reshape(-1)))
    out("points", m.points)
    for i, c in enumerate(m.cells):
        out("cells " + c.type, c.data)
        for name, d in m.cell_data.items():
            out("cd " + name + " " + c.type, d[i])
    for name, d in m.point_data.items():
        out("pd " + name, d)
)PY";

void expect_meshio_sees(const Values& v, const std::string& tag, const Mesh& m) {
  SCOPED_TRACE(tag);
  auto at = [&](const std::string& k) -> const std::vector<double>& {
    static const std::vector<double> none;
    auto it = v.find(tag + " " + k);
    EXPECT_NE(it, v.end()) << "meshio has no " << k;
    return it == v.end() ? none : it->second;
  };
  expect_values(at("points"), m.xyz, 0, "points");
  expect_values(at("cells tetra"), as_doubles(m.tet), 0, "tetra");
  expect_values(at("cells triangle"), as_doubles(m.bface), 0, "triangle");
  expect_values(at("cd region tetra"), as_doubles(m.tet_region), 0, "region");
  expect_values(at("cd region triangle"), as_doubles(m.bface_tag), 0, "tags");
  if (!m.weight.empty()) expect_values(at("pd weight"), m.weight, 0, "weight");
  for (const Field& f : m.fields) {
    const std::size_t ne = field_entity_count(m, f);
    for (std::size_t s = 0; s < f.step_count(); ++s) {
      std::string name = s == 0 ? f.name : f.name + "@" + std::to_string(s + 1);
      // meshio's legacy reader keeps the spaces encoded as %20.
      std::string key = f.location == FieldLocation::node ? "pd " + name : "cd " + name + " tetra";
      if (v.find(tag + " " + key) == v.end()) {
        std::string enc;
        for (char c : name) enc += c == ' ' ? std::string("%20") : std::string(1, c);
        key = f.location == FieldLocation::node ? "pd " + enc : "cd " + enc + " tetra";
      }
      auto sp = f.step(s, ne);
      expect_values(at(key), std::vector<double>(sp.begin(), sp.end()), 0, name);
    }
  }
}

// Many small arrays of various component counts (zlib appended data of rich_mesh() is the case
// where meshio's offset renumbering mixed up arrays before foxi stored the blocks in reverse).
Mesh small_arrays_mesh() {
  Mesh m = bench::kuhn_grid_mesh(1, 0.1, 4);
  std::uint32_t comps[] = {1, 3, 6, 2, 5, 1, 9};
  for (std::size_t i = 0; i < std::size(comps); ++i) {
    bool cell = i % 2 == 1;
    Field f{"f" + std::to_string(i), cell ? FieldLocation::cell : FieldLocation::node, comps[i], "", {}, {}};
    f.values.resize(comps[i] * (cell ? m.tet_count() : m.node_count()));
    for (std::size_t k = 0; k < f.values.size(); ++k)
      f.values[k] = static_cast<double>(k) * 0.25 - static_cast<double>(i);
    m.fields.push_back(f);
  }
  return m;
}

TEST(VtuWrite, MeshioReadsFoxiFiles) {
  if (!have_meshio()) GTEST_SKIP() << "no meshio";
  TempDir dir;
  const Mesh meshes[] = {rich_mesh(), small_arrays_mesh()};
  const char* names[] = {"ascii.vtu", "base64.vtu", "raw.vtu", "zlib.vtu"};
  std::string args;
  for (int k = 0; k < 2; ++k) {
    const std::string pre = std::to_string(k);
    int i = 0;
    for (VtuEncoding e :
         {VtuEncoding::ascii, VtuEncoding::base64, VtuEncoding::appended_raw, VtuEncoding::zlib}) {
      write_vtu(meshes[k], dir / (pre + names[i]), e);
      args += " '" + (dir / (pre + names[i])).string() + "'";
      ++i;
    }
    write_vtk_legacy(meshes[k], dir / (pre + "a.vtk"), false);
    write_vtk_legacy(meshes[k], dir / (pre + "b.vtk"), true);
    args += " '" + (dir / (pre + "a.vtk")).string() + "' '" + (dir / (pre + "b.vtk")).string() + "'";
  }
  Values v = run_python(dir, kMeshioReadScript, args);
  for (int k = 0; k < 2; ++k) {
    const std::string pre = std::to_string(k);
    for (const char* n : names) expect_meshio_sees(v, pre + n, meshes[k]);
    expect_meshio_sees(v, pre + "a.vtk", meshes[k]);
    expect_meshio_sees(v, pre + "b.vtk", meshes[k]);
  }
}

TEST(VtkLegacyRead, GmshWrittenFiles) {
  if (!test::have_program("gmsh") || !have_meshio()) GTEST_SKIP() << "no gmsh or meshio";
  TempDir dir;
  test::write_text(dir / "box.geo",
                   "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 1, 2, 0.5};\n"
                   "Mesh.CharacteristicLengthMax = 0.3;\n");
  ASSERT_EQ(
      test::run("cd '" + dir.path().string() + "' && gmsh -3 box.geo -format vtk -o a.vtk", dir / "gmsh.log"),
      0);
  ASSERT_EQ(test::run("cd '" + dir.path().string() + "' && gmsh -3 box.geo -format vtk -bin -o b.vtk",
                      dir / "gmsh2.log"),
            0);
  Values v = run_python(dir, R"PY(
import sys, numpy as np, meshio
for p in sys.argv[1:]:
    m = meshio.read(p)
    t = p.rsplit("/", 1)[-1]
    tet = np.concatenate([c.data for c in m.cells if c.type == "tetra"])
    tri = np.concatenate([c.data for c in m.cells if c.type == "triangle"])
    print(t + " n|", len(m.points), len(tet), len(tri))
    print(t + " points|" + " ".join(repr(float(x)) for x in m.points.ravel()))
    print(t + " tets|" + " ".join(str(int(x)) for x in tet.ravel()))
    print(t + " tris|" + " ".join(str(int(x)) for x in tri.ravel()))
)PY",
                        "'" + (dir / "a.vtk").string() + "' '" + (dir / "b.vtk").string() + "'");
  for (const char* name : {"a.vtk", "b.vtk"}) {
    SCOPED_TRACE(name);
    Mesh m = read_mesh(dir / name);
    const auto& n = v.at(std::string(name) + " n");
    ASSERT_EQ(n.size(), 3u);
    EXPECT_GT(n[1], 50);
    EXPECT_EQ(m.node_count(), n[0]);
    EXPECT_EQ(m.tet_count(), n[1]);
    EXPECT_EQ(m.bface_count(), n[2]);
    expect_values(m.xyz, v.at(std::string(name) + " points"), 0, "points");
    expect_values(as_doubles(m.tet), v.at(std::string(name) + " tets"), 0, "tets");
    expect_values(as_doubles(m.bface), v.at(std::string(name) + " tris"), 0, "tris");
    // The tets fill the box: volume 1.
    double vol = 0;
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      const double* p[4];
      for (int k = 0; k < 4; ++k) p[k] = &m.xyz[3 * m.tet[4 * t + static_cast<std::size_t>(k)]];
      double a[3], b[3], c[3];
      for (int d = 0; d < 3; ++d) {
        a[d] = p[1][d] - p[0][d];
        b[d] = p[2][d] - p[0][d];
        c[d] = p[3][d] - p[0][d];
      }
      vol += std::abs(a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                      a[2] * (b[0] * c[1] - b[1] * c[0])) /
             6;
    }
    EXPECT_NEAR(vol, 1.0, 1e-9);
  }
}

// ------------------------------------------------------------------------------------------------
// Malformed input.

void expect_io_error(const std::function<void()>& f, const std::string& what,
                     const std::string& reason_part = "") {
  try {
    f();
    ADD_FAILURE() << what << ": no IoError";
  } catch (const IoError& e) {
    EXPECT_FALSE(e.file().empty()) << what;
    EXPECT_FALSE(e.reason().empty()) << what;
    EXPECT_TRUE(e.line() != 0 || e.byte_offset() != IoError::kNoOffset ||
                e.reason().find("piece") != std::string::npos || e.reason().find("cell") != std::string::npos)
        << what << ": " << e.what();
    if (!reason_part.empty()) {
      EXPECT_NE(e.reason().find(reason_part), std::string::npos) << what << ": " << e.what();
    }
  }
}

TEST(VtkBadInput, CorpusRejectedWithLocationAndReason) {
  // tests/data/bad/{vtu,vtk}/expect.txt: "file|part of the reason" per line.
  int checked = 0;
  for (const char* sub : {"vtu", "vtk"}) {
    fs::path d = fs::path(test::data_dir()) / "bad" / sub;
    std::istringstream in(test::read_text(d / "expect.txt"));
    std::string line;
    while (std::getline(in, line)) {
      std::size_t bar = line.find('|');
      if (bar == std::string::npos) continue;
      std::string name = line.substr(0, bar), part = line.substr(bar + 1);
      fs::path p = d / name;
      ASSERT_TRUE(fs::exists(p)) << p;
      expect_io_error([&] { read_mesh(p); }, name, part);
      ++checked;
    }
  }
  EXPECT_GE(checked, 20);
}

TEST(VtkBadInput, MixedLineEndingsRead) {
  std::string text =
      "# vtk DataFile Version 4.2\r\ntitle\rASCII\nDATASET UNSTRUCTURED_GRID\r\nPOINTS 4 float\r"
      "0 0 0\n1 0 0\r\n0 1 0\r0 0 1\nCELLS 1 5\r\n4 0 1 2 3\rCELL_TYPES 1\n10\r\n";
  Mesh m = parse_vtk_legacy(text, "mixed.vtk");
  EXPECT_EQ(m.tet, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(m.xyz[3 * 3 + 2], 1.0);
}

TEST(VtkBadInput, NanCoordinatesAreAcceptedForValidation) {
  std::string text =
      "# vtk DataFile Version 4.2\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n"
      "nan 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";
  Mesh m = parse_vtk_legacy(text, "nan.vtk");
  EXPECT_TRUE(std::isnan(m.xyz[0]));
}

std::string small_file(VtuEncoding e, const TempDir& dir) {
  Mesh m = bench::kuhn_grid_mesh(1, 0.1, 2);
  Field f{"f", FieldLocation::node, 1, "", {1, 2}, std::vector<double>(16, 0.5)};
  m.fields.push_back(f);
  fs::path p = dir / "small.vtu";
  write_vtu(m, p, e);
  return test::read_text(p);
}

TEST(VtkBadInput, TruncationSweepNeverCrashes) {
  TempDir dir;
  for (VtuEncoding e :
       {VtuEncoding::ascii, VtuEncoding::base64, VtuEncoding::appended_raw, VtuEncoding::zlib}) {
    std::string full = small_file(e, dir);
    ASSERT_NO_THROW(parse_vtu(full, "full.vtu"));
    const std::size_t closing = full.rfind("</VTKFile>");
    for (std::size_t n = 0; n < closing + 10; ++n) {
      std::string cut = full.substr(0, n);  // own buffer: ASan sees reads past the end
      expect_io_error([&] { parse_vtu(cut, "cut.vtu"); }, "vtu prefix " + std::to_string(n));
    }
  }
  Mesh m = bench::kuhn_grid_mesh(1, 0.1, 2);
  for (bool binary : {false, true}) {
    write_vtk_legacy(m, dir / "s.vtk", binary);
    std::string full = test::read_text(dir / "s.vtk");
    for (std::size_t n = 0; n < full.size(); ++n) {
      std::string cut = full.substr(0, n);
      try {
        Mesh r = parse_vtk_legacy(cut, "cut.vtk");
        EXPECT_EQ(check_sizes(r), "");  // a cut at a section boundary can still be a valid file
      } catch (const IoError&) {
      }
    }
  }
}

TEST(VtkBadInput, ByteFlipsNeverCrash) {
  TempDir dir;
  std::mt19937 rng(11);
  auto flip_sweep = [&](const std::string& full, auto&& parse) {
    for (int i = 0; i < 1000; ++i) {
      std::string s = full;
      for (int k = 0; k < 3; ++k) s[rng() % s.size()] = static_cast<char>(rng());
      try {
        Mesh r = parse(s);
        EXPECT_EQ(check_sizes(r), "");
        for (std::uint32_t v : r.tet) ASSERT_LT(v, r.node_count());
        for (std::uint32_t v : r.bface) ASSERT_LT(v, r.node_count());
      } catch (const IoError&) {
      }
    }
  };
  for (VtuEncoding e :
       {VtuEncoding::ascii, VtuEncoding::base64, VtuEncoding::appended_raw, VtuEncoding::zlib})
    flip_sweep(small_file(e, dir), [](const std::string& s) { return parse_vtu(s, "flip.vtu"); });
  Mesh m = bench::kuhn_grid_mesh(1, 0.1, 2);
  m.fields.push_back({"f", FieldLocation::node, 3, "", {}, std::vector<double>(24, 0.5)});
  for (bool binary : {false, true}) {
    write_vtk_legacy(m, dir / "s.vtk", binary);
    flip_sweep(test::read_text(dir / "s.vtk"),
               [](const std::string& s) { return parse_vtk_legacy(s, "flip.vtk"); });
  }
}

}  // namespace
}  // namespace foxi
