// VTK readers and writers: XML unstructured grid (.vtu) and legacy (.vtk).
//
// Decisions (see also io_vtk.hpp):
// - NaN or infinite coordinates and values are accepted as read; validate() reports them.
// - Region and boundary names and field units / step values are not part of the VTK formats. The
//   .vtu writer keeps them in attributes that VTK, ParaView and meshio ignore: foxi_region_names
//   and foxi_boundary_names on the "region" DataArray ("id=name;id=name", names %-escaped), and
//   foxi_unit / foxi_step_value on each field array. Each region's material (name and properties)
//   goes into foxi_region_materials on the region array ("id=name|k|sigma|eps|E|nu|alpha;...", NaN
//   for a property not set), so that a mesh written from a model solves without restating them.
//   The reader restores them when present; the legacy format keeps none of them (multi-step fields
//   get step values 0, 1, 2, ...).
// - A field with several steps is written as arrays "name", "name@2", "name@3", ...; the reader
//   groups such a consecutive run (same location and components) back into one field.
// - Cell fields keep the values of the tet cells only; the writer gives boundary triangle cells NaN.
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

namespace foxi {
namespace {

using vtk::VType;
constexpr bool kHostLittle = std::endian::native == std::endian::little;
constexpr std::uint64_t kUnknown = ~std::uint64_t{0};
// zlib cannot expand data by more than about 1032:1; used to bound declared sizes.
constexpr std::uint64_t kZlibMaxRatio = 1032;

constexpr const char* kRegionNames[] = {"region", "gmsh:physical", "CellEntityIds", "medit:ref",
                                        "tetgen:ref"};


// ------------------------------------------------------------------------------------------------
// Decoded arrays: bytes of `count` values of `type`, either lent (a view into the file) or owned.
struct ArrayData {
  VType type = VType::f64;
  std::uint64_t count = 0;  // values (tuples * components)
  std::string_view lent;    // count * type_size(type) bytes in the file, or
  std::string owned;        // the same, owned (is_owned)
  bool is_owned = false;
  bool swap = false;  // bytes are in the other byte order

