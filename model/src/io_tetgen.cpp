// TetGen .node / .ele / .face and Medit .mesh readers and writers.
//
// Orientation. foxi stores tets with det[p1-p0, p2-p0, p3-p0] > 0. TetGen 1.5 (Debian 1.5.0-5) writes
// its .ele corners in that same order. Verified by experiment: `tetgen -pqAa` on a two-region box
// .poly (two unit cubes), then the determinant of every tet of box.1.ele computed with numpy: 365 of
// 365 positive, signed volumes summing to the box's 2.0; the same with -pA, -pqAaY, -z and -o2. The
// test TetgenOracle.OrientationMatchesFoxi repeats the check against the installed tetgen on every
// run. gmsh's Medit export (`gmsh -3 -format mesh`) gives positive tets as well (checked by
// MeditOracle.GmshFileMatchesMeshioAndAnalyticVolumes), as Medit/MMG expect. So both readers keep the
// vertex order as written: no conversion is needed. A file with inverted tets is reported by
// validate() and fixed by validate_and_repair(), never silently here.
//
// Non-finite coordinates (nan, inf) are rejected with an IoError naming the line: neither format
// can mean anything by them and a located error is more use than a count from validate() later.
//
// Quadratic files: 10-node tets keep their 4 corners, 6-node .face triangles their 3 corners; the
// mid-edge nodes stay in the node list (unused by any tet, so node numbers keep their meaning).
#include "foxi/model/io_tetgen.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {
namespace {

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

// A small non-negative header number (attribute and marker counts).
std::uint64_t header_small(Scanner& in, const char* what) {
  in.to_field<Span::kLine>(what);
  std::size_t at = in.pos();
  std::int64_t v = in.integer<Span::kLine>(what);
  if (v < 0 || static_cast<std::uint64_t>(v) > in.remaining() + 1) {
    in.fail_at(at, "implausible " + std::string(what) + " " + std::to_string(v));
  }
  return static_cast<std::uint64_t>(v);
}


void fill_names(Mesh& m) {
  for (std::int32_t id : io::distinct_ids(m.tet_region)) m.regions.push_back(Region{id, {}, kNone});
  for (std::int32_t tag : io::distinct_ids(m.bface_tag)) m.boundaries.push_back(Boundary{tag, {}});
}

// ---------------------------------------------------------------------------------------------
// TetGen

constexpr Span L = Span::kLine;

std::int64_t parse_node_file(Scanner& in, Mesh& m) {
  if (!in.skip_to_content()) {
    in.fail("empty file, expected the header '<nodes> <dimension> <attributes> <boundary markers>'");
  }
  std::size_t head = in.pos();
  std::int64_t n_probe = in.integer<L>("node count");
  std::int64_t dim = in.integer<L>("dimension");
  if (dim != 3) in.fail_at(head, "dimension is " + std::to_string(dim) + ", foxi reads 3-D meshes only");
  std::uint64_t nattr = header_small(in, "node attribute count");
  std::uint64_t nmark = header_small(in, "boundary marker count");
  in.end_line("the header");
  if (n_probe < 0) in.fail_at(head, "node count is negative (" + std::to_string(n_probe) + ")");
  const std::uint64_t n = static_cast<std::uint64_t>(n_probe);
  if (!io::count_fits(n, 2 * (4 + nattr + nmark), in.remaining() + 1)) {
    in.fail_at(head, "declares " + std::to_string(n) + " nodes but the file has only " +
                         std::to_string(in.remaining()) + " bytes left");
  }
  if (n > kNone - 1) {
    in.fail_at(head, "declares " + std::to_string(n) + " nodes, more than foxi's 32-bit indices hold");
  }
  m.xyz.resize(3 * n);
  std::int64_t offset = 1;
  double* xyz = m.xyz.data();
  for (std::uint64_t k = 0; k < n; ++k) {
    in.set_record("node", k + static_cast<std::uint64_t>(offset));
    if (!in.skip_to_content()) in.fail("unexpected end of file, expected " + std::to_string(n) + " nodes");
    std::size_t at = in.pos();
    std::int64_t id = in.integer<L>("node number");
    if (k == 0) {
      if (id != 0 && id != 1)
        in.fail_at(at, "the first node is numbered " + std::to_string(id) + ", not 0 or 1");
      offset = id;
      in.set_record("node", static_cast<std::uint64_t>(id));
    } else if (id != static_cast<std::int64_t>(k) + offset) {
      in.fail_at(at, "expected node number " + std::to_string(static_cast<std::int64_t>(k) + offset) +
                         ", found " + std::to_string(id) + " (nodes must be numbered consecutively)");
    }
    xyz[3 * k] = in.coordinate<L>("x coordinate");
    xyz[3 * k + 1] = in.coordinate<L>("y coordinate");
    xyz[3 * k + 2] = in.coordinate<L>("z coordinate");
    for (std::uint64_t a = 0; a < nattr; ++a) in.skip_number<L>("node attribute");
    for (std::uint64_t a = 0; a < nmark; ++a) in.skip_number<L>("boundary marker");
    in.end_line("the node's values");
  }
  in.set_record(nullptr, 0);
  if (in.skip_to_content()) in.fail("more data after the " + std::to_string(n) + " declared nodes");
  return offset;
}

void parse_ele_file(Scanner& in, Mesh& m, std::int64_t offset) {
  if (!in.skip_to_content()) {
    in.fail("empty file, expected the header '<tetrahedra> <nodes per tetrahedron> <attributes>'");
  }
  std::size_t head = in.pos();
  std::int64_t n_probe = in.integer<L>("tetrahedron count");
  in.to_field<L>("nodes per tetrahedron");
  std::size_t at_npt = in.pos();
  std::int64_t npt = in.integer<L>("nodes per tetrahedron");
  if (npt != 4 && npt != 10) {
    in.fail_at(at_npt, "tetrahedra have " + std::to_string(npt) + " nodes, expected 4 or 10");
  }
  std::uint64_t nattr = header_small(in, "tetrahedron attribute count");
  in.end_line("the header");
  if (n_probe < 0) in.fail_at(head, "tetrahedron count is negative (" + std::to_string(n_probe) + ")");
  std::uint64_t n = static_cast<std::uint64_t>(n_probe);
  if (!io::count_fits(n, 2 * (1 + static_cast<std::uint64_t>(npt) + nattr), in.remaining() + 1)) {
    in.fail_at(head, "declares " + std::to_string(n) + " tetrahedra but the file has only " +
                         std::to_string(in.remaining()) + " bytes left");
  }
  const std::uint64_t nodes = m.node_count();
  m.tet.resize(4 * n);
  if (nattr > 0) m.tet_region.resize(n);
  std::uint32_t* tet = m.tet.data();
  for (std::uint64_t k = 0; k < n; ++k) {
    in.set_record("tetrahedron", k + 1);
    if (!in.skip_to_content()) {
      in.fail("unexpected end of file, expected " + std::to_string(n) + " tetrahedra");
    }
    (void)in.integer<L>("tetrahedron number");
    for (int c = 0; c < 4; ++c) tet[4 * k + c] = in.node_index<L>("node", offset, nodes);
    for (int c = 4; c < npt; ++c) (void)in.node_index<L>("mid-edge node", offset, nodes);
    if (nattr > 0) m.tet_region[k] = in.id_value<L>("region attribute");
    for (std::uint64_t a = 1; a < nattr; ++a) in.skip_number<L>("attribute");
    in.end_line("the tetrahedron's values");
  }
  in.set_record(nullptr, 0);
  if (in.skip_to_content()) in.fail("more data after the " + std::to_string(n) + " declared tetrahedra");
}

void parse_face_file(Scanner& in, Mesh& m, std::int64_t offset) {
  if (!in.skip_to_content()) in.fail("empty file, expected the header '<faces> <boundary markers>'");
  std::size_t head = in.pos();
  std::int64_t n_probe = in.integer<L>("face count");
  std::uint64_t nmark = header_small(in, "boundary marker count");
  in.end_line("the header");
  if (n_probe < 0) in.fail_at(head, "face count is negative (" + std::to_string(n_probe) + ")");
  std::uint64_t n = static_cast<std::uint64_t>(n_probe);
  if (!io::count_fits(n, 2 * (4 + nmark), in.remaining() + 1)) {
    in.fail_at(head, "declares " + std::to_string(n) + " faces but the file has only " +
                         std::to_string(in.remaining()) + " bytes left");
  }
  const std::uint64_t nodes = m.node_count();
  m.bface.resize(3 * n);
  m.bface_tag.assign(n, 0);
  int mid_nodes = -1;  // 0 or 3 (second-order faces, tetgen -o2), decided by the first face
  for (std::uint64_t k = 0; k < n; ++k) {
    in.set_record("face", k + 1);
    if (!in.skip_to_content()) in.fail("unexpected end of file, expected " + std::to_string(n) + " faces");
    (void)in.integer<L>("face number");
    if (mid_nodes < 0) mid_nodes = in.tokens_left_on_line() == 6 + nmark ? 3 : 0;
    for (int c = 0; c < 3; ++c) m.bface[3 * k + c] = in.node_index<L>("node", offset, nodes);
    for (int c = 0; c < mid_nodes; ++c) (void)in.node_index<L>("mid-edge node", offset, nodes);
    if (nmark > 0) m.bface_tag[k] = in.id_value<L>("boundary marker");
    for (std::uint64_t a = 1; a < nmark; ++a) in.skip_number<L>("boundary marker");
    in.end_line("the face's values");
  }
  in.set_record(nullptr, 0);
  if (in.skip_to_content()) in.fail("more data after the " + std::to_string(n) + " declared faces");
}

// ---------------------------------------------------------------------------------------------
// Writing

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
void check_writable(const Mesh& mesh, const std::string& file) {
  std::string problem = check_sizes(mesh);
  if (!problem.empty())
    throw IoError(file, 0, IoError::kNoOffset, "cannot write an inconsistent mesh: " + problem);
  const std::size_t nodes = mesh.node_count();
  for (std::size_t i = 0; i < mesh.tet.size(); ++i) {
    if (mesh.tet[i] >= nodes) {
      throw IoError(file, 0, IoError::kNoOffset,
                    "cannot write: tetrahedron " + std::to_string(i / 4) + " names node " +
                        std::to_string(mesh.tet[i]) + " of " + std::to_string(nodes));
    }
  }
  for (std::size_t i = 0; i < mesh.bface.size(); ++i) {
    if (mesh.bface[i] >= nodes) {
      throw IoError(file, 0, IoError::kNoOffset,
                    "cannot write: boundary triangle " + std::to_string(i / 3) + " names node " +
                        std::to_string(mesh.bface[i]) + " of " + std::to_string(nodes));
    }
  }
  for (std::size_t i = 0; i < mesh.xyz.size(); ++i) {
    if (!std::isfinite(mesh.xyz[i])) {
      throw IoError(file, 0, IoError::kNoOffset,
                    "cannot write: node " + std::to_string(i / 3) + " has a non-finite coordinate");
    }
  }
}

std::filesystem::path with_suffix(const std::filesystem::path& base, const char* ext) {
  std::filesystem::path p = base;
  p += ext;
  return p;
}

std::string base_string(const std::filesystem::path& base) { return base.string(); }

}  // namespace

