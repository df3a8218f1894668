// CSV tables as a field source (the header conventions are in field_source.hpp).
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <unordered_set>

#include "foxi/fields/field_source.hpp"
#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

// One header cell: the field it belongs to, the component index, the unit.
struct Column {
  enum Role { key, x, y, z, value } role = value;
  std::string field;
  int component = 0;
  std::string unit;
};

Column classify(std::string_view cell, SourceKey& key) {
  Column c;
  std::string_view s = trim(cell);
  // A unit in brackets at the end: "temperature [K]" or "temperature (K)".
  if (!s.empty() && (s.back() == ']' || s.back() == ')')) {
    const char open = s.back() == ']' ? '[' : '(';
    const std::size_t b = s.rfind(open);
    if (b != std::string_view::npos) {
      c.unit = std::string(trim(s.substr(b + 1, s.size() - b - 2)));
      s = trim(s.substr(0, b));
    }
  }
  const std::string l = lower(s);
  if (l == "id" || l == "node" || l == "node_id" || l == "nodeid") {
    c.role = Column::key;
    key = SourceKey::node_id;
    return c;
  }
  if (l == "cell" || l == "cell_id" || l == "element" || l == "element_id" || l == "tet") {
    c.role = Column::key;
    key = SourceKey::cell_id;
    return c;
  }
  if (l == "x" || l == "points:0") c.role = Column::x;
  if (l == "y" || l == "points:1") c.role = Column::y;
  if (l == "z" || l == "points:2") c.role = Column::z;
  if (c.role != Column::value) return c;
  c.field = std::string(s);
  // "NAME:k" (ParaView) or "NAME_x" / "_y" / "_z".
  const std::size_t colon = s.rfind(':');
  if (colon != std::string_view::npos && colon + 1 < s.size()) {
    int k = -1;
    auto [p, ec] = std::from_chars(s.data() + colon + 1, s.data() + s.size(), k);
    if (ec == std::errc() && p == s.data() + s.size() && k >= 0 && k < 64) {
      c.field = std::string(s.substr(0, colon));
      c.component = k;
    }
  } else if (s.size() > 2 && s[s.size() - 2] == '_') {
    const char a = static_cast<char>(std::tolower(static_cast<unsigned char>(s.back())));
    if (a == 'x' || a == 'y' || a == 'z') {
      c.field = std::string(s.substr(0, s.size() - 2));
      c.component = a - 'x';
    }
  }
  return c;
}

// Splits one line at `sep` (double quotes protect separators inside a cell).
void split(std::string_view line, char sep, std::vector<std::string_view>& cells) {
  cells.clear();
  std::size_t b = 0;
  bool quoted = false;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i < line.size() && line[i] == '"') quoted = !quoted;
    if (i == line.size() || (line[i] == sep && !quoted)) {
      cells.push_back(line.substr(b, i - b));
      b = i + 1;
    }
  }
}

}  // namespace