  // Never a stored view of `owned`: a moved std::string may move its (short) buffer.
  const char* data() const { return is_owned ? owned.data() : lent.data(); }
  void own(std::string s) {
    owned = std::move(s);
    is_owned = true;
  }
};

ArrayData make_owned_f64(std::vector<double>& v) {
  ArrayData a;
  a.type = VType::f64;
  a.count = v.size();
  a.owned.assign(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  a.is_owned = true;
  return a;
}
ArrayData make_owned_i64(std::vector<std::int64_t>& v) {
  ArrayData a;
  a.type = VType::i64;
  a.count = v.size();
  a.owned.assign(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(std::int64_t));
  a.is_owned = true;
  return a;
}

template <class T>
struct Acc {
  const char* p;
  bool swap;
  T operator[](std::size_t i) const { return io::load<T>(p + i * sizeof(T), swap); }
};

template <class F>
decltype(auto) dispatch(const ArrayData& a, F&& f) {
  const char* p = a.data();
  switch (a.type) {
    case VType::i8:
      return f(Acc<std::int8_t>{p, a.swap});
    case VType::u8:
      return f(Acc<std::uint8_t>{p, a.swap});
    case VType::i16:
      return f(Acc<std::int16_t>{p, a.swap});
    case VType::u16:
      return f(Acc<std::uint16_t>{p, a.swap});
    case VType::i32:
      return f(Acc<std::int32_t>{p, a.swap});
    case VType::u32:
      return f(Acc<std::uint32_t>{p, a.swap});
    case VType::i64:
      return f(Acc<std::int64_t>{p, a.swap});
    case VType::u64:
      return f(Acc<std::uint64_t>{p, a.swap});
    case VType::f32:
      return f(Acc<float>{p, a.swap});
    case VType::f64:
      break;
  }
  return f(Acc<double>{p, a.swap});
}

// Appends values [first, first + n) of `a` as doubles to `out`.
void append_doubles(const ArrayData& a, std::size_t first, std::size_t n, std::vector<double>& out) {
  std::size_t at = out.size();
  io::reserve_huge(out, at + n);
  out.resize(at + n);
  double* d = out.data() + at;
  if (n == 0) return;
  if (a.type == VType::f64 && !a.swap) {
    std::memcpy(d, a.data() + first * 8, n * 8);
    return;
  }
  dispatch(a, [&](auto acc) {
    for (std::size_t i = 0; i < n; ++i) d[i] = static_cast<double>(acc[first + i]);
  });
}

// An integer array as int32 or int64 in host order (converted when it is anything else). Throws via
// `fail` (a callable taking a reason) if a value is not an integer that fits in int64.
template <class Fail>
ArrayData normalize_ints(ArrayData a, Fail&& fail) {
  if ((a.type == VType::i32 || a.type == VType::i64) && !a.swap) return a;
  std::vector<std::int64_t> v(a.count);
  dispatch(a, [&](auto acc) {
    using T = std::decay_t<decltype(acc[0])>;
    for (std::size_t i = 0; i < a.count; ++i) {
      T x = acc[i];
      if constexpr (std::is_floating_point_v<T>) {
        if (!(x >= -9.2e18 && x <= 9.2e18) || std::trunc(x) != x)
          fail("value " + std::to_string(x) + " at index " + std::to_string(i) + " is not an integer");
      } else if constexpr (std::is_same_v<T, std::uint64_t>) {
        if (x > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
          fail("value " + std::to_string(x) + " at index " + std::to_string(i) + " is too large");
      }
      v[i] = static_cast<std::int64_t>(x);
    }
  });
  return make_owned_i64(v);
}

template <class F>
decltype(auto) dispatch_int(const ArrayData& a, F&& f) {
  if (a.type == VType::i32) return f(Acc<std::int32_t>{a.data(), false});
  return f(Acc<std::int64_t>{a.data(), false});
}

// ------------------------------------------------------------------------------------------------
// What a reader hands to the assembler, piece by piece.
struct NamedArray {
  std::string name;
  std::uint32_t components = 1;
  ArrayData data;
  std::string unit;
  std::optional<double> step_value;
  std::string region_names;    // foxi_region_names attribute (region array only)
  std::string region_materials;  // foxi_region_materials attribute (region array only)
  std::string boundary_names;  // foxi_boundary_names attribute
  std::size_t at = 0;          // file offset of its declaration (for errors)
};

struct Piece {
  std::uint64_t npoints = 0, ncells = 0;
  std::size_t at = 0, cells_at = 0;  // file offsets of the piece and its cells (for errors)
  ArrayData points;                  // 3 * npoints values
  ArrayData conn;                    // connectivity
  ArrayData offsets;                 // ncells values: end of each cell in conn
  ArrayData types;                   // ncells values
  std::vector<NamedArray> point_arrays, cell_arrays;
};

struct CollectedArray {
  std::string name;
  FieldLocation location;
  std::uint32_t components;
  std::vector<double> values;
  std::string unit;
  std::optional<double> step_value;
  std::size_t pieces = 0;
};

const char* cell_type_name(std::int64_t t) {
  switch (t) {
    case 0:
      return "empty cell";
    case 6:
      return "triangle strip";
    case 7:
      return "polygon";
    case 8:
      return "pixel";
    case 9:
      return "quad";
    case 11:
      return "voxel";
    case 12:
      return "hexahedron";
    case 13:
      return "wedge";
    case 14:
      return "pyramid";
    case 15:
      return "pentagonal prism";
    case 16:
      return "hexagonal prism";
    case 21:
      return "quadratic edge";
    case 22:
      return "quadratic triangle";
    case 23:
      return "quadratic quad";
    case 24:
      return "quadratic tetra";
    case 25:
      return "quadratic hexahedron";
    case 42:
      return "polyhedron";
    default:
      return "unknown";
  }
}

std::string percent_decode(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size()) {
      unsigned v = 0;
      auto r = std::from_chars(s.data() + i + 1, s.data() + i + 3, v, 16);
      if (r.ec == std::errc() && r.ptr == s.data() + i + 3) {
        out.push_back(static_cast<char>(v));
        i += 2;
        continue;
      }
    }
    out.push_back(s[i]);
  }
  return out;
}

std::string percent_encode(std::string_view s, std::string_view special) {
  std::string out;
  for (char c : s) {
    auto u = static_cast<unsigned char>(c);
    if (u <= 32 || u == 127 || c == '%' || special.find(c) != std::string_view::npos) {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", u);
      out += buf;
    } else {
      out.push_back(c);
    }
  }
  return out;
}

// "1=lower;2=upper" -> id -> name
std::map<std::int32_t, std::string> parse_names(std::string_view s) {
  std::map<std::int32_t, std::string> m;
  while (!s.empty()) {
    std::size_t semi = s.find(';');
    std::string_view item = s.substr(0, semi);
    s = semi == std::string_view::npos ? std::string_view() : s.substr(semi + 1);
    std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) continue;
    std::int32_t id = 0;
    auto r = std::from_chars(item.data(), item.data() + eq, id);
    if (r.ec != std::errc() || r.ptr != item.data() + eq) continue;
    m[id] = percent_decode(item.substr(eq + 1));
  }
  return m;
}

// A material's properties in the order foxi_region_materials keeps them, as bit patterns (so that
// NaN, "not set", compares equal to NaN).
std::array<std::uint64_t, 6> material_values(const Material& m) {
  const double v[6] = {m.thermal_conductivity, m.electrical_conductivity, m.relative_permittivity,
                       m.youngs_modulus,       m.poisson_ratio,           m.thermal_expansion};
  std::array<std::uint64_t, 6> bits{};
  for (std::size_t i = 0; i < 6; ++i) bits[i] = std::isnan(v[i]) ? 0x7ff8000000000000ull : std::bit_cast<std::uint64_t>(v[i]);
  return bits;
}

// "name|k|sigma|eps|E|nu|alpha" (name %-escaped, "nan" for a property not set); nothing when it
// does not have that form (an attribute another writer put there is ignored, not an error).
std::optional<Material> parse_material(std::string_view s) {
  std::vector<std::string_view> parts;
  for (std::size_t bar; (bar = s.find('|')) != std::string_view::npos; s = s.substr(bar + 1)) parts.push_back(s.substr(0, bar));
  parts.push_back(s);
  if (parts.size() != 7) return std::nullopt;
  Material m;
  m.name = percent_decode(parts[0]);
  double* v[6] = {&m.thermal_conductivity, &m.electrical_conductivity, &m.relative_permittivity,
                  &m.youngs_modulus,       &m.poisson_ratio,           &m.thermal_expansion};
  for (std::size_t i = 0; i < 6; ++i) {
    const std::string_view t = parts[i + 1];
    if (t == "nan") continue;
    auto r = std::from_chars(t.data(), t.data() + t.size(), *v[i]);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
  }
  return m;
}

// Builds the mesh from pieces: appends nodes, tets, boundary triangles and arrays.
class Assembler {
 public:
  Assembler(const std::string& file, std::string_view text) : file_(file), text_(text) {}

