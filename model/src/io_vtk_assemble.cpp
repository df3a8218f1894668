// The VTK readers' common back end: decoded-array helpers and the Assembler that builds the mesh
// from pieces (regions, boundaries, materials and fields from their arrays). Decisions: io_vtk_internal.hpp.
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

namespace foxi::vtk {
namespace {

constexpr const char* kRegionNames[] = {"region", "gmsh:physical", "CellEntityIds", "medit:ref",
                                        "tetgen:ref"};

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
std::array<std::uint64_t, 8> material_values(const Material& m) {
  const double v[8] = {m.thermal_conductivity,
                       m.electrical_conductivity,
                       m.relative_permittivity,
                       m.youngs_modulus,
                       m.poisson_ratio,
                       m.thermal_expansion,
                       m.density,
                       m.specific_heat};
  std::array<std::uint64_t, 8> bits{};
  for (std::size_t i = 0; i < 8; ++i)
    bits[i] = std::isnan(v[i]) ? 0x7ff8000000000000ull : std::bit_cast<std::uint64_t>(v[i]);
  return bits;
}

// "name|k|sigma|eps|E|nu|alpha|rho|c" (name %-escaped, "nan" for a property not set; files written
// before density and specific heat have the first seven only); nothing when it does not have that form (an
// attribute another writer put there is ignored, not an error).
std::optional<Material> parse_material(std::string_view s) {
  std::vector<std::string_view> parts;
  for (std::size_t bar; (bar = s.find('|')) != std::string_view::npos; s = s.substr(bar + 1))
    parts.push_back(s.substr(0, bar));
  parts.push_back(s);
  if (parts.size() != 7 && parts.size() != 9) return std::nullopt;
  Material m;
  m.name = percent_decode(parts[0]);
  double* v[8] = {&m.thermal_conductivity,
                  &m.electrical_conductivity,
                  &m.relative_permittivity,
                  &m.youngs_modulus,
                  &m.poisson_ratio,
                  &m.thermal_expansion,
                  &m.density,
                  &m.specific_heat};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string_view t = parts[i + 1];
    if (t == "nan") continue;
    auto r = std::from_chars(t.data(), t.data() + t.size(), *v[i]);
    if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
  }
  return m;
}

}  // namespace

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

void Assembler::add(Piece& p, std::size_t piece_index) {
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
  ArrayData types =
      p.types.type == VType::u8 ? std::move(p.types) : normalize_ints(std::move(p.types), int_fail("types"));
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
               (end < prev ? " is smaller than the previous offset " + std::to_string(prev)
                           : " is past the end of the connectivity (" + std::to_string(nconn) + " entries)"));
        }
        std::uint8_t k = kind[i];
        if (k != 0) {
          const std::int64_t corners = k == 1 ? 4 : 3;
          const std::int64_t want = quadratic[i] ? (k == 1 ? 10 : 6) : corners;
          if (end - prev != want)
            fail("cell " + std::to_string(i) + " (" + (quadratic[i] ? "quadratic " : "") +
                 (k == 1 ? "tetra" : "triangle") + ") has " + std::to_string(end - prev) +
                 " nodes, expected " + std::to_string(want));
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
      if (p.cell_arrays[a].name == rn && p.cell_arrays[a].components == 1) region_index = static_cast<int>(a);
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

Mesh Assembler::finish() {
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
        auto same = [&](const Material& a) {
          return a.name == m->second.name && material_values(a) == material_values(m->second);
        };
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

CollectedArray& Assembler::collect(NamedArray& na, FieldLocation loc, std::size_t piece_index) {
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

}  // namespace foxi::vtk