FieldSource parse_csv_source(std::string_view text, const std::string& name) {
  FieldSource src;
  src.path = name;
  src.format = "csv";
  std::size_t pos = 0;
  std::uint64_t line_no = 0;
  std::string_view line;
  auto next_line = [&]() {
    while (pos < text.size()) {
      const std::size_t e = std::min(text.find('\n', pos), text.size());
      line = text.substr(pos, e - pos);
      pos = e + 1;
      ++line_no;
      if (!trim(line).empty() && trim(line).front() != '#')
        return true;  // blank lines and # comments skipped
    }
    return false;
  };
  auto fail = [&](const std::string& why) { throw IoError(name, line_no, IoError::kNoOffset, why); };
  if (text.size() >= 3 && text.substr(0, 3) == "\xEF\xBB\xBF") pos = 3;  // a spreadsheet's byte order mark
  if (!next_line()) fail("no header row");
  const char sep = line.find('\t') != std::string_view::npos  ? '\t'
                   : line.find(';') != std::string_view::npos ? ';'
                                                              : ',';
  std::vector<std::string_view> cells;
  split(line, sep, cells);
  SourceKey key = SourceKey::position;
  std::vector<Column> cols;
  int key_col = -1, coord_col[3] = {-1, -1, -1};
  std::unordered_set<std::string> seen_names;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    SourceKey k = key;
    Column c = classify(cells[i], k);
    if (c.role == Column::key) {
      if (key_col >= 0)
        fail("two key columns ('" + std::string(trim(cells[key_col])) + "' and '" +
             std::string(trim(cells[i])) + "')");
      key_col = static_cast<int>(i);
      key = k;
    } else if (c.role != Column::value) {
      int& slot = coord_col[c.role - Column::x];
      if (slot >= 0) fail("two columns for coordinate " + std::string(1, char('x' + c.role - Column::x)));
      slot = static_cast<int>(i);
    } else {
      if (c.field.empty()) fail("column " + std::to_string(i + 1) + " has no name");
      const std::string label = c.field + ":" + std::to_string(c.component);
      if (!seen_names.insert(label).second) fail("two columns for " + std::string(trim(cells[i])));
    }
    cols.push_back(std::move(c));
  }
  const int coords = (coord_col[0] >= 0) + (coord_col[1] >= 0) + (coord_col[2] >= 0);
  if (coords != 0 && coords != 3) fail("the header names some coordinates but not all three of x, y, z");
  if (key_col < 0 && coords == 0)
    fail("no key column: name one 'id' (node ids), 'cell' (tet ids) or 'x', 'y', 'z' (coordinates)");
  if (key_col >= 0 && key == SourceKey::cell_id && coords == 3)
    fail("a cell table with coordinates: give node rows by 'id' or by 'x, y, z', cell rows by 'cell'");
  if (key_col < 0) key = SourceKey::coordinates;
  src.key = key;

  // The fields in header order; a field's components are its columns' indices 0..k-1, each once.
  std::vector<std::string> order;
  std::map<std::string, std::pair<int, std::string>> comps;  // name -> (component count, unit)
  for (const Column& c : cols) {
    if (c.role != Column::value) continue;
    auto [it, fresh] = comps.emplace(c.field, std::pair<int, std::string>{0, c.unit});
    if (fresh) order.push_back(c.field);
    it->second.first = std::max(it->second.first, c.component + 1);
    if (!c.unit.empty() && !it->second.second.empty() && c.unit != it->second.second)
      fail("the components of " + c.field + " have different units ('" + it->second.second + "', '" + c.unit +
           "')");
    if (!c.unit.empty()) it->second.second = c.unit;
  }
  if (order.empty()) fail("no field columns: the header names only the key");
  for (const std::string& f : order) {
    std::vector<bool> have(comps[f].first, false);
    for (const Column& c : cols)
      if (c.role == Column::value && c.field == f) have[c.component] = true;
    for (std::size_t k = 0; k < have.size(); ++k)
      if (!have[k])
        fail("field " + f + " lacks its component " + std::to_string(k) + " (column " + f + ":" +
             std::to_string(k) + ")");
  }
  std::vector<int> field_of(cols.size(), -1);
  for (std::size_t i = 0; i < cols.size(); ++i)
    if (cols[i].role == Column::value)
      field_of[i] = static_cast<int>(std::find(order.begin(), order.end(), cols[i].field) - order.begin());

  // Rows: values per field, row-major.
  std::vector<std::vector<double>> values(order.size());
  std::vector<std::uint64_t> ids;
  std::vector<double> xyz;
  std::unordered_set<std::uint64_t> seen_ids;
  while (next_line()) {
    split(line, sep, cells);
    if (cells.size() != cols.size())
      fail(std::to_string(cells.size()) + " cells where the header has " + std::to_string(cols.size()));
    for (std::size_t f = 0; f < order.size(); ++f)
      values[f].resize(values[f].size() + comps[order[f]].first, kNaN);
    for (std::size_t i = 0; i < cols.size(); ++i) {
      std::string_view s = trim(cells[i]);
      if (cols[i].role == Column::key) {
        std::uint64_t id = 0;
        auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), id);
        if (s.empty() || ec != std::errc() || p != s.data() + s.size() || id == 0)
          fail("column " + std::to_string(i + 1) + ": '" + std::string(s) +
               "' is not an id (a positive integer)");
        if (!seen_ids.insert(id).second) fail("id " + std::to_string(id) + " appears twice");
        ids.push_back(id);
        continue;
      }
      double v = kNaN;
      if (!s.empty() && lower(s) != "nan") {
        if (s.front() == '+') s.remove_prefix(1);
        auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec != std::errc() || p != s.data() + s.size())
          fail("column " + std::to_string(i + 1) + ": '" + std::string(trim(cells[i])) + "' is not a number");
      }
      if (cols[i].role == Column::value) {
        std::vector<double>& out = values[field_of[i]];
        out[out.size() - comps[order[field_of[i]]].first + cols[i].component] = v;
      } else {
        if (std::isnan(v)) fail("column " + std::to_string(i + 1) + ": a coordinate must be a number");
        xyz.push_back(v);
      }
    }
    // Coordinates in x, y, z order whatever the columns' order.
    if (coords == 3) {
      double p[3];
      for (int k = 0; k < 3; ++k) {
        int rank = 0;
        for (int j = 0; j < 3; ++j) rank += coord_col[j] < coord_col[k];
        p[k] = xyz[xyz.size() - 3 + rank];
      }
      std::copy(p, p + 3, xyz.end() - 3);
    }
  }
  const std::size_t rows = values[0].size() / comps[order[0]].first;
  if (rows == 0) fail("a header and no rows");
  src.mesh.xyz = std::move(xyz);
  const FieldLocation loc = key == SourceKey::cell_id ? FieldLocation::cell : FieldLocation::node;
  if (key == SourceKey::node_id) src.node_id = std::move(ids);
  if (key == SourceKey::cell_id) src.cell_id = std::move(ids);
  for (std::size_t f = 0; f < order.size(); ++f)
    src.mesh.fields.push_back(Field{order[f],
                                    loc,
                                    static_cast<std::uint32_t>(comps[order[f]].first),
                                    comps[order[f]].second,
                                    {},
                                    std::move(values[f])});
  return src;
}

FieldSource read_csv_source(const std::filesystem::path& path) {
  const std::string bytes = io::read_file(path);
  return parse_csv_source(bytes, path.string());
}

}  // namespace foxi
