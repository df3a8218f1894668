// Model diagnostics (diagnostics.hpp) on small models written here, each with the answer worked out
// by hand from its geometry: a part floating above its substrate, a die wider than its attach (the
// exposed area is the die's area minus the attach's, or minus a regular 16-gon's for a cylinder),
// a part cut off from every fixed value in one physics but not another; and the shipped models,
// where the only warnings are the overhangs they were drawn with (the BGA package beyond its balls,
// the DBC ceramic's margin beyond its copper), at the areas their parameters give.
#include "foxi/model/diagnostics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "foxi/model/model_file.hpp"
#include "foxi/model/structure.hpp"
#include "structure_mesh.hpp"
#include "test_util.hpp"

namespace {

using foxi::ModelWarning;
using foxi::ModelWarningKind;
using foxi::Physics;
using foxi::test::box;
using foxi::test::kMm;
using foxi::test::kMm2;
using foxi::test::kMm3;
using foxi::test::kModels;
using foxi::test::ngon_area;
using foxi::test::TempDir;

struct Diagnosed {
  foxi::Model model;
  foxi::ModelDiagnostics d;
};

Diagnosed diagnose_file(const std::string& path) {
  Diagnosed r;
  r.model = foxi::load_model(path);
  r.d = foxi::diagnose_model(r.model, foxi::build_structure(r.model));
  return r;
}

Diagnosed diagnose_text(const std::string& text) {
  TempDir dir;
  foxi::test::write_text(dir / "m.toml", text);
  return diagnose_file((dir / "m.toml").string());
}

std::vector<ModelWarning> of_kind(const Diagnosed& x, ModelWarningKind kind) {
  std::vector<ModelWarning> out;
  for (const ModelWarning& w : x.d.warnings)
    if (w.kind == kind) out.push_back(w);
  return out;
}

std::string all(const Diagnosed& x) {
  std::string s;
  for (const ModelWarning& w : x.d.warnings) s += foxi::describe(w, x.model) + "\n";
  return s;
}

// Every property, so that each physics has its groups; "ins" carries no current.
const std::string kMaterials = R"TOML(units.length = "mm"
[materials.a]
thermal_conductivity = 1
electrical_conductivity = 1
relative_permittivity = 2
youngs_modulus = 1e9
poisson_ratio = 0.3
thermal_expansion = 1e-6
[materials.ins]
thermal_conductivity = 1
electrical_conductivity = 0
relative_permittivity = 2
youngs_modulus = 1e9
poisson_ratio = 0.3
thermal_expansion = 1e-6
)TOML";

std::string condition(const std::string& type, const std::string& surface, const std::string& rest) {
  return "[[conditions]]\ntype = \"" + type + "\"\nsurface = \"" + surface + "\"\n" + rest + "\n";
}

TEST(ModelDiagnostics, FloatingDieIsIsolatedAndNamed) {
  // a 10 x 10 x 1 mm substrate, a 4 x 4 x 0.5 mm die 1 mm above it, cooled on top
  const std::string text = kMaterials + box("substrate", 0, 0, 0, 10, 10, 1) +
                           box("die", 3, 3, 2, 4, 4, 0.5) +
                           condition("temperature", "substrate.bottom", "value = \"25 degC\"") +
                           condition("convection", "die.top", "h = 10\nambient = 300");
  const Diagnosed x = diagnose_text(text);
  const auto iso = of_kind(x, ModelWarningKind::isolated);
  ASSERT_EQ(iso.size(), 1u) << all(x);
  EXPECT_EQ(iso[0].parts, std::vector<std::string>{"die"});
  EXPECT_NEAR(iso[0].volume, 8 * kMm3, 1e-12 * kMm3);
  // the die's convection is a fixed value: the thermal problem is posed, only the geometry is wrong
  EXPECT_TRUE(of_kind(x, ModelWarningKind::no_fixed_value).empty()) << all(x);
  EXPECT_TRUE(of_kind(x, ModelWarningKind::overhang).empty()) << all(x);
  EXPECT_NE(foxi::describe(iso[0], x.model).find("part 'die' touches no other part"), std::string::npos);

  // on the substrate it is fine
  const Diagnosed on =
      diagnose_text(kMaterials + box("substrate", 0, 0, 0, 10, 10, 1) + box("die", 3, 3, 1, 4, 4, 0.5) +
                    condition("temperature", "substrate.bottom", "value = 300"));
  EXPECT_TRUE(on.d.warnings.empty()) << all(on);
}

