// Model files that once crashed or hung foxi (issue 22), and the model limits (model_limits in
// model_file.hpp): each must be refused quickly with an IoError that names the file, the line where
// it is known, and the bound. The oracle is the limit itself: values just inside load, values past
// it are refused; and for the referenced-file policy, what the error may not contain.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/structure.hpp"
#include "foxi/model/units.hpp"
#include "test_util.hpp"

namespace {

using foxi::test::TempDir;
namespace lim = foxi::model_limits;

const std::string kModels = foxi::test::models_dir();

std::string header() { return "units.length = \"mm\"\n[materials.a]\nthermal_conductivity = 1\n"; }

// A model with one part of `shape` and the given key lines.
std::string part(const std::string& name, const std::string& shape, const std::string& keys) {
  return "[[parts]]\nname = \"" + name + "\"\nmaterial = \"a\"\nshape = \"" + shape + "\"\n" + keys + "\n";
}

std::string sub() { return part("sub", "box", "origin = [0, 0, 0]\nsize = [10, 10, 1]"); }

// The error of loading and building `path` (which must fail within `seconds`).
foxi::IoError error_of(const std::filesystem::path& path, std::vector<std::string> sets = {},
                       double seconds = 5) {
  const auto t0 = std::chrono::steady_clock::now();
  try {
    const foxi::Model m = foxi::load_model(path, sets);
    foxi::build_structure(m);
  } catch (const foxi::IoError& e) {
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
              seconds * foxi::test::kTimeScale)
        << e.what();
    return e;
  }
  ADD_FAILURE() << "no error for " << path;
  return foxi::IoError("", 0, 0, "");
}

foxi::IoError text_error(const std::string& text, std::vector<std::string> sets = {}) {
  TempDir dir;
  foxi::test::write_text(dir / "bad.toml", text);
  foxi::IoError e = error_of(dir / "bad.toml", sets);
  EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
  return e;
}

bool has(const foxi::IoError& e, const std::string& s) {
  return std::string(e.what()).find(s) != std::string::npos;
}

std::uint64_t line_of(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<std::uint64_t>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  s.replace(s.find(from), from.size(), to);
  return s;
}

foxi::Quantity eval(const std::string& text) {
  return foxi::evaluate_expression(text, [](std::string_view) { return std::optional<foxi::Quantity>(); });
}

// --- the crashes of issue 22 ---

// foxi model check die_on_substrate.toml --set "die_w=1e-30 mm" crashed inside CGAL: the die's
// outline collapses in doubles (5 mm + 1e-33 m is 5 mm).
TEST(ModelLimits, FeatureFarBelowTheStructureIsDegenerate) {
  const foxi::IoError e = error_of(kModels + "die_on_substrate.toml", {"die_w=1e-30 mm"});
  EXPECT_TRUE(has(e, "part 'die'")) << e.what();
  EXPECT_TRUE(has(e, "degenerate geometry")) << e.what();
  EXPECT_TRUE(has(e, "1e-06 of the model's extent")) << e.what();
  EXPECT_GT(e.line(), 0u);
  // just above the bound it loads: 2e-5 mm against the 10 mm substrate (2e-6 of the extent)
  const foxi::Model ok =
      foxi::load_model(kModels + "die_on_substrate.toml", std::vector<std::string>{"die_w=2e-5 mm"});
  EXPECT_EQ(ok.parts.size(), 2u);
}

// --set "die_w=1e300 mm" on the BGA model crashed in GMP (SIGFPE).
TEST(ModelLimits, HugeLengthIsBeyondTheBound) {
  const foxi::IoError e = error_of(kModels + "bga.toml", {"die_w=1e300 mm"});
  EXPECT_TRUE(has(e, "beyond the limit of 1000 m")) << e.what();
  EXPECT_TRUE(has(e, "part 'die'")) << e.what();
}

