// Model files: TOML (toml11) -> Model. Parameters are evaluated lazily, so their order in the file
// does not matter and cycles are found by the "being evaluated" mark.
#include "foxi/model/model_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>
#include <toml.hpp>

#include "foxi/model/io_error.hpp"
#include "io_util.hpp"
#include "model_conditions.hpp"

namespace foxi {

double Prism::area() const {
  double a = 0;
  const std::size_t n = xy.size() / 2;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    a += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
  }
  return 0.5 * a;
}

namespace {

using Value = toml::basic_value<toml::discard_comments, std::map, std::vector>;
using Table = Value::table_type;

// A located error: thrown once with file and line and passed through unchanged by outer handlers.
struct Located {
  std::uint64_t line;
  std::string reason;
};

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

double orient(const double* a, const double* b, const double* c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

// Whether closed segments ab and cd share a point (touching counts).
bool segments_meet(const double* a, const double* b, const double* c, const double* d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  auto on = [](const double* p, const double* q, const double* r) {  // r on segment pq, collinear
    return std::min(p[0], q[0]) <= r[0] && r[0] <= std::max(p[0], q[0]) && std::min(p[1], q[1]) <= r[1] &&
           r[1] <= std::max(p[1], q[1]);
  };
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return true;
  return (o1 == 0 && on(a, b, c)) || (o2 == 0 && on(a, b, d)) || (o3 == 0 && on(c, d, a)) ||
         (o4 == 0 && on(c, d, b));
}

// Why a closed outline (2 doubles per vertex) is not a simple polygon, or "" when it is one: repeated
// points, edges that cross or touch other than at their shared vertex, edges that fold back.
std::string polygon_problem(const std::vector<double>& xy) {
  const std::size_t n = xy.size() / 2;
  const double* v = xy.data();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n, k = (i + 2) % n;
    if (v[2 * i] == v[2 * j] && v[2 * i + 1] == v[2 * j + 1])
      return "point " + std::to_string(j) + " repeats point " + std::to_string(i);
    // consecutive edges fold back on each other: collinear with the turn point not between them
    const double* a = v + 2 * i;
    const double* b = v + 2 * j;
    const double* c = v + 2 * k;
    if (n > 3 && orient(a, b, c) == 0 && (c[0] - b[0]) * (a[0] - b[0]) + (c[1] - b[1]) * (a[1] - b[1]) > 0)
      return "edges " + std::to_string(i) + " and " + std::to_string(j) + " fold back on each other";
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the closing edge
      if (segments_meet(v + 2 * i, v + 2 * ((i + 1) % n), v + 2 * j, v + 2 * ((j + 1) % n)))
        return "the outline is not a simple polygon: edge " + std::to_string(i) + " meets edge " +
               std::to_string(j);
    }
  double area = 0;
  for (std::size_t i = 0; i < n; ++i) area += orient(v, v + 2 * i, v + 2 * ((i + 1) % n));
  if (area == 0) return "the outline has no area";
  return "";
}

namespace lim = model_limits;

// The first place where `text` nests deeper than kTomlDepth, as (line, reason); line 0 when it does
// not. toml11 parses (and frees) nested values recursively, so a deep file would exhaust the stack
// before it could report anything. Counts the open [ and { of values plus the dotted parts of the
// table header and of the key being read, skipping strings and comments; it does not validate the
// TOML (toml11 does that next).
std::pair<std::uint64_t, std::string> toml_nesting(std::string_view s) {
  std::uint64_t line = 1;
  std::size_t open = 0;             // [ and { of values not yet closed
  std::vector<bool> inline_table;   // for each open one: a { (keys inside) or a [
  std::size_t header = 0, key = 0;  // dotted parts of the current [header] and of the key being read
  bool at_key = true;  // reading a key: at a line's start outside values, after { or , in an inline table
  auto deep = [&](std::size_t n) -> std::pair<std::uint64_t, std::string> {
    if (n <= static_cast<std::size_t>(lim::kTomlDepth)) return {0, ""};
    return {line, "tables, arrays and dotted keys nest deeper than " + std::to_string(lim::kTomlDepth) +
                      " levels (the limit for model files)"};
  };
  const std::size_t n = s.size();
  // toml11 looks through a value's whole line for every value on it (region::comments, even when it
  // discards them), so a long line costs its length squared: a 440 KB line of numbers took a minute
  for (std::size_t b = 0, l = 1; b < n; ++l) {
    std::size_t e = s.find('\n', b);
    if (e == std::string_view::npos) e = n;
    if (e - b > lim::kLineBytes)
      return {l, "the line has " + std::to_string(e - b) + " characters, more than the limit of " +
                     std::to_string(lim::kLineBytes) + " (break long arrays over several lines)"};
    b = e + 1;
  }
  auto skip_string = [&](std::size_t& i) {  // i at the opening quote; leaves i at the closing one
    const char q = s[i];
    const bool multi = i + 2 < n && s[i + 1] == q && s[i + 2] == q;
    i += multi ? 3 : 1;
    for (; i < n; ++i) {
      if (s[i] == '\n' && !multi) {  // an unterminated string (toml11 reports it): the line ends it
        --i;
        return;
      }
      if (s[i] == '\n') {
        ++line;
      } else if (s[i] == '\\' && q == '"') {  // an escape; in a multi-line string it may end the line
        if (i + 1 < n && s[i + 1] == '\n') {
          if (!multi) return;
          ++line;
        }
        ++i;
      } else if (s[i] == q && (!multi || (i + 2 < n && s[i + 1] == q && s[i + 2] == q))) {
        if (multi) {  // up to two more quotes belong to the string ("""a"""" is a")
          i += 2;
          for (int extra = 0; extra < 2 && i + 1 < n && s[i + 1] == q; ++extra) ++i;
        }
        return;
      }
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      if (open == 0) at_key = true, key = 0;
    } else if (c == '#') {
      while (i + 1 < n && s[i + 1] != '\n') ++i;
    } else if (c == '"' || c == '\'') {
      skip_string(i);
    } else if (c == '[' && open == 0 && at_key && key == 0) {  // a table header [a.b] or [[a.b]]
      header = 1;
      for (++i; i < n && s[i] != ']' && s[i] != '\n'; ++i) {
        if (s[i] == '"' || s[i] == '\'')
          skip_string(i);
        else if (s[i] == '.')
          ++header;
      }
      if (auto d = deep(header); d.first) return d;
      if (i < n && s[i] == '\n')
        --i;  // the loop counts the line
      else
        while (i + 1 < n && s[i + 1] == ']') ++i;
      at_key = false;
    } else if (at_key && c != '[' && c != '{') {  // (a bracket where a key belongs is counted below)
      if (c == '.') ++key;
      if (c == '=') {
        if (auto d = deep(header + open + key + 1); d.first) return d;
        at_key = false;
        key = 0;
      }
    } else if (c == '[' || c == '{') {
      ++open;
      inline_table.push_back(c == '{');
      if (auto d = deep(header + open); d.first) return d;
      at_key = c == '{';
    } else if (c == ']' || c == '}') {
      if (open > 0) --open, inline_table.pop_back();
    } else if (c == ',' && open > 0 && inline_table.back()) {
      at_key = true;
    }
  }
  return {0, ""};
}

// The first line of a toml11 message without its "[error] " tag: the summary, not the quoted source.
std::string toml_summary(const std::string& what) {
  std::string first = what.substr(0, what.find('\n'));
  if (first.rfind("[error] ", 0) == 0) first.erase(0, 8);
  return first;
}

std::uint64_t line_of(const Value& v) {
  const auto loc = v.location();
  return loc.line();
}

constexpr Dims kConductivity = {1, 1, -3, -1, 0}, kElectrical = {-3, -1, 3, 0, 2},
               kModulus = {-1, 1, -2, 0, 0}, kExpansion = {0, 0, 0, -1, 0}, kDensity = {-3, 1, 0, 0, 0},
               kSpecificHeat = {2, 0, -2, -1, 0};

class Loader {
 public:
  Loader(std::filesystem::path path, std::span<const ParameterOverride> overrides, std::string_view origin)
      : path_(std::move(path)), overrides_(overrides), origin_(origin) {}

