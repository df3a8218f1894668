// What the field importer's readers promise for a source they return (fuzz_frd.cpp, fuzz_csv.cpp):
// every field has steps x entities x components values, the keys match the entities, and the
// source's mesh is consistent.
#pragma once

#include "foxi/fields/field_source.hpp"
#include "fuzz_util.hpp"

namespace foxi::fuzz {

inline void check_field_source(const FieldSource& s) {
  Mesh bare = s.mesh;  // the fields are checked below against the source's keys, not the mesh's nodes
  bare.fields.clear();
  check_read_mesh(bare);
  if (s.key == SourceKey::node_id && !s.mesh.xyz.empty())
    FOXI_FUZZ_CHECK(s.node_id.size() == s.mesh.node_count(), "node ids " + std::to_string(s.node_id.size()));
  for (const Field& f : s.mesh.fields) {
    FOXI_FUZZ_CHECK(f.components >= 1, f.name);
    FOXI_FUZZ_CHECK(f.values.size() == f.step_count() * s.entity_count(f) * f.components,
                    f.name + ": " + std::to_string(f.values.size()) + " values");
  }
}

}  // namespace foxi::fuzz
