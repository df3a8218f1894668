// Internal helpers shared by the readers and writers (not a public header).
#pragma once

#include <sys/mman.h>

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "foxi/model/durable_file.hpp"
#include "foxi/api.hpp"
#include "foxi/model/io_error.hpp"

namespace foxi::io {

// The functions below are internal (this header is not installed) but FOXI_API: foxi_structure
// reads its files with them, and a shared libfoxi_structure.so can only call what libfoxi_model.so
// exports.

// Reads a whole file into memory. Throws IoError (line 0) if it cannot be opened or read.
FOXI_API std::string read_file(const std::filesystem::path& path);
// Text as XML character data or an attribute value: & < > " escaped, and tab, CR and LF as character
// references (so an attribute keeps them).
FOXI_API std::string xml_escape(std::string_view s);
// Removes a UTF-8 byte order mark at the start of a text file (an editor's or a spreadsheet's; the
// readers of .msh, .vtk, .mesh and .node refused the file for it).
FOXI_API void strip_byte_order_mark(std::string& text);

// 1-based line number of byte `offset` in `text` (counts '\n'; a lone '\r' also ends a line).
FOXI_API std::uint64_t line_of(std::string_view text, std::size_t offset);

// Throws IoError for a problem at byte `offset` of `text` (a text file: the line is computed).
[[noreturn]] FOXI_API void fail_text(const std::string& file, std::string_view text, std::size_t offset,
                                     const std::string& reason);
// Throws IoError for a problem at byte `offset` of binary data (no line).
[[noreturn]] FOXI_API void fail_binary(const std::string& file, std::size_t offset,
                                       const std::string& reason);

// Reads whitespace-separated tokens from a text held in memory. Whitespace is space, tab, '\r',
// '\n', '\f', '\v', so files with mixed line endings read the same. Errors name the line.
class TextCursor {
 public:
  TextCursor(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  std::string_view text() const { return text_; }
  const std::string& file() const { return file_; }
  std::size_t pos() const { return pos_; }
  void set_pos(std::size_t p) { pos_ = p; }
  bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }
  std::size_t remaining() const { return text_.size() - pos_; }

  // Skips whitespace; if `comment` is not 0, also from that character to the end of its line.
  void skip_space(char comment = 0) {
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
        ++pos_;
      } else if (comment != 0 && c == comment) {
        while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') ++pos_;
      } else {
        break;
      }
    }
  }
  // Skips spaces and tabs only (stays on the current line).
  void skip_blank() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) ++pos_;
  }
  // True if only blanks remain before the end of the current line (or a comment char).
  bool at_line_end(char comment = 0) {
    skip_blank();
    return pos_ >= text_.size() || text_[pos_] == '\n' || text_[pos_] == '\r' ||
           (comment != 0 && text_[pos_] == comment);
  }
  // Moves past the end of the current line.
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '\r') ++pos_;
    if (pos_ < text_.size() && text_[pos_] == '\n') ++pos_;
  }
  // The rest of the current line (without the line end), and moves past it.
  std::string_view rest_of_line() {
    std::size_t b = pos_;
    while (pos_ < text_.size() && text_[pos_] != '\n' && text_[pos_] != '\r') ++pos_;
    std::string_view s = text_.substr(b, pos_ - b);
    skip_line();
    return s;
  }

  // Next token; throws "unexpected end of file, expected <what>" at the end.
  std::string_view token(const char* what, char comment = 0) {
    skip_space(comment);
    if (pos_ >= text_.size()) fail("unexpected end of file, expected " + std::string(what));
    std::size_t b = pos_;
    while (pos_ < text_.size()) {
      char c = text_[pos_];
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') break;
      ++pos_;
    }
    return text_.substr(b, pos_ - b);
  }

  // Number parsing: the whole token must be the number; errors name what was expected.
  template <class T>
  T number(const char* what, char comment = 0) {
    std::string_view t = token(what, comment);
    T value{};
    auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (ec != std::errc() || ptr != t.data() + t.size()) {
      // from_chars does not take a leading '+'; accept it for numbers.
      if (!t.empty() && t[0] == '+' && t.size() > 1) {
        auto r = std::from_chars(t.data() + 1, t.data() + t.size(), value);
        if (r.ec == std::errc() && r.ptr == t.data() + t.size()) return value;
      }
      pos_ -= t.size();
      fail("expected " + std::string(what) + ", found '" + shorten(t) + "'");
    }
    return value;
  }
  double real(const char* what, char comment = 0) { return number<double>(what, comment); }
  std::int64_t integer(const char* what, char comment = 0) { return number<std::int64_t>(what, comment); }

  // Expects the exact token `word`.
  void expect(std::string_view word, char comment = 0) {
    std::string_view t = token(word.data(), comment);
    if (t != word) {
      pos_ -= t.size();
      fail("expected '" + std::string(word) + "', found '" + shorten(t) + "'");
    }
  }

  [[noreturn]] void fail(const std::string& reason) const { fail_text(file_, text_, pos_, reason); }
  [[noreturn]] void fail_at(std::size_t offset, const std::string& reason) const {
    fail_text(file_, text_, offset, reason);
  }

  static std::string shorten(std::string_view t) {
    std::string s(t.substr(0, 40));
    for (char& c : s)
      if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    if (t.size() > 40) s += "...";
    return s;
  }

 private:
  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
};

