// Placeholder until quality lands.
#include "foxi/model/quality.hpp"
#include <stdexcept>
namespace foxi {
TetQuality tet_quality(const double*, const double*, const double*, const double*) { throw std::logic_error("quality not built yet"); }
QualitySummary summarize_quality(const Mesh&) { throw std::logic_error("quality not built yet"); }
}  // namespace foxi
