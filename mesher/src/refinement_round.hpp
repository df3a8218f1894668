// Internal to the mesher: one round of a refinement loop (conforming.cpp, layer_refinement.cpp) —
// TetGen on the current PLC, the guards, and the exact certificate — with the report kept alike.
#pragma once

#include <cstdint>
#include <map>
#include <optional>

#include "foxi/mesher/conforming.hpp"
#include "foxi/model/delaunay.hpp"

namespace foxi::detail {

class RefinementRounds {
 public:
  RefinementRounds(const MeshParams& tetgen_params, ConformingReport& rep)
      : params_(tetgen_params), rep_(rep) {}

  // Meshes `current` (round `it`, 0 first) into `mesh` and certifies it, filling the report's
  // violations, first-mesh figures and `delaunay`. A later round whose TetGen run fails (code 2) or
  // whose mesh has other regions or region volumes than the first (TetGen lost a facet and a region
  // leaked) is rejected: `current` and `mesh` go back to what keep() saved, rep.tetgen_failed is set
  // and nothing is returned. Other errors (a bad PLC, cancel) propagate.
  // With `mesh_given`, round 0 takes `mesh` as TetGen's mesh of `current` instead of running TetGen.
  std::optional<DelaunayCertificate> run(std::size_t it, Plc& current, Mesh& mesh, bool mesh_given = false);

  // Saves the PLC and mesh a rejected next round returns to; call before editing `current`.
  void keep(const Plc& current, const Mesh& mesh) {
    previous_ = current;
    previous_mesh_ = mesh;
  }

 private:
  const MeshParams& params_;
  ConformingReport& rep_;
  Plc previous_;
  Mesh previous_mesh_;
  std::map<std::int32_t, double> first_volumes_;
  double first_seconds_ = 0;  // round 0's TetGen run (0 when round 0's mesh was given)
};

}  // namespace foxi::detail
