// Errors of foxi's readers and writers: they say which file, where in it, and why.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "foxi/api.hpp"

namespace foxi {

class FOXI_API IoError : public std::runtime_error {
 public:
  // line: 1-based line number, 0 when unknown or not meaningful (binary data);
  // byte_offset: offset of the problem in the file, or kNoOffset.
  static constexpr std::uint64_t kNoOffset = ~std::uint64_t{0};
  IoError(std::string file, std::uint64_t line, std::uint64_t byte_offset, std::string reason);

  const std::string& file() const { return file_; }
  std::uint64_t line() const { return line_; }
  std::uint64_t byte_offset() const { return byte_offset_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_;
  std::uint64_t line_;
  std::uint64_t byte_offset_;
  std::string reason_;
};

// A write the system would not take: the disk or quota full, an I/O error (a failure of the work,
// not of the input: foxi's apps exit 1 for it, 3 for other IoErrors).
class FOXI_API WriteError : public IoError {
 public:
  using IoError::IoError;
};

}  // namespace foxi