TEST(ModelDiagnostics, ParkedAtAnEdgeTouchesNothing) {
  // two boxes meeting only along an edge share no area: nothing passes between them
  const Diagnosed x = diagnose_text(kMaterials + box("a1", 0, 0, 0, 1, 1, 1) + box("a2", 1, 1, 0, 1, 1, 2) +
                                    condition("temperature", "a1.bottom", "value = 300") +
                                    condition("temperature", "a2.bottom", "value = 300"));
  const auto iso = of_kind(x, ModelWarningKind::isolated);
  ASSERT_EQ(iso.size(), 1u) << all(x);
  EXPECT_EQ(iso[0].parts, std::vector<std::string>{"a1"});  // the smaller group
}

TEST(ModelDiagnostics, DieWiderThanItsAttachOverhangs) {
  // die 4 x 4 mm on a centred 2 x 2 mm attach: 16 - 4 = 12 mm^2 exposed, 3/4 of the die's bottom
  const std::string text = kMaterials + box("substrate", 0, 0, 0, 10, 10, 1) +
                           box("attach", 4, 4, 1, 2, 2, 0.1) + box("die", 3, 3, 1.1, 4, 4, 0.5) +
                           condition("temperature", "substrate.bottom", "value = 300");
  const Diagnosed x = diagnose_text(text);
  const auto over = of_kind(x, ModelWarningKind::overhang);
  ASSERT_EQ(over.size(), 1u) << all(x);
  EXPECT_EQ(over[0].parts, std::vector<std::string>{"die"});
  EXPECT_EQ(over[0].supports, std::vector<std::string>{"attach"});
  EXPECT_NEAR(over[0].z, 1.1 * kMm, 1e-12);
  EXPECT_NEAR(over[0].area, 12 * kMm2, 1e-9 * kMm2);
  EXPECT_NEAR(over[0].fraction, 0.75, 1e-9);
  EXPECT_EQ(x.d.warnings.size(), 1u) << all(x);

  // shifted by 1 mm: a 1 x 4 mm strip hangs over the attach's edge (attach 4 x 4 at x 4..8)
  const Diagnosed s = diagnose_text(kMaterials + box("substrate", 0, 0, 0, 10, 10, 1) +
                                    box("attach", 4, 3, 1, 4, 4, 0.1) + box("die", 3, 3, 1.1, 4, 4, 0.5) +
                                    condition("temperature", "substrate.bottom", "value = 300"));
  const auto so = of_kind(s, ModelWarningKind::overhang);
  ASSERT_EQ(so.size(), 1u) << all(s);
  EXPECT_NEAR(so[0].area, 4 * kMm2, 1e-9 * kMm2);
  EXPECT_NEAR(so[0].fraction, 0.25, 1e-9);
}

TEST(ModelDiagnostics, DieOnAPillarOverhangsByTheSquareLessThePolygon) {
  // a 16-segment cylinder of radius 1 mm under a 4 x 4 mm die: the contact is the inscribed 16-gon
  const std::string pillar =
      "[[parts]]\nname = \"pillar\"\nmaterial = \"a\"\nshape = \"cylinder\"\ncenter = [5, 5, 1]\n"
      "radius = 1\nheight = 0.2\nsegments = 16\n";
  const Diagnosed x = diagnose_text(kMaterials + box("substrate", 0, 0, 0, 10, 10, 1) + pillar +
                                    box("die", 3, 3, 1.2, 4, 4, 0.5) +
                                    condition("temperature", "substrate.bottom", "value = 300"));
  const auto over = of_kind(x, ModelWarningKind::overhang);
  ASSERT_EQ(over.size(), 1u) << all(x);
  const double want = 16 * kMm2 - ngon_area(16, 1 * kMm);
  EXPECT_NEAR(over[0].area, want, 1e-9 * want);
}

