// region_id_of and boundary_tag_of (mesh.hpp): names and numbers as a user writes them, on a mesh
// whose regions and boundaries are listed here by hand.
#include <gtest/gtest.h>

#include "foxi/model/mesh.hpp"

namespace foxi {
namespace {

Mesh named_mesh() {
  Mesh m;
  m.regions = {{1, "substrate", kNone}, {7, "die", kNone}, {9, "", kNone}};
  m.boundaries = {{3, "die.top"}, {12, "bottom"}};
  return m;
}

TEST(MeshLookup, NamesAndNumbers) {
  const Mesh m = named_mesh();
  EXPECT_EQ(region_id_of(m, "die"), 7);
  EXPECT_EQ(region_id_of(m, "substrate"), 1);
  EXPECT_EQ(region_id_of(m, "7"), 7);
  EXPECT_EQ(region_id_of(m, "42"), 42) << "a number is an id as it is, listed or not";
  EXPECT_EQ(region_id_of(m, "-3"), -3);
  EXPECT_EQ(region_id_of(m, "lid"), std::nullopt);
  EXPECT_EQ(region_id_of(m, ""), std::nullopt) << "the unnamed region is not found by an empty name";
  EXPECT_EQ(region_id_of(m, "7x"), std::nullopt);
  EXPECT_EQ(boundary_tag_of(m, "die.top"), 3);
  EXPECT_EQ(boundary_tag_of(m, "bottom"), 12);
  EXPECT_EQ(boundary_tag_of(m, "12"), 12);
  EXPECT_EQ(boundary_tag_of(m, "die"), std::nullopt) << "region names are not boundary names";
  EXPECT_EQ(region_id_of(m, "bottom"), std::nullopt);
}

}  // namespace
}  // namespace foxi
