// The front ends' option parsers (view_options.hpp) and the palette (palette.hpp). Oracles: subsets
// of a structured grid whose cells are known (a box holding whole cells selects 5 tets per cell),
// the region ids assigned here, the camera_from_options call written out by hand, and the exploded
// mesh's tets compared corner by corner with the original's, lifted by the region's gap.
#include "foxi/viz/view_options.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/palette.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "mesh_factory.hpp"

namespace foxi {
namespace {

TEST(ViewOptions, RegionOpacitiesByIdOrName) {
  Mesh m = test::grid_mesh(4, 3, 2, 1.0, 1.0, 1.0, 5);
  test::regions_along_x(m, 1.0, 3.0);
  m.regions = {{1, "mould", kNone}, {2, "die=2", kNone}, {3, "bumps", kNone}};
  const std::vector<RegionOpacity> r = parse_region_opacity(m, "mould=0.25,3=1,die=2=0");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].region, 1);
  EXPECT_EQ(r[0].opacity, 0.25);
  EXPECT_EQ(r[1].region, 3);
  EXPECT_EQ(r[1].opacity, 1.0);
  EXPECT_EQ(r[2].region, 2) << "the last '=' splits: a name may hold one";
  EXPECT_EQ(r[2].opacity, 0.0);
  EXPECT_THROW(parse_region_opacity(m, "mould"), OptionError);
  EXPECT_THROW(parse_region_opacity(m, "=0.5"), OptionError);
  EXPECT_THROW(parse_region_opacity(m, "nosuch=0.5"), OptionError);
  EXPECT_THROW(parse_region_opacity(m, "mould=1.01"), OptionError);
  EXPECT_THROW(parse_region_opacity(m, "mould=nan"), OptionError);
  EXPECT_THROW(parse_region_opacity(m, "mould=0.5,1=0.2"), OptionError) << "region 1 twice";
  EXPECT_THROW(parse_region_opacity(m, "mould=0.5,"), OptionError);
  EXPECT_EQ(parse_opacity("0.5", "--iso-opacity"), 0.5);
  EXPECT_THROW(parse_opacity("-0.1", "--iso-opacity"), OptionError);
  EXPECT_THROW(parse_opacity("", "--iso-opacity"), OptionError);
}

TEST(ViewOptions, OpacityCurve) {
  const std::vector<OpacityPoint> c = parse_opacity_curve("20:0,45.5:0.25,60:0.9");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[1].value, 45.5);
  EXPECT_EQ(c[1].opacity, 0.25);
  EXPECT_THROW(parse_opacity_curve("20"), OptionError);
  EXPECT_THROW(parse_opacity_curve("20:1"), OptionError) << "opacity 1 has no finite extinction";
  EXPECT_THROW(parse_opacity_curve("20:0.99999999"), OptionError) << "drawn as 0.999999: refused";
  EXPECT_EQ(parse_opacity_curve("20:0.999999")[0].opacity, 0.999999);
  EXPECT_THROW(parse_opacity_curve("20:0.1,10:0.2"), OptionError);
  EXPECT_THROW(parse_opacity_curve("20:0.1,20:0.2"), OptionError);
  EXPECT_THROW(parse_opacity_curve("a:0.1"), OptionError);
}

TEST(ViewOptions, SubsetsOfAGrid) {
  Mesh m = test::grid_mesh(4, 3, 2, 1.0, 1.0, 1.0, 5);  // 24 unit cells, 5 tets each
  test::regions_along_x(m, 1.0, 3.0);                   // x in [0,1]: 1, [1,3]: 2, [3,4]: 3
  // The cells with x in [1, 3], y in [0, 2], all z: 2 x 2 x 2 = 8 cells (centroids strictly inside).
  const auto box = parse_subset(m, "box:1,0,0,3,2,2", 1);
  EXPECT_EQ(box.size(), 8u * 5u);
  const auto regions = parse_subset(m, "regions:1,3", 1);
  EXPECT_EQ(regions.size(), 2u * 6u * 5u);  // the cells of x in [0,1] and [3,4]: 6 each
  for (std::uint32_t t : regions) EXPECT_NE(m.region_of(t), 2);
  EXPECT_EQ(parse_subset(m, "regions:1,1,3", 1), regions) << "each tet once";
  const auto random = parse_subset(m, "random:0.5", 3);
  EXPECT_GT(random.size(), 20u);
  EXPECT_LT(random.size(), 100u);
  EXPECT_EQ(parse_subset(m, "random:0.5", 3), random) << "the seed decides";
  EXPECT_EQ(std::set<std::uint32_t>(random.begin(), random.end()).size(), random.size());
  EXPECT_THROW(parse_subset(m, "regions:9", 1), OptionError);  // selects none
  EXPECT_THROW(parse_subset(m, "box:1,2,3", 1), OptionError);
  EXPECT_THROW(parse_subset(m, "sphere:1", 1), OptionError);
  EXPECT_THROW(parse_subset(m, "regions:a", 1), OptionError);
  EXPECT_EQ(tets_of_regions(m, "2", "--regions").size(), 12u * 5u);
}

