// Fields written by other programs: meshio (.vtu, legacy .vtk, Gmsh 2.2 .msh) and gmsh itself (its
// 4.1 .msh of a view). Oracle: the values those programs were given, printed by the script with 17
// significant digits; foxi must read the same numbers (bit for bit where the format is binary or
// prints 17 digits, to gmsh's 16 printed digits otherwise).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "foxi/fields.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

const char* kScript = R"PY(
import sys, numpy as np, meshio
out = sys.argv[1]
rng = np.random.default_rng(5)
n = 4
g = np.linspace(0.0, 1.0, n + 1)
pts = np.array([[x, y, z] for z in g for y in g for x in g])
idx = lambda i, j, k: (k * (n + 1) + j) * (n + 1) + i
tets = []
for k in range(n):
    for j in range(n):
        for i in range(n):
            c = [idx(i + (a & 1), j + ((a >> 1) & 1), k + ((a >> 2) & 1)) for a in range(8)]
            for p in [(1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)]:
                t = [c[0], c[p[0]], c[p[1]], c[7]]
                a, b, cc, d = pts[t]
                if np.linalg.det(np.array([b - a, cc - a, d - a])) < 0:
                    t[1], t[2] = t[2], t[1]
                tets.append(t)
tets = np.array(tets)
f = 1 + 2 * pts[:, 0] - 3 * pts[:, 1] + 0.5 * pts[:, 2] + rng.random(len(pts)) / 3
v = rng.random((len(pts), 3)) * 1e-3
c = rng.random(len(tets)) * 7
m = meshio.Mesh(pts, [("tetra", tets)], point_data={"f": f, "v": v}, cell_data={"c": [c]})
meshio.write(out + "/meshio.vtu", m)
meshio.write(out + "/meshio.vtk", m, binary=True)
meshio.write(out + "/meshio.msh", meshio.Mesh(pts, [("tetra", tets)], point_data={"f": f}), file_format="gmsh22", binary=False)
np.savetxt(out + "/f.txt", f, fmt="%.17g")
np.savetxt(out + "/v.txt", v.reshape(-1), fmt="%.17g")
np.savetxt(out + "/c.txt", c, fmt="%.17g")
)PY";

std::vector<double> read_numbers(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

class ExternalFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    if (test::run("/usr/bin/python3 -c 'import meshio, numpy' > /dev/null 2>&1") != 0)
      GTEST_SKIP() << "python3 with meshio and numpy not installed";
    test::write_text(dir_ / "make.py", kScript);
    ASSERT_EQ(
        test::run("/usr/bin/python3 '" + (dir_ / "make.py").string() + "' '" + dir_.path().string() + "'",
                  dir_ / "py.log"),
        0)
        << test::read_text(dir_ / "py.log");
    f_ = read_numbers(dir_ / "f.txt");
    v_ = read_numbers(dir_ / "v.txt");
    c_ = read_numbers(dir_ / "c.txt");
    ASSERT_EQ(f_.size(), 125u);
  }
  test::TempDir dir_;
  std::vector<double> f_, v_, c_;
};

TEST_F(ExternalFiles, MeshioVtuVtkAndMshHoldWhatMeshioWrote) {
  for (const char* name : {"meshio.vtu", "meshio.vtk", "meshio.msh"}) {
    SCOPED_TRACE(name);
    const FieldSource s = read_field_source(dir_ / name);
    ASSERT_EQ(s.mesh.node_count(), 125u);
    ASSERT_EQ(s.mesh.tet_count(), 384u);
    const Field* f = s.mesh.find_field("f");
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(f->values, f_);  // binary doubles, or 17 digits: the same bits
    if (std::string(name) == "meshio.msh") continue;
    const Field* v = s.mesh.find_field("v");
    const Field* c = s.mesh.find_field("c");
    ASSERT_NE(v, nullptr);
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(v->components, 3u);
    EXPECT_EQ(v->values, v_);
    EXPECT_EQ(c->location, FieldLocation::cell);
    EXPECT_EQ(c->values, c_);
  }
}

TEST_F(ExternalFiles, GmshWrittenViewHoldsTheValues) {
  if (!test::have_program("gmsh")) GTEST_SKIP() << "gmsh not installed";
  // gmsh loads meshio's file and writes the view itself, as .msh 4.1 with the mesh ($NodeData).
  test::write_text(dir_ / "resave.geo",
                   "Merge \"meshio.msh\";\nPostProcessing.SaveMesh = 1;\n"
                   "Mesh.MshFileVersion = 4.1;\nSave View[0] \"gmsh.msh\";\n");
  ASSERT_EQ(test::run("cd '" + dir_.path().string() + "' && gmsh -0 resave.geo", dir_ / "gmsh.log"), 0)
      << test::read_text(dir_ / "gmsh.log");
  ASSERT_NE(test::read_text(dir_ / "gmsh.msh").find("$NodeData"), std::string::npos);
  const FieldSource s = read_field_source(dir_ / "gmsh.msh");
  ASSERT_EQ(s.mesh.fields.size(), 1u);
  const Field& f = s.mesh.fields[0];
  ASSERT_EQ(f.values.size(), f_.size());
  // gmsh may renumber nodes: compare by position, through a transfer by location onto meshio's mesh.
  const FieldSource m = read_field_source(dir_ / "meshio.vtu");
  TransferParams p;
  p.names = {f.name};
  const TransferReport rep = transfer_fields(s, m.mesh, p);
  EXPECT_EQ(rep.nodes_outside, 0u);
  for (std::size_t i = 0; i < f_.size(); ++i)
    EXPECT_NEAR(rep.fields[0].values[i], f_[i], 1e-14 * std::abs(f_[i]) + 1e-14);
}

}  // namespace
}  // namespace foxi
