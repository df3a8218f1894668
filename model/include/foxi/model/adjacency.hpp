// Face adjacency of the tets: the neighbour across each tet face, found by sorting face keys
// (a counting sort on each face's smallest vertex, then small sorts; O(n) for bounded vertex degree,
// O(n log n) at worst), no hashing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"

namespace foxi {

// Face f of tet t is the face opposite its vertex f. neighbour[4t+f] is 4u+g when face g of tet u
// is the same triangle, kNone on the boundary and on non-manifold faces (shared by 3 or more tets,
// counted in nonmanifold_faces). Needs tet_count < 2^30.
struct FaceAdjacency {
  std::vector<std::uint32_t> neighbour;  // 4 per tet
  std::size_t interior_faces = 0;        // faces shared by exactly two tets
  std::size_t boundary_faces = 0;        // faces of exactly one tet
  std::size_t nonmanifold_faces = 0;     // distinct triangles shared by three or more tets
};

// Computes the adjacency afresh (uses both cores on large meshes: 50k tets and more). Orientation is
// not checked (two tets on one triangle are paired whatever their orientations). Indices >= node_count
// are tolerated up to max(node_count, 4 * tet_count); beyond that std::invalid_argument is thrown.
FOXI_API FaceAdjacency compute_face_adjacency(const MeshView& mesh);
// Cached on the mesh (see invalidate_derived); the reference lives as long as the mesh's cache.
FOXI_API const FaceAdjacency& face_adjacency(const MeshView& mesh);

}  // namespace foxi