TEST(ViewOptions, CameraSizeAndShrink) {
  const CameraOptions o = parse_camera_options("3,-4,5", "", "0,0,1", "40", "");
  EXPECT_TRUE(o.has_eye && o.has_up && !o.has_at && !o.has_dir);
  EXPECT_EQ(o.eye[1], -4);
  EXPECT_EQ(o.fov_deg, 40);
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3}, eye[3] = {3, -4, 5}, up[3] = {0, 0, 1};
  const Camera a = camera_for(o, lo, hi, 1.5);
  const Camera b = camera_from_options(lo, hi, 1.5, eye, nullptr, up, 40, nullptr);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.eye[k], b.eye[k]);
    EXPECT_EQ(a.at[k], b.at[k]);
  }
  EXPECT_EQ(a.fov_deg, b.fov_deg);
  EXPECT_THROW(parse_camera_options("1,2,3", "", "", "", "0,0,1"), OptionError);  // --dir with --eye
  EXPECT_THROW(parse_camera_options("", "", "", "", "0,0,0"), OptionError);
  EXPECT_THROW(parse_camera_options("1,2", "", "", "", ""), OptionError);
  EXPECT_THROW(parse_camera_options("", "", "", "180", ""), OptionError);
  EXPECT_THROW(parse_camera_options("", "nan,0,0", "", "", ""), OptionError);
  const ImageSize s = parse_image_size("640x480");
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 480);
  for (const char* bad : {"640", "x480", "0x10", "16385x10", "64ax48", ""})
    EXPECT_THROW(parse_image_size(bad), OptionError) << bad;
  EXPECT_EQ(parse_shrink("0.8"), 0.8);
  for (const char* bad : {"0", "1.5", "-1", "a"}) EXPECT_THROW(parse_shrink(bad), OptionError) << bad;
  // Cameras a projection cannot use, refused as options (they were "degenerate" errors at drawing):
  // the eye on the point looked at (given, or the box centre --at defaults to), too far to square
  // its distance, an up along the view.
  EXPECT_THROW(camera_for(parse_camera_options("1,1,1", "1,1,1", "", "", ""), lo, hi, 1.5), OptionError);
  EXPECT_THROW(camera_for(parse_camera_options("0.5,1,1.5", "", "", "", ""), lo, hi, 1.5), OptionError);
  EXPECT_THROW(camera_for(parse_camera_options("1e300,0,0", "", "", "", ""), lo, hi, 1.5), OptionError);
  EXPECT_THROW(camera_for(parse_camera_options("0,0,5", "0,0,0", "0,0,1", "", ""), lo, hi, 1.5), OptionError);
  // A direction's length does not matter, however small: the same camera as its unit multiple.
  const Camera tiny = camera_for(parse_camera_options("", "", "", "", "1e-300,0,1e-300"), lo, hi, 1.5);
  const Camera unit = camera_for(parse_camera_options("", "", "", "", "1,0,1"), lo, hi, 1.5);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(tiny.eye[k], unit.eye[k]);
  EXPECT_DOUBLE_EQ(tiny.ortho_height, unit.ortho_height);
}

TEST(Palette, ExplodedMeshLiftsEachRegion) {
  Mesh m = test::grid_mesh(3, 1, 1, 1.0, 1.0, 1.0, 6);
  test::regions_along_x(m, 1.0, 2.0);
  const double gap = 0.25;
  const Mesh e = exploded_mesh(m, gap);
  ASSERT_EQ(e.tet_count(), m.tet_count());
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    ASSERT_EQ(e.region_of(t), m.region_of(t));
    for (int v = 0; v < 4; ++v)
      for (int k = 0; k < 3; ++k) {
        const double lift = k == 2 ? gap * (m.region_of(t) - 1) : 0;
        EXPECT_EQ(e.xyz[3 * std::size_t(e.tet[4 * t + std::size_t(v)]) + std::size_t(k)],
                  m.xyz[3 * std::size_t(m.tet[4 * t + std::size_t(v)]) + std::size_t(k)] + lift);
      }
  }
  // Nodes on a region interface are copied once per region: 16 grid nodes, the 2 interfaces' 4 each again.
  EXPECT_EQ(e.node_count(), 16u + 8u);
  EXPECT_EQ(material_color("copper", 0), pack_rgba(200, 117, 51));
  EXPECT_EQ(material_color("unobtainium", 4), region_color(4));
}

}  // namespace
}  // namespace foxi
