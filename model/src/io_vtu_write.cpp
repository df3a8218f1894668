// The VTK XML unstructured grid (.vtu) writer. Decisions: io_vtk_internal.hpp.
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
// .vtu writer
namespace {

using namespace vtk;

std::string names_attribute(const std::vector<std::pair<std::int32_t, std::string>>& items) {
  std::string s;
  for (const auto& [id, name] : items) {
    if (name.empty()) continue;
    if (!s.empty()) s += ';';
    s += std::to_string(id) + "=" + percent_encode(name, ";=");
  }
  return s;
}

// parse_material's form: "name|k|sigma|eps|E|nu|alpha|rho|c", shortest round-trip numbers.
std::string material_attribute(const Material& m) {
  std::string s = percent_encode(m.name, ";=|");
  for (double v : {m.thermal_conductivity, m.electrical_conductivity, m.relative_permittivity,
                   m.youngs_modulus, m.poisson_ratio, m.thermal_expansion, m.density, m.specific_heat}) {
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
      if (g.material < mesh.materials.size())
        rm.emplace_back(g.id, material_attribute(mesh.materials[g.material]));
    std::string ra = names_attribute(rn), ba = names_attribute(bn), ma = names_attribute(rm);
    if (!ra.empty()) r.extra += " foxi_region_names=\"" + io::xml_escape(ra) + "\"";
    if (!ma.empty()) r.extra += " foxi_region_materials=\"" + io::xml_escape(ma) + "\"";
    if (!ba.empty()) r.extra += " foxi_boundary_names=\"" + io::xml_escape(ba) + "\"";
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
      if (!f.unit.empty()) a.extra += " foxi_unit=\"" + io::xml_escape(f.unit) + "\"";
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
    head += "\" Name=\"" + io::xml_escape(a.name) + "\"";
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
}  // namespace foxi
