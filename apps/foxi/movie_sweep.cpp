#include "movie_sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "foxi/viz/picture.hpp"

namespace foxi::cli {

namespace {

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

Sweep parse_sweep(const std::string& text) {
  Sweep s;
  if (text.empty()) return s;
  if (text == "steps") {
    s.kind = Sweep::Kind::steps;
    return s;
  }
  const std::size_t colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  if (colon == std::string::npos || (kind != "iso" && kind != "threshold"))
    throw UsageError("--sweep takes iso:a,b, threshold:a,b or steps, not '" + text + "'");
  s.kind = kind == "iso" ? Sweep::Kind::iso : Sweep::Kind::threshold;
  const std::vector<double> v = parse_numbers(text.substr(colon + 1), "--sweep");
  if (v.size() != 2 || v[0] == v[1])
    throw UsageError("--sweep " + kind + ":a,b takes two different values, not '" + text + "'");
  if (s.kind == Sweep::Kind::threshold && !(v[0] < v[1]))
    throw UsageError("--sweep threshold:a,b grows the range [a, v] from v = a to b: a < b, not '" + text +
                     "'");
  s.a = v[0];
  s.b = v[1];
  return s;
}

void check_sweep_options(const Sweep& sweep, const FieldOptions& field, const IsoOptions& iso) {
  using K = Sweep::Kind;
  if (sweep.kind != K::none && field.spec.empty())
    throw UsageError("--sweep draws a field: give --field NAME");
  if (sweep.kind == K::none && (!iso.iso.empty() || iso.slice))
    throw UsageError(
        "--iso and --slice draw polygons, which the back-and-forth and rotating movies do not: "
        "sweep them with --sweep iso:a,b or --sweep steps");
  if (sweep.kind == K::iso && (!iso.iso.empty() || iso.slice))
    throw UsageError("--sweep iso:a,b gives each frame its isovalue: leave out --iso and --slice");
  if (sweep.kind == K::steps && field.step >= 0)
    throw UsageError("--sweep steps draws every step of the field: leave out --step");
  // A threshold sweep with --slice: the plane's section through each frame's threshold subset.
  if (sweep.kind == K::threshold && iso.has_threshold)
    throw UsageError("--sweep threshold:a,b gives each frame its threshold: leave out --threshold");
}

double sweep_value(const Sweep& sweep, int k, int n) {
  if (k == n - 1) return sweep.b;
  return sweep.a + (sweep.b - sweep.a) * double(k) / double(n - 1);
}

SweepRange fixed_step_range(const FieldOptions& options, const Mesh& mesh,
                            std::span<const std::uint32_t> subset, const std::string& path) {
  FieldOptions o = options;
  o.step = 0;
  SweepRange r;
  const FieldPicture first = resolve_field(o, mesh, subset, path);
  r.steps = first.choice.field->step_count();
  r.lo = first.legend.scale.lo;
  r.hi = first.legend.scale.hi;
  for (std::size_t k = 1; k < r.steps; ++k) {
    o.step = long(k);
    const FieldPicture f = resolve_field(o, mesh, subset, path);
    r.lo = std::min(r.lo, f.legend.scale.lo);
    r.hi = std::max(r.hi, f.legend.scale.hi);
  }
  return r;
}

std::string sweep_caption(const Sweep& sweep, const SweepStats& st, std::size_t k) {
  using K = Sweep::Kind;
  const std::string unit = st.unit.empty() ? "" : " " + st.unit;
  char b[128];
  if (sweep.kind == K::steps) {
    // A field's step values are the times its writer gave (foxi's transient solver: seconds).
    if (st.step_values.size() == st.frames && k < st.step_values.size())
      std::snprintf(b, sizeof b, "t = %.6g s", st.step_values[k]);
    else
      std::snprintf(b, sizeof b, "step %zu of %zu", k + 1, st.frames);
  } else if (sweep.kind == K::iso) {
    std::snprintf(b, sizeof b, "iso %.6g%s", st.values[k], unit.c_str());
  } else {
    std::snprintf(b, sizeof b, "threshold %.6g to %.6g%s", sweep.a, st.values[k], unit.c_str());
  }
  return b;
}

SweepStats run_sweep(
    const SweepInputs& in,
    const std::function<void(const Framebuffer&, const FieldPicture&, const std::string&)>& frame) {
  using K = Sweep::Kind;
  SweepStats st;
  const bool steps = in.sweep.kind == K::steps;
  const int n = steps ? int(in.steps) : in.frames;
  FieldPicture field = in.field;  // its legend's marks change per frame
  st.unit = field.legend.unit.symbol;
  if (steps) st.step_values = field.choice.field->step_values;
  st.frames = std::size_t(n);  // for the captions' "step k of n"
  // One unit for every step (resolve_field picks a step's default from its own values): the fixed range's.
  const DisplayUnit unit = field.legend.unit;
  IsoCache cache;  // one field and step for iso and threshold sweeps: the interval tree built once
  for (int k = 0; k < n; ++k) {
    IsoOptions o = in.iso_options;
    double value = 0;
    if (steps) {
      FieldOptions fo = in.field_options;
      fo.step = k;
      field = resolve_field(fo, in.mesh, in.base, in.path);
      if (fo.units.empty()) field.legend.unit = unit;
      value = double(k);
    } else {
      value = sweep_value(in.sweep, k, n);
      if (in.sweep.kind == K::iso) {
        o.iso = {value};
        o.iso_only = in.iso_only;
      } else {
        o.has_threshold = true;
        o.threshold[0] = in.sweep.a;
        o.threshold[1] = value;
      }
    }
    st.values.push_back(value);
    IsoPicture iso;
    if (o.any()) {
      iso = resolve_iso(o, in.mesh, field, in.base, steps ? nullptr : &cache);
      st.build_ms += iso.build_ms;
      st.query_ms += iso.query_ms;
    }
    field.legend.marks = iso.iso_si;
    st.crossing.push_back(iso.crossing);
    const IsoDrawing drawing = iso.drawing();
    PictureParams pp;
    pp.render = in.render;
    pp.render.field = field.paint;
    pp.subset = o.any() ? std::span<const std::uint32_t>(iso.subset) : in.base;
    pp.subset_exact = o.any();
    if (iso.polygons) pp.iso = &drawing;
    Framebuffer fb(in.width, in.height);
    const auto t0 = std::chrono::steady_clock::now();
    const PictureReport report = draw_picture(in.mesh, in.table, in.camera, fb, pp);
    st.draw_ms += ms_since(t0);
    st.depth_buffer = st.depth_buffer || report.depth_buffer;
    st.drawn.push_back(report.tets_drawn);
    frame(fb, field, sweep_caption(in.sweep, st, std::size_t(k)));
  }
  return st;
}

void print_sweep(const SweepStats& st, const Sweep& sweep, const FieldPicture& field) {
  using K = Sweep::Kind;
  const std::string unit = st.unit.empty() ? "" : " " + st.unit;
  auto list = [&](const char* fmt) {  // every value, or the first and last three of many
    std::string s;
    for (std::size_t i = 0; i < st.values.size(); ++i) {
      if (st.values.size() > 12 && i == 3) {
        s += ", ...";
        i = st.values.size() - 4;
        continue;
      }
      char b[64];
      std::snprintf(b, sizeof b, fmt, st.values[i]);
      s += (i ? ", " : "") + std::string(b);
    }
    return s;
  };
  const auto [dmin, dmax] = std::minmax_element(st.drawn.begin(), st.drawn.end());
  if (sweep.kind == K::iso) {
    const auto [cmin, cmax] = std::minmax_element(st.crossing.begin(), st.crossing.end());
    std::printf("sweep       isovalue of %s, %zu frames: %s%s\n", field.legend.title.c_str(), st.frames,
                list("%.6g").c_str(), unit.c_str());
    std::printf(
        "pruned      %zu to %zu tets crossed a frame, %zu to %zu ordered and drawn; interval tree built "
        "once (%.1f ms), queries %.2f ms in all\n",
        *cmin, *cmax, *dmin, *dmax, st.build_ms, st.query_ms);
  } else if (sweep.kind == K::threshold) {
    char a[64];
    std::snprintf(a, sizeof a, "%.6g", sweep.a);
    std::printf("sweep       threshold [%s, v] of %s, %zu frames, v = %s%s\n", a, field.legend.title.c_str(),
                st.frames, list("%.6g").c_str(), unit.c_str());
    std::printf("selected    %zu to %zu tets a frame\n", *dmin, *dmax);
  } else {
    std::printf("sweep       steps of %s, %zu frames", field.legend.title.c_str(), st.frames);
    if (!st.step_values.empty())
      std::printf(", step values %.6g to %.6g", st.step_values.front(), st.step_values.back());
    std::printf("\n");
  }
  std::printf("drawn       %.1f ms in all%s\n", st.draw_ms,
              st.depth_buffer ? ", in MPVO order with the depth buffer (the mesh is not Delaunay)"
                              : ", by the painter in the power order");
}

}  // namespace foxi::cli
