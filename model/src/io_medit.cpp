// Medit .mesh reader and writer (the record scanner is shared with TetGen: io_records.hpp). gmsh's
// Medit export (`gmsh -3 -format mesh`) gives positive tets (checked by
// MeditOracle.GmshFileMatchesMeshioAndAnalyticVolumes), as Medit/MMG expect, so the reader keeps the
// vertex order as written; see io_tetgen.cpp for TetGen's. Non-finite coordinates are rejected with
// an IoError naming the line.
#include "foxi/model/io_medit.hpp"

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
#include "io_records.hpp"

namespace foxi {

namespace {

using namespace records;

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
  io::strip_byte_order_mark(bytes);
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
