#include "io_util.hpp"

#include <algorithm>
#include <cstdio>
#include <system_error>

namespace foxi {

static std::string compose(const std::string& file, std::uint64_t line, std::uint64_t offset,
                           const std::string& reason) {
  // Appends piece by piece: GCC 12 warns falsely (-Wrestrict) on operator+ chains here.
  std::string s = file;
  if (line != 0) {
    s.append(":").append(std::to_string(line));
  } else if (offset != IoError::kNoOffset) {
    s.append(": byte ").append(std::to_string(offset));
  }
  s.append(": ").append(reason);
  return s;
}

IoError::IoError(std::string file, std::uint64_t line, std::uint64_t byte_offset, std::string reason)
    : std::runtime_error(compose(file, line, byte_offset, reason)),
      file_(std::move(file)),
      line_(line),
      byte_offset_(byte_offset),
      reason_(std::move(reason)) {}

namespace io {

std::string xml_escape(std::string_view s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\n':
        out += "&#10;";
        break;
      case '\r':
        out += "&#13;";
        break;
      case '\t':
        out += "&#9;";
        break;
      default:
        out.push_back(ch);
    }
  }
  return out;
}

void strip_byte_order_mark(std::string& text) {
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
}

std::string read_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw IoError(path.string(), 0, IoError::kNoOffset, "is a directory, not a file");
  }
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    throw IoError(path.string(), 0, IoError::kNoOffset,
                  "cannot open: " + std::generic_category().message(errno));
  }
  std::string data;
  if (std::fseek(f, 0, SEEK_END) == 0) {
    long size = std::ftell(f);
    if (size > 0) {
      std::fseek(f, 0, SEEK_SET);
      // Huge pages make the zero fill and the copy cheap next to 4 KiB page faults.
      data.reserve(static_cast<std::size_t>(size));
      advise_huge(data.data(), static_cast<std::size_t>(size));
      data.resize(static_cast<std::size_t>(size));
      std::size_t got = std::fread(data.data(), 1, data.size(), f);
      data.resize(got);
    }
  }
  // Pipes and special files report no size: read to the end in chunks.
  char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) data.append(buf, n);
  bool bad = std::ferror(f) != 0;
  std::fclose(f);
  if (bad) throw IoError(path.string(), 0, IoError::kNoOffset, "read error");
  return data;
}

std::uint64_t line_of(std::string_view text, std::size_t offset) {
  offset = std::min(offset, text.size());
  std::uint64_t line = 1;
  for (std::size_t i = 0; i < offset; ++i) {
    char c = text[i];
    if (c == '\n') {
      ++line;
    } else if (c == '\r' && (i + 1 >= text.size() || text[i + 1] != '\n')) {
      ++line;
    }
  }
  return line;
}

void fail_text(const std::string& file, std::string_view text, std::size_t offset,
               const std::string& reason) {
  throw IoError(file, line_of(text, offset), offset, reason);
}

void fail_binary(const std::string& file, std::size_t offset, const std::string& reason) {
  throw IoError(file, 0, offset, reason);
}

}  // namespace io
}  // namespace foxi
