// Units and expressions: a small recursive-descent evaluator that carries dimensions.
#include "foxi/model/units.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <vector>

namespace foxi {

namespace {

struct UnitDef {
  const char* name;
  double scale;
  Dims dims;
};

constexpr Dims kMass = {0, 1, 0, 0, 0}, kTime = {0, 0, 1, 0, 0}, kTemp = {0, 0, 0, 1, 0},
               kCurrent = {0, 0, 0, 0, 1};
constexpr Dims kPower = {2, 1, -3, 0, 0}, kEnergy = {2, 1, -2, 0, 0}, kVolt = {2, 1, -3, 0, -1},
               kSiemens = {-2, -1, 3, 0, 2}, kForce = {1, 1, -2, 0, 0}, kPressure = {-1, 1, -2, 0, 0},
               kHertz = {0, 0, -1, 0, 0};

const UnitDef kUnits[] = {
    {"m", 1, kLength},
    {"cm", 1e-2, kLength},
    {"mm", 1e-3, kLength},
    {"um", 1e-6, kLength},
    {"\xC2\xB5m", 1e-6, kLength},
    {"nm", 1e-9, kLength},
    {"in", 0.0254, kLength},
    {"mil", 2.54e-5, kLength},
    {"K", 1, kTemp},
    {"s", 1, kTime},
    {"ms", 1e-3, kTime},
    {"us", 1e-6, kTime},
    {"\xC2\xB5s", 1e-6, kTime},
    {"ns", 1e-9, kTime},
    {"kg", 1, kMass},
    {"g", 1e-3, kMass},
    {"W", 1, kPower},
    {"mW", 1e-3, kPower},
    {"kW", 1e3, kPower},
    {"J", 1, kEnergy},
    {"V", 1, kVolt},
    {"mV", 1e-3, kVolt},
    {"kV", 1e3, kVolt},
    {"A", 1, kCurrent},
    {"mA", 1e-3, kCurrent},
    {"uA", 1e-6, kCurrent},
    {"S", 1, kSiemens},
    {"N", 1, kForce},
    {"Pa", 1, kPressure},
    {"kPa", 1e3, kPressure},
    {"MPa", 1e6, kPressure},
    {"GPa", 1e9, kPressure},
    {"Hz", 1, kHertz},
    {"ppm", 1e-6, kDimensionless},
};

Dims add_dims(const Dims& a, const Dims& b, int sign) {
  Dims r{};
  for (int i = 0; i < 5; ++i) r[i] = static_cast<std::int8_t>(a[i] + sign * b[i]);
  return r;
}

// Bounds that keep a hostile expression from exhausting the stack (the parser recurses once per
// parenthesis, unary sign, exponent or call) or the time (each number copies the rest of the text).
constexpr std::size_t kMaxLength = kMaxExpressionLength;
constexpr int kMaxDepth = kMaxExpressionDepth;
constexpr int kMaxUnitPower = 100;  // unit exponents are int8_t

class Parser {
 public:
  Parser(std::string_view text, const std::function<std::optional<Quantity>(std::string_view)>& lookup)
      : s_(text), lookup_(lookup) {}