// nan and inf (TOML floats) in an extrusion's outline crashed with SIGFPE.
TEST(ModelLimits, NanAndInfinityInAnOutlineAreRefused) {
  for (const char* bad : {"nan", "inf", "-inf", "\"1e400 mm\""}) {
    const std::string t =
        header() + sub() +
        part("e", "extrusion", std::string("points = [[0, 0], [") + bad + ", 0], [1, 1]]\nz = 1\nheight = 1");
    const foxi::IoError e = text_error(t);
    EXPECT_TRUE(has(e, "part 'e' points[1][0]")) << bad << ": " << e.what();
    EXPECT_TRUE(has(e, "not a finite number") || has(e, "not finite")) << bad << ": " << e.what();
    EXPECT_EQ(e.line(), line_of(t, "points =")) << bad;
  }
  const foxi::IoError m = text_error(header() + "[materials.b]\nthermal_conductivity = nan\n" + sub());
  EXPECT_TRUE(has(m, "not a finite number")) << m.what();
}

// A deeply nested TOML array (~200 KB) overflowed the stack inside toml11.
TEST(ModelLimits, DeeplyNestedTomlIsRefusedBeforeParsing) {
  // 100,000 levels in 200 KB, a thousand brackets a line (lines have a limit of their own)
  std::string opening, closing;
  for (int k = 0; k < 100; ++k)
    opening += std::string(1000, '[') + "\n", closing += std::string(1000, ']') + "\n";
  const std::string t = header() + "x = " + opening + closing + sub();
  const foxi::IoError e = text_error(t);
  EXPECT_TRUE(has(e, "nest deeper than 32 levels")) << e.what();
  EXPECT_EQ(e.line(), line_of(t, "x = "));
  // inline tables, dotted keys and table headers count too
  EXPECT_TRUE(has(text_error(header() + "y = " + std::string(50, '{') + "\n"), "nest deeper"));
  std::string dotted = "a";
  for (int i = 0; i < 5000; ++i) dotted += ".a";
  EXPECT_TRUE(has(text_error(header() + dotted + " = 1\n"), "nest deeper"));
  EXPECT_TRUE(has(text_error(header() + "[" + dotted + "]\n"), "nest deeper"));
  // brackets in strings and comments are not nesting: this model loads
  TempDir dir;
  foxi::test::write_text(dir / "ok.toml", "units.length = \"mm\" # " + std::string(100, '[') +
                                              "\n[parameters]\nw = \"10 mm\" # [[[[[\n[materials.a]\n"
                                              "thermal_conductivity = 1\nnote = \"" +
                                              std::string(100, '{') + "\\\"\"\nsource = '''\n" +
                                              std::string(100, '[') + "\n'''\n" + sub());
  EXPECT_NO_THROW(foxi::load_model(dir / "ok.toml"));
}

// 20,000 nested parentheses in an expression overflowed the stack of foxi's own parser.
TEST(ModelLimits, DeeplyNestedExpressionIsRefused) {
  const std::string deep = std::string(20000, '(') + "1" + std::string(20000, ')');
  EXPECT_THROW(eval(deep), foxi::ExpressionError);
  for (const std::string& nested :
       {std::string(2000, '(') + "1" + std::string(2000, ')'), std::string(2000, '-') + "1",
        "2" + std::string(1000, '^') /* unterminated, but deep first */, std::string(1000, '+') + "1", [] {
          std::string s = "1";
          for (int i = 0; i < 100; ++i) s = "abs(" + s + ")";
          return s;
        }()}) {
    try {
      eval(nested);
      ADD_FAILURE() << "no error";
    } catch (const foxi::ExpressionError& e) {
      if (nested[1] != '^') {
        EXPECT_NE(std::string(e.what()).find("nests deeper than 64"), std::string::npos) << e.what();
      }
      EXPECT_LT(std::string(e.what()).size(), 300u) << "the message quotes a long expression whole";
    }
  }
  // within the limit it evaluates
  EXPECT_DOUBLE_EQ(eval(std::string(60, '(') + "2" + std::string(60, ')')).value, 2);
  EXPECT_DOUBLE_EQ(eval(std::string(40, '-') + "3").value, 3);
  // too long, and units raised past int8_t
  EXPECT_THROW(eval(std::string(5000, '1')), foxi::ExpressionError);
  EXPECT_THROW(eval("(m^20)^20"), foxi::ExpressionError);
  EXPECT_THROW(eval("m^20*m^20*m^20*m^20*m^20*m^20*m^20"), foxi::ExpressionError);
  // in a model, through an override, with the parameter named
  const foxi::IoError e = error_of(kModels + "die_on_substrate.toml", {"die_w=" + deep});
  EXPECT_TRUE(has(e, "parameter 'die_w' (from an override)")) << e.what();
}

