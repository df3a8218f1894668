// CalculiX .frd results (ASCII and binary) as a field source. Format: CalculiX GraphiX manual, "Result
// Format": "    2C" node block (" -1" id x y z), "    3C" element block (" -1" id type group material, then
// " -2" records of node ids), "  100C" result header (value = step time, node count in columns 25-36, I2
// format flag at its end), " -4" NAME ncomps, " -5" one line per component (iexist 1: computed by the
// reader, not in the file), " -1" id + values, " -2" continuation values, " -3" block end, " 9999" file
// end. Fixed columns (trailing blanks ignored): ids are I5 (short format 0) or I10 (long format 1), values
// E12.5 back to back (a minus sign may touch the previous value).
// Binary (what ccx writes for *NODE OUTPUT / *ELEMENT OUTPUT): the header lines stay ASCII, each block's
// records follow its header (or its last " -5" line) as raw little-endian data, with no " -3" end line:
// nodes (format 2: int32 id + 3 float32, format 3: int32 id + 3 float64), elements (format 2: int32 id,
// type, group, material, then the type's node ids as int32), results (format 2: for each of the 100C
// header's nodes an int32 id + the stored components as float32). Binary errors name the byte offset.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>

#include "foxi/fields/field_source.hpp"
#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Nodes per element of CalculiX's element types 1..12 (C3D8, C3D6, C3D4, C3D20, C3D15, C3D10, S3,
// S6, S4, S8, B21, B32).
constexpr int kElementNodes[] = {0, 8, 6, 4, 20, 15, 10, 3, 6, 4, 8, 2, 3};

class FrdParser {
 public:
  FrdParser(std::string_view text, const std::string& name, const FrdLimits& limits)
      : text_(text), name_(name), limits_(limits) {}

  FieldSource parse();

 private:
  // Past binary data, line numbers mean nothing (the data may hold newline bytes): the error names the
  // byte offset of the record instead.
  [[noreturn]] void fail(const std::string& why) const {
    if (binary_seen_) throw IoError(name_, 0, line_start_, why);
    throw IoError(name_, line_no_, IoError::kNoOffset, why);
  }
  [[noreturn]] void fail_at(std::size_t offset, const std::string& why) const {
    throw IoError(name_, 0, offset, why);
  }
  // `bytes` raw bytes of a binary block at the read position (advanced past them).
  const unsigned char* take(std::size_t bytes, const std::string& what) {
    if (bytes > text_.size() - std::min(pos_, text_.size()))
      fail_at(std::min(pos_, text_.size()),
              "the file ends inside the binary " + what + " (" + std::to_string(bytes) + " bytes needed, " +
                  std::to_string(text_.size() - std::min(pos_, text_.size())) + " left): truncated?");
    const auto* p = reinterpret_cast<const unsigned char*>(text_.data() + pos_);
    pos_ += bytes;
    binary_seen_ = true;
    return p;
  }
  // Bytes of the binary blocks are little-endian (ccx's x86 builds); decoded byte by byte so that the
  // reader is right on any host.
  static std::uint32_t le32(const unsigned char* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
           std::uint32_t(p[3]) << 24;
  }
  static std::int32_t int32_at(const unsigned char* p) { return static_cast<std::int32_t>(le32(p)); }
  static double float32_at(const unsigned char* p) {
    return static_cast<double>(std::bit_cast<float>(le32(p)));
  }
  static double float64_at(const unsigned char* p) {
    return std::bit_cast<double>(std::uint64_t(le32(p)) | std::uint64_t(le32(p + 4)) << 32);
  }
  // A declared record count that the bytes left cannot hold is refused before anything is reserved.
  void check_fits(std::int64_t count, std::size_t min_record, const std::string& what) const {
    const std::size_t left = text_.size() - std::min(pos_, text_.size());
    if (count < 0 || static_cast<std::uint64_t>(count) > left / min_record)
      fail("a binary " + what + " of " + std::to_string(count) + " records of at least " +
           std::to_string(min_record) + " bytes, and " + std::to_string(left) + " bytes left in the file");
  }

