#include "foxi/model/sweep_values.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>

#include "foxi/model/units.hpp"

namespace foxi {

namespace {

// The SI value and dimensions of a value with units ("2mm" -> 0.002, m).
Quantity quantity(const std::string& text) {
  return evaluate_expression(text, [](std::string_view) { return std::optional<Quantity>{}; });
}

// The unit written after the number of `text` ("2mm" -> "mm", "2 mm" -> "mm", "2" -> "").
std::string unit_suffix(const std::string& text) {
  std::size_t at = 0;
  while (at < text.size() && (std::isdigit(static_cast<unsigned char>(text[at])) || text[at] == '.' ||
                              text[at] == '-' || text[at] == '+' ||
                              ((text[at] == 'e' || text[at] == 'E') && at + 1 < text.size() &&
                               (std::isdigit(static_cast<unsigned char>(text[at + 1])) ||
                                text[at + 1] == '-' || text[at + 1] == '+'))))
    ++at;
  while (at < text.size() && text[at] == ' ') ++at;
  return text.substr(at);
}

}  // namespace

SweepValues sweep_range(const std::string& lo_text, const std::string& hi_text, int n) {
  if (n < 1 || n > 10000)
    throw ExpressionError("the count N must be a whole number from 1 to 10000, not '" + std::to_string(n) +
                          "'");
  SweepValues v;
  const Quantity lo = quantity(lo_text), hi = quantity(hi_text);
  if (lo.dims != hi.dims)
    throw ExpressionError(lo_text + " and " + hi_text + " are not of one dimension (" +
                          dims_to_string(lo.dims) + ", " + dims_to_string(hi.dims) + ")");
  // The values are written in LO's unit ("2.5mm"), as the user would write them.
  const std::string unit = unit_suffix(lo_text);
  const double unit_si = unit.empty() ? 1 : quantity("1 " + unit).value;
  if (!(unit_si != 0) || !std::isfinite(unit_si))
    throw ExpressionError("cannot write values in '" + unit + "'");
  v.unit = unit, v.unit_si = unit_si;
  for (int i = 0; i < n; ++i) {
    const double si = n == 1 ? lo.value : lo.value + (hi.value - lo.value) * i / (n - 1);
    char text[64];
    std::snprintf(text, sizeof text, "%.10g%s", si / unit_si, unit.c_str());
    v.texts.push_back(text);
    v.si.push_back(si);
  }
  v.si_unit = dims_to_string(lo.dims);
  if (v.si_unit == "1") v.si_unit.clear();
  return v;
}

SweepValues sweep_list(const std::vector<std::string>& values) {
  SweepValues v;
  Dims dims{};
  for (const std::string& item : values) {
    if (item.empty()) throw ExpressionError("empty value");
    const Quantity q = quantity(item);
    if (!v.texts.empty() && q.dims != dims)
      throw ExpressionError("the values are not of one dimension ('" + item + "')");
    dims = q.dims;
    v.texts.push_back(item);
    v.si.push_back(q.value);
  }
  v.si_unit = dims_to_string(dims);
  // The chart's unit: the first value's, when it converts (else SI).
  const std::string unit = v.texts.empty() ? std::string() : unit_suffix(v.texts.front());
  double unit_si = 1;
  try {
    unit_si = unit.empty() ? 1 : quantity("1 " + unit).value;
  } catch (const ExpressionError&) {
    unit_si = 0;
  }
  if (unit_si != 0 && std::isfinite(unit_si))
    v.unit = unit, v.unit_si = unit_si;
  else
    v.unit = v.si_unit;
  if (v.si_unit == "1") v.si_unit.clear();
  return v;
}

SweepValues parse_sweep_values(const std::string& spec) {
  if (spec.find(':') != std::string::npos) {
    const auto c1 = spec.find(':'), c2 = spec.find(':', c1 + 1);
    if (c2 == std::string::npos || spec.find(':', c2 + 1) != std::string::npos)
      throw ExpressionError("give LO:HI:N or V1,V2,..., not '" + spec + "'");
    const std::string count = spec.substr(c2 + 1);
    int n = 0;
    const auto [end, ec] = std::from_chars(count.data(), count.data() + count.size(), n);
    if (ec != std::errc() || end != count.data() + count.size() || n < 1 || n > 10000)
      throw ExpressionError("the count N must be a whole number from 1 to 10000, not '" + count + "'");
    return sweep_range(spec.substr(0, c1), spec.substr(c1 + 1, c2 - c1 - 1), n);
  }
  std::vector<std::string> items;
  for (std::size_t at = 0; at <= spec.size();) {
    const std::size_t comma = std::min(spec.find(',', at), spec.size());
    items.push_back(spec.substr(at, comma - at));
    if (items.back().empty()) throw ExpressionError("empty value in '" + spec + "'");
    at = comma + 1;
  }
  return sweep_list(items);
}

}  // namespace foxi