Mesh parse_tetgen(std::string_view node_text, std::string_view ele_text, std::string_view face_text,
                  const std::string& base_name) {
  Mesh m;
  Scanner nodes(node_text, base_name + ".node");
  std::int64_t offset = parse_node_file(nodes, m);
  Scanner eles(ele_text, base_name + ".ele");
  parse_ele_file(eles, m, offset);
  if (!face_text.empty()) {
    Scanner faces(face_text, base_name + ".face");
    parse_face_file(faces, m, offset);
  }
  fill_names(m);
  return m;
}

Mesh read_tetgen(const std::filesystem::path& base) {
  std::string node = io::read_file(with_suffix(base, ".node"));
  std::string ele = io::read_file(with_suffix(base, ".ele"));
  std::string face;
  std::filesystem::path face_path = with_suffix(base, ".face");
  std::error_code ec;
  if (std::filesystem::exists(face_path, ec)) {
    face = io::read_file(face_path);
    if (face.empty())
      throw IoError(face_path.string(), 1, 0, "empty file, expected the header '<faces> <boundary markers>'");
  }
  return parse_tetgen(node, ele, face, base_string(base));
}

void write_tetgen(const Mesh& mesh, const std::filesystem::path& base) {
  const std::filesystem::path node_path = with_suffix(base, ".node");
  const std::filesystem::path ele_path = with_suffix(base, ".ele");
  const std::filesystem::path face_path = with_suffix(base, ".face");
  check_writable(mesh, node_path.string());
  // All three are written to temporaries first and committed together with the .node as the
  // marker (commit_together): the old .node goes first and the new one comes last, so a .node on
  // disk always has its own .ele and .face beside it, even after a kill or a power loss.
  std::vector<io::AtomicFile> files;
  files.emplace_back(node_path);
  files.emplace_back(ele_path);
  files.emplace_back(face_path);
  io::AtomicFile &node_file = files[0], &ele_file = files[1], &face_file = files[2];
  {
    Out o(node_file);
    const std::size_t n = mesh.node_count();
    o.num(n);
    o.text(" 3 0 0\n");
    for (std::size_t i = 0; i < n; ++i) {
      o.num(i + 1);
      for (int c = 0; c < 3; ++c) {
        o.sp();
        o.real(mesh.xyz[3 * i + c]);
      }
      o.nl();
    }
    o.flush();
  }
  {
    Out o(ele_file);
    const std::size_t n = mesh.tet_count();
    const bool regions = !mesh.tet_region.empty();
    o.num(n);
    o.text(regions ? " 4 1\n" : " 4 0\n");
    for (std::size_t i = 0; i < n; ++i) {
      o.num(i + 1);
      for (int c = 0; c < 4; ++c) {
        o.sp();
        o.num(std::uint64_t{mesh.tet[4 * i + c]} + 1);
      }
      if (regions) {
        o.sp();
        o.num(mesh.tet_region[i]);
      }
      o.nl();
    }
    o.flush();
  }
  {
    Out o(face_file);
    const std::size_t n = mesh.bface_count();
    o.num(n);
    o.text(" 1\n");
    for (std::size_t i = 0; i < n; ++i) {
      o.num(i + 1);
      for (int c = 0; c < 3; ++c) {
        o.sp();
        o.num(std::uint64_t{mesh.bface[3 * i + c]} + 1);
      }
      o.sp();
      o.num(mesh.bface_tag[i]);
      o.nl();
    }
    o.flush();
  }
  commit_together(files, 0);
}

