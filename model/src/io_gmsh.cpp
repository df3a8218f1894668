// Placeholder until the Gmsh reader and writer land.
#include "foxi/model/io_gmsh.hpp"
#include "foxi/model/io_error.hpp"
namespace foxi {
Mesh read_gmsh(const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "gmsh reader not built yet"); }
Mesh parse_gmsh(std::string_view, const std::string& n) { throw IoError(n, 0, IoError::kNoOffset, "gmsh reader not built yet"); }
void write_gmsh(const Mesh&, const std::filesystem::path& p, const GmshWriteOptions&) { throw IoError(p.string(), 0, IoError::kNoOffset, "gmsh writer not built yet"); }
}  // namespace foxi
