// TetGen .node / .ele / .face readers and writers (Medit .mesh: io_medit.cpp; the record scanner both
// use: io_records.hpp).
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
#include "io_records.hpp"

namespace foxi {
namespace {

using namespace records;

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
  // Decided by the first face's columns past its corners and markers: 3 mid-edge nodes (second-order
  // faces, tetgen -o2), 2 adjacent tets (tetgen -nn, after the markers; it was refused), or both.
  int mid_nodes = -1, adjacent = 0;
  for (std::uint64_t k = 0; k < n; ++k) {
    in.set_record("face", k + 1);
    if (!in.skip_to_content()) in.fail("unexpected end of file, expected " + std::to_string(n) + " faces");
    (void)in.integer<L>("face number");
    if (mid_nodes < 0) {
      const std::uint64_t extra =
          in.tokens_left_on_line() - std::min<std::uint64_t>(in.tokens_left_on_line(), 3 + nmark);
      mid_nodes = extra == 3 || extra == 5 ? 3 : 0;
      adjacent = extra == 2 || extra == 5 ? 2 : 0;
    }
    for (int c = 0; c < 3; ++c) m.bface[3 * k + c] = in.node_index<L>("node", offset, nodes);
    for (int c = 0; c < mid_nodes; ++c) (void)in.node_index<L>("mid-edge node", offset, nodes);
    if (nmark > 0) m.bface_tag[k] = in.id_value<L>("boundary marker");
    for (std::uint64_t a = 1; a < nmark; ++a) in.skip_number<L>("boundary marker");
    for (int a = 0; a < adjacent; ++a) in.skip_number<L>("adjacent tet");
    in.end_line("the face's values");
  }
  in.set_record(nullptr, 0);
  if (in.skip_to_content()) in.fail("more data after the " + std::to_string(n) + " declared faces");
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
  io::strip_byte_order_mark(node);
  io::strip_byte_order_mark(ele);
  std::string face;
  std::filesystem::path face_path = with_suffix(base, ".face");
  std::error_code ec;
  if (std::filesystem::exists(face_path, ec)) {
    face = io::read_file(face_path);
    io::strip_byte_order_mark(face);
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

}  // namespace foxi
