// Fields as other programs write them, with what they stand on: the readers of the field importer.
//
//   .vtu .vtk .msh   the mesh readers of foxi::model (read_mesh): point/cell data, $NodeData /
//                    $ElementData with every step; the source mesh is the file's mesh.
//   .pvd             a ParaView collection of .vtu files (as foxi solve --physics transient writes
//                    it): every data set one step (its timestep attribute the step value) of the
//                    fields of the first; all data sets must have the same nodes and cells.
//   .frd             CalculiX results, ASCII or binary (float32 values): the nodes (2C) and the tets among
//   the elements (3C:
//                    C3D4, C3D10 as its corners), every nodal result block (DISP, NDTEMP, STRESS,
//                    FLUX, ERROR, ...) of every step; a block name seen again is a new step of the
//                    same field (step value: the time of its 100C record). Components that ccx
//                    computes itself (the "ALL" entry of DISP) are not in the file and not read.
//                    Binary blocks' errors name the byte offset instead of the line.
//   .csv             one header row naming the columns, then one row per node (or cell). The key:
//                    a column "id" / "node" / "node_id" (node ids, 1-based as foxi's .msh and .inp
//                    writers number them), or "cell" / "cell_id" / "element" (tet ids, 1-based), or
//                    the coordinates "x", "y", "z" (also ParaView's "Points:0".."Points:2"). Every
//                    other column is a field component: "NAME", "NAME [UNIT]", and for vectors and
//                    tensors "NAME:k" (ParaView's spelling) or "NAME_x" / "NAME_y" / "NAME_z".
//                    Separator: comma, semicolon or tab (from the header); empty cells and "nan" are
//                    NaN; any other non-number is an error naming its line and column.
//
// Every reader throws IoError (file, line, reason) on a malformed file and never returns half a
// source.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

// A transfer the inputs do not allow (counts, ids, coordinates or components that do not match,
// a field that is not in the source, a location transfer without source tets): the message says
// which and why.
class FOXI_API FieldError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a source's entities are keyed by.
enum class SourceKey : std::uint8_t {
  position,     // entity i of the file is entity i of its mesh (.vtu, .vtk, .msh, .pvd)
  node_id,      // node_id[i] is the file's number of node i (.frd, CSV with an id column)
  cell_id,      // cell_id[i] is the file's number of cell i (CSV with a cell column)
  coordinates,  // nodes are points (mesh.xyz) without tets (CSV with x, y, z)
};

struct FieldSource {
  std::string path;
  std::string format;  // "vtu", "vtk", "msh", "pvd", "frd", "csv"
  SourceKey key = SourceKey::position;
  // The source's nodes and tets where the file has them (xyz is empty for a CSV keyed by id alone),
  // its regions (tet_region empty where the file has none) and its fields (mesh.fields). A field
  // over nodes has an entry per node of this mesh; a CSV keyed by cells, per row (cell_id).
  Mesh mesh;
  std::vector<std::uint64_t> node_id;  // key node_id: one per node of `mesh`
  std::vector<std::uint64_t> cell_id;  // key cell_id: one per value row of the cell fields

  // The entities a field of this source has values for.
  std::size_t entity_count(const Field& f) const {
    if (f.location == FieldLocation::node)
      return key == SourceKey::node_id ? node_id.size() : mesh.node_count();
    return key == SourceKey::cell_id ? cell_id.size() : mesh.tet_count();
  }
};

// Reads a field source, the format from the extension (see above). Throws IoError.
FOXI_API FieldSource read_field_source(const std::filesystem::path& path);

// The readers by format; `name` is used in error messages.
// The .frd reader keeps node values dense (NaN where a block has no line for a node), and a block of
// a few lines stands for every node (ccx's *NODE FILE with an NSET writes a few nodes an increment),
// so its memory is bounded by the file: all blocks together keep at most max(min_values,
// values_per_byte x the file's bytes) values, else IoError naming the block. The defaults: 2^27
// values (1 GB), or 128 bytes of memory per byte of file (a dense ASCII block holds about one value
// per 12 bytes, a binary one one per 4).
struct FrdLimits {
  std::size_t min_values = std::size_t(1) << 27;
  std::size_t values_per_byte = 16;
};
FOXI_API FieldSource read_frd_source(const std::filesystem::path& path, const FrdLimits& limits = {});
FOXI_API FieldSource parse_frd_source(std::string_view bytes, const std::string& name,
                                      const FrdLimits& limits = {});
FOXI_API FieldSource read_csv_source(const std::filesystem::path& path);
FOXI_API FieldSource parse_csv_source(std::string_view bytes, const std::string& name);
FOXI_API FieldSource read_pvd_source(const std::filesystem::path& path);

}  // namespace foxi
