// Internal pieces of the thermoelastic solver shared with the CalculiX deck writer: materials per
// region, the temperature change per tet, and the displacement constraints as per-node frames.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "foxi/model/vec3.hpp"  // Vec3, dot, cross
#include "foxi/solver/thermoelastic.hpp"
#include "scalar_p1.hpp"

namespace foxi::detail {

inline Vec3 point(const Mesh& mesh, std::size_t v) {
  return {mesh.xyz[3 * v], mesh.xyz[3 * v + 1], mesh.xyz[3 * v + 2]};
}

// E, nu, alpha per region with tets (params first, then the region's material); SolverError naming
// the region when one is missing or invalid.
struct ElasticMaterials {
  RegionTable regions;
  std::vector<double> young, poisson, expansion;  // per region index
};
ElasticMaterials elastic_materials(const Mesh& mesh, const ThermoelasticParams& params);

// dT per tet: params.delta_t, or the mean of (temperature - reference) over its 4 nodes. SolverError
// on a field of the wrong size or a non-finite value on a used node.
std::vector<double> tet_temperature_change(const Mesh& mesh, const ThermoelasticParams& params);

// Per node: m constrained directions (the first m rows of the orthonormal frame r, rows = local axes
// in global coordinates) and their prescribed values g (local components 0..m-1). m = 0: free node,
// r and g unused.
struct NodeFrames {
  std::vector<std::uint8_t> m;
  std::vector<double> r;  // 9 per node, row-major
  std::vector<double> g;  // 3 per node
};

// The frames of the nodes with `used` set, from params.fixed (fixed components; the lumped-area mean
// of the values where fixed tags meet) and params.sliding (the tag's plane normal, value 0), Gram-
// Schmidt orthonormalised per node. SolverError on an unknown tag, a tag with two conditions, a sliding
// tag that is not planar, contradictory constraints at a node.
NodeFrames displacement_frames(const Mesh& mesh, const ThermoelasticParams& params,
                               const std::vector<char>& used);

// The unique edges of the tets (the mid-edge nodes of 10-node tets): edge e joins nodes a[e] < b[e],
// edges sorted by (a, b); tet t's k-th edge joins its corners kTetEdge[k] (the C3D10 order 01, 12, 20,
// 03, 13, 23) and is edge tet_edge[6 t + k].
inline constexpr int kTetEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
struct TetEdges {
  std::vector<std::uint32_t> a, b;
  std::vector<std::uint32_t> tet_edge;  // 6 per tet
  std::size_t size() const { return a.size(); }
  // Edge joining nodes p and q, or kNone when no tet has it.
  std::uint32_t find(std::uint32_t p, std::uint32_t q) const;
};
TetEdges tet_edges(const Mesh& mesh);

// The mesh's nodes followed by one node per edge (its midpoint, node mesh.node_count() + e), and
// each boundary triangle split into 4 through its mid-edge nodes with the triangle's tag: the
// boundary on which displacement_frames gives the mid-edge nodes of a constrained boundary the same
// constraints as its corners. A boundary triangle with an edge that no tet has (not on a tet's face)
// is kept whole.
Mesh quadratic_boundary(const Mesh& mesh, const TetEdges& edges);

}  // namespace foxi::detail
