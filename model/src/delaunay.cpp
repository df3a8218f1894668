// Placeholder until the certificate lands.
#include "foxi/model/delaunay.hpp"
#include <stdexcept>
namespace foxi {
DelaunayCertificate compute_delaunay_certificate(const Mesh&, const CertificateOptions&) { throw std::logic_error("certificate not built yet"); }
const DelaunayCertificate& delaunay_certificate(const Mesh&) { throw std::logic_error("certificate not built yet"); }
}  // namespace foxi