// A chain of parameters, each needing the next, recursed once per link.
TEST(ModelLimits, LongParameterChainIsRefused) {
  std::string t = header() + "[parameters]\np0 = \"1 mm\"\n";
  for (int i = 1; i <= 1000; ++i)
    t += "p" + std::to_string(i) + " = \"p" + std::to_string(i - 1) + " + 1 mm\"\n";
  const foxi::IoError e = text_error(t + sub());
  EXPECT_TRUE(has(e, "more than 64 parameters")) << e.what();
}

// --- the hangs: values with no upper bound ---

// A part's name makes its boundaries' and interfaces' names (part.face, a/b): '.', '/', control
// characters, an empty or a very long name are refused at the part's line (parts p/q and r, beside
// p and q/r, once shared one boundary "p/q/r").
TEST(ModelLimits, PartNamesThatWouldGarbleBoundaryNamesAreRefused) {
  const std::string box = "origin = [0, 0, 1]\nsize = [1, 1, 1]";
  for (const std::string& name : {std::string("p/q"), std::string("die.top"), std::string(""),
                                  std::string("a\\u001b[31mred"), std::string(300, 'x')}) {
    const std::string t = header() + part(name, "box", box) + sub();
    const foxi::IoError e = text_error(t);
    EXPECT_TRUE(has(e, "without '.', '/' or control characters")) << e.what();
    EXPECT_GE(e.line(), line_of(t, "[[parts]]")) << e.what();  // the part's own lines
    EXPECT_LE(e.line(), line_of(t, "[[parts]]") + 4) << e.what();
    EXPECT_FALSE(has(e, "\x1b")) << "a control character printed raw";
  }
}

TEST(ModelLimits, HugeArrayCountIsRefused) {
  const std::string t = header() + sub() +
                        part("pins", "array",
                             "count = [100000, 1]\npitch = [1, 1]\nitem = { shape = \"box\", origin = [0, 0, "
                             "1], size = [0.5, 0.5, 1] }");
  const foxi::IoError e = text_error(t);
  EXPECT_TRUE(has(e, "must be an integer from 1 to 10000")) << e.what();
  EXPECT_TRUE(has(text_error(replaced(t, "[100000, 1]", "[200, 200]")),
                  "200 x 200 items, more than the limit of 10000"));
  // the outline vertices of all items together: 100 x 100 cylinders of 16 segments
  const std::string cyl =
      header() + sub() +
      part("vias", "array",
           "count = [100, 100]\npitch = [0.1, 0.1]\nitem = { shape = \"cylinder\", center = "
           "[0.05, 0.05, 1], radius = 0.01, height = 1 }");
  EXPECT_TRUE(
      has(text_error(cyl), "outline vertices (all prisms and array items), more than the limit of 100000"));
}

TEST(ModelLimits, CylinderSegmentsAndOutlinePointsAreBounded) {
  const std::string cyl =
      header() + sub() +
      part("c", "cylinder", "center = [5, 5, 1]\nradius = 1\nheight = 1\nsegments = 1000000");
  const foxi::IoError e = text_error(cyl);
  EXPECT_TRUE(has(e, "part 'c' segments = 1e+06: must be an integer from 3 to 1000")) << e.what();
  EXPECT_EQ(e.line(), line_of(cyl, "segments ="));
  TempDir dir;
  foxi::test::write_text(dir / "ok.toml", replaced(cyl, "1000000", "1000"));
  EXPECT_EQ(foxi::load_model(dir / "ok.toml").parts[1].prisms[0].xy.size(), 2000u);

  std::string pts = "points = [";
  for (int i = 0; i < 20000; ++i) {
    const double a = 2 * 3.141592653589793 * i / 20000;
    pts += (i ? ",\n [" : "[") + std::to_string(5 + 2 * std::cos(a)) + ", " +
           std::to_string(5 + 2 * std::sin(a)) + "]";
  }
  const std::string ext = header() + sub() + part("e", "extrusion", pts + "]\nz = 1\nheight = 1");
  const foxi::IoError o = text_error(ext);
  EXPECT_TRUE(has(o, "20000 points, more than the limit of 2000")) << o.what();
  // a long line: toml11's time goes as its length squared (20,000 points on one line took a minute)
  const std::string long_line = header() + "x = [" + std::string(70000, ' ') + "]\n";
  const foxi::IoError ll = text_error(long_line);
  EXPECT_TRUE(has(ll, "the line has 70006 characters, more than the limit of 65536")) << ll.what();
  EXPECT_EQ(ll.line(), 4u);
}

