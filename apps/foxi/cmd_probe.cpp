// foxi probe RESULT --field NAME --at x,y,z: the value of a field at points; foxi plot RESULT --field
// NAME --line A:B: the field along a segment, as CSV. Both locate their points through foxi::fields'
// uniform grid (locate_points) and interpolate with field_value_in_tet, so a probe and a plot sample
// agree with each other and with the field transfer.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/fields/transfer.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/viz/field_paint.hpp"
#include "mesh_input.hpp"

namespace foxi::cli {

namespace {

const char* kProbeUsage =
    "foxi probe RESULT --field NAME[:COMPONENT] --at x,y,z [--at x,y,z ...] [--step k]\n"
    "  For each point (metres, as the mesh): the tet that holds it (its index from 0, as foxi solve\n"
    "  and ParaView number tets), its region (id and name) and the\n"
    "  field's value there: a node field interpolated linearly (barycentric) in that tet, a cell\n"
    "  field the tet's value; in SI and in the field's usual display unit (°C for K, MPa for Pa, ...).\n"
    "  A point on a face shared by two tets takes one of them (the value is the same for a node field).\n"
    "  COMPONENT as foxi render --field: an index, x y z, mag, xx .. xz, vm, p1 p2 p3.\n"
    "  --step k  the field's step k (0-based; default the last)\n"
    "  A point in no tet is reported as outside the mesh.\n"
    "  Exit status: 0 at least one point lies in the mesh, 2 usage error (also an unknown field or\n"
    "  component), 3 unreadable or unusable file, or no point in the mesh.";

const char* kPlotUsage =
    "foxi plot RESULT --field NAME[:COMPONENT] --line x0,y0,z0:x1,y1,z1 [--samples N] [--step k]\n"
    "          -o PLOT.csv\n"
    "  The field along the segment at N equally spaced samples (default 101, ends included), each\n"
    "  located and interpolated as foxi probe does. CSV columns: s (distance from the start, m),\n"
    "  x, y, z (m), tet (index from 0; empty outside), region, and the value in SI (its unit in the\n"
    "  header); a sample outside the mesh has an empty tet and region and the value nan (a gap).\n"
    "  Exit status: 0 written, 2 usage error, 3 unreadable or unusable file, or no sample in the mesh.";

std::string number(double v) {
  if (std::isnan(v)) return "nan";
  char b[32];
  std::snprintf(b, sizeof b, "%.15g", v);
  return b;
}

std::vector<double> take_point(const std::string& text, const char* what) {
  std::vector<double> p = parse_numbers(text, what);
  if (p.size() != 3) throw UsageError(std::string(what) + " takes x,y,z (three numbers), not '" + text + "'");
  return p;
}

// The field and step asked for; UsageError naming the file and what it has otherwise.
struct Selection {
  FieldChoice choice;
  std::size_t step = 0;
};
Selection select_field(const Mesh& mesh, const std::string& spec, const std::string& step_text,
                       const std::string& path) {
  Selection s;
  long step = -1;
  if (!step_text.empty()) {
    char* end = nullptr;
    step = std::strtol(step_text.c_str(), &end, 10);
    if (*end != 0 || step < 0) throw UsageError("--step takes a step number 0, 1, ..., not '" + step_text + "'");
  }
  try {
    s.choice = choose_field(mesh, spec);
  } catch (const FieldSelectError& e) {
    throw UsageError(path + ": " + e.what());
  }
  const std::size_t steps = s.choice.field->step_count();
  if (step >= 0 && std::size_t(step) >= steps)
    throw UsageError(path + ": field '" + s.choice.field->name + "' has " + std::to_string(steps) +
                     " step(s): --step takes 0.." + std::to_string(steps - 1));
  s.step = step < 0 ? steps - 1 : std::size_t(step);
  return s;
}

std::string region_text(const Mesh& mesh, std::uint32_t t) {
  const std::int32_t id = mesh.region_of(t);
  const Region* r = mesh.find_region(id);
  return std::to_string(id) + (r && !r->name.empty() ? " (" + r->name + ")" : "");
}

}  // namespace

int cmd_probe(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kProbeUsage);
    return kExitOk;
  }
  const std::string spec = args.option("--field");
  if (spec.empty()) throw UsageError("--field NAME is required\n" + std::string(kProbeUsage));
  std::vector<double> points;
  while (args.has_option("--at")) {
    const std::vector<double> p = take_point(args.option("--at"), "--at");
    points.insert(points.end(), p.begin(), p.end());
  }
  if (points.empty()) throw UsageError("give at least one --at x,y,z\n" + std::string(kProbeUsage));
  const std::string step_text = args.option("--step");
  const std::string path = args.positional(1, 1, kProbeUsage)[0];

  Mesh mesh = read_usable_mesh(path, "probe");
  const Selection sel = select_field(mesh, spec, step_text, path);
  const Field& f = *sel.choice.field;
  const PointLocation loc = locate_points(mesh, points);

  std::size_t inside = 0;
  for (std::size_t i = 0; i < loc.tet.size(); ++i) {
    const double* p = &points[3 * i];
    std::printf("point %s,%s,%s: ", number(p[0]).c_str(), number(p[1]).c_str(), number(p[2]).c_str());
    const std::uint32_t t = loc.tet[i];
    if (t == kNone) {
      std::printf("outside the mesh\n");
      continue;
    }
    ++inside;
    const double v = field_value_in_tet(mesh, sel.choice, t, &loc.bary[4 * i], sel.step);
    std::printf("tet %u, region %s, %s = ", t, region_text(mesh, t).c_str(), sel.choice.label.c_str());
    if (std::isnan(v)) {
      std::printf("no value (NaN)\n");
      continue;
    }
    std::printf("%s%s%s", number(v).c_str(), f.unit.empty() ? "" : " ", f.unit.c_str());
    const DisplayUnit u = default_display_unit(f.unit, std::abs(v));
    if (u.symbol != f.unit) std::printf(" (%.6g %s)", u.to_display(v), u.symbol.c_str());
    std::printf("\n");
  }
  if (inside == 0) {
    std::fprintf(stderr, "foxi probe: error: no point lies in the mesh of %s\n", path.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

int cmd_plot(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kPlotUsage);
    return kExitOk;
  }
  const std::string spec = args.option("--field");
  if (spec.empty()) throw UsageError("--field NAME is required\n" + std::string(kPlotUsage));
  const std::string line = args.option("--line");
  const std::size_t colon = line.find(':');
  if (line.empty() || colon == std::string::npos)
    throw UsageError("--line takes x0,y0,z0:x1,y1,z1, not '" + line + "'");
  const std::vector<double> a = take_point(line.substr(0, colon), "--line's start");
  const std::vector<double> b = take_point(line.substr(colon + 1), "--line's end");
  const std::string samples_text = args.option("--samples", "101");
  char* end = nullptr;
  const long samples = std::strtol(samples_text.c_str(), &end, 10);
  if (*end != 0 || samples < 2 || samples > 10000000)
    throw UsageError("--samples takes a whole number from 2 to 10000000, not '" + samples_text + "'");
  const std::string out = args.option("-o");
  if (out.empty()) throw UsageError("-o PLOT.csv is required\n" + std::string(kPlotUsage));
  if (!(out.size() > 4 && out.compare(out.size() - 4, 4, ".csv") == 0))
    throw UsageError("-o takes a .csv file (a PNG chart is not available yet), not '" + out + "'");
  const std::string step_text = args.option("--step");
  const std::string path = args.positional(1, 1, kPlotUsage)[0];
  check_output_path(out);

  Mesh mesh = read_usable_mesh(path, "plot");
  const Selection sel = select_field(mesh, spec, step_text, path);
  const Field& f = *sel.choice.field;
  const std::size_t n = std::size_t(samples);
  std::vector<double> xyz(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = double(i) / double(n - 1);
    for (int k = 0; k < 3; ++k) xyz[3 * i + k] = i + 1 == n ? b[k] : a[k] + s * (b[k] - a[k]);
  }
  const PointLocation loc = locate_points(mesh, xyz);
  const double length = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);

  // The value column's name, quoted when it has a comma ("displacement, magnitude").
  std::string label = sel.choice.label + (f.unit.empty() ? "" : " [" + f.unit + "]");
  if (label.find_first_of(",\"") != std::string::npos) {
    std::string q = "\"";
    for (char c : label) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    label = q + "\"";
  }
  std::string text = "s [m],x [m],y [m],z [m],tet,region," + label + "\n";
  std::size_t inside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = loc.tet[i];
    text += number(length * double(i) / double(n - 1));
    for (int k = 0; k < 3; ++k) text += "," + number(xyz[3 * i + k]);
    if (t == kNone) {
      text += ",,,nan\n";
      continue;
    }
    ++inside;
    text += "," + std::to_string(t) + "," + std::to_string(mesh.region_of(t)) + "," +
            number(field_value_in_tet(mesh, sel.choice, t, &loc.bary[4 * i], sel.step)) + "\n";
  }
  if (inside == 0) {
    std::fprintf(stderr, "foxi plot: error: no sample of the line lies in the mesh of %s; nothing written\n",
                 path.c_str());
    return kExitBadInput;
  }
  DurableFile file(out);
  file.write(text);
  file.commit();
  std::fprintf(stderr, "foxi plot: %zu samples over %.6g m, %zu in the mesh, %zu outside; wrote %s\n", n, length,
               inside, n - inside, out.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
