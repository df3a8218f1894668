// The legacy VTK (.vtk) reader and writer, ASCII and big-endian binary. Decisions: io_vtk_internal.hpp.
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
#include <thread>

#include "foxi/model/io_error.hpp"
#include "io_util.hpp"
#include "io_vtk_codec.hpp"
#include "io_vtk_internal.hpp"

namespace foxi {

// ------------------------------------------------------------------------------------------------
// Legacy .vtk reader
namespace {

using namespace vtk;

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& ch : r) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return r;
}

class LegacyReader {
 public:
  LegacyReader(std::string_view text, const std::string& file) : tc_(text, file), text_(text), file_(file) {}

  Mesh read() {
    if (text_.empty()) tc_.fail("empty file");
    std::string_view l1 = tc_.rest_of_line();
    if (l1.substr(0, 5) != "# vtk" && l1.substr(0, 5) != "# VTK")
      tc_.fail_at(0, "not a legacy VTK file (the first line must be '# vtk DataFile Version ...')");
    tc_.rest_of_line();  // title
    if (tc_.remaining() == 0) tc_.fail("unexpected end of file, expected ASCII or BINARY");
    std::string fmt = lower(tc_.token("ASCII or BINARY"));
    if (fmt == "binary")
      binary_ = true;
    else if (fmt != "ascii")
      tc_.fail_at(tc_.pos() - fmt.size(),
                  "expected ASCII or BINARY, found '" + io::TextCursor::shorten(fmt) + "'");
    std::string kw = lower(tc_.token("DATASET"));
    if (kw != "dataset")
      tc_.fail_at(tc_.pos() - kw.size(), "expected DATASET, found '" + io::TextCursor::shorten(kw) + "'");
    std::string ds = lower(tc_.token("dataset type"));
    if (ds != "unstructured_grid")
      tc_.fail_at(tc_.pos() - ds.size(), "dataset type '" + io::TextCursor::shorten(ds) +
                                             "' is not supported (only UNSTRUCTURED_GRID)");
    Piece p;
    bool have_points = false, have_cells = false, have_types = false;
    std::vector<NamedArray>* attrs = nullptr;
    std::uint64_t attr_count = 0;
    while (!tc_.at_end()) {
      std::size_t kw_at = tc_.pos();
      std::string k = lower(tc_.token("keyword"));
      if (k == "points") {
        p.at = kw_at;
        p.npoints = count("point count");
        if (p.npoints > text_.size() / 3)
          tc_.fail_at(kw_at, "declares " + std::to_string(p.npoints) + " points but the file has only " +
                                 std::to_string(text_.size()) + " bytes");
        VType t = type_token();
        p.points = values(3 * p.npoints, t, "POINTS");
        have_points = true;
      } else if (k == "cells") {
        p.cells_at = kw_at;
        std::uint64_t n = count("cell count");
        std::uint64_t size = count("cell list size");
        std::size_t save = tc_.pos();
        std::string next = tc_.at_end() ? std::string() : lower(tc_.token("cells"));
        if (next == "offsets") {
          // VTK 5.1: CELLS <noffsets> <nconn>, OFFSETS type, offsets, CONNECTIVITY type, connectivity.
          if (n == 0) tc_.fail_at(kw_at, "CELLS with OFFSETS needs at least one offset");
          VType ot = type_token();
          ArrayData off = values(n, ot, "OFFSETS");
          expect_kw("connectivity");
          VType ct = type_token();
          p.conn = values(size, ct, "CONNECTIVITY");
          p.ncells = n - 1;
          // Offsets start at 0: drop the first to keep "end of each cell".
          ArrayData o = normalize_ints(std::move(off),
                                       [&](const std::string& r) { tc_.fail_at(kw_at, "OFFSETS: " + r); });
          std::vector<std::int64_t> ends(n - 1);
          dispatch_int(o, [&](auto acc) {
            if (acc[0] != 0) tc_.fail_at(kw_at, "OFFSETS must start at 0");
            for (std::size_t i = 1; i < n; ++i) ends[i - 1] = static_cast<std::int64_t>(acc[i]);
          });
          p.offsets = make_owned_i64(ends);
        } else {
          tc_.set_pos(save);
          // Old layout: per cell "k i1 ... ik".
          if (!io::count_fits(size, binary_ ? 4 : 2, tc_.remaining() + 1))
            tc_.fail_at(kw_at, "CELLS declares " + std::to_string(size) + " values but the file has only " +
                                   std::to_string(tc_.remaining()) + " bytes left");
          if (n > size)
            tc_.fail_at(kw_at, "CELLS declares " + std::to_string(n) + " cells in " + std::to_string(size) +
                                   " values");
          ArrayData all = values(size, VType::i32, "CELLS");
          all = normalize_ints(std::move(all),
                               [&](const std::string& r) { tc_.fail_at(kw_at, "CELLS: " + r); });
          std::vector<std::int64_t> conn, ends(n);
          conn.reserve(size - n);
          dispatch_int(all, [&](auto acc) {
            std::uint64_t at = 0;
            for (std::uint64_t i = 0; i < n; ++i) {
              if (at >= size) tc_.fail_at(kw_at, "CELLS: the cell list ends at cell " + std::to_string(i));
              auto k2 = static_cast<std::int64_t>(acc[at++]);
              if (k2 < 0 || static_cast<std::uint64_t>(k2) > size - at)
                tc_.fail_at(kw_at, "CELLS: cell " + std::to_string(i) + " declares " + std::to_string(k2) +
                                       " nodes, past the end of the list");
              for (std::int64_t j = 0; j < k2; ++j) conn.push_back(static_cast<std::int64_t>(acc[at++]));
              ends[i] = static_cast<std::int64_t>(conn.size());
            }
            if (at != size)
              tc_.fail_at(kw_at, "CELLS: list size " + std::to_string(size) + " does not match the cells (" +
                                     std::to_string(at) + " values used)");
          });
          p.ncells = n;
          p.conn = make_owned_i64(conn);
          p.offsets = make_owned_i64(ends);
        }
        have_cells = true;
      } else if (k == "cell_types") {
        std::uint64_t n = count("cell count");
        if (have_cells && n != p.ncells)
          tc_.fail_at(
              kw_at, "CELL_TYPES has " + std::to_string(n) + " cells, CELLS has " + std::to_string(p.ncells));
        p.types = values(n, VType::i32, "CELL_TYPES");
        if (!have_cells) p.ncells = n;
        have_types = true;
      } else if (k == "point_data" || k == "cell_data") {
        attr_count = count("count");
        if (k == "point_data") {
          if (attr_count != p.npoints)
            tc_.fail_at(kw_at, "POINT_DATA " + std::to_string(attr_count) + " does not match the " +
                                   std::to_string(p.npoints) + " points");
          attrs = &p.point_arrays;
        } else {
          if (attr_count != p.ncells)
            tc_.fail_at(kw_at, "CELL_DATA " + std::to_string(attr_count) + " does not match the " +
                                   std::to_string(p.ncells) + " cells");
          attrs = &p.cell_arrays;
        }
      } else if (k == "scalars" || k == "vectors" || k == "normals" || k == "tensors" || k == "tensors6" ||
                 k == "texture_coordinates" || k == "color_scalars") {
        if (attrs == nullptr) tc_.fail_at(kw_at, k + " before POINT_DATA or CELL_DATA");
        NamedArray a;
        a.at = kw_at;
        a.name = percent_decode(tc_.token("array name"));
        std::uint32_t nc = 1;
        VType t = VType::f32;
        if (k == "color_scalars") {
          nc = static_cast<std::uint32_t>(small_count("component count"));
          t = binary_ ? VType::u8 : VType::f32;
        } else if (k == "texture_coordinates") {
          nc = static_cast<std::uint32_t>(small_count("dimension"));
          t = type_token();
        } else {
          t = type_token();
          if (k == "scalars") {
            if (!tc_.at_line_end()) nc = static_cast<std::uint32_t>(small_count("component count"));
            std::size_t save = tc_.pos();
            if (!tc_.at_end() && lower(tc_.token("LOOKUP_TABLE")) == "lookup_table")
              tc_.token("table name");
            else
              tc_.set_pos(save);
          } else {
            nc = k == "tensors" ? 9 : k == "tensors6" ? 6 : 3;
          }
        }
        a.components = nc;
        a.data = values(attr_count * nc, t, k.c_str());
        attrs->push_back(std::move(a));
      } else if (k == "lookup_table") {
        tc_.token("table name");
        std::uint64_t n = count("table size");
        values(4 * n, binary_ ? VType::u8 : VType::f32, "LOOKUP_TABLE");
      } else if (k == "field") {
        tc_.token("field name");
        std::uint64_t narr = count("array count");
        for (std::uint64_t i = 0; i < narr; ++i) {
          NamedArray a;
          tc_.skip_space();
          std::size_t name_at = tc_.pos();
          a.at = name_at;
          a.name = percent_decode(tc_.token("array name"));
          if (lower(a.name) == "metadata") {
            skip_metadata();
            --i;
            continue;
          }
          std::uint64_t nc = small_count("component count");
          std::uint64_t nt = count("tuple count");
          VType t = type_token();
          if (nc != 0 && nt > std::numeric_limits<std::uint64_t>::max() / nc)
            tc_.fail_at(name_at, "too many values");
          a.components = static_cast<std::uint32_t>(nc);
          a.data = values(nc * nt, t, ("FIELD array '" + a.name + "'").c_str());
          if (attrs != nullptr) {
            if (nt != attr_count)
              tc_.fail_at(name_at, "FIELD array '" + a.name + "' has " + std::to_string(nt) +
                                       " tuples, expected " + std::to_string(attr_count));
            attrs->push_back(std::move(a));
          }
        }
      } else if (k == "metadata") {
        skip_metadata();
      } else {
        tc_.fail_at(kw_at, "unknown keyword '" + io::TextCursor::shorten(k) + "'");
      }
    }
    if (!have_points) tc_.fail("no POINTS section");
    if (have_cells != have_types)
      tc_.fail(have_cells ? "CELLS without CELL_TYPES" : "CELL_TYPES without CELLS");
    if (!have_cells) {
      p.conn.type = VType::i64;
      p.offsets.type = VType::i64;
      p.types.type = VType::i32;
    }
    Assembler a(file_, text_);
    a.add(p, 0);
    return a.finish();
  }