// Checks a declared count against what the rest of the input could hold, before allocating:
// `count` items of at least `min_bytes_each` bytes must fit in `remaining` bytes.
inline bool count_fits(std::uint64_t count, std::uint64_t min_bytes_each, std::uint64_t remaining) {
  if (min_bytes_each == 0) min_bytes_each = 1;
  return count <= remaining / min_bytes_each;
}

// Writes a file through a temporary in the same folder, renamed into place by commit(), durably
// (foxi/model/durable_file.hpp); if commit() is never reached, the destructor removes the temporary.
using AtomicFile = DurableFile;

// Appends the shortest round-trip text of a double (std::to_chars) to `out`.
inline void append_double(std::string& out, double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}
template <class I>
inline void append_int(std::string& out, I v) {
  static_assert(std::is_integral_v<I>);
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// Asks the kernel for huge pages over [p, p + bytes) (no-op for small ranges): a fresh big allocation
// is first touched while parsing, and its 4 KiB page faults cost more than the parsing itself.
inline void advise_huge(const void* p, std::size_t bytes) {
#if defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  if (bytes < 2 * kHuge) return;
  const auto b = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t hb = (b + kHuge - 1) & ~(kHuge - 1), he = (b + bytes) & ~(kHuge - 1);
  if (he > hb) madvise(reinterpret_cast<void*>(hb), he - hb, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

// Reserves room for n values, with huge pages for big arrays (see advise_huge). Reserving only takes
// address space; pages that are never written are never backed.
template <class T>
void reserve_huge(std::vector<T>& v, std::size_t n) {
  if (n <= v.capacity()) return;
  v.reserve(n);
  advise_huge(v.data(), n * sizeof(T));
}

// The distinct values of `v`, sorted. Linear for the few region ids and boundary tags a mesh has
// (a short list; runs of equal values skipped); falls back to sorting a copy when there are many.
inline std::vector<std::int32_t> distinct_ids(const std::vector<std::int32_t>& v) {
  std::vector<std::int32_t> seen;
  std::int32_t last = 0;
  bool have_last = false;
  for (std::int32_t x : v) {
    if (have_last && x == last) continue;
    last = x;
    have_last = true;
    auto it = std::lower_bound(seen.begin(), seen.end(), x);
    if (it != seen.end() && *it == x) continue;
    seen.insert(it, x);
    if (seen.size() > 256) {
      std::vector<std::int32_t> all = v;
      std::sort(all.begin(), all.end());
      all.erase(std::unique(all.begin(), all.end()), all.end());
      return all;
    }
  }
  return seen;
}

// Reads a little- or big-endian value from unaligned bytes.
template <class T>
inline T load(const char* p, bool swap = false) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if (swap) {
    char* b = reinterpret_cast<char*>(&v);
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
  }
  return v;
}

}  // namespace foxi::io
