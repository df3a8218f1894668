// Fuzz target: the CalculiX .frd reader (parse_frd_source). Any input gives a consistent field source or an
// IoError naming the file; never a crash, a hang, an over-allocation or another exception.
#include "fuzz_field_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string name = "fuzz.frd";
  try {
    foxi::fuzz::check_field_source(foxi::parse_frd_source(foxi::fuzz::as_text(data, size), name));
  } catch (const foxi::IoError& e) {
    foxi::fuzz::check_io_error(e, name);
  }
  return 0;
}
