// Gmsh .msh 2.2 and 4.1 reader, ASCII and binary (the writer is io_gmsh_write.cpp).
// Over 900 lines because it is one class, Reader, whose sections share the cursor and tag maps.
//
// Reading choices (see io_gmsh.hpp for the contract):
// - Nodes are numbered densely in the order they appear in the file; node tags may be sparse,
//   unordered, and (in 4.1) larger than 32 bits. A tag defined twice is an error.
// - Tets and boundary triangles keep the order of the file.
// - Region id of a tet / tag of a triangle: 2.2: its first element tag (physical group), 0 if it has
//   none; 4.1: the first physical tag of its entity ($Entities), 0 when the entity has none or the
//   file has no $Entities section. So "no physical group" is 0 in both versions (as gmsh 2.2 writes).
//   A triangle of a surface in several physical groups is repeated, once with each tag, as a 2.2 file
//   repeats it (a boundary condition on any of the groups finds it); a tet keeps the first.
// - NaN / Inf coordinates are read as they are (validate() reports them); a token that is not a
//   number is an error.
// - Binary files must be little-endian with 8-byte size_t / double (what gmsh writes on all current
//   machines); a byte-swapped file is rejected with a message saying so.
// - $ElementData values of elements that are not tets (triangles, lines, points, or tags that name no
//   element) are ignored; $NodeData naming an undefined node is an error. Blocks with the same name
//   and time step index (partitions) are merged into one step; entities not listed are NaN.
// - Partitioned 4.1 files ($PartitionedEntities) are rejected; other unknown sections are skipped.
#include "foxi/model/io_gmsh.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {
namespace {

using io::TextCursor;

inline bool is_ws(char c) {
  return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v';
}

// Parses the next whitespace-separated number at the cursor: a fast path straight on the bytes,
// falling back to TextCursor::number (which accepts a leading '+' and reports errors) otherwise.
template <class T>
inline T num(TextCursor& c, const char* what) {
  const std::string_view t = c.text();
  const char* b = t.data();
  const char* e = b + t.size();
  const char* q = b + c.pos();
  while (q < e && is_ws(*q)) ++q;
  T v{};
  auto r = std::from_chars(q, e, v);
  if (r.ec == std::errc() && (r.ptr == e || is_ws(*r.ptr))) {
    c.set_pos(static_cast<std::size_t>(r.ptr - b));
    return v;
  }
  return c.number<T>(what);
}

std::string str(std::uint64_t v) { return std::to_string(v); }

// Maps sparse 64-bit tags to dense indices in order of appearance.
class TagMap {
 public:
  // Builds the map; returns the first tag defined twice, or nothing.
  bool build(const std::vector<std::uint64_t>& tags, std::uint64_t* duplicate) {
    n_ = tags.size();
    mode_ = Mode::offset;
    first_ = n_ ? tags[0] : 0;
    bool contiguous = true;
    for (std::size_t i = 0; i < n_; ++i) {
      if (tags[i] != first_ + i) {
        contiguous = false;
        break;
      }
    }
    if (contiguous) return true;
    std::uint64_t lo = *std::min_element(tags.begin(), tags.end());
    std::uint64_t hi = *std::max_element(tags.begin(), tags.end());
    if (hi - lo < 4 * static_cast<std::uint64_t>(n_) + 1024) {
      mode_ = Mode::table;
      first_ = lo;
      table_.assign(hi - lo + 1, kNone);
      for (std::size_t i = 0; i < n_; ++i) {
        std::uint32_t& slot = table_[tags[i] - lo];
        if (slot != kNone) {
          *duplicate = tags[i];
          return false;
        }
        slot = static_cast<std::uint32_t>(i);
      }
      return true;
    }
    mode_ = Mode::sorted;
    sorted_.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) sorted_[i] = {tags[i], static_cast<std::uint32_t>(i)};
    std::sort(sorted_.begin(), sorted_.end());
    for (std::size_t i = 1; i < n_; ++i) {
      if (sorted_[i].first == sorted_[i - 1].first) {
        *duplicate = sorted_[i].first;
        return false;
      }
    }
    return true;
  }

  std::uint32_t find(std::uint64_t tag) const {
    switch (mode_) {
      case Mode::offset: {
        std::uint64_t i = tag - first_;
        return i < n_ ? static_cast<std::uint32_t>(i) : kNone;
      }
      case Mode::table: {
        std::uint64_t i = tag - first_;
        return i < table_.size() ? table_[i] : kNone;
      }
      case Mode::sorted: {
        auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(tag, std::uint32_t{0}));
        return it != sorted_.end() && it->first == tag ? it->second : kNone;
      }
    }
    return kNone;
  }
  bool is_offset() const { return mode_ == Mode::offset; }
  std::uint64_t first() const { return first_; }
  std::uint64_t size() const { return n_; }

 private:
  enum class Mode { offset, table, sorted };
  Mode mode_ = Mode::offset;
  std::uint64_t first_ = 0;
  std::uint64_t n_ = 0;
  std::vector<std::uint32_t> table_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sorted_;
};

// Number of nodes of the element types foxi reads; -1 for any other type. Second-order tets and
// triangles are read as their corner nodes (the first 4 or 3; the mid-edge nodes stay in the node
// list, unused).
int nodes_of_type(std::int64_t type) {
  switch (type) {
    case 15:
      return 1;  // point
    case 1:
      return 2;  // line
    case 8:
      return 3;  // second-order line
    case 2:
      return 3;  // triangle
    case 9:
      return 6;  // second-order triangle
    case 4:
      return 4;  // tet
    case 11:
      return 10;  // second-order tet
    default:
      return -1;
  }
}