 private:
  std::uint64_t count(const char* what) {
    std::int64_t v = tc_.integer(what);
    if (v < 0) tc_.fail_at(tc_.pos(), std::string(what) + " must not be negative");
    return static_cast<std::uint64_t>(v);
  }
  std::uint64_t small_count(const char* what) {
    std::uint64_t v = count(what);
    if (v == 0 || v > 1024)
      tc_.fail_at(tc_.pos(), std::string(what) + " " + std::to_string(v) + " is not supported");
    return v;
  }
  VType type_token() {
    std::string_view t = tc_.token("data type");
    VType v;
    if (!vtk::parse_legacy_type(t, v))
      tc_.fail_at(tc_.pos() - t.size(), "unsupported data type '" + io::TextCursor::shorten(t) + "'");
    return v;
  }
  void expect_kw(const char* kw) {
    std::string_view t = tc_.token(kw);
    if (lower(t) != kw)
      tc_.fail_at(tc_.pos() - t.size(),
                  "expected " + lower(kw) + ", found '" + io::TextCursor::shorten(t) + "'");
  }
  void skip_metadata() {
    // METADATA blocks (VTK 8+) end at an empty line.
    tc_.skip_line();
    while (tc_.remaining() > 0) {
      std::size_t b = tc_.pos();
      std::string_view line = tc_.rest_of_line();
      bool blank = line.find_first_not_of(" \t") == std::string_view::npos;
      if (blank && tc_.pos() != b) break;
    }
  }
  // `n` values of type t, at the cursor (ASCII) or after the end of the current line (BINARY).
  ArrayData values(std::uint64_t n, VType t, const char* what) {
    if (binary_) {
      tc_.skip_line();
      std::size_t at = tc_.pos();
      std::size_t vs = vtk::type_size(t);
      if (!io::count_fits(n, vs, text_.size() - at))
        io::fail_binary(file_, at,
                        std::string(what) + ": declares " + std::to_string(n) + " values of " +
                            std::to_string(vs) + " bytes but the file has only " +
                            std::to_string(text_.size() - at) + " bytes left");
      ArrayData a;
      a.type = t;
      a.count = n;
      a.swap = kHostLittle;
      a.lent = text_.substr(at, n * vs);
      tc_.set_pos(at + n * vs);
      return a;
    }
    tc_.skip_space();
    std::size_t b = tc_.pos();
    if (!io::count_fits(n, 2, text_.size() - b + 1))
      tc_.fail_at(b, std::string(what) + ": declares " + std::to_string(n) +
                         " values but the file has only " + std::to_string(text_.size() - b) + " bytes left");
    // Parse exactly n numbers.
    const char* s = text_.data();
    std::size_t pos = b;
    auto is_space = [](char ch) {
      return ch == ' ' || ch == '\n' || ch == '\r' || ch == '\t' || ch == '\f' || ch == '\v';
    };
    auto parse = [&](auto zero) {
      using T = decltype(zero);
      std::vector<T> v(n);
      for (std::uint64_t i = 0; i < n; ++i) {
        while (pos < text_.size() && is_space(s[pos])) ++pos;
        if (pos >= text_.size())
          tc_.fail_at(pos, std::string(what) + ": unexpected end of file after " + std::to_string(i) +
                               " of " + std::to_string(n) + " values");
        const char* p0 = s + pos + (s[pos] == '+' ? 1 : 0);
        auto r = std::from_chars(p0, s + text_.size(), v[i]);
        if (r.ec != std::errc() || (r.ptr < s + text_.size() && !is_space(*r.ptr))) {
          std::size_t e = pos;
          while (e < text_.size() && !is_space(s[e])) ++e;
          tc_.fail_at(pos, std::string(what) + ": expected " +
                               (std::is_floating_point_v<T> ? "a number" : "an integer") + ", found '" +
                               io::TextCursor::shorten(text_.substr(pos, e - pos)) + "'");
        }
        pos = static_cast<std::size_t>(r.ptr - s);
      }
      tc_.set_pos(pos);
      if constexpr (std::is_floating_point_v<T>)
        return make_owned_f64(v);
      else
        return make_owned_i64(v);
    };
    if (vtk::is_float(t)) return parse(double{});
    return parse(std::int64_t{});
  }

