#include "mesh_input.hpp"

#include <cstdio>
#include <filesystem>

#include "cli.hpp"
#include "foxi/fields/field_source.hpp"
#include "foxi/model/mesh_io.hpp"

namespace foxi::cli {

ValidationReport require_usable(Mesh& mesh, const std::string& name, const char* command) {
  ValidationReport report = validate_and_repair(mesh);
  if (!report.ok()) {
    std::string why = name + " is not a usable mesh:";
    for (const std::string& line : describe(report)) why += "\n  " + line;
    for (const std::string& m : report.messages) why += "\n  " + m;
    throw InputError(why);
  }
  if (report.inverted > 0)
    std::fprintf(stderr, "foxi %s: note: %s: %zu inverted tet%s (negative orientation) re-oriented\n",
                 command, name.c_str(), report.inverted, report.inverted == 1 ? "" : "s");
  return report;
}

Mesh read_usable_mesh(const std::string& path, const char* command) {
  // A ParaView collection (foxi solve --physics transient's output) is one mesh whose fields have a
  // step per data set: read through the field importer, which checks that the sets agree.
  Mesh mesh =
      std::filesystem::path(path).extension() == ".pvd" ? read_field_source(path).mesh : read_mesh(path);
  require_usable(mesh, path, command);
  return mesh;
}

}  // namespace foxi::cli