// The corners kept: 4 for tets, 3 for triangles, 0 for elements that are skipped.
int corners_of_type(std::int64_t type) {
  switch (type) {
    case 4:
    case 11:
      return 4;
    case 2:
    case 9:
      return 3;
    default:
      return 0;
  }
}

std::string type_name(std::int64_t type) {
  switch (type) {
    case 3:
      return " (4-node quadrangle)";
    case 5:
      return " (8-node hexahedron)";
    case 6:
      return " (6-node prism)";
    case 7:
      return " (5-node pyramid)";
    default:
      return "";
  }
}

struct PendingStep {
  std::int64_t index = 0;
  double time = 0;
  std::vector<double> values;
};
struct PendingField {
  std::string name;
  FieldLocation location = FieldLocation::node;
  std::uint32_t components = 1;
  std::vector<PendingStep> steps;
};

class Reader {
 public:
  Reader(std::string_view data, const std::string& name) : data_(data), name_(name), cur_(data, name) {}

  Mesh run() {
    cur_.skip_space();
    if (cur_.at_end()) cur_.fail("empty file, expected '$MeshFormat'");
    {
      std::size_t at = cur_.pos();
      std::string_view first = cur_.token("$MeshFormat");
      if (first == "$NOD" || first == "$PTS") cur_.fail_at(at, "Gmsh version 1 files are not supported");
      if (first != "$MeshFormat") {
        cur_.fail_at(at,
                     "not a Gmsh file: expected '$MeshFormat', found '" + TextCursor::shorten(first) + "'");
      }
    }
    read_format();
    while (true) {
      cur_.skip_space();
      if (cur_.pos() >= data_.size()) break;
      std::size_t at = cur_.pos();
      std::string_view sec = cur_.token("a section");
      if (sec.empty() || sec[0] != '$') {
        cur_.fail_at(at, "expected a section such as '$Nodes', found '" + TextCursor::shorten(sec) + "'");
      }
      if (sec == "$PhysicalNames") {
        read_physical_names();
      } else if (sec == "$Entities" && version_ == 41) {
        read_entities();
      } else if (sec == "$Nodes") {
        if (have_nodes_) cur_.fail_at(at, "second $Nodes section");
        if (version_ == 41)
          read_nodes41();
        else
          read_nodes22();
        finish_nodes(at);
      } else if (sec == "$Elements") {
        if (!have_nodes_) cur_.fail_at(at, "$Elements before $Nodes");
        if (have_elements_) cur_.fail_at(at, "second $Elements section");
        if (version_ == 41)
          read_elements41();
        else
          read_elements22();
        have_elements_ = true;
      } else if (sec == "$NodeData") {
        if (!have_nodes_) cur_.fail_at(at, "$NodeData before $Nodes");
        read_data(true);
      } else if (sec == "$ElementData") {
        if (!have_elements_) cur_.fail_at(at, "$ElementData before $Elements");
        read_data(false);
      } else if (sec == "$PartitionedEntities") {
        cur_.fail_at(at, "partitioned meshes ($PartitionedEntities) are not supported");
      } else if (sec.substr(0, 4) == "$End") {
        cur_.fail_at(at, "unexpected '" + TextCursor::shorten(sec) + "' with no section open");
      } else if (sec == "$MeshFormat") {
        cur_.fail_at(at, "second $MeshFormat section");
      } else {
        skip_section(sec, at);
      }
    }
    if (!have_nodes_) cur_.fail("no $Nodes section");
    return finish();
  }

 private:
  // ---- structure ----
  void read_format() {
    std::size_t at = cur_.pos();
    std::string_view v = cur_.token("a version number");
    if (v == "2.2" || v == "2.1" || v == "2" || v == "2.0") {
      version_ = 22;
    } else if (v == "4.1") {
      version_ = 41;
    } else {
      cur_.fail_at(
          at, "Gmsh format version '" + TextCursor::shorten(v) + "' is not supported (supported: 2.2, 4.1)");
    }
    std::int64_t type = num<std::int64_t>(cur_, "file type (0 ASCII, 1 binary)");
    if (type != 0 && type != 1) cur_.fail("file type must be 0 (ASCII) or 1 (binary), found " + str(type));
    binary_ = type == 1;
    std::int64_t size = num<std::int64_t>(cur_, "data size");
    if (binary_) {
      if (size != 8) cur_.fail("binary files with data size " + str(size) + " are not supported (only 8)");
      cur_.rest_of_line();
      std::size_t p = cur_.pos();
      if (data_.size() - p < 4)
        io::fail_binary(name_, p, "file ends before the binary endianness check (int 1)");
      std::int32_t one = io::load<std::int32_t>(data_.data() + p);
      if (one != 1) {
        if (io::load<std::int32_t>(data_.data() + p, true) == 1) {
          io::fail_binary(name_, p, "byte-swapped (big-endian) binary file: not supported");
        }
        io::fail_binary(name_, p,
                        "bad endianness check: the int after the header should be 1, is " +
                            str(static_cast<std::uint32_t>(one)));
      }
      cur_.set_pos(p + 4);
    }
    cur_.expect("$EndMeshFormat");
  }

  void skip_section(std::string_view sec, std::size_t at) {
    std::string end = "$End" + std::string(sec.substr(1));
    std::size_t p = cur_.pos();
    while (true) {
      std::size_t f = data_.find(end, p);
      if (f == std::string_view::npos) {
        cur_.fail_at(at,
                     "section '" + TextCursor::shorten(sec) + "' has no '" + TextCursor::shorten(end) + "'");
      }
      std::size_t e = f + end.size();
      // The marker must stand alone on its line.
      if ((f == 0 || data_[f - 1] == '\n' || data_[f - 1] == '\r') &&
          (e == data_.size() || is_ws(data_[e]))) {
        cur_.set_pos(e);
        return;
      }
      p = f + 1;
    }
  }

