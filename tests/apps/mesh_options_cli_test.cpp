// mesh_model's options (model_mesh.hpp) against `foxi mesh` given the same options on its command line
// (the file it writes, read back: the same nodes and tets), and against brute-force checks of their
// own: a refinement box's tets are shorter inside than out (edge lengths measured here), TetGen's mesh
// left unconformed reports the certificate computed here, the CGAL mesh passes the weighted
// certificate, refused options and a cancelled CGAL run have their types.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/plc.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

const std::string kDie = test::models_dir() + "die_on_substrate.toml";

// The same nodes, tets and regions (the CLI's file, written and read back, against the library's
// mesh): a thin CLI must give the library's mesh exactly.
void expect_same_mesh(const Mesh& a, const Mesh& b) {
  EXPECT_EQ(a.node_count(), b.node_count());
  EXPECT_EQ(a.tet_count(), b.tet_count());
  EXPECT_TRUE(a.xyz == b.xyz) << "node coordinates differ";
  EXPECT_TRUE(a.tet == b.tet) << "tets differ";
  EXPECT_TRUE(a.tet_region == b.tet_region) << "regions differ";
  EXPECT_TRUE(a.weight == b.weight) << "weights differ";
}

double edge_length(const Mesh& m, std::uint32_t a, std::uint32_t b) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) d2 += std::pow(m.xyz[3 * a + k] - m.xyz[3 * b + k], 2);
  return std::sqrt(d2);
}

// The mean edge length of the tets inside `box` (every vertex in it) and of those wholly outside it.
struct BoxEdges {
  double in_mean = 0, out_mean = 0;
  std::size_t in_n = 0, out_n = 0;  // edges counted
};
BoxEdges box_edges(const Mesh& m, const RefinementBox& box) {
  double in_sum = 0, out_sum = 0;
  BoxEdges e;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    int inside = 0;
    for (int c = 0; c < 4; ++c) {
      const double* p = &m.xyz[3 * m.tet[4 * t + c]];
      bool in = true;
      for (int k = 0; k < 3; ++k) in = in && p[k] >= box.lo[k] - 1e-12 && p[k] <= box.hi[k] + 1e-12;
      inside += in;
    }
    if (inside != 0 && inside != 4) continue;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const double len = edge_length(m, m.tet[4 * t + i], m.tet[4 * t + j]);
        (inside == 4 ? in_sum : out_sum) += len;
        ++(inside == 4 ? e.in_n : e.out_n);
      }
  }
  e.in_mean = e.in_n ? in_sum / double(e.in_n) : 0;
  e.out_mean = e.out_n ? out_sum / double(e.out_n) : 0;
  return e;
}

TEST(MeshOptionsCli, TetGenSizesBoxesAndPartsEqualTheCommandLine) {
  test::TempDir dir;
  const auto out = dir / "a.vtu";
  ASSERT_EQ(test::run_cli("mesh '" + kDie +
                              "' --set die_w=3mm --max-size 0.9mm --region-size 1=0.8mm "
                              "--refine-box 0,0,0,3,3,1=0.3mm -o '" +
                              out.string() + "'",
                          dir / "log.txt"),
            0)
      << test::read_text(dir / "log.txt");
  const std::vector<ParameterOverride> set = {{"die_w", "3mm"}};
  ModelMeshOptions o;
  o.max_size = 0.9e-3;
  o.sizes.region_ids = {1};
  o.sizes.region_sizes = {0.8e-3};
  RefinementBox box;
  box.hi[0] = box.hi[1] = 3e-3;
  box.hi[2] = 1e-3;
  box.size = 0.3e-3;
  o.sizes.boxes = {box};
  const MeshedModel m = mesh_loaded_model(load_model(kDie, set, "--set"), o);
  expect_same_mesh(read_mesh(out), m.mesh);
  EXPECT_TRUE(m.conforming.delaunay);
  EXPECT_TRUE(compute_delaunay_certificate(m.mesh).delaunay);

  // The box refines: edges of tets inside it against those wholly outside, measured here. TetGen's
  // size field is a target, not a bound: the means are compared.
  const BoxEdges e = box_edges(m.mesh, box);
  ASSERT_GT(e.in_n, 100u);
  ASSERT_GT(e.out_n, 100u);
  const double in_mean = e.in_mean, out_mean = e.out_mean;
  EXPECT_LT(in_mean, 1.5 * box.size) << "inside the box: edges about its size";
  // Measured: 0.38 mm inside, 0.66 mm outside; the same model without the box: 0.57 and 0.51 mm.
  EXPECT_LT(in_mean, 0.75 * out_mean) << in_mean << " inside, " << out_mean << " outside";
}

