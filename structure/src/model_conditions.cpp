// [surfaces], [[conditions]], [[loads]], [mesh] -> plain data (conditions.hpp). Expressions are
// evaluated against the model's already evaluated parameters; absolute temperatures take "degC" (with
// its 273.15 K offset) as a suffix, since the unit evaluator only knows differences.
#include "model_conditions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "foxi/model/io_error.hpp"

namespace foxi {

const char* condition_kind_name(ConditionKind kind) {
  switch (kind) {
    case ConditionKind::temperature:
      return "temperature";
    case ConditionKind::heat_flux:
      return "heat_flux";
    case ConditionKind::convection:
      return "convection";
    case ConditionKind::voltage:
      return "voltage";
    case ConditionKind::current:
      return "current";
    case ConditionKind::displacement:
      return "displacement";
    case ConditionKind::sliding:
      return "sliding";
  }
  return "?";
}

bool is_conditions_key(std::string_view key) {
  return key == "surfaces" || key == "conditions" || key == "loads" || key == "mesh";
}

namespace {

using Value = ModelToml;

constexpr Dims kTemperature = {0, 0, 0, 1, 0}, kHeatFlux = {0, 1, -3, 0, 0}, kFilm = {0, 1, -3, -1, 0},
               kVoltage = {2, 1, -3, 0, -1}, kCurrent = {0, 0, 0, 0, 1}, kPower = {2, 1, -3, 0, 0},
               kPowerDensity = {-1, 1, -3, 0, 0};

class ConditionReader {
 public:
  explicit ConditionReader(Model& m) : m_(m) {}

  void read(const Value& root) {
    const auto& t = root.as_table();
    if (auto it = t.find("surfaces"); it != t.end()) read_surfaces(it->second);
    if (auto it = t.find("conditions"); it != t.end())
      for (const Value& c : entries(it->second, "conditions")) read_condition(c);
    if (auto it = t.find("loads"); it != t.end())
      for (const Value& l : entries(it->second, "loads")) read_load(l);
    if (auto it = t.find("mesh"); it != t.end()) read_mesh(it->second);
  }

 private:
  [[noreturn]] void fail(const Value& at, const std::string& reason) const {
    throw IoError(m_.file, at.location().line(), IoError::kNoOffset, reason);
  }

  const std::vector<Value>& entries(const Value& v, const char* key) const {
    if (!v.is_array()) fail(v, std::string("'") + key + "' must be an array of tables ([[" + key + "]])");
    for (const Value& e : v.as_array())
      if (!e.is_table()) fail(e, std::string("a [[") + key + "]] entry is not a table");
    return v.as_array();
  }

  const Value* find(const Value& table, const char* key) const {
    const auto& t = table.as_table();
    auto it = t.find(key);
    return it == t.end() ? nullptr : &it->second;
  }
  const Value& need(const Value& table, const char* key, const std::string& who) const {
    const Value* v = find(table, key);
    if (v == nullptr) fail(table, who + ": missing '" + key + "'");
    return *v;
  }
  void allow_keys(const Value& table, const std::string& who, std::initializer_list<const char*> keys) const {
    // Not a structured binding: clang before 16 cannot capture one in the lambda (the fuzz build).
    std::string list;
    for (const char* a : keys) list += (list.empty() ? "" : ", ") + std::string(a);
    for (const auto& entry : table.as_table()) {
      const std::string& k = entry.first;
      if (std::none_of(keys.begin(), keys.end(), [&](const char* a) { return k == a; }))
        fail(entry.second, who + ": unknown key '" + k + "' (expected " + list + ")");
    }
  }
  std::string text(const Value& v, const std::string& what) const {
    if (!v.is_string()) fail(v, what + " must be a string");
    return v.as_string().str;
  }

  std::optional<Quantity> parameter(std::string_view n) const {
    auto it = std::lower_bound(m_.parameters.begin(), m_.parameters.end(), n,
                               [](const Parameter& p, std::string_view x) { return p.name < x; });
    if (it == m_.parameters.end() || it->name != n) return std::nullopt;
    return it->value;
  }

