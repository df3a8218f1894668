// Saving a model file (model_save.hpp): toml11 finds where each value to change is written (line,
// column, length); the file's text is edited there and nowhere else, so comments and layout stay.
#include "foxi/model/model_save.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <toml.hpp>
#include <vector>

#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {

namespace {

using Value = toml::basic_value<toml::discard_comments, std::map, std::vector>;

// One value's text replaced: at 1-based line and column, `length` characters on that line.
struct Edit {
  std::size_t line = 0, column = 0, length = 0;
  std::string text;
};

// A TOML basic string holding `s` (the escapes TOML requires: quote, backslash, control characters).
std::string toml_quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Where `v` is written, as an edit that replaces it by `text`; IoError when it spans lines (a
// multi-line string), which a one-line edit cannot replace.
Edit edit_of(const std::filesystem::path& file, const Value& v, const std::string& what, std::string text) {
  const auto loc = v.location();
  const std::string line = loc.line_str();
  if (loc.column() < 1 || loc.column() - 1 + loc.region() > line.size())
    throw IoError(file.string(), loc.line(), IoError::kNoOffset,
                  what + " is not written on one line; write it as \"...\" on one line to save it");
  return {loc.line(), loc.column(), loc.region(), std::move(text)};
}

// The value of parameter `name` ("a.b" for a nested table) in the parsed file, or null.
const Value* parameter_value(const Value& root, const std::string& name) {
  const Value* v = &root;
  if (!v->is_table() || !v->as_table().count("parameters")) return nullptr;
  v = &v->as_table().at("parameters");
  std::size_t b = 0;
  while (true) {
    const std::size_t e = name.find('.', b);
    const std::string key = name.substr(b, e == std::string::npos ? std::string::npos : e - b);
    if (!v->is_table()) return nullptr;
    const auto it = v->as_table().find(key);
    if (it == v->as_table().end()) return nullptr;
    v = &it->second;
    if (e == std::string::npos) return v;
    b = e + 1;
  }
}

// `name` (relative to `from`) renamed relative to `to`, with '/' separators.
std::string moved_reference(const std::filesystem::path& file, std::uint64_t line, const std::string& name,
                            const std::filesystem::path& from, const std::filesystem::path& to) {
  std::error_code ec;
  const std::filesystem::path target = std::filesystem::weakly_canonical(from / name, ec);
  std::filesystem::path rel;
  if (!ec) rel = std::filesystem::relative(target, to, ec);
  if (ec || rel.empty() || rel.is_absolute())
    throw IoError(file.string(), line, IoError::kNoOffset,
                  "the referenced file '" + name + "' cannot be named relative to " + to.string());
  return rel.generic_string();
}

bool same_doubles(const std::vector<double>& a, const std::vector<double>& b) { return a == b; }

bool same_material(const Material& a, const Material& b) {
  auto eq = [](double x, double y) { return x == y || (x != x && y != y); };  // unset (NaN) equals unset
  return a.name == b.name && eq(a.thermal_conductivity, b.thermal_conductivity) &&
         eq(a.electrical_conductivity, b.electrical_conductivity) &&
         eq(a.relative_permittivity, b.relative_permittivity) && eq(a.youngs_modulus, b.youngs_modulus) &&
         eq(a.poisson_ratio, b.poisson_ratio) && eq(a.thermal_expansion, b.thermal_expansion) &&
         eq(a.density, b.density) && eq(a.specific_heat, b.specific_heat);
}

// Why `saved` differs from `expected`, or "" when it loads the same.
std::string model_difference(const Model& expected, const Model& saved) {
  if (saved.length_unit != expected.length_unit) return "the length unit differs";
  if (saved.parameters.size() != expected.parameters.size()) return "the parameters differ";
  for (std::size_t i = 0; i < saved.parameters.size(); ++i) {
    const Parameter &a = expected.parameters[i], &b = saved.parameters[i];
    if (a.name != b.name || a.expression != b.expression || a.value.value != b.value.value ||
        a.value.dims != b.value.dims)
      return "parameter '" + a.name + "' would load as '" + b.expression + "'";
  }
  if (saved.materials.size() != expected.materials.size()) return "the materials differ";
  for (std::size_t i = 0; i < saved.materials.size(); ++i)
    if (!same_material(expected.materials[i], saved.materials[i]))
      return "material '" + expected.materials[i].name + "' differs";
  if (saved.parts.size() != expected.parts.size()) return "the parts differ";
  for (std::size_t i = 0; i < saved.parts.size(); ++i) {
    const Part &a = expected.parts[i], &b = saved.parts[i];
    bool same = a.name == b.name && a.material == b.material && a.shape == b.shape &&
                a.prisms.size() == b.prisms.size() && a.surface.xyz == b.surface.xyz &&
                a.surface.tri == b.surface.tri;
    for (std::size_t k = 0; same && k < a.prisms.size(); ++k)
      same = same_doubles(a.prisms[k].xy, b.prisms[k].xy) && a.prisms[k].z0 == b.prisms[k].z0 &&
             a.prisms[k].z1 == b.prisms[k].z1;
    if (!same) return "part '" + a.name + "' differs";
  }
  if (saved.surfaces.size() != expected.surfaces.size() ||
      saved.conditions.size() != expected.conditions.size() || saved.loads.size() != expected.loads.size())
    return "the surfaces, conditions or loads differ";
  return "";
}

// `name` (relative to `from`) copied into `to` under its own file name (or "NAME-2.EXT", ... when
// `copied` holds another file of that name); returns the copy's name. A file already there (a model
// saved over itself) is not copied again.
std::string copied_reference(const std::filesystem::path& file, std::uint64_t line, const std::string& name,
                             const std::filesystem::path& from, const std::filesystem::path& to,
                             std::map<std::string, std::filesystem::path>& copied) {
  std::error_code ec;
  const std::filesystem::path src = std::filesystem::weakly_canonical(from / name, ec);
  if (ec || !std::filesystem::is_regular_file(src))
    throw IoError(file.string(), line, IoError::kNoOffset,
                  "the referenced file '" + name + "' cannot be read");
  const std::string stem = src.stem().string(), ext = src.extension().string();
  std::string copy = src.filename().string();
  for (int i = 2; copied.count(copy) && copied[copy] != src; ++i) copy = stem + "-" + std::to_string(i) + ext;
  if (copied.emplace(copy, src).second && std::filesystem::weakly_canonical(to / copy, ec) != src) {
    // whole or not at all: a temporary beside it, renamed over it
    const std::filesystem::path temp = to / (copy + ".part");
    std::filesystem::copy_file(src, temp, std::filesystem::copy_options::overwrite_existing, ec);
    if (!ec) std::filesystem::rename(temp, to / copy, ec);
    if (ec) {
      std::filesystem::remove(temp);
      throw IoError((to / copy).string(), 0, IoError::kNoOffset,
                    "cannot copy the referenced file '" + name + "' here: " + ec.message());
    }
  }
  return copy;
}

}  // namespace

void save_model(const std::filesystem::path& source, const std::filesystem::path& target,
                std::span<const ParameterOverride> values, const SaveModelOptions& options) {
  // The source loads with the values (so it is a model within the limits, safe to parse again)
  const Model expected = load_model(source, values, "the saved values");
  const std::string text = io::read_file(source);
  std::istringstream in(text);
  const Value root = toml::parse<toml::discard_comments, std::map, std::vector>(in, source.string());

  std::vector<Edit> edits;
  for (const ParameterOverride& o : values) {
    const Value* v = parameter_value(root, o.name);
    if (!v) throw IoError(source.string(), 0, IoError::kNoOffset, "unknown parameter '" + o.name + "'");
    edits.push_back(edit_of(source, *v, "parameter '" + o.name + "'", toml_quoted(o.expression)));
  }
  // Referenced files, renamed when the model moves to another folder (or copied there)
  std::error_code ec;
  const std::filesystem::path from =
      std::filesystem::weakly_canonical(std::filesystem::absolute(source).parent_path(), ec);
  const std::filesystem::path to =
      std::filesystem::weakly_canonical(std::filesystem::absolute(target).parent_path(), ec);
  std::map<std::string, std::filesystem::path> copied;  // copy's name -> the file it copies
  // the model's own name is taken (a library of that name is copied as "NAME-2.toml")
  copied[target.filename().string()] = to / target.filename();
  if (from != to || options.copy_references) {
    auto reference = [&](const Value& v, const std::string& what) {
      if (!v.is_string()) return;  // load_model refused it already
      const std::string name = v.as_string().str;
      const std::uint64_t line = v.location().line();
      const std::string renamed = options.copy_references
                                      ? copied_reference(source, line, name, from, to, copied)
                                      : moved_reference(source, line, name, from, to);
      edits.push_back(edit_of(source, v, what, toml_quoted(renamed)));
    };
    const auto& t = root.as_table();
    if (auto it = t.find("library"); it != t.end()) reference(it->second, "library");
    if (auto it = t.find("parts"); it != t.end() && it->second.is_array())
      for (const Value& part : it->second.as_array()) {
        if (!part.is_table()) continue;
        const auto& pt = part.as_table();
        if (auto f = pt.find("file"); f != pt.end()) reference(f->second, "an STL file");
        if (auto item = pt.find("item"); item != pt.end() && item->second.is_table())
          if (auto f = item->second.as_table().find("file"); f != item->second.as_table().end())
            reference(f->second, "an STL file");
      }
  }

  // The edits, applied line by line (right to left within a line, so earlier columns stay valid)
  std::map<std::size_t, std::vector<const Edit*>> by_line;
  for (const Edit& e : edits) by_line[e.line].push_back(&e);
  std::string out;
  out.reserve(text.size() + 64 * edits.size());
  std::size_t b = 0;
  for (std::size_t line = 1; b <= text.size(); ++line) {
    std::size_t e = text.find('\n', b);
    const bool last = e == std::string::npos;
    if (last) e = text.size();
    std::string s = text.substr(b, e - b);
    if (auto it = by_line.find(line); it != by_line.end()) {
      auto& list = it->second;
      std::sort(list.begin(), list.end(), [](const Edit* x, const Edit* y) { return x->column > y->column; });
      for (const Edit* ed : list) s.replace(ed->column - 1, ed->length, ed->text);
    }
    out += s;
    if (last) break;
    out += '\n';
    b = e + 1;
  }

  DurableFile file(target);
  file.write(out);
  file.finish();
  Model saved;
  try {
    saved = load_model(file.temp());
  } catch (const IoError& e) {
    throw IoError(target.string(), e.line(), IoError::kNoOffset,
                  std::string("the saved model would not load: ") + e.reason());
  }
  if (const std::string why = model_difference(expected, saved); !why.empty())
    throw IoError(target.string(), 0, IoError::kNoOffset,
                  "the saved model would load differently (" + why + "); nothing was written");
  file.commit();
}

}  // namespace foxi
