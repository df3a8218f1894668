// Placeholder until validation lands.
#include "foxi/model/validate.hpp"
#include <stdexcept>
namespace foxi {
ValidationReport validate(const Mesh&) { throw std::logic_error("validation not built yet"); }
ValidationReport validate_and_repair(Mesh&) { throw std::logic_error("validation not built yet"); }
}  // namespace foxi
