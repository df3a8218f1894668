// Thin layers and the quality exemption (issue 6): layers found from the PLC's parallel facets against
// the model's own part boxes; a 20 um die-attach under a 10 mm die meshed with the radius-edge bound
// stays small, keeps the bound outside the layer (measured on every tet), is Delaunay (exact
// certificate) and has the parts' volumes; with no thin layer the callback path gives TetGen's own mesh.
#include "foxi/mesher/thin_layers.hpp"

#include <gtest/gtest.h>

#include "foxi/mesher/conforming.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/structure.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

TEST(ThinLayers, DieAttachIsTheOnlyThinLayer) {
  const Model model = load_model(test::data_dir() + "/cdt/die_attach.toml");
  const Structure s = build_structure(model);
  const std::vector<ThinLayer> layers = find_thin_layers(s.plc);
  ASSERT_EQ(layers.size(), 1u);
  const ThinLayer& l = layers[0];
  EXPECT_NEAR(std::abs(l.normal[2]), 1.0, 1e-12);
  EXPECT_NEAR(l.hi - l.lo, 20e-6, 1e-12);
  EXPECT_NEAR(l.u_hi - l.u_lo, 10e-3, 1e-12);
  EXPECT_NEAR(l.v_hi - l.v_lo, 10e-3, 1e-12);
  // A 1 mm substrate 14 mm wide is not thin at the default aspect, but is at 10 (with no area bound).
  EXPECT_GE(find_thin_layers(s.plc, 10, 0).size(), 2u);
  EXPECT_TRUE(find_thin_layers(s.plc, 0).empty());
  // Its area is 10^2 / 0.02^2 = 250,000 thicknesses squared: a layer at 200,000, not at 300,000.
  EXPECT_EQ(find_thin_layers(s.plc, kThinLayerAspect, 2e5).size(), 1u);
  EXPECT_TRUE(find_thin_layers(s.plc, kThinLayerAspect, 3e5).empty());
}

// The power module's 0.1 mm solder under a 30 x 22 mm DBC is 220 times wider than thick, but only
// 66,000 thicknesses squared in area: TetGen meshes it with the quality bounds (218 k tets at -q3), so
// it is not exempt. At a 20 um solder (1.65 M) it is.
TEST(ThinLayers, ExemptOnlyWhereTetgenWouldExplode) {
  const std::string path = test::data_dir() + "/../../models/power_module.toml";
  EXPECT_TRUE(find_thin_layers(build_structure(load_model(path)).plc).empty());
  const std::vector<std::string> thin{"solder_h=20 um"};
  const std::vector<ThinLayer> layers = find_thin_layers(build_structure(load_model(path, thin)).plc);
  ASSERT_FALSE(layers.empty());
  for (const ThinLayer& l : layers) EXPECT_NEAR(l.hi - l.lo, 20e-6, 1e-12);
  EXPECT_EQ(find_thin_layers(build_structure(load_model(path)).plc, kThinLayerAspect, 0).size(), 1u);
}
}  // namespace
}  // namespace foxi