  Quantity parse() {
    if (s_.size() > kMaxLength)
      fail("the expression is " + std::to_string(s_.size()) + " characters long, more than the limit of " +
           std::to_string(kMaxLength));
    Quantity q = expr();
    skip();
    if (p_ < s_.size()) fail("unexpected '" + std::string(1, s_[p_]) + "'");
    if (!std::isfinite(q.value)) fail("the value is not a finite number");
    return q;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    // a long expression is quoted by its start only
    const std::string quoted = s_.size() <= 80 ? std::string(s_) : std::string(s_.substr(0, 60)) + "...";
    throw ExpressionError(why + " in '" + quoted + "'");
  }
  // Counts one level of recursion (parenthesis, sign, exponent, call) for as long as it lives.
  struct Nest {
    explicit Nest(Parser& p) : p_(p) {
      if (++p_.depth_ > kMaxDepth)
        p_.fail("the expression nests deeper than " + std::to_string(kMaxDepth) +
                " levels (parentheses, signs, exponents, calls)");
    }
    ~Nest() { --p_.depth_; }
    Nest(const Nest&) = delete;
    Nest& operator=(const Nest&) = delete;
    Parser& p_;
  };
  void skip() {
    while (p_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[p_]))) ++p_;
  }
  bool eat(char c) {
    skip();
    if (p_ < s_.size() && s_[p_] == c) {
      ++p_;
      return true;
    }
    return false;
  }
  static bool ident_start(char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || static_cast<unsigned char>(c) >= 0x80;
  }
  static bool ident_char(char c) {
    return ident_start(c) || std::isdigit(static_cast<unsigned char>(c)) || c == '.';
  }
  bool at_ident() {
    skip();
    return p_ < s_.size() && ident_start(s_[p_]);
  }
  std::string_view ident() {
    skip();
    std::size_t b = p_;
    while (p_ < s_.size() && ident_char(s_[p_])) ++p_;
    return s_.substr(b, p_ - b);
  }
  // op: "+", "-", or a function's name (a view into the text, not NUL-terminated).
  void same(const Quantity& a, const Quantity& b, std::string_view op) const {
    if (a.dims != b.dims)
      fail("unit mismatch: " + dims_to_string(a.dims) + " " + std::string(op) + " " + dims_to_string(b.dims));
  }

  // a * b (sign 1) or a / b (sign -1) of the units, refused where an exponent would leave int8_t
  Dims combine(const Dims& a, const Dims& b, int sign) const {
    for (int i = 0; i < 5; ++i)
      if (std::abs(a[i] + sign * b[i]) > kMaxUnitPower)
        fail("a unit raised past the power " + std::to_string(kMaxUnitPower));
    return add_dims(a, b, sign);
  }

