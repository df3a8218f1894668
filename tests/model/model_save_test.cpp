// save_model: a model saved with edited parameters loads back (load_model, the reader the saved file
// is for) to the source loaded with the same overrides, meshes to the same mesh, keeps every other
// line of the source as written, and still finds its referenced files (material library, STL) when
// saved into another folder. What cannot be saved is refused with nothing written.
#include "foxi/model/model_save.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/model_file.hpp"
#include "structure_mesh.hpp"
#include "test_util.hpp"

namespace {

using foxi::ParameterOverride;
using foxi::test::TempDir;

std::vector<std::string> lines_of(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> out;
  for (std::string s; std::getline(in, s);) out.push_back(s);
  return out;
}

void expect_same_model(const foxi::Model& a, const foxi::Model& b) {
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  for (std::size_t i = 0; i < a.parameters.size(); ++i) {
    EXPECT_EQ(a.parameters[i].name, b.parameters[i].name);
    EXPECT_EQ(a.parameters[i].expression, b.parameters[i].expression);
    EXPECT_EQ(a.parameters[i].value.value, b.parameters[i].value.value) << a.parameters[i].name;
  }
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    EXPECT_EQ(a.parts[i].name, b.parts[i].name);
    EXPECT_EQ(a.parts[i].material, b.parts[i].material);
    ASSERT_EQ(a.parts[i].prisms.size(), b.parts[i].prisms.size());
    for (std::size_t k = 0; k < a.parts[i].prisms.size(); ++k) {
      EXPECT_EQ(a.parts[i].prisms[k].xy, b.parts[i].prisms[k].xy);
      EXPECT_EQ(a.parts[i].prisms[k].z1, b.parts[i].prisms[k].z1);
    }
    EXPECT_EQ(a.parts[i].surface.xyz, b.parts[i].surface.xyz);
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    EXPECT_EQ(a.materials[i].name, b.materials[i].name);
    EXPECT_EQ(a.materials[i].thermal_conductivity, b.materials[i].thermal_conductivity);
  }
  EXPECT_EQ(a.conditions.size(), b.conditions.size());
  EXPECT_EQ(a.loads.size(), b.loads.size());
}

TEST(ModelSave, SavedInAnotherFolderLoadsAndMeshesAsTheEditedSource) {
  const std::filesystem::path source = foxi::test::models_dir() + "die_on_substrate.toml";
  const std::vector<ParameterOverride> values = {{"die_w", "6 mm"}, {"sub_h", "die_h * 3"}};
  TempDir dir;
  const std::filesystem::path target = dir.path() / "deeper" / "saved.toml";
  std::filesystem::create_directories(target.parent_path());
  foxi::save_model(source, target, values);

  const foxi::Model expected = foxi::load_model(source, values);
  const foxi::Model saved = foxi::load_model(target);
  expect_same_model(expected, saved);
  EXPECT_EQ(saved.parameters[0].name, "die_d");
  // the edits are where the file had them: every other line as written, the library renamed
  const auto a = lines_of(source), b = lines_of(target);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].rfind("die_w =", 0) == 0) {
      EXPECT_EQ(b[i], "die_w = \"6 mm\"");
    } else if (a[i].rfind("sub_h =", 0) == 0) {
      EXPECT_EQ(b[i], "sub_h = \"die_h * 3\"");
    } else if (a[i].rfind("library =", 0) == 0) {
      EXPECT_NE(b[i], a[i]);
      EXPECT_NE(b[i].find("materials.toml\""), std::string::npos) << b[i];
    } else {
      EXPECT_EQ(a[i], b[i]) << "line " << i + 1;
    }
  }

  // the same mesh, vertex for vertex (a coarse one: the meshing is the same code both times)
  foxi::ModelMeshOptions options;
  options.size_scale = 2;
  const foxi::MeshedModel m1 = foxi::mesh_model(source, values, options);
  const foxi::MeshedModel m2 = foxi::mesh_model(target, {}, options);
  ASSERT_GT(m1.mesh.tet_count(), 0u);
  EXPECT_EQ(m1.mesh.xyz, m2.mesh.xyz);
  EXPECT_EQ(m1.mesh.tet, m2.mesh.tet);
  EXPECT_EQ(m1.mesh.tet_region, m2.mesh.tet_region);
}