  std::string quoted() {
    cur_.skip_space();
    std::size_t at = cur_.pos();
    if (at < data_.size() && data_[at] == '"') {
      std::size_t e = at + 1;
      while (e < data_.size() && data_[e] != '"' && data_[e] != '\n' && data_[e] != '\r') ++e;
      if (e >= data_.size() || data_[e] != '"') cur_.fail_at(at, "string has no closing '\"'");
      cur_.set_pos(e + 1);
      return std::string(data_.substr(at + 1, e - at - 1));
    }
    return std::string(cur_.token("a string"));
  }

  // Reads a count and checks that `count` items of at least `min_bytes` each fit in the file.
  std::uint64_t count(const char* what, std::uint64_t min_bytes, std::uint64_t limit = kNone - 1) {
    std::size_t at = cur_.pos();
    std::int64_t c = num<std::int64_t>(cur_, what);
    check_count(c, what, min_bytes, at, limit);
    return static_cast<std::uint64_t>(c);
  }
  void check_count(std::int64_t c, const char* what, std::uint64_t min_bytes, std::size_t at,
                   std::uint64_t limit = kNone - 1) {
    if (c < 0) cur_.fail_at(at, std::string("negative ") + what + ": " + std::to_string(c));
    std::uint64_t u = static_cast<std::uint64_t>(c);
    if (!io::count_fits(u, min_bytes, cur_.remaining())) {
      cur_.fail_at(at, "declares " + str(u) + " " + what + " but the file has only " + str(cur_.remaining()) +
                           " bytes left");
    }
    if (u > limit) cur_.fail_at(at, "declares " + str(u) + " " + what + ", more than foxi supports");
  }

  // Binary: checks that `bytes` remain at the cursor.
  const char* need(std::uint64_t bytes, const std::string& what) {
    std::size_t p = cur_.pos();
    if (bytes > data_.size() - p) {
      io::fail_binary(name_, p,
                      "file ends inside " + what + ": needs " + str(bytes) + " bytes, " +
                          str(data_.size() - p) + " left");
    }
    return data_.data() + p;
  }
  void advance(std::uint64_t bytes) { cur_.set_pos(cur_.pos() + bytes); }
  template <class T>
  T bin(const std::string& what) {
    const char* p = need(sizeof(T), what);
    advance(sizeof(T));
    return io::load<T>(p);
  }
  std::uint64_t bin_count(const std::string& what, std::uint64_t min_bytes, std::uint64_t limit = kNone - 1) {
    std::size_t at = cur_.pos();
    std::uint64_t c = bin<std::uint64_t>(what);
    if (!io::count_fits(c, min_bytes, cur_.remaining())) {
      io::fail_binary(name_, at,
                      "declares " + str(c) + " " + what + " but the file has only " + str(cur_.remaining()) +
                          " bytes left");
    }
    if (c > limit)
      io::fail_binary(name_, at, "declares " + str(c) + " " + what + ", more than foxi supports");
    return c;
  }
  std::int32_t to_i32(std::int64_t v, std::size_t at, const char* what) {
    if (v < std::numeric_limits<std::int32_t>::min() || v > std::numeric_limits<std::int32_t>::max()) {
      cur_.fail_at(at, std::string(what) + " " + std::to_string(v) + " does not fit in 32 bits");
    }
    return static_cast<std::int32_t>(v);
  }

  void read_physical_names() {
    std::uint64_t n = count("physical names", 6);
    for (std::uint64_t i = 0; i < n; ++i) {
      std::size_t at = cur_.pos();
      std::int64_t dim = num<std::int64_t>(cur_, "physical dimension");
      std::int32_t tag = to_i32(num<std::int64_t>(cur_, "physical tag"), at, "physical tag");
      std::string nm = quoted();
      // One tag named twice differently: which name was meant is not known (the last won in silence).
      if (dim == 2 || dim == 3) {
        auto& names = dim == 2 ? surface_names_ : volume_names_;
        const auto [it, fresh] = names.emplace(tag, nm);
        // (at the name: `at` may be the end of the line before)
        if (!fresh && it->second != nm)
          cur_.fail_at(cur_.pos() - 1, "physical " + std::string(dim == 2 ? "surface" : "volume") + " " +
                                           std::to_string(tag) + " is named twice: '" + it->second +
                                           "' and '" + nm + "'");
      }
    }
    cur_.expect("$EndPhysicalNames");
  }