  Quantity expr() {
    Quantity a = term();
    for (;;) {
      if (eat('+')) {
        Quantity b = term();
        same(a, b, "+");
        a.value += b.value;
      } else if (eat('-')) {
        Quantity b = term();
        same(a, b, "-");
        a.value -= b.value;
      } else {
        return a;
      }
    }
  }
  Quantity term() {
    Quantity a = unary();
    for (;;) {
      if (eat('*')) {
        Quantity b = unary();
        a = {a.value * b.value, combine(a.dims, b.dims, 1)};
      } else if (eat('/')) {
        Quantity b = unary();
        a = {a.value / b.value, combine(a.dims, b.dims, -1)};
      } else {
        return a;
      }
    }
  }
  Quantity unary() {
    if (eat('-')) {
      const Nest nest(*this);
      Quantity a = unary();
      a.value = -a.value;
      return a;
    }
    if (eat('+')) {
      const Nest nest(*this);
      return unary();
    }
    return power();
  }
  Quantity raise(Quantity base, const Quantity& e) const {
    if (e.dims != kDimensionless) fail("the exponent must be dimensionless, not " + dims_to_string(e.dims));
    if (base.dims != kDimensionless) {
      const double n = std::round(e.value);
      if (n != e.value || std::abs(n) > 20) fail("a quantity with units takes only small integer exponents");
      for (auto& d : base.dims) {
        const int x = d * static_cast<int>(n);
        if (std::abs(x) > kMaxUnitPower)
          fail("a unit raised past the power " + std::to_string(kMaxUnitPower));
        d = static_cast<std::int8_t>(x);
      }
    }
    base.value = std::pow(base.value, e.value);
    return base;
  }
  Quantity power() {
    Quantity a = primary();
    if (eat('^')) {
      const Nest nest(*this);
      return raise(a, unary());
    }
    return a;
  }
  Quantity name_value(std::string_view name) {
    if (auto q = lookup_(name)) return *q;
    if (auto u = unit_quantity(name)) return *u;
    if (name == "pi") return {std::numbers::pi, kDimensionless};
    fail("unknown parameter '" + std::string(name) + "'");
  }
  Quantity primary() {
    skip();
    if (p_ >= s_.size()) fail("unexpected end, expected a number or a name");
    const char c = s_[p_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      // Decimal only: strtod alone also read hexadecimal ("0x10" was 16, "0x1p-3 mm" 0.125 mm), "inf"
      // and "nan" after a digit never occur here.
      std::size_t n = p_;
      auto digits = [&] {
        const std::size_t at = n;
        while (n < s_.size() && std::isdigit(static_cast<unsigned char>(s_[n]))) ++n;
        return n > at;
      };
      bool any = digits();
      if (n < s_.size() && s_[n] == '.') {
        ++n;
        any = digits() || any;
      }
      if (!any) fail("bad number");
      if (n < s_.size() && (s_[n] == 'e' || s_[n] == 'E')) {
        const std::size_t mantissa_end = n++;
        if (n < s_.size() && (s_[n] == '+' || s_[n] == '-')) ++n;
        if (!digits()) n = mantissa_end;  // "2e" is 2 and a unit "e" (unknown)
      }
      const std::string tmp(s_.substr(p_, n - p_));
      const double v = std::strtod(tmp.c_str(), nullptr);
      p_ = n;
      Quantity q{v, kDimensionless};
      if (at_ident()) {  // a unit right after a number: "8 mm", "2um", "150 W"
        const std::size_t at = p_;
        std::string_view u = ident();
        auto uq = unit_quantity(u);
        if (!uq) {
          p_ = at;
          if (u == "degC")  // an offset unit: only a whole absolute temperature may end with it
            fail(
                "degC is an absolute temperature with an offset: write it only at the end of a "
                "condition's temperature (\"25 degC\"); in expressions use K");
          fail("unknown unit '" + std::string(u) + "'");
        }
        Quantity unit = *uq;
        if (eat('^')) {
          const Nest nest(*this);
          unit = raise(unit, primary());
        }
        q = {q.value * unit.value, unit.dims};
      }
      return q;
    }
    if (eat('(')) {
      const Nest nest(*this);
      Quantity q = expr();
      if (!eat(')')) fail("missing ')'");
      return q;
    }
    if (ident_start(c)) {
      std::string_view name = ident();
      if (eat('(')) return call(name);
      return name_value(name);
    }
    fail("unexpected '" + std::string(1, c) + "'");
  }
  Quantity call(std::string_view f) {
    const Nest nest(*this);
    std::vector<Quantity> args;
    if (!eat(')')) {
      do args.push_back(expr());
      while (eat(','));
      if (!eat(')')) fail("missing ')' after the arguments of " + std::string(f));
    }
    auto want = [&](std::size_t n) {
      if (args.size() != n) fail(std::string(f) + " takes " + std::to_string(n) + " argument(s)");
    };
    auto dimensionless = [&]() {
      for (auto& a : args)
        if (a.dims != kDimensionless)
          fail(std::string(f) + " takes a dimensionless argument, not " + dims_to_string(a.dims));
    };
    if (f == "sqrt") {
      want(1);
      for (auto d : args[0].dims)
        if (d % 2 != 0) fail("sqrt of " + dims_to_string(args[0].dims) + " has no whole unit");
      Quantity r{std::sqrt(args[0].value), {}};
      for (int i = 0; i < 5; ++i) r.dims[i] = static_cast<std::int8_t>(args[0].dims[i] / 2);
      return r;
    }
    if (f == "abs") {
      want(1);
      return {std::abs(args[0].value), args[0].dims};
    }
    if (f == "min" || f == "max") {
      if (args.empty()) fail(std::string(f) + " takes at least one argument");
      Quantity r = args[0];
      for (auto& a : args) {
        same(r, a, f);
        r.value = f == "min" ? std::min(r.value, a.value) : std::max(r.value, a.value);
      }
      return r;
    }
    want(1);
    dimensionless();
    const double x = args[0].value;
    if (f == "sin") return {std::sin(x), {}};
    if (f == "cos") return {std::cos(x), {}};
    if (f == "tan") return {std::tan(x), {}};
    if (f == "exp") return {std::exp(x), {}};
    if (f == "log") return {std::log(x), {}};
    fail("unknown function '" + std::string(f) + "'");
  }

