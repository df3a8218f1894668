// Internal: the derived results cached on a mesh (see DerivedCache in mesh.hpp).
#pragma once

#include <memory>
#include <mutex>

#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"

namespace foxi {

struct DerivedData {
  std::mutex lock;  // guards lazy computation when several threads ask at once
  // The sizes the results were computed for: a cheap guard against use after an in-place change
  // that forgot invalidate_derived().
  std::size_t nodes = 0, tets = 0;
  // And the arrays they were computed from (a host's view whose arrays moved is a new mesh).
  const double* xyz = nullptr;
  const std::uint32_t* tet = nullptr;
  std::unique_ptr<FaceAdjacency> adjacency;
  std::unique_ptr<DelaunayCertificate> certificate;
};

// Returns the mesh's cache, emptied first if the mesh's sizes or arrays changed since it was filled.
// Throws std::invalid_argument for a view without a cache (MeshView::derived null).
DerivedData& derived_of(const MeshView& mesh);

}  // namespace foxi
