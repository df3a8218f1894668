// Validation on hand-made broken meshes: each defect is planted, so the expected counts are known.
#include "foxi/model/validate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "../../bench/bench_meshes.hpp"
#include "foxi/model/adjacency.hpp"

namespace foxi {
namespace {

// Two positively oriented tets sharing the face (1,2,3): det[B,C,D] > 0 by hand.
Mesh two_tets() {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  m.tet = {0, 1, 2, 3, 1, 4, 2, 3};
  return m;
}

bool mentions(const ValidationReport& r, const std::string& text) {
  for (const auto& m : r.messages)
    if (m.find(text) != std::string::npos) return true;
  return false;
}

TEST(Validate, CleanMeshesPass) {
  ValidationReport r = validate(two_tets());
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.inverted + r.unused_nodes + r.zero_volume, 0u);
  EXPECT_TRUE(r.messages.empty());
  ValidationReport g = validate(bench::kuhn_grid_mesh(5));
  EXPECT_TRUE(g.ok());
  EXPECT_EQ(g.inverted, 0u);
  EXPECT_EQ(g.unused_nodes, 0u);
}

TEST(Validate, SizeProblemStopsTheCheck) {
  Mesh m = two_tets();
  m.tet.push_back(0);  // 9 indices
  ValidationReport r = validate(m);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.size_problem, check_sizes(m));
  EXPECT_FALSE(r.size_problem.empty());
  Mesh w = two_tets();
  w.weight = {1, 2};
  EXPECT_FALSE(validate(w).size_problem.empty());
}

TEST(Validate, IndexOutOfRange) {
  Mesh m = two_tets();
  m.tet[6] = 5;  // tet 1, node count 5
  m.bface = {0, 1, 7};
  m.bface_tag = {1};
  ValidationReport r = validate(m);
  EXPECT_EQ(r.index_out_of_range, 2u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "tet 1"));
  EXPECT_TRUE(mentions(r, "boundary triangle 0"));
}

TEST(Validate, RepeatedVertex) {
  Mesh m = two_tets();
  m.tet[7] = 1;  // tet 1 = (1 4 2 1)
  ValidationReport r = validate(m);
  EXPECT_EQ(r.repeated_vertex, 1u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "tet 1"));
}

TEST(Validate, NonFiniteCoordinates) {
  Mesh m = two_tets();
  m.xyz[3 * 4 + 1] = std::numeric_limits<double>::quiet_NaN();
  m.xyz[3 * 2] = std::numeric_limits<double>::infinity();
  ValidationReport r = validate(m);
  EXPECT_EQ(r.nonfinite_nodes, 2u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "node 4"));
}

// Found by fuzzing (tests/data/bad/fuzz/mesh_pipeline/infinite_weight): an infinite vertex weight
// passed validation, and the sphere table then crashed in GMP (SIGFPE converting it exactly).
TEST(Validate, NonFiniteWeights) {
  Mesh m = two_tets();
  m.weight = {0, 0, std::numeric_limits<double>::infinity(), 0, std::numeric_limits<double>::quiet_NaN()};
  ValidationReport r = validate(m);
  EXPECT_EQ(r.nonfinite_nodes, 2u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "node 2: non-finite weight"));
  EXPECT_TRUE(mentions(r, "node 4: non-finite weight"));
}

TEST(Validate, ZeroVolumeExactly) {
  // Tet 0 lies exactly in the plane z = x (the stored doubles satisfy it exactly); tet 1 is lifted
  // off that plane by one unit in the last place, which an exact predicate must still see.
  Mesh m;
  const double a = 0.1, b = 0.7, c = 0.3, d = 1.0 / 3.0;
  m.xyz = {a, 0.0, a, b, 0.3, b, c, 0.9, c, d, 0.2, d, d, 0.2, std::nextafter(d, 1.0)};
  m.tet = {0, 1, 2, 3, 0, 1, 2, 4};
  ValidationReport r = validate(m);
  EXPECT_EQ(r.zero_volume, 1u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "tet 0"));
  EXPECT_FALSE(mentions(r, "tet 1 (0 1 2 4): zero"));
}

TEST(Validate, InvertedTetsRepaired) {
  Mesh m = bench::kuhn_grid_mesh(3);
  // Invert tets 5 and 17 by swapping two vertices.
  std::swap(m.tet[4 * 5 + 0], m.tet[4 * 5 + 1]);
  std::swap(m.tet[4 * 17 + 1], m.tet[4 * 17 + 3]);
  const FaceAdjacency before = face_adjacency(m);  // cached, must be dropped by the repair
  ValidationReport r = validate(m);
  EXPECT_EQ(r.inverted, 2u);
  EXPECT_TRUE(r.ok());  // a warning only
  EXPECT_TRUE(mentions(r, "tet 5"));
  EXPECT_TRUE(mentions(r, "tet 17"));
  ValidationReport rr = validate_and_repair(m);
  EXPECT_EQ(rr.inverted, 2u);
  EXPECT_EQ(validate(m).inverted, 0u);
  // The repair swapped the last two vertices, so the faces of those tets moved: a fresh adjacency
  // (not the stale cached one) must come back.
  EXPECT_EQ(face_adjacency(m).neighbour, compute_face_adjacency(m).neighbour);
  EXPECT_NE(face_adjacency(m).neighbour, before.neighbour);
}

TEST(Validate, UnusedNodes) {
  Mesh m = two_tets();
  m.xyz.insert(m.xyz.end(), {5, 5, 5, 6, 6, 6});
  ValidationReport r = validate(m);
  EXPECT_EQ(r.unused_nodes, 2u);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(mentions(r, "node 5"));
}

TEST(Validate, MessagesAreFewButCountsComplete) {
  Mesh m = bench::kuhn_grid_mesh(4);
  for (std::size_t t = 0; t < m.tet_count(); ++t) m.tet[4 * t + 3] = m.tet[4 * t];  // all repeated
  ValidationReport r = validate(m);
  EXPECT_EQ(r.repeated_vertex, m.tet_count());
  EXPECT_LE(r.messages.size(), 50u);
  EXPECT_GT(r.messages.size(), 0u);
}

}  // namespace
}  // namespace foxi
