// Fuzz target: the parameter-expression parser (evaluate_expression), with a few names known to the
// lookup (one of them refers to itself through the lookup, as a circular parameter would). Any text
// gives a quantity or an ExpressionError; never a crash, a hang or another exception.
#include "foxi/model/units.hpp"
#include "fuzz_util.hpp"

namespace {

std::optional<foxi::Quantity> lookup(std::string_view name, int depth);

std::optional<foxi::Quantity> lookup(std::string_view name, int depth) {
  if (name == "w") return foxi::Quantity{4e-3, foxi::kLength};
  if (name == "n") return foxi::Quantity{3, foxi::kDimensionless};
  if (name == "k") return foxi::Quantity{150, {1, 1, -3, -1, 0}};
  // A parameter defined by another expression, which the lookup evaluates (nesting the parser).
  if (name == "r" && depth < 4)
    return foxi::evaluate_expression("2 * w + r",
                                     [depth](std::string_view n) { return lookup(n, depth + 1); });
  return std::nullopt;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    foxi::evaluate_expression(foxi::fuzz::as_text(data, size),
                              [](std::string_view n) { return lookup(n, 0); });
  } catch (const foxi::ExpressionError&) {
  }
  return 0;
}