  bool next_line() {
    if (pos_ >= text_.size()) return false;
    const char* start = text_.data() + pos_;
    const void* nl = std::memchr(start, '\n', text_.size() - pos_);
    std::size_t end =
        nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - text_.data()) : text_.size();
    line_ = text_.substr(pos_, end - pos_);
    line_start_ = pos_;
    while (!line_.empty() && (line_.back() == '\r' || line_.back() == ' ')) line_.remove_suffix(1);
    pos_ = end + 1;
    ++line_no_;
    return true;
  }
  bool starts(std::string_view key) const { return line_.substr(0, key.size()) == key; }

  // An integer in columns [from, from + width) (blanks around it allowed).
  std::int64_t int_at(std::size_t from, std::size_t width, const char* what) const {
    if (from >= line_.size()) fail(std::string("the record ends before its ") + what);
    std::string_view f = line_.substr(from, width);
    while (!f.empty() && f.front() == ' ') f.remove_prefix(1);
    while (!f.empty() && f.back() == ' ') f.remove_suffix(1);
    std::int64_t v = 0;
    auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
    if (f.empty() || ec != std::errc() || p != f.data() + f.size())
      fail(std::string("expected an integer (") + what + ") in columns " + std::to_string(from + 1) + "-" +
           std::to_string(from + width) + ", found '" + std::string(f) + "'");
    return v;
  }
  // The last blank-separated integer of the line (the format flag of 2C, 3C and 100C records).
  int trailing_int() const {
    std::size_t e = line_.size();
    while (e > 0 && line_[e - 1] == ' ') --e;
    std::size_t b = e;
    while (b > 0 && line_[b - 1] != ' ') --b;
    int v = -1;
    std::from_chars(line_.data() + b, line_.data() + e, v);
    return v;
  }
  // The 12-column values from `from` to the end of the line, appended to out; returns how many.
  std::size_t values_from(std::size_t from, double* out, std::size_t max) const {
    std::size_t n = 0;
    for (std::size_t p = from; p < line_.size(); p += 12) {
      if (n == max) fail("more values than the block declares");
      const char* b = line_.data() + p;
      const char* e = line_.data() + std::min(p + 12, line_.size());
      while (b < e && *b == ' ') ++b;
      double v = 0;
      auto [q, ec] = std::from_chars(b, e, v);
      if (b == e || (ec != std::errc() && ec != std::errc::result_out_of_range) || q != e)
        fail("expected a number in columns " + std::to_string(p + 1) + "-" + std::to_string(p + 12) +
             ", found '" + std::string(line_.substr(p, 12)) + "'");
      out[n++] = v;
    }
    return n;
  }
  std::size_t id_width(int format) const { return format == 0 ? 5 : 10; }
  // The header's format flag: 0 and 1 ASCII, 2 binary (3 too where `double_ok`: binary float64).
  void check_format(int format, const char* block, bool double_ok) const {
    if (format == 3 && !double_ok)
      fail(std::string("binary float64 data (format 3) in the ") + block +
           ": CalculiX writes binary results as float32 (format 2); format 3 is not read here");
    if (format < 0 || format > 3) fail(std::string("unknown .frd format flag in the ") + block + " header");
  }
  std::uint32_t node_lookup(std::int64_t id) const {
    if (id > 0 && static_cast<std::uint64_t>(id) < dense_.size() && dense_[id] != kNone) return dense_[id];
    if (!sparse_.empty()) {
      auto it = sparse_.find(static_cast<std::uint64_t>(id));
      if (it != sparse_.end()) return it->second;
    }
    return kNone;
  }
  std::uint32_t node_index(std::int64_t id) const {
    const std::uint32_t i = node_lookup(id);
    if (i == kNone) fail("node " + std::to_string(id) + " is not in the file's node block");
    return i;
  }

  void read_nodes();
  void read_elements();
  void read_results();
  void index_nodes();
  void add_element(std::int64_t type, const std::uint32_t* nodes);

  std::string_view text_;
  const std::string& name_;
  std::size_t pos_ = 0;
  std::size_t values_kept_ = 0;  // doubles held by the fields' value arrays so far
  FrdLimits limits_;
  std::string_view line_;
  std::uint64_t line_no_ = 0;
  std::size_t line_start_ = 0;  // byte offset of line_
  bool binary_seen_ = false;
  FieldSource src_;
  std::vector<std::uint32_t> dense_;  // node id -> index (ids up to a few times the count)
  std::unordered_map<std::uint64_t, std::uint32_t> sparse_;  // the others
  double step_value_ = 0;
  bool have_step_ = false;
  int format_ = 1;                               // of the current result block
  std::int64_t step_nodes_ = 0;                  // the 100C header's node count (binary records)
  std::map<std::string, std::size_t> field_of_;  // block name -> index in src_.mesh.fields
};