  // The value of a TOML number or expression string: bare numbers get `want` times `bare_scale`.
  Quantity evaluate(const Value& v, const std::string& expr, const std::string& entity) const {
    try {
      return evaluate_expression(expr, [&](std::string_view n) { return parameter(n); });
    } catch (const ExpressionError& x) {
      fail(v, entity + ": " + x.what());
    }
  }
  double quantity(const Value& v, const Dims& want, const std::string& entity, double bare_scale) const {
    Quantity q;
    if (v.is_integer())
      q.value = static_cast<double>(v.as_integer());
    else if (v.is_floating())
      q.value = v.as_floating();
    else if (v.is_string())
      q = evaluate(v, v.as_string().str, entity);
    else
      fail(v, entity + ": expected a number or an expression string");
    if (q.dims == kDimensionless && want != kDimensionless) q = {q.value * bare_scale, want};
    if (q.dims != want)
      fail(v,
           entity + ": unit mismatch: expected " + dims_to_string(want) + ", got " + dims_to_string(q.dims));
    if (!std::isfinite(q.value)) fail(v, entity + " is not finite");
    return q.value;
  }
  double length(const Value& v, const std::string& entity) const {
    const double x = quantity(v, kLength, entity, m_.length_scale);
    if (std::abs(x) > model_limits::kMaxLength)
      fail(v, entity + " is beyond the limit of 1000 m for any coordinate or size");
    return x;
  }
  double positive_length(const Value& v, const std::string& entity) const {
    const double x = length(v, entity);
    if (!(x > 0)) fail(v, entity + " must be positive");
    return x;
  }
  void point(const Value& v, const std::string& entity, double out[3]) const {
    if (!v.is_array() || v.as_array().size() != 3) fail(v, entity + ": expected [x, y, z]");
    for (int i = 0; i < 3; ++i)
      out[i] = length(v.as_array()[static_cast<std::size_t>(i)], entity + "[" + std::to_string(i) + "]");
  }

  // A temperature in K: numbers and expressions in K, or "EXPR degC" (also "°C") with the offset
  // (evaluate_temperature, units.hpp); `absolute` false takes degC as a difference (no offset).
  // Absolute temperatures must be above 0 K, in degC too.
  double temperature(const Value& v, const std::string& entity, bool absolute) const {
    const TemperatureKind kind = absolute ? TemperatureKind::absolute : TemperatureKind::difference;
    if (v.is_string()) {
      try {
        return evaluate_temperature(v.as_string().str, kind,
                                    [&](std::string_view n) { return parameter(n); });
      } catch (const ExpressionError& x) {
        fail(v, entity + ": " + x.what());
      }
    }
    const double t = quantity(v, kTemperature, entity, 1);
    if (absolute && !(t > 0)) {
      char buf[96];
      std::snprintf(buf, sizeof buf, " = %g K is not above absolute zero (for Celsius write \"%g degC\")", t,
                    t);
      fail(v, entity + buf);
    }
    return t;
  }

  std::size_t part_index(const std::string& name) const {
    for (std::size_t i = 0; i < m_.parts.size(); ++i)
      if (m_.parts[i].name == name) return i;
    return m_.parts.size();
  }

  void read_surfaces(const Value& v) {
    if (!v.is_table()) fail(v, "'surfaces' must be a table of named surfaces ([surfaces.NAME])");
    for (const auto& [name, s] : v.as_table()) {
      const std::string who = "surface '" + name + "'";
      if (!s.is_table()) fail(s, who + " must be a table with 'plane' or 'box'");
      if (name.find_first_of("./,") != std::string::npos)
        fail(s, who + ": a surface name may not contain '.', '/' or ','");
      allow_keys(s, who, {"plane", "box"});
      SurfaceSelector sel;
      sel.name = name;
      sel.line = s.location().line();
      const Value* plane = find(s, "plane");
      const Value* box = find(s, "box");
      if ((plane == nullptr) == (box == nullptr)) fail(s, who + ": give exactly one of 'plane' or 'box'");
      if (plane != nullptr) {
        if (!plane->is_table()) fail(*plane, who + ": plane = { point = [x, y, z], normal = [nx, ny, nz] }");
        allow_keys(*plane, who + " plane", {"point", "normal"});
        sel.plane = true;
        point(need(*plane, "point", who + " plane"), who + " plane point", sel.point);
        const Value& n = need(*plane, "normal", who + " plane");
        if (!n.is_array() || n.as_array().size() != 3) fail(n, who + " plane normal: expected [nx, ny, nz]");
        double len = 0;
        for (std::size_t i = 0; i < 3; ++i) {
          sel.normal[i] = quantity(n.as_array()[i], kDimensionless, who + " plane normal", 1);
          len += sel.normal[i] * sel.normal[i];
        }
        if (!(len > 0)) fail(n, who + " plane normal is zero");
        for (double& c : sel.normal) c /= std::sqrt(len);
      } else {
        if (!box->is_table()) fail(*box, who + ": box = { min = [x, y, z], max = [x, y, z] }");
        allow_keys(*box, who + " box", {"min", "max"});
        point(need(*box, "min", who + " box"), who + " box min", sel.lo);
        point(need(*box, "max", who + " box"), who + " box max", sel.hi);
        for (int i = 0; i < 3; ++i)
          if (!(sel.lo[i] <= sel.hi[i])) fail(*box, who + " box: min is above max");
      }
      m_.surfaces.push_back(sel);
    }
  }

