// Face adjacency against independent oracles: a brute-force std::map of sorted vertex triples, and
// TetGen's own neighbour list (.neigh, written by `tetgen -n`).
#include "foxi/model/adjacency.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_meshes.hpp"
#include "plc_text.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

// The oracle: every face keyed by its sorted vertex triple in a std::map.
struct BruteAdjacency {
  std::vector<std::uint32_t> neighbour;
  std::size_t interior = 0, boundary = 0, nonmanifold = 0;
};

BruteAdjacency brute_adjacency(const Mesh& m) {
  std::map<std::array<std::uint32_t, 3>, std::vector<std::uint32_t>> faces;
  for (std::uint32_t t = 0; t < m.tet_count(); ++t)
    for (std::uint32_t f = 0; f < 4; ++f) {
      std::array<std::uint32_t, 3> key;
      int k = 0;
      for (std::uint32_t j = 0; j < 4; ++j)
        if (j != f) key[k++] = m.tet[4 * t + j];
      std::sort(key.begin(), key.end());
      faces[key].push_back(4 * t + f);
    }
  BruteAdjacency b;
  b.neighbour.assign(4 * m.tet_count(), kNone);
  for (const auto& [key, list] : faces) {
    if (list.size() == 1) ++b.boundary;
    if (list.size() == 2) {
      ++b.interior;
      b.neighbour[list[0]] = list[1];
      b.neighbour[list[1]] = list[0];
    }
    if (list.size() >= 3) ++b.nonmanifold;
  }
  return b;
}

void expect_same_as_brute(const Mesh& m) {
  FaceAdjacency a = compute_face_adjacency(m);
  BruteAdjacency b = brute_adjacency(m);
  ASSERT_EQ(a.neighbour.size(), b.neighbour.size());
  std::size_t diffs = 0;
  for (std::size_t i = 0; i < b.neighbour.size(); ++i) diffs += a.neighbour[i] != b.neighbour[i];
  EXPECT_EQ(diffs, 0u);
  EXPECT_EQ(a.interior_faces, b.interior);
  EXPECT_EQ(a.boundary_faces, b.boundary);
  EXPECT_EQ(a.nonmanifold_faces, b.nonmanifold);
}

// Random tets over few nodes: many shared and non-manifold faces, repeated tets, any orientation.
Mesh random_mesh(std::uint32_t nodes, std::uint32_t tets, std::uint32_t seed) {
  Mesh m;
  std::mt19937 rng(seed);
  m.xyz.assign(3 * nodes, 0.0);
  std::uniform_int_distribution<std::uint32_t> pick(0, nodes - 1);
  for (std::uint32_t t = 0; t < tets; ++t) {
    std::array<std::uint32_t, 4> v;
    do {
      for (auto& x : v) x = pick(rng);
      std::array<std::uint32_t, 4> s = v;
      std::sort(s.begin(), s.end());
      if (std::adjacent_find(s.begin(), s.end()) == s.end()) break;
    } while (true);
    m.tet.insert(m.tet.end(), v.begin(), v.end());
  }
  return m;
}

TEST(FaceAdjacency, EmptyMesh) {
  Mesh m;
  FaceAdjacency a = compute_face_adjacency(m);
  EXPECT_TRUE(a.neighbour.empty());
  EXPECT_EQ(a.interior_faces + a.boundary_faces + a.nonmanifold_faces, 0u);
}

TEST(FaceAdjacency, RandomMeshesMatchBruteForce) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE(seed);
    expect_same_as_brute(random_mesh(9 + seed, 60 * seed, seed));  // dense: non-manifold faces
    expect_same_as_brute(random_mesh(400, 3000, seed + 100));      // sparse: mostly boundary
  }
}

TEST(FaceAdjacency, NonManifoldFacesLeftUnpaired) {
  // Three tets on the triangle (0,1,2), apexes 3, 4, 5: one non-manifold face, 9 boundary faces.
  Mesh m;
  m.xyz.assign(3 * 6, 0.0);
  m.tet = {0, 1, 2, 3, 1, 0, 2, 4, 2, 1, 0, 5};
  FaceAdjacency a = compute_face_adjacency(m);
  EXPECT_EQ(a.nonmanifold_faces, 1u);
  EXPECT_EQ(a.interior_faces, 0u);
  EXPECT_EQ(a.boundary_faces, 9u);
  for (std::uint32_t t = 0; t < 3; ++t) EXPECT_EQ(a.neighbour[4 * t + 3], kNone);
  expect_same_as_brute(m);
}

TEST(FaceAdjacency, KuhnGridMatchesBruteForceSerialAndParallel) {
  expect_same_as_brute(bench::kuhn_grid_mesh(3));
  // 63,888 tets: above the threshold where the work is split over threads.
  Mesh big = bench::kuhn_grid_mesh(22);
  FaceAdjacency a = compute_face_adjacency(big);
  // Closed-form counts for an n^3 Kuhn grid: 12 n^2 boundary triangles, (24 n^3 - 12 n^2) / 2 interior.
  const std::size_t n = 22;
  EXPECT_EQ(a.boundary_faces, 12 * n * n);
  EXPECT_EQ(a.interior_faces, (24 * n * n * n - 12 * n * n) / 2);
  EXPECT_EQ(a.nonmanifold_faces, 0u);
  expect_same_as_brute(big);
}