  Model load() {
    model_.file = path_.string();
    try {
      root_ = parse_toml(path_, false);
      run();
    } catch (const Located& e) {
      throw IoError(model_.file, e.line, IoError::kNoOffset, e.reason);
    }
    return std::move(model_);
  }

 private:
  // A model (`library` false) or a materials library: a regular file within the size limit, nested
  // within the depth limit, parsed by toml11. A library's syntax errors give the place only: a file
  // named by a model may be anything, and its content is not to be echoed.
  Value parse_toml(const std::filesystem::path& p, bool library) {
    const std::string text = read_regular_file(p, lim::kFileBytes);
    if (const auto [line, why] = toml_nesting(text); line != 0)
      throw IoError(p.string(), line, IoError::kNoOffset, why);
    std::istringstream in(text);
    try {
      return toml::parse<toml::discard_comments, std::map, std::vector>(in, p.string());
    } catch (const toml::syntax_error& e) {
      const auto loc = e.location();
      throw IoError(p.string(), loc.line(), IoError::kNoOffset,
                    library ? "not a TOML materials library (a TOML syntax error at column " +
                                  std::to_string(loc.column()) + ")"
                            : "TOML syntax: " + toml_summary(e.what()));
    } catch (const std::exception& e) {
      throw IoError(
          p.string(), 0, IoError::kNoOffset,
          library ? std::string("not a TOML materials library") : "TOML: " + toml_summary(e.what()));
    }
  }

  // The bytes of `p`, which must be a regular file (symlinks followed) of at most `limit` bytes: a
  // directory, device or pipe could fail oddly, never end or exhaust memory.
  static std::string read_regular_file(const std::filesystem::path& p, std::uintmax_t limit) {
    std::error_code ec;
    const auto st = std::filesystem::status(p, ec);
    if (!std::filesystem::exists(st)) throw IoError(p.string(), 0, IoError::kNoOffset, "no such file");
    if (std::filesystem::is_directory(st))
      throw IoError(p.string(), 0, IoError::kNoOffset, "is a directory, not a file");
    if (!std::filesystem::is_regular_file(st))
      throw IoError(p.string(), 0, IoError::kNoOffset, "is not a regular file (a device, pipe or socket)");
    const std::uintmax_t size = std::filesystem::file_size(p, ec);
    if (!ec && size > limit)
      throw IoError(
          p.string(), 0, IoError::kNoOffset,
          "the file has " + std::to_string(size) + " bytes, more than the limit of " + std::to_string(limit));
    std::string data = io::read_file(p);
    if (data.size() > limit)  // it grew since
      throw IoError(p.string(), 0, IoError::kNoOffset,
                    "the file has more than the limit of " + std::to_string(limit) + " bytes");
    return data;
  }