  void add(Piece& p, std::size_t piece_index) {
    std::size_t where = p.at;  // offset in the file the next error refers to
    auto fail = [&](const std::string& reason) -> void {
      io::fail_text(file_, text_, where,
                    (piece_count_ > 0 || piece_index > 0 ? "piece " + std::to_string(piece_index + 1) + ": "
                                                         : std::string()) +
                        reason);
    };
    const std::uint64_t node_base = mesh_.node_count();
    if (node_base + p.npoints >= kNone) fail("too many nodes for 32-bit indices");
    if (p.points.count != 3 * p.npoints) fail("points array does not hold 3 values per point");
    append_doubles(p.points, 0, p.points.count, mesh_.xyz);

    // Cells.
    where = p.cells_at;
    if (p.offsets.count != p.ncells || p.types.count != p.ncells)
      fail("offsets and types must have one entry per cell (" + std::to_string(p.ncells) + ")");
    auto int_fail = [&](const char* what) {
      return [&, what](const std::string& r) { fail(std::string(what) + ": " + r); };
    };
    p.conn = normalize_ints(std::move(p.conn), int_fail("connectivity"));
    p.offsets = normalize_ints(std::move(p.offsets), int_fail("offsets"));
    ArrayData types = p.types.type == VType::u8 ? std::move(p.types)
                                                : normalize_ints(std::move(p.types), int_fail("types"));
    // Count tets and triangles, check types.
    // 0 skip, 1 tet, 2 triangle; quadratic tets (24) and triangles (22) are read as their corners
    // (the first 4 or 3 nodes; the mid-edge points stay, unused).
    std::vector<std::uint8_t> kind(p.ncells), quadratic(p.ncells, 0);
    std::size_t ntet = 0, ntri = 0;
    auto types_loop = [&](auto t) {
      for (std::size_t i = 0; i < p.ncells; ++i) {
        auto v = static_cast<std::int64_t>(t[i]);
        if (v == 10 || v == 24) {
          kind[i] = 1;
          quadratic[i] = v == 24;
          ++ntet;
        } else if (v == 5 || v == 22) {
          kind[i] = 2;
          quadratic[i] = v == 22;
          ++ntri;
        } else if ((v >= 1 && v <= 4) || v == 21) {
          kind[i] = 0;
        } else {
          fail("cell " + std::to_string(i) + " has unsupported cell type " + std::to_string(v) + " (" +
               cell_type_name(v) +
               "); foxi reads tetra (10) and quadratic tetra (24), triangle (5) and quadratic triangle "
               "(22), and skips vertices and lines");
        }
      }
    };
    if (types.type == VType::u8)
      types_loop(Acc<std::uint8_t>{types.data(), false});
    else
      dispatch_int(types, types_loop);
    std::size_t tet_at = mesh_.tet.size(), tri_at = mesh_.bface.size();
    io::reserve_huge(mesh_.tet, tet_at + 4 * ntet);
    mesh_.tet.resize(tet_at + 4 * ntet);
    mesh_.bface.resize(tri_at + 3 * ntri);
    std::uint32_t* td = mesh_.tet.data() + tet_at;
    std::uint32_t* fd = mesh_.bface.data() + tri_at;
    const std::int64_t nconn = static_cast<std::int64_t>(p.conn.count);
    const std::int64_t np = static_cast<std::int64_t>(p.npoints);
    const auto base = static_cast<std::uint32_t>(node_base);
    dispatch_int(p.offsets, [&](auto off) {
      dispatch_int(p.conn, [&](auto c) {
        std::int64_t prev = 0;
        for (std::size_t i = 0; i < p.ncells; ++i) {
          std::int64_t end = static_cast<std::int64_t>(off[i]);
          if (end < prev || end > nconn) {
            fail("cell " + std::to_string(i) + ": offset " + std::to_string(end) +
                 (end < prev
                      ? " is smaller than the previous offset " + std::to_string(prev)
                      : " is past the end of the connectivity (" + std::to_string(nconn) + " entries)"));
          }
          std::uint8_t k = kind[i];
          if (k != 0) {
            const std::int64_t corners = k == 1 ? 4 : 3;
            const std::int64_t want = quadratic[i] ? (k == 1 ? 10 : 6) : corners;
            if (end - prev != want)
              fail("cell " + std::to_string(i) + " (" + (quadratic[i] ? "quadratic " : "") +
                   (k == 1 ? "tetra" : "triangle") + ") has " + std::to_string(end - prev) + " nodes, expected " +
                   std::to_string(want));
            std::uint32_t* d = k == 1 ? td : fd;
            for (std::int64_t j = 0; j < want; ++j) {
              auto v = static_cast<std::int64_t>(c[static_cast<std::size_t>(prev + j)]);
              if (v < 0 || v >= np)
                fail("cell " + std::to_string(i) + ": node index " + std::to_string(v) +
                     " out of range (the piece has " + std::to_string(np) + " points)");
              if (j < corners) d[j] = static_cast<std::uint32_t>(v) + base;
            }
            if (k == 1)
              td += 4;
            else
              fd += 3;
          }
          prev = end;
        }
      });
    });

    // Cell arrays: the region array first.
    int region_index = -1;
    for (const char* rn : kRegionNames) {
      for (std::size_t a = 0; a < p.cell_arrays.size() && region_index < 0; ++a)
        if (p.cell_arrays[a].name == rn && p.cell_arrays[a].components == 1)
          region_index = static_cast<int>(a);
      if (region_index >= 0) break;
    }
    std::size_t tets_before = tet_at / 4;
    if (region_index >= 0) {
      NamedArray& ra = p.cell_arrays[static_cast<std::size_t>(region_index)];
      where = ra.at;
      if (ra.data.count != p.ncells) fail("cell array '" + ra.name + "' size does not match the cell count");
      ArrayData r = normalize_ints(std::move(ra.data), int_fail(ra.name.c_str()));
      if (!have_region_ && tets_before > 0) mesh_.tet_region.assign(tets_before, 0);
      io::reserve_huge(mesh_.tet_region, mesh_.tet_count());
      have_region_ = true;
      dispatch_int(r, [&](auto acc) {
        for (std::size_t i = 0; i < p.ncells; ++i) {
          if (kind[i] == 0) continue;
          auto v = static_cast<std::int64_t>(acc[i]);
          if (v < std::numeric_limits<std::int32_t>::min() || v > std::numeric_limits<std::int32_t>::max())
            fail("cell array '" + ra.name + "': value " + std::to_string(v) + " does not fit in 32 bits");
          if (kind[i] == 1)
            mesh_.tet_region.push_back(static_cast<std::int32_t>(v));
          else
            mesh_.bface_tag.push_back(static_cast<std::int32_t>(v));
        }
      });
      for (auto& [id, n] : parse_names(ra.region_names)) region_names_[id] = n;
      for (auto& [id, m] : parse_names(ra.region_materials))
        if (std::optional<Material> mat = parse_material(m)) region_materials_[id] = *mat;
      for (auto& [id, n] : parse_names(ra.boundary_names)) boundary_names_[id] = n;
    } else {
      if (have_region_) mesh_.tet_region.resize(mesh_.tet_count(), 0);
      mesh_.bface_tag.resize(mesh_.bface_count(), 0);
    }

    // Point arrays.
    for (NamedArray& na : p.point_arrays) {
      where = na.at;
      if (na.data.count != p.npoints * na.components)
        fail("point array '" + na.name + "' has " + std::to_string(na.data.count) + " values, expected " +
             std::to_string(p.npoints * na.components));
      if (na.name == "weight" && na.components == 1) {
        if (mesh_.weight.size() != node_base) fail("point array 'weight' is missing in a piece");
        append_doubles(na.data, 0, na.data.count, mesh_.weight);
        continue;
      }
      CollectedArray& ca = collect(na, FieldLocation::node, piece_index);
      append_doubles(na.data, 0, na.data.count, ca.values);
    }
    // Other cell arrays become cell fields (tet values only).
    for (std::size_t a = 0; a < p.cell_arrays.size(); ++a) {
      if (static_cast<int>(a) == region_index) continue;
      NamedArray& na = p.cell_arrays[a];
      where = na.at;
      if (na.data.count != p.ncells * na.components)
        fail("cell array '" + na.name + "' has " + std::to_string(na.data.count) + " values, expected " +
             std::to_string(p.ncells * na.components));
      CollectedArray& ca = collect(na, FieldLocation::cell, piece_index);
      const std::size_t nc = na.components;
      if (ntet == p.ncells) {
        append_doubles(na.data, 0, na.data.count, ca.values);
      } else {
        std::size_t at = ca.values.size();
        io::reserve_huge(ca.values, at + ntet * nc);
        ca.values.resize(at + ntet * nc);
        double* d = ca.values.data() + at;
        dispatch(na.data, [&](auto acc) {
          for (std::size_t i = 0; i < p.ncells; ++i) {
            if (kind[i] != 1) continue;
            for (std::size_t k = 0; k < nc; ++k) *d++ = static_cast<double>(acc[i * nc + k]);
          }
        });
      }
    }
    ++piece_count_;
  }