  // A boundary name as the structure builder writes it; interfaces "B/A" become "A/B" (file order).
  std::string surface_name(const Value& at, const std::string& name, const std::string& who) const {
    for (const SurfaceSelector& s : m_.surfaces)
      if (s.name == name) return name;
    if (const auto slash = name.find('/'); slash != std::string::npos) {
      const std::size_t a = part_index(name.substr(0, slash)), b = part_index(name.substr(slash + 1));
      if (a < m_.parts.size() && b < m_.parts.size() && a != b)
        return a < b ? name : m_.parts[b].name + "/" + m_.parts[a].name;
    } else if (const auto dot = name.rfind('.'); dot != std::string::npos) {
      const std::string face = name.substr(dot + 1);
      if (part_index(name.substr(0, dot)) < m_.parts.size() &&
          (face == "top" || face == "bottom" || face == "side"))
        return name;
    }
    fail(at, who + ": surface '" + name +
                 "' does not exist (expected PART.top, PART.bottom, PART.side, an interface PART/PART, or "
                 "a name from [surfaces])");
  }

  void read_condition(const Value& c) {
    const std::string type = text(need(c, "type", "[[conditions]] entry"), "condition type");
    const std::string who = "condition '" + type + "'";
    BoundaryCondition bc;
    bc.line = c.location().line();
    const Value& surf = need(c, "surface", who);
    if (surf.is_string()) {
      bc.surfaces.push_back(surface_name(surf, surf.as_string().str, who));
    } else if (surf.is_array() && !surf.as_array().empty()) {
      for (const Value& s : surf.as_array())
        bc.surfaces.push_back(surface_name(s, text(s, who + " surface"), who));
    } else {
      fail(surf, who + ": surface must be a name or an array of names");
    }
    const std::string on = who + " on '" + bc.surfaces.front() + "'";
    if (const Value* n = find(c, "name")) bc.name = text(*n, who + " name");
    if (type == "temperature") {
      bc.kind = ConditionKind::temperature;
      allow_keys(c, who, {"type", "surface", "value"});
      bc.value = temperature(need(c, "value", on), on, true);
    } else if (type == "heat_flux") {
      bc.kind = ConditionKind::heat_flux;
      allow_keys(c, who, {"type", "surface", "value"});
      bc.value = quantity(need(c, "value", on), kHeatFlux, on, 1);
    } else if (type == "convection") {
      bc.kind = ConditionKind::convection;
      allow_keys(c, who, {"type", "surface", "h", "ambient"});
      bc.h = quantity(need(c, "h", on), kFilm, on + " h", 1);
      if (!(bc.h > 0)) fail(need(c, "h", on), on + ": h must be positive");
      bc.ambient = temperature(need(c, "ambient", on), on + " ambient", true);
    } else if (type == "voltage" || type == "ground") {
      bc.kind = ConditionKind::voltage;
      if (type == "voltage") {
        allow_keys(c, who, {"type", "surface", "value", "name", "physics"});
        bc.value = quantity(need(c, "value", on), kVoltage, on, 1);
      } else {
        allow_keys(c, who, {"type", "surface", "name", "physics"});
      }
      if (const Value* ph = find(c, "physics")) {
        bc.physics = text(*ph, who + " physics");
        if (bc.physics != "electrostatic" && bc.physics != "current")
          fail(*ph, on + ": physics must be \"electrostatic\" or \"current\", not '" + bc.physics + "'");
      }
    } else if (type == "current") {
      bc.kind = ConditionKind::current;
      allow_keys(c, who, {"type", "surface", "value", "name"});
      bc.value = quantity(need(c, "value", on), kCurrent, on, 1);
    } else if (type == "displacement") {
      bc.kind = ConditionKind::displacement;
      allow_keys(c, who, {"type", "surface", "value"});
      if (const Value* v = find(c, "value")) point(*v, on, bc.displacement);
    } else if (type == "sliding") {
      bc.kind = ConditionKind::sliding;
      allow_keys(c, who, {"type", "surface"});
    } else {
      fail(c, "unknown condition type '" + type +
                  "' (expected temperature, heat_flux, convection, voltage, ground, current, displacement, "
                  "sliding)");
    }
    if (bc.name.empty())
      for (const std::string& s : bc.surfaces) bc.name += (bc.name.empty() ? "" : ",") + s;
    m_.conditions.push_back(std::move(bc));
  }