// ---------------------------------------------------------------------------------------------
// Medit

namespace {

constexpr Span A = Span::kAny;

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

// Keywords foxi does not use, skipped by their count and numbers per record (3-D files).
struct SkipKeyword {
  const char* name;
  int numbers;
};
constexpr SkipKeyword kSkipped[] = {
    {"Edges", 3},
    {"Corners", 1},
    {"Ridges", 1},
    {"RequiredVertices", 1},
    {"RequiredEdges", 1},
    {"RequiredTriangles", 1},
    {"RequiredTetrahedra", 1},
    {"Normals", 3},
    {"NormalAtVertices", 2},
    {"NormalAtTriangleVertices", 3},
    {"Tangents", 3},
    {"TangentAtVertices", 2},
    {"TangentAtEdges", 3},
    {"SubDomainFromMesh", 4},
    {"VertexOnGeometricVertex", 2},
    {"VertexOnGeometricEdge", 3},
    {"EdgeOnGeometricEdge", 2},
};
// Elements foxi cannot represent: an error rather than a mesh silently missing them.
constexpr const char* kUnsupported[] = {"Quadrilaterals", "Hexahedra",    "Prisms",      "Pyramids",
                                        "Hexaedra",       "TetrahedraP2", "TrianglesP2", "EdgesP2"};

struct PendingRange {  // element block read before the Vertices: its indices are checked at the end
  const char* kind;
  std::size_t keyword_pos;
  std::size_t first, count, per;  // range in the index array, indices per element
  bool tets;
};

}  // namespace

