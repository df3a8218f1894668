// The VTK XML unstructured grid (.vtu) reader: ASCII, base64 (zlib or raw) and appended data. Decisions:
// io_vtk_internal.hpp.
#include "foxi/model/io_vtk.hpp"

#include <sys/mman.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <pugixml.hpp>

#include "foxi/model/io_error.hpp"
#include "foxi/model/parallel.hpp"
#include "io_util.hpp"
#include "io_vtk_codec.hpp"
#include "io_vtk_internal.hpp"

namespace foxi {
namespace {

using namespace vtk;

// ASCII number lists.

// Parses whitespace-separated numbers from text[begin, end) (text is the whole file, for line
// numbers). `expected` values, or all of them if kUnknown. Floats as f64, integers as i64.
ArrayData parse_ascii_values(std::string_view text, std::size_t begin, std::size_t end,
                             std::uint64_t expected, bool floats, const std::string& file,
                             const std::string& what) {
  const char* s = text.data();
  std::size_t pos = begin;
  auto is_space = [](char c) {
    return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v';
  };
  if (expected != kUnknown && !io::count_fits(expected, 2, end - begin + 1)) {
    io::fail_text(file, text, begin,
                  what + ": declares " + std::to_string(expected) +
                      " values but the text has room for at most " + std::to_string((end - begin + 1) / 2));
  }
  auto parse_all = [&](auto zero) {
    using T = decltype(zero);
    std::vector<T> v;
    if (expected != kUnknown) v.reserve(expected);
    while (true) {
      while (pos < end && is_space(s[pos])) ++pos;
      if (pos >= end) break;
      if (expected != kUnknown && v.size() == expected)
        io::fail_text(file, text, pos,
                      what + ": more values than the " + std::to_string(expected) + " declared");
      T x{};
      const char* b = s + pos;
      const char* b2 = b + (*b == '+' ? 1 : 0);
      auto r = std::from_chars(b2, s + end, x);
      if (r.ec != std::errc() || (r.ptr < s + end && !is_space(*r.ptr))) {
        std::size_t e = pos;
        while (e < end && !is_space(s[e])) ++e;
        io::fail_text(file, text, pos,
                      what + ": expected " + (std::is_floating_point_v<T> ? "a number" : "an integer") +
                          ", found '" + io::TextCursor::shorten(text.substr(pos, e - pos)) + "'");
      }
      v.push_back(x);
      pos = static_cast<std::size_t>(r.ptr - s);
    }
    if (expected != kUnknown && v.size() != expected)
      io::fail_text(
          file, text, pos,
          what + ": expected " + std::to_string(expected) + " values, found " + std::to_string(v.size()));
    if constexpr (std::is_floating_point_v<T>)
      return make_owned_f64(v);
    else
      return make_owned_i64(v);
  };
  if (floats) return parse_all(double{});
  return parse_all(std::int64_t{});
}

// ------------------------------------------------------------------------------------------------
// .vtu reader

struct VtuContext {
  std::string_view text;  // the whole file
  const std::string& file;
  bool swap = false;
  std::size_t header_size = 4;
  bool compressed = false;
  bool has_appended = false;
  bool appended_raw = false;
  std::size_t appended_begin = 0;  // first byte after '_'
  std::size_t appended_end = 0;    // raw: end of file; base64: the '<' that ends the text
  std::size_t appended_max = 0;    // raw: the largest end of an array read
};

std::uint64_t read_header_value(const char* p, const VtuContext& c) {
  return c.header_size == 8 ? io::load<std::uint64_t>(p, c.swap) : io::load<std::uint32_t>(p, c.swap);
}

// A source of binary bytes: raw (a view into the file) or base64 text.
struct ByteSource {
  const VtuContext& c;
  bool raw;
  std::size_t pos;  // raw: file offset
  std::size_t end;
  std::optional<vtk::Base64Reader> b64;
  const std::string& what;

