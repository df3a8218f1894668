// Internal: the derived results cached on a mesh (see DerivedCache in mesh.hpp).
#pragma once

#include <memory>
#include <mutex>

#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

struct DerivedData {
  std::mutex lock;  // guards lazy computation when several threads ask at once
  // The sizes the results were computed for: a cheap guard against use after an in-place change
  // that forgot invalidate_derived().
  std::size_t nodes = 0, tets = 0;
  std::unique_ptr<FaceAdjacency> adjacency;
  std::unique_ptr<DelaunayCertificate> certificate;
};

// Returns the mesh's cache, emptied first if the mesh's sizes changed since it was filled.
DerivedData& derived_of(const Mesh& mesh);

}  // namespace foxi