  io::TextCursor tc_;
  std::string_view text_;
  const std::string& file_;
  bool binary_ = false;
};

}  // namespace

Mesh parse_vtk_legacy(std::string_view bytes, const std::string& name) {
  return LegacyReader(bytes, name).read();
}

Mesh read_vtk_legacy(const std::filesystem::path& path) {
  std::string bytes = io::read_file(path);
  io::strip_byte_order_mark(bytes);
  return LegacyReader(bytes, path.string()).read();
}

// ------------------------------------------------------------------------------------------------
// Legacy .vtk writer (4.2 layout: CELLS n size with "k i j ..." rows; data as FIELD arrays)
namespace {

template <class T>
void put_be(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (kHostLittle) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

}  // namespace

void write_vtk_legacy(const Mesh& mesh, const std::filesystem::path& path, bool binary) {
  const std::string file = path.string();
  if (std::string err = check_sizes(mesh); !err.empty())
    throw IoError(file, 0, IoError::kNoOffset, "cannot write an inconsistent mesh: " + err);
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nf = mesh.bface_count();
  const std::size_t ncells = nt + nf;
  // A legacy array's name is a word: an empty one wrote a file no reader takes back (an outside probe).
  for (std::size_t i = 0; i < mesh.fields.size(); ++i)
    if (mesh.fields[i].name.empty())
      throw IoError(file, 0, IoError::kNoOffset,
                    "field " + std::to_string(i + 1) +
                        " has no name, which the legacy VTK format needs (write .vtu, or name it)");
  if (5 * nt + 4 * nf > 0x7fffffffu)
    throw IoError(file, 0, IoError::kNoOffset, "mesh too large for the legacy VTK format");
  std::string out;
  out.reserve(binary ? 24 * nn + 24 * ncells : 60 * nn + 40 * ncells);
  out += "# vtk DataFile Version 4.2\nfoxi mesh\n";
  out += binary ? "BINARY\n" : "ASCII\n";
  out += "DATASET UNSTRUCTURED_GRID\n";
  // ASCII writes a NaN or infinity as "nan"/"inf", which foxi reads back (an imported field's "no
  // value") but VTK's reader does not (it stops there and loses every array after it): foxi writes
  // none of its own (the boundary triangles' rows below), a field's own NaN is the user's to see.
  auto doubles = [&](const double* v, std::size_t n, std::size_t per_line) {
    if (binary) {
      for (std::size_t i = 0; i < n; ++i) put_be(out, v[i]);
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        io::append_double(out, v[i]);
        out.push_back((i + 1) % per_line == 0 || i + 1 == n ? '\n' : ' ');
      }
    }
    if (binary) out.push_back('\n');
  };
  auto ints = [&](std::int32_t v, bool last) {
    if (binary)
      put_be(out, v);
    else {
      io::append_int(out, v);
      out.push_back(last ? '\n' : ' ');
    }
  };
  out += "POINTS " + std::to_string(nn) + " double\n";
  doubles(mesh.xyz.data(), mesh.xyz.size(), 3);
  out += "CELLS " + std::to_string(ncells) + " " + std::to_string(5 * nt + 4 * nf) + "\n";
  for (std::size_t t = 0; t < nt; ++t) {
    ints(4, false);
    for (int k = 0; k < 4; ++k)
      ints(static_cast<std::int32_t>(mesh.tet[4 * t + static_cast<std::size_t>(k)]), k == 3);
  }
  for (std::size_t f = 0; f < nf; ++f) {
    ints(3, false);
    for (int k = 0; k < 3; ++k)
      ints(static_cast<std::int32_t>(mesh.bface[3 * f + static_cast<std::size_t>(k)]), k == 2);
  }
  if (binary) out.push_back('\n');
  out += "CELL_TYPES " + std::to_string(ncells) + "\n";
  for (std::size_t i = 0; i < ncells; ++i) ints(i < nt ? 10 : 5, true);
  if (binary) out.push_back('\n');

