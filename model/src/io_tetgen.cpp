// Placeholder until the TetGen and Medit readers and writers land.
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/io_error.hpp"
namespace foxi {
Mesh read_tetgen(const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "tetgen reader not built yet"); }
Mesh parse_tetgen(std::string_view, std::string_view, std::string_view, const std::string& n) { throw IoError(n, 0, IoError::kNoOffset, "tetgen reader not built yet"); }
void write_tetgen(const Mesh&, const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "tetgen writer not built yet"); }
Mesh read_medit(const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "medit reader not built yet"); }
Mesh parse_medit(std::string_view, const std::string& n) { throw IoError(n, 0, IoError::kNoOffset, "medit reader not built yet"); }
void write_medit(const Mesh&, const std::filesystem::path& p) { throw IoError(p.string(), 0, IoError::kNoOffset, "medit writer not built yet"); }
}  // namespace foxi