  void read_entities() {
    std::uint64_t n[4];
    if (binary_) {
      cur_.rest_of_line();
      const std::uint64_t mins[4] = {4 + 24 + 8, 4 + 48 + 16, 4 + 48 + 16, 4 + 48 + 16};
      for (int d = 0; d < 4; ++d) n[d] = bin_count("entities", mins[d]);
      for (int d = 0; d < 4; ++d) {
        for (std::uint64_t i = 0; i < n[d]; ++i) {
          std::int32_t tag = bin<std::int32_t>("an entity");
          need(d == 0 ? 24 : 48, "an entity");
          advance(d == 0 ? 24 : 48);
          std::uint64_t np = bin_count("physical tags", 4);
          const char* p = need(4 * np, "physical tags");
          if (np > 0) entity_phys_[d][tag] = io::load<std::int32_t>(p);
          for (std::uint64_t k = 1; d == 2 && k < np; ++k)
            entity_more_phys_[tag].push_back(io::load<std::int32_t>(p + 4 * k));
          advance(4 * np);
          if (d > 0) {
            std::uint64_t nb = bin_count("bounding entities", 4);
            need(4 * nb, "bounding entities");
            advance(4 * nb);
          }
        }
      }
    } else {
      for (int d = 0; d < 4; ++d) n[d] = count("entities", 10);
      for (int d = 0; d < 4; ++d) {
        for (std::uint64_t i = 0; i < n[d]; ++i) {
          std::size_t at = cur_.pos();
          std::int32_t tag = to_i32(num<std::int64_t>(cur_, "entity tag"), at, "entity tag");
          for (int k = 0; k < (d == 0 ? 3 : 6); ++k) num<double>(cur_, "entity bounding box coordinate");
          std::uint64_t np = count("physical tags", 2);
          for (std::uint64_t k = 0; k < np; ++k) {
            std::size_t pat = cur_.pos();
            std::int32_t ph = to_i32(num<std::int64_t>(cur_, "physical tag"), pat, "physical tag");
            if (k == 0) entity_phys_[d][tag] = ph;
            if (k > 0 && d == 2) entity_more_phys_[tag].push_back(ph);
          }
          if (d > 0) {
            std::uint64_t nb = count("bounding entities", 2);
            for (std::uint64_t k = 0; k < nb; ++k) num<std::int64_t>(cur_, "bounding entity tag");
          }
        }
      }
    }
    cur_.expect("$EndEntities");
  }

  // ---- nodes ----
  void read_nodes22() {
    std::uint64_t n = count("nodes", binary_ ? 28 : 8);
    io::reserve_huge(mesh_.xyz, 3 * n);
    io::reserve_huge(node_tags_, n);
    mesh_.xyz.resize(3 * n);
    node_tags_.resize(n);
    double* xyz = mesh_.xyz.data();
    if (binary_) {
      cur_.rest_of_line();
      const char* p = need(28 * n, "node records");
      for (std::uint64_t i = 0; i < n; ++i, p += 28) {
        std::int32_t tag = io::load<std::int32_t>(p);
        if (tag < 0)
          io::fail_binary(name_, static_cast<std::size_t>(p - data_.data()),
                          "negative node tag " + std::to_string(tag));
        node_tags_[i] = static_cast<std::uint64_t>(tag);
        std::memcpy(xyz + 3 * i, p + 4, 24);
      }
      advance(28 * n);
    } else {
      for (std::uint64_t i = 0; i < n; ++i) {
        node_tags_[i] = num<std::uint64_t>(cur_, "node tag");
        xyz[3 * i] = num<double>(cur_, "x coordinate");
        xyz[3 * i + 1] = num<double>(cur_, "y coordinate");
        xyz[3 * i + 2] = num<double>(cur_, "z coordinate");
      }
    }
    cur_.expect("$EndNodes");
  }

