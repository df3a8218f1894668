// foxi fields list FILE | foxi fields import MESH FILE: fields from other programs' files (VTK,
// ParaView series, Gmsh, CalculiX .frd, CSV) listed, or carried onto a foxi mesh (foxi::fields).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/fields.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "mesh_input.hpp"

namespace foxi::cli {

namespace {

const char* kFieldsUsage =
    "foxi fields list FILE\n"
    "foxi fields import MESH FILE [--by id|location] [--field NAME]... [--outside nan|nearest]\n"
    "                   [--no-regions] [--tolerance REL] -o OUT\n"
    "  FILE: .vtu .vtk (point and cell data), .pvd (a ParaView series of .vtu files, one step each),\n"
    "  .msh ($NodeData/$ElementData, every step), .frd (CalculiX results, ASCII or binary, every block\n"
    "  of every step), .csv (a header row: a key column 'id' (node ids, 1-based), 'cell' (tet ids,\n"
    "  1-based) or 'x','y','z'; then field columns 'NAME', 'NAME [UNIT]', 'NAME:0'.. or 'NAME_x'.. for "
    "vectors).\n"
    "  list: each field's name, location (node/cell), components, steps, unit, value range and NaNs.\n"
    "  import: the fields of FILE (all, or each --field NAME) carried onto MESH, written with MESH's\n"
    "  own fields to OUT (any mesh format; a field of the same name is replaced):\n"
    "    --by id        the same mesh: counts, coordinates (within REL x the bounding-box diagonal,\n"
    "                   --tolerance, default 1e-5) and tets checked; ids of .frd/.csv 1-based\n"
    "    --by location  another mesh of the same domain: each node located in FILE's tets and\n"
    "                   interpolated linearly, cell values taken at the tet centroid; inside the same\n"
    "                   region where both meshes have regions (--no-regions: ignore them)\n"
    "    (default: id when FILE is keyed by ids, or has MESH's node and tet counts and proves to be\n"
    "    the same mesh; else location)\n"
    "    --outside      what a point in no source tet gets: nan (default, drawn in the 'no value'\n"
    "                   colour) or nearest (the nearest source node's or centroid's value)\n"
    "  Counts of points outside, nodes without a value and NaN values are printed. OUT is written\n"
    "  whole or not at all. Exit status: 0 ok, 2 usage, 3 unreadable or mismatched input.";

const char* location_name(FieldLocation l) { return l == FieldLocation::node ? "node" : "cell"; }

const char* key_name(SourceKey k) {
  switch (k) {
    case SourceKey::position:
      return "its own mesh";
    case SourceKey::node_id:
      return "node ids";
    case SourceKey::cell_id:
      return "tet ids";
    case SourceKey::coordinates:
      return "coordinates";
  }
  return "?";
}

int fields_list(Args& args) {
  const auto files = args.positional(1, 1, kFieldsUsage);
  const FieldSource src = read_field_source(files[0]);
  std::printf("%s (%s, keyed by %s): %zu nodes, %zu tets, %zu fields\n", files[0].c_str(), src.format.c_str(),
              key_name(src.key), src.key == SourceKey::node_id ? src.node_id.size() : src.mesh.node_count(),
              src.mesh.tet_count(), src.mesh.fields.size());
  for (const Field& f : src.mesh.fields) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    std::size_t nan = 0;
    for (double v : f.values) {
      if (std::isnan(v))
        ++nan;
      else if (std::isfinite(v))
        lo = std::min(lo, v), hi = std::max(hi, v);
    }
    std::string steps = std::to_string(f.step_count()) + (f.step_count() == 1 ? " step" : " steps");
    if (f.step_values.size() > 1)
      steps += " (" + json_number(f.step_values.front()) + " .. " + json_number(f.step_values.back()) + ")";
    std::printf("  %-16s %s, %u component%s, %s, unit %s, ", f.name.c_str(), location_name(f.location),
                f.components, f.components == 1 ? "" : "s", steps.c_str(),
                f.unit.empty() ? "-" : f.unit.c_str());
    if (lo <= hi)
      std::printf("values %.6g .. %.6g", lo, hi);
    else
      std::printf("no finite values");
    std::printf(", %zu NaN\n", nan);
  }
  return kExitOk;
}

int fields_import(Args& args) {
  TransferParams params;
  const std::string by = args.option("--by", "");
  if (!by.empty() && by != "id" && by != "location")
    throw UsageError("--by takes id or location, not '" + by + "'");
  const std::string outside = args.option("--outside", "nan");
  if (outside == "nan")
    params.outside = Outside::nan;
  else if (outside == "nearest")
    params.outside = Outside::nearest;
  else
    throw UsageError("--outside takes nan or nearest, not '" + outside + "'");
  if (args.has_option("--tolerance")) {
    const std::vector<double> t = parse_numbers(args.option("--tolerance"), "--tolerance");
    if (t.size() != 1 || !(t[0] >= 0)) throw UsageError("--tolerance takes one number >= 0");
    params.coordinate_tolerance = t[0];
  }
  params.match_regions = !args.flag("--no-regions");
  while (args.has_option("--field")) params.names.push_back(args.option("--field"));
  const std::string out = args.option("-o");
  const auto files = args.positional(2, 2, kFieldsUsage);
  if (out.empty()) throw UsageError("give the output mesh: -o OUT.vtu");
  // an unknown extension fails before any reading, and so does a format that holds no fields (the
  // import was written without them, exit 0; an outside probe)
  const MeshFormat out_format = format_from_path(out);
  if (out_format == MeshFormat::medit || out_format == MeshFormat::tetgen)
    throw UsageError(std::string("the ") + format_name(out_format) +
                     " format holds no fields: write the imported fields to .vtu, .vtk or .msh, not '" + out +
                     "'");
  check_output_path(out);

  const auto t0 = std::chrono::steady_clock::now();
  Mesh mesh = read_usable_mesh(files[0], "fields");
  const FieldSource src = read_field_source(files[1]);
  const auto t1 = std::chrono::steady_clock::now();
  if (by.empty()) {
    const bool same = src.key != SourceKey::position || (src.mesh.node_count() == mesh.node_count() &&
                                                         src.mesh.tet_count() == mesh.tet_count());
    params.by = same ? MatchBy::id : MatchBy::location;
  } else {
    params.by = by == "id" ? MatchBy::id : MatchBy::location;
  }
  TransferReport rep;
  try {
    try {
      rep = transfer_fields(src, mesh, params);
    } catch (const FieldError& e) {
      // The default with equal counts is a guess: another mesh with the same counts (other
      // coordinates or tets) goes by location, and says so.
      if (!by.empty() || src.key != SourceKey::position || params.by != MatchBy::id ||
          src.mesh.tet_count() == 0)
        throw;
      std::fprintf(stderr, "foxi fields: note: not the same mesh (%s): matching by location\n", e.what());
      params.by = MatchBy::location;
      rep = transfer_fields(src, mesh, params);
    }
  } catch (const FieldError& e) {
    throw InputError(e.what());
  }
  const auto t2 = std::chrono::steady_clock::now();
  for (Field& f : rep.fields) {
    bool replaced = false;
    for (Field& g : mesh.fields)
      if (g.name == f.name) {
        g = std::move(f);
        replaced = true;
        break;
      }
    if (!replaced) mesh.fields.push_back(std::move(f));
  }
  write_mesh(mesh, out);
  const auto t3 = std::chrono::steady_clock::now();
  const auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::printf("%s -> %s: %zu field%s by %s onto %s (%zu nodes, %zu tets)\n", files[1].c_str(), out.c_str(),
              rep.fields.size(), rep.fields.size() == 1 ? "" : "s",
              params.by == MatchBy::id ? "id" : "location", files[0].c_str(), rep.target_nodes,
              rep.target_cells);
  if (params.by == MatchBy::location)
    std::printf("  outside the source mesh: %zu nodes, %zu tet centroids (%s)\n", rep.nodes_outside,
                rep.cells_outside, params.outside == Outside::nan ? "NaN" : "nearest value");
  else
    std::printf("  without a source value: %zu nodes, %zu tets (NaN)\n", rep.nodes_missing,
                rep.cells_missing);
  std::printf("  NaN values: %zu; read %.3f s, transfer %.3f s, write %.3f s\n", rep.nan_values, sec(t0, t1),
              sec(t1, t2), sec(t2, t3));
  return kExitOk;
}

}  // namespace

int cmd_fields(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kFieldsUsage);
    return kExitOk;
  }
  const std::vector<std::string>& rest = args.remaining();
  if (rest.empty()) throw UsageError(std::string("missing list or import\n") + kFieldsUsage);
  const std::string sub = rest[0];
  std::vector<std::string> tail(rest.begin() + 1, rest.end());
  Args sub_args(std::move(tail));
  if (sub == "list") return fields_list(sub_args);
  if (sub == "import") return fields_import(sub_args);
  throw UsageError("unknown fields command '" + sub + "' (list or import)\n" + kFieldsUsage);
}

}  // namespace foxi::cli
