// Expressions with units: values against hand-computed SI numbers, dimensions, and the errors.
#include "foxi/model/units.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

namespace {

using foxi::Quantity;

Quantity eval(const std::string& text, const std::map<std::string, Quantity>& names = {}) {
  return foxi::evaluate_expression(text, [&](std::string_view n) -> std::optional<Quantity> {
    auto it = names.find(std::string(n));
    if (it == names.end()) return std::nullopt;
    return it->second;
  });
}

std::string error_of(const std::string& text, const std::map<std::string, Quantity>& names = {}) {
  try {
    eval(text, names);
  } catch (const foxi::ExpressionError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for " << text;
  return {};
}

TEST(Units, LengthsConvertToMetres) {
  EXPECT_DOUBLE_EQ(eval("8 mm").value, 8e-3);
  EXPECT_DOUBLE_EQ(eval("2.5um").value, 2.5e-6);
  EXPECT_DOUBLE_EQ(eval("3 \xC2\xB5m").value, 3e-6);
  EXPECT_DOUBLE_EQ(eval("1 in").value, 0.0254);
  EXPECT_DOUBLE_EQ(eval("10 mil").value, 2.54e-4);
  EXPECT_EQ(eval("1 cm").dims, foxi::kLength);
  // Times below a second (the README's pulse example, 'pulse:3W,1ms,10ms', was refused: unknown unit)
  EXPECT_DOUBLE_EQ(eval("10 ms").value, 1e-2);
  EXPECT_DOUBLE_EQ(eval("5 us").value, 5e-6);
  EXPECT_DOUBLE_EQ(eval("2 ns").value, 2e-9);
  EXPECT_EQ(eval("1 ms").dims, (foxi::Dims{0, 0, 1, 0, 0}));
}

TEST(Units, ArithmeticCarriesDimensions) {
  const std::map<std::string, Quantity> p = {{"w", {4e-3, foxi::kLength}}, {"n", {3, foxi::kDimensionless}}};
  EXPECT_DOUBLE_EQ(eval("(w - 2 mm) / 2", p).value, 1e-3);
  const Quantity area = eval("w * w", p);
  EXPECT_DOUBLE_EQ(area.value, 16e-6);
  EXPECT_EQ(area.dims, (foxi::Dims{2, 0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(eval("sqrt(w^2)", p).value, 4e-3);
  EXPECT_DOUBLE_EQ(eval("n * w + -1 mm", p).value, 11e-3);
  EXPECT_DOUBLE_EQ(eval("max(w, 5 mm)", p).value, 5e-3);
  EXPECT_NEAR(eval("2 * pi").value, 6.283185307179586, 1e-15);
  EXPECT_DOUBLE_EQ(eval("2^3").value, 8);
  const Quantity k = eval("150 W/(m*K)");
  EXPECT_DOUBLE_EQ(k.value, 150);
  EXPECT_EQ(k.dims, (foxi::Dims{1, 1, -3, -1, 0}));
  EXPECT_DOUBLE_EQ(eval("130 GPa").value, 130e9);
  EXPECT_DOUBLE_EQ(eval("17 ppm / K").value, 17e-6);
}

TEST(Units, MismatchesAndUnknownNamesAreErrors) {
  EXPECT_NE(error_of("1 mm + 300 K").find("unit mismatch: m + K"), std::string::npos);
  EXPECT_NE(error_of("2 mm - 1").find("unit mismatch"), std::string::npos);
  EXPECT_NE(error_of("die_w * 2").find("unknown parameter 'die_w'"), std::string::npos);
  EXPECT_NE(error_of("3 furlong").find("unknown unit 'furlong'"), std::string::npos);
  EXPECT_NE(error_of("sin(1 mm)").find("dimensionless"), std::string::npos);
  EXPECT_NE(error_of("(1 mm)^0.5").find("integer"), std::string::npos);
  EXPECT_NE(error_of("sqrt(1 mm)").find("sqrt"), std::string::npos);
  EXPECT_NE(error_of("(1 + 2").find("')'"), std::string::npos);
  EXPECT_NE(error_of("1 +").find("unexpected end"), std::string::npos);
  EXPECT_NE(error_of("1 / 0").find("finite"), std::string::npos);
  EXPECT_NE(error_of("").find("unexpected end"), std::string::npos);
  // Numbers are decimal: hexadecimal was read as such ("0x10" was 16; an outside probe).
  EXPECT_NE(error_of("0x10").find("unknown unit 'x10'"), std::string::npos);
  EXPECT_NE(error_of("0x1p-3 mm").find("unknown unit"), std::string::npos);
  EXPECT_NE(error_of("2e mm").find("unknown unit 'e'"), std::string::npos);
  EXPECT_DOUBLE_EQ(eval("1e-1 mm").value, 1e-4);
  EXPECT_DOUBLE_EQ(eval("1E+2").value, 100);
  EXPECT_DOUBLE_EQ(eval(".5 mm").value, 5e-4);
  EXPECT_DOUBLE_EQ(eval("5. mm").value, 5e-3);
}

// Found by fuzzing (tests/data/bad/fuzz/expression/min_max_mismatch): min/max named themselves in a
// unit mismatch through the text's pointer, read as a C string past the end of the view (ASan: a
// heap overflow) and quoting the rest of the text as the operator.
TEST(Units, MinMaxMismatchNamesOnlyTheFunction) {
  const std::string text = "max(1, 2 mm)TRAILING";
  try {
    foxi::evaluate_expression(std::string_view(text).substr(0, 12),
                              [](std::string_view) { return std::nullopt; });
    FAIL() << "no error";
  } catch (const foxi::ExpressionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unit mismatch: 1 (dimensionless) max m in 'max(1, 2 mm)'"), std::string::npos)
        << what;
    EXPECT_EQ(what.find("TRAILING"), std::string::npos) << what;
  }
}

// evaluate_in / evaluate_temperature: what foxi solve's options read (--power die=3W, --fix top=25degC).
template <class F>
std::string thrown(F f) {
  try {
    f();
  } catch (const foxi::ExpressionError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return {};
}

TEST(UnitsValue, ValuesInTheExpectedUnitBareNumbersSI) {
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("3 W", "W"), 3);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("3000 mW", "W"), 3);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("3", "W"), 3);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("150 W/(m*K)", "W/(m*K)"), 150);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("1.5 W/(mm*K)", "W/(m*K)"), 1500);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("2.6 ppm/K", "1/K"), 2.6e-6);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("130GPa", "Pa"), 130e9);
  EXPECT_DOUBLE_EQ(foxi::evaluate_in("5 mV", "V"), 5e-3);
  const std::string e = thrown([] { foxi::evaluate_in("3 m", "W"); });
  EXPECT_NE(e.find("unit mismatch: '3 m' is m, not W"), std::string::npos) << e;
  EXPECT_FALSE(thrown([] { foxi::evaluate_in("2 W", "W/(m*K)"); }).empty());
}