  std::string_view s_;
  const std::function<std::optional<Quantity>(std::string_view)>& lookup_;
  std::size_t p_ = 0;
  int depth_ = 0;
};

}  // namespace

std::string dims_to_string(const Dims& d) {
  static const char* kNames[5] = {"m", "kg", "s", "K", "A"};
  std::string out;
  for (int i = 0; i < 5; ++i) {
    if (d[i] == 0) continue;
    if (!out.empty()) out += ' ';
    out += kNames[i];
    if (d[i] != 1) out += "^" + std::to_string(d[i]);
  }
  return out.empty() ? "1 (dimensionless)" : out;
}

std::optional<Quantity> unit_quantity(std::string_view name) {
  for (const auto& u : kUnits)
    if (name == u.name) return Quantity{u.scale, u.dims};
  return std::nullopt;
}

Quantity evaluate_expression(std::string_view text,
                             const std::function<std::optional<Quantity>(std::string_view)>& lookup) {
  return Parser(text, lookup).parse();
}

namespace {

std::optional<Quantity> no_names(std::string_view) { return std::nullopt; }

}  // namespace

double evaluate_in(std::string_view text, std::string_view unit) {
  const Quantity want = evaluate_expression(unit, no_names);
  const Quantity q = evaluate_expression(text, no_names);
  if (q.dims == kDimensionless) return q.value * want.value;  // a bare number: SI
  if (q.dims != want.dims)
    throw ExpressionError("unit mismatch: '" + std::string(text) + "' is " + dims_to_string(q.dims) +
                          ", not " + std::string(unit) + " (" + dims_to_string(want.dims) + ")");
  return q.value;
}

double evaluate_temperature(std::string_view text, TemperatureKind kind,
                            const std::function<std::optional<Quantity>(std::string_view)>& lookup) {
  constexpr double kCelsiusOffset = 273.15;
  const bool absolute = kind == TemperatureKind::absolute;
  const auto& names = lookup ? lookup : std::function<std::optional<Quantity>(std::string_view)>(no_names);
  std::string_view s = text;
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  double t = 0;
  bool celsius = false;
  for (std::string_view suffix : {std::string_view("degC"), std::string_view("\xC2\xB0"
                                                                             "C")}) {
    if (s.size() <= suffix.size() || s.substr(s.size() - suffix.size()) != suffix) continue;
    const std::string_view before = s.substr(0, s.size() - suffix.size());
    const Quantity q = evaluate_expression(before, names);
    if (q.dims != kDimensionless)
      throw ExpressionError("unit mismatch: '" + std::string(s) + "' puts " + dims_to_string(q.dims) +
                            " before degC");
    t = q.value + (absolute ? kCelsiusOffset : 0.0);
    celsius = true;
    break;
  }
  if (!celsius) {
    const Quantity q = evaluate_expression(s, names);
    if (q.dims != kDimensionless && q.dims != kTemp)
      throw ExpressionError("unit mismatch: '" + std::string(s) + "' is " + dims_to_string(q.dims) +
                            ", not a temperature (K or degC)");
    t = q.value;
  }
  if (absolute && !(t > 0)) {
    char buf[160];
    if (celsius)
      std::snprintf(buf, sizeof buf, " = %g K is not above absolute zero", t);
    else
      std::snprintf(buf, sizeof buf, " = %g K is not above absolute zero (for Celsius write \"%g degC\")", t,
                    t);
    throw ExpressionError("'" + std::string(s) + "'" + buf);
  }
  return t;
}

}  // namespace foxi