TEST(MeshOptionsCli, CgalThroughMeshModelEqualsFoxiMeshCgal) {
  test::TempDir dir;
  const auto out = dir / "c.vtu";
  ASSERT_EQ(test::run_cli("mesh '" + kDie + "' --mesher cgal --region-size 2=0.4mm -o '" + out.string() + "'",
                          dir / "log.txt"),
            0)
      << test::read_text(dir / "log.txt");
  ModelMeshOptions o;
  o.mesher = Mesher::cgal;
  o.part_sizes = {{.part = "die", .max_size = 0.4e-3}};  // the die is region 2: the same bound by name
  const MeshedModel m = mesh_model(kDie, {}, o);
  EXPECT_EQ(m.mesher, Mesher::cgal);
  expect_same_mesh(read_mesh(out), m.mesh);
  ASSERT_EQ(m.mesh.weight.size(), m.mesh.node_count()) << "a regular mesh carries its weights";
  const DelaunayCertificate cert = compute_delaunay_certificate(m.mesh);
  EXPECT_TRUE(cert.weighted);
  EXPECT_TRUE(cert.delaunay);
  EXPECT_EQ(m.conforming.delaunay, cert.delaunay) << "the report carries the weighted certificate";
  EXPECT_TRUE(m.cgal.volumes_match);
}

// A model's own [[mesh.refine]] box on the CGAL path: its mesh is the one the same box gives as
// --refine-box (foxi mesh --mesher cgal, through the options), certified with its weights, the part
// volumes kept; the box's tets are finer than those outside it and than the same place without the
// box (edges measured here); a box too fine for the tet limit is refused by its estimate.
TEST(MeshOptionsCli, CgalTakesTheModelsBoxesAndRefineBoxAsTetGenDoes) {
  test::TempDir dir;
  std::filesystem::copy(test::models_dir() + "materials.toml", dir / "materials.toml");
  test::write_text(dir / "boxed.toml", test::read_text(kDie) +
                                           "\n[[mesh.refine]]\nmin = [0, 0, 0]\nmax = [3, 3, 1]\n"
                                           "max_size = \"0.3 mm\"\n");
  ModelMeshOptions o;
  o.mesher = Mesher::cgal;
  const MeshedModel own = mesh_model(dir / "boxed.toml", {}, o);
  EXPECT_EQ(own.cgal.boxes, 1u);
  // The same box through the options (foxi mesh --refine-box): the same mesh.
  const auto out = dir / "c.vtu";
  ASSERT_EQ(test::run_cli(
                "mesh '" + kDie + "' --mesher cgal --refine-box 0,0,0,3,3,1=0.3mm -o '" + out.string() + "'",
                dir / "log.txt"),
            0)
      << test::read_text(dir / "log.txt");
  expect_same_mesh(read_mesh(out), own.mesh);
  EXPECT_NE(test::read_text(dir / "log.txt").find("refinement boxes: 1"), std::string::npos)
      << test::read_text(dir / "log.txt");

  const DelaunayCertificate cert = compute_delaunay_certificate(own.mesh);
  RefinementBox box;
  box.hi[0] = box.hi[1] = 3e-3;
  box.hi[2] = 1e-3;
  box.size = 0.3e-3;
  EXPECT_TRUE(cert.weighted);
  EXPECT_TRUE(cert.delaunay);
  EXPECT_TRUE(own.cgal.volumes_match) << "worst part volume change " << own.cgal.worst_volume_change;
  const BoxEdges e = box_edges(own.mesh, box), plain = box_edges(mesh_model(kDie, {}, o).mesh, box);
  ASSERT_GT(e.in_n, 100u);
  ASSERT_GT(plain.in_n, 0u);
  // Measured: 0.24 mm inside, 0.49 mm outside; without the box 0.60 mm inside.
  EXPECT_LT(e.in_mean, box.size) << "inside the box: edges below its size (a circumradius bound)";
  EXPECT_LT(e.in_mean, 0.6 * e.out_mean) << e.in_mean << " inside, " << e.out_mean << " outside";
  EXPECT_LT(e.in_mean, 0.6 * plain.in_mean) << e.in_mean << " with the box, " << plain.in_mean << " without";

  // A box too fine for the tet limit is refused before CGAL runs (its estimate counted here: two tets
  // per regular-tet volume of its edge over its 9 mm^3).
  box.size = 1e-6;
  o.sizes.boxes = {box};
  const double box_tets = 2 * 9e-9 / (std::pow(box.size, 3) / (6 * std::sqrt(2.0)));
  try {
    (void)mesh_model(kDie, {}, o);
    ADD_FAILURE() << "a box of 1 um edges over 9 mm^3 was meshed";
  } catch (const TetLimitError& limit) {
    EXPECT_GE(limit.estimate(), box_tets);
    EXPECT_LT(limit.estimate(), box_tets * 1.001);
  }
}

