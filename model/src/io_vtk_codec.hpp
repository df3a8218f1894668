// Internal: value types, base64 and zlib block codecs shared by the VTK readers and writers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace foxi::vtk {

// The numeric types of VTK data arrays.
enum class VType : std::uint8_t { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };

std::size_t type_size(VType t);
bool is_float(VType t);
// XML names ("Float32", "Int64", ...). Returns false for an unknown name.
bool parse_xml_type(std::string_view name, VType& t);
const char* xml_type_name(VType t);
// Legacy names ("float", "double", "int", "vtktypeint64", ...). Returns false for an unknown name.
bool parse_legacy_type(std::string_view name, VType& t);

// Base64 encoding of `n` bytes appended to `out` (standard alphabet, '=' padding).
void base64_encode(const void* data, std::size_t n, std::string& out);

// Streaming base64 decoder over text[begin, end): whitespace is skipped, and a padded group ends a
// quantum without ending the stream (VTK encodes a header and its data as separate base64 runs).
// Errors throw IoError at the offending character's line (the text is the whole file).
class Base64Reader {
 public:
  Base64Reader(std::string_view text, std::size_t begin, std::size_t end, const std::string& file)
      : text_(text), pos_(begin), end_(end), file_(file) {}
  // Decodes exactly n bytes into dst; throws if the text ends first or holds a bad character.
  void read(char* dst, std::size_t n, const char* what);
  std::size_t pos() const { return pos_; }
  // Characters left: an upper bound for the bytes left is chars_left() * 3 / 4 + pending.
  std::size_t bytes_left_bound() const { return (end_ - pos_) / 4 * 3 + 3 + pending_; }

 private:
  // Decodes the next group of 4 characters; returns the bytes it holds (0 at the end of the text).
  int next_group(unsigned char out[3], const char* what);

  std::string_view text_;
  std::size_t pos_;
  std::size_t end_;
  const std::string& file_;
  unsigned char buf_[3] = {0, 0, 0};
  int pending_ = 0;  // bytes of buf_ not handed out yet (the last `pending_` of the group)
  int group_bytes_ = 0;
};

// Compresses `n` bytes as vtkZLibDataCompressor does: blocks of `block_size` bytes, each compressed
// separately; appends the header (nblocks, block_size, last_block_size, compressed sizes, as
// UInt64) to `header` and the compressed blocks to `blocks`.
void zlib_compress_blocks(const void* data, std::size_t n, std::size_t block_size, int level,
                          std::string& header, std::string& blocks);

}  // namespace foxi::vtk
