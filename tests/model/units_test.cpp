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
}

// Found by fuzzing (tests/data/bad/fuzz/expression/min_max_mismatch): min/max named themselves in a
// unit mismatch through the text's pointer, read as a C string past the end of the view (ASan: a
// heap overflow) and quoting the rest of the text as the operator.
TEST(Units, MinMaxMismatchNamesOnlyTheFunction) {
  const std::string text = "max(1, 2 mm)TRAILING";
  try {
    foxi::evaluate_expression(std::string_view(text).substr(0, 12), [](std::string_view) { return std::nullopt; });
    FAIL() << "no error";
  } catch (const foxi::ExpressionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unit mismatch: 1 (dimensionless) max m in 'max(1, 2 mm)'"), std::string::npos) << what;
    EXPECT_EQ(what.find("TRAILING"), std::string::npos) << what;
  }
}

}  // namespace
