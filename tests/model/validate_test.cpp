// Validation on hand-made broken meshes: each defect is planted, so the expected counts are known.
#include "foxi/model/validate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "bench_meshes.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "../test_util.hpp"

namespace foxi {
namespace {

// Two positively oriented tets sharing the face (1,2,3): det[B,C,D] > 0 by hand.
Mesh two_tets() {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  m.tet = {0, 1, 2, 3, 1, 4, 2, 3};
  return m;
}

// Whether what a user is shown (describe's summary lines, then the per-element messages) says `text`.
bool mentions(const ValidationReport& r, const std::string& text) {
  for (const auto& m : describe(r))
    if (m.find(text) != std::string::npos) return true;
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

TEST(Validate, EmptyMeshIsUnusable) {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0};
  ValidationReport r = validate(m);
  EXPECT_TRUE(r.no_tets);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "no tets"));
  EXPECT_FALSE(validate(Mesh{}).ok());
  EXPECT_FALSE(validate(two_tets()).no_tets);
}

TEST(Validate, DuplicateTetsAreErrors) {
  Mesh m = two_tets();
  m.tet.insert(m.tet.end(), {3, 2, 1, 0});  // tet 0's nodes in another order (inverted, too)
  m.tet.insert(m.tet.end(), {1, 4, 2, 3});  // tet 1 again
  ValidationReport r = validate(m);
  EXPECT_EQ(r.duplicate_tets, 2u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "the same nodes as tet 0"));
  EXPECT_TRUE(mentions(r, "the same nodes as tet 1"));
  // Sharing three nodes is no duplicate.
  EXPECT_EQ(validate(two_tets()).duplicate_tets, 0u);
}

TEST(Validate, CoincidentUsedNodesAreErrors) {
  // Tet 1 uses node 5, a copy of node 1: the two tets no longer share their face (a tear).
  Mesh m = two_tets();
  m.xyz.insert(m.xyz.end(), {1, 0, 0});
  m.tet[4] = 5;
  ValidationReport r = validate(m);
  EXPECT_EQ(r.duplicate_nodes, 1u);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(mentions(r, "nodes 1 and 5"));
  // A copy that no tet uses is only an unused node.
  Mesh u = two_tets();
  u.xyz.insert(u.xyz.end(), {1, 0, 0});
  ValidationReport ru = validate(u);
  EXPECT_EQ(ru.duplicate_nodes, 0u);
  EXPECT_EQ(ru.unused_nodes, 1u);
  EXPECT_TRUE(ru.ok());
  // -0.0 and 0.0 are one point.
  Mesh z = two_tets();
  z.xyz.insert(z.xyz.end(), {1, -0.0, -0.0});  // node 1 = (1, 0, 0), still used by tet 0
  z.tet[4] = 5;
  EXPECT_EQ(validate(z).duplicate_nodes, 1u);
}

// The volume of two_tets() scaled by s, computed as the solvers do (double determinant / 6).
double scaled_volume(double s) {
  const double B[3] = {s, 0, 0}, C[3] = {0, s, 0}, D[3] = {0, 0, s};
  return (B[0] * (C[1] * D[2] - C[2] * D[1]) - B[1] * (C[0] * D[2] - C[2] * D[0]) +
          B[2] * (C[0] * D[1] - C[1] * D[0])) /
         6;
}

TEST(Validate, GeometryBeyondDoubleRangeIsRefused) {
  // The cases: coordinates scaled by 1e154 (volumes overflow to inf), near 1e300, and
  // near 1e-300 (volumes underflow to 0 while the exact orientation is still positive).
  for (double s : {1e154, 1e300, 1e-300, 1e-120, 1e100}) {
    Mesh m = two_tets();
    for (double& x : m.xyz) x *= s;
    ValidationReport r = validate(m);
    EXPECT_EQ(r.out_of_range, 2u) << s;
    EXPECT_FALSE(r.ok()) << s;
    EXPECT_EQ(r.inverted + r.zero_volume, 0u) << s;
    EXPECT_TRUE(mentions(r, "beyond the range")) << s;
  }
  EXPECT_FALSE(std::isfinite(scaled_volume(1e154)));  // what went unnoticed
  EXPECT_EQ(scaled_volume(1e-300), 0.0);
}

// A flat sliver of normal size (a mesher's four nearly coplanar corners: 6V cancels to nothing in
// double while the exact orientation is positive) is said to be one, to mesh again; rescaling, which
// the message once advised, cannot mend it.
TEST(Validate, NearlyFlatTetOfNormalSizeIsSaidToBeOne) {
  Mesh m;
  m.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1e-300};
  m.tet = {0, 1, 2, 3};
  const ValidationReport r = validate(m);
  EXPECT_EQ(r.out_of_range, 1u);
  EXPECT_EQ(r.zero_volume, 0u);
  EXPECT_TRUE(mentions(r, "nearly flat")) << describe(r).front();
  EXPECT_FALSE(mentions(r, "rescale"));
}

