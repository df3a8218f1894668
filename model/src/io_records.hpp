// Internal to the TetGen and Medit formats (io_tetgen.cpp, io_medit.cpp): the scanner of records of
// whitespace-separated numbers, the chunked text writer and the checks both writers make.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>
#include <string>
#include <string_view>
#include <utility>

#include "foxi/model/mesh.hpp"
#include "io_util.hpp"

namespace foxi::records {

// ---------------------------------------------------------------------------------------------
// Scanning: records of whitespace-separated numbers with '#' comments. TetGen records are one line
// each (kLine); Medit numbers may be spread over lines (kAny). Messages name the record being read.

enum class Span { kLine, kAny };

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; }
inline bool is_eol(char c) { return c == '\n' || c == '\r'; }
inline bool ends_token(char c) { return is_blank(c) || is_eol(c) || c == '#'; }

class Scanner {
 public:
  Scanner(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  const std::string& file() const { return file_; }
  std::size_t pos() const { return p_; }
  std::size_t remaining() const { return text_.size() - p_; }

  // The record being read, for messages ("tet 12: ..."); kind nullptr for none.
  void set_record(const char* kind, std::uint64_t number) {
    kind_ = kind;
    number_ = number;
  }

  // Skips whitespace, line ends and comments. True if something other than that follows.
  bool skip_to_content() {
    const std::size_t n = text_.size();
    while (p_ < n) {
      char c = text_[p_];
      if (is_blank(c) || is_eol(c)) {
        ++p_;
      } else if (c == '#') {
        while (p_ < n && !is_eol(text_[p_])) ++p_;
      } else {
        return true;
      }
    }
    return false;
  }

  // Moves to the next token of the current record; fails if there is none.
  template <Span kSpan>
  void to_field(const char* what) {
    if constexpr (kSpan == Span::kLine) {
      while (p_ < text_.size() && is_blank(text_[p_])) ++p_;
      if (p_ >= text_.size()) fail(std::string("unexpected end of file, expected ") + what);
      if (is_eol(text_[p_]) || text_[p_] == '#') fail(std::string("line ends early, expected ") + what);
    } else {
      if (!skip_to_content()) fail(std::string("unexpected end of file, expected ") + what);
    }
  }

  // The next number; the whole token must be the number.
  template <class T, Span kSpan>
  T number(const char* what) {
    to_field<kSpan>(what);
    const char* b = text_.data() + p_;
    const char* e = text_.data() + text_.size();
    const char* s = b;
    if (*s == '+' && s + 1 < e && s[1] != '-') ++s;  // from_chars does not take a leading '+'
    T value{};
    auto [q, ec] = std::from_chars(s, e, value);
    if (ec != std::errc() || (q < e && !ends_token(*q))) bad_number(what, ec);
    p_ = static_cast<std::size_t>(q - text_.data());
    return value;
  }
  template <Span kSpan>
  double real(const char* what) {
    return number<double, kSpan>(what);
  }
  template <Span kSpan>
  std::int64_t integer(const char* what) {
    return number<std::int64_t, kSpan>(what);
  }
  // A finite coordinate.
  template <Span kSpan>
  double coordinate(const char* what) {
    std::size_t at = p_;
    double v = real<kSpan>(what);
    if (!std::isfinite(v)) {
      skip_to_token(at);
      fail("expected " + std::string(what) + ", found the non-finite value '" + token_at(p_) + "'");
    }
    return v;
  }
  // A whole number that fits an int32 (region ids, boundary markers); a real is rounded.
  template <Span kSpan>
  std::int32_t id_value(const char* what) {
    std::size_t at = p_;
    double v = real<kSpan>(what);
    double r = std::nearbyint(v);
    if (!std::isfinite(v) || r < -2147483648.0 || r > 2147483647.0) {
      skip_to_token(at);
      fail("expected " + std::string(what) + " (a 32-bit integer), found '" + token_at(p_) + "'");
    }
    return static_cast<std::int32_t>(r);
  }
  // A node index: `raw - offset` must lie in [0, nodes).
  template <Span kSpan>
  std::uint32_t node_index(const char* what, std::int64_t offset, std::uint64_t nodes) {
    std::size_t at = p_;
    std::int64_t v = integer<kSpan>(what);
    std::int64_t i = v - offset;
    if (i < 0 || static_cast<std::uint64_t>(i) >= nodes) {
      skip_to_token(at);
      std::string range = nodes == 0 ? std::string("there are no nodes")
                                     : "nodes are numbered " + std::to_string(offset) + ".." +
                                           std::to_string(static_cast<std::int64_t>(nodes) - 1 + offset);
      fail(std::string(what) + " " + std::to_string(v) + " is out of range (" + range + ")");
    }
    return static_cast<std::uint32_t>(i);
  }

  // TetGen: the record must end here (only blanks or a comment before the line end).
  void end_line(const char* what) {
    while (p_ < text_.size() && is_blank(text_[p_])) ++p_;
    if (p_ < text_.size() && !is_eol(text_[p_]) && text_[p_] != '#') {
      fail("unexpected '" + token_at(p_) + "' after " + what);
    }
  }
  // Number of tokens left on the current line (before a comment); does not move.
  std::size_t tokens_left_on_line() const {
    std::size_t q = p_, count = 0;
    while (q < text_.size()) {
      while (q < text_.size() && is_blank(text_[q])) ++q;
      if (q >= text_.size() || is_eol(text_[q]) || text_[q] == '#') break;
      ++count;
      while (q < text_.size() && !ends_token(text_[q])) ++q;
    }
    return count;
  }
  // Skips one token of any content on the current record (Medit: skipped keyword data).
  template <Span kSpan>
  void skip_number(const char* what) {
    (void)real<kSpan>(what);
  }
  // The rest of the current line (without its end), and moves past the line end.
  std::string_view rest_of_line() {
    std::size_t b = p_;
    while (p_ < text_.size() && !is_eol(text_[p_])) ++p_;
    std::string_view s = text_.substr(b, p_ - b);
    if (p_ < text_.size() && text_[p_] == '\r') ++p_;
    if (p_ < text_.size() && text_[p_] == '\n') ++p_;
    return s;
  }
  // The next token as text (for keywords), after whitespace and comments; empty at the end.
  std::string_view word() {
    if (!skip_to_content()) return {};
    std::size_t b = p_;
    while (p_ < text_.size() && !ends_token(text_[p_])) ++p_;
    return text_.substr(b, p_ - b);
  }

  [[noreturn]] void fail(const std::string& reason) const { fail_at(p_, reason); }
  [[noreturn]] void fail_at(std::size_t offset, const std::string& reason) const {
    std::string r;
    if (kind_ != nullptr) r.append(kind_).append(" ").append(std::to_string(number_)).append(": ");
    r += reason;
    io::fail_text(file_, text_, offset, r);
  }
  std::string token_at(std::size_t at) const {
    std::size_t e = at;
    while (e < text_.size() && !ends_token(text_[e])) ++e;
    return io::TextCursor::shorten(text_.substr(at, e - at));
  }

 private:
  // Back to the start of the token read from `at` (for messages that quote it).
  void skip_to_token(std::size_t at) {
    p_ = at;
    skip_to_content();
  }
  [[noreturn]] void bad_number(const char* what, std::errc ec) {
    std::string t = token_at(p_);
    if (ec == std::errc::result_out_of_range) fail(std::string(what) + " '" + t + "' is out of range");
    fail("expected " + std::string(what) + ", found '" + t + "'");
  }

  std::string_view text_;
  std::string file_;
  std::size_t p_ = 0;
  const char* kind_ = nullptr;
  std::uint64_t number_ = 0;
};

// A declared count, checked against the bytes left before anything is allocated: each record
// needs at least `tokens` tokens of one character plus a separator.
template <Span kSpan>
std::uint64_t declared_count(Scanner& in, const char* what, std::uint64_t tokens) {
  in.to_field<kSpan>(what);
  std::size_t at = in.pos();
  std::int64_t n = in.integer<kSpan>(what);
  if (n < 0) in.fail_at(at, std::string(what) + " is negative (" + std::to_string(n) + ")");
  std::uint64_t rest = in.remaining() + 1;
  if (!io::count_fits(static_cast<std::uint64_t>(n), 2 * tokens, rest)) {
    in.fail_at(at, "declares " + std::to_string(n) + " " + what + " but the file has only " +
                       std::to_string(in.remaining()) + " bytes left");
  }
  return static_cast<std::uint64_t>(n);
}

void fill_names(Mesh& m);

// Collects text and hands it to an AtomicFile in large pieces.
class Out {
 public:
  explicit Out(io::AtomicFile& f) : f_(f) { buf_.reserve(kChunk + 256); }
  std::string& buf() { return buf_; }
  void maybe_flush() {
    if (buf_.size() >= kChunk) flush();
  }
  void flush() {
    f_.write(buf_);
    buf_.clear();
  }
  void text(std::string_view s) { buf_.append(s); }
  template <class I>
  void num(I v) {
    io::append_int(buf_, v);
  }
  void real(double v) { io::append_double(buf_, v); }
  void sp() { buf_.push_back(' '); }
  void nl() {
    buf_.push_back('\n');
    maybe_flush();
  }

 private:
  static constexpr std::size_t kChunk = 1 << 20;
  io::AtomicFile& f_;
  std::string buf_;
};

// Refuses meshes a reader could not read back (inconsistent sizes, indices past the nodes,
// non-finite coordinates, which the readers reject).
void check_writable(const Mesh& mesh, const std::string& file);

}  // namespace foxi::records
