// VTK: XML unstructured grid (.vtu) and legacy (.vtk).
//
// Read: points; cells of type 10 (tetra) become tets, type 5 (triangle) boundary triangles (quadratic
// tetra 24 and triangle 22 as their corners, the mid-edge points left unused); vertices
// and lines are skipped; other cell types are an error. Cell arrays named "region", "gmsh:physical",
// "CellEntityIds", "medit:ref" or "tetgen:ref" (Int) give tets their region and triangles their
// boundary tag; every other point or cell array becomes a field. A "weight" point array becomes the
// vertex weights. .vtu encodings: ascii, binary (base64, UInt32 or UInt64 headers), appended (raw or
// base64), compressed with vtkZLibDataCompressor. Legacy: ASCII and binary (big-endian).
// Write: region ids as the cell array "region", boundary triangles as triangle cells with tag in the
// same array, fields as point/cell arrays (one array per step, "name" then "name@step").
//
// Details of foxi's choices:
// - Steps: step k >= 2 of a field is the array "name@k"; on reading, a run "name", "name@2", ...
//   with equal location and components becomes one field again. Field order on reading: point
//   arrays first, then cell arrays.
// - Names, units, step values: .vtu keeps region/boundary names in the attributes
//   foxi_region_names / foxi_boundary_names ("id=name;..." %-escaped) of the "region" array, and
//   foxi_unit / foxi_step_value on field arrays; VTK, ParaView and meshio ignore them. Legacy .vtk
//   keeps none of these (steps read back as step values 0, 1, 2, ...); array names are %-escaped
//   (spaces as %20), as VTK does. Materials are not stored.
// - Cell fields hold tet values only; the writers give boundary-triangle cells NaN.
// - Encodings written: ascii (shortest round-trip decimals), base64 (inline binary), appended_raw,
//   zlib (appended raw, vtkZLibDataCompressor blocks of 32 KiB, level 1); UInt64 headers. Appended
//   blocks lie in reverse document order (meshio's offset renumbering needs it). Connectivity and
//   offsets are Int32 when they fit, else Int64.
// - NaN or infinite coordinates are read as they are (validate() reports them), not rejected.
// - Legacy write: version 4.2 layout ("CELLS n size" rows, CELL_TYPES), data as FIELD arrays.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_io.hpp"

namespace foxi {

FOXI_API Mesh read_vtu(const std::filesystem::path& path);
FOXI_API Mesh parse_vtu(std::string_view bytes, const std::string& name);
FOXI_API void write_vtu(const Mesh& mesh, const std::filesystem::path& path,
                        VtuEncoding encoding = VtuEncoding::appended_raw);

FOXI_API Mesh read_vtk_legacy(const std::filesystem::path& path);
FOXI_API Mesh parse_vtk_legacy(std::string_view bytes, const std::string& name);
FOXI_API void write_vtk_legacy(const Mesh& mesh, const std::filesystem::path& path, bool binary = true);

}  // namespace foxi