// A solved field's error as the size field: the library's mesh is the CLI's, and the error it reports
// is the one the CLI prints.
TEST(MeshOptionsCli, RefineFromAResultEqualsTheCommandLine) {
  test::TempDir dir;
  ASSERT_EQ(test::run_cli("solve '" + kDie + "' --physics thermal -o '" + (dir / "s.vtu").string() + "'",
                          dir / "solve.txt"),
            0)
      << test::read_text(dir / "solve.txt");
  ASSERT_EQ(
      test::run_cli("mesh '" + kDie + "' --refine-from '" + (dir / "s.vtu").string() +
                        "' --field temperature --target-error 0.3 -o '" + (dir / "r.vtu").string() + "'",
                    dir / "log.txt"),
      0)
      << test::read_text(dir / "log.txt");
  const Mesh solved = read_mesh(dir / "s.vtu");
  ModelMeshOptions o;
  o.refine_from = {.mesh = &solved, .field = "temperature", .target_error = 0.3, .origin = "s.vtu"};
  const MeshedModel m = mesh_model(kDie, {}, o);
  expect_same_mesh(read_mesh(dir / "r.vtu"), m.mesh);
  ASSERT_TRUE(m.refined);
  EXPECT_EQ(m.refined->field, "temperature");
  EXPECT_EQ(m.refined->tets, solved.tet_count());
  char printed[64];
  std::snprintf(printed, sizeof printed, "relative gradient error %.3g", m.refined->relative_error);
  EXPECT_NE(test::read_text(dir / "log.txt").find(printed), std::string::npos)
      << test::read_text(dir / "log.txt");
  EXPECT_TRUE(compute_delaunay_certificate(m.mesh).delaunay);
  // A field the solved mesh lacks: refused with the source named.
  ModelMeshOptions missing = o;
  missing.refine_from.field = "no_such";
  try {
    (void)mesh_model(kDie, {}, missing);
    ADD_FAILURE() << "a missing field was accepted";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::bad_input);
    EXPECT_NE(std::string(e.what()).find("s.vtu has no node field named 'no_such'"), std::string::npos)
        << e.what();
  }
}

// A PLC without a model (foxi model plc's .poly) under the options: the CLI's .poly path; TetGen's
// mesh left as it is reports the certificate computed here.
TEST(MeshOptionsCli, PlcWithoutConformingEqualsTheCommandLine) {
  test::TempDir dir;
  const auto poly = dir / "d.poly";
  ASSERT_EQ(test::run_cli("model plc '" + kDie + "' -o '" + poly.string() + "'", dir / "plc.txt"), 0)
      << test::read_text(dir / "plc.txt");
  ASSERT_EQ(test::run_cli("mesh '" + poly.string() + "' --max-size 0.7e-3 --no-conform -o '" +
                              (dir / "p.vtu").string() + "'",
                          dir / "log.txt"),
            0)
      << test::read_text(dir / "log.txt");
  ModelMeshOptions o;
  o.max_size = 0.7e-3;
  o.conform = false;
  const MeshedModel m = mesh_plc_with_options(read_poly(poly), o, poly.string());
  expect_same_mesh(read_mesh(dir / "p.vtu"), m.mesh);
  const DelaunayCertificate cert = compute_delaunay_certificate(m.mesh);
  EXPECT_EQ(m.conforming.delaunay, cert.delaunay);
  EXPECT_EQ(m.conforming.first_mesh_violations, cert.violating_tet_count);
  EXPECT_EQ(m.conforming.iterations, 0u) << "no conforming rounds";
  // Sizes by part name need a model.
  ModelMeshOptions parts;
  parts.part_sizes = {{.part = "die", .max_size = 1e-3}};
  EXPECT_THROW((void)mesh_plc_with_options(read_poly(poly), parts, poly.string()), MesherError);
}

TEST(MeshOptions, RefusedOptionsAndACancelledCgalRun) {
  auto refused = [](const ModelMeshOptions& o, const std::string& why) {
    try {
      check_mesh_options(o);
      ADD_FAILURE() << "accepted: " << why;
    } catch (const MesherError& e) {
      EXPECT_EQ(e.failure(), MesherFailure::bad_input);
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  ModelMeshOptions o;
  o.quality = 1.2;
  refused(o, "at least 1.414");
  o = {};
  o.mesher = Mesher::cgal;
  o.sizes.boxes.resize(1);
  o.sizes.boxes[0].size = 1e-3;
  EXPECT_NO_THROW(check_mesh_options(o)) << "CGAL takes boxes";
  o.sizes.boxes[0].lo[2] = 1;
  refused(o, "lo <= hi");
  o = {};
  o.max_size = -1;
  refused(o, "must be > 0");
  const Mesh solved;
  o = {};
  o.mesher = Mesher::cgal;
  o.refine_from.mesh = &solved;
  o.refine_from.target_error = 0.1;
  refused(o, "needs the TetGen mesher");
  // An unknown part: the model file's error.
  ModelMeshOptions parts;
  parts.part_sizes = {{.part = "no_such", .max_size = 1e-3}};
  try {
    (void)mesh_model(kDie, {}, parts);
    ADD_FAILURE() << "an unknown part was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("no part named 'no_such'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("die_on_substrate.toml"), std::string::npos) << e.what();
  }
  // CGAL asks the progress function while its child runs: false stops it.
  ModelMeshOptions stop;
  stop.mesher = Mesher::cgal;
  stop.max_size = 0.1e-3;
  stop.max_tets = 1e8;
  stop.progress = [](std::string_view, double) { return false; };
  EXPECT_THROW((void)mesh_model(kDie, {}, stop), Cancelled);
}

}  // namespace
}  // namespace foxi