// A tet both inverted and beyond the range (issue 17 item 7): one message naming both problems, not
// two lines about the same tet; the counts still count it under each problem.
TEST(Validate, InvertedTetBeyondTheRangeHasOneMessage) {
  for (double s : {1e154, 1e-300}) {
    Mesh m = two_tets();
    for (double& x : m.xyz) x *= s;
    std::swap(m.tet[4 * 1 + 0], m.tet[4 * 1 + 1]);  // tet 1 inverted
    const ValidationReport r = validate(m);
    EXPECT_EQ(r.inverted, 1u) << s;
    EXPECT_EQ(r.out_of_range, 2u) << s;
    std::size_t about_tet1 = 0;
    for (const std::string& msg : r.messages) about_tet1 += msg.rfind("tet 1 ", 0) == 0;
    EXPECT_EQ(about_tet1, 1u) << s;
    EXPECT_TRUE(mentions(r, "inverted")) << s;
    EXPECT_TRUE(mentions(r, "beyond the range")) << s;
  }
}

// Coordinates above 1e60 (issue 22's audit): a mesh moved far from the origin keeps finite, positive
// volumes, but at 1e60 doubles are 1e44 apart, so no tet there is smaller than that, and its
// circumsphere reaches past the 1e24 the order's error bounds hold: refused, whatever the offset.
TEST(Validate, CoordinatesAbove1e60AreRefusedEvenWithFiniteVolumes) {
  for (const auto& [offset, size] :
       {std::pair{1e60, 1e50}, std::pair{1e60, 1e45}, std::pair{1e61, 1e61}, std::pair{-1e100, 1e90}}) {
    Mesh m = two_tets();
    for (double& x : m.xyz) x = offset + size * x;
    const ValidationReport r = validate(m);
    EXPECT_FALSE(r.ok()) << offset << " " << size;
    EXPECT_TRUE(mentions(r, "beyond the range")) << offset << " " << size;
    EXPECT_TRUE(std::isfinite(size * size * size)) << "the volumes themselves do not overflow";
  }
}

TEST(Validate, AcceptedGeometryHasFiniteExactlyScaledVolumes) {
  // For every power of ten that validation accepts, the double volume is finite, positive and
  // equals s^3 / 6 (the analytic volume of the scaled corner tet) to rounding. The accepted powers
  // are one unbroken range covering every physical scale in SI units (1e-9 .. 1e20 m), and stop
  // before the visibility order's float error bounds fail (circumspheres reaching 1e24, or a mesh
  // under 1e-12 across).
  int accepted_lo = 1000, accepted_hi = -1000, accepted = 0;
  for (int k = -320; k <= 308; ++k) {
    const double s = std::pow(10.0, k);
    Mesh m = two_tets();
    for (double& x : m.xyz) x *= s;
    if (!validate(m).ok()) continue;
    ++accepted;
    accepted_lo = std::min(accepted_lo, k);
    accepted_hi = std::max(accepted_hi, k);
    const double v = scaled_volume(s), expected = static_cast<double>(std::pow(10.0L, 3 * k) / 6);
    ASSERT_TRUE(std::isfinite(v) && v > 0) << k;
    EXPECT_NEAR(v / expected, 1.0, 1e-14) << k;
  }
  EXPECT_EQ(accepted, accepted_hi - accepted_lo + 1);
  EXPECT_LE(accepted_lo, -9);
  EXPECT_GE(accepted_hi, 20);
  EXPECT_GE(accepted_lo, -12);  // 2 x 1e-13 across: refused
  EXPECT_LE(accepted_hi, 24);   // spheres reaching 1.7e24: refused
}

// Overlapping tets. Each mesh below passes every local check (indices, orientation, volume,
// duplicates) and yet two of its tets cover the same space; each was found by fuzzing or is the
// smallest case of one kind. The oracle is the construction: the overlap is planted.

// The six Kuhn tets of the cube [0,2]^3 around its diagonal 0-7 (node i at (2(i&1), 2(i>>1&1), 2(i>>2&1))).
Mesh kuhn_cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i) {
    m.xyz.push_back(2.0 * (i & 1));
    m.xyz.push_back(2.0 * (i >> 1 & 1));
    m.xyz.push_back(2.0 * (i >> 2 & 1));
  }
  m.tet = {0, 1, 3, 7, 0, 1, 5, 7, 0, 2, 3, 7, 0, 2, 6, 7, 0, 4, 5, 7, 0, 4, 6, 7};
  return m;
}

TEST(ValidateOverlap, KuhnCubeIsOneMesh) {
  Mesh m = kuhn_cube();
  ValidationReport r = validate_and_repair(m);
  EXPECT_TRUE(r.ok()) << (r.messages.empty() ? "" : r.messages[0]);
  EXPECT_EQ(r.overlapping, 0u);
}

