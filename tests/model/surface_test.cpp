// STL reading (surface.hpp): ASCII and binary files written here must give the same merged surface,
// and broken files must fail with the file and the line (ASCII) or byte offset (binary).
#include "foxi/model/surface.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <limits>
#include <string>

#include "foxi/model/io_error.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;

// A tetrahedron in ASCII STL: line 1 "solid", 7 lines per facet, last line "endsolid".
const char* kTetra = R"(solid t
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 1 0
  vertex 1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 0 1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 1
  vertex 0 1 0
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 1 0 0
  vertex 0 1 0
  vertex 0 0 1
 endloop
endfacet
endsolid t
)";

foxi::IoError stl_error(const std::string& data) {
  TempDir dir;
  std::ofstream(dir / "bad.stl", std::ios::binary)
      .write(data.data(), static_cast<std::streamsize>(data.size()));
  try {
    foxi::read_stl(dir / "bad.stl");
  } catch (const foxi::IoError& e) {
    EXPECT_NE(e.file().find("bad.stl"), std::string::npos) << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << data;
  return foxi::IoError("", 0, 0, "");
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  s.replace(s.find(from), from.size(), to);
  return s;
}

std::string binary_of(const foxi::TriSurface& s) {
  std::string data(80, 's');  // a header that starts with "solid", as some exporters write
  std::memcpy(data.data(), "solid", 5);
  const auto n = static_cast<std::uint32_t>(s.triangle_count());
  data.append(reinterpret_cast<const char*>(&n), 4);
  for (std::size_t t = 0; t < s.triangle_count(); ++t) {
    float f[12] = {};
    for (std::size_t v = 0; v < 3; ++v)
      for (std::size_t i = 0; i < 3; ++i)
        f[3 + 3 * v + i] = static_cast<float>(s.xyz[3 * s.tri[3 * t + v] + i]);
    data.append(reinterpret_cast<const char*>(f), sizeof f);
    data.append(2, '\0');
  }
  return data;
}

TEST(Stl, AsciiAndBinaryGiveTheSameMergedSurface) {
  TempDir dir;
  foxi::test::write_text(dir / "a.stl", kTetra);
  const foxi::TriSurface a = foxi::read_stl(dir / "a.stl", 2);
  ASSERT_EQ(a.vertex_count(), 4u);  // 12 corners merged
  ASSERT_EQ(a.triangle_count(), 4u);
  EXPECT_EQ(a.xyz[3 * a.tri[11] + 2], 2.0);  // scaled: the last corner (0, 0, 1) x 2
  const std::string bin = binary_of(a);
  std::ofstream(dir / "b.stl", std::ios::binary).write(bin.data(), static_cast<std::streamsize>(bin.size()));
  const foxi::TriSurface b = foxi::read_stl(dir / "b.stl");
  EXPECT_EQ(a.xyz, b.xyz);
  EXPECT_EQ(a.tri, b.tri);
}

TEST(Stl, BadAsciiNamesTheLine) {
  const foxi::IoError e =
      stl_error(replaced(kTetra, "vertex 1 0 0\n  vertex 0 0 1", "vertex 1 0 0\n  vertex 0 x 1"));
  EXPECT_EQ(e.line(), 13u);
  EXPECT_NE(e.reason().find("vertex coordinate"), std::string::npos) << e.what();
  EXPECT_EQ(
      stl_error(replaced(kTetra, " endloop\nendfacet\nfacet normal -1", " endloop\nfacet normal -1")).line(),
      15u);
  EXPECT_EQ(
      stl_error(replaced(kTetra, "  vertex 0 1 0\n  vertex 1 0 0\n", "  vertex 0 1 0\n  vertex 0 1 0\n"))
          .line(),
      2u);  // the degenerate facet starts on line 2
  const foxi::IoError end = stl_error(replaced(kTetra, "endsolid t\n", ""));
  EXPECT_NE(end.reason().find("end of file"), std::string::npos) << end.what();
  EXPECT_EQ(stl_error("solid empty\nendsolid empty\n").reason().find("no facets") != std::string::npos, true);
  EXPECT_EQ(stl_error("hello").line(), 1u);
}

TEST(Stl, BadBinaryNamesTheByte) {
  TempDir dir;
  foxi::test::write_text(dir / "a.stl", kTetra);
  std::string bin = binary_of(foxi::read_stl(dir / "a.stl"));
  std::string truncated = bin.substr(0, bin.size() - 7);
  truncated[0] = 'x';  // not "solid": a binary file whose count disagrees with its size
  const foxi::IoError e = stl_error(truncated);
  EXPECT_EQ(e.byte_offset(), 80u);
  EXPECT_NE(e.reason().find("4 triangles"), std::string::npos) << e.what();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bin.data() + 84 + 50 + 12 + 4, &nan, 4);  // triangle 1, first vertex, y
  const foxi::IoError f = stl_error(bin);
  EXPECT_EQ(f.byte_offset(), 84u + 50 + 16);
  EXPECT_NE(f.reason().find("not finite"), std::string::npos) << f.what();
}

}  // namespace