  // The file a model names (library, STL): a non-empty path relative to the model's folder (it may
  // lead out of it with ".."; absolute paths are refused so that a model means the same wherever its
  // folder is copied), which must exist and be a regular file (README, "Referenced files").
  std::filesystem::path referenced_file(const Value& v, const std::string& what) {
    const std::string name = string_of(v, what);
    if (name.empty()) throw Located{line_of(v), what + ": the file name is empty"};
    if (name.find('\0') != std::string::npos) throw Located{line_of(v), what + ": the file name holds a NUL"};
    const std::filesystem::path rel(name);
    if (rel.is_absolute())
      throw Located{line_of(v), what + " '" + name +
                                    "' is an absolute path: name it relative to the model file's folder"};
    const std::filesystem::path file = path_.parent_path() / rel;
    std::error_code ec;
    const auto st = std::filesystem::status(file, ec);
    if (!std::filesystem::exists(st))
      throw Located{line_of(v), what + " '" + name + "': no such file (" + file.string() + ")"};
    if (std::filesystem::is_directory(st))
      throw Located{line_of(v), what + " '" + name + "' is a directory, not a file"};
    if (!std::filesystem::is_regular_file(st))
      throw Located{line_of(v), what + " '" + name + "' is not a regular file (a device, pipe or socket)"};
    return file;
  }

  void run() {
    if (!root_.is_table()) throw Located{0, "the model is not a TOML table"};
    for (const auto& [k, v] : root_.as_table())
      if (k != "units" && k != "library" && k != "parameters" && k != "materials" && k != "parts" &&
          !is_conditions_key(k))  // the list below is every key allowed here
        throw Located{line_of(v), "unknown key '" + k +
                                      "' (expected units, library, parameters, materials, parts, surfaces, "
                                      "conditions, loads, mesh)"};
    read_units();
    read_parameters();
    read_materials();
    read_parts();
    check_features();
    for (auto& p : params_) value_of(p.first, {});  // every parameter evaluates, used or not
    for (auto& [name, e] : params_) model_.parameters.push_back(e.param);
    read_model_conditions(root_, model_);
  }

  void read_units() {
    const Table& t = root_.as_table();
    auto it = t.find("units");
    if (it == t.end()) return;
    if (!it->second.is_table()) throw Located{line_of(it->second), "'units' must be a table"};
    for (const auto& [k, v] : it->second.as_table()) {
      if (k != "length")
        throw Located{line_of(v), "unknown unit setting 'units." + k + "' (expected units.length)"};
      if (!v.is_string()) throw Located{line_of(v), "units.length must be a string such as \"mm\""};
      const std::string u = v.as_string().str;
      auto q = unit_quantity(u);
      if (!q || q->dims != kLength)
        throw Located{line_of(v), "units.length: '" + u + "' is not a length unit"};
      model_.length_unit = u;
      model_.length_scale = q->value;
    }
  }

  struct ParamEntry {
    Parameter param;
    std::uint64_t line = 0;
    int state = 0;  // 0 not evaluated, 1 being evaluated, 2 done
  };

  void flatten(const std::string& prefix, const Value& v) {
    for (const auto& [k, x] : v.as_table()) {
      const std::string name = prefix.empty() ? k : prefix + "." + k;
      if (x.is_table()) {
        flatten(name, x);
        continue;
      }
      ParamEntry e;
      e.param.name = name;
      e.line = line_of(x);
      if (x.is_string()) {
        e.param.expression = x.as_string().str;
      } else if (x.is_integer()) {
        e.param.expression = std::to_string(x.as_integer());
      } else if (x.is_floating()) {
        e.param.expression = toml::format(x);
      } else {
        throw Located{e.line, "parameter '" + name + "': expected a number or an expression string"};
      }
      params_[name] = std::move(e);
    }
  }

  void read_parameters() {
    const Table& t = root_.as_table();
    auto it = t.find("parameters");
    if (it != t.end()) {
      if (!it->second.is_table()) throw Located{line_of(it->second), "'parameters' must be a table"};
      flatten("", it->second);
    }
    for (const ParameterOverride& o : overrides_) {
      auto p = params_.find(o.name);
      if (p == params_.end()) throw Located{0, origin_ + ": unknown parameter '" + o.name + "'"};
      p->second.param.expression = o.expression;
      p->second.param.overridden = true;
    }
  }

  Quantity value_of(const std::string& name, std::vector<std::string> chain) {
    ParamEntry& e = params_.at(name);
    if (e.state == 2) return e.param.value;
    chain.push_back(name);
    // each link evaluates an expression inside the one before: a bound keeps the stack bounded
    if (chain.size() > lim::kParameterChain)
      throw Located{e.line, "parameter '" + chain.front() + "' needs a chain of more than " +
                                std::to_string(lim::kParameterChain) +
                                " parameters, each needing the next (the limit)"};
    if (e.state == 1) {
      std::string path;
      for (auto& c : chain) path += (path.empty() ? "" : " -> ") + c;
      throw Located{e.line, "circular expression: parameter " + path};
    }
    e.state = 1;
    try {
      e.param.value = evaluate(e.param.expression, chain);
    } catch (const ExpressionError& x) {
      throw Located{e.param.overridden ? 0 : e.line,
                    "parameter '" + name + "'" + (e.param.overridden ? " (from " + origin_ + ")" : "") +
                        ": " + x.what()};
    }
    e.state = 2;
    return e.param.value;
  }

