// Per-mesh precompute of the power ordering (seed paper, section 3): for every tet its circumcentre
// c and s = |c|^2 - r^2, or for a weighted mesh (vertex weights, a regular triangulation) its
// orthocentre and s = |c|^2 - R^2 where R^2 may be negative (s keeps its sign; no square root is
// ever taken). The power of a point p w.r.t. the tet is then s - 2 c.p + |p|^2, so drawing in
// decreasing key = s - 2 c.p is back to front (Theorem 1).
//
// Also found once per mesh: cospherical clusters, maximal sets of face-adjacent tets with the same
// circumsphere (decided with CGAL's exact insphere test across each shared face), e.g. the 5 or 6
// tets of one cube of a structured grid. Their keys tie exactly for every view; each is drawn as one
// unit in the global order and ordered inside by a local MPVO over its own faces (section 3.3).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

// Sort items carry a tet index, or a cluster index with this bit set.
inline constexpr std::uint32_t kClusterBit = 0x80000000u;

struct SphereTable {
  // Centres are stored relative to `origin` (the centre of the mesh's bounding box), and s with them:
  // s = |c - origin|^2 - r^2, so that keys of a mesh far from the coordinate origin keep their
  // precision. A view's eye point is taken relative to the same origin.
  double origin[3] = {0, 0, 0};
  std::vector<double> c;           // 3 per tet: circumcentre (orthocentre if weighted) - origin
  std::vector<double> s;           // 1 per tet: |c|^2 - r^2 (|c|^2 - R^2 if weighted), local frame
  std::vector<std::uint8_t> flat;  // 1 per tet: 1 = zero volume, no sphere (a point sphere at
                                   // its centroid stands in, so it still gets a place)
  bool weighted = false;
  // Conditioning: a centre computed in double whose estimated relative error exceeds 2^-40 is
  // recomputed with exact rational arithmetic and rounded.
  std::size_t recomputed_exactly = 0;
  std::size_t flat_count = 0;

  // Rounding bounds of the keys. For tet t and eye p (local frame), |key error| <= A_t + B_t |p|_1
  // (orthographic: B_t |d|_1). Most tets are within (bound_a, bound_b); the few that are not (huge
  // circumspheres of slivers near the hull, badly conditioned centres) are "wide" items, sorted with
  // their own bound (wide_a, wide_b) so that they do not widen everyone's near-tie window.
  double bound_a = 0, bound_b = 0;
  std::vector<std::uint8_t> wide;         // 1 per tet: 1 = a wide item (see above)
  std::vector<std::uint32_t> wide_items;  // the wide items of the whole mesh (tet or cluster|bit)
  std::vector<float> wide_a, wide_b;      // their bounds (same order)

  // Cospherical clusters (only those with 2 or more tets). cluster_of[t] = cluster id or kNone.
  std::vector<std::uint32_t> cluster_of;
  std::vector<std::uint32_t> cluster_begin;  // CSR over cluster_tets, size = clusters + 1
  std::vector<std::uint32_t> cluster_tets;
  // The faces inside each cluster, CSR by cluster: face_tet[2k], face_tet[2k+1] are the two tets
  // (the first on the positive side of the triangle), face_vertex[3k..3k+2] the triangle's nodes;
  // after them, in a cluster the mesh's boundary cuts, separating planes (ClusterFace::separating).
  // A cluster is the tets of one sphere joined by shared faces, and also, where the mesh's boundary
  // cuts a cell apart, tets of one sphere with a face on the mesh's boundary.
  std::vector<std::uint32_t> cluster_face_begin;
  std::vector<std::uint32_t> face_tet;
  std::vector<std::uint32_t> face_vertex;
  // Per cluster face, for a fast side test, in one record so that a cluster's faces lie together
  // in memory (clusters are expanded in key order, i.e. at scattered places).
  struct ClusterFace {
    double plane[4];         // n.x = d, n = (v1 - v0) x (v2 - v0), positive on the first tet's side
    float scale, anorm;      // for the rounding bound: |v1 - v0|_1 |v2 - v0|_1 and |v0|_1
    std::uint16_t local[2];  // its two tets' indices within the cluster; 0xFFFF if it is too large
    // 1: a separating plane of two tets that share no face (add_separating_planes), which orders
    // them only where a ray from the eye meets both.
    std::uint8_t separating = 0;
  };
  std::vector<ClusterFace> face_test;
  // Of the cluster faces, how many are separating planes of tets of a cluster the mesh's boundary
  // cuts (spheres.cpp, add_separating_planes): listed like shared faces, after them.
  std::size_t separating_planes = 0;
  // The sort items of the whole mesh that are not wide, built once: each tet not in a cluster, and
  // each cluster as (cluster | kClusterBit), unless clusters_split (below). A cluster's key is the
  // key of its first tet.
  std::vector<std::uint32_t> all_items;
  std::vector<std::uint32_t> all_rep;  // the tet whose key each item takes (same order)
  // A mesh with few cluster tets (at most 1 in kSplitClusters) has its clusters split instead:
  // all_items (and wide_items, fixed_keys) list every tet as itself, in tet order, cluster
  // members too, so that a whole-mesh order takes the cluster-free paths (one tet an item, no
  // cluster checks per item). A cluster's tets tie exactly, so they always meet in one near-tie
  // run, where they are drawn as one unit (its local order). Subsets take clusters as units.
  static constexpr std::size_t kSplitClusters = 1024;
  bool clusters_split = false;
  // Per-tet key bounds, kept for subsets (which must find their own wide items).
  std::vector<float> key_a, key_b;
  // The keys of all_items in fixed point (same order): c = c_fixed * c_unit, s = s_fixed * s_unit
  // (units powers of two, set so that every non-wide item fits), so that the key pass of a
  // whole-mesh order reads 16 bytes an item, in sequence, instead of 32 (and a cluster's from
  // wherever its first tet lies). Their rounding widens the key bound by (fixed_a, fixed_b) in the
  // terms of (bound_a, bound_b): a few 2^-31 of the mesh's extent, far below the keys' spacing.
  struct FixedKey {
    std::int32_t c[3];
    std::int32_t s;
  };
  std::vector<FixedKey> fixed_keys;
  double c_unit = 0, s_unit = 0;
  double fixed_a = 0, fixed_b = 0;
  // The indices of fixed_keys in space order (by the Morton order of the cell of their centre in
  // a grid over the mesh's bounding box), and per block of kKeyBlock consecutive ones (the last one
  // shorter) the box of their c and the range of their s, in the fixed-point units. A view bounds
  // the keys of a whole block from these alone, so that a progressive order finds its first
  // (farthest) items by reading only the few blocks that may hold them. Empty when fixed_keys is.
  static constexpr std::size_t kKeyBlock = 64;
  struct KeyBlock {
    std::int32_t c_lo[3], c_hi[3];
    std::int32_t s_lo, s_hi;
  };
  std::vector<std::uint32_t> key_order;
  std::vector<KeyBlock> key_blocks;

  std::size_t tet_count() const { return s.size(); }
  std::size_t cluster_count() const { return cluster_begin.empty() ? 0 : cluster_begin.size() - 1; }
};

// Builds the table (both cores). Uses the mesh's cached face adjacency.
FOXI_API SphereTable compute_spheres(const MeshView& mesh, const ProgressFn& progress = {});

}  // namespace foxi
