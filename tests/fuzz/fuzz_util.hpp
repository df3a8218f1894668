// Helpers shared by the fuzz targets (tests/fuzz/fuzz_*.cpp): a byte reader that decodes the fuzz
// input into small values, and the checks a target makes on what the code under test returned.
// Each target defines LLVMFuzzerTestOneInput; it is linked either with libFuzzer (FOXI_BUILD_FUZZERS,
// clang) or with replay_main.cpp, which runs it over files (the regression tests of the normal build).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi::fuzz {

// A property the code under test promised does not hold: print it and abort, which libFuzzer reports
// as a crash (with the input saved) and the replay test as a failure.
[[noreturn]] inline void fail(const char* what, const std::string& detail = {}) {
  std::fprintf(stderr, "fuzz check failed: %s%s%s\n", what, detail.empty() ? "" : ": ", detail.c_str());
  std::abort();
}

#define FOXI_FUZZ_CHECK(cond, detail)               \
  do {                                              \
    if (!(cond)) ::foxi::fuzz::fail(#cond, detail); \
  } while (0)

// Reads the input front to back; past its end every value is 0 (so any input decodes to something).
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  double f64() {
    std::uint64_t bits = 0;
    for (int k = 0; k < 8; ++k) bits |= std::uint64_t(u8()) << (8 * k);
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  std::size_t left() const { return size_ - pos_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// What every reader promises for a mesh it returns: consistent array sizes and every index naming a
// node that exists (see the readers' headers: out-of-range indices are an IoError).
inline void check_read_mesh(const Mesh& m) {
  const std::string sizes = check_sizes(m);
  FOXI_FUZZ_CHECK(sizes.empty(), sizes);
  for (std::uint32_t v : m.tet) FOXI_FUZZ_CHECK(v < m.node_count(), "tet index " + std::to_string(v));
  for (std::uint32_t v : m.bface) FOXI_FUZZ_CHECK(v < m.node_count(), "boundary index " + std::to_string(v));
}

// What every reader promises for an error: an IoError whose message names the file it was given.
inline void check_io_error(const IoError& e, const std::string& name) {
  FOXI_FUZZ_CHECK(e.file() == name, e.what());
  FOXI_FUZZ_CHECK(std::string_view(e.what()).find(name) != std::string_view::npos, e.what());
  FOXI_FUZZ_CHECK(!e.reason().empty(), e.what());
}

}  // namespace foxi::fuzz
