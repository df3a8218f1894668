// foxi info MESH: what is in a mesh file, and whether it is fit to use.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/solver/results.hpp"  // json_quoted

namespace foxi::cli {

namespace {

const char* kInfoUsage =
    "foxi info MESH [--json] [--check-delaunay] [--no-quality]\n"
    "  Prints node, tet and boundary-triangle counts, the bounding box, regions (tets, volume),\n"
    "  boundaries, fields, total volume, tet quality (radius-edge ratio, minimum dihedral angle),\n"
    "  face adjacency (boundary and non-manifold faces) and validation problems.\n"
    "  --json            the same as one JSON object on stdout\n"
    "  --check-delaunay  also certify that every tet's circumsphere is empty (exact predicates)\n"
    "  --no-quality      skip the quality statistics\n"
    "  Validation: sizes and indices, non-finite coordinates, flat tets (exact predicate), geometry\n"
    "  beyond the range foxi computes in (volumes, circumspheres, keys), duplicate tets, coincident\n"
    "  nodes, no tets; warnings: inverted tets (every command re-orients them), unused nodes.\n"
    "  Exit status: 0 usable mesh, 2 usage error, 3 unreadable file or unusable mesh.";

struct RegionStats {
  std::size_t tets = 0;
  double volume = 0;
};

double tet_volume(const Mesh& m, std::size_t t) {
  const double* p[4];
  for (int i = 0; i < 4; ++i) p[i] = &m.xyz[3 * std::size_t(m.tet[4 * t + i])];
  double a[3], b[3], c[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = p[1][k] - p[0][k];
    b[k] = p[2][k] - p[0][k];
    c[k] = p[3][k] - p[0][k];
  }
  return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
          a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6.0;
}

const char* location_name(FieldLocation l) { return l == FieldLocation::node ? "node" : "cell"; }

// A field's range for foxi info: its default scalar (the value, a vector's magnitude, a tensor's von
// Mises stress) over all its steps, SI; NaN, NaN when it has none (no finite value, or a component
// count with no default scalar), and how many values are NaN.
struct FieldRange {
  std::string scalar;  // "value", "magnitude", "von Mises"
  double lo = std::nan(""), hi = std::nan("");
  std::size_t nan = 0;
};
FieldRange field_range(const Mesh& mesh, const Field& f) {
  FieldRange r;
  FieldChoice c;
  try {
    c = choose_field(mesh, f.name);
  } catch (const FieldSelectError&) {
    return r;
  }
  // A cell field named as a node field: the name chose the node one (its range was shown for both;
  // an outside probe). This field, with the scalar of its component count.
  if (c.field != &f) {
    if (c.field->components != f.components) return r;
    c.field = &f;
  }
  r.scalar = c.scalar.kind == FieldScalar::Kind::magnitude   ? "magnitude"
             : c.scalar.kind == FieldScalar::Kind::von_mises ? "von Mises"
                                                             : "value";
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t s = 0; s < f.step_count(); ++s)
    for (double v : field_scalar_values(mesh, c, s)) {
      if (std::isnan(v)) {
        ++r.nan;
      } else if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
  if (lo <= hi) {
    r.lo = lo;
    r.hi = hi;
  }
  return r;
}

}  // namespace

int cmd_info(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kInfoUsage);
    return kExitOk;
  }
  const bool json = args.flag("--json");
  const bool check_delaunay = args.flag("--check-delaunay");
  const bool quality = !args.flag("--no-quality");
  const std::string path = args.positional(1, 1, kInfoUsage)[0];

  auto t0 = std::chrono::steady_clock::now();
  const MeshFormat format = format_from_path(path);
  const Mesh mesh = read_mesh(path);
  const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const ValidationReport report = validate(mesh);
  const bool indices_ok = report.size_problem.empty() && report.index_out_of_range == 0;

  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t i = 0; i < mesh.node_count(); ++i)
    for (int k = 0; k < 3; ++k) {
      double v = mesh.xyz[3 * i + k];
      if (std::isfinite(v)) {
        lo[k] = std::min(lo[k], v);
        hi[k] = std::max(hi[k], v);
      }
    }

  std::map<std::int32_t, RegionStats> regions;
  double volume = 0;
  if (indices_ok) {
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      double v = std::abs(tet_volume(mesh, t));
      RegionStats& r = regions[mesh.region_of(t)];
      ++r.tets;
      r.volume += v;
      volume += v;
    }
  }
  for (const Region& r : mesh.regions) regions.try_emplace(r.id);
  std::map<std::int32_t, std::size_t> boundaries;
  for (std::int32_t tag : mesh.bface_tag) ++boundaries[tag];
  for (const Boundary& b : mesh.boundaries) boundaries.try_emplace(b.tag, 0);

  // Quality figures of non-finite or out-of-range geometry would be inf or NaN: not printed.
  const bool quality_ok = indices_ok && report.nonfinite_nodes == 0 && report.out_of_range == 0;
  QualitySummary q;
  if (quality && quality_ok) q = summarize_quality(mesh);
  FaceAdjacency adjacency;
  bool have_adjacency = indices_ok && report.repeated_vertex == 0;
  if (have_adjacency) adjacency = compute_face_adjacency(mesh);
  DelaunayCertificate cert;
  bool have_cert = check_delaunay && report.ok();
  if (have_cert) cert = compute_delaunay_certificate(mesh);

  // By id through maps: Mesh::find_region is a linear search, and 74k regions took 7 s (an outside
  // probe's mesh of one region per tet).
  std::unordered_map<std::int32_t, const Region*> region_by_id;
  for (const Region& r : mesh.regions) region_by_id.try_emplace(r.id, &r);
  std::unordered_map<std::int32_t, const Boundary*> boundary_by_tag;
  for (const Boundary& b : mesh.boundaries) boundary_by_tag.try_emplace(b.tag, &b);
  auto find_region = [&](std::int32_t id) -> const Region* {
    const auto it = region_by_id.find(id);
    return it == region_by_id.end() ? nullptr : it->second;
  };
  auto region_name = [&](std::int32_t id) {
    const Region* r = find_region(id);
    return r ? r->name : std::string();
  };
  auto material_name = [&](std::int32_t id) {
    const Region* r = find_region(id);
    return r && r->material != kNone ? mesh.materials[r->material].name : std::string();
  };
  auto boundary_name = [&](std::int32_t tag) {
    const auto it = boundary_by_tag.find(tag);
    return it == boundary_by_tag.end() ? std::string() : it->second->name;
  };

  if (json) {
    std::string o = "{\n";
    o += "  \"file\": " + json_quoted(path) + ",\n";
    o += "  \"format\": " + json_quoted(format_name(format)) + ",\n";
    o += "  \"read_seconds\": " + json_number(read_s) + ",\n";
    o += "  \"nodes\": " + std::to_string(mesh.node_count()) + ",\n";
    o += "  \"tets\": " + std::to_string(mesh.tet_count()) + ",\n";
    o += "  \"boundary_triangles\": " + std::to_string(mesh.bface_count()) + ",\n";
    o += "  \"weighted\": " + std::string(mesh.weight.empty() ? "false" : "true") + ",\n";
    o += "  \"bounding_box\": {\"min\": [" + json_number(lo[0]) + ", " + json_number(lo[1]) + ", " +
         json_number(lo[2]) + "], \"max\": [" + json_number(hi[0]) + ", " + json_number(hi[1]) + ", " +
         json_number(hi[2]) + "]},\n";
    o += "  \"volume\": " + json_number(volume) + ",\n";
    o += "  \"regions\": [";
    bool first = true;
    for (auto& [id, s] : regions) {
      o += first ? "\n" : ",\n";
      first = false;
      o += "    {\"id\": " + std::to_string(id) + ", \"name\": " + json_quoted(region_name(id)) +
           ", \"material\": " + json_quoted(material_name(id)) + ", \"tets\": " + std::to_string(s.tets) +
           ", \"volume\": " + json_number(s.volume) + "}";
    }
    o += first ? "],\n" : "\n  ],\n";
    o += "  \"boundaries\": [";
    first = true;
    for (auto& [tag, n] : boundaries) {
      o += first ? "\n" : ",\n";
      first = false;
      o += "    {\"tag\": " + std::to_string(tag) + ", \"name\": " + json_quoted(boundary_name(tag)) +
           ", \"triangles\": " + std::to_string(n) + "}";
    }
    o += first ? "],\n" : "\n  ],\n";
    o += "  \"fields\": [";
    first = true;
    for (const Field& f : mesh.fields) {
      o += first ? "\n" : ",\n";
      first = false;
      const FieldRange range = field_range(mesh, f);
      o += "    {\"name\": " + json_quoted(f.name) +
           ", \"location\": " + json_quoted(location_name(f.location)) +
           ", \"components\": " + std::to_string(f.components) +
           ", \"steps\": " + std::to_string(f.step_count()) + ", \"unit\": " + json_quoted(f.unit) +
           ", \"scalar\": " + json_quoted(range.scalar) + ", \"min\": " + json_number(range.lo) +
           ", \"max\": " + json_number(range.hi) + ", \"nan_values\": " + std::to_string(range.nan) + "}";
    }
    o += first ? "],\n" : "\n  ],\n";
    if (quality && quality_ok) {
      auto stat = [](const Stat& s) {
        return "{\"min\": " + json_number(s.min) + ", \"mean\": " + json_number(s.mean) +
               ", \"max\": " + json_number(s.max) + "}";
      };
      o += "  \"quality\": {\"radius_edge\": " + stat(q.radius_edge) +
           ", \"min_dihedral_deg\": " + stat(q.min_dihedral_deg) + ", \"volume\": " + stat(q.volume) +
           ", \"slivers\": " + std::to_string(q.slivers) + "},\n";
    }
    if (have_adjacency) {
      o += "  \"faces\": {\"interior\": " + std::to_string(adjacency.interior_faces) +
           ", \"boundary\": " + std::to_string(adjacency.boundary_faces) +
           ", \"nonmanifold\": " + std::to_string(adjacency.nonmanifold_faces) + "},\n";
    }
    if (have_cert) {
      o += "  \"delaunay\": {\"delaunay\": " + std::string(cert.delaunay ? "true" : "false") +
           ", \"weighted\": " + std::string(cert.weighted ? "true" : "false") +
           ", \"violating_tets\": " + std::to_string(cert.violating_tet_count) +
           ", \"degenerate_tets\": " + std::to_string(cert.degenerate_tet_count) +
           ", \"max_relative_depth\": " + json_number(cert.max_relative_depth) + "},\n";
    }
    o += "  \"validation\": {\"ok\": " + std::string(report.ok() ? "true" : "false") +
         ", \"size_problem\": " + json_quoted(report.size_problem) +
         ", \"index_out_of_range\": " + std::to_string(report.index_out_of_range) +
         ", \"repeated_vertex\": " + std::to_string(report.repeated_vertex) +
         ", \"nonfinite_nodes\": " + std::to_string(report.nonfinite_nodes) +
         ", \"zero_volume\": " + std::to_string(report.zero_volume) +
         ", \"inverted\": " + std::to_string(report.inverted) +
         ", \"out_of_range\": " + std::to_string(report.out_of_range) +
         ", \"duplicate_tets\": " + std::to_string(report.duplicate_tets) +
         ", \"duplicate_nodes\": " + std::to_string(report.duplicate_nodes) +
         ", \"overlapping\": " + std::to_string(report.overlapping) +
         ", \"no_tets\": " + std::string(report.no_tets ? "true" : "false") +
         ", \"unused_nodes\": " + std::to_string(report.unused_nodes) + ", \"messages\": [";
    for (std::size_t i = 0; i < report.messages.size(); ++i)
      o += (i ? ", " : "") + json_quoted(report.messages[i]);
    o += "]}\n}\n";
    std::fputs(o.c_str(), stdout);
    return report.ok() ? kExitOk : kExitBadInput;
  }

  std::printf("file                %s (%s, read in %.3f s)\n", path.c_str(), format_name(format), read_s);
  std::printf("nodes               %zu%s\n", mesh.node_count(), mesh.weight.empty() ? "" : " (weighted)");
  std::printf("tets                %zu\n", mesh.tet_count());
  std::printf("boundary triangles  %zu\n", mesh.bface_count());
  if (mesh.node_count() > 0)
    std::printf("bounding box        [%g, %g, %g] .. [%g, %g, %g]\n", lo[0], lo[1], lo[2], hi[0], hi[1],
                hi[2]);
  std::printf("volume              %.10g\n", volume);
  std::printf("regions             %zu\n", regions.size());
  for (auto& [id, s] : regions) {
    std::string name = region_name(id), mat = material_name(id);
    std::printf("  %6d  %-20s %-14s %10zu tets  volume %.6g\n", id, name.empty() ? "-" : name.c_str(),
                mat.empty() ? "-" : mat.c_str(), s.tets, s.volume);
  }
  std::printf("boundaries          %zu\n", boundaries.size());
  for (auto& [tag, n] : boundaries) {
    std::string name = boundary_name(tag);
    std::printf("  %6d  %-20s %10zu triangles\n", tag, name.empty() ? "-" : name.c_str(), n);
  }
  std::printf("fields              %zu\n", mesh.fields.size());
  for (const Field& f : mesh.fields) {
    std::printf("  %-24s %s, %u component%s, %zu step%s%s%s\n", f.name.c_str(), location_name(f.location),
                f.components, f.components == 1 ? "" : "s", f.step_count(), f.step_count() == 1 ? "" : "s",
                f.unit.empty() ? "" : ", ", f.unit.c_str());
    const FieldRange r = field_range(mesh, f);
    if (r.scalar.empty()) continue;
    if (std::isnan(r.lo)) {
      std::printf("  %-24s %s: no finite value\n", "", r.scalar.c_str());
      continue;
    }
    // SI, and in the unit an engineer reads it in when that differs (°C for K, MPa for Pa, ...).
    const DisplayUnit u = default_display_unit(f.unit, std::max(std::abs(r.lo), std::abs(r.hi)));
    std::printf("  %-24s %s %.6g to %.6g%s%s", "", r.scalar.c_str(), r.lo, r.hi, f.unit.empty() ? "" : " ",
                f.unit.c_str());
    if (u.symbol != f.unit)
      std::printf(" (%.6g to %.6g %s)", u.to_display(r.lo), u.to_display(r.hi), u.symbol.c_str());
    if (f.step_count() > 1) std::printf(" over all steps");
    if (r.nan > 0) std::printf(", %zu values NaN", r.nan);
    std::printf("\n");
  }
  if (quality && quality_ok && mesh.tet_count() > 0) {
    std::printf("radius-edge ratio   min %.4g  mean %.4g  max %.4g\n", q.radius_edge.min, q.radius_edge.mean,
                q.radius_edge.max);
    std::printf("min dihedral (deg)  min %.4g  mean %.4g  max %.4g  (%zu slivers below 5 deg)\n",
                q.min_dihedral_deg.min, q.min_dihedral_deg.mean, q.min_dihedral_deg.max, q.slivers);
  }
  if (have_adjacency)
    std::printf("faces               %zu interior, %zu boundary, %zu non-manifold\n",
                adjacency.interior_faces, adjacency.boundary_faces, adjacency.nonmanifold_faces);
  if (have_cert) {
    if (cert.delaunay)
      std::printf("delaunay            yes: every %s is empty (%zu tets, exact predicates)\n",
                  cert.weighted ? "orthosphere" : "circumsphere", cert.tets_checked);
    else
      std::printf(
          "delaunay            NO: %zu of %zu tets have a vertex inside their %s (deepest %.3g of the "
          "radius), %zu degenerate\n",
          cert.violating_tet_count, cert.tets_checked, cert.weighted ? "orthosphere" : "circumsphere",
          cert.max_relative_depth, cert.degenerate_tet_count);
  } else if (check_delaunay) {
    std::printf("delaunay            not checked: the mesh is invalid\n");
  }
  if (report.clean()) {
    std::printf("validation          ok\n");
  } else {
    std::printf("validation          %s\n", report.ok() ? "usable, with warnings" : "INVALID");
    for (const std::string& line : describe(report)) std::printf("  %s\n", line.c_str());
    for (const std::string& m : report.messages) std::printf("  %s\n", m.c_str());
  }
  return report.ok() ? kExitOk : kExitBadInput;
}

}  // namespace foxi::cli