  // Cell data.
  std::size_t n_cell_arrays = 0, n_point_arrays = mesh.weight.empty() ? 0 : 1;
  const bool has_region = !mesh.tet_region.empty() || nf > 0 || !mesh.regions.empty();
  if (has_region) ++n_cell_arrays;
  for (const Field& f : mesh.fields)
    (f.location == FieldLocation::cell ? n_cell_arrays : n_point_arrays) += f.step_count();
  auto field_arrays = [&](FieldLocation loc, std::size_t ne, std::size_t ne_written) {
    for (const Field& f : mesh.fields) {
      if (f.location != loc) continue;
      for (std::size_t s = 0; s < f.step_count(); ++s) {
        std::string name = s == 0 ? f.name : f.name + "@" + std::to_string(s + 1);
        out += percent_encode(name, "") + " " + std::to_string(f.components) + " " +
               std::to_string(ne_written) + " double\n";
        std::span<const double> v = f.step(s, ne);
        std::vector<double> tmp;
        const double* d = v.data();
        if (ne_written != ne) {
          // The boundary triangles' rows of a cell field (it has none of its own): NaN, "no value";
          // 0 in ASCII, which holds no NaN.
          tmp.assign(v.begin(), v.end());
          tmp.resize(ne_written * f.components, binary ? std::numeric_limits<double>::quiet_NaN() : 0.0);
          d = tmp.data();
        }
        doubles(d, ne_written * f.components, f.components == 1 ? 6 : f.components);
      }
    }
  };
  if (n_cell_arrays > 0) {
    out +=
        "CELL_DATA " + std::to_string(ncells) + "\nFIELD FieldData " + std::to_string(n_cell_arrays) + "\n";
    if (has_region) {
      out += "region 1 " + std::to_string(ncells) + " int\n";
      for (std::size_t i = 0; i < ncells; ++i)
        ints(i < nt ? mesh.region_of(i) : mesh.bface_tag[i - nt], (i + 1) % 10 == 0 || i + 1 == ncells);
      if (binary) out.push_back('\n');
    }
    field_arrays(FieldLocation::cell, nt, ncells);
  }
  if (n_point_arrays > 0) {
    out += "POINT_DATA " + std::to_string(nn) + "\nFIELD FieldData " + std::to_string(n_point_arrays) + "\n";
    if (!mesh.weight.empty()) {
      out += "weight 1 " + std::to_string(nn) + " double\n";
      doubles(mesh.weight.data(), nn, 6);
    }
    field_arrays(FieldLocation::node, nn, nn);
  }
  io::AtomicFile f(path);
  f.write(out);
  f.commit();
}

}  // namespace foxi
