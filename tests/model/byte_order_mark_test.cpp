// A UTF-8 byte order mark before a text mesh file (an editor's, a spreadsheet's): the .msh, .vtk,
// .mesh and .node readers refused such files (an outside probe), while .vtu and .csv took them. Each
// text format foxi writes, with the mark put in front, reads back as the file without it does.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/mesh_io.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

void expect_same(const Mesh& a, const Mesh& b, const std::string& what) {
  EXPECT_EQ(a.xyz, b.xyz) << what;
  EXPECT_EQ(a.tet, b.tet) << what;
  EXPECT_EQ(a.tet_region, b.tet_region) << what;
  EXPECT_EQ(a.bface, b.bface) << what;
  EXPECT_EQ(a.bface_tag, b.bface_tag) << what;
}

TEST(ByteOrderMark, TextMeshFilesReadWithAMarkInFront) {
  test::TempDir dir;
  const Mesh m = bench::kuhn_grid_mesh(2, 0.25, 4);
  const std::string mark = "\xEF\xBB\xBF";
  for (const char* name : {"m.msh", "m.vtk", "m.mesh", "m.vtu"}) {
    const std::filesystem::path plain = dir / name, marked = dir / (std::string("bom_") + name);
    write_mesh(m, plain);
    test::write_text(marked, mark + test::read_text(plain));
    expect_same(read_mesh(marked), read_mesh(plain), name);
  }
  write_tetgen(m, dir / "t");
  const Mesh plain = read_tetgen(dir / "t");
  for (const char* suffix : {".node", ".ele", ".face"})
    test::write_text(dir / (std::string("t") + suffix),
                     mark + test::read_text(dir / (std::string("t") + suffix)));
  expect_same(read_tetgen(dir / "t"), plain, "tetgen");
}

}  // namespace
}  // namespace foxi