TEST(FaceAdjacency, ShuffledVertexNumberingGivesSameFaces) {
  // Relabel the nodes at random: the adjacency (in tet/face ids) must not change.
  Mesh m = bench::kuhn_grid_mesh(6);
  FaceAdjacency ref = compute_face_adjacency(m);
  std::vector<std::uint32_t> perm(m.node_count());
  for (std::uint32_t i = 0; i < perm.size(); ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), std::mt19937(7));
  for (auto& v : m.tet) v = perm[v];
  EXPECT_EQ(compute_face_adjacency(m).neighbour, ref.neighbour);
}

TEST(FaceAdjacency, CachedOnMeshAndInvalidated) {
  Mesh m = bench::kuhn_grid_mesh(2);
  const FaceAdjacency& a = face_adjacency(m);
  EXPECT_EQ(&a, &face_adjacency(m));
  EXPECT_EQ(a.neighbour, compute_face_adjacency(m).neighbour);
  // Drop the last tet in place: the size guard must refresh the cache.
  m.tet.erase(m.tet.end() - 4, m.tet.end());
  m.tet_region.pop_back();
  const FaceAdjacency& b = face_adjacency(m);
  EXPECT_EQ(b.neighbour.size(), m.tet.size());
  EXPECT_EQ(b.neighbour, compute_face_adjacency(m).neighbour);
}

TEST(FaceAdjacency, RejectsAbsurdIndex) {
  Mesh m;
  m.xyz.assign(12, 0.0);
  m.tet = {0, 1, 2, 0xfffffff0u};
  EXPECT_THROW(compute_face_adjacency(m), std::invalid_argument);
}

// --- TetGen oracle ---------------------------------------------------------------------------------

struct TetgenMesh {
  Mesh mesh;
  std::vector<std::int64_t> neigh;  // 4 per tet, 0-based tet index or -1
};

TetgenMesh read_tetgen_with_neigh(const std::filesystem::path& base) {
  TetgenMesh r;
  std::vector<double> node = test::read_numbers(base.string() + ".node");
  const std::size_t nn = static_cast<std::size_t>(node[0]), dim = static_cast<std::size_t>(node[1]);
  const std::size_t nattr = static_cast<std::size_t>(node[2]), nmark = static_cast<std::size_t>(node[3]);
  const std::size_t stride = 1 + dim + nattr + nmark;
  const long node_base = static_cast<long>(node[4]);
  for (std::size_t i = 0; i < nn; ++i)
    for (std::size_t d = 0; d < 3; ++d) r.mesh.xyz.push_back(node[4 + i * stride + 1 + d]);
  std::vector<double> ele = test::read_numbers(base.string() + ".ele");
  const std::size_t ne = static_cast<std::size_t>(ele[0]), npt = static_cast<std::size_t>(ele[1]);
  const std::size_t eattr = static_cast<std::size_t>(ele[2]);
  const std::size_t estride = 1 + npt + eattr;
  const long ele_base = static_cast<long>(ele[3]);
  for (std::size_t t = 0; t < ne; ++t)
    for (std::size_t j = 0; j < 4; ++j)
      r.mesh.tet.push_back(
          static_cast<std::uint32_t>(static_cast<long>(ele[3 + t * estride + 1 + j]) - node_base));
  std::vector<double> nb = test::read_numbers(base.string() + ".neigh");
  EXPECT_EQ(static_cast<std::size_t>(nb[0]), ne);
  for (std::size_t t = 0; t < ne; ++t)
    for (std::size_t j = 0; j < 4; ++j) {
      long u = static_cast<long>(nb[2 + t * 5 + 1 + j]);
      r.neigh.push_back(u < 0 ? -1 : u - ele_base);
    }
  return r;
}

void check_against_tetgen(const std::string& poly_text, const std::string& switches) {
  if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  test::TempDir dir;
  test::write_text(dir / "m.poly", poly_text);
  ASSERT_EQ(test::run("tetgen " + switches + " '" + (dir / "m.poly").string() + "'", dir / "log"), 0)
      << test::read_text(dir / "log");
  TetgenMesh tg = read_tetgen_with_neigh(dir / "m.1");
  const Mesh& m = tg.mesh;
  ASSERT_GT(m.tet_count(), 100u);
  FaceAdjacency a = compute_face_adjacency(m);
  std::size_t mismatches = 0, boundary = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t)
    for (std::size_t f = 0; f < 4; ++f) {
      const std::int64_t want = tg.neigh[4 * t + f];  // TetGen: neighbour opposite corner f
      const std::uint32_t got = a.neighbour[4 * t + f];
      if (want < 0) {
        ++boundary;
        mismatches += got != kNone;
      } else {
        mismatches += got == kNone || got / 4 != static_cast<std::uint64_t>(want);
        // The face on the other side must point back.
        if (got != kNone) mismatches += a.neighbour[got] != 4 * t + f;
      }
    }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(a.boundary_faces, boundary);
  EXPECT_EQ(a.nonmanifold_faces, 0u);
  EXPECT_EQ(2 * a.interior_faces + a.boundary_faces, 4 * m.tet_count());
}

TEST(FaceAdjacency, MatchesTetgenNeighboursOnBox) {
  check_against_tetgen(test::box_poly(2, 1, 1), "-pq1.414a0.0005O0nQ");
}

TEST(FaceAdjacency, MatchesTetgenNeighboursOnTrench) {
  check_against_tetgen(test::trench_poly(), "-pq1.414a0.001nQ");
}

}  // namespace
}  // namespace foxi
