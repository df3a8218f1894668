// Field sources by extension; the .pvd collection reader.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <vector>
#include <cmath>
#include <string>

#include <pugixml.hpp>

#include "foxi/fields/field_source.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh_io.hpp"
#include "io_util.hpp"

namespace foxi {

namespace {

std::string extension(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

FieldSource mesh_source(const std::filesystem::path& path, Mesh mesh, const char* format) {
  FieldSource s;
  s.path = path.string();
  s.format = format;
  s.key = SourceKey::position;
  s.mesh = std::move(mesh);
  return s;
}

}  // namespace

FieldSource read_pvd_source(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string bytes = io::read_file(path);
  pugi::xml_document doc;
  const pugi::xml_parse_result ok = doc.load_buffer(bytes.data(), bytes.size());
  if (!ok)
    io::fail_text(name, bytes, static_cast<std::size_t>(std::max<std::ptrdiff_t>(ok.offset, 0)),
                  std::string("not XML: ") + ok.description());
  const pugi::xml_node root = doc.child("VTKFile");
  if (!root || std::string(root.attribute("type").as_string()) != "Collection")
    throw IoError(name, 0, IoError::kNoOffset, "not a ParaView collection (<VTKFile type=\"Collection\">)");
  FieldSource src = mesh_source(path, Mesh{}, "pvd");
  // The data sets in the order of their timesteps, as ParaView reads them (a collection may list them
  // in another order; an outside probe's steps came out in file order), equal ones in file order.
  struct DataSet {
    std::string file;
    double t = 0;
    std::size_t line = 0;
  };
  std::vector<DataSet> list;
  for (const pugi::xml_node ds : root.child("Collection").children("DataSet")) {
    const std::size_t line = io::line_of(bytes, static_cast<std::size_t>(ds.offset_debug()));
    auto fail = [&](const std::string& why) { throw IoError(name, line, IoError::kNoOffset, why); };
    const std::string file = ds.attribute("file").as_string();
    if (file.empty()) fail("a DataSet without its file attribute");
    if (ds.attribute("part") && ds.attribute("part").as_int() != 0)
      fail("a collection of several parts per step: only one part (part=\"0\") is read");
    const std::string ts = ds.attribute("timestep").as_string();
    double t = static_cast<double>(list.size());
    if (!ts.empty()) {
      auto [p, ec] = std::from_chars(ts.data(), ts.data() + ts.size(), t);
      if (ec != std::errc() || p != ts.data() + ts.size() || !std::isfinite(t))
        fail("timestep '" + ts + "' is not a number");
    }
    list.push_back({file, t, line});
  }
  std::stable_sort(list.begin(), list.end(), [](const DataSet& a, const DataSet& b) { return a.t < b.t; });
  std::size_t sets = 0;
  for (const DataSet& ds : list) {
    auto fail = [&](const std::string& why) { throw IoError(name, ds.line, IoError::kNoOffset, why); };
    const std::string& file = ds.file;
    const double t = ds.t;
    const std::filesystem::path fp =
        std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : path.parent_path() / file;
    Mesh m = read_mesh(fp);  // an IoError names that file
    if (sets == 0) {
      src.mesh = std::move(m);
      for (Field& f : src.mesh.fields)
        if (f.step_count() == 1) f.step_values = {t};
    } else {
      if (m.node_count() != src.mesh.node_count() || m.tet != src.mesh.tet || m.xyz != src.mesh.xyz)
        fail(fp.string() +
             " has other nodes or tets than the first data set: a series over one mesh is read");
      for (Field& f : src.mesh.fields) {
        const Field* g = m.find_field(f.name);
        if (!g) fail(fp.string() + " lacks the field " + f.name + " of the first data set");
        if (g->location != f.location || g->components != f.components)
          fail(fp.string() + ": field " + f.name +
               " has another location or component count than in the first data set");
        if (g->step_count() == 1) {
          f.step_values.push_back(t);
        } else {
          f.step_values.insert(f.step_values.end(), g->step_values.begin(), g->step_values.end());
        }
        f.values.insert(f.values.end(), g->values.begin(), g->values.end());
      }
    }
    ++sets;
  }
  if (sets == 0) throw IoError(name, 0, IoError::kNoOffset, "a collection without data sets");
  return src;
}

FieldSource read_field_source(const std::filesystem::path& path) {
  const std::string e = extension(path);
  if (e == ".frd") return read_frd_source(path);
  if (e == ".csv" || e == ".tsv" || e == ".txt") return read_csv_source(path);
  if (e == ".pvd") return read_pvd_source(path);
  const MeshFormat format = format_from_path(path);  // IoError for an unknown extension
  const char* name = format == MeshFormat::vtu          ? "vtu"
                     : format == MeshFormat::vtk_legacy ? "vtk"
                     : format == MeshFormat::gmsh       ? "msh"
                                                        : format_name(format);
  return mesh_source(path, read_mesh(path), name);
}

}  // namespace foxi
