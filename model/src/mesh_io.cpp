#include "foxi/model/mesh_io.hpp"

#include "foxi/model/io_error.hpp"
#include "foxi/model/io_gmsh.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/io_vtk.hpp"

namespace foxi {

MeshFormat format_from_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".msh") return MeshFormat::gmsh;
  if (ext == ".vtu") return MeshFormat::vtu;
  if (ext == ".vtk") return MeshFormat::vtk_legacy;
  if (ext == ".node" || ext == ".ele" || ext == ".face") return MeshFormat::tetgen;
  if (ext == ".mesh") return MeshFormat::medit;
  // TetGen base names such as box.1 have a numeric "extension": look for the .node file.
  std::filesystem::path node = path;
  node += ".node";
  std::error_code ec;
  if (std::filesystem::exists(node, ec)) return MeshFormat::tetgen;
  throw IoError(path.string(), 0, IoError::kNoOffset,
                "unknown mesh format '" + ext + "' (known: .msh .vtu .vtk .node/.ele/.face .mesh)");
}

const char* format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::gmsh:
      return "Gmsh .msh";
    case MeshFormat::vtu:
      return "VTK XML .vtu";
    case MeshFormat::vtk_legacy:
      return "VTK legacy .vtk";
    case MeshFormat::tetgen:
      return "TetGen .node/.ele";
    case MeshFormat::medit:
      return "Medit .mesh";
  }
  return "?";
}

static std::filesystem::path tetgen_base(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  if (ext == ".node" || ext == ".ele" || ext == ".face") {
    std::filesystem::path base = path;
    base.replace_extension();
    return base;
  }
  return path;
}

Mesh read_mesh(const std::filesystem::path& path) {
  switch (format_from_path(path)) {
    case MeshFormat::gmsh:
      return read_gmsh(path);
    case MeshFormat::vtu:
      return read_vtu(path);
    case MeshFormat::vtk_legacy:
      return read_vtk_legacy(path);
    case MeshFormat::tetgen:
      return read_tetgen(tetgen_base(path));
    case MeshFormat::medit:
      return read_medit(path);
  }
  throw IoError(path.string(), 0, IoError::kNoOffset, "unknown mesh format");
}

void write_mesh(const Mesh& mesh, const std::filesystem::path& path, const WriteOptions& options) {
  switch (format_from_path(path)) {
    case MeshFormat::gmsh:
      write_gmsh(mesh, path, GmshWriteOptions{options.gmsh_version, options.binary});
      return;
    case MeshFormat::vtu:
      write_vtu(mesh, path, options.vtu_encoding);
      return;
    case MeshFormat::vtk_legacy:
      write_vtk_legacy(mesh, path, options.binary);
      return;
    case MeshFormat::tetgen:
      write_tetgen(mesh, tetgen_base(path));
      return;
    case MeshFormat::medit:
      write_medit(mesh, path);
      return;
  }
}

}  // namespace foxi