TEST(ValidateOverlap, TetAcrossTheCubeIsRefused) {
  // Found by fuzz_mesh_pipeline: tet (0,1,3,7) replaced by (6,1,3,7), which cuts through its
  // neighbours. Every face is shared by at most two tets on opposite sides, so only the boundary
  // crossing itself shows the overlap. The undoable painter then disagreed with a fresh drawing.
  Mesh m = kuhn_cube();
  m.tet[0] = 6;
  ValidationReport r = validate_and_repair(m);
  EXPECT_FALSE(r.ok());
  EXPECT_GT(r.overlapping, 0u);
  EXPECT_TRUE(mentions(r, "overlap")) << (r.messages.empty() ? "" : r.messages[0]);
}

TEST(ValidateOverlap, FoldedFaceIsRefused) {
  // Two tets on the same side of their shared face (1,2,3).
  Mesh m = two_tets();
  m.xyz[12] = m.xyz[13] = m.xyz[14] = 0.1;  // node 4 moved to the side of node 0
  ValidationReport r = validate_and_repair(m);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.overlapping, 1u);
  EXPECT_TRUE(mentions(r, "same side of their shared face"));
}

TEST(ValidateOverlap, FaceOfThreeTetsIsRefused) {
  Mesh m = two_tets();
  m.xyz.insert(m.xyz.end(), {2, 2, 2});
  m.tet.insert(m.tet.end(), {1, 5, 2, 3});
  ValidationReport r = validate_and_repair(m);
  EXPECT_FALSE(r.ok());
  EXPECT_GT(r.overlapping, 0u);
  EXPECT_TRUE(mentions(r, "three or more tets"));
}

TEST(ValidateOverlap, MeshInsideAnotherIsRefused) {
  // A small tet strictly inside a large one, sharing no node: no face is shared and no boundary face
  // crosses another, so only the covering count finds it.
  Mesh m;
  m.xyz = {0, 0, 0, 10, 0, 0, 0, 10, 0, 0, 0, 10, 1, 1, 1, 2, 1, 1, 1, 2, 1, 1, 1, 2};
  m.tet = {0, 1, 2, 3, 4, 5, 6, 7};
  ValidationReport r = validate_and_repair(m);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.overlapping, 1u);
  EXPECT_TRUE(mentions(r, "covers the inside of tet"));
}

TEST(ValidateOverlap, TouchingAtAVertexOrAnEdgeIsAllowed) {
  // Two tets meeting in one vertex, and two meeting in one edge, coplanar faces included: a mesh.
  Mesh vertex;
  vertex.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1};
  vertex.tet = {0, 1, 2, 3, 0, 4, 5, 6};
  EXPECT_TRUE(validate_and_repair(vertex).ok());
  Mesh edge;  // the edge 0-1; node 4 in the plane z=0 of the face (0,1,2), on the far side of 0-1
  edge.xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5, -1, 0, 0.5, -1, -1};
  edge.tet = {0, 1, 2, 3, 0, 1, 4, 5};
  ValidationReport r = validate_and_repair(edge);
  EXPECT_TRUE(r.ok()) << (r.messages.empty() ? "" : r.messages[0]);
  // The same with node 4 on the near side of 0-1: the two coplanar faces overlap.
  edge.xyz[13] = 0.2;
  edge.xyz[16] = 0.2;
  edge.xyz[17] = 1;
  EXPECT_FALSE(validate_and_repair(edge).ok());
}

TEST(ValidateOverlap, TetgenMeshOfANonConvexDomainIsOneMesh) {
  // An outside oracle: TetGen's conforming mesh of the seed paper's trench (non-convex, coplanar
  // boundary faces meeting at reflex edges) is a mesh.
  if (!test::have_program("tetgen")) GTEST_SKIP() << "no tetgen";
  test::TempDir dir;
  std::filesystem::copy_file(test::data_dir() + "/../../examples/trench.poly", dir / "t.poly");
  ASSERT_EQ(test::run("tetgen -pq1.4a0.002Q '" + (dir / "t.poly").string() + "'", dir / "log"), 0);
  Mesh m = read_tetgen(dir / "t.1");
  ASSERT_GT(m.tet_count(), 500u);
  ValidationReport r = validate_and_repair(m);
  EXPECT_TRUE(r.ok()) << (r.messages.empty() ? "" : r.messages[0]);
  // Removing nothing but moving one interior node far outside makes its tets overlap others.
  const FaceAdjacency& adj = face_adjacency(m);
  std::vector<char> on_boundary(m.node_count(), 0);
  for (std::size_t t = 0; t < m.tet_count(); ++t)
    for (int f = 0; f < 4; ++f)
      if (adj.neighbour[4 * t + f] == kNone)
        for (int j = 0; j < 4; ++j)
          if (j != f) on_boundary[m.tet[4 * t + j]] = 1;
  std::uint32_t inner = 0;
  while (on_boundary[m.tet[inner]]) ++inner;
  const std::uint32_t v = m.tet[inner];
  m.xyz[3 * v + 2] += 0.3;  // through its neighbours' faces
  invalidate_derived(m);
  ValidationReport moved = validate_and_repair(m);
  EXPECT_FALSE(moved.ok() && moved.inverted == 0) << "moving an interior node 0.3 up left a valid mesh";
}

}  // namespace
}  // namespace foxi
