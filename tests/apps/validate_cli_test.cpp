// Every command tells the truth about pathological but readable meshes (issue 22): inverted tets are
// re-oriented before ordering and drawing; duplicate tets, coincident nodes, geometry beyond the
// range of double and meshes without tets are refused with exit status 3 (bad input) and no output
// file; the exit-status table (apps/foxi/exit_codes.hpp) holds for each kind of failure.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <regex>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

struct Result {
  int status;
  std::string out;
};

Result foxi_cli(const std::string& args, const test::TempDir& dir) {
  const auto log = dir / "cli.log";
  const int status = test::run("timeout 300 '" + test::cli_path() + "' " + args, log);
  return {status, test::read_text(log)};
}

std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

std::size_t differing_pixels(const Framebuffer& a, const Framebuffer& b) {
  if (a.width != b.width || a.height != b.height) return std::size_t(-1);
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.rgba.size(); ++i) n += (a.rgba[i] & 0xFFFFFFu) != (b.rgba[i] & 0xFFFFFFu);
  return n;
}

TEST(ValidateCli, InvertedTetsAreReorientedBeforeOrderAndRender) {
  test::TempDir dir;
  const Mesh good = bench::kuhn_grid_mesh(4, 0.0);  // exactly Delaunay, positively oriented
  Mesh bad = good;
  std::size_t inverted = 0;
  for (std::size_t t = 0; t < bad.tet_count(); t += 3, ++inverted)
    std::swap(bad.tet[4 * t], bad.tet[4 * t + 1]);
  write_mesh(good, dir / "good.vtu");
  write_mesh(bad, dir / "bad.vtu");

  Result info = foxi_cli("info " + q(dir / "bad.vtu"), dir);
  EXPECT_EQ(info.status, 0) << info.out;
  EXPECT_NE(info.out.find("usable, with warnings"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find(std::to_string(inverted) + " inverted tets"), std::string::npos) << info.out;

  Result order = foxi_cli("order " + q(dir / "bad.vtu") + " --views 8 --check", dir);
  EXPECT_EQ(order.status, 0) << order.out;
  EXPECT_NE(order.out.find("total       0 violations over 8 views"), std::string::npos) << order.out;
  EXPECT_NE(order.out.find(std::to_string(inverted) + " inverted tets (negative orientation) re-oriented"),
            std::string::npos)
      << order.out;

  // The picture of the inverted file is the picture of the good one (the oracle), and not blank.
  const std::string camera = " --size 160x120 --dir 0.3,-0.4,-1 --shrink 0.8";
  Result a = foxi_cli("render " + q(dir / "good.vtu") + camera + " -o " + q(dir / "good.png"), dir);
  ASSERT_EQ(a.status, 0) << a.out;
  Result b = foxi_cli("render " + q(dir / "bad.vtu") + camera + " -o " + q(dir / "bad.png"), dir);
  ASSERT_EQ(b.status, 0) << b.out;
  EXPECT_NE(b.out.find("painter"), std::string::npos) << b.out;  // Delaunay: no depth-buffer fallback
  const Framebuffer fa = read_png(dir / "good.png"), fb = read_png(dir / "bad.png");
  EXPECT_EQ(differing_pixels(fa, fb), 0u);
  std::size_t background = 0;
  for (std::uint32_t p : fa.rgba) background += (p & 0xFFFFFFu) == (fa.rgba[0] & 0xFFFFFFu);
  EXPECT_LT(background, fa.rgba.size() * 9 / 10);  // a picture, not a blank
}

// One unusable mesh and what `info` must say about it.
struct BadCase {
  std::string name;
  std::function<void(Mesh&)> spoil;
  std::string info_says;
};

TEST(ValidateCli, UnusableMeshesAreRefusedByEveryCommand) {
  const std::vector<BadCase> cases = {
      {"duplicate_tet",
       [](Mesh& m) {
         m.tet.insert(m.tet.end(), {m.tet[3], m.tet[2], m.tet[1], m.tet[0]});
         m.tet_region.push_back(m.tet_region[0]);
       },
       "the same nodes as tet 0"},
      {"coincident_nodes",
       [](Mesh& m) {
         // Tet 0's first node gets a copy of its own: tet 0 is torn off its neighbours.
         const std::uint32_t v = m.tet[0];
         m.xyz.insert(m.xyz.end(), {m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]});
         m.tet[0] = static_cast<std::uint32_t>(m.node_count() - 1);
       },
       "both used by tets"},
      {"scaled_1e154",
       [](Mesh& m) {
         for (double& x : m.xyz) x *= 1e154;
       },
       "beyond the range"},
      {"scaled_1e300",
       [](Mesh& m) {
         for (double& x : m.xyz) x *= 1e300;
       },
       "beyond the range"},
      {"scaled_1e-300",
       [](Mesh& m) {
         for (double& x : m.xyz) x *= 1e-300;
       },
       "beyond the range"},
      {"no_tets",
       [](Mesh& m) {
         m.tet.clear();
         m.tet_region.clear();
       },
       "no tets"},
  };
  test::TempDir dir;
  for (const BadCase& c : cases) {
    Mesh m = bench::kuhn_grid_mesh(3, 0.0);
    c.spoil(m);
    const auto file = dir / (c.name + ".vtu");
    write_mesh(m, file);

    Result info = foxi_cli("info --check-delaunay " + q(file), dir);
    EXPECT_EQ(info.status, 3) << c.name << ": " << info.out;
    EXPECT_NE(info.out.find("INVALID"), std::string::npos) << c.name << ": " << info.out;
    EXPECT_NE(info.out.find(c.info_says), std::string::npos) << c.name << ": " << info.out;
    EXPECT_EQ(info.out.find("delaunay            yes"), std::string::npos) << c.name << ": " << info.out;
    Result json = foxi_cli("info --json " + q(file), dir);
    EXPECT_EQ(json.status, 3) << c.name;
    EXPECT_NE(json.out.find("\"ok\": false"), std::string::npos) << c.name << ": " << json.out;

    const std::string out_png = (dir / (c.name + ".png")).string();
    const std::string out_vtu = (dir / (c.name + "_out.vtu")).string();
    const std::string out_gif = (dir / (c.name + ".gif")).string();
    for (const std::string& cmd :
         {"order " + q(file) + " --views 2", "render " + q(file) + " --size 64x48 -o '" + out_png + "'",
          "movie " + q(file) + " --size 32x24 --frames 2 -o '" + out_gif + "'",
          "convert " + q(file) + " '" + out_vtu + "'",
          "solve " + q(file) + " --physics thermal --fix 1=300 --fix 2=400 -o '" + out_vtu + "'"}) {
      Result r = foxi_cli(cmd, dir);
      EXPECT_EQ(r.status, 3) << c.name << ": " << cmd << "\n" << r.out;
      EXPECT_NE(r.out.find(file.string()), std::string::npos) << c.name << ": " << cmd << "\n" << r.out;
      EXPECT_NE(r.out.find(c.info_says), std::string::npos) << c.name << ": " << cmd << "\n" << r.out;
    }
    EXPECT_FALSE(std::filesystem::exists(out_png)) << c.name;
    EXPECT_FALSE(std::filesystem::exists(out_gif)) << c.name;
    EXPECT_FALSE(std::filesystem::exists(out_vtu)) << c.name;
  }
}