  void read_nodes41() {
    std::uint64_t blocks, n;
    std::size_t at = cur_.pos();
    if (binary_) {
      cur_.rest_of_line();
      at = cur_.pos();
      blocks = bin_count("node blocks", 20);
      n = bin_count("nodes", 32);
      bin<std::uint64_t>("minimum node tag");
      bin<std::uint64_t>("maximum node tag");
    } else {
      blocks = count("node blocks", 8);
      n = count("nodes", 8);
      num<std::uint64_t>(cur_, "minimum node tag");
      num<std::uint64_t>(cur_, "maximum node tag");
    }
    io::reserve_huge(mesh_.xyz, 3 * n);
    io::reserve_huge(node_tags_, n);
    mesh_.xyz.resize(3 * n);
    node_tags_.resize(n);
    std::uint64_t done = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      std::size_t bat = cur_.pos();
      std::int64_t dim, par;
      std::uint64_t m;
      if (binary_) {
        const char* p = need(20, "a node block header");
        dim = io::load<std::int32_t>(p);
        par = io::load<std::int32_t>(p + 8);
        advance(12);
        m = bin_count("nodes in a block", 32);
      } else {
        dim = num<std::int64_t>(cur_, "entity dimension");
        num<std::int64_t>(cur_, "entity tag");
        par = num<std::int64_t>(cur_, "parametric flag");
        m = count("nodes in a block", 8);
      }
      if (dim < 0 || dim > 3) fail_at(bat, "entity dimension must be 0 to 3, found " + std::to_string(dim));
      if (par != 0 && par != 1) fail_at(bat, "parametric flag must be 0 or 1, found " + std::to_string(par));
      if (m > n - done) {
        fail_at(bat, "node blocks hold more nodes than the " + str(n) + " declared in the header");
      }
      const std::uint64_t extra = par ? static_cast<std::uint64_t>(dim) : 0;
      const std::uint64_t per = 3 + extra;
      std::uint64_t* tags = node_tags_.data() + done;
      double* xyz = mesh_.xyz.data() + 3 * done;
      if (binary_ && m > 0) {  // (an empty block: no memcpy, whose pointers may then be null)
        const char* p = need(m * (8 + 8 * per), "node block");
        std::memcpy(tags, p, 8 * m);
        p += 8 * m;
        if (per == 3) {
          std::memcpy(xyz, p, 24 * m);
        } else {
          for (std::uint64_t i = 0; i < m; ++i) std::memcpy(xyz + 3 * i, p + 8 * per * i, 24);
        }
        advance(m * (8 + 8 * per));
      } else {
        for (std::uint64_t i = 0; i < m; ++i) tags[i] = num<std::uint64_t>(cur_, "node tag");
        for (std::uint64_t i = 0; i < m; ++i) {
          xyz[3 * i] = num<double>(cur_, "x coordinate");
          xyz[3 * i + 1] = num<double>(cur_, "y coordinate");
          xyz[3 * i + 2] = num<double>(cur_, "z coordinate");
          for (std::uint64_t k = 0; k < extra; ++k) num<double>(cur_, "parametric coordinate");
        }
      }
      done += m;
    }
    if (done != n) fail_at(at, "header declares " + str(n) + " nodes but the blocks hold " + str(done));
    cur_.expect("$EndNodes");
  }

  void finish_nodes(std::size_t at) {
    std::uint64_t dup = 0;
    if (!nodes_.build(node_tags_, &dup)) fail_at(at, "node tag " + str(dup) + " is defined twice");
    have_nodes_ = true;
  }

  std::size_t here() {
    cur_.skip_space();
    return cur_.pos();
  }

  [[noreturn]] void fail_at(std::size_t offset, const std::string& reason) {
    if (binary_) io::fail_binary(name_, offset, reason);
    cur_.fail_at(offset, reason);
  }

  [[noreturn]] void undefined_node(std::uint64_t tag, std::size_t offset) {
    fail_at(offset, "element refers to node " + str(tag) + ", which is not defined in $Nodes");
  }

  // ---- elements ----
  void add_element(int nn, std::int32_t phys, const std::uint32_t* v, std::uint64_t tag) {
    if (nn == 4) {
      mesh_.tet.insert(mesh_.tet.end(), v, v + 4);
      mesh_.tet_region.push_back(phys);
      note_tet_tag(tag, mesh_.tet_region.size() - 1);
    } else if (nn == 3) {
      mesh_.bface.insert(mesh_.bface.end(), v, v + 3);
      mesh_.bface_tag.push_back(phys);
    }
  }

  void read_elements22() {
    std::size_t at = cur_.pos();
    std::uint64_t n = count("elements", 8);
    io::reserve_huge(mesh_.tet, 4 * n);
    io::reserve_huge(mesh_.tet_region, n);
    io::reserve_huge(mesh_.bface, 3 * n);
    io::reserve_huge(mesh_.bface_tag, n);
    std::uint32_t v[10];
    if (binary_) {
      cur_.rest_of_line();
      std::uint64_t done = 0;
      while (done < n) {
        std::size_t hat = cur_.pos();
        const char* h = need(12, "an element block header");
        std::int32_t type = io::load<std::int32_t>(h);
        std::int32_t follow = io::load<std::int32_t>(h + 4);
        std::int32_t ntags = io::load<std::int32_t>(h + 8);
        advance(12);
        int nn = nodes_of_type(type);
        if (nn < 0) fail_at(hat, "unsupported element type " + std::to_string(type) + type_name(type));
        if (follow < 0 || static_cast<std::uint64_t>(follow) > n - done) {
          fail_at(hat, "element block of " + std::to_string(follow) + " elements does not fit the " + str(n) +
                           " declared");
        }
        if (ntags < 0 || ntags > 1000) fail_at(hat, "bad number of element tags " + std::to_string(ntags));
        const std::uint64_t rec = 4 * (1 + static_cast<std::uint64_t>(ntags) + nn);
        const char* p = need(rec * follow, "element records");
        for (std::int32_t i = 0; i < follow; ++i, p += rec) {
          std::int32_t phys = ntags > 0 ? io::load<std::int32_t>(p + 4) : 0;
          const char* q = p + 4 + 4 * ntags;
          for (int k = 0; k < nn; ++k) {
            std::int32_t t = io::load<std::int32_t>(q + 4 * k);
            std::uint32_t idx = t < 0 ? kNone : nodes_.find(static_cast<std::uint64_t>(t));
            if (idx == kNone)
              undefined_node(static_cast<std::uint64_t>(t),
                             static_cast<std::size_t>(q + 4 * k - data_.data()));
            v[k] = idx;
          }
          add_element(corners_of_type(type), phys, v, static_cast<std::uint64_t>(io::load<std::int32_t>(p)));
        }
        advance(rec * follow);
        done += static_cast<std::uint64_t>(follow);
      }
    } else {
      for (std::uint64_t i = 0; i < n; ++i) {
        std::uint64_t tag = num<std::uint64_t>(cur_, "element number");
        std::size_t tat = here();
        std::int64_t type = num<std::int64_t>(cur_, "element type");
        int nn = nodes_of_type(type);
        if (nn < 0) cur_.fail_at(tat, "unsupported element type " + std::to_string(type) + type_name(type));
        std::size_t gat = cur_.pos();
        std::int64_t ntags = num<std::int64_t>(cur_, "number of element tags");
        if (ntags < 0 || ntags > 1000)
          cur_.fail_at(gat, "bad number of element tags " + std::to_string(ntags));
        std::int32_t phys = 0;
        for (std::int64_t k = 0; k < ntags; ++k) {
          std::size_t pat = cur_.pos();
          std::int64_t t = num<std::int64_t>(cur_, "element tag");
          if (k == 0) phys = to_i32(t, pat, "physical tag");
        }
        for (int k = 0; k < nn; ++k) {
          std::size_t nat = here();
          std::uint64_t t = num<std::uint64_t>(cur_, "node number");
          std::uint32_t idx = nodes_.find(t);
          if (idx == kNone) undefined_node(t, nat);
          v[k] = idx;
        }
        add_element(corners_of_type(type), phys, v, tag);
      }
    }
    (void)at;
    cur_.expect("$EndElements");
  }

  void note_tet_tag(std::uint64_t tag, std::uint64_t tet) {
    if (!tet_tag_runs_.empty()) {
      TagRun& r = tet_tag_runs_.back();
      if (r.tag0 + r.count == tag && r.first + r.count == tet) [[likely]] {
        ++r.count;
        return;
      }
    }
    new_tag_run(tag, tet);
  }
  void new_tag_run(std::uint64_t tag, std::uint64_t tet) { tet_tag_runs_.push_back({tag, tet, 1}); }
  void add_tag_run(std::uint64_t tag0, std::uint64_t first, std::uint64_t count) {
    if (!tet_tag_runs_.empty()) {
      TagRun& r = tet_tag_runs_.back();
      if (r.tag0 + r.count == tag0 && r.first + r.count == first) {
        r.count += count;
        return;
      }
    }
    tet_tag_runs_.push_back({tag0, first, count});
  }
  // A run of consecutive element tags kept in registers inside a block loop.
  struct LocalRun {
    std::uint64_t tag0 = 0, first = 0, count = 0;
    void note(std::uint64_t tag, std::uint64_t tet, Reader& r) {
      if (count != 0 && tag == tag0 + count) [[likely]] {
        ++count;
        return;
      }
      flush(r);
      tag0 = tag;
      first = tet;
      count = 1;
    }
    void flush(Reader& r) {
      if (count != 0) r.add_tag_run(tag0, first, count);
      count = 0;
    }
  };

  // The last m triangles again for each further physical tag of their surface entity.
  void repeat_triangles(std::int64_t dim, std::int64_t tag, std::uint64_t m) {
    if (dim != 2) return;
    const auto it = entity_more_phys_.find(tag);
    if (it == entity_more_phys_.end()) return;
    // Bounded memory: a hostile file could name a surface in millions of groups.
    if (it->second.size() > 255)
      fail_at(cur_.pos(), "surface entity " + std::to_string(tag) + " is in " +
                              std::to_string(it->second.size() + 1) + " physical groups, more than 256");
    if (mesh_.bface_tag.size() + m * it->second.size() >= kNone)
      fail_at(cur_.pos(), "more than 4294967294 boundary triangles (a surface's triangles once per group)");
    const std::size_t first = mesh_.bface_tag.size() - m;
    // A copy: inserting a vector's own elements into it may read them after it reallocated.
    const std::vector<std::uint32_t> block(mesh_.bface.begin() + std::ptrdiff_t(3 * first),
                                           mesh_.bface.end());
    for (std::int32_t phys : it->second) {
      mesh_.bface.insert(mesh_.bface.end(), block.begin(), block.end());
      mesh_.bface_tag.insert(mesh_.bface_tag.end(), m, phys);
    }
  }

  std::int32_t entity_physical(std::int64_t dim, std::int64_t tag) const {
    if (dim < 0 || dim > 3) return 0;
    auto it = entity_phys_[dim].find(tag);
    return it == entity_phys_[dim].end() ? 0 : it->second;
  }

  template <int NN, int NC, class Find>
  void block41_binary(std::uint64_t m, std::int32_t phys, Find find) {
    // NN nodes per element in the file, the first NC (4: tet, 3: triangle) kept.
    constexpr std::uint64_t rec = 8 * (1 + NN);
    const char* p = need(m * rec, "element block");
    std::vector<std::uint32_t>& out = NC == 4 ? mesh_.tet : mesh_.bface;
    std::vector<std::int32_t>& reg = NC == 4 ? mesh_.tet_region : mesh_.bface_tag;
    std::size_t base = out.size() / NC;
    out.resize(out.size() + NC * m);
    reg.resize(reg.size() + m, phys);
    std::uint32_t* o = out.data() + NC * base;
    LocalRun run;
    for (std::uint64_t i = 0; i < m; ++i, p += rec) {
      if (NC == 4) run.note(io::load<std::uint64_t>(p), base + i, *this);
      for (int k = 0; k < NN; ++k) {
        std::uint64_t t = io::load<std::uint64_t>(p + 8 + 8 * k);
        std::uint32_t idx = find(t);
        if (idx == kNone) undefined_node(t, static_cast<std::size_t>(p + 8 + 8 * k - data_.data()));
        if (k < NC) o[NC * i + k] = idx;
      }
    }
    if (NC == 4) run.flush(*this);
    advance(m * rec);
  }

  template <int NN, int NC, class Find>
  void block41_ascii(std::uint64_t m, std::int32_t phys, Find find) {
    std::vector<std::uint32_t>& out = NC == 4 ? mesh_.tet : mesh_.bface;
    std::vector<std::int32_t>& reg = NC == 4 ? mesh_.tet_region : mesh_.bface_tag;
    std::size_t base = out.size() / NC;
    out.resize(out.size() + NC * m);
    reg.resize(reg.size() + m, phys);
    std::uint32_t* o = out.data() + NC * base;
    LocalRun run;
    for (std::uint64_t i = 0; i < m; ++i) {
      std::uint64_t tag = num<std::uint64_t>(cur_, "element tag");
      if (NC == 4) run.note(tag, base + i, *this);
      for (int k = 0; k < NN; ++k) {
        std::size_t nat = here();
        std::uint64_t t = num<std::uint64_t>(cur_, "node tag");
        std::uint32_t idx = find(t);
        if (idx == kNone) undefined_node(t, nat);
        if (k < NC) o[NC * i + k] = idx;
      }
    }
    if (NC == 4) run.flush(*this);
  }

  template <int NN, int NC>
  void block41(std::uint64_t m, std::int32_t phys) {
    if (nodes_.is_offset()) {
      const std::uint64_t first = nodes_.first(), n = nodes_.size();
      auto find = [first, n](std::uint64_t t) {
        std::uint64_t i = t - first;
        return i < n ? static_cast<std::uint32_t>(i) : kNone;
      };
      if (binary_)
        block41_binary<NN, NC>(m, phys, find);
      else
        block41_ascii<NN, NC>(m, phys, find);
    } else {
      auto find = [this](std::uint64_t t) { return nodes_.find(t); };
      if (binary_)
        block41_binary<NN, NC>(m, phys, find);
      else
        block41_ascii<NN, NC>(m, phys, find);
    }
  }

  void read_elements41() {
    std::uint64_t blocks, n;
    std::size_t at = cur_.pos();
    if (binary_) {
      cur_.rest_of_line();
      at = cur_.pos();
      blocks = bin_count("element blocks", 20);
      n = bin_count("elements", 16, std::numeric_limits<std::uint64_t>::max());
      bin<std::uint64_t>("minimum element tag");
      bin<std::uint64_t>("maximum element tag");
    } else {
      blocks = count("element blocks", 8);
      n = count("elements", 4, std::numeric_limits<std::uint64_t>::max());
      num<std::uint64_t>(cur_, "minimum element tag");
      num<std::uint64_t>(cur_, "maximum element tag");
    }
    // Any element may be a tet or a triangle: reserve for both (address space only).
    io::reserve_huge(mesh_.tet, 4 * n);
    io::reserve_huge(mesh_.tet_region, n);
    io::reserve_huge(mesh_.bface, 3 * n);
    io::reserve_huge(mesh_.bface_tag, n);
    std::uint64_t done = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      std::size_t bat = cur_.pos();
      std::int64_t dim, etag, type;
      std::uint64_t m;
      if (binary_) {
        const char* p = need(20, "an element block header");
        dim = io::load<std::int32_t>(p);
        etag = io::load<std::int32_t>(p + 4);
        type = io::load<std::int32_t>(p + 8);
        advance(12);
        int nn = nodes_of_type(type);
        if (nn < 0) fail_at(bat + 8, "unsupported element type " + std::to_string(type) + type_name(type));
        m = bin_count("elements in a block", 8 * (1 + static_cast<std::uint64_t>(nn)),
                      std::numeric_limits<std::uint64_t>::max());
      } else {
        dim = num<std::int64_t>(cur_, "entity dimension");
        etag = num<std::int64_t>(cur_, "entity tag");
        std::size_t tat = here();
        type = num<std::int64_t>(cur_, "element type");
        int nn = nodes_of_type(type);
        if (nn < 0) fail_at(tat, "unsupported element type " + std::to_string(type) + type_name(type));
        m = count("elements in a block", 2 * (1 + static_cast<std::uint64_t>(nn)),
                  std::numeric_limits<std::uint64_t>::max());
      }
      if (m > n - done) fail_at(bat, "element blocks hold more elements than the " + str(n) + " declared");
      const std::int32_t phys = entity_physical(dim, etag);
      switch (type) {
        case 4:
          block41<4, 4>(m, phys);
          break;
        case 11:
          block41<10, 4>(m, phys);
          break;
        case 2:
          block41<3, 3>(m, phys);
          repeat_triangles(dim, etag, m);
          break;
        case 9:
          block41<6, 3>(m, phys);
          repeat_triangles(dim, etag, m);
          break;
        default:
          skip_block41(m, nodes_of_type(type));
          break;
      }
      if (mesh_.tet_count() >= kNone) fail_at(bat, "more than 4294967294 tets");
      done += m;
    }
    if (done != n) fail_at(at, "header declares " + str(n) + " elements but the blocks hold " + str(done));
    cur_.expect("$EndElements");
  }

  void skip_block41(std::uint64_t m, int nn) {
    if (binary_) {
      need(m * 8 * (1 + nn), "element block");
      advance(m * 8 * (1 + nn));
      return;
    }
    for (std::uint64_t i = 0; i < m; ++i) {
      num<std::uint64_t>(cur_, "element tag");
      for (int k = 0; k < nn; ++k) {
        std::size_t nat = here();
        std::uint64_t t = num<std::uint64_t>(cur_, "node tag");
        if (nodes_.find(t) == kNone) undefined_node(t, nat);
      }
    }
  }

  // ---- fields ----
  void read_data(bool node) {
    const char* end = node ? "$EndNodeData" : "$EndElementData";
    std::size_t at = cur_.pos();
    std::uint64_t ns = count("string tags", 2, 1000);
    std::string fname;
    for (std::uint64_t i = 0; i < ns; ++i) {
      std::string s = quoted();
      if (i == 0) fname = std::move(s);
    }
    std::uint64_t nr = count("real tags", 2, 1000);
    double time = 0;
    for (std::uint64_t i = 0; i < nr; ++i) {
      double r = num<double>(cur_, "real tag");
      if (i == 0) time = r;
    }
    std::size_t iat = cur_.pos();
    std::uint64_t ni = count("integer tags", 2, 1000);
    std::int64_t it[3] = {0, 1, 0};
    std::size_t cat = cur_.pos();
    for (std::uint64_t i = 0; i < ni; ++i) {
      if (i == 2) cat = cur_.pos();
      std::int64_t v = num<std::int64_t>(cur_, "integer tag");
      if (i < 3) it[i] = v;
    }
    if (ni < 3) {
      cur_.fail_at(iat, "needs 3 integer tags (time step, components, entity count), found " + str(ni));
    }
    const std::int64_t comps = it[1];
    if (comps < 1 || comps > 1000)
      cur_.fail_at(iat, "bad number of field components " + std::to_string(comps));
    const std::uint64_t nc = static_cast<std::uint64_t>(comps);
    const std::uint64_t rec = binary_ ? 4 + 8 * nc : 2 * (1 + nc);
    if (binary_) cur_.rest_of_line();
    check_count(it[2], "field values", rec, binary_ ? cur_.pos() : cat);
    const std::uint64_t m = static_cast<std::uint64_t>(it[2]);

    const FieldLocation loc = node ? FieldLocation::node : FieldLocation::cell;
    PendingField* f = nullptr;
    for (PendingField& p : fields_) {
      if (p.name == fname && p.location == loc) f = &p;
    }
    if (f == nullptr) {
      fields_.push_back({fname, loc, static_cast<std::uint32_t>(nc), {}});
      f = &fields_.back();
    } else if (f->components != nc) {
      cur_.fail_at(iat, "field '" + fname + "' has " + str(nc) + " components here but " +
                            str(f->components) + " in an earlier step");
    }
    PendingStep* s = nullptr;
    for (PendingStep& p : f->steps) {
      if (p.index == it[0]) s = &p;
    }
    const std::size_t entities = node ? mesh_.node_count() : mesh_.tet_count();
    if (s == nullptr) {
      // Each new step allocates a value for every entity: bound the total by the file's size so that a
      // small file cannot ask for gigabytes through many tiny blocks.
      pending_values_ += entities * nc;
      if (pending_values_ > 16 * data_.size() + (std::uint64_t{1} << 20)) {
        cur_.fail_at(at, "field data would need " + str(pending_values_) +
                             " values, far more than this file can hold");
      }
      f->steps.push_back(
          {it[0], time, std::vector<double>(entities * nc, std::numeric_limits<double>::quiet_NaN())});
      s = &f->steps.back();
    }
    if (!node && !tet_map_built_) {
      std::uint64_t dup = 0;
      std::vector<std::uint64_t> tags(mesh_.tet_count());
      for (const TagRun& r : tet_tag_runs_) {
        for (std::uint64_t i = 0; i < r.count; ++i) tags[r.first + i] = r.tag0 + i;
      }
      if (!tet_map_.build(tags, &dup)) fail_at(at, "element tag " + str(dup) + " appears twice");
      tet_map_built_ = true;
    }
    double* out = s->values.data();
    if (binary_) {
      const char* p = need(m * rec, "field values");
      for (std::uint64_t i = 0; i < m; ++i, p += rec) {
        std::int32_t tag = io::load<std::int32_t>(p);
        std::uint32_t idx =
            tag < 0 ? kNone : (node ? nodes_ : tet_map_).find(static_cast<std::uint64_t>(tag));
        if (idx == kNone) {
          if (node)
            fail_at(static_cast<std::size_t>(p - data_.data()),
                    "field value for undefined node " + std::to_string(tag));
          continue;
        }
        std::memcpy(out + nc * idx, p + 4, 8 * nc);
      }
      advance(m * rec);
    } else {
      for (std::uint64_t i = 0; i < m; ++i) {
        std::size_t tat = here();
        std::uint64_t tag = num<std::uint64_t>(cur_, node ? "node tag" : "element tag");
        std::uint32_t idx = (node ? nodes_ : tet_map_).find(tag);
        if (idx == kNone && node) cur_.fail_at(tat, "field value for undefined node " + str(tag));
        for (std::uint64_t k = 0; k < nc; ++k) {
          double v = num<double>(cur_, "field value");
          if (idx != kNone) out[nc * idx + k] = v;
        }
      }
    }
    cur_.expect(end);
  }

  // ---- assembly ----
  Mesh finish() {
    for (std::int32_t id : io::distinct_ids(mesh_.tet_region)) {
      auto it = volume_names_.find(id);
      mesh_.regions.push_back({id, it == volume_names_.end() ? std::string() : it->second, kNone});
    }
    for (std::int32_t id : io::distinct_ids(mesh_.bface_tag)) {
      auto it = surface_names_.find(id);
      mesh_.boundaries.push_back({id, it == surface_names_.end() ? std::string() : it->second});
    }
    for (PendingField& p : fields_) {
      Field f;
      f.name = std::move(p.name);
      f.location = p.location;
      f.components = p.components;
      const std::size_t per =
          (p.location == FieldLocation::node ? mesh_.node_count() : mesh_.tet_count()) * p.components;
      f.values.reserve(per * p.steps.size());
      for (PendingStep& s : p.steps) {
        f.step_values.push_back(s.time);
        // A step read before more tets were added cannot happen ($ElementData needs $Elements first).
        f.values.insert(f.values.end(), s.values.begin(), s.values.end());
      }
      mesh_.fields.push_back(std::move(f));
    }
    return std::move(mesh_);
  }

  std::string_view data_;
  const std::string& name_;
  TextCursor cur_;
  int version_ = 0;
  bool binary_ = false;
  bool have_nodes_ = false, have_elements_ = false;
  Mesh mesh_;
  std::vector<std::uint64_t> node_tags_;
  TagMap nodes_;
  // Element tags of the tets, as runs of consecutive tags (one run per block in usual files).
  struct TagRun {
    std::uint64_t tag0, first, count;
  };
  std::vector<TagRun> tet_tag_runs_;
  TagMap tet_map_;
  bool tet_map_built_ = false;
  std::unordered_map<std::int64_t, std::int32_t> entity_phys_[4];
  // A surface entity's physical tags after its first: its triangles are repeated with each, as
  // gmsh's 2.2 files repeat them (a tet keeps its entity's first: it has one region).
  std::unordered_map<std::int64_t, std::vector<std::int32_t>> entity_more_phys_;
  std::unordered_map<std::int32_t, std::string> volume_names_, surface_names_;
  std::vector<PendingField> fields_;
  std::uint64_t pending_values_ = 0;
};

}  // namespace

Mesh parse_gmsh(std::string_view bytes, const std::string& name) { return Reader(bytes, name).run(); }

Mesh read_gmsh(const std::filesystem::path& path) {
  std::string data = io::read_file(path);
  io::strip_byte_order_mark(data);
  return parse_gmsh(data, path.string());
}

}  // namespace foxi