  Mesh finish() {
    auto fail = [&](const std::string& reason) { throw IoError(file_, 0, IoError::kNoOffset, reason); };
    if (!mesh_.weight.empty() && mesh_.weight.size() != mesh_.node_count())
      fail("point array 'weight' is missing in a piece");
    for (auto& ca : arrays_)
      if (ca.pieces != piece_count_) fail("array '" + ca.name + "' is missing in some pieces");
    // Group "name", "name@2", "name@3", ... into one field with steps.
    std::vector<bool> used(arrays_.size(), false);
    for (std::size_t a = 0; a < arrays_.size(); ++a) {
      if (used[a]) continue;
      used[a] = true;
      CollectedArray& first = arrays_[a];
      std::vector<std::size_t> steps{a};
      for (int s = 2;; ++s) {
        auto it = index_.find({first.name + "@" + std::to_string(s), first.location});
        if (it == index_.end() || used[it->second]) break;
        const CollectedArray& c = arrays_[it->second];
        if (c.components != first.components) break;
        steps.push_back(it->second);
      }
      Field f;
      f.name = first.name;
      f.location = first.location;
      f.components = first.components;
      f.unit = first.unit;
      bool all_values = true;
      for (std::size_t s : steps) all_values = all_values && arrays_[s].step_value.has_value();
      if (steps.size() == 1) {
        if (first.step_value) f.step_values = {*first.step_value};
        f.values = std::move(first.values);
      } else {
        for (std::size_t k = 0; k < steps.size(); ++k) {
          CollectedArray& c = arrays_[steps[k]];
          used[steps[k]] = true;
          f.step_values.push_back(all_values ? *c.step_value : static_cast<double>(k));
          f.values.insert(f.values.end(), c.values.begin(), c.values.end());
          c.values.clear();
          c.values.shrink_to_fit();
        }
      }
      mesh_.fields.push_back(std::move(f));
    }
    // Regions and boundaries: one per distinct id.
    if (have_region_) {
      std::vector<std::int32_t> ids = io::distinct_ids(mesh_.tet_region);
      for (std::int32_t id : ids) {
        auto it = region_names_.find(id);
        mesh_.regions.push_back({id, it == region_names_.end() ? std::string() : it->second, kNone});
        if (auto m = region_materials_.find(id); m != region_materials_.end()) {
          // Regions of one material share it (equal name and properties, NaN equal to NaN).
          auto same = [&](const Material& a) { return a.name == m->second.name && material_values(a) == material_values(m->second); };
          auto at = std::find_if(mesh_.materials.begin(), mesh_.materials.end(), same);
          if (at == mesh_.materials.end()) at = mesh_.materials.insert(mesh_.materials.end(), m->second);
          mesh_.regions.back().material = static_cast<std::uint32_t>(at - mesh_.materials.begin());
        }
      }
    }
    for (std::int32_t tag : io::distinct_ids(mesh_.bface_tag)) {
      auto it = boundary_names_.find(tag);
      mesh_.boundaries.push_back({tag, it == boundary_names_.end() ? std::string() : it->second});
    }
    return std::move(mesh_);
  }