TEST(ModelDiagnostics, BridgeBetweenTwoPostsIsNoOverhang) {
  // a 4 x 4 mm plate on two 1 x 4 mm posts at its ends: its bottom between them is inside the
  // contact's hull (a clip, a lid); with the plate 1 mm wider than the posts' span it overhangs 4 mm^2
  const std::string posts =
      box("substrate", 0, 0, 0, 10, 10, 1) + box("p1", 3, 3, 1, 1, 4, 1) + box("p2", 6, 3, 1, 1, 4, 1);
  const Diagnosed x = diagnose_text(kMaterials + posts + box("plate", 3, 3, 2, 4, 4, 0.5) +
                                    condition("temperature", "substrate.bottom", "value = 300"));
  EXPECT_TRUE(x.d.warnings.empty()) << all(x);
  const Diagnosed wide = diagnose_text(kMaterials + posts + box("plate", 3, 3, 2, 5, 4, 0.5) +
                                       condition("temperature", "substrate.bottom", "value = 300"));
  const auto over = of_kind(wide, ModelWarningKind::overhang);
  ASSERT_EQ(over.size(), 1u) << all(wide);
  EXPECT_EQ(over[0].supports, (std::vector<std::string>{"p1", "p2"}));
  EXPECT_NEAR(over[0].area, 4 * kMm2, 1e-9 * kMm2);
}

TEST(ModelDiagnostics, PathToAFixedValueDependsOnThePhysics) {
  // base (a) / spacer (ins: no current) / top (a), stacked; a voltage on the base's bottom and a
  // current into the top. Electrostatics has the spacer's dielectric: one group, fixed. DC current
  // does not pass the spacer: the top has only a current, no voltage. Thermal: the convection on the
  // top fixes the whole stack. Thermoelastic: held at the base, the stack is bonded.
  std::string spacer = box("spacer", 0, 0, 1, 4, 4, 1);  // box() writes material "a"
  spacer.replace(spacer.find("material = \"a\""), 14, "material = \"ins\"");
  const std::string stack = box("base", 0, 0, 0, 4, 4, 1) + spacer + box("top", 0, 0, 2, 4, 4, 1);
  const std::string model = kMaterials + stack + condition("voltage", "base.bottom", "value = \"1 V\"") +
                            condition("current", "top.top", "value = \"1 mA\"") +
                            condition("convection", "top.top", "h = 10\nambient = \"25 degC\"") +
                            condition("displacement", "base.bottom", "value = [0, 0, 0]");
  const Diagnosed x = diagnose_text(model);
  const auto unfixed = of_kind(x, ModelWarningKind::no_fixed_value);
  ASSERT_EQ(unfixed.size(), 1u) << all(x);
  EXPECT_EQ(unfixed[0].physics, Physics::current);
  EXPECT_EQ(unfixed[0].parts, std::vector<std::string>{"top"});
  EXPECT_NEAR(unfixed[0].volume, 16 * kMm3, 1e-12 * kMm3);
  EXPECT_TRUE(of_kind(x, ModelWarningKind::isolated).empty()) << all(x);
  EXPECT_EQ(foxi::warnings_for(x.d, Physics::current).size(), 1u);
  EXPECT_TRUE(foxi::warnings_for(x.d, Physics::electrostatic).empty());
  EXPECT_NE(foxi::describe(unfixed[0], x.model).find("current: part 'top'"), std::string::npos)
      << foxi::describe(unfixed[0], x.model);

  // a ground on the interface spacer/top ties the top to a voltage
  const Diagnosed g = diagnose_text(model + condition("ground", "spacer/top", ""));
  EXPECT_TRUE(of_kind(g, ModelWarningKind::no_fixed_value).empty()) << all(g);
}