TEST(ModelLimits, BallToleranceIsBoundedByTheRadius) {
  const foxi::IoError e = error_of(kModels + "bga.toml", {"ball_tol=1e-6 mm"});
  EXPECT_TRUE(has(e, "tolerance = 1e-06 mm is below the limit of 0.001 times the radius (0.38 mm)"))
      << e.what();
  // at the bound a ball has about 10,000 triangles: one loads
  const std::string ball = header() + part("b", "ball", "center = [0, 0, 0]\nradius = 1\ntolerance = 0.001");
  TempDir dir;
  foxi::test::write_text(dir / "ok.toml", ball);
  const foxi::Model m = foxi::load_model(dir / "ok.toml");
  EXPECT_GT(m.parts[0].surface.triangle_count(), 5000u);
  EXPECT_LT(m.parts[0].surface.triangle_count(), 20000u);
  // 25 of them pass the limit on all surface triangles
  const foxi::IoError many = text_error(
      header() +
      part("bs", "array",
           "count = [5, 5]\npitch = [3, 3]\nitem = { shape = \"ball\", center = [0, 0, 0], radius = 1, "
           "tolerance = 0.001 }"));
  EXPECT_TRUE(has(many, "triangles, more than the limit of 200000")) << many.what();
}

TEST(ModelLimits, ModelExtentIsBounded) {
  const foxi::IoError tiny = text_error(
      header() + part("t", "box", "origin = [0, 0, 0]\nsize = [\"1e-4 nm\", \"1e-4 nm\", \"1e-4 nm\"]"));
  EXPECT_TRUE(has(tiny, "across, below the limit of 1e-09 m")) << tiny.what();
  const foxi::IoError far = text_error(
      header() + sub() + part("far", "box", "origin = [\"999 m\", 0, 0]\nsize = [\"999 m\", 1, 1]"));
  EXPECT_TRUE(has(far, "beyond the limit of 1000 m")) << far.what();
}

// --- referenced files (library, STL): regular files, relative to the model's folder, never quoted ---

TEST(ModelFiles, ReferencedFilesMustBeRegularFilesNamedRelatively) {
  TempDir dir;
  std::filesystem::create_directory(dir / "folder");
  const std::string stl_part = part("s", "stl", "file = \"FILE\"");
  struct Case {
    std::string text, want;
  } cases[] = {
      {"library = \"\"\n" + header() + sub(), "library: the file name is empty"},
      {"library = \"folder\"\n" + header() + sub(), "library 'folder' is a directory, not a file"},
      {"library = \".\"\n" + header() + sub(), "is a directory, not a file"},
      {"library = \"/etc/passwd\"\n" + header() + sub(),
       "is an absolute path: name it relative to the model file's folder"},
      {"library = \"nothing.toml\"\n" + header() + sub(), "library 'nothing.toml': no such file"},
      {"library = \"zero\"\n" + header() + sub(), "library 'zero' is not a regular file"},
      {header() + sub() + replaced(stl_part, "FILE", "folder"),
       "part 's' file 'folder' is a directory, not a file"},
      {header() + sub() + replaced(stl_part, "FILE", ""), "part 's' file: the file name is empty"},
      {"library = 3\n" + header() + sub(), "library must be a string"},
  };
  std::filesystem::create_symlink("/dev/zero", dir / "zero");  // reading it would never end
  for (const Case& c : cases) {
    foxi::test::write_text(dir / "m.toml", c.text);
    const foxi::IoError e = error_of(dir / "m.toml");
    EXPECT_TRUE(has(e, c.want)) << c.want << "\n" << e.what();
    EXPECT_TRUE(has(e, "m.toml")) << e.what();
    EXPECT_GT(e.line(), 0u) << e.what();
  }
}