void FrdParser::read_nodes() {
  if (!src_.mesh.xyz.empty() || !src_.node_id.empty()) fail("a second node block (2C)");
  const int format = trailing_int();
  check_format(format, "node block", true);
  const std::int64_t declared = int_at(6, 30, "node count");
  if (format >= 2) {
    const std::size_t real = format == 2 ? 4 : 8;
    check_fits(declared, 4 + 3 * real, "node block");
    src_.mesh.xyz.reserve(3 * declared);
    src_.node_id.reserve(declared);
    for (std::int64_t k = 0; k < declared; ++k) {
      const std::size_t at = pos_;
      const unsigned char* r = take(4 + 3 * real, "node block");
      const std::int32_t id = int32_at(r);
      if (id <= 0) fail_at(at, "node id " + std::to_string(id) + " is not positive");
      src_.node_id.push_back(static_cast<std::uint64_t>(id));
      for (int c = 0; c < 3; ++c)
        src_.mesh.xyz.push_back(real == 4 ? float32_at(r + 4 + 4 * c) : float64_at(r + 4 + 8 * c));
    }
    index_nodes();
    return;
  }
  const std::size_t w = id_width(format);
  if (declared < 0 || static_cast<std::uint64_t>(declared) > text_.size() / 40 + 1)
    fail("a node count of " + std::to_string(declared) + " that the file is too short to hold");
  src_.mesh.xyz.reserve(3 * declared);
  src_.node_id.reserve(declared);
  while (true) {
    if (!next_line()) fail("the file ends inside the node block");
    if (starts(" -3")) break;
    if (!starts(" -1")) fail("expected a node record (' -1') or the block end (' -3')");
    const std::int64_t id = int_at(3, w, "node id");
    if (id <= 0) fail("node id " + std::to_string(id) + " is not positive");
    double x[3];
    if (values_from(3 + w, x, 3) != 3) fail("a node record without its 3 coordinates");
    src_.node_id.push_back(static_cast<std::uint64_t>(id));
    src_.mesh.xyz.insert(src_.mesh.xyz.end(), x, x + 3);
  }
  if (src_.node_id.size() != static_cast<std::size_t>(declared))
    fail("the node block declares " + std::to_string(declared) + " nodes and holds " +
         std::to_string(src_.node_id.size()));
  index_nodes();
}

void FrdParser::index_nodes() {
  // Ids to indices: a table where the ids are dense enough, a hash map for the rest.
  const std::uint64_t max_id =
      src_.node_id.empty() ? 0 : *std::max_element(src_.node_id.begin(), src_.node_id.end());
  const bool dense = max_id <= 4 * src_.node_id.size() + 1024;
  if (dense) dense_.assign(max_id + 1, kNone);
  for (std::size_t i = 0; i < src_.node_id.size(); ++i) {
    const std::uint64_t id = src_.node_id[i];
    const bool fresh = dense ? dense_[id] == kNone : sparse_.emplace(id, std::uint32_t(i)).second;
    if (!fresh) fail("node id " + std::to_string(id) + " appears twice in the node block");
    if (dense) dense_[id] = static_cast<std::uint32_t>(i);
  }
}

void FrdParser::add_element(std::int64_t type, const std::uint32_t* nodes) {
  if (type == 3 || type == 6) {  // C3D4, C3D10: the 4 corners come first
    src_.mesh.tet.insert(src_.mesh.tet.end(), nodes, nodes + 4);
  }
}

