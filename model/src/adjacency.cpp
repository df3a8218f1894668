// Placeholder until face adjacency lands.
#include "foxi/model/adjacency.hpp"
#include <stdexcept>
namespace foxi {
FaceAdjacency compute_face_adjacency(const Mesh&) { throw std::logic_error("face adjacency not built yet"); }
const FaceAdjacency& face_adjacency(const Mesh&) { throw std::logic_error("face adjacency not built yet"); }
}  // namespace foxi