TEST(UnitsValue, TemperaturesAbsoluteAndDifferences) {
  using foxi::TemperatureKind;
  const auto abs = TemperatureKind::absolute, diff = TemperatureKind::difference;
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("300", abs), 300);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("300K", abs), 300);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("25 degC", abs), 298.15);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("25degC", abs), 298.15);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("25 \xC2\xB0"
                                              "C",
                                              abs),
                   298.15);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("-40 degC", abs), 233.15);
  // a difference: 5 degC is 5 K, never 278.15 K; negative differences are fine
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("5 degC", diff), 5);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("5K", diff), 5);
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("-100 K", diff), -100);
  // names resolve through the lookup, before degC too
  const auto t_amb = [](std::string_view n) -> std::optional<Quantity> {
    if (n == "t") return Quantity{20, foxi::kDimensionless};
    return std::nullopt;
  };
  EXPECT_DOUBLE_EQ(foxi::evaluate_temperature("t + 5 degC", abs, t_amb), 298.15);
  // below absolute zero, in K or in degC; the wrong dimension; degC inside an expression
  const std::string k = thrown([&] { foxi::evaluate_temperature("-5", abs); });
  EXPECT_NE(k.find("not above absolute zero"), std::string::npos) << k;
  EXPECT_NE(k.find("-5 degC"), std::string::npos) << k;  // the hint for Celsius
  EXPECT_NE(thrown([&] { foxi::evaluate_temperature("-300 degC", abs); }).find("absolute zero"),
            std::string::npos);
  EXPECT_NE(thrown([&] { foxi::evaluate_temperature("0 K", abs); }).find("absolute zero"), std::string::npos);
  EXPECT_NE(thrown([&] { foxi::evaluate_temperature("5 V", abs); }).find("not a temperature (K or degC)"),
            std::string::npos);
  EXPECT_NE(thrown([&] { foxi::evaluate_temperature("5 mm degC", diff); }).find("before degC"),
            std::string::npos);
  EXPECT_FALSE(thrown([&] { foxi::evaluate_temperature("5 degC + 1 K", abs); }).empty());
}

}  // namespace
