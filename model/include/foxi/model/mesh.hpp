// The common mesh database: the one structure every foxi library reads and writes.
//
// Plain data, structure of arrays, std::uint32_t indices with kNone as "no index". All quantities in
// SI units (metres, kelvin, ...). Derived data (face adjacency, circumspheres, the Delaunay
// certificate) is never stored here twice: it is computed on demand by the functions that own it and
// cached in `derived`, which a copy of the mesh does not share.
//
// Host-owned data: a Mesh owns its arrays. A host that keeps its own coordinates, tets and regions
// hands them to the ordering, the painter, the pictures and the checks as a MeshView (mesh_view.hpp:
// std::span over its arrays, no copy; that header lists which entry points take a view and which
// take a Mesh); for the rest (readers, writers, mesher, solvers, named fields) it moves or copies
// them into a Mesh once. Either way nothing is copied after that: the certificate and adjacency are
// cached (here, or in the host's DerivedCache for a view), the sphere table is a value the caller
// keeps, orders and subsets go as std::span, the solvers add their result fields to the Mesh.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

inline constexpr std::uint32_t kNone = 0xffffffffu;

// Material properties in SI units; NaN means "not given".
struct Material {
  static constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  std::string name;
  double thermal_conductivity = kUnset;     // W/(m K)
  double electrical_conductivity = kUnset;  // S/m
  double relative_permittivity = kUnset;    // 1
  double youngs_modulus = kUnset;           // Pa
  double poisson_ratio = kUnset;            // 1
  double thermal_expansion = kUnset;        // 1/K
  double density = kUnset;                  // kg/m^3 (transient heat: rho c dT/dt)
  double specific_heat = kUnset;            // J/(kg K), at constant pressure
};

// A region (a part, a physical volume group): tets whose tet_region equals `id`.
struct Region {
  std::int32_t id = 0;
  std::string name;                // may be empty
  std::uint32_t material = kNone;  // index into Mesh::materials, or kNone
};

// A named boundary: boundary triangles whose bface_tag equals `tag`.
struct Boundary {
  std::int32_t tag = 0;
  std::string name;  // may be empty
};

enum class FieldLocation : std::uint8_t { node, cell };

// A named field on nodes or on cells, with `components` values per entity (1 scalar, 3 vector,
// 6 symmetric tensor in the order xx yy zz xy yz xz, 9 full tensor row-major; other counts are kept
// as they are). Several steps (time or load steps) are stored one after the other:
// values[(step * entity_count + entity) * components + component].
struct Field {
  std::string name;
  FieldLocation location = FieldLocation::node;
  std::uint32_t components = 1;
  std::string unit;                 // SI unit symbol, may be empty
  std::vector<double> step_values;  // time or load value of each step; size = step count (>= 1)
  std::vector<double> values;

  std::size_t step_count() const { return step_values.empty() ? 1 : step_values.size(); }
  // Values of one step: entity_count * components doubles.
  std::span<const double> step(std::size_t s, std::size_t entity_count) const {
    return std::span<const double>(values).subspan(s * entity_count * components, entity_count * components);
  }
};

struct DerivedData;  // defined by the derived-data functions (adjacency.hpp, delaunay.hpp, ...)

// Holds derived data; copying gives an empty cache so that copies never share stale results.
class FOXI_API DerivedCache {
 public:
  DerivedCache() = default;
  DerivedCache(const DerivedCache&) {}
  DerivedCache& operator=(const DerivedCache&) {
    data_.reset();
    return *this;
  }
  DerivedCache(DerivedCache&&) noexcept = default;
  DerivedCache& operator=(DerivedCache&&) noexcept = default;
  ~DerivedCache();
  void clear() { data_.reset(); }
  DerivedData& get() const;  // creates the (empty) data on first use
 private:
  mutable std::shared_ptr<DerivedData> data_;
};

struct FOXI_API Mesh {
  std::vector<double> xyz;               // 3 per node
  std::vector<std::uint32_t> tet;        // 4 per tet, positively oriented (see validate.hpp)
  std::vector<std::int32_t> tet_region;  // 1 per tet (region id), or empty = all region 0
  std::vector<Region> regions;           // id -> name and material
  std::vector<Material> materials;
  std::vector<std::uint32_t> bface;     // 3 per boundary triangle
  std::vector<std::int32_t> bface_tag;  // 1 per boundary triangle (boundary tag)
  std::vector<Boundary> boundaries;     // tag -> name
  std::vector<double> weight;           // 1 per node (regular triangulation), or empty
  std::vector<Field> fields;
  DerivedCache derived;  // see invalidate_derived()

  std::size_t node_count() const { return xyz.size() / 3; }
  std::size_t tet_count() const { return tet.size() / 4; }
  std::size_t bface_count() const { return bface.size() / 3; }
  std::int32_t region_of(std::size_t t) const { return tet_region.empty() ? 0 : tet_region[t]; }

  const Field* find_field(std::string_view name) const;
  const Region* find_region(std::int32_t id) const;
  const Boundary* find_boundary(std::int32_t tag) const;
};

// Drops every cached derived result. Call after changing xyz, tet or weight in place; the functions
// of foxi that change a mesh call it themselves.
FOXI_API void invalidate_derived(Mesh& mesh);

// Entity count a field's location refers to (node_count or tet_count).
FOXI_API std::size_t field_entity_count(const Mesh& mesh, const Field& field);

// Checks the sizes of every array against each other (xyz % 3, tet % 4, tet_region, bface_tag,
// weight, field value counts). Returns an empty string when consistent, else the first problem.
FOXI_API std::string check_sizes(const Mesh& mesh);

// Name-or-number lookups, as a user names a region or a boundary: `key` written as a whole number
// (decimal, optional sign) is that id or tag as it is (it need not be listed); otherwise the id of the
// region, the tag of the boundary, with that name (an empty key names none). nullopt when neither.
FOXI_API std::optional<std::int32_t> region_id_of(const Mesh& mesh, std::string_view key);
FOXI_API std::optional<std::int32_t> boundary_tag_of(const Mesh& mesh, std::string_view key);

}  // namespace foxi
