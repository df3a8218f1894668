#include "io_vtk_codec.hpp"

#include <zlib.h>

#include <array>
#include <cstring>

#include "io_util.hpp"

namespace foxi::vtk {

std::size_t type_size(VType t) {
  switch (t) {
    case VType::i8:
    case VType::u8:
      return 1;
    case VType::i16:
    case VType::u16:
      return 2;
    case VType::i32:
    case VType::u32:
    case VType::f32:
      return 4;
    case VType::i64:
    case VType::u64:
    case VType::f64:
      return 8;
  }
  return 1;
}

bool is_float(VType t) { return t == VType::f32 || t == VType::f64; }

bool parse_xml_type(std::string_view n, VType& t) {
  static constexpr std::pair<std::string_view, VType> kNames[] = {
      {"Int8", VType::i8},     {"UInt8", VType::u8},    {"Int16", VType::i16}, {"UInt16", VType::u16},
      {"Int32", VType::i32},   {"UInt32", VType::u32},  {"Int64", VType::i64}, {"UInt64", VType::u64},
      {"Float32", VType::f32}, {"Float64", VType::f64}, {"Char", VType::i8},   {"UChar", VType::u8},
      {"Short", VType::i16},   {"UShort", VType::u16},  {"Int", VType::i32},   {"UInt", VType::u32},
      {"Float", VType::f32},   {"Double", VType::f64},  {"IdType", VType::i64}};
  for (const auto& [name, type] : kNames) {
    if (n == name) {
      t = type;
      return true;
    }
  }
  return false;
}

const char* xml_type_name(VType t) {
  switch (t) {
    case VType::i8:
      return "Int8";
    case VType::u8:
      return "UInt8";
    case VType::i16:
      return "Int16";
    case VType::u16:
      return "UInt16";
    case VType::i32:
      return "Int32";
    case VType::u32:
      return "UInt32";
    case VType::i64:
      return "Int64";
    case VType::u64:
      return "UInt64";
    case VType::f32:
      return "Float32";
    case VType::f64:
      return "Float64";
  }
  return "?";
}

bool parse_legacy_type(std::string_view name, VType& t) {
  std::string n(name);
  for (char& c : n) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static constexpr std::pair<std::string_view, VType> kNames[] = {
      {"char", VType::i8},          {"signed_char", VType::i8},     {"unsigned_char", VType::u8},
      {"short", VType::i16},        {"unsigned_short", VType::u16}, {"int", VType::i32},
      {"unsigned_int", VType::u32}, {"long", VType::i64},           {"unsigned_long", VType::u64},
      {"vtktypeint64", VType::i64}, {"vtktypeuint64", VType::u64},  {"vtkidtype", VType::i64},
      {"vtktypeint32", VType::i32}, {"vtktypeuint32", VType::u32},  {"float", VType::f32},
      {"double", VType::f64}};
  for (const auto& [k, type] : kNames) {
    if (n == k) {
      t = type;
      return true;
    }
  }
  return false;
}

static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void base64_encode(const void* data, std::size_t n, std::string& out) {
  const auto* s = static_cast<const unsigned char*>(data);
  std::size_t start = out.size();
  out.resize(start + (n + 2) / 3 * 4);
  char* d = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    std::uint32_t v = (std::uint32_t{s[i]} << 16) | (std::uint32_t{s[i + 1]} << 8) | s[i + 2];
    d[0] = kAlphabet[v >> 18];
    d[1] = kAlphabet[(v >> 12) & 63];
    d[2] = kAlphabet[(v >> 6) & 63];
    d[3] = kAlphabet[v & 63];
    d += 4;
  }
  if (i < n) {
    std::uint32_t v = std::uint32_t{s[i]} << 16;
    if (i + 1 < n) v |= std::uint32_t{s[i + 1]} << 8;
    d[0] = kAlphabet[v >> 18];
    d[1] = kAlphabet[(v >> 12) & 63];
    d[2] = i + 1 < n ? kAlphabet[(v >> 6) & 63] : '=';
    d[3] = '=';
  }
}

namespace {
constexpr std::uint8_t kInvalid = 0xff, kPad = 0xfe, kSpace = 0xfd;
constexpr std::array<std::uint8_t, 256> kDecode = [] {
  std::array<std::uint8_t, 256> t{};
  for (auto& v : t) v = kInvalid;
  for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(kAlphabet[i])] = static_cast<std::uint8_t>(i);
  t['='] = kPad;
  for (unsigned char c : {' ', '\t', '\n', '\r', '\f', '\v'}) t[c] = kSpace;
  return t;
}();
}  // namespace