  void read_load(const Value& l) {
    const std::string type = text(need(l, "type", "[[loads]] entry"), "load type");
    std::string who = "load '" + type + "'";
    Load load;
    load.line = l.location().line();
    if (const Value* p = find(l, "part")) {
      load.part = text(*p, who + " part");
      if (part_index(load.part) == m_.parts.size()) fail(*p, who + ": unknown part '" + load.part + "'");
      who += " on part '" + load.part + "'";
    }
    allow_keys(l, who, {"type", "part", "value"});
    const Value& v = need(l, "value", who);
    if (type == "power") {
      load.kind = LoadKind::power;
      if (load.part.empty()) fail(l, who + ": missing 'part'");
      // W for the whole part, or W/m^3: decided by the value's unit
      Quantity q;
      if (v.is_string()) q = evaluate(v, v.as_string().str, who);
      if (q.dims == kPowerDensity) {
        load.total = false;
        load.value = q.value;
      } else {
        load.value = quantity(v, kPower, who + " (W, or W/m^3 for a density)", 1);
      }
    } else if (type == "temperature_change") {
      load.kind = LoadKind::temperature_change;
      load.value = temperature(v, who, false);
    } else {
      fail(l, "unknown load type '" + type + "' (expected power, temperature_change)");
    }
    m_.loads.push_back(std::move(load));
  }

  void read_mesh(const Value& v) {
    if (!v.is_table()) fail(v, "'mesh' must be a table ([mesh])");
    allow_keys(v, "[mesh]", {"max_size", "quality", "min_dihedral", "parts", "refine"});
    ModelMeshControls& mc = m_.mesh;
    if (const Value* s = find(v, "max_size")) mc.max_size = positive_length(*s, "mesh max_size");
    if (const Value* q = find(v, "quality")) {
      mc.quality = quantity(*q, kDimensionless, "mesh quality", 1);
      // TetGen 1.5's refinement did not finish within 5 minutes below sqrt(2) (1.0 and 1.1 on
      // die_on_substrate, 1.2 and 1.3 on die_attach and power_module); mesh_plc refuses it too.
      if (!(mc.quality == 0 || mc.quality >= 1.414))
        fail(*q,
             "mesh quality (a radius-edge bound) must be 0 (off) or at least 1.414 (TetGen's refinement "
             "does not finish below it on thin layers)");
    }
    if (const Value* d = find(v, "min_dihedral")) {
      mc.min_dihedral = quantity(*d, kDimensionless, "mesh min_dihedral", 1);
      if (!(mc.min_dihedral >= 0 && mc.min_dihedral < 30))
        fail(*d, "mesh min_dihedral must be between 0 and 30 degrees (larger bounds do not terminate)");
    }
    if (const Value* p = find(v, "parts")) {
      if (!p->is_table()) fail(*p, "mesh parts must be a table { PART = max_size, ... }");
      for (const auto& [name, s] : p->as_table()) {
        if (part_index(name) == m_.parts.size()) fail(s, "mesh parts: unknown part '" + name + "'");
        mc.part_sizes.push_back(
            {name, positive_length(s, "mesh size of part '" + name + "'"), s.location().line()});
      }
    }
    if (const Value* r = find(v, "refine")) {
      for (const Value& e : entries(*r, "mesh.refine")) {
        allow_keys(e, "[[mesh.refine]]", {"min", "max", "max_size"});
        RefineBox box;
        box.line = e.location().line();
        point(need(e, "min", "[[mesh.refine]]"), "mesh.refine min", box.lo);
        point(need(e, "max", "[[mesh.refine]]"), "mesh.refine max", box.hi);
        for (int i = 0; i < 3; ++i)
          if (!(box.lo[i] < box.hi[i])) fail(e, "mesh.refine: min must be below max");
        box.max_size = positive_length(need(e, "max_size", "[[mesh.refine]]"), "mesh.refine max_size");
        mc.refine.push_back(box);
      }
    }
  }

  Model& m_;
};

}  // namespace

void read_model_conditions(const ModelToml& root, Model& model) { ConditionReader(model).read(root); }

}  // namespace foxi