void FrdParser::read_elements() {
  if (src_.node_id.empty()) fail("an element block (3C) before the node block (2C)");
  const int format = trailing_int();
  check_format(format, "element block", false);
  if (format == 2) {
    const std::int64_t declared = int_at(6, 30, "element count");
    check_fits(declared, 4 * 4 + 4 * 2, "element block");  // id type group material + 2 nodes at least
    for (std::int64_t k = 0; k < declared; ++k) {
      const std::size_t at = pos_;
      const std::int32_t type = int32_at(take(16, "element block") + 4);
      if (type < 1 || type > 12) fail_at(at, "unknown element type " + std::to_string(type));
      const int want = kElementNodes[type];
      const unsigned char* r = take(4 * std::size_t(want), "element block");
      std::uint32_t nodes[20];
      for (int j = 0; j < want; ++j) {
        const std::int32_t id = int32_at(r + 4 * j);
        if (id <= 0 || node_lookup(id) == kNone)
          fail_at(at, "element node " + std::to_string(id) + " is not in the file's node block");
        nodes[j] = node_lookup(id);
      }
      add_element(type, nodes);
    }
    return;
  }
  const std::size_t w = id_width(format);
  if (!next_line()) fail("the file ends inside the element block");
  while (!starts(" -3")) {
    if (!starts(" -1")) fail("expected an element record (' -1') or the block end (' -3')");
    const std::int64_t type = int_at(3 + w, 5, "element type");
    if (type < 1 || type > 12) fail("unknown element type " + std::to_string(type));
    const int want = kElementNodes[type];
    std::uint32_t nodes[20];
    int got = 0;
    while (true) {
      if (!next_line()) fail("the file ends inside the element block");
      if (!starts(" -2")) break;
      for (std::size_t p = 3; p < line_.size(); p += w) {
        if (got == want) fail("an element with more nodes than its type " + std::to_string(type) + " has");
        nodes[got++] = node_index(int_at(p, w, "element node"));
      }
    }
    if (got != want)
      fail("an element of type " + std::to_string(type) + " with " + std::to_string(got) + " nodes, not " +
           std::to_string(want));
    add_element(type, nodes);
  }
}

void FrdParser::read_results() {
  if (!have_step_) fail("a result block (-4) without its step header (100C)");
  if (src_.node_id.empty()) fail("a result block before the node block (2C)");
  // " -4  NAME    ncomps irtype"
  std::string name(line_.size() > 5 ? line_.substr(5, 8) : std::string_view{});
  while (!name.empty() && name.front() == ' ') name.erase(0, 1);
  while (!name.empty() && name.back() == ' ') name.pop_back();
  if (name.empty()) fail("a result block without a name");
  const std::uint64_t header_line = line_no_;
  const std::int64_t declared = int_at(13, 5, "component count");
  if (declared < 1 || declared > 64) fail("a component count of " + std::to_string(declared));
  // " -5" component lines; iexist (columns 34-38) 1 marks a component the file does not hold.
  std::vector<std::string> comp_names;
  std::size_t comps = 0;
  for (std::int64_t c = 0; c < declared; ++c) {
    if (!next_line() || !starts(" -5"))
      fail("expected " + std::to_string(declared) + " component lines (' -5')");
    const std::int64_t iexist = line_.size() >= 38 ? int_at(33, 5, "component flag") : 0;
    if (iexist != 1) ++comps;
  }
  // Every component marked as computed by the reader leaves the block nothing to hold: refused, as a
  // field of 0 components would have no values to show (found by fuzzing, tests/data/bad/fuzz/frd).
  if (comps == 0)
    fail("block " + name + " has 0 components in the file: its " + std::to_string(declared) +
         " component line(s) are all flagged as not in the file (1 in columns 34-38)");
  const std::size_t w = id_width(format_);
  const std::size_t n = src_.node_id.size();
  auto it = field_of_.find(name);
  Field* f;
  if (it == field_of_.end()) {
    field_of_.emplace(name, src_.mesh.fields.size());
    src_.mesh.fields.push_back(
        Field{name, FieldLocation::node, static_cast<std::uint32_t>(comps), "", {}, {}});
    f = &src_.mesh.fields.back();
  } else {
    f = &src_.mesh.fields[it->second];
    if (f->components != comps)
      fail("block " + name + " has " + std::to_string(comps) + " components here and " +
           std::to_string(f->components) + " in an earlier step");
  }
  // Memory is bounded by the file (FrdLimits): a mutated file could declare a 64-component block for
  // every node in 3 KB and ask for gigabytes.
  const std::size_t budget = std::max(limits_.min_values, limits_.values_per_byte * text_.size());
  if (n * comps > budget - std::min(budget, values_kept_)) {
    line_no_ = header_line;  // the error names the block's own line
    fail("result block " + name + " would make the fields keep " + std::to_string(values_kept_ + n * comps) +
         " values (" + std::to_string((values_kept_ + n * comps) * sizeof(double) >> 20) + " MB, " +
         std::to_string(n) + " nodes x " + std::to_string(comps) + " components a block) for a file of " +
         std::to_string(text_.size()) + " bytes; foxi keeps at most " + std::to_string(budget) +
         " (blocks that list few of the nodes each stand for all of them)");
  }
  values_kept_ += n * comps;
  const std::size_t step = f->step_values.size();
  f->step_values.push_back(step_value_);
  f->values.resize((step + 1) * n * comps, kNaN);
  double* base = f->values.data() + step * n * comps;
  std::vector<bool> seen(n, false);
  if (format_ == 2) {
    if (comps == 0) fail("binary result block " + name + " stores no component");
    check_fits(step_nodes_, 4 + 4 * comps, "result block " + name);
    for (std::int64_t k = 0; k < step_nodes_; ++k) {
      const std::size_t at = pos_;
      const unsigned char* r = take(4 + 4 * comps, "result block " + name);
      const std::int32_t id = int32_at(r);
      const std::uint32_t i = node_lookup(id);
      if (i == kNone)
        fail_at(at, "node " + std::to_string(id) + " of block " + name + " is not in the file's node block");
      if (seen[i]) fail_at(at, "node " + std::to_string(id) + " appears twice in block " + name);
      seen[i] = true;
      double* out = base + std::size_t(i) * comps;
      for (std::size_t c = 0; c < comps; ++c) out[c] = float32_at(r + 4 + 4 * c);
    }
    return;
  }
  while (true) {
    if (!next_line()) fail("the file ends inside result block " + name);
    if (starts(" -3")) break;
    if (!starts(" -1")) fail("expected a node record (' -1') or the block end (' -3') in block " + name);
    const std::uint32_t i = node_index(int_at(3, w, "node id"));
    if (seen[i]) fail("node " + std::to_string(src_.node_id[i]) + " appears twice in block " + name);
    seen[i] = true;
    double* out = base + std::size_t(i) * comps;
    std::size_t got = values_from(3 + w, out, comps);
    // Values beyond one line continue on " -2" records (6 per line).
    while (got < comps) {
      if (!next_line() || !starts(" -2"))
        fail("node " + std::to_string(src_.node_id[i]) + " of block " + name + " has " + std::to_string(got) +
             " values, not " + std::to_string(comps));
      got += values_from(3 + w, out + got, comps - got);
    }
  }
}

