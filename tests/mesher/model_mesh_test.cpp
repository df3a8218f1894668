// mesh_model (model_mesh.hpp): a shipped model with a parameter override to a certified, named mesh.
// Oracles: the exact Delaunay certificate computed here on the mesh returned, the regions' volumes
// summed from the tets against the boxes' analytic volumes (with the override's size), the parts'
// names on the regions; the limit, an unknown override and a cancel are refused with their types.
#include "foxi/mesher/model_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "foxi/model/delaunay.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

const std::string kModel = test::models_dir() + "die_on_substrate.toml";

double tet_volume(const Mesh& m, std::size_t t) {
  const double* p[4];
  for (int k = 0; k < 4; ++k) p[k] = &m.xyz[3 * std::size_t(m.tet[4 * t + std::size_t(k)])];
  double u[3], v[3], w[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = p[1][k] - p[0][k];
    v[k] = p[2][k] - p[0][k];
    w[k] = p[3][k] - p[0][k];
  }
  return std::abs(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
                  u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6;
}

TEST(ModelMesh, OverrideGivesACertifiedNamedMeshOfTheRightVolumes) {
  const std::vector<ParameterOverride> overrides = {{"die_w", "6 mm"}};
  ModelMeshOptions options;
  options.physics = Physics::thermal;
  std::size_t progress_calls = 0;
  options.progress = [&](std::string_view, double) {
    ++progress_calls;
    return true;
  };
  const MeshedModel m = mesh_model(kModel, overrides, options);
  ASSERT_GT(m.mesh.tet_count(), 100u);
  EXPECT_TRUE(m.conforming.delaunay);
  EXPECT_TRUE(compute_delaunay_certificate(m.mesh).delaunay) << "the mesh returned is certified";
  ASSERT_EQ(m.model.parts.size(), 2u);
  // Region i + 1 is part i, named after it; the die's volume follows the override.
  double volume[3] = {0, 0, 0};
  for (std::size_t t = 0; t < m.mesh.tet_count(); ++t) {
    const std::int32_t r = m.mesh.region_of(t);
    ASSERT_TRUE(r == 1 || r == 2) << r;
    volume[r] += tet_volume(m.mesh, t);
  }
  EXPECT_NEAR(volume[1], 10e-3 * 8e-3 * 1e-3, 1e-15);   // substrate 10 x 8 x 1 mm
  EXPECT_NEAR(volume[2], 6e-3 * 3e-3 * 0.5e-3, 1e-15);  // die 6 (overridden from 4) x 3 x 0.5 mm
  bool named_die = false, named_substrate = false;
  for (const auto& r : m.mesh.regions) {
    named_die = named_die || (r.id == 2 && r.name == "die");
    named_substrate = named_substrate || (r.id == 1 && r.name == "substrate");
  }
  EXPECT_TRUE(named_die && named_substrate);
  EXPECT_FALSE(m.mesh.boundaries.empty()) << "boundaries named after the structure's surfaces";
  EXPECT_TRUE(m.model.parameters.size() > 0);
  for (const Parameter& p : m.model.parameters) {
    if (p.name == "die_w") {
      EXPECT_TRUE(p.overridden);
    }
  }
  (void)progress_calls;  // TetGen may finish before the first 100 ms poll
}

TEST(ModelMesh, RefusesPastTheLimitUnknownOverridesAndACancel) {
  ModelMeshOptions options;
  options.max_tets = 10;
  try {
    (void)mesh_model(kModel, {}, options);
    ADD_FAILURE() << "a mesh past the limit was made";
  } catch (const TetLimitError& e) {
    EXPECT_EQ(e.limit(), 10);
    EXPECT_GT(e.estimate(), 10);
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << "no command-line option: " << e.what();
  }
  const std::vector<ParameterOverride> unknown = {{"no_such", "1 mm"}};
  ModelMeshOptions named;
  named.override_origin = "the host's table";
  try {
    (void)mesh_model(kModel, unknown, named);
    ADD_FAILURE() << "an unknown parameter was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("the host's table: unknown parameter 'no_such'"), std::string::npos)
        << e.what();
  }
  ModelMeshOptions stop;
  stop.progress = [](std::string_view, double) { return false; };
  // A finer mesh, so that TetGen runs long enough to be asked.
  const std::vector<ParameterOverride> fine = {{"sub_h", "1 mm"}};
  stop.size_scale = 0.2;
  stop.max_tets = 1e8;
  EXPECT_THROW((void)mesh_model(kModel, fine, stop), Cancelled);
}

}  // namespace
}  // namespace foxi