 private:


  CollectedArray& collect(NamedArray& na, FieldLocation loc, std::size_t piece_index) {
    auto key = std::make_pair(na.name, loc);
    auto it = index_.find(key);
    if (it == index_.end()) {
      if (piece_index > 0)
        io::fail_text(file_, text_, na.at,
                      "array '" + na.name + "' of piece " + std::to_string(piece_index + 1) +
                          " is not in the first piece");
      index_[key] = arrays_.size();
      arrays_.push_back({na.name, loc, na.components, {}, na.unit, na.step_value, 0});
      arrays_.back().pieces = 1;
      return arrays_.back();
    }
    CollectedArray& ca = arrays_[it->second];
    if (ca.components != na.components)
      io::fail_text(file_, text_, na.at,
                    "array '" + na.name + "' has different component counts in different pieces");
    ++ca.pieces;
    return ca;
  }

  const std::string& file_;
  std::string_view text_;
  Mesh mesh_;
  bool have_region_ = false;
  std::size_t piece_count_ = 0;
  std::vector<CollectedArray> arrays_;
  std::map<std::pair<std::string, FieldLocation>, std::size_t> index_;
  std::map<std::int32_t, std::string> region_names_, boundary_names_;
  std::map<std::int32_t, Material> region_materials_;
};

// ------------------------------------------------------------------------------------------------
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
    if (nblocks >= 16) {
      std::thread helper(inflate_range, nblocks / 2, nblocks);
      inflate_range(0, nblocks / 2);
      helper.join();
    } else {
      inflate_range(0, nblocks);
    }
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

// ------------------------------------------------------------------------------------------------
// .vtu writer
namespace {

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

std::string names_attribute(const std::vector<std::pair<std::int32_t, std::string>>& items) {
  std::string s;
  for (const auto& [id, name] : items) {
    if (name.empty()) continue;
    if (!s.empty()) s += ';';
    s += std::to_string(id) + "=" + percent_encode(name, ";=");
  }
  return s;
}

// parse_material's form: "name|k|sigma|eps|E|nu|alpha", shortest round-trip numbers.
std::string material_attribute(const Material& m) {
  std::string s = percent_encode(m.name, ";=|");
  for (double v : {m.thermal_conductivity, m.electrical_conductivity, m.relative_permittivity, m.youngs_modulus,
                   m.poisson_ratio, m.thermal_expansion}) {
    s += '|';
    if (std::isnan(v)) {
      s += "nan";
      continue;
    }
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    s.append(buf, r.ptr);
  }
  return s;
}

struct OutArray {
  std::string name;
  VType type;
  std::uint32_t components = 1;
  const void* data = nullptr;  // count values of `type`, host order
  std::size_t count = 0;
  std::string extra;  // more attributes, already escaped, starting with a space
};

template <class T>
void append_ascii(std::string& out, const T* v, std::size_t n, std::size_t per_line) {
  for (std::size_t i = 0; i < n; ++i) {
    if constexpr (std::is_floating_point_v<T>)
      io::append_double(out, v[i]);
    else
      io::append_int(out, v[i]);
    out.push_back((i + 1) % per_line == 0 || i + 1 == n ? '\n' : ' ');
  }
}

void append_ascii_array(std::string& out, const OutArray& a) {
  std::size_t per_line = a.components == 1 ? 6 : a.components;
  switch (a.type) {
    case VType::f64:
      append_ascii(out, static_cast<const double*>(a.data), a.count, per_line);
      break;
    case VType::i32:
      append_ascii(out, static_cast<const std::int32_t*>(a.data), a.count, per_line);
      break;
    case VType::i64:
      append_ascii(out, static_cast<const std::int64_t*>(a.data), a.count, per_line);
      break;
    case VType::u8: {
      const auto* p = static_cast<const std::uint8_t*>(a.data);
      for (std::size_t i = 0; i < a.count; ++i) {
        io::append_int(out, static_cast<unsigned>(p[i]));
        out.push_back((i + 1) % 20 == 0 || i + 1 == a.count ? '\n' : ' ');
      }
      break;
    }
    default:
      break;
  }
}

void write_vtu_impl(const Mesh& mesh, const std::filesystem::path& path, VtuEncoding enc) {
  const std::string file = path.string();
  if (std::string err = check_sizes(mesh); !err.empty())
    throw IoError(file, 0, IoError::kNoOffset, "cannot write an inconsistent mesh: " + err);
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nf = mesh.bface_count();
  const std::size_t ncells = nt + nf;
  const std::size_t nconn = 4 * nt + 3 * nf;
  const bool wide = nconn > 0x7fffffffu || nn > 0x7fffffffu;

  // Cells.
  std::vector<std::int32_t> conn32, off32;
  std::vector<std::int64_t> conn64, off64;
  std::vector<std::uint8_t> types(ncells);
  std::fill(types.begin(), types.begin() + static_cast<std::ptrdiff_t>(nt), std::uint8_t{10});
  std::fill(types.begin() + static_cast<std::ptrdiff_t>(nt), types.end(), std::uint8_t{5});
  auto fill_cells = [&](auto& conn, auto& off) {
    using T = typename std::decay_t<decltype(conn)>::value_type;
    conn.resize(nconn);
    off.resize(ncells);
    for (std::size_t i = 0; i < 4 * nt; ++i) conn[i] = static_cast<T>(mesh.tet[i]);
    for (std::size_t i = 0; i < 3 * nf; ++i) conn[4 * nt + i] = static_cast<T>(mesh.bface[i]);
    for (std::size_t i = 0; i < nt; ++i) off[i] = static_cast<T>(4 * (i + 1));
    for (std::size_t i = 0; i < nf; ++i) off[nt + i] = static_cast<T>(4 * nt + 3 * (i + 1));
  };
  std::vector<OutArray> point_arrays, cell_arrays;
  OutArray points{"Points", VType::f64, 3, mesh.xyz.data(), mesh.xyz.size(), ""};
  OutArray conn_a{"connectivity", VType::i32, 1, nullptr, nconn, ""};
  OutArray off_a{"offsets", VType::i32, 1, nullptr, ncells, ""};
  if (wide) {
    fill_cells(conn64, off64);
    conn_a.type = off_a.type = VType::i64;
    conn_a.data = conn64.data();
    off_a.data = off64.data();
  } else {
    fill_cells(conn32, off32);
    conn_a.data = conn32.data();
    off_a.data = off32.data();
  }
  OutArray types_a{"types", VType::u8, 1, types.data(), ncells, ""};

  // Region array (tets then triangles).
  std::vector<std::int32_t> region;
  if (!mesh.tet_region.empty() || nf > 0 || !mesh.regions.empty()) {
    region.resize(ncells, 0);
    if (!mesh.tet_region.empty()) std::copy(mesh.tet_region.begin(), mesh.tet_region.end(), region.begin());
    std::copy(mesh.bface_tag.begin(), mesh.bface_tag.end(), region.begin() + static_cast<std::ptrdiff_t>(nt));
    OutArray r{"region", VType::i32, 1, region.data(), ncells, ""};
    std::vector<std::pair<std::int32_t, std::string>> rn, bn;
    for (const Region& g : mesh.regions) rn.emplace_back(g.id, g.name);
    for (const Boundary& b : mesh.boundaries) bn.emplace_back(b.tag, b.name);
    std::vector<std::pair<std::int32_t, std::string>> rm;
    for (const Region& g : mesh.regions)
      if (g.material < mesh.materials.size()) rm.emplace_back(g.id, material_attribute(mesh.materials[g.material]));
    std::string ra = names_attribute(rn), ba = names_attribute(bn), ma = names_attribute(rm);
    if (!ra.empty()) r.extra += " foxi_region_names=\"" + xml_escape(ra) + "\"";
    if (!ma.empty()) r.extra += " foxi_region_materials=\"" + xml_escape(ma) + "\"";
    if (!ba.empty()) r.extra += " foxi_boundary_names=\"" + xml_escape(ba) + "\"";
    cell_arrays.push_back(std::move(r));
  }
  if (!mesh.weight.empty()) point_arrays.push_back({"weight", VType::f64, 1, mesh.weight.data(), nn, ""});
  std::vector<std::vector<double>> padded_store;  // cell field steps extended with NaN for triangles
  for (const Field& f : mesh.fields) {
    const std::size_t ne = field_entity_count(mesh, f);
    for (std::size_t s = 0; s < f.step_count(); ++s) {
      OutArray a;
      a.name = s == 0 ? f.name : f.name + "@" + std::to_string(s + 1);
      a.type = VType::f64;
      a.components = f.components;
      std::span<const double> v = f.step(s, ne);
      if (!f.unit.empty()) a.extra += " foxi_unit=\"" + xml_escape(f.unit) + "\"";
      if (!f.step_values.empty()) {
        std::string sv;
        io::append_double(sv, f.step_values[s]);
        a.extra += " foxi_step_value=\"" + sv + "\"";
      }
      if (f.location == FieldLocation::cell && nf > 0) {
        padded_store.emplace_back(v.begin(), v.end());
        padded_store.back().resize(ncells * f.components, std::numeric_limits<double>::quiet_NaN());
        a.data = padded_store.back().data();
        a.count = padded_store.back().size();
      } else {
        a.data = v.data();
        a.count = v.size();
      }
      (f.location == FieldLocation::node ? point_arrays : cell_arrays).push_back(std::move(a));
    }
  }

  // Emit.
  io::AtomicFile out(path);
  std::string head;
  head.reserve(enc == VtuEncoding::ascii || enc == VtuEncoding::base64 ? nconn * 8 + nn * 60 : 4096);
  head += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
  head += kHostLittle ? "LittleEndian" : "BigEndian";
  head += "\" header_type=\"UInt64\"";
  if (enc == VtuEncoding::zlib) head += " compressor=\"vtkZLibDataCompressor\"";
  head += ">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(nn) +
          "\" NumberOfCells=\"" + std::to_string(ncells) + "\">\n";
  // Appended payloads in document order: a header (byte count, or the zlib block header) and the
  // data (a view of the array, or its compressed blocks).
  struct Payload {
    std::string header;
    const void* data;
    std::size_t bytes;
    std::string zdata;
  };
  std::vector<Payload> payloads;
  std::size_t next_payload = 0;
  // Appended blocks are stored in reverse document order (the last DataArray at offset 0): meshio
  // renumbers appended offsets in place while it walks the data, and finds a tag by its offset in
  // document order; with this order an already renumbered tag can never shadow the next one.
  std::uint64_t offset = 0;  // the total size, counted down
  if (enc == VtuEncoding::appended_raw || enc == VtuEncoding::zlib) {
    std::vector<const OutArray*> all{&points, &conn_a, &off_a, &types_a};
    for (const auto* list : {&point_arrays, &cell_arrays})
      for (const OutArray& a : *list) all.push_back(&a);
    for (const OutArray* a : all) {
      Payload p{{}, a->data, a->count * vtk::type_size(a->type), {}};
      if (enc == VtuEncoding::zlib) {
        vtk::zlib_compress_blocks(a->data, p.bytes, 32768, 1, p.header, p.zdata);
        p.data = nullptr;  // zdata (a pointer into it would not survive moving a short string)
        p.bytes = p.zdata.size();
      } else {
        std::uint64_t h = p.bytes;
        p.header.assign(reinterpret_cast<const char*>(&h), 8);
      }
      offset += p.header.size() + p.bytes;
      payloads.push_back(std::move(p));
    }
  }
  auto emit = [&](const OutArray& a, const char* indent) {
    head += indent;
    head += "<DataArray type=\"";
    head += vtk::xml_type_name(a.type);
    head += "\" Name=\"" + xml_escape(a.name) + "\"";
    if (a.components != 1) head += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
    head += a.extra;
    const std::size_t nbytes = a.count * vtk::type_size(a.type);
    switch (enc) {
      case VtuEncoding::ascii:
        head += " format=\"ascii\">\n";
        append_ascii_array(head, a);
        head += indent;
        head += "</DataArray>\n";
        break;
      case VtuEncoding::base64: {
        head += " format=\"binary\">\n";
        std::string raw(8 + nbytes, '\0');
        std::uint64_t h = nbytes;
        std::memcpy(raw.data(), &h, 8);
        if (nbytes) std::memcpy(raw.data() + 8, a.data, nbytes);
        vtk::base64_encode(raw.data(), raw.size(), head);
        head += "\n";
        head += indent;
        head += "</DataArray>\n";
        break;
      }
      case VtuEncoding::appended_raw:
      case VtuEncoding::zlib: {
        const Payload& p = payloads[next_payload++];
        offset -= p.header.size() + p.bytes;
        head += " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
        break;
      }
    }
  };
  constexpr const char* kIn = "        ";
  head += "      <Points>\n";
  emit(points, kIn);
  head += "      </Points>\n      <Cells>\n";
  emit(conn_a, kIn);
  emit(off_a, kIn);
  emit(types_a, kIn);
  head += "      </Cells>\n";
  if (!point_arrays.empty()) {
    head += "      <PointData>\n";
    for (const OutArray& a : point_arrays) emit(a, kIn);
    head += "      </PointData>\n";
  }
  if (!cell_arrays.empty()) {
    head += "      <CellData>\n";
    for (const OutArray& a : cell_arrays) emit(a, kIn);
    head += "      </CellData>\n";
  }
  head += "    </Piece>\n  </UnstructuredGrid>\n";
  if (enc == VtuEncoding::appended_raw || enc == VtuEncoding::zlib) {
    head += "  <AppendedData encoding=\"raw\">\n   _";
    out.write(head);
    for (auto it = payloads.rbegin(); it != payloads.rend(); ++it) {
      const Payload& p = *it;
      out.write(p.header);
      if (p.bytes) out.write(p.data != nullptr ? p.data : p.zdata.data(), p.bytes);
    }
    out.write("\n  </AppendedData>\n</VTKFile>\n");
  } else {
    head += "</VTKFile>\n";
    out.write(head);
  }
  out.commit();
}

}  // namespace

void write_vtu(const Mesh& mesh, const std::filesystem::path& path, VtuEncoding encoding) {
  write_vtu_impl(mesh, path, encoding);
}

// ------------------------------------------------------------------------------------------------
// Legacy .vtk reader
namespace {

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
  if (5 * nt + 4 * nf > 0x7fffffffu)
    throw IoError(file, 0, IoError::kNoOffset, "mesh too large for the legacy VTK format");
  std::string out;
  out.reserve(binary ? 24 * nn + 24 * ncells : 60 * nn + 40 * ncells);
  out += "# vtk DataFile Version 4.2\nfoxi mesh\n";
  out += binary ? "BINARY\n" : "ASCII\n";
  out += "DATASET UNSTRUCTURED_GRID\n";
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
          tmp.assign(v.begin(), v.end());
          tmp.resize(ne_written * f.components, std::numeric_limits<double>::quiet_NaN());
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