int Base64Reader::next_group(unsigned char out[3], const char* what) {
  std::uint8_t v[4];
  int got = 0;
  std::size_t first = pos_;
  while (got < 4) {
    if (pos_ >= end_) {
      if (got == 0) return 0;
      io::fail_text(file_, text_, first,
                    std::string(what) + ": base64 data ends inside a group of 4 characters");
    }
    auto c = static_cast<unsigned char>(text_[pos_]);
    std::uint8_t d = kDecode[c];
    if (d == kSpace) {
      ++pos_;
      continue;
    }
    if (got == 0) first = pos_;
    if (d == kInvalid || (d == kPad && got < 2)) {
      io::fail_text(file_, text_, pos_,
                    std::string(what) + ": invalid base64 character '" +
                        io::TextCursor::shorten(std::string_view(text_.data() + pos_, 1)) + "'");
    }
    if (got == 3 && v[2] == kPad && d != kPad) {
      io::fail_text(file_, text_, pos_, std::string(what) + ": base64 data after padding '='");
    }
    v[got++] = d;
    ++pos_;
  }
  int bytes = v[2] == kPad ? 1 : v[3] == kPad ? 2 : 3;
  std::uint32_t x = (std::uint32_t{v[0]} << 18) | (std::uint32_t{v[1]} << 12);
  if (bytes >= 2) x |= std::uint32_t{v[2]} << 6;
  if (bytes == 3) x |= v[3];
  out[0] = static_cast<unsigned char>(x >> 16);
  out[1] = static_cast<unsigned char>(x >> 8);
  out[2] = static_cast<unsigned char>(x);
  return bytes;
}

void Base64Reader::read(char* dst, std::size_t n, const char* what) {
  while (n > 0 && pending_ > 0) {
    *dst++ = static_cast<char>(buf_[group_bytes_ - pending_]);
    --pending_;
    --n;
  }
  const auto* s = reinterpret_cast<const unsigned char*>(text_.data());
  while (n > 0) {
    // Fast path: whole groups of 4 plain characters.
    while (n >= 3 && end_ - pos_ >= 4) {
      std::uint32_t a = kDecode[s[pos_]], b = kDecode[s[pos_ + 1]], c = kDecode[s[pos_ + 2]],
                    d = kDecode[s[pos_ + 3]];
      if ((a | b | c | d) & 0xc0u) break;
      std::uint32_t x = (a << 18) | (b << 12) | (c << 6) | d;
      dst[0] = static_cast<char>(x >> 16);
      dst[1] = static_cast<char>(x >> 8);
      dst[2] = static_cast<char>(x);
      dst += 3;
      n -= 3;
      pos_ += 4;
    }
    if (n == 0) break;
    int k = next_group(buf_, what);
    if (k == 0) {
      io::fail_text(
          file_, text_, pos_,
          std::string(what) + ": base64 data ends early (" + std::to_string(n) + " more bytes expected)");
    }
    group_bytes_ = k;
    int take = static_cast<int>(std::min<std::size_t>(n, static_cast<std::size_t>(k)));
    std::memcpy(dst, buf_, static_cast<std::size_t>(take));
    dst += take;
    n -= static_cast<std::size_t>(take);
    pending_ = k - take;
  }
}

void zlib_compress_blocks(const void* data, std::size_t n, std::size_t block_size, int level,
                          std::string& header, std::string& blocks) {
  const auto* s = static_cast<const unsigned char*>(data);
  std::uint64_t nblocks = n == 0 ? 0 : (n + block_size - 1) / block_size;
  std::uint64_t last = n == 0 ? 0 : n - (nblocks - 1) * block_size;
  std::vector<std::uint64_t> h;
  h.reserve(3 + nblocks);
  h.push_back(nblocks);
  h.push_back(block_size);
  h.push_back(last);
  for (std::uint64_t b = 0; b < nblocks; ++b) {
    std::size_t len = b + 1 == nblocks ? last : block_size;
    uLongf cap = compressBound(static_cast<uLong>(len));
    std::size_t at = blocks.size();
    blocks.resize(at + cap);
    int rc = compress2(reinterpret_cast<Bytef*>(blocks.data() + at), &cap, s + b * block_size,
                       static_cast<uLong>(len), level);
    if (rc != Z_OK) throw std::runtime_error("zlib compress2 failed");
    blocks.resize(at + cap);
    h.push_back(cap);
  }
  header.append(reinterpret_cast<const char*>(h.data()), h.size() * sizeof(std::uint64_t));
}

}  // namespace foxi::vtk
