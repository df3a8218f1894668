// MeshView (mesh_view.hpp): a view over a host's arrays validates, pairs faces and certifies exactly
// as the same arrays copied into a foxi::Mesh (the oracle: the Mesh path, tested against brute force
// in adjacency_test and delaunay_test); its derived data lives in the host's DerivedCache and is
// recomputed when the host's arrays move.
#include "foxi/model/mesh_view.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/validate.hpp"

namespace foxi {
namespace {

// n^3 cubes of 6 Kuhn tets (a Delaunay mesh: all cospherical per cube), positively oriented.
void kuhn_grid(int n, std::vector<double>& xyz, std::vector<std::uint32_t>& tet) {
  const auto id = [&](int i, int j, int k) { return std::uint32_t((k * (n + 1) + j) * (n + 1) + i); };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) xyz.insert(xyz.end(), {double(i), double(j), double(k)});
  const int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {1, 0, 2}, {2, 1, 0}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int p = 0; p < 6; ++p) {
          int c[3] = {i, j, k};
          std::uint32_t v[4] = {id(i, j, k), 0, 0, 0};
          for (int s = 0; s < 3; ++s) {
            ++c[perms[p][s]];
            v[s + 1] = id(c[0], c[1], c[2]);
          }
          if (p >= 3) std::swap(v[2], v[3]);
          tet.insert(tet.end(), v, v + 4);
        }
}

TEST(MeshView, AgreesWithTheSameArraysInAMesh) {
  std::vector<double> xyz;
  std::vector<std::uint32_t> tet;
  kuhn_grid(4, xyz, tet);
  Mesh mesh;
  mesh.xyz = xyz;
  mesh.tet = tet;
  DerivedCache cache;
  const MeshView view{xyz, tet, {}, {}, {}, &cache};
  EXPECT_EQ(check_sizes(view), "");
  EXPECT_TRUE(validate(view).clean());
  EXPECT_EQ(face_adjacency(view).neighbour, face_adjacency(mesh).neighbour);
  EXPECT_EQ(face_adjacency(view).boundary_faces, 6u * 16 * 2);
  EXPECT_TRUE(delaunay_certificate(view).delaunay);
  EXPECT_EQ(&face_adjacency(view), &face_adjacency(view));  // kept in the host's cache

  // An inverted tet and a point moved into a neighbour's sphere are seen in the view as in the Mesh.
  std::swap(tet[2], tet[3]);
  xyz[3 * 31] += 0.4;
  mesh.tet = tet;
  mesh.xyz = xyz;
  cache.clear();  // the host changed its arrays in place
  EXPECT_EQ(validate(view).inverted, validate(mesh).inverted);
  EXPECT_EQ(validate(view).inverted, 1u);
  const DelaunayCertificate a = compute_delaunay_certificate(view), b = compute_delaunay_certificate(mesh);
  EXPECT_FALSE(a.delaunay);
  EXPECT_EQ(a.violating_tets, b.violating_tets);
}

TEST(MeshView, CacheFollowsTheArrays) {
  std::vector<double> xyz;
  std::vector<std::uint32_t> tet;
  kuhn_grid(2, xyz, tet);
  DerivedCache cache;
  const FaceAdjacency& first = face_adjacency(MeshView{xyz, tet, {}, {}, {}, &cache});
  EXPECT_EQ(first.boundary_faces, 6u * 4 * 2);  // 6 sides of 2 x 2 squares, 2 triangles each
  EXPECT_EQ(2 * first.interior_faces + first.boundary_faces, tet.size());
  // The same cache handed a grown copy of the arrays (other data, other sizes): recomputed, not reused.
  std::vector<double> xyz3;
  std::vector<std::uint32_t> tet3;
  kuhn_grid(3, xyz3, tet3);
  const FaceAdjacency& second = face_adjacency(MeshView{xyz3, tet3, {}, {}, {}, &cache});
  EXPECT_EQ(second.neighbour.size(), tet3.size());
  EXPECT_EQ(second.boundary_faces, 6u * 9 * 2);
}

TEST(MeshView, SizesAndMissingCacheAreReported) {
  std::vector<double> xyz;
  std::vector<std::uint32_t> tet;
  kuhn_grid(1, xyz, tet);
  const std::vector<std::int32_t> region(5, 1);  // 6 tets
  EXPECT_NE(check_sizes(MeshView{xyz, tet, region}).find("tet_region has 5 entries for 6 tets"),
            std::string::npos);
  EXPECT_FALSE(validate(MeshView{xyz, tet, region}).ok());
  EXPECT_NE(check_sizes(MeshView{std::span<const double>(xyz).first(7), tet}).find("multiple of 3"),
            std::string::npos);
  EXPECT_THROW(face_adjacency(MeshView{xyz, tet}), std::invalid_argument);
}

}  // namespace
}  // namespace foxi
