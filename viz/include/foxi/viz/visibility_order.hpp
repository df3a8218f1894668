// The per-view visibility order of a set of tets (seed paper, sections 3-5): back to front by
// decreasing power of the viewpoint w.r.t. each tet's circumsphere, for any subset of the mesh
// (non-convex, disconnected), with no adjacency graph. Orthographic views order by decreasing c.d.
//
// Exactness: keys are computed in double, mapped monotonically to 32-bit integers and sorted in a
// progressive MSD radix sort; every run of keys whose integers are closer than the rounding bound is
// re-sorted in double, and chains of overlapping intervals in it with exact comparisons of the powers
// (interval arithmetic first, exact binary-float fractions where the intervals overlap); cospherical
// clusters are single items expanded by a local MPVO. Extra memory per view: 16 bytes per item
// (besides the output's 4 a tet). For a Delaunay (or regular) mesh
// the result is a visibility order: no face-adjacent pair is drawn in the wrong order.
//
// Non-Delaunay meshes (see delaunay.hpp) have no such guarantee; use mpvo_order() for them, which
// follows face adjacency and reports the cycles it had to break.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/view.hpp"

namespace foxi {

struct OrderStats {
  std::size_t items = 0;  // sort items: singleton tets + clusters
  std::size_t buckets = 0;
  std::size_t near_tie_runs = 0;  // runs re-sorted exactly
  std::size_t near_tie_items = 0;
  std::size_t cluster_cycles = 0;  // cycles broken inside clusters (0 for a Delaunay mesh)
  double key_bound = 0;            // the rounding bound of ordinary items (key units)
  double key_range = 0;            // largest minus smallest key
  std::size_t wide_items = 0;      // items sorted with their own, wider bound
  // Wall time of the phases of visibility_order_into (seconds): keys with the first-level histogram,
  // the scatter into first-level buckets, and the per-bucket sorts with near-tie fix-up and cluster
  // expansion (both cores in each).
  double keys_seconds = 0, scatter_seconds = 0, sort_seconds = 0;
  // Keys computed before a progressive order's first batch (from the key blocks that may hold it).
  std::size_t first_batch_keys = 0;
};

// Hands out the order of one view progressively: next() returns the next batch of tets (back to
// front, or front to back if asked). Orders of fewer than 50,000 items are computed on the
// caller's thread. For larger ones the constructor finds only the first buckets (a whole-mesh order
// reads just the blocks of keys whose bounds may reach them, SphereTable::key_blocks; a subset
// computes every key on both cores), the first next() sorts and returns them on the caller's thread
// and hands the rest to a pooled thread that computes the other keys, places and sorts them ahead
// while the caller draws. Destroying the object stops that work within a fraction of a
// millisecond. The table and the mesh are lent and must outlive it; one object is used from one
// thread.
class FOXI_API ProgressiveOrder {
 public:
  // subset: tet indices to order (each at most once); empty span = all tets.
  ProgressiveOrder(const MeshView& mesh, const SphereTable& table, const View& view,
                   std::span<const std::uint32_t> subset = {}, bool front_to_back = false);
  ~ProgressiveOrder();
  ProgressiveOrder(ProgressiveOrder&&) noexcept;
  ProgressiveOrder& operator=(ProgressiveOrder&&) noexcept;

  // The next batch (a view into internal storage, valid until the next call); empty when done.
  std::span<const std::uint32_t> next();
  std::size_t handed_out() const;  // tets handed out so far
  std::size_t total() const;       // tets in the order
  const OrderStats& stats() const;

 private:
  friend void visibility_order_into(std::vector<std::uint32_t>&, const MeshView&, const SphereTable&,
                                    const View&, std::span<const std::uint32_t>, bool, OrderStats*);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The whole order at once (both cores).
FOXI_API std::vector<std::uint32_t> visibility_order(const MeshView& mesh, const SphereTable& table,
                                                     const View& view,
                                                     std::span<const std::uint32_t> subset = {},
                                                     bool front_to_back = false, OrderStats* stats = nullptr);

// The same into `out`, resized to the order's size: a caller that orders view after view and keeps
// `out` allocates nothing per view (the internal buffers are kept per thread as well).
FOXI_API void visibility_order_into(std::vector<std::uint32_t>& out, const MeshView& mesh,
                                    const SphereTable& table, const View& view,
                                    std::span<const std::uint32_t> subset = {}, bool front_to_back = false,
                                    OrderStats* stats = nullptr);

// MPVO for meshes without a visibility order guarantee: a topological sort of the view-directed
// face-adjacency graph of the subset, ready tets taken in decreasing power key; cycles are broken at
// the tet of largest key and counted in `cycles_broken`.
FOXI_API std::vector<std::uint32_t> mpvo_order(const MeshView& mesh, const SphereTable& table,
                                               const View& view, std::span<const std::uint32_t> subset = {},
                                               std::size_t* cycles_broken = nullptr);

// A centroid-depth order (what VTK's vtkCellCenterDepthSort does): the baseline that power order
// beats. Back to front by decreasing distance from the eye (or along dir) of each tet's centroid.
FOXI_API std::vector<std::uint32_t> centroid_order(const MeshView& mesh, const View& view,
                                                   std::span<const std::uint32_t> subset = {});

struct ViolationReport {
  std::size_t pairs_checked = 0;  // face-adjacent pairs both in the order, eye not on their face
  std::size_t violations = 0;     // pairs drawn in the wrong order for this view
};

// Counts face-adjacent pairs drawn in the wrong order (back-to-front order expected): for each
// interior face shared by two ordered tets, the tet on the eye's side of the face (exact
// orientation test) must come later. Pairs whose face plane contains the eye are not compared.
FOXI_API ViolationReport count_violations(const MeshView& mesh, const View& view,
                                          std::span<const std::uint32_t> order);

}  // namespace foxi