TEST(ValidateCli, ConvertKeepInvalidConvertsAsItIs) {
  test::TempDir dir;
  Mesh m = bench::kuhn_grid_mesh(2, 0.0);
  m.tet.insert(m.tet.end(), {m.tet[0], m.tet[1], m.tet[2], m.tet[3]});
  m.tet_region.push_back(1);
  write_mesh(m, dir / "dup.vtu");
  Result r = foxi_cli("convert " + q(dir / "dup.vtu") + " " + q(dir / "dup.msh") + " --keep-invalid", dir);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("warning"), std::string::npos) << r.out;
  EXPECT_EQ(read_mesh(dir / "dup.msh").tet_count(), m.tet_count());
}

TEST(ValidateCli, ExitStatusTable) {
  test::TempDir dir;
  write_mesh(bench::kuhn_grid_mesh(2, 0.0), dir / "ok.vtu");
  test::write_text(dir / "broken.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n");
  EXPECT_EQ(foxi_cli("info " + q(dir / "ok.vtu"), dir).status, 0);
  EXPECT_EQ(foxi_cli("", dir).status, 2);
  EXPECT_EQ(foxi_cli("frobnicate", dir).status, 2);
  EXPECT_EQ(foxi_cli("info --no-such-option " + q(dir / "ok.vtu"), dir).status, 2);
  EXPECT_EQ(foxi_cli("order " + q(dir / "ok.vtu"), dir).status, 2);  // no view given
  Result broken = foxi_cli("info " + q(dir / "broken.msh"), dir);
  EXPECT_EQ(broken.status, 3) << broken.out;
  EXPECT_NE(broken.out.find("broken.msh"), std::string::npos) << broken.out;
  EXPECT_EQ(foxi_cli("info " + q(dir / "missing.vtu"), dir).status, 3);
  EXPECT_EQ(foxi_cli("order " + q(dir / "broken.msh") + " --views 1", dir).status, 3);
  EXPECT_EQ(foxi_cli("render " + q(dir / "missing.vtu") + " -o " + q(dir / "x.png"), dir).status, 3);
  EXPECT_EQ(foxi_cli("model check " + q(dir / "missing.toml"), dir).status, 3);
  // A result that fails its own check: the centroid order of a Delaunay grid has violations.
  // The jittered grid's centroid order has some (the test below counts them); the power order none.
  write_mesh(bench::kuhn_grid_mesh(5, 0.2), dir / "jitter.vtu");
  Result c = foxi_cli("order " + q(dir / "jitter.vtu") + " --views 8 --method centroid --check", dir);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(c.out, m, std::regex("total +(\\d+) violations"))) << c.out;
  EXPECT_GT(std::stoul(m[1]), 0u) << c.out;
  EXPECT_EQ(c.status, 4) << c.out;
  Result p = foxi_cli("order " + q(dir / "ok.vtu") + " --views 8 --method power --check", dir);
  EXPECT_EQ(p.status, 0) << p.out;
  EXPECT_NE(p.out.find("total       0 violations"), std::string::npos) << p.out;
}

}  // namespace
}  // namespace foxi