// An STL part in a subfolder and a library beside the model: saved two folders away, both renamed;
// saved over itself, nothing but the value changes.
TEST(ModelSave, ReferencedFilesStayValid) {
  TempDir dir;
  const auto src = dir.path() / "a";
  std::filesystem::create_directories(src / "shapes");
  foxi::test::write_text(
      src / "shapes" / "t.stl",
      "solid t\n"
      " facet normal 0 0 0\n  outer loop\n   vertex 1 1 1\n   vertex 1 2 1\n   vertex 2 1 1\n"
      "  endloop\n endfacet\n"
      " facet normal 0 0 0\n  outer loop\n   vertex 1 1 1\n   vertex 2 1 1\n   vertex 1 1 2\n"
      "  endloop\n endfacet\n"
      " facet normal 0 0 0\n  outer loop\n   vertex 1 1 1\n   vertex 1 1 2\n   vertex 1 2 1\n"
      "  endloop\n endfacet\n"
      " facet normal 0 0 0\n  outer loop\n   vertex 2 1 1\n   vertex 1 2 1\n   vertex 1 1 2\n"
      "  endloop\n endfacet\n"
      "endsolid t\n");
  foxi::test::write_text(src / "lib.toml", "[materials.a]\nthermal_conductivity = 3\n");
  const std::string model =
      "units.length = \"mm\"  # a comment after a value\n"
      "library = \"lib.toml\"\n"
      "[parameters]\n"
      "w = 3   # the base's width\n"
      "h = \"1 mm\"\n"
      "[[parts]]\nname = \"base\"\nmaterial = \"a\"\nshape = \"box\"\norigin = [0, 0, 0]\n"
      "size = [\"w * 1 mm\", 3, \"h\"]\n"
      "[[parts]]\nname = \"tip\"\nmaterial = \"a\"\nshape = \"stl\"\nfile = \"shapes/t.stl\"\n";
  foxi::test::write_text(src / "m.toml", model);
  const std::vector<ParameterOverride> values = {{"w", "4"}};
  const auto target = dir.path() / "b" / "c" / "m.toml";
  std::filesystem::create_directories(target.parent_path());
  foxi::save_model(src / "m.toml", target, values);
  const std::string text = foxi::test::read_text(target);
  EXPECT_NE(text.find("library = \"../../a/lib.toml\"\n"), std::string::npos) << text;
  EXPECT_NE(text.find("file = \"../../a/shapes/t.stl\"\n"), std::string::npos) << text;
  EXPECT_NE(text.find("w = \"4\"   # the base's width\n"), std::string::npos) << text;
  const foxi::Model saved = foxi::load_model(target);
  expect_same_model(foxi::load_model(src / "m.toml", values), saved);
  EXPECT_EQ(saved.materials[0].thermal_conductivity, 3);
  EXPECT_EQ(saved.parts[0].prisms[0].xy[2], 4e-3);  // the base's width, 4 mm

  // over itself: only the value's text changes
  foxi::save_model(src / "m.toml", src / "m.toml", std::vector<ParameterOverride>{{"h", "2 mm"}});
  std::string expected = model;
  expected.replace(expected.find("\"1 mm\""), 6, "\"2 mm\"");
  EXPECT_EQ(foxi::test::read_text(src / "m.toml"), expected);
}