  Quantity evaluate(const std::string& text, const std::vector<std::string>& chain) {
    return evaluate_expression(text, [&](std::string_view n) -> std::optional<Quantity> {
      auto it = params_.find(std::string(n));
      if (it == params_.end()) return std::nullopt;
      return value_of(it->first, chain);
    });
  }

  // A quantity from a TOML number or expression string; `entity` names it in errors. Dimensionless
  // results for a length are taken in units.length.
  Quantity quantity(const Value& v, const Dims& want, const std::string& entity, double bare_scale) {
    Quantity q;
    if (v.is_integer() || v.is_floating()) {
      q = {v.is_integer() ? static_cast<double>(v.as_integer()) : v.as_floating(), kDimensionless};
    } else if (v.is_string()) {
      try {
        q = evaluate(v.as_string().str, {});
      } catch (const ExpressionError& x) {
        throw Located{line_of(v), entity + ": " + x.what()};
      }
    } else {
      throw Located{line_of(v), entity + ": expected a number or an expression string"};
    }
    if (q.dims == kDimensionless && want != kDimensionless) q = {q.value * bare_scale, want};
    if (q.dims != want)
      throw Located{line_of(v), entity + ": unit mismatch: expected " + dims_to_string(want) + ", got " +
                                    dims_to_string(q.dims)};
    if (!std::isfinite(q.value))  // TOML has nan and inf; a bare number may overflow when scaled
      throw Located{line_of(v), entity + " is not a finite number"};
    return q;
  }

  void read_material_table(const Value& mats, bool from_library) {
    if (!mats.is_table()) throw Located{line_of(mats), "'materials' must be a table of tables"};
    for (const auto& [name, m] : mats.as_table()) {
      if (!m.is_table()) throw Located{line_of(m), "material '" + name + "' must be a table"};
      Material mat;
      mat.name = name;
      for (const auto& [k, v] : m.as_table()) {
        const std::string entity = "material '" + name + "' " + k;
        if (k == "source" || k == "note") continue;
        double* field = nullptr;
        Dims d = kDimensionless;
        if (k == "thermal_conductivity")
          field = &mat.thermal_conductivity, d = kConductivity;
        else if (k == "electrical_conductivity")
          field = &mat.electrical_conductivity, d = kElectrical;
        else if (k == "relative_permittivity")
          field = &mat.relative_permittivity;
        else if (k == "youngs_modulus")
          field = &mat.youngs_modulus, d = kModulus;
        else if (k == "poisson_ratio")
          field = &mat.poisson_ratio;
        else if (k == "thermal_expansion")
          field = &mat.thermal_expansion, d = kExpansion;
        else if (k == "density")
          field = &mat.density, d = kDensity;
        else if (k == "specific_heat")
          field = &mat.specific_heat, d = kSpecificHeat;
        else
          throw Located{line_of(v), "material '" + name + "': unknown property '" + k +
                                        "' (expected thermal_conductivity, electrical_conductivity, "
                                        "relative_permittivity, youngs_modulus, poisson_ratio, "
                                        "thermal_expansion, density, specific_heat, source, note)"};
        const double x = quantity(v, d, entity, 1).value;
        // Negative: a thermal expansion can be (Invar near 0, some ceramics below), and a Poisson ratio
        // down to -1 (auxetic foams: --nu took them, the model file refused them).
        if (k == "poisson_ratio" ? !(x > -1) : (!(x >= 0) && k != "thermal_expansion"))
          throw Located{line_of(v),
                        entity + (k == "poisson_ratio" ? " must be above -1" : " must not be negative")};
        *field = x;
      }
      if (from_library && materials_.count(name)) continue;  // the model's own definition wins
      materials_[name] = mat;
    }
  }

  void read_materials() {
    const Table& t = root_.as_table();
    if (auto it = t.find("materials"); it != t.end()) read_material_table(it->second, false);
    if (auto it = t.find("library"); it != t.end()) {
      const std::filesystem::path lib = referenced_file(it->second, "library");
      Value libroot = parse_toml(lib, true);
      try {
        if (!libroot.is_table() || !libroot.as_table().count("materials"))
          throw Located{0, "not a materials library: it has no [materials] table"};
        for (const auto& [k, v] : libroot.as_table())
          if (k != "materials")
            throw Located{line_of(v), "unknown key '" + k + "' in a materials library (expected materials)"};
        read_material_table(libroot.as_table().at("materials"), true);
      } catch (const Located& e) {
        throw IoError(lib.string(), e.line, IoError::kNoOffset, e.reason);
      }
    }
  }

