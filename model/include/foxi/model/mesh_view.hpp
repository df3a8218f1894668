// A mesh over the host's own arrays: the part of the mesh database that meshing's consumers read
// (coordinates, tets, regions, weights, boundary triangles), as std::span, with no copy.
//
// Which entry points take a view (and so read a host's arrays in place) and which copy:
//   take a MeshView (a foxi::Mesh converts to one implicitly, so they take a Mesh as well):
//     validate, compute_face_adjacency / face_adjacency, compute_delaunay_certificate /
//     delaunay_certificate, compute_spheres, visibility_order(_into), ProgressiveOrder, mpvo_order,
//     safe_order, TetRasterizer, render_tets, iso_polygon, IsoPainter, draw_picture, mesh_bounds,
//     node_corner_values, cell_corner_values;
//   take a foxi::Mesh (names, materials, boundaries, named fields, or they change the mesh): the
//     readers and writers, the mesher, the solvers, validate_and_repair, choose_field and the field
//     functions that take a FieldChoice, make_movie, InteractiveView. A host copies or moves its
//     arrays into a Mesh once for these.
//
// Derived data. A view owns nothing: the face adjacency and the Delaunay certificate of a view are
// kept in the DerivedCache that `derived` points to, which the host owns (one per mesh; it must
// outlive the calls and the objects that lend the view, and be cleared, DerivedCache::clear, when
// the host changes its arrays in place). The sphere table (compute_spheres) is a value the host keeps,
// as for a Mesh. A Mesh's view points at the mesh's own cache.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

struct MeshView {
  std::span<const double> xyz;               // 3 per node
  std::span<const std::uint32_t> tet;        // 4 per tet, positively oriented (see validate.hpp)
  std::span<const std::int32_t> tet_region;  // 1 per tet, or empty = all region 0
  std::span<const double> weight;            // 1 per node (regular triangulation), or empty
  std::span<const std::uint32_t> bface;      // 3 per boundary triangle, or empty (validate only)
  // Where the adjacency and the certificate of this view are cached (host-owned, see the top); null:
  // the calls that cache (face_adjacency, delaunay_certificate and those that use them: spheres,
  // orders, draw_picture) throw std::invalid_argument.
  const DerivedCache* derived = nullptr;

  MeshView() = default;
  // A view of a host's arrays (lent: they must outlive the view and every object that keeps it).
  MeshView(std::span<const double> xyz_, std::span<const std::uint32_t> tet_,
           std::span<const std::int32_t> tet_region_ = {}, std::span<const double> weight_ = {},
           std::span<const std::uint32_t> bface_ = {}, const DerivedCache* derived_ = nullptr)
      : xyz(xyz_), tet(tet_), tet_region(tet_region_), weight(weight_), bface(bface_), derived(derived_) {}
  // The view of a Mesh, its cache included (lent: the mesh must outlive the view and stay unchanged).
  MeshView(const Mesh& m)  // NOLINT(google-explicit-constructor): a Mesh is usable wherever a view is
      : xyz(m.xyz),
        tet(m.tet),
        tet_region(m.tet_region),
        weight(m.weight),
        bface(m.bface),
        derived(&m.derived) {}

  std::size_t node_count() const { return xyz.size() / 3; }
  std::size_t tet_count() const { return tet.size() / 4; }
  std::size_t bface_count() const { return bface.size() / 3; }
  std::int32_t region_of(std::size_t t) const { return tet_region.empty() ? 0 : tet_region[t]; }
};

// Checks the sizes of the view's arrays against each other (xyz % 3, tet % 4, tet_region, weight,
// bface % 3). Returns an empty string when consistent, else the first problem.
FOXI_API std::string check_sizes(const MeshView& mesh);

}  // namespace foxi