TEST(ModelDiagnostics, IslandWithoutConditionsIsCutOffInEveryPhysics) {
  // an island apart from a fixed slab: isolated, and in every physics with conditions a group with
  // no fixed value; held by a [surfaces] selector on its top, it is fixed (the selector's facets
  // keep their part)
  const std::string parts = box("slab", 0, 0, 0, 4, 4, 1) + box("island", 10, 0, 0, 1, 1, 1);
  const std::string conditions = condition("temperature", "slab.bottom", "value = 300") +
                                 condition("voltage", "slab.bottom", "value = 0") +
                                 condition("voltage", "slab.top", "value = 1") +
                                 condition("displacement", "slab.bottom", "value = [0, 0, 0]");
  const Diagnosed x = diagnose_text(kMaterials + parts + conditions);
  ASSERT_EQ(of_kind(x, ModelWarningKind::isolated).size(), 1u) << all(x);
  const auto unfixed = of_kind(x, ModelWarningKind::no_fixed_value);
  ASSERT_EQ(unfixed.size(), 4u) << all(x);
  const Physics order[] = {Physics::thermal, Physics::electrostatic, Physics::current,
                           Physics::thermal_stress};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(unfixed[i].physics, order[i]);
    EXPECT_EQ(unfixed[i].parts, std::vector<std::string>{"island"});
  }
  const Diagnosed held = diagnose_text(kMaterials + parts +
                                       "[surfaces.cold]\nbox = { min = [9, -1, 0.5], max = [12, 2, 1.5] }\n" +
                                       conditions + condition("temperature", "cold", "value = 300"));
  const auto left = of_kind(held, ModelWarningKind::no_fixed_value);
  ASSERT_EQ(left.size(), 3u) << all(held);
  for (const ModelWarning& w : left) EXPECT_NE(w.physics, Physics::thermal);
}

// Slow (every shipped model built, about 3 minutes under the sanitizers): the Release pass runs it.
TEST(ModelDiagnosticsSlow, ShippedModelsWarnOnlyAboutTheirDrawnOverhangs) {
  for (const char* name : {"die_on_substrate", "die_attach", "flip_chip", "multi_chip", "trench",
                           "via_in_dielectric", "bga", "power_module"}) {
    SCOPED_TRACE(name);
    const Diagnosed x = diagnose_file(kModels + name + ".toml");
    EXPECT_TRUE(of_kind(x, ModelWarningKind::isolated).empty()) << all(x);
    EXPECT_TRUE(of_kind(x, ModelWarningKind::no_fixed_value).empty()) << all(x);
    const auto over = of_kind(x, ModelWarningKind::overhang);
    if (std::string(name) == "power_module") {
      // the alumina is 32 x 24 mm (a 1 mm margin) on 30 x 22 mm of copper: 768 - 660 mm^2
      ASSERT_EQ(over.size(), 1u) << all(x);
      EXPECT_EQ(over[0].parts, std::vector<std::string>{"ceramic"});
      EXPECT_EQ(over[0].supports, std::vector<std::string>{"dbc_bottom"});
      EXPECT_NEAR(over[0].area, 108 * kMm2, 1e-9 * kMm2);
      EXPECT_NEAR(over[0].fraction, 108.0 / 768, 1e-9);
    } else if (std::string(name) == "bga") {
      // the 6 x 6 mm package on a 3 x 3 array of balls at a 2 mm pitch, each cut by the package's
      // bottom 0.3 mm above its centre: contact circles of radius sqrt(0.38^2 - 0.3^2) mm at the
      // corners of a 4 mm square, whose hull is 16 + 4 * 4 r + pi r^2; the facets lie inside the
      // circles, by at most the faceting tolerance 0.004 mm over the hull's perimeter
      ASSERT_EQ(over.size(), 1u) << all(x);
      EXPECT_EQ(over[0].parts, std::vector<std::string>{"package"});
      EXPECT_EQ(over[0].supports, std::vector<std::string>{"balls"});
      const double r = std::sqrt(0.38 * 0.38 - 0.3 * 0.3);
      const double exposed = (36 - (16 + 16 * r + std::numbers::pi * r * r)) * kMm2;
      const double slack = (16 + 2 * std::numbers::pi * r) * 0.004 * kMm2;
      EXPECT_GE(over[0].area, exposed - 1e-9 * kMm2);
      EXPECT_LE(over[0].area, exposed + slack);
    } else {
      EXPECT_TRUE(over.empty()) << all(x);
    }
  }
}

}  // namespace
