// Fuzz target: the in-memory TetGen reader (parse_tetgen). The input is the .node, .ele and .face
// texts separated by NUL bytes (a missing part is empty; TetGen text holds no NUL). Any input gives
// a consistent mesh or an IoError naming one of the three files.
#include "foxi/model/io_tetgen.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view rest = foxi::fuzz::as_text(data, size), part[3];
  for (int k = 0; k < 3; ++k) {
    const std::size_t cut = k < 2 ? rest.find('\0') : std::string_view::npos;
    part[k] = rest.substr(0, cut);
    rest = cut == std::string_view::npos ? std::string_view{} : rest.substr(cut + 1);
  }
  const std::string base = "fuzz.1";
  try {
    foxi::fuzz::check_read_mesh(foxi::parse_tetgen(part[0], part[1], part[2], base));
  } catch (const foxi::IoError& e) {
    const std::string& f = e.file();
    FOXI_FUZZ_CHECK(f == base + ".node" || f == base + ".ele" || f == base + ".face", e.what());
    FOXI_FUZZ_CHECK(std::string_view(e.what()).find(f) != std::string_view::npos, e.what());
  }
  return 0;
}
