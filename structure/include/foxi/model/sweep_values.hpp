// The values a parameter sweep gives one parameter (foxi sweep --vary NAME=LO:HI:N or NAME=V1,V2,...,
// and the workbench's sweep from its history), as the parameter table and --set take them.
#pragma once

#include <string>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

struct SweepValues {
  std::vector<std::string> texts;  // as given to --set ("2.5mm")
  std::vector<double> si;          // their SI values
  std::string si_unit;             // "m", "W", "" (dimensionless)
  std::string unit;                // the unit the values are written in ("mm"; the first value's)
  double unit_si = 1;              // its SI value
};

// `count` values from `lo` to `hi` evenly ("2mm", "8mm", 4 -> 2mm, 4mm, 6mm, 8mm), written in lo's
// unit as "%.10g" and the unit. Throws ExpressionError (units.hpp) for a value that does not
// evaluate on its own (no parameter names), lo and hi of two dimensions, a count outside 1..10000, a
// unit the values cannot be written in.
FOXI_API SweepValues sweep_range(const std::string& lo, const std::string& hi, int count);

// The values as given (each evaluated on its own); the unit is the first value's when it converts,
// else SI. Throws ExpressionError for an empty or bad value, values of two dimensions.
FOXI_API SweepValues sweep_list(const std::vector<std::string>& values);

// The values of a spec as foxi sweep --vary takes it after NAME=: "LO:HI:N" (sweep_range) or
// "V1,V2,..." (sweep_list). Throws ExpressionError as those do, and for a spec of another form, a
// count that is not a whole number, an empty value.
FOXI_API SweepValues parse_sweep_values(const std::string& spec);

}  // namespace foxi