  const Value& need(const Value& part, const std::string& key, const std::string& who) {
    const Table& t = part.as_table();
    auto it = t.find(key);
    if (it == t.end()) throw Located{line_of(part), who + ": missing '" + key + "'"};
    return it->second;
  }
  double length(const Value& v, const std::string& entity) {
    const double x = quantity(v, kLength, entity, model_.length_scale).value;
    if (std::abs(x) > lim::kMaxLength)
      throw Located{line_of(v), entity + " = " + short_number(x / model_.length_scale) + " " +
                                    model_.length_unit + " is beyond the limit of " +
                                    short_number(lim::kMaxLength) + " m for any coordinate or size"};
    return x;
  }
  double positive_length(const Value& v, const std::string& entity) {
    const double x = length(v, entity);
    if (!(x > 0))
      throw Located{line_of(v), entity + " = " + short_number(x / model_.length_scale) + " " +
                                    model_.length_unit + " is not positive (negative or zero size)"};
    return x;
  }
  std::vector<double> lengths(const Value& v, std::size_t n, const std::string& entity, bool positive) {
    if (!v.is_array() || (n != 0 && v.as_array().size() != n))
      throw Located{line_of(v), entity + ": expected an array of " +
                                    (n ? std::to_string(n) : std::string("some")) + " values"};
    std::vector<double> out;
    std::size_t i = 0;
    for (const auto& x : v.as_array()) {
      const std::string e = entity + "[" + std::to_string(i++) + "]";
      out.push_back(positive ? positive_length(x, e) : length(x, e));
    }
    return out;
  }
  long integer(const Value& v, const std::string& entity, long min, long max) {
    const double x = quantity(v, kDimensionless, entity, 1).value;
    if (x != std::round(x) || x < static_cast<double>(min) || x > static_cast<double>(max))
      throw Located{line_of(v), entity + " = " + short_number(x) + ": must be an integer from " +
                                    std::to_string(min) + " to " + std::to_string(max)};
    return static_cast<long>(x);
  }

  // A ball or an STL surface shifted by (sx, sy), appended to out.surface.
  void surface_primitive(Part& out, const Value& part, const std::string& shape, const std::string& who,
                         double sx, double sy) {
    const Table& t = part.as_table();
    if (shape == "stl") {
      const Value& f = need(part, "file", who);
      const std::filesystem::path file = referenced_file(f, who + " file");
      auto cached = stl_.find(file.string());
      if (cached == stl_.end()) {
        std::error_code ec;
        if (const auto size = std::filesystem::file_size(file, ec); !ec && size > lim::kStlBytes)
          throw IoError(file.string(), 0, IoError::kNoOffset,
                        "the STL file has " + std::to_string(size) + " bytes, more than the limit of " +
                            std::to_string(lim::kStlBytes));
        cached = stl_.emplace(file.string(), read_stl(file, model_.length_scale)).first;
      }
      count(0, cached->second.triangle_count(), line_of(part), who);
      out.surface.append(cached->second, sx, sy, 0);
      out.source = file.string();
      return;
    }
    Ball b;
    const auto c = lengths(need(part, "center", who), 3, who + " center", false);
    b.center[0] = c[0] + sx;
    b.center[1] = c[1] + sy;
    b.center[2] = c[2];
    b.radius = positive_length(need(part, "radius", who), who + " radius");
    b.z0 = c[2] - b.radius;
    b.z1 = c[2] + b.radius;
    if (auto it = t.find("z_range"); it != t.end()) {
      const auto z = lengths(it->second, 2, who + " z_range", false);
      if (!(z[0] < z[1]) || z[1] <= b.z0 || z[0] >= b.z1)
        throw Located{line_of(it->second),
                      who + " z_range: expected [z0, z1] with z0 < z1 cutting the sphere"};
      b.z0 = std::max(b.z0, z[0]);
      b.z1 = std::min(b.z1, z[1]);
    }
    b.tolerance = 0.01 * b.radius;
    if (auto it = t.find("tolerance"); it != t.end()) {
      b.tolerance = positive_length(it->second, who + " tolerance");
      // the facet count grows as radius / tolerance
      if (b.tolerance < lim::kBallTolerance * b.radius)
        throw Located{line_of(it->second),
                      who + " tolerance = " + short_number(b.tolerance / model_.length_scale) + " " +
                          model_.length_unit + " is below the limit of " + short_number(lim::kBallTolerance) +
                          " times the radius (" + short_number(b.radius / model_.length_scale) + " " +
                          model_.length_unit + ")"};
    }
    const TriSurface ball = ball_surface(b);
    count(0, ball.triangle_count(), line_of(part), who);
    out.surface.append(ball);
  }

