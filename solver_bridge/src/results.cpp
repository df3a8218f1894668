// One run's results as a record, its JSON and the convergence table (results.hpp).
#include "foxi/solver/results.hpp"

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace foxi {

const char* run_status_name(RunStatus s) {
  switch (s) {
    case RunStatus::ok:
      return "ok";
    case RunStatus::unreliable:
      return "unreliable";
    case RunStatus::failed:
      return "failed";
  }
  return "failed";
}

const ResultValue* RunResults::find(std::string_view name) const {
  for (const ResultValue& v : values)
    if (v.name == name) return &v;
  return nullptr;
}

std::string region_name(const Mesh& mesh, std::int32_t id) {
  const Region* r = mesh.find_region(id);
  return r && !r->name.empty() ? r->name : std::to_string(id);
}

std::string boundary_name(const Mesh& mesh, std::int32_t tag) {
  const Boundary* b = mesh.find_boundary(tag);
  return b && !b->name.empty() ? b->name : std::to_string(tag);
}

namespace {

struct Values {
  std::vector<ResultValue>& out;
  void key(std::string name, const char* unit, double v) { out.push_back({std::move(name), unit, v, true}); }
  void add(std::string name, const char* unit, double v) { out.push_back({std::move(name), unit, v, false}); }
};

std::string bracket(const std::string& base, const std::string& inside) { return base + "[" + inside + "]"; }

template <class Report>
RunResults common(const Mesh& mesh, const Report& r, const char* physics) {
  RunResults res;
  res.physics = physics;
  res.nodes = mesh.node_count();
  res.tets = mesh.tet_count();
  res.solve_seconds = r.assembly_seconds + r.solve_seconds;
  res.solver = r.solver;
  if constexpr (requires { r.checks; }) {
    res.checks = r.checks;
    res.status = all_passed(r.checks) ? RunStatus::ok : RunStatus::unreliable;
  }
  return res;
}

void solver_values(Values& v, std::size_t unknowns, std::size_t iterations, double relative_residual) {
  v.add("unknowns", "", double(unknowns));
  v.add("iterations", "", double(iterations));
  v.add("relative_residual", "", relative_residual);
}

void matrix_values(Values& v, const char* symbol, const char* unit, const std::vector<ElectrodeResult>& e,
                   const std::vector<std::vector<double>>& m) {
  for (std::size_t i = 0; i < e.size(); ++i)
    for (std::size_t j = 0; j < e.size(); ++j)
      v.key(bracket(symbol, e[i].name + "," + e[j].name), unit, m[i][j]);
}

// The text of one theta side as the CLI takes it: a bare name for the defaults (max= for the junction,
// surface= for the reference), KIND=NAME otherwise.
std::string probe_text(const Mesh& mesh, const ThermalProbe& p, ThermalProbeKind bare) {
  const bool region = p.kind == ThermalProbeKind::region_max || p.kind == ThermalProbeKind::region_mean;
  const std::string name = region ? region_name(mesh, p.id) : boundary_name(mesh, p.id);
  if (p.kind == bare) return name;
  switch (p.kind) {
    case ThermalProbeKind::region_max:
      return "max=" + name;
    case ThermalProbeKind::region_mean:
      return "mean=" + name;
    case ThermalProbeKind::boundary_mean:
      return "surface=" + name;
    case ThermalProbeKind::ambient:
      return "ambient=" + name;
  }
  return name;
}

}  // namespace

RunResults thermal_results(const Mesh& mesh, const ThermalReport& r) {
  RunResults res = common(mesh, r, "thermal");
  Values v{res.values};
  v.key("T_max", "K", r.max_temperature);
  for (const RegionTemperature& t : r.regions) {
    const std::string n = region_name(mesh, t.region);
    v.key(bracket("T_max", n), "K", t.max_temperature);
    v.key(bracket("T_mean", n), "K", t.mean_temperature);
  }
  for (const ThermalResistance& t : r.resistances) {
    const std::string n = probe_text(mesh, t.spec.junction, ThermalProbeKind::region_max) + ":" +
                          probe_text(mesh, t.spec.reference, ThermalProbeKind::boundary_mean);
    v.key(bracket("theta", n), "K/W", t.theta);
    v.add(bracket("theta_path", n), "K/W", t.path_theta);
    v.add(bracket("T_junction", n), "K", t.junction_temperature);
    v.add(bracket("T_reference", n), "K", t.reference_temperature);
    v.add(bracket("dT", n), "K", t.delta_t);
    v.add(bracket("P", n), "W", t.power);
    v.add(bracket("heat_out", n), "W", t.reference_heat_out);
  }
  if (r.max_node != kNone) {
    const double* p = &mesh.xyz[3 * std::size_t{r.max_node}];
    for (const RegionTemperature& t : r.regions)
      if (t.max_temperature == r.max_temperature) {
        res.texts.push_back({"T_max_region", region_name(mesh, t.region)});
        break;
      }
    v.add("T_max_node", "", r.max_node);
    v.add("T_max_x", "m", p[0]);
    v.add("T_max_y", "m", p[1]);
    v.add("T_max_z", "m", p[2]);
  }
  for (const RegionTemperature& t : r.regions) {
    const std::string n = region_name(mesh, t.region);
    v.add(bracket("k", n), "W/(m*K)", t.conductivity);
    v.add(bracket("power", n), "W", t.power);
    v.add(bracket("volume", n), "m^3", t.volume);
  }
  for (const BoundaryHeat& b : r.boundaries) {
    const std::string n = boundary_name(mesh, b.tag);
    v.add(bracket("area", n), "m^2", b.area);
    v.add(bracket("heat_in", n), "W", b.heat_in);
    v.add(bracket("T_surface", n), "K", b.mean_temperature);
    res.texts.push_back({bracket("condition", n), b.kind});
  }
  v.add("power_sources", "W", r.total_power);
  v.add("imbalance", "W", r.imbalance);
  v.add("heat_flow", "W", r.heat_flow);
  v.add("nonzeros", "", double(r.nonzeros));
  solver_values(v, r.unknowns, r.iterations, r.relative_residual);
  return res;
}

RunResults electrostatic_results(const Mesh& mesh, const ElectrostaticReport& r) {
  RunResults res = common(mesh, r, "electrostatic");
  Values v{res.values};
  matrix_values(v, "C", "F", r.conductors, r.capacitance);
  for (const ElectrodeResult& e : r.conductors) {
    v.add(bracket("area", e.name), "m^2", e.area);
    v.add(bracket("V", e.name), "V", e.voltage);
    v.add(bracket("Q", e.name), "C", e.charge);
    std::string metal;
    for (std::int32_t id : e.metal_regions) metal += (metal.empty() ? "" : "+") + region_name(mesh, id);
    if (!metal.empty()) res.texts.push_back({bracket("metal", e.name), metal});
  }
  for (std::size_t i = 0; i < r.floating.size(); ++i) {
    std::string n;
    for (std::int32_t id : r.floating[i].regions) n += (n.empty() ? "" : "+") + region_name(mesh, id);
    v.add(bracket("V_floating", n), "V", r.floating[i].voltage);
    v.add(bracket("nodes_floating", n), "", double(r.floating[i].nodes));
  }
  v.add("energy", "J", r.energy);
  v.add("field_energy", "J", r.field_energy);
  v.add("residual", "", r.residual);
  solver_values(v, r.unknowns, r.iterations, r.relative_residual);
  return res;
}

RunResults current_results(const Mesh& mesh, const CurrentReport& r) {
  RunResults res = common(mesh, r, "current");
  Values v{res.values};
  v.key("R", "ohm", r.resistance);
  matrix_values(v, "G", "S", r.terminals, r.conductance);
  for (const ElectrodeResult& e : r.terminals) {
    v.add(bracket("area", e.name), "m^2", e.area);
    v.add(bracket("V", e.name), "V", e.voltage);
    v.add(bracket("I", e.name), "A", e.charge);
  }
  for (const RegionJoule& j : r.regions) {
    const std::string n = region_name(mesh, j.region);
    v.add(bracket("sigma", n), "S/m", j.conductivity);
    v.add(bracket("volume", n), "m^3", j.volume);
    v.add(bracket("joule_heat", n), "W", j.power);
  }
  v.add("joule_heat", "W", r.total_power);
  v.add("terminal_power", "W", r.terminal_power);
  v.add("residual", "", r.residual);
  solver_values(v, r.unknowns, r.iterations, r.relative_residual);
  return res;
}

RunResults thermoelastic_results(const Mesh& mesh, const ThermoelasticReport& r) {
  RunResults res = common(mesh, r, "thermoelastic");
  Values v{res.values};
  v.key("von_mises_max", "Pa", r.max_von_mises);
  for (const RegionStress& s : r.regions)
    v.key(bracket("von_mises_max", region_name(mesh, s.region)), "Pa", s.max_von_mises);
  v.add("displacement_max", "m", r.max_displacement);
  for (const InterfaceStress& s : r.interfaces)
    v.add(bracket("von_mises_max", region_name(mesh, s.region_a) + "/" + region_name(mesh, s.region_b)), "Pa",
          s.max_von_mises);
  for (const RegionStress& s : r.regions) {
    const std::string n = region_name(mesh, s.region);
    v.add(bracket("E", n), "Pa", s.youngs_modulus);
    v.add(bracket("nu", n), "", s.poisson_ratio);
    v.add(bracket("alpha", n), "1/K", s.thermal_expansion);
  }
  v.add("nonzeros", "", double(r.nonzeros));
  solver_values(v, r.unknowns, r.iterations, r.relative_residual);
  return res;
}

// ---- JSON ----

std::string json_quoted(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

namespace {

// Shortest text that reads back to the same double (std::to_chars); null for NaN and infinities.
std::string jnum(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

const char* jbool(bool b) { return b ? "true" : "false"; }

}  // namespace

std::string results_json(const RunResults& r) {
  std::string o = "{\"foxi_results\": 1,\n";
  o += " \"model\": " + json_quoted(r.model) + ",\n";
  o += " \"physics\": " + json_quoted(r.physics) + ",\n";
  o += " \"parameters\": [";
  for (std::size_t i = 0; i < r.parameters.size(); ++i)
    o += std::string(i ? ", " : "") + "{\"name\": " + json_quoted(r.parameters[i].name) +
         ", \"text\": " + json_quoted(r.parameters[i].text) + "}";
  o += "],\n";
  o += " \"status\": " + json_quoted(run_status_name(r.status)) + ",\n";
  o += " \"error\": " + json_quoted(r.error) + ",\n";
  o += " \"nodes\": " + std::to_string(r.nodes) + ", \"tets\": " + std::to_string(r.tets) + ",\n";
  o += " \"mesh_seconds\": " + jnum(r.mesh_seconds) + ", \"solve_seconds\": " + jnum(r.solve_seconds) +
       ", \"wall_seconds\": " + jnum(r.wall_seconds) + ",\n";
  o += " \"error_indicator\": " + jnum(r.error_indicator) + ",\n";
  o += " \"solver\": " + json_quoted(r.solver) + ",\n";
  o += " \"values\": [";
  for (std::size_t i = 0; i < r.values.size(); ++i) {
    const ResultValue& v = r.values[i];
    o += std::string(i ? ",\n  " : "\n  ") + "{\"name\": " + json_quoted(v.name) +
         ", \"unit\": " + json_quoted(v.unit) + ", \"value\": " + jnum(v.value) +
         ", \"key\": " + jbool(v.key) + "}";
  }
  o += "],\n \"texts\": [";
  for (std::size_t i = 0; i < r.texts.size(); ++i)
    o += std::string(i ? ", " : "") + "{\"name\": " + json_quoted(r.texts[i].name) +
         ", \"text\": " + json_quoted(r.texts[i].text) + "}";
  o += "],\n \"checks\": [";
  for (std::size_t i = 0; i < r.checks.size(); ++i) {
    const BalanceCheck& c = r.checks[i];
    o += std::string(i ? ",\n  " : "\n  ") + "{\"name\": " + json_quoted(c.name) +
         ", \"what\": " + json_quoted(c.what) + ", \"figure\": " + jnum(c.figure) +
         ", \"tolerance\": " + jnum(c.tolerance) + ", \"passed\": " + jbool(c.passed) + "}";
  }
  o += "]}\n";
  return o;
}

namespace {

// A reader for the JSON results_json writes: values are read into the record as the members come;
// unknown members (of any JSON type) are skipped.
class Reader {
 public:
  explicit Reader(std::string_view t) : t_(t) {}

  [[noreturn]] void fail(const char* what) const {
    throw std::runtime_error("results JSON: " + std::string(what) + " at byte " + std::to_string(at_));
  }
  void ws() {
    while (at_ < t_.size() && (t_[at_] == ' ' || t_[at_] == '\n' || t_[at_] == '\r' || t_[at_] == '\t'))
      ++at_;
  }
  bool peek(char c) {
    ws();
    return at_ < t_.size() && t_[at_] == c;
  }
  void expect(char c) {
    if (!peek(c)) fail((std::string("expected '") + c + "'").c_str());
    ++at_;
  }
  bool literal(std::string_view word) {
    ws();
    if (t_.substr(at_, word.size()) != word) return false;
    at_ += word.size();
    return true;
  }
  std::string string() {
    expect('"');
    std::string s;
    while (at_ < t_.size() && t_[at_] != '"') {
      char c = t_[at_++];
      if (c == '\\') {
        if (at_ >= t_.size()) fail("unfinished escape");
        c = t_[at_++];
        switch (c) {
          case 'n':
            s += '\n';
            break;
          case 'r':
            s += '\r';
            break;
          case 't':
            s += '\t';
            break;
          case 'b':
            s += '\b';
            break;
          case 'f':
            s += '\f';
            break;
          case 'u': {
            if (at_ + 4 > t_.size()) fail("short \\u escape");
            unsigned code = 0;
            const auto r = std::from_chars(t_.data() + at_, t_.data() + at_ + 4, code, 16);
            if (r.ptr != t_.data() + at_ + 4) fail("bad \\u escape");
            at_ += 4;
            if (code < 0x80) {
              s += char(code);
            } else if (code < 0x800) {
              s += char(0xC0 | (code >> 6));
              s += char(0x80 | (code & 0x3F));
            } else {
              s += char(0xE0 | (code >> 12));
              s += char(0x80 | ((code >> 6) & 0x3F));
              s += char(0x80 | (code & 0x3F));
            }
            break;
          }
          default:
            s += c;
        }
      } else {
        s += c;
      }
    }
    if (at_ >= t_.size()) fail("unfinished string");
    ++at_;
    return s;
  }
  double number() {
    ws();
    if (literal("null")) return NAN;
    char* end = nullptr;
    const std::string copy(t_.substr(at_, std::min<std::size_t>(64, t_.size() - at_)));
    const double v = std::strtod(copy.c_str(), &end);
    if (end == copy.c_str()) fail("expected a number");
    at_ += std::size_t(end - copy.c_str());
    return v;
  }
  bool boolean() {
    if (literal("true")) return true;
    if (literal("false")) return false;
    fail("expected true or false");
  }
  void skip() {
    ws();
    if (peek('"')) {
      (void)string();
    } else if (peek('{')) {
      object([&](const std::string&) { skip(); });
    } else if (peek('[')) {
      array([&] { skip(); });
    } else if (!literal("true") && !literal("false") && !literal("null")) {
      (void)number();
    }
  }
  template <class F>
  void object(F&& member) {
    expect('{');
    if (peek('}')) {
      ++at_;
      return;
    }
    for (;;) {
      const std::string name = string();
      expect(':');
      member(name);
      if (peek(',')) {
        ++at_;
        continue;
      }
      expect('}');
      return;
    }
  }
  template <class F>
  void array(F&& item) {
    expect('[');
    if (peek(']')) {
      ++at_;
      return;
    }
    for (;;) {
      item();
      if (peek(',')) {
        ++at_;
        continue;
      }
      expect(']');
      return;
    }
  }
  void end() {
    ws();
    if (at_ != t_.size()) fail("text after the object");
  }

 private:
  std::string_view t_;
  std::size_t at_ = 0;
};

}  // namespace

RunResults parse_results_json(std::string_view text) {
  RunResults r;
  Reader in(text);
  bool tagged = false;
  in.object([&](const std::string& m) {
    if (m == "foxi_results") {
      tagged = in.number() == 1;
    } else if (m == "model") {
      r.model = in.string();
    } else if (m == "physics") {
      r.physics = in.string();
    } else if (m == "parameters") {
      in.array([&] {
        RunParameter p;
        in.object([&](const std::string& k) {
          if (k == "name")
            p.name = in.string();
          else if (k == "text")
            p.text = in.string();
          else
            in.skip();
        });
        r.parameters.push_back(p);
      });
    } else if (m == "status") {
      const std::string s = in.string();
      r.status = s == "ok" ? RunStatus::ok : s == "unreliable" ? RunStatus::unreliable : RunStatus::failed;
    } else if (m == "error") {
      r.error = in.string();
    } else if (m == "nodes") {
      r.nodes = std::size_t(in.number());
    } else if (m == "tets") {
      r.tets = std::size_t(in.number());
    } else if (m == "mesh_seconds") {
      r.mesh_seconds = in.number();
    } else if (m == "solve_seconds") {
      r.solve_seconds = in.number();
    } else if (m == "wall_seconds") {
      r.wall_seconds = in.number();
    } else if (m == "error_indicator") {
      r.error_indicator = in.number();
    } else if (m == "solver") {
      r.solver = in.string();
    } else if (m == "values") {
      in.array([&] {
        ResultValue v;
        in.object([&](const std::string& k) {
          if (k == "name")
            v.name = in.string();
          else if (k == "unit")
            v.unit = in.string();
          else if (k == "value")
            v.value = in.number();
          else if (k == "key")
            v.key = in.boolean();
          else
            in.skip();
        });
        r.values.push_back(v);
      });
    } else if (m == "texts") {
      in.array([&] {
        ResultText t;
        in.object([&](const std::string& k) {
          if (k == "name")
            t.name = in.string();
          else if (k == "text")
            t.text = in.string();
          else
            in.skip();
        });
        r.texts.push_back(t);
      });
    } else if (m == "checks") {
      in.array([&] {
        BalanceCheck c;
        in.object([&](const std::string& k) {
          if (k == "name")
            c.name = in.string();
          else if (k == "what")
            c.what = in.string();
          else if (k == "figure")
            c.figure = in.number();
          else if (k == "tolerance")
            c.tolerance = in.number();
          else if (k == "passed")
            c.passed = in.boolean();
          else
            in.skip();
        });
        r.checks.push_back(c);
      });
    } else {
      in.skip();
    }
  });
  in.end();
  if (!tagged)
    throw std::runtime_error("results JSON: no \"foxi_results\": 1 member (not a foxi results file)");
  return r;
}

// ---- convergence ----

double observed_order(double f0, double f1, double f2, double h0, double h1, double h2) {
  const double d1 = f1 - f0, d2 = f2 - f1;
  if (!(d1 != 0) || !(d2 != 0) || (d1 > 0) != (d2 > 0) || !(h0 > h1 && h1 > h2 && h2 > 0)) return NAN;
  const double ratio = d2 / d1;  // in (0, inf)
  // g(p) = (h2^p - h1^p) / (h1^p - h0^p) falls from (log h2 - log h1) / (log h1 - log h0) at p -> 0
  // towards 0 as p grows (the finer step's share shrinks); bisect g(p) = ratio.
  auto g = [&](double p) {
    return (std::pow(h2, p) - std::pow(h1, p)) / (std::pow(h1, p) - std::pow(h0, p));
  };
  double lo = 0.05, hi = 8;
  if (!(ratio <= g(lo) && ratio >= g(hi))) return NAN;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) > ratio ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

// f(h) = f* + C h^p through the levels: three levels exactly (observed_order), more in the least
// squares sense (for each p, f* and C are a linear fit; p minimizes its residual on a grid over
// [0.05, 8], refined; a minimum at either end is no order). Non-nested unstructured meshes scatter
// each level's error, so three levels give a noisy p (0.9 to 3 where the true order is 2 in foxi's
// own test); a fit through four or more levels is much steadier.
void fit_power_law(ConvergenceRow& row, const std::vector<double>& h) {
  const std::vector<double>& f = row.level_values;
  const std::size_t n = f.size();
  for (double v : f)
    if (!std::isfinite(v)) return;
  if (n < 3) return;
  auto linear_fit = [&](double p, double& fstar, double& c) {
    double mx = 0, mf = 0;
    for (std::size_t k = 0; k < n; ++k) mx += std::pow(h[k], p) / double(n), mf += f[k] / double(n);
    double sxx = 0, sxf = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const double x = std::pow(h[k], p) - mx;
      sxx += x * x;
      sxf += x * (f[k] - mf);
    }
    c = sxx > 0 ? sxf / sxx : 0;
    fstar = mf - c * mx;
    double ssr = 0;
    for (std::size_t k = 0; k < n; ++k) ssr += std::pow(fstar + c * std::pow(h[k], p) - f[k], 2);
    return ssr;
  };
  double p = NAN;
  if (n == 3) {
    p = observed_order(f[0], f[1], f[2], h[0], h[1], h[2]);
  } else {
    double best = INFINITY, fs = 0, c = 0;
    int at = -1;
    const int steps = 800;
    for (int i = 0; i <= steps; ++i) {
      const double q = 0.05 + (8 - 0.05) * i / steps;
      const double r = linear_fit(q, fs, c);
      if (r < best) best = r, at = i;
    }
    if (at > 0 && at < steps) {
      double lo = 0.05 + (8 - 0.05) * (at - 1) / steps, hi = 0.05 + (8 - 0.05) * (at + 1) / steps;
      for (int i = 0; i < 60; ++i) {  // golden-section search on the bracket
        const double a = hi - 0.618034 * (hi - lo), b = lo + 0.618034 * (hi - lo);
        if (linear_fit(a, fs, c) < linear_fit(b, fs, c))
          hi = b;
        else
          lo = a;
      }
      p = 0.5 * (lo + hi);
    }
  }
  if (!std::isfinite(p)) return;
  double fstar = 0, c = 0;
  (void)linear_fit(p, fstar, c);
  row.order = p;
  row.extrapolated = fstar;
  row.error_estimate = std::abs(f[n - 1] - fstar);
}

}  // namespace

std::vector<ConvergenceRow> convergence_table(const std::vector<RunResults>& levels,
                                              const std::vector<double>& h) {
  if (levels.size() != h.size()) throw std::invalid_argument("convergence_table: one size per level");
  std::vector<ConvergenceRow> rows;
  if (levels.empty()) return rows;
  for (const ResultValue& v : levels.front().values) {
    if (!v.key) continue;
    ConvergenceRow row{v.name, v.unit, {}, NAN, NAN, NAN};
    for (const RunResults& level : levels) {
      const ResultValue* x = level.find(v.name);
      row.level_values.push_back(x ? x->value : NAN);
    }
    fit_power_law(row, h);
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace foxi
