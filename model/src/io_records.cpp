// The record scanner's out-of-line parts (io_records.hpp).
#include "io_records.hpp"

#include <cmath>

#include "foxi/model/io_error.hpp"

namespace foxi::records {

void fill_names(Mesh& m) {
  for (std::int32_t id : io::distinct_ids(m.tet_region)) m.regions.push_back(Region{id, {}, kNone});
  for (std::int32_t tag : io::distinct_ids(m.bface_tag)) m.boundaries.push_back(Boundary{tag, {}});
}

void check_writable(const Mesh& mesh, const std::string& file) {
  std::string problem = check_sizes(mesh);
  if (!problem.empty())
    throw IoError(file, 0, IoError::kNoOffset, "cannot write an inconsistent mesh: " + problem);
  const std::size_t nodes = mesh.node_count();
  for (std::size_t i = 0; i < mesh.tet.size(); ++i) {
    if (mesh.tet[i] >= nodes) {
      throw IoError(file, 0, IoError::kNoOffset,
                    "cannot write: tetrahedron " + std::to_string(i / 4) + " names node " +
                        std::to_string(mesh.tet[i]) + " of " + std::to_string(nodes));
    }
  }
  for (std::size_t i = 0; i < mesh.bface.size(); ++i) {
    if (mesh.bface[i] >= nodes) {
      throw IoError(file, 0, IoError::kNoOffset,
                    "cannot write: boundary triangle " + std::to_string(i / 3) + " names node " +
                        std::to_string(mesh.bface[i]) + " of " + std::to_string(nodes));
    }
  }
  for (std::size_t i = 0; i < mesh.xyz.size(); ++i) {
    if (!std::isfinite(mesh.xyz[i])) {
      throw IoError(file, 0, IoError::kNoOffset,
                    "cannot write: node " + std::to_string(i / 3) + " has a non-finite coordinate");
    }
  }
}

}  // namespace foxi::records
