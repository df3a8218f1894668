// VTK: XML unstructured grid (.vtu) and legacy (.vtk).
//
// Read: points; cells of type 10 (tetra) become tets, type 5 (triangle) boundary triangles; vertices
// and lines are skipped; other cell types are an error. Cell arrays named "region", "gmsh:physical",
// "CellEntityIds", "medit:ref" or "tetgen:ref" (Int) give tets their region and triangles their
// boundary tag; every other point or cell array becomes a field. A "weight" point array becomes the
// vertex weights. .vtu encodings: ascii, binary (base64, UInt32 or UInt64 headers), appended (raw or
// base64), compressed with vtkZLibDataCompressor. Legacy: ASCII and binary (big-endian).
// Write: region ids as the cell array "region", boundary triangles as triangle cells with tag in the
// same array, fields as point/cell arrays (one array per step, "name" then "name@step").
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_io.hpp"

namespace foxi {

Mesh read_vtu(const std::filesystem::path& path);
Mesh parse_vtu(std::string_view bytes, const std::string& name);
void write_vtu(const Mesh& mesh, const std::filesystem::path& path,
               VtuEncoding encoding = VtuEncoding::appended_raw);

Mesh read_vtk_legacy(const std::filesystem::path& path);
Mesh parse_vtk_legacy(std::string_view bytes, const std::string& name);
void write_vtk_legacy(const Mesh& mesh, const std::filesystem::path& path, bool binary = true);

}  // namespace foxi