  // A box, cylinder or extrusion shifted by (sx, sy) appended to out.prisms, or a ball or STL
  // surface appended to out.surface.
  void primitive(Part& out, const Value& part, const std::string& shape, const std::string& who, double sx,
                 double sy, bool check_outline = true) {
    if (shape == "ball" || shape == "stl") return surface_primitive(out, part, shape, who, sx, sy);
    Prism& p = out.prisms.emplace_back();
    if (shape == "box") {
      const auto o = lengths(need(part, "origin", who), 3, who + " origin", false);
      const auto s = lengths(need(part, "size", who), 3, who + " size", true);
      const double x0 = o[0] + sx, y0 = o[1] + sy;
      p.xy = {x0, y0, x0 + s[0], y0, x0 + s[0], y0 + s[1], x0, y0 + s[1]};
      p.z0 = o[2];
      p.z1 = o[2] + s[2];
    } else if (shape == "cylinder") {
      const auto c = lengths(need(part, "center", who), 3, who + " center", false);
      const double r = positive_length(need(part, "radius", who), who + " radius");
      const double h = positive_length(need(part, "height", who), who + " height");
      long n = 16;
      if (part.as_table().count("segments"))
        n = integer(part.as_table().at("segments"), who + " segments", 3, lim::kSegments);
      for (long k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
        p.xy.push_back(c[0] + sx + r * std::cos(a));
        p.xy.push_back(c[1] + sy + r * std::sin(a));
      }
      p.z0 = c[2];
      p.z1 = c[2] + h;
    } else if (shape == "extrusion") {
      const Value& pts = need(part, "points", who);
      if (!pts.is_array() || pts.as_array().size() < 3)
        throw Located{line_of(pts), who + " points: expected an array of at least 3 [x, y] points"};
      if (pts.as_array().size() > lim::kOutlinePoints)
        throw Located{line_of(pts), who + " points: " + std::to_string(pts.as_array().size()) +
                                        " points, more than the limit of " +
                                        std::to_string(lim::kOutlinePoints)};
      std::size_t i = 0;
      for (const Value& q : pts.as_array()) {
        const auto xy = lengths(q, 2, who + " points[" + std::to_string(i++) + "]", false);
        p.xy.push_back(xy[0] + sx);
        p.xy.push_back(xy[1] + sy);
      }
      p.z0 = length(need(part, "z", who), who + " z");
      p.z1 = p.z0 + positive_length(need(part, "height", who), who + " height");
      // O(n^2): an array's items are translations of the first, checked once (check_features sees
      // the rest)
      if (check_outline)
        if (const std::string why = polygon_problem(p.xy); !why.empty())
          throw Located{line_of(pts), who + " points: " + why};
      if (p.area() < 0)  // clockwise as written: the builders take counter-clockwise outlines
        for (std::size_t a = 0, b = p.xy.size() / 2 - 1; a < b; ++a, --b) {
          std::swap(p.xy[2 * a], p.xy[2 * b]);
          std::swap(p.xy[2 * a + 1], p.xy[2 * b + 1]);
        }
    } else {
      throw Located{line_of(part), who + ": unknown shape '" + shape +
                                       "' (expected box, cylinder, extrusion, ball, stl, layers, array)"};
    }
    count(p.xy.size() / 2, 0, line_of(part), who);
  }

  void check_keys(const Value& part, const std::string& who, std::initializer_list<const char*> allowed) {
    for (const auto& [k, v] : part.as_table()) {
      bool ok = false;
      std::string list;
      for (const char* a : allowed) {
        ok = ok || k == a;
        list += (list.empty() ? "" : ", ") + std::string(a);
      }
      if (!ok) throw Located{line_of(v), who + ": unknown key '" + k + "' (expected " + list + ")"};
    }
  }

  std::string material(const Value& v, const std::string& who) {
    if (!v.is_string()) throw Located{line_of(v), who + ": material must be a name"};
    const std::string m = v.as_string().str;
    auto it = materials_.find(m);
    if (it == materials_.end()) throw Located{line_of(v), who + ": unknown material '" + m + "'"};
    bool have = false;
    for (auto& x : model_.materials) have = have || x.name == m;
    if (!have) model_.materials.push_back(it->second);
    return m;
  }

  std::string string_of(const Value& v, const std::string& what) {
    if (!v.is_string()) throw Located{line_of(v), what + " must be a string"};
    return v.as_string().str;
  }

