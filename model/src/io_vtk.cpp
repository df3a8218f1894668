// Placeholder until the VTK readers and writers land.
#include "foxi/model/io_vtk.hpp"
#include "foxi/model/io_error.hpp"
namespace foxi {
Mesh read_vtu(const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "vtu reader not built yet"); }
Mesh parse_vtu(std::string_view, const std::string& n) { throw IoError(n, 0, IoError::kNoOffset, "vtu reader not built yet"); }
void write_vtu(const Mesh&, const std::filesystem::path& p, VtuEncoding) { throw IoError(p.string(), 0, IoError::kNoOffset, "vtu writer not built yet"); }
Mesh read_vtk_legacy(const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "vtk reader not built yet"); }
Mesh parse_vtk_legacy(std::string_view, const std::string& n) { throw IoError(n, 0, IoError::kNoOffset, "vtk reader not built yet"); }
void write_vtk_legacy(const Mesh&, const std::filesystem::path& p, bool) { throw IoError(p.string(), 0, IoError::kNoOffset, "vtk writer not built yet"); }
}  // namespace foxi
