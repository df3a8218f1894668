// Option values with units for foxi solve (solve_options.hpp): the model file's unit system
// (units.hpp), so that "--power die=3W" and a model's `value = "3 W"` read alike.
#include <string>
#include <utility>

#include "solve_options.hpp"

namespace foxi::cli {

double parse_value(const std::string& text, const std::string& option, const char* unit) {
  try {
    return evaluate_in(text, unit);
  } catch (const ExpressionError& e) {
    throw UsageError(option + ": " + e.what() + " (expected a value in " + unit + "; a bare number is in " +
                     unit + ")");
  }
}

double parse_temperature(const std::string& text, const std::string& option, TemperatureKind kind) {
  try {
    return evaluate_temperature(text, kind);
  } catch (const ExpressionError& e) {
    throw UsageError(option + ": " + e.what() +
                     (kind == TemperatureKind::absolute
                          ? " (expected a temperature in K or degC; a bare number is in K)"
                          : " (expected a temperature difference in K or degC; a bare number is in K)"));
  }
}

double size_scale_option(Args& args) {
  const std::string text = args.option("--size-scale", "1");
  const double v = parse_number(text, "--size-scale");
  if (!(v > 0)) throw UsageError("--size-scale takes a number > 0, not '" + text + "'");
  return v;
}

std::pair<std::string, std::string> split_pair(const std::string& text, const std::string& option,
                                               const char* form) {
  int depth = 0;
  std::size_t at = std::string::npos;
  for (std::size_t i = 0; i < text.size(); ++i) {
    depth += text[i] == '(' ? 1 : text[i] == ')' ? -1 : 0;
    if (text[i] == ',' && depth == 0) at = i;
  }
  if (at == std::string::npos || at == 0 || at + 1 == text.size())
    throw UsageError(option + " takes " + form + ", not '" + text + "'");
  return {text.substr(0, at), text.substr(at + 1)};
}

}  // namespace foxi::cli
