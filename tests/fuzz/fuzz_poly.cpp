// Fuzz target: the TetGen .poly reader (parse_poly). Any input gives a PLC whose facets name points
// that exist, or an IoError naming the file.
#include "foxi/model/plc.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string name = "fuzz.poly";
  try {
    const foxi::Plc plc = foxi::parse_poly(foxi::fuzz::as_text(data, size), name);
    for (std::uint32_t v : plc.polygon_vertices)
      FOXI_FUZZ_CHECK(v < plc.point_count(), "facet vertex " + std::to_string(v));
  } catch (const foxi::IoError& e) {
    foxi::fuzz::check_io_error(e, name);
  }
  return 0;
}