  void read_parts() {
    const Table& t = root_.as_table();
    auto it = t.find("parts");
    if (it == t.end()) throw Located{0, "the model has no [[parts]]"};
    if (!it->second.is_array())
      throw Located{line_of(it->second), "'parts' must be an array of tables ([[parts]])"};
    std::size_t index = 0;
    for (const Value& pv : it->second.as_array()) {
      ++index;
      if (!pv.is_table())
        throw Located{line_of(pv), "parts entry " + std::to_string(index) + " is not a table"};
      const std::string name = string_of(need(pv, "name", "parts entry " + std::to_string(index)), "name");
      const std::string who = "part '" + name + "'";
      const std::string shape = string_of(need(pv, "shape", who), who + " shape");
      if (shape == "layers") {
        check_keys(pv, who, {"name", "shape", "origin", "footprint", "thicknesses", "names", "materials"});
        const auto o = lengths(need(pv, "origin", who), 3, who + " origin", false);
        const auto f = lengths(need(pv, "footprint", who), 2, who + " footprint", true);
        const auto th = lengths(need(pv, "thicknesses", who), 0, who + " thicknesses", true);
        const Value& names = need(pv, "names", who);
        const Value& mats = need(pv, "materials", who);
        if (!names.is_array() || names.as_array().size() != th.size() || !mats.is_array() ||
            mats.as_array().size() != th.size())
          throw Located{line_of(pv), who + ": names and materials need one entry per thickness"};
        double z = o[2];
        for (std::size_t i = 0; i < th.size(); ++i) {
          Part part;
          part.name = string_of(names.as_array()[i], who + " names");
          part.material = material(mats.as_array()[i], "layer '" + part.name + "' of " + who);
          part.shape = "layers";
          part.line = line_of(pv);
          Prism p;
          p.xy = {o[0], o[1], o[0] + f[0], o[1], o[0] + f[0], o[1] + f[1], o[0], o[1] + f[1]};
          p.z0 = z;
          p.z1 = z + th[i];
          z = p.z1;
          part.prisms.push_back(std::move(p));
          add_part(std::move(part));
        }
        continue;
      }
      Part part;
      part.name = name;
      part.shape = shape;
      part.line = line_of(pv);
      part.material = material(need(pv, "material", who), who);
      if (shape == "array") {
        check_keys(pv, who, {"name", "shape", "material", "count", "pitch", "item"});
        const Value& cnt = need(pv, "count", who);
        const Value& pitch = need(pv, "pitch", who);
        if (!cnt.is_array() || cnt.as_array().size() != 2)
          throw Located{line_of(cnt), who + " count: expected [nx, ny]"};
        const long nx = integer(cnt.as_array()[0], who + " count[0]", 1, lim::kArrayItems);
        const long ny = integer(cnt.as_array()[1], who + " count[1]", 1, lim::kArrayItems);
        if (nx * ny > lim::kArrayItems)
          throw Located{line_of(cnt), who + " count: " + std::to_string(nx) + " x " + std::to_string(ny) +
                                          " items, more than the limit of " +
                                          std::to_string(lim::kArrayItems)};
        const auto pp = lengths(pitch, 2, who + " pitch", true);
        const Value& item = need(pv, "item", who);
        if (!item.is_table()) throw Located{line_of(item), who + " item must be a table"};
        const std::string ishape = string_of(need(item, "shape", who + " item"), who + " item shape");
        if (ishape == "box") check_keys(item, who + " item", {"shape", "origin", "size"});
        if (ishape == "cylinder")
          check_keys(item, who + " item", {"shape", "center", "radius", "height", "segments"});
        if (ishape == "extrusion") check_keys(item, who + " item", {"shape", "points", "z", "height"});
        if (ishape == "ball")
          check_keys(item, who + " item", {"shape", "center", "radius", "z_range", "tolerance"});
        if (ishape == "stl") check_keys(item, who + " item", {"shape", "file"});
        for (long j = 0; j < ny; ++j)
          for (long i = 0; i < nx; ++i)
            primitive(part, item, ishape, who + " item", static_cast<double>(i) * pp[0],
                      static_cast<double>(j) * pp[1], i == 0 && j == 0);
      } else {
        if (shape == "box") check_keys(pv, who, {"name", "shape", "material", "origin", "size"});
        if (shape == "cylinder")
          check_keys(pv, who, {"name", "shape", "material", "center", "radius", "height", "segments"});
        if (shape == "extrusion") check_keys(pv, who, {"name", "shape", "material", "points", "z", "height"});
        if (shape == "ball")
          check_keys(pv, who, {"name", "shape", "material", "center", "radius", "z_range", "tolerance"});
        if (shape == "stl") check_keys(pv, who, {"name", "shape", "material", "file"});
        primitive(part, pv, shape, who, 0, 0);
      }
      add_part(std::move(part));
    }
  }

