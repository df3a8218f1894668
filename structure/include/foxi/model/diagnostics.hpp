// What a model's geometry and conditions leave unsound before anything is meshed or solved: parts
// that touch nothing, parts that overhang what they sit on, and, per physics, groups of parts that no
// condition ties to a fixed value. Computed from the built structure's interfaces ("A/B" boundaries
// and their areas) and facets, and from the model's conditions and materials; plain data, the apps
// print it (foxi model check, and foxi solve MODEL before solving).
//
// Why these: a part that touches no other part exchanges nothing with them (a die floating above its
// substrate heats up without bound, limited only by its own convection: 2659 degC without a word);
// an overhang leaves the part's bottom beside its support insulated (a die wider than its attach); a
// group of parts with no fixed value has a solution only up to a constant (or a rigid motion).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/structure.hpp"

namespace foxi {

enum class ModelWarningKind : std::uint8_t {
  // `parts` (a group of parts joined by interfaces) touches no other part of the model: every part
  // of the model not in the group is at zero contact area from it (touching along an edge or at a
  // point counts as nothing). Reported for every group but the largest by volume.
  isolated,
  // `parts[0]` sits on `supports` at height `z`, but `area` of its bottom at that height lies outside
  // the convex hull of its contact with them (exposed, insulated unless a condition says otherwise);
  // `fraction` is that area over the part's whole bottom area at that height. The part's bottom
  // between the supports (a die on bumps, a clip bridging two posts) is inside the hull and is not an
  // overhang.
  overhang,
  // `physics`: the group `parts` (joined through parts that carry it) has no condition that fixes
  // its value on any of its boundaries: temperature or convection (thermal), voltage or ground
  // (electrostatic, current), displacement or sliding (thermoelastic; whether sliding planes alone
  // hold every rigid motion is the solver's check).
  no_fixed_value,
};

struct ModelWarning {
  ModelWarningKind kind = ModelWarningKind::isolated;
  Physics physics = Physics::thermal;  // no_fixed_value only
  std::vector<std::string> parts;      // in file order
  std::vector<std::string> supports;   // overhang: the parts below, in file order
  double volume = 0;                   // isolated, no_fixed_value: the group's volume (m^3)
  double z = 0;                        // overhang: the height of the part's bottom (m)
  double area = 0;                     // overhang: the exposed area outside the supports' hull (m^2)
  double fraction = 0;                 // overhang: area / the part's bottom area at z
};

struct ModelDiagnostics {
  std::vector<ModelWarning> warnings;  // isolated, then overhang, then no_fixed_value by physics
};

struct DiagnosticsParams {
  // Overhangs smaller than this fraction of the part's bottom at that height are not reported
  // (round-off of faceted contacts, a part flush with its support's edge).
  double min_overhang_fraction = 1e-3;
};

// Every warning of `model` built as `structure` (build_structure). no_fixed_value is looked for only
// in the physics whose conditions the model has (at least one condition of that physics that fixes
// a value): a model with none is not ready for that physics at all, which check_physics says.
// A part conducts in a physics when its material has the property and it is positive (thermal
// conductivity, permittivity, electrical conductivity; Young's modulus): a part that does not is left
// out of that physics' groups and joins nothing.
FOXI_API ModelDiagnostics diagnose_model(const Model& model, const Structure& structure,
                                         const DiagnosticsParams& params = {});

// The warnings of `d` that concern `physics`: isolated and overhang, and no_fixed_value of `physics`.
FOXI_API std::vector<ModelWarning> warnings_for(const ModelDiagnostics& d, Physics physics);

// One line in words, lengths in the model's unit: "part 'die' touches no other part ...".
FOXI_API std::string describe(const ModelWarning& w, const Model& model);

}  // namespace foxi