FieldSource FrdParser::parse() {
  src_.path = name_;
  src_.format = "frd";
  src_.key = SourceKey::node_id;
  bool ended = false;
  while (next_line()) {
    if (starts("    2C")) {
      read_nodes();
    } else if (starts("    3C")) {
      read_elements();
    } else if (starts("  100C")) {
      format_ = trailing_int();
      check_format(format_, "result block", false);
      if (format_ == 2) step_nodes_ = int_at(24, 12, "node count");
      double v = 0;
      std::string_view f = line_.size() >= 24 ? line_.substr(12, 12) : std::string_view{};
      while (!f.empty() && f.front() == ' ') f.remove_prefix(1);
      auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || ec != std::errc() || p != f.data() + f.size())
        fail("expected the step value in columns 13-24");
      step_value_ = v;
      have_step_ = true;
    } else if (starts(" -4")) {
      read_results();
    } else if (starts(" 9999") || starts("9999")) {
      ended = true;
      break;
    } else if (starts(" -1") || starts(" -2") || starts(" -5")) {
      fail("a record outside any block");
    }
    // Other records (1C, 1U user text, 1P parameters, blank lines) carry nothing foxi uses.
  }
  if (!ended) fail("the file ends without its end record (9999): truncated?");
  if (src_.node_id.empty()) fail("no node block (2C)");
  // No regions: the file's material and group numbers are not foxi's region ids, and a region
  // restriction on the wrong ids would be worse than none.
  return std::move(src_);
}

}  // namespace

FieldSource parse_frd_source(std::string_view bytes, const std::string& name, const FrdLimits& limits) {
  return FrdParser(bytes, name, limits).parse();
}

FieldSource read_frd_source(const std::filesystem::path& path, const FrdLimits& limits) {
  const std::string bytes = io::read_file(path);
  return parse_frd_source(bytes, path.string(), limits);
}

}  // namespace foxi