  void add_part(Part p) {
    // A part's name makes its boundaries' names (part.face) and its interfaces' (a/b): a '.' or '/'
    // in it made names collide (parts p/q and r met p and q/r as one boundary "p/q/r"), control
    // characters reached the terminal raw, and an empty one made ".top".
    std::string shown;
    bool bad = p.name.empty() || p.name.size() > 100;
    for (const char c : p.name) {
      const auto u = static_cast<unsigned char>(c);
      bad = bad || c == '.' || c == '/' || u < 0x20 || u == 0x7f;
      if (u < 0x20 || u == 0x7f) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "\\x%02x", u);
        shown += hex;
      } else if (shown.size() < 100) {
        shown += c;
      }
    }
    if (bad)
      throw Located{p.line,
                    "part name '" + shown +
                        "': give a name of 1 to 100 characters without '.', '/' or control characters "
                        "(it names the part's boundaries, part.face, and its interfaces, a/b)"};
    for (const Part& q : model_.parts)
      if (q.name == p.name) throw Located{p.line, "part '" + p.name + "' is defined twice"};
    if (model_.parts.size() == lim::kParts)
      throw Located{p.line, "part '" + p.name + "': more than the limit of " + std::to_string(lim::kParts) +
                                " parts (each layer of a stack counts)"};
    if (p.shape == "layers") count(4, 0, p.line, "part '" + p.name + "'");  // the others count in primitive()
    model_.parts.push_back(std::move(p));
  }

  // Adds an item's outline vertices and surface triangles to the model's totals, which have limits
  // (checked as each array item is made, before a huge array is).
  void count(std::size_t vertices, std::size_t triangles, std::uint64_t line, const std::string& who) {
    outline_vertices_ += vertices;
    surface_triangles_ += triangles;
    if (outline_vertices_ > lim::kOutlineVertices)
      throw Located{line, who + ": the parts so far have " + std::to_string(outline_vertices_) +
                              " outline vertices (all prisms and array items), more than the limit of " +
                              std::to_string(lim::kOutlineVertices)};
    if (surface_triangles_ > lim::kSurfaceTriangles)
      throw Located{line, who + ": the balls and STL surfaces so far have " +
                              std::to_string(surface_triangles_) + " triangles, more than the limit of " +
                              std::to_string(lim::kSurfaceTriangles)};
  }

  // Degenerate geometry, refused before CGAL or the mesher see it: a model larger than kMaxLength or
  // smaller than kMinExtent, or with an edge or height below kMinFeature of its extent (in doubles, so
  // a size lost to rounding against its origin counts as zero). CGAL's exact arithmetic would follow
  // such features down to any scale (and crash or run out of memory); TetGen cannot mesh them.
  void check_features() {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    auto grow = [&](int k, double x) { lo[k] = std::min(lo[k], x), hi[k] = std::max(hi[k], x); };
    for (const Part& p : model_.parts) {
      for (const Prism& q : p.prisms) {
        for (std::size_t i = 0; i < q.xy.size(); ++i) grow(static_cast<int>(i % 2), q.xy[i]);
        grow(2, q.z0), grow(2, q.z1);
      }
      for (std::size_t i = 0; i < p.surface.xyz.size(); ++i) grow(static_cast<int>(i % 3), p.surface.xyz[i]);
    }
    if (model_.parts.empty()) return;
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    const double u = model_.length_scale;
    const std::string unit = " " + model_.length_unit;
    if (!(extent <= lim::kMaxLength))
      throw Located{0, "the model is " + short_number(extent / u) + unit + " across, beyond the limit of " +
                           short_number(lim::kMaxLength) + " m"};
    if (!(extent >= lim::kMinExtent))
      throw Located{0, "the model is " + short_number(extent / u) + unit + " across, below the limit of " +
                           short_number(lim::kMinExtent) + " m"};
    const double min_feature = lim::kMinFeature * extent;
    for (const Part& p : model_.parts) {
      auto refuse = [&](const std::string& what, double size) {
        throw Located{p.line, "part '" + p.name + "': " + what + " is " + short_number(size / u) + unit +
                                  ", below the smallest feature foxi meshes, " +
                                  short_number(lim::kMinFeature) + " of the model's extent (" +
                                  short_number(extent / u) + unit + "): degenerate geometry"};
      };
      for (std::size_t k = 0; k < p.prisms.size(); ++k) {
        const Prism& q = p.prisms[k];
        const std::string item = p.prisms.size() > 1 ? " of item " + std::to_string(k) : "";
        if (!(q.z1 - q.z0 >= min_feature)) refuse("the height" + item, q.z1 - q.z0);
        const std::size_t n = q.xy.size() / 2;
        for (std::size_t i = 0; i < n; ++i) {
          const std::size_t j = (i + 1) % n;
          const double len = std::hypot(q.xy[2 * j] - q.xy[2 * i], q.xy[2 * j + 1] - q.xy[2 * i + 1]);
          if (!(len >= min_feature)) refuse("outline edge " + std::to_string(i) + item, len);
        }
      }
      // STL surfaces only: a ball's faceting may put a ring of tiny edges next to a pole cut by its
      // z_range (made by foxi, and carved and meshed fine)
      const TriSurface& s = p.surface;
      for (std::size_t t = 0; !p.source.empty() && t < s.triangle_count(); ++t)
        for (int e = 0; e < 3; ++e) {
          const double* a = &s.xyz[3 * std::size_t{s.tri[3 * t + static_cast<std::size_t>(e)]}];
          const double* b = &s.xyz[3 * std::size_t{s.tri[3 * t + static_cast<std::size_t>((e + 1) % 3)]}];
          const double len = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
          if (!(len >= min_feature)) refuse("an edge of surface triangle " + std::to_string(t), len);
        }
    }
  }

  std::filesystem::path path_;
  std::span<const ParameterOverride> overrides_;
  std::string origin_;  // where the overrides came from, for messages
  Value root_;
  Model model_;
  std::map<std::string, ParamEntry> params_;
  std::map<std::string, Material> materials_;
  std::map<std::string, TriSurface> stl_;                     // by file, read once
  std::size_t outline_vertices_ = 0, surface_triangles_ = 0;  // of the parts so far
};

}  // namespace

Model load_model(const std::filesystem::path& path, std::span<const ParameterOverride> overrides,
                 std::string_view origin) {
  return Loader(path, overrides, origin).load();
}

std::vector<ParameterOverride> split_overrides(const std::filesystem::path& path,
                                               std::span<const std::string> texts, std::string_view origin) {
  std::vector<ParameterOverride> out;
  for (const std::string& o : texts) {
    const auto eq = o.find('=');
    if (eq == std::string::npos || eq == 0)
      throw IoError(path.string(), 0, IoError::kNoOffset,
                    std::string(origin) + " '" + o + "': expected name=value");
    for (const ParameterOverride& earlier : out)
      if (earlier.name == o.substr(0, eq))  // the last one won in silence
        throw IoError(path.string(), 0, IoError::kNoOffset,
                      std::string(origin) + " '" + o + "': parameter '" + earlier.name +
                          "' is set twice (also to '" + earlier.expression + "')");
    out.push_back({o.substr(0, eq), o.substr(eq + 1)});
  }
  return out;
}

Model load_model(const std::filesystem::path& path, std::span<const std::string> overrides,
                 std::string_view origin) {
  const std::vector<ParameterOverride> split = split_overrides(path, overrides, origin);
  return load_model(path, split, origin);
}

}  // namespace foxi