Mesh parse_medit(std::string_view bytes, const std::string& name) {
  Mesh m;
  Scanner in(bytes, name);
  std::string_view w = in.word();
  if (w.empty()) in.fail("empty file, expected 'MeshVersionFormatted'");
  if (!iequals(w, "MeshVersionFormatted")) {
    in.fail_at(in.pos() - w.size(),
               "expected 'MeshVersionFormatted', found '" + io::TextCursor::shorten(w) + "'");
  }
  {
    in.to_field<A>("format version");
    std::size_t at = in.pos();
    std::int64_t version = in.integer<A>("format version");
    if (version < 1 || version > 4) in.fail_at(at, "unknown format version " + std::to_string(version));
  }
  bool have_dimension = false, have_vertices = false;
  std::vector<PendingRange> pending;
  std::uint64_t nodes = 0;
  for (;;) {
    in.set_record(nullptr, 0);
    std::size_t kw_pos = in.pos();
    w = in.word();
    if (w.empty()) break;  // a missing End is tolerated, as by libMeshb
    kw_pos = in.pos() - w.size();
    if (iequals(w, "End")) break;  // whatever follows End is not part of the mesh
    if (iequals(w, "Dimension")) {
      in.to_field<A>("dimension");
      std::size_t at = in.pos();
      std::int64_t dim = in.integer<A>("dimension");
      if (dim != 3) in.fail_at(at, "dimension is " + std::to_string(dim) + ", foxi reads 3-D meshes only");
      have_dimension = true;
      continue;
    }
    if (!have_dimension) in.fail_at(kw_pos, "'" + io::TextCursor::shorten(w) + "' before 'Dimension'");
    if (iequals(w, "Vertices")) {
      if (have_vertices) in.fail_at(kw_pos, "a second 'Vertices' section");
      std::uint64_t n = declared_count<A>(in, "vertices", 4);
      if (n > kNone - 1)
        in.fail_at(kw_pos, "declares " + std::to_string(n) + " vertices, more than 32-bit indices hold");
      m.xyz.resize(3 * n);
      double* xyz = m.xyz.data();
      for (std::uint64_t k = 0; k < n; ++k) {
        in.set_record("vertex", k + 1);
        xyz[3 * k] = in.coordinate<A>("x coordinate");
        xyz[3 * k + 1] = in.coordinate<A>("y coordinate");
        xyz[3 * k + 2] = in.coordinate<A>("z coordinate");
        (void)in.id_value<A>("vertex reference");
      }
      nodes = n;
      have_vertices = true;
      continue;
    }
    const bool tets = iequals(w, "Tetrahedra");
    if (tets || iequals(w, "Triangles")) {
      const std::size_t per = tets ? 4 : 3;
      const char* kind = tets ? "tetrahedron" : "triangle";
      std::uint64_t n = declared_count<A>(in, tets ? "tetrahedra" : "triangles", per + 1);
      std::vector<std::uint32_t>& idx = tets ? m.tet : m.bface;
      std::vector<std::int32_t>& ref = tets ? m.tet_region : m.bface_tag;
      std::size_t first = idx.size();
      idx.resize(first + per * n);
      ref.resize(ref.size() + n);
      std::uint32_t* out = idx.data() + first;
      std::int32_t* ref_out = ref.data() + (ref.size() - n);
      if (have_vertices) {
        for (std::uint64_t k = 0; k < n; ++k) {
          in.set_record(kind, k + 1);
          for (std::size_t c = 0; c < per; ++c) out[per * k + c] = in.node_index<A>("vertex", 1, nodes);
          ref_out[k] = in.id_value<A>("reference");
        }
      } else {
        for (std::uint64_t k = 0; k < n; ++k) {
          in.set_record(kind, k + 1);
          for (std::size_t c = 0; c < per; ++c) {
            in.to_field<A>("vertex");
            std::size_t at = in.pos();
            std::int64_t v = in.integer<A>("vertex");
            if (v < 1 || v > static_cast<std::int64_t>(kNone))
              in.fail_at(at, "vertex " + std::to_string(v) + " is out of range");
            out[per * k + c] = static_cast<std::uint32_t>(v - 1);
          }
          ref_out[k] = in.id_value<A>("reference");
        }
        pending.push_back(PendingRange{kind, kw_pos, first, n, per, tets});
      }
      continue;
    }
    if (iequals(w, "Identifier") || iequals(w, "Geometry")) {  // a string: the rest of the line or the next
      std::string_view rest = in.rest_of_line();
      if (rest.find_first_not_of(" \t\f\v") == std::string_view::npos) {
        if (in.skip_to_content()) (void)in.rest_of_line();
      }
      continue;
    }
    bool skipped = false;
    for (const SkipKeyword& s : kSkipped) {
      if (!iequals(w, s.name)) continue;
      std::uint64_t n = declared_count<A>(in, "entries", static_cast<std::uint64_t>(s.numbers));
      for (std::uint64_t k = 0; k < n; ++k) {
        in.set_record(s.name, k + 1);
        for (int c = 0; c < s.numbers; ++c) in.skip_number<A>("number");
      }
      skipped = true;
      break;
    }
    if (skipped) continue;
    for (const char* u : kUnsupported) {
      if (iequals(w, u))
        in.fail_at(
            kw_pos,
            "'" + std::string(u) +
                "' are not supported: foxi reads tetrahedral meshes (4-node tetrahedra, 3-node triangles)");
    }
    in.fail_at(kw_pos, "unknown keyword '" + io::TextCursor::shorten(w) + "'");
  }
  in.set_record(nullptr, 0);
  if (!have_vertices) in.fail("no 'Vertices' section");
  for (const PendingRange& r : pending) {
    const std::vector<std::uint32_t>& idx = r.tets ? m.tet : m.bface;
    for (std::size_t i = 0; i < r.count * r.per; ++i) {
      if (idx[r.first + i] >= nodes) {
        in.fail_at(r.keyword_pos, std::string(r.kind) + " " + std::to_string(i / r.per + 1) + ": vertex " +
                                      std::to_string(std::uint64_t{idx[r.first + i]} + 1) +
                                      " is out of range (vertices are numbered 1.." + std::to_string(nodes) +
                                      ")");
      }
    }
  }
  fill_names(m);
  return m;
}

