// foxi probe RESULT --field NAME --at x,y,z: the value of a field at points; foxi plot RESULT --field
// NAME --line A:B: the field along a segment, as CSV or a line chart (PNG). Both locate their points through
// foxi::fields' uniform grid (locate_points) and interpolate with field_value_in_tet, so a probe and a plot
// sample agree with each other and with the field transfer.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <cstdio>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "foxi/fields/transfer.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/viz/chart.hpp"
#include "foxi/viz/field_paint.hpp"
#include "foxi/viz/png.hpp"
#include "foxi/viz/text.hpp"
#include "mesh_input.hpp"
#include "render_options.hpp"

namespace foxi::cli {

namespace {

const char* kProbeUsage =
    "foxi probe RESULT --field NAME[:COMPONENT] --at x,y,z [--at x,y,z ...] [--step k]\n"
    "  For each point (metres, as the mesh): the tet that holds it (its index from 0, as foxi solve\n"
    "  and ParaView number tets), its region (id and name) and the field's value there: a node field\n"
    "  interpolated linearly (barycentric) in that tet, a cell field the tet's value; in SI and in the\n"
    "  field's usual display unit (°C for K, MPa for Pa, ...).\n"
    "  A point on a face shared by two tets takes one of them (the value is the same for a node field).\n"
    "  COMPONENT as foxi render --field: an index, x y z, mag, xx .. xz, vm, p1 p2 p3.\n"
    "  --step k  the field's step k (0-based; default the last)\n"
    "  A point in no tet is reported as outside the mesh.\n"
    "  Exit status: 0 at least one point lies in the mesh, 2 usage error (also an unknown field or\n"
    "  component), 3 unreadable or unusable file, or no point in the mesh.";

const char* kPlotUsage =
    "foxi plot RESULT --field NAME[:COMPONENT] --line x0,y0,z0:x1,y1,z1 [--samples N] [--step k]\n"
    "          [--size WxH] -o PLOT.csv|PLOT.png\n"
    "  The field along the segment at N equally spaced samples (default 101, ends included), each\n"
    "  located and interpolated as foxi probe does. CSV columns: s (distance from the start, m),\n"
    "  x, y, z (m), tet (index from 0; empty outside), region, and the value in SI (its unit in the\n"
    "  header); a sample outside the mesh has an empty tet and region and the value nan (a gap).\n"
    "  PNG: a line chart of the value (display units, as foxi render's legend) against the distance\n"
    "  along the segment, with axes, ticks and units; samples outside the mesh break the line.\n"
    "  --size WxH  the PNG's size in pixels (default 800x500)\n"
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
    if (*end != 0 || step < 0)
      throw UsageError("--step takes a step number 0, 1, ..., not '" + step_text + "'");
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

// The chart of foxi plot: the value in its display unit against the distance along the segment (mm
// below a metre, else m); NaN values (outside the mesh) break the line.
Framebuffer line_chart(const TextRenderer& text, const Selection& sel, const Field& f,
                       const std::vector<double>& a, const std::vector<double>& b,
                       const std::vector<double>& along, const std::vector<double>& value, int width,
                       int height) {
  double max_abs = 0;
  for (double v : value)
    if (std::isfinite(v)) max_abs = std::max(max_abs, std::abs(v));
  const DisplayUnit u = default_display_unit(f.unit, max_abs);
  const bool mm = along.back() < 1;
  Chart chart;
  char title[256];
  std::snprintf(title, sizeof title, "%s from (%g, %g, %g) to (%g, %g, %g)", sel.choice.label.c_str(), a[0],
                a[1], a[2], b[0], b[1], b[2]);
  chart.title = title;
  chart.x.label = "distance along the line";
  chart.x.unit = mm ? "mm" : "m";
  chart.y.label = sel.choice.label;
  chart.y.unit = u.symbol;
  ChartSeries series;
  for (std::size_t i = 0; i < along.size(); ++i) {
    series.x.push_back(mm ? along[i] * 1e3 : along[i]);
    series.y.push_back(std::isnan(value[i]) ? value[i] : u.to_display(value[i]));
  }
  chart.series.push_back(std::move(series));
  Framebuffer fb(width, height);
  try {
    draw_chart(fb, text, chart, PixelRect{0, 0, width - 1, height - 1});
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("cannot draw the chart: ") + e.what() + " (a larger --size?)");
  }
  return fb;
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
  auto ends_with = [&](const char* ext) {
    return out.size() > 4 && out.compare(out.size() - 4, 4, ext) == 0;
  };
  const bool png = ends_with(".png");
  if (!png && !ends_with(".csv")) throw UsageError("-o takes a .csv or .png file, not '" + out + "'");
  const std::string size_text = args.option("--size");
  if (!size_text.empty() && !png) throw UsageError("--size is for a PNG chart (-o PLOT.png)");
  int width = 800, height = 500;
  if (!size_text.empty()) parse_size(size_text, width, height);
  const std::string step_text = args.option("--step");
  const std::string path = args.positional(1, 1, kPlotUsage)[0];
  check_output_path(out);
  std::unique_ptr<TextRenderer> font;
  if (png) font = std::make_unique<TextRenderer>(find_font_file());  // a missing font fails before the work

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
  std::string csv = "s [m],x [m],y [m],z [m],tet,region," + label + "\n";
  std::size_t inside = 0;
  std::vector<double> along(n), value(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = loc.tet[i];
    along[i] = length * double(i) / double(n - 1);
    csv += number(along[i]);
    for (int k = 0; k < 3; ++k) csv += "," + number(xyz[3 * i + k]);
    if (t == kNone) {
      csv += ",,,nan\n";
      continue;
    }
    ++inside;
    value[i] = field_value_in_tet(mesh, sel.choice, t, &loc.bary[4 * i], sel.step);
    csv += "," + std::to_string(t) + "," + std::to_string(mesh.region_of(t)) + "," + number(value[i]) + "\n";
  }
  if (inside == 0) {
    std::fprintf(stderr, "foxi plot: error: no sample of the line lies in the mesh of %s; nothing written\n",
                 path.c_str());
    return kExitBadInput;
  }
  if (png) {
    write_png(out, line_chart(*font, sel, f, a, b, along, value, width, height));
  } else {
    DurableFile file(out);
    file.write(csv);
    file.commit();
  }
  std::fprintf(stderr, "foxi plot: %zu samples over %.6g m, %zu in the mesh, %zu outside; wrote %s\n", n,
               length, inside, n - inside, out.c_str());
  return kExitOk;
}

}  // namespace foxi::cli