TEST(ModelFiles, ContentOfAFileOfTheWrongKindIsNeverQuoted) {
  TempDir dir;
  const std::string secret = "root:x:0:0:SECRET-LINE:/root:/bin/bash";
  foxi::test::write_text(dir / "notes.txt", secret + "\n" + secret + "\n");
  foxi::test::write_text(dir / "m.toml", "library = \"notes.txt\"\n" + header() + sub());
  const foxi::IoError e = error_of(dir / "m.toml");
  EXPECT_FALSE(has(e, "SECRET")) << e.what();
  EXPECT_FALSE(has(e, "root")) << e.what();
  EXPECT_TRUE(has(e, "notes.txt")) << e.what();
  EXPECT_TRUE(has(e, "not a TOML materials library")) << e.what();
  EXPECT_EQ(e.line(), 1u);
  // a TOML file that is not a library: its keys are named, not its values
  foxi::test::write_text(dir / "other.toml", "password = \"SECRET\"\n");
  foxi::test::write_text(dir / "m.toml", "library = \"other.toml\"\n" + header() + sub());
  const foxi::IoError o = error_of(dir / "m.toml");
  EXPECT_FALSE(has(o, "SECRET")) << o.what();
  EXPECT_TRUE(has(o, "not a materials library: it has no [materials] table")) << o.what();
  // an STL part naming a text file
  foxi::test::write_text(dir / "m.toml", header() + sub() + part("s", "stl", "file = \"notes.txt\""));
  const foxi::IoError s = error_of(dir / "m.toml");
  EXPECT_FALSE(has(s, "SECRET")) << s.what();
  EXPECT_TRUE(has(s, "not an STL file")) << s.what();
}

TEST(ModelFiles, LibraryOutsideTheFolderByARelativePathLoads) {
  TempDir dir;
  std::filesystem::create_directory(dir / "project");
  std::filesystem::create_directory(dir / "project" / "models");
  foxi::test::write_text(dir / "project" / "lib.toml", "[materials.a]\nthermal_conductivity = 7\n");
  foxi::test::write_text(dir / "project" / "models" / "m.toml",
                         "library = \"../lib.toml\"\nunits.length = \"mm\"\n" + sub());
  const foxi::Model m = foxi::load_model(dir / "project" / "models" / "m.toml");
  EXPECT_DOUBLE_EQ(m.materials.at(0).thermal_conductivity, 7);
}

TEST(ModelFiles, UnknownKeyErrorsListTheAllowedKeys) {
  const foxi::IoError p =
      text_error(header() + part("b", "box", "origin = [0, 0, 0]\nsize = [1, 1, 1]\ncolour = 3"));
  EXPECT_TRUE(has(p, "part 'b': unknown key 'colour' (expected name, shape, material, origin, size)"))
      << p.what();
  const foxi::IoError u = text_error("units.lenght = \"mm\"\n" + header() + sub());
  EXPECT_TRUE(has(u, "(expected units.length)")) << u.what();
  const foxi::IoError m = text_error(header() + "[materials.b]\nconductivity = 1\n" + sub());
  EXPECT_TRUE(has(m, "(expected thermal_conductivity, electrical_conductivity")) << m.what();
  const foxi::IoError c = text_error(
      header() + sub() + "[[conditions]]\ntype = \"temperature\"\nsurface = \"sub.top\"\nvalu = 300\n");
  EXPECT_TRUE(has(c, "unknown key 'valu' (expected type, surface, value)")) << c.what();
  const foxi::IoError t = text_error("colour = 1\n" + header() + sub());
  EXPECT_TRUE(has(t, "(expected units, library, parameters")) << t.what();
}

TEST(ModelFiles, ModelFileThatIsNotARegularFileOrTooLarge) {
  TempDir dir;
  std::filesystem::create_directory(dir / "d.toml");
  EXPECT_TRUE(has(error_of(dir / "d.toml"), "is a directory"));
  std::filesystem::create_symlink("/dev/zero", dir / "z.toml");
  EXPECT_TRUE(has(error_of(dir / "z.toml"), "not a regular file"));
  foxi::test::write_text(dir / "big.toml", "# " + std::string(lim::kFileBytes, 'x') + "\n");
  EXPECT_TRUE(has(error_of(dir / "big.toml"), "more than the limit of 4194304"));
}

}  // namespace