Mesh read_medit(const std::filesystem::path& path) {
  std::string bytes = io::read_file(path);
  return parse_medit(bytes, path.string());
}

void write_medit(const Mesh& mesh, const std::filesystem::path& path) {
  check_writable(mesh, path.string());
  io::AtomicFile file(path);
  Out o(file);
  o.text("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n");
  const std::size_t n = mesh.node_count();
  o.num(n);
  o.nl();
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      o.real(mesh.xyz[3 * i + c]);
      o.sp();
    }
    o.text("0");
    o.nl();
  }
  if (mesh.tet_count() > 0) {
    o.text("\nTetrahedra\n");
    o.num(mesh.tet_count());
    o.nl();
    for (std::size_t i = 0; i < mesh.tet_count(); ++i) {
      for (int c = 0; c < 4; ++c) {
        o.num(std::uint64_t{mesh.tet[4 * i + c]} + 1);
        o.sp();
      }
      o.num(mesh.region_of(i));
      o.nl();
    }
  }
  if (mesh.bface_count() > 0) {
    o.text("\nTriangles\n");
    o.num(mesh.bface_count());
    o.nl();
    for (std::size_t i = 0; i < mesh.bface_count(); ++i) {
      for (int c = 0; c < 3; ++c) {
        o.num(std::uint64_t{mesh.bface[3 * i + c]} + 1);
        o.sp();
      }
      o.num(mesh.bface_tag[i]);
      o.nl();
    }
  }
  o.text("\nEnd\n");
  o.flush();
  file.commit();
}

}  // namespace foxi
