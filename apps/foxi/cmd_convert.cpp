// foxi convert IN OUT: between mesh formats, through the common mesh database.
#include <chrono>
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "mesh_input.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/validate.hpp"

namespace foxi::cli {

namespace {

const char* kConvertUsage =
    "foxi convert IN OUT [--ascii | --binary] [--msh-version 2.2|4.1]\n"
    "                    [--vtu-encoding raw|zlib|base64|ascii] [--keep-orientation] [--keep-invalid]\n"
    "  Reads IN and writes OUT, each format chosen from the file extension (.msh .vtu .vtk\n"
    "  .node/.ele/.face .mesh). Regions, boundary tags, vertex weights and fields are carried\n"
    "  where the output format can hold them. Inverted tets are re-oriented (and counted) unless\n"
    "  --keep-orientation. A mesh that validation calls unusable (see foxi info) is refused (exit\n"
    "  status 3) unless --keep-invalid, which converts it as it is, with a warning. OUT is written to a "
    "temporary file and renamed, so a failure leaves\n"
    "  no partial file. Defaults: binary, Gmsh 4.1, appended raw .vtu.";

}  // namespace

int cmd_convert(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kConvertUsage);
    return kExitOk;
  }
  WriteOptions options;
  const bool ascii = args.flag("--ascii");
  const bool binary = args.flag("--binary");
  if (ascii && binary) throw UsageError("--ascii and --binary exclude each other");
  options.binary = !ascii;
  const std::string version = args.option("--msh-version", "4.1");
  if (version == "4.1" || version == "4")
    options.gmsh_version = 41;
  else if (version == "2.2" || version == "2")
    options.gmsh_version = 22;
  else
    throw UsageError("--msh-version takes 2.2 or 4.1, not '" + version + "'");
  const bool encoding_given = args.has_option("--vtu-encoding");
  const std::string encoding = args.option("--vtu-encoding", "raw");
  if (encoding == "raw" || encoding == "appended")
    options.vtu_encoding = VtuEncoding::appended_raw;
  else if (encoding == "zlib")
    options.vtu_encoding = VtuEncoding::zlib;
  else if (encoding == "base64")
    options.vtu_encoding = VtuEncoding::base64;
  else if (encoding == "ascii")
    options.vtu_encoding = VtuEncoding::ascii;
  else
    throw UsageError("--vtu-encoding takes raw, zlib, base64 or ascii, not '" + encoding + "'");
  if (ascii && !encoding_given) options.vtu_encoding = VtuEncoding::ascii;
  const bool keep_orientation = args.flag("--keep-orientation");
  const bool keep_invalid = args.flag("--keep-invalid");
  const auto files = args.positional(2, 2, kConvertUsage);

  // Both formats are checked before any work, so a typo costs nothing.
  const MeshFormat in_format = format_from_path(files[0]);
  const MeshFormat out_format = format_from_path(files[1]);
  check_output_path(files[1]);

  auto t0 = std::chrono::steady_clock::now();
  Mesh mesh = read_mesh(files[0]);
  auto t1 = std::chrono::steady_clock::now();
  ValidationReport report;
  if (keep_invalid) {
    report = keep_orientation ? validate(mesh) : validate_and_repair(mesh);
    if (!report.ok()) {
      std::fprintf(stderr,
                   "foxi convert: warning: %s is not a usable mesh (converted as it is, --keep-invalid):\n",
                   files[0].c_str());
      for (const std::string& m : describe(report)) std::fprintf(stderr, "  %s\n", m.c_str());
      for (const std::string& m : report.messages) std::fprintf(stderr, "  %s\n", m.c_str());
    }
  } else if (keep_orientation) {
    report = validate(mesh);
    if (!report.ok()) require_usable(mesh, files[0], "convert");  // throws: says why
  } else {
    report = require_usable(mesh, files[0], "convert");
  }
  write_mesh(mesh, files[1], options);
  auto t2 = std::chrono::steady_clock::now();
  std::printf(
      "%s (%s) -> %s (%s): %zu nodes, %zu tets, %zu boundary triangles, %zu fields; read %.3f s, "
      "write %.3f s\n",
      files[0].c_str(), format_name(in_format), files[1].c_str(), format_name(out_format), mesh.node_count(),
      mesh.tet_count(), mesh.bface_count(), mesh.fields.size(),
      std::chrono::duration<double>(t1 - t0).count(), std::chrono::duration<double>(t2 - t1).count());
  if (!mesh.fields.empty() && (out_format == MeshFormat::medit || out_format == MeshFormat::tetgen))
    std::printf("warning: the %s format holds no fields: the %zu fields of %s are not in %s\n",
                format_name(out_format), mesh.fields.size(), files[0].c_str(), files[1].c_str());
  if (report.inverted > 0) {
    std::printf("%zu inverted tets %s\n", report.inverted,
                keep_orientation ? "kept as they were (--keep-orientation)" : "re-oriented");
  }
  return kExitOk;
}

}  // namespace foxi::cli