  ByteSource(const VtuContext& ctx, bool is_raw, std::size_t begin, std::size_t e, const std::string& w)
      : c(ctx), raw(is_raw), pos(begin), end(e), what(w) {
    if (!raw) b64.emplace(c.text, begin, e, c.file);
  }
  std::uint64_t bytes_left_bound() const { return raw ? end - pos : b64->bytes_left_bound(); }
  std::size_t where() const { return raw ? pos : b64->pos(); }
  [[noreturn]] void fail(const std::string& reason) const {
    if (raw) io::fail_binary(c.file, pos, what + ": " + reason);
    io::fail_text(c.file, c.text, b64->pos(), what + ": " + reason);
  }
  void need(std::uint64_t n) const {
    if (n > bytes_left_bound())
      fail("needs " + std::to_string(n) + " bytes but only " + std::to_string(bytes_left_bound()) +
           " are left");
  }
  // Reads n bytes: a view (raw) or a copy into `store`.
  std::string_view take(std::uint64_t n, std::string& store) {
    need(n);
    if (raw) {
      std::string_view v = c.text.substr(pos, n);
      pos += n;
      return v;
    }
    store.resize(n);
    b64->read(store.data(), n, what.c_str());
    return store;
  }
  std::uint64_t header() {
    char buf[8];
    need(c.header_size);
    if (raw) {
      std::memcpy(buf, c.text.data() + pos, c.header_size);
      pos += c.header_size;
    } else {
      b64->read(buf, c.header_size, what.c_str());
    }
    return read_header_value(buf, c);
  }
};

// Reads one binary data block (header + data, compressed or not) of values of `type`.
ArrayData read_binary_block(ByteSource& src, VType type, std::uint64_t expected) {
  const std::size_t vs = vtk::type_size(type);
  ArrayData a;
  a.type = type;
  a.swap = src.c.swap;
  std::uint64_t nbytes = 0;
  if (!src.c.compressed) {
    nbytes = src.header();
    if (expected != kUnknown && expected > std::numeric_limits<std::uint64_t>::max() / vs)
      src.fail("declared value count " + std::to_string(expected) + " is too large");
    if (expected != kUnknown && nbytes != expected * vs)
      src.fail("data block holds " + std::to_string(nbytes) + " bytes, expected " + std::to_string(expected) +
               " values of " + std::to_string(vs) + " bytes");
    if (nbytes % vs != 0)
      src.fail("data block size " + std::to_string(nbytes) + " is not a multiple of " + std::to_string(vs));
    std::string store;
    std::string_view v = src.take(nbytes, store);
    if (src.raw)
      a.lent = v;
    else
      a.own(std::move(store));
  } else {
    const std::uint64_t nblocks = src.header();
    const std::uint64_t block_size = src.header();
    std::uint64_t last_size = src.header();
    if (!io::count_fits(nblocks, src.c.header_size, src.bytes_left_bound()))
      src.fail("zlib header declares " + std::to_string(nblocks) + " blocks but only " +
               std::to_string(src.bytes_left_bound()) + " bytes are left");
    if (nblocks > 0 && last_size == 0) last_size = block_size;  // VTK: 0 means a full last block
    if (nblocks > 0 && (last_size > block_size || block_size == 0))
      src.fail("zlib header: last block size " + std::to_string(last_size) +
               " is larger than the block size " + std::to_string(block_size));
    std::vector<std::uint64_t> csize(nblocks);
    std::uint64_t ctotal = 0;
    for (auto& s : csize) {
      s = src.header();
      if (s > src.bytes_left_bound())
        src.fail("zlib header: compressed block size " + std::to_string(s) + " is past the end of the data");
      ctotal += s;
    }
    if (nblocks > 0 && block_size > (std::uint64_t{1} << 40))
      src.fail("zlib header: block size " + std::to_string(block_size) + " is not plausible");
    nbytes = nblocks == 0 ? 0 : (nblocks - 1) * block_size + last_size;
    if (expected != kUnknown &&
        (expected > std::numeric_limits<std::uint64_t>::max() / vs || nbytes != expected * vs))
      src.fail("compressed data holds " + std::to_string(nbytes) + " bytes, expected " +
               std::to_string(expected) + " values of " + std::to_string(vs) + " bytes");
    if (nbytes % vs != 0)
      src.fail("data size " + std::to_string(nbytes) + " is not a multiple of " + std::to_string(vs));
    if (nbytes > ctotal * kZlibMaxRatio + 64 * nblocks)
      src.fail("zlib header declares " + std::to_string(nbytes) + " bytes from only " +
               std::to_string(ctotal) + " compressed bytes");
    std::string store;
    std::size_t data_at = src.where();
    std::string_view comp = src.take(ctotal, store);
    std::string out(nbytes, '\0');
    // Block starts; blocks inflate independently, on two threads when there are many.
    std::vector<std::uint64_t> cstart(nblocks + 1, 0);
    for (std::uint64_t b = 0; b < nblocks; ++b) cstart[b + 1] = cstart[b] + csize[b];
    std::vector<int> status(nblocks, Z_OK);
    std::vector<std::uint64_t> got_size(nblocks, 0);
    auto inflate_range = [&](std::uint64_t b0, std::uint64_t b1) {
      for (std::uint64_t b = b0; b < b1; ++b) {
        const std::uint64_t want = b + 1 == nblocks ? last_size : block_size;
        uLongf got = static_cast<uLongf>(want);
        status[b] =
            uncompress(reinterpret_cast<Bytef*>(out.data() + b * block_size), &got,
                       reinterpret_cast<const Bytef*>(comp.data() + cstart[b]), static_cast<uLong>(csize[b]));
        got_size[b] = got;
      }
    };
    detail::parallel_for(
        std::size_t(nblocks), 2, [&](std::size_t b0, std::size_t b1, unsigned) { inflate_range(b0, b1); },
        16);
    for (std::uint64_t b = 0; b < nblocks; ++b) {
      const std::uint64_t want = b + 1 == nblocks ? last_size : block_size;
      const int rc = status[b];
      const std::uint64_t got = got_size[b];
      if (rc != Z_OK || got != want) {
        std::string why =
            rc == Z_BUF_ERROR
                ? "holds more than (or is cut before) the declared " + std::to_string(want) + " bytes"
            : rc == Z_DATA_ERROR ? "is not valid zlib data"
            : rc != Z_OK         ? "cannot be decompressed"
                         : "holds " + std::to_string(got) + " bytes, expected " + std::to_string(want);
        if (src.raw)
          io::fail_binary(src.c.file, data_at + cstart[b],
                          src.what + ": zlib block " + std::to_string(b + 1) + " of " +
                              std::to_string(nblocks) + " " + why);
        io::fail_text(src.c.file, src.c.text, data_at,
                      src.what + ": zlib block " + std::to_string(b + 1) + " of " + std::to_string(nblocks) +
                          " " + why);
      }
    }
    a.own(std::move(out));
  }
  a.count = nbytes / vs;
  return a;
}

std::uint64_t attr_u64(const VtuContext& c, pugi::xml_node n, const char* name, std::uint64_t dflt) {
  pugi::xml_attribute a = n.attribute(name);
  if (!a) {
    if (dflt != kUnknown) return dflt;
    io::fail_text(c.file, c.text, static_cast<std::size_t>(n.offset_debug()),
                  std::string("<") + n.name() + "> lacks the attribute " + name);
  }
  std::string_view v = a.value();
  while (!v.empty() && v.front() == ' ') v.remove_prefix(1);
  while (!v.empty() && v.back() == ' ') v.remove_suffix(1);
  std::uint64_t x = 0;
  auto r = std::from_chars(v.data(), v.data() + v.size(), x);
  if (r.ec != std::errc() || r.ptr != v.data() + v.size() || v.empty())
    io::fail_text(c.file, c.text, static_cast<std::size_t>(n.offset_debug()),
                  std::string("<") + n.name() + "> attribute " + name + "=\"" +
                      io::TextCursor::shorten(a.value()) + "\" is not a non-negative integer");
  return x;
}

// The text range of an element's content in the original file.
std::pair<std::size_t, std::size_t> content_range(const VtuContext& c, pugi::xml_node n) {
  for (pugi::xml_node ch = n.first_child(); ch; ch = ch.next_sibling()) {
    if (ch.type() == pugi::node_pcdata || ch.type() == pugi::node_cdata) {
      auto b = static_cast<std::size_t>(ch.offset_debug());
      if (b > c.text.size()) b = c.text.size();
      std::size_t e = c.text.find('<', b);
      if (e == std::string_view::npos) e = c.text.size();
      return {b, e};
    }
  }
  return {0, 0};
}

NamedArray read_data_array(VtuContext& c, pugi::xml_node da, std::uint64_t tuples,
                           std::uint32_t want_components, const std::string& where) {
  NamedArray out;
  out.at = static_cast<std::size_t>(da.offset_debug());
  out.name = da.attribute("Name").value();
  const std::string what = where + (out.name.empty() ? "" : " '" + out.name + "'");
  const auto at = static_cast<std::size_t>(da.offset_debug());
  auto fail = [&](const std::string& reason) { io::fail_text(c.file, c.text, at, what + ": " + reason); };
  VType type;
  if (!vtk::parse_xml_type(da.attribute("type").value(), type))
    fail(std::string("unsupported data type '") + da.attribute("type").value() + "'");
  std::uint64_t nc = attr_u64(c, da, "NumberOfComponents", 1);
  if (nc == 0 || nc > 1024) fail("NumberOfComponents " + std::to_string(nc) + " is not supported");
  if (want_components != 0 && nc != want_components)
    fail("has " + std::to_string(nc) + " components, expected " + std::to_string(want_components));
  out.components = static_cast<std::uint32_t>(nc);
  std::uint64_t expected = kUnknown;
  if (tuples != kUnknown) {
    if (tuples > std::numeric_limits<std::uint64_t>::max() / nc) fail("too many values");
    expected = tuples * nc;
  }
  std::string format = da.attribute("format").value();
  if (format.empty()) format = "ascii";
  if (format == "ascii") {
    auto [b, e] = content_range(c, da);
    out.data = parse_ascii_values(c.text, b, e, expected, vtk::is_float(type), c.file, what);
  } else if (format == "binary") {
    auto [b, e] = content_range(c, da);
    ByteSource src(c, false, b, e, what);
    out.data = read_binary_block(src, type, expected);
  } else if (format == "appended") {
    if (!c.has_appended) fail("format=\"appended\" but the file has no <AppendedData>");
    std::uint64_t off = attr_u64(c, da, "offset", kUnknown);
    if (off >= c.appended_end - c.appended_begin)
      fail("appended offset " + std::to_string(off) + " is past the end of the appended data (" +
           std::to_string(c.appended_end - c.appended_begin) + " bytes)");
    ByteSource src(c, c.appended_raw, c.appended_begin + off, c.appended_end, what);
    out.data = read_binary_block(src, type, expected);
    if (c.appended_raw) c.appended_max = std::max(c.appended_max, src.pos);
  } else {
    fail("unknown format '" + io::TextCursor::shorten(format) + "'");
  }
  out.unit = da.attribute("foxi_unit").value();
  if (pugi::xml_attribute sv = da.attribute("foxi_step_value")) {
    double v = 0;
    std::string_view s = sv.value();
    auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec == std::errc() && r.ptr == s.data() + s.size()) out.step_value = v;
  }
  out.region_names = da.attribute("foxi_region_names").value();
  out.region_materials = da.attribute("foxi_region_materials").value();
  out.boundary_names = da.attribute("foxi_boundary_names").value();
  return out;
}

// Size of an appended raw block at `off` (header included), for arrays not read (FieldData).
std::size_t appended_block_end(const VtuContext& c, std::uint64_t off) {
  std::size_t p = c.appended_begin + off;
  auto hdr = [&](std::size_t at) -> std::uint64_t {
    if (at + c.header_size > c.text.size())
      io::fail_binary(c.file, at, "appended data block header past the end of the file");
    return read_header_value(c.text.data() + at, c);
  };
  if (!c.compressed) {
    std::uint64_t n = hdr(p);
    if (n > c.text.size()) io::fail_binary(c.file, p, "appended data block past the end of the file");
    return p + c.header_size + n;
  }
  std::uint64_t nb = hdr(p);
  if (!io::count_fits(nb, c.header_size, c.text.size() - p))
    io::fail_binary(c.file, p, "appended zlib header past the end of the file");
  std::size_t q = p + (3 + nb) * c.header_size;
  std::uint64_t total = 0;
  for (std::uint64_t b = 0; b < nb; ++b) {
    std::uint64_t s = hdr(p + (3 + b) * c.header_size);
    if (s > c.text.size()) io::fail_binary(c.file, p, "appended zlib block past the end of the file");
    total += s;
  }
  return q + total;
}

Mesh parse_vtu_impl(std::string_view text, const std::string& file) {
  VtuContext c{text, file};
  if (text.empty()) io::fail_text(file, text, 0, "empty file");
  // Find appended data; pugixml must not see raw binary.
  std::size_t xml_end = text.size();
  std::string tail;
  std::size_t ad = text.find("<AppendedData");
  if (ad != std::string_view::npos) {
    std::size_t gt = text.find('>', ad);
    if (gt == std::string_view::npos) io::fail_text(file, text, ad, "unterminated <AppendedData> tag");
    std::string_view tag = text.substr(ad, gt - ad);
    bool raw = tag.find("\"raw\"") != std::string_view::npos || tag.find("'raw'") != std::string_view::npos;
    bool b64 =
        tag.find("\"base64\"") != std::string_view::npos || tag.find("'base64'") != std::string_view::npos;
    if (!raw && !b64) io::fail_text(file, text, ad, "<AppendedData> needs encoding=\"raw\" or \"base64\"");
    std::size_t us = gt + 1;
    while (us < text.size() && (text[us] == ' ' || text[us] == '\n' || text[us] == '\r' || text[us] == '\t'))
      ++us;
    if (us >= text.size() || text[us] != '_')
      io::fail_text(file, text, std::min(us, text.size()), "<AppendedData> must start with '_'");
    c.has_appended = true;
    c.appended_raw = raw;
    c.appended_begin = us + 1;
    if (raw) {
      c.appended_end = text.size();
    } else {
      std::size_t lt = text.find('<', c.appended_begin);
      if (lt == std::string_view::npos)
        io::fail_text(file, text, text.size(), "unexpected end of file in <AppendedData>");
      c.appended_end = lt;
    }
    xml_end = gt + 1;
    tail = "</AppendedData></VTKFile>";
  }
  std::string buf;
  buf.reserve(xml_end + tail.size());
  buf.append(text.substr(0, xml_end));
  buf.append(tail);
  pugi::xml_document doc;
  pugi::xml_parse_result pr = doc.load_buffer_inplace(
      buf.data(), buf.size(), pugi::parse_minimal | pugi::parse_escapes, pugi::encoding_utf8);
  if (!pr) {
    auto off = static_cast<std::size_t>(pr.offset);
    io::fail_text(file, text, std::min(off, xml_end), std::string("XML error: ") + pr.description());
  }
  pugi::xml_node root = doc.child("VTKFile");
  if (!root) io::fail_text(file, text, 0, "not a VTK XML file (no <VTKFile> element)");
  const auto root_at = static_cast<std::size_t>(root.offset_debug());
  if (std::string_view(root.attribute("type").value()) != "UnstructuredGrid")
    io::fail_text(file, text, root_at,
                  std::string("VTKFile type '") + root.attribute("type").value() +
                      "' is not supported (only UnstructuredGrid)");
  std::string_view order = root.attribute("byte_order").value();
  if (order == "BigEndian")
    c.swap = kHostLittle;
  else if (order.empty() || order == "LittleEndian")
    c.swap = !kHostLittle;
  else
    io::fail_text(file, text, root_at, "unknown byte_order '" + std::string(order) + "'");
  std::string_view ht = root.attribute("header_type").value();
  if (ht.empty() || ht == "UInt32")
    c.header_size = 4;
  else if (ht == "UInt64")
    c.header_size = 8;
  else
    io::fail_text(file, text, root_at, "unsupported header_type '" + std::string(ht) + "'");
  std::string_view comp = root.attribute("compressor").value();
  if (comp.empty())
    c.compressed = false;
  else if (comp == "vtkZLibDataCompressor")
    c.compressed = true;
  else
    io::fail_text(file, text, root_at,
                  "unsupported compressor '" + std::string(comp) + "' (foxi reads vtkZLibDataCompressor)");

  pugi::xml_node grid = root.child("UnstructuredGrid");
  if (!grid) io::fail_text(file, text, root_at, "no <UnstructuredGrid> element");
  // Upper bound on any count: each value takes at least one byte (or 1/1032 compressed).
  const std::uint64_t bound = c.compressed ? text.size() * kZlibMaxRatio + 1024 : text.size();
  Assembler asm_(file, text);
  std::size_t piece_index = 0;
  for (pugi::xml_node pn = grid.child("Piece"); pn; pn = pn.next_sibling("Piece"), ++piece_index) {
    const auto pat = static_cast<std::size_t>(pn.offset_debug());
    Piece p;
    p.at = p.cells_at = pat;
    p.npoints = attr_u64(c, pn, "NumberOfPoints", kUnknown);
    p.ncells = attr_u64(c, pn, "NumberOfCells", kUnknown);
    if (p.npoints > bound / 3)
      io::fail_text(file, text, pat,
                    "declares " + std::to_string(p.npoints) + " points but the file has only " +
                        std::to_string(text.size()) + " bytes");
    if (p.ncells > bound)
      io::fail_text(file, text, pat,
                    "declares " + std::to_string(p.ncells) + " cells but the file has only " +
                        std::to_string(text.size()) + " bytes");
    std::string where = "piece " + std::to_string(piece_index + 1);
    pugi::xml_node pts = pn.child("Points").child("DataArray");
    if (!pts) {
      if (p.npoints > 0) io::fail_text(file, text, pat, where + ": no <Points> data");
      p.points.type = VType::f64;
    } else {
      p.points = read_data_array(c, pts, p.npoints, 3, where + " Points").data;
    }
    pugi::xml_node cells = pn.child("Cells");
    if (!cells && p.ncells > 0) io::fail_text(file, text, pat, where + ": no <Cells> element");
    bool got_conn = false, got_off = false, got_types = false;
    for (pugi::xml_node da = cells.child("DataArray"); da; da = da.next_sibling("DataArray")) {
      std::string_view n = da.attribute("Name").value();
      if (n == "connectivity") {
        p.cells_at = static_cast<std::size_t>(da.offset_debug());
        p.conn = read_data_array(c, da, kUnknown, 1, where + " Cells").data;
        got_conn = true;
      } else if (n == "offsets") {
        p.offsets = read_data_array(c, da, p.ncells, 1, where + " Cells").data;
        got_off = true;
      } else if (n == "types") {
        p.types = read_data_array(c, da, p.ncells, 1, where + " Cells").data;
        got_types = true;
      } else if (n == "faces" || n == "faceoffsets") {
        continue;  // polyhedra: their cell type is rejected below
      }
    }
    if (p.ncells > 0 && !(got_conn && got_off && got_types))
      io::fail_text(file, text, pat, where + ": <Cells> needs the arrays connectivity, offsets and types");
    if (!got_conn) p.conn.type = VType::i64;
    if (!got_off) p.offsets.type = VType::i64;
    if (!got_types) p.types.type = VType::u8;
    for (pugi::xml_node da = pn.child("PointData").child("DataArray"); da; da = da.next_sibling("DataArray"))
      p.point_arrays.push_back(read_data_array(c, da, p.npoints, 0, where + " PointData"));
    for (pugi::xml_node da = pn.child("CellData").child("DataArray"); da; da = da.next_sibling("DataArray"))
      p.cell_arrays.push_back(read_data_array(c, da, p.ncells, 0, where + " CellData"));
    asm_.add(p, piece_index);
  }
  if (piece_index == 0) io::fail_text(file, text, root_at, "<UnstructuredGrid> has no <Piece>");
  if (c.has_appended && c.appended_raw) {
    // Arrays not read (field data, faces) also live in the appended block: include them.
    for (pugi::xpath_node xn :
         doc.select_nodes("//DataArray[@format='appended'] | //Array[@format='appended']")) {
      pugi::xml_node da = xn.node();
      std::uint64_t off = attr_u64(c, da, "offset", kUnknown);
      if (off >= c.appended_end - c.appended_begin)
        io::fail_binary(file, c.appended_begin,
                        "appended offset " + std::to_string(off) + " is past the end of the file");
      c.appended_max = std::max(c.appended_max, appended_block_end(c, off));
    }
    // After the data: </AppendedData> and </VTKFile>.
    io::TextCursor tc(text, file);
    tc.set_pos(std::max(c.appended_max, c.appended_begin));
    if (tc.at_end())
      io::fail_binary(file, text.size(),
                      "unexpected end of file: </AppendedData> missing after the appended data");
    std::size_t here = tc.pos();
    if (text.substr(here, 15) != "</AppendedData>")
      io::fail_binary(file, here, "expected </AppendedData> after the appended data");
    tc.set_pos(here + 15);
    if (tc.at_end() || text.substr(tc.pos(), 10) != "</VTKFile>")
      io::fail_binary(file, tc.pos(), "expected </VTKFile> after </AppendedData>");
  } else if (c.has_appended) {
    std::size_t here = c.appended_end;
    if (text.substr(here, 15) != "</AppendedData>")
      io::fail_text(file, text, here, "expected </AppendedData> after the appended data");
    io::TextCursor tc(text, file);
    tc.set_pos(here + 15);
    if (tc.at_end() || text.substr(tc.pos(), 10) != "</VTKFile>")
      io::fail_text(file, text, tc.pos(), "expected </VTKFile> after </AppendedData>");
  }
  return asm_.finish();
}

}  // namespace

Mesh parse_vtu(std::string_view bytes, const std::string& name) { return parse_vtu_impl(bytes, name); }

Mesh read_vtu(const std::filesystem::path& path) {
  std::string bytes = io::read_file(path);
  return parse_vtu_impl(bytes, path.string());
}

}  // namespace foxi