// copy_references: the library and the STL files copied beside the saved model (two STL files of
// one name: the second as t-2.stl), named by their copies: with the source folder gone, the saved
// model loads equal to the source's. Saved over itself, nothing is copied again.
TEST(ModelSave, CopiedReferencesNeedNothingOutside) {
  TempDir dir;
  const auto src = dir.path() / "a";
  std::filesystem::create_directories(src / "s1");
  std::filesystem::create_directories(src / "s2");
  auto tetra = [](double z) {
    std::string t = "solid t\n";
    const std::string v[4] = {"1 1 " + std::to_string(z), "1 2 " + std::to_string(z),
                              "2 1 " + std::to_string(z), "1 1 " + std::to_string(z + 1)};
    const int f[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {2, 1, 3}};
    for (const auto& tri : f)
      t += " facet normal 0 0 0\n  outer loop\n   vertex " + v[tri[0]] + "\n   vertex " + v[tri[1]] +
           "\n   vertex " + v[tri[2]] + "\n  endloop\n endfacet\n";
    return t + "endsolid t\n";
  };
  foxi::test::write_text(src / "s1" / "t.stl", tetra(2));
  foxi::test::write_text(src / "s2" / "t.stl", tetra(4));
  foxi::test::write_text(dir.path() / "lib.toml", "[materials.a]\nthermal_conductivity = 3\n");
  foxi::test::write_text(src / "m.toml",
                         "units.length = \"mm\"\nlibrary = \"../lib.toml\"\n[parameters]\nw = \"3 mm\"\n"
                         "[[parts]]\nname = \"base\"\nmaterial = \"a\"\nshape = \"box\"\norigin = [0, 0, 0]\n"
                         "size = [\"w\", 3, 1]\n"
                         "[[parts]]\nname = \"p\"\nmaterial = \"a\"\nshape = \"stl\"\nfile = \"s1/t.stl\"\n"
                         "[[parts]]\nname = \"q\"\nmaterial = \"a\"\nshape = \"stl\"\nfile = \"s2/t.stl\"\n"
                         "[[parts]]\nname = \"r\"\nmaterial = \"a\"\nshape = \"stl\"\nfile = \"s1/t.stl\"\n");
  const std::vector<ParameterOverride> values = {{"w", "4 mm"}};
  const foxi::Model expected = foxi::load_model(src / "m.toml", values);
  const auto target = dir.path() / "b" / "m.toml";
  std::filesystem::create_directories(target.parent_path());
  foxi::save_model(src / "m.toml", target, values, {.copy_references = true});
  const std::string text = foxi::test::read_text(target);
  EXPECT_NE(text.find("library = \"lib.toml\"\n"), std::string::npos) << text;
  EXPECT_NE(text.find("file = \"t.stl\"\n[[parts]]\nname = \"q\""), std::string::npos) << text;
  EXPECT_NE(text.find("file = \"t-2.stl\"\n[[parts]]\nname = \"r\""), std::string::npos) << text;
  EXPECT_EQ(foxi::test::read_text(target.parent_path() / "t-2.stl"), tetra(4));
  std::filesystem::remove_all(src);
  std::filesystem::remove(dir.path() / "lib.toml");
  expect_same_model(expected, foxi::load_model(target));
  // over itself: the copies are there already, not written again
  const auto stl_time = std::filesystem::last_write_time(target.parent_path() / "t.stl");
  foxi::save_model(target, target, std::vector<ParameterOverride>{{"w", "5 mm"}}, {.copy_references = true});
  EXPECT_EQ(std::filesystem::last_write_time(target.parent_path() / "t.stl"), stl_time);
  EXPECT_EQ(foxi::load_model(target).parts[0].prisms[0].xy[2], 5e-3);
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(target.parent_path())) ++files;
  EXPECT_EQ(files, 4u);  // m.toml, lib.toml, t.stl, t-2.stl
}

TEST(ModelSave, RefusesWhatItCannotSaveAndWritesNothing) {
  TempDir dir;
  const std::string model =
      "units.length = \"mm\"\n[materials.a]\nthermal_conductivity = 1\n"
      "[parameters]\nw = \"\"\"3 mm\"\"\"\nd = \"\"\"\n3 mm\"\"\"\n"
      "[[parts]]\nname = \"base\"\nmaterial = \"a\"\nshape = \"box\"\norigin = [0, 0, 0]\n"
      "size = [\"w\", \"d\", 1]\n";
  foxi::test::write_text(dir.path() / "m.toml", model);
  const auto target = dir.path() / "out.toml";
  auto error_of = [&](std::vector<ParameterOverride> values) {
    try {
      foxi::save_model(dir.path() / "m.toml", target, values);
    } catch (const foxi::IoError& e) {
      return std::string(e.what());
    }
    return std::string("saved");
  };
  // a parameter the model does not have
  EXPECT_NE(error_of({{"depth", "2 mm"}}).find("unknown parameter 'depth'"), std::string::npos);
  // a value that does not load (a length where a length is not expected is left to load_model)
  EXPECT_NE(error_of({{"w", "2 kg"}}).find("m.toml"), std::string::npos);
  // a multi-line string cannot be replaced in place
  const std::string multi = error_of({{"d", "4 mm"}});
  EXPECT_NE(multi.find("not written on one line"), std::string::npos) << multi;
  EXPECT_NE(multi.find(":6"), std::string::npos) << multi;  // its line
  EXPECT_FALSE(std::filesystem::exists(target));
  // nothing left beside it either (the durable temporary is removed)
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find("out.toml"), std::string::npos) << e.path();
  // a one-line triple-quoted string is one line: it saves
  EXPECT_EQ(error_of({{"w", "5 mm"}}), "saved");
  EXPECT_EQ(foxi::load_model(target).parts[0].prisms[0].xy[2], 5e-3);
}

}  // namespace
