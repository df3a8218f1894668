// Fuzz target: the in-memory medit reader (parse_medit). Any input gives a consistent mesh or an IoError
// naming the file; never a crash, a hang, an over-allocation or another exception.
#include "foxi/model/io_medit.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string name = "fuzz.mesh";
  try {
    foxi::fuzz::check_read_mesh(foxi::parse_medit(foxi::fuzz::as_text(data, size), name));
  } catch (const foxi::IoError& e) {
    foxi::fuzz::check_io_error(e, name);
  }
  return 0;
}
