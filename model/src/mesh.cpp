#include "foxi/model/mesh.hpp"

#include <cerrno>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "derived.hpp"

namespace foxi {

DerivedCache::~DerivedCache() = default;

DerivedData& DerivedCache::get() const {
  if (!data_) data_ = std::make_shared<DerivedData>();
  return *data_;
}

DerivedData& derived_of(const MeshView& mesh) {
  if (mesh.derived == nullptr)
    throw std::invalid_argument(
        "mesh view: no DerivedCache to keep its adjacency and certificate in (MeshView::derived is null)");
  DerivedData& d = mesh.derived->get();
  std::lock_guard<std::mutex> g(d.lock);
  if (d.nodes != mesh.node_count() || d.tets != mesh.tet_count() || d.xyz != mesh.xyz.data() ||
      d.tet != mesh.tet.data()) {
    d.adjacency.reset();
    d.certificate.reset();
    d.nodes = mesh.node_count();
    d.tets = mesh.tet_count();
    d.xyz = mesh.xyz.data();
    d.tet = mesh.tet.data();
  }
  return d;
}

std::string check_sizes(const MeshView& mesh) {
  if (mesh.xyz.size() % 3 != 0)
    return "xyz holds " + std::to_string(mesh.xyz.size()) + " values, not a multiple of 3";
  if (mesh.tet.size() % 4 != 0)
    return "tet holds " + std::to_string(mesh.tet.size()) + " indices, not a multiple of 4";
  if (mesh.bface.size() % 3 != 0)
    return "bface holds " + std::to_string(mesh.bface.size()) + " indices, not a multiple of 3";
  if (!mesh.tet_region.empty() && mesh.tet_region.size() != mesh.tet_count())
    return "tet_region has " + std::to_string(mesh.tet_region.size()) + " entries for " +
           std::to_string(mesh.tet_count()) + " tets";
  if (!mesh.weight.empty() && mesh.weight.size() != mesh.node_count())
    return "weight has " + std::to_string(mesh.weight.size()) + " entries for " +
           std::to_string(mesh.node_count()) + " nodes";
  return {};
}

void invalidate_derived(Mesh& mesh) { mesh.derived.clear(); }

const Field* Mesh::find_field(std::string_view name) const {
  for (const Field& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}
const Region* Mesh::find_region(std::int32_t id) const {
  for (const Region& r : regions)
    if (r.id == id) return &r;
  return nullptr;
}
const Boundary* Mesh::find_boundary(std::int32_t tag) const {
  for (const Boundary& b : boundaries)
    if (b.tag == tag) return &b;
  return nullptr;
}

std::size_t field_entity_count(const Mesh& mesh, const Field& field) {
  return field.location == FieldLocation::node ? mesh.node_count() : mesh.tet_count();
}

std::string check_sizes(const Mesh& mesh) {
  // The arrays a view shares are checked by the view's rule; then what only a Mesh holds.
  if (std::string why = check_sizes(MeshView(mesh)); !why.empty()) return why;
  if (mesh.bface_tag.size() != mesh.bface_count())
    return "bface_tag has " + std::to_string(mesh.bface_tag.size()) + " entries for " +
           std::to_string(mesh.bface_count()) + " boundary triangles";
  for (const Region& r : mesh.regions)
    if (r.material != kNone && r.material >= mesh.materials.size())
      return "region " + std::to_string(r.id) + " names material " + std::to_string(r.material) + " of " +
             std::to_string(mesh.materials.size());
  for (const Field& f : mesh.fields) {
    if (f.components == 0) return "field '" + f.name + "' has 0 components";
    std::size_t want = f.step_count() * field_entity_count(mesh, f) * f.components;
    if (f.values.size() != want)
      return "field '" + f.name + "' has " + std::to_string(f.values.size()) + " values, expected " +
             std::to_string(want);
  }
  return {};
}

namespace {

// A whole number as strtol reads it, the whole key consumed (the CLI's reading before this moved).
bool whole_number(std::string_view key, std::int32_t& out) {
  const std::string s(key);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size()) return false;
  // Not one past the ids' range (4294967297 is no region, not region 1 after a cast).
  if (errno == ERANGE || v < std::numeric_limits<std::int32_t>::min() ||
      v > std::numeric_limits<std::int32_t>::max())
    return false;
  out = static_cast<std::int32_t>(v);
  return true;
}

}  // namespace

std::optional<std::int32_t> region_id_of(const Mesh& mesh, std::string_view key) {
  std::int32_t id = 0;
  if (whole_number(key, id)) return id;
  if (key.empty()) return std::nullopt;  // not the unnamed regions
  for (const Region& r : mesh.regions)
    if (r.name == key) return r.id;
  return std::nullopt;
}

std::optional<std::int32_t> boundary_tag_of(const Mesh& mesh, std::string_view key) {
  std::int32_t tag = 0;
  if (whole_number(key, tag)) return tag;
  if (key.empty()) return std::nullopt;
  for (const Boundary& b : mesh.boundaries)
    if (b.name == key) return b.tag;
  return std::nullopt;
}

}  // namespace foxi
