// Physical quantities with units, and the arithmetic expressions of model files ("die_w + 2 mm",
// "150 W/(m*K)", "sqrt(area)"): values are SI, dimensions are tracked so that "1 mm + 300 K" is an
// error instead of a number.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "foxi/api.hpp"

namespace foxi {

// Exponents of the SI base units metre, kilogram, second, kelvin, ampere.
using Dims = std::array<std::int8_t, 5>;
inline constexpr Dims kDimensionless = {0, 0, 0, 0, 0};
inline constexpr Dims kLength = {1, 0, 0, 0, 0};

struct Quantity {
  double value = 0;  // SI
  Dims dims = kDimensionless;
};

// An error in an expression: what was wrong, with the expression text in the message.
struct FOXI_API ExpressionError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "m", "kg K^-1", "m^2", "1" for dimensionless.
FOXI_API std::string dims_to_string(const Dims& d);

// The SI value of unit `name` ("mm" -> 1e-3 m), or nothing if it is not a unit foxi knows: lengths
// m cm mm um µm nm in mil; K s kg g W mW kW J V mV kV A mA uA S N Pa kPa MPa GPa Hz ppm (1e-6).
// Absolute temperatures in degC are read by the boundary conditions (conditions.hpp), not here.
FOXI_API std::optional<Quantity> unit_quantity(std::string_view name);

// Limits on an expression (README, "Limits"): its length in characters and how deep it nests
// (parentheses, unary signs, exponents and function calls each count one level).
constexpr std::size_t kMaxExpressionLength = 4096;
constexpr int kMaxExpressionDepth = 64;

// Evaluates `text`: numbers, a number followed by a unit ("8 mm", "2.5um"), names (resolved by
// `lookup` first, then as units; `lookup` returns nothing for an unknown name), + - * / ^ (integer
// exponent on dimensioned bases), parentheses, pi, sqrt abs min max sin cos tan exp log (dimensionless
// arguments except sqrt abs min max). Throws ExpressionError on syntax errors, unknown names ("unknown
// parameter 'x'") unit mismatches ("unit mismatch: m + K")
// and expressions past the limits above; `lookup` may throw its own errors.
FOXI_API Quantity evaluate_expression(std::string_view text,
                                      const std::function<std::optional<Quantity>(std::string_view)>& lookup);

// `text` (an expression with units, no parameters) in SI, checked to have the dimension of `unit`
// (itself an expression: "W", "W/(m*K)", "V", "1/K"); a bare number is taken as SI. E.g. "3 W",
// "3W", "3" and "3000 mW" are 3 for unit "W". Throws ExpressionError naming `unit` when the
// dimension differs ("'3 m' is m, not W") and on syntax errors.
FOXI_API double evaluate_in(std::string_view text, std::string_view unit);

// How a temperature is read: a point on the scale (degC adds 273.15 K, and it must be above 0 K)
// or a difference (1 degC = 1 K, any sign).
enum class TemperatureKind : std::uint8_t { absolute, difference };

// A temperature in K: "300", "300 K", "300K", "T_amb + 5 K" (`lookup` as for evaluate_expression),
// or an expression followed by degC or °C ("25 degC", "25degC", "25 °C"). Throws
// ExpressionError on other units (naming K and degC), on degC inside an expression, and (absolute)
// on a value not above absolute zero.
FOXI_API double evaluate_temperature(
    std::string_view text, TemperatureKind kind,
    const std::function<std::optional<Quantity>(std::string_view)>& lookup = {});

}  // namespace foxi
