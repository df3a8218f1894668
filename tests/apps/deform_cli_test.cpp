// foxi render --deform NAME:SCALE, end to end: scale 0 draws the undeformed picture; a uniform
// displacement d draws exactly the picture of the undeformed mesh seen from a camera moved by -d
// (integer coordinates, so both are the same arithmetic); a shear that breaks the Delaunay property
// is drawn in MPVO order with the depth buffer and equals the picture of the same deformed mesh
// written by the test itself; a field that is not a vector is a usage error.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

// Displacements of node p: uniform (1, 0, 0), and a shear that grows with z and y.
void shear(const double* p, double* u) {
  u[0] = 0.35 * p[2] * p[1];
  u[1] = 0.2 * p[2] * p[2];
  u[2] = 0.1 * p[0];
}

class DeformCli : public ::testing::Test {
 protected:
  void SetUp() override {
    Mesh m = test::grid_mesh(6, 4, 3, 1, 1, 1, 6);
    test::regions_along_x(m, 2, 4);
    Field uniform{"uniform", FieldLocation::node, 3, "m", {}, {}};
    Field sh{"shear", FieldLocation::node, 3, "m", {}, {}};
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    Field c{"cellvec", FieldLocation::cell, 3, "m", {}, {}};
    for (std::size_t n = 0; n < m.node_count(); ++n) {
      for (double v : {1.0, 0.0, 0.0}) uniform.values.push_back(v);
      double u[3];
      shear(&m.xyz[3 * n], u);
      for (double v : u) sh.values.push_back(v);
      t.values.push_back(300 + m.xyz[3 * n]);
    }
    for (std::size_t e = 0; e < m.tet_count(); ++e)
      for (double v : {1.0, 0.0, 0.0}) c.values.push_back(v);
    m.fields = {uniform, sh, t, c};
    mesh_ = m;
    path_ = dir_ / "result.vtu";
    write_mesh(m, path_);
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run("'" + test::cli_path() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  // Renders `file` with `args` into NAME.png; returns the picture.
  Framebuffer render(const std::filesystem::path& file, const std::string& args, const std::string& name,
                     std::string* log) {
    const auto png = dir_ / (name + ".png");
    EXPECT_EQ(
        foxi("render '" + file.string() + "' " + args + " --size 320x200 -o '" + png.string() + "'", log), 0)
        << *log;
    return read_png(png);
  }
  static std::size_t differing(const Framebuffer& a, const Framebuffer& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.rgba.size() && i < b.rgba.size(); ++i) n += a.rgba[i] != b.rgba[i];
    return n;
  }
  test::TempDir dir_;
  Mesh mesh_;
  std::filesystem::path path_;
};

TEST_F(DeformCli, ScaleZeroIsTheUndeformedPicture) {
  const std::string cam = "--eye -7,-9,8 --at 3,2,1 --up 0,0,1 --fov 40";
  std::string log;
  const Framebuffer plain = render(path_, cam, "plain", &log);
  const Framebuffer zero = render(path_, cam + " --deform shear:0", "zero", &log);
  EXPECT_NE(log.find("deformed    by shear x 0"), std::string::npos) << log;
  EXPECT_EQ(differing(plain, zero), 0u);
}

TEST_F(DeformCli, UniformDisplacementIsTheCameraMovedBack) {
  std::string log;
  // Moved by 2 x (1, 0, 0) = (2, 0, 0), seen from (-7,-9,8) -> (3,2,1) ...
  const Framebuffer moved =
      render(path_, "--eye -7,-9,8 --at 3,2,1 --up 0,0,1 --fov 40 --deform uniform:2", "moved", &log);
  EXPECT_NE(log.find("nodes moved up to 2"), std::string::npos) << log;
  // ... is the undeformed mesh seen from a camera moved by (-2, 0, 0).
  const Framebuffer camera = render(path_, "--eye -9,-9,8 --at 1,2,1 --up 0,0,1 --fov 40", "camera", &log);
  EXPECT_EQ(differing(moved, camera), 0u);
  // And not the undeformed picture (the comparison can fail).
  const Framebuffer plain = render(path_, "--eye -7,-9,8 --at 3,2,1 --up 0,0,1 --fov 40", "plain", &log);
  EXPECT_GT(differing(moved, plain), 1000u);
}

TEST_F(DeformCli, ShearedMeshIsDrawnWithTheDepthBufferAsTheTestDeformsIt) {
  const std::string cam = "--eye -7,-9,8 --at 3,2,1 --up 0,0,1 --fov 40";
  std::string log;
  const Framebuffer deformed =
      render(path_, cam + " --deform shear:1.5 --field temperature", "deformed", &log);
  EXPECT_NE(log.find("MPVO order with the depth buffer"), std::string::npos) << log;
  EXPECT_NE(log.find("NOT Delaunay"), std::string::npos) << log;
  // The same deformation done here, written, and drawn without --deform.
  Mesh m = mesh_;
  for (std::size_t n = 0; n < m.node_count(); ++n) {
    double u[3];
    shear(&mesh_.xyz[3 * n], u);
    for (int k = 0; k < 3; ++k) m.xyz[3 * n + std::size_t(k)] += 1.5 * u[k];
  }
  const auto moved = dir_ / "moved_here.vtu";
  write_mesh(m, moved);
  const Framebuffer expected = render(moved, cam + " --field temperature", "expected", &log);
  EXPECT_EQ(differing(deformed, expected), 0u);
}

TEST_F(DeformCli, NotAVectorIsAUsageError) {
  const auto png = dir_ / "x.png";
  const std::string out = " -o '" + png.string() + "'";
  std::string log;
  EXPECT_EQ(foxi("render '" + path_.string() + "' --deform temperature:1" + out, &log), 2) << log;
  EXPECT_NE(log.find("not a displacement"), std::string::npos) << log;
  EXPECT_EQ(foxi("render '" + path_.string() + "' --deform cellvec:1" + out, &log), 2) << log;
  EXPECT_EQ(foxi("render '" + path_.string() + "' --deform nothere:1" + out, &log), 2) << log;
  EXPECT_NE(log.find("uniform, shear"), std::string::npos) << log;  // names the fields it could use
  EXPECT_EQ(foxi("render '" + path_.string() + "' --deform shear" + out, &log), 2) << log;
  EXPECT_EQ(foxi("render '" + path_.string() + "' --deform shear:abc" + out, &log), 2) << log;
  EXPECT_EQ(foxi("render '" + path_.string() + "' --deform shear:inf" + out, &log), 2) << log;
  EXPECT_FALSE(std::filesystem::exists(png));
}

}  // namespace
}  // namespace foxi
