// Reading and writing meshes, the format chosen from the file name.
//
//   .msh                 Gmsh 2.2 or 4.1, ASCII or binary (read: detected; write: options)
//   .vtu                 VTK XML unstructured grid (ASCII, base64, appended raw, zlib-compressed)
//   .vtk                 VTK legacy unstructured grid (ASCII or binary)
//   .node / .ele / .face TetGen (name any of the three or the base name with no extension)
//   .mesh                Medit (ASCII)
//
// Readers throw IoError (file, line or byte offset, reason) on any malformed input and check every
// declared size against the file's length before allocating. Writers write to a temporary file in
// the same folder and rename it into place, so a failed write leaves nothing behind.
#pragma once

#include <filesystem>
#include <string>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"

namespace foxi {

enum class MeshFormat { gmsh, vtu, vtk_legacy, tetgen, medit };

enum class VtuEncoding { ascii, base64, appended_raw, zlib };

struct WriteOptions {
  bool binary = true;     // .msh and legacy .vtk
  int gmsh_version = 41;  // 22 or 41
  VtuEncoding vtu_encoding = VtuEncoding::appended_raw;
};

// The format of a path from its extension; throws IoError for an unknown one.
FOXI_API MeshFormat format_from_path(const std::filesystem::path& path);
FOXI_API const char* format_name(MeshFormat format);

FOXI_API Mesh read_mesh(const std::filesystem::path& path);
FOXI_API void write_mesh(const Mesh& mesh, const std::filesystem::path& path,
                         const WriteOptions& options = {});

}  // namespace foxi
