// foxi/structure.hpp: structure models, TOML files of parts, materials and conditions turned into a
// PLC for the mesher (foxi::structure), in one include. The entry points, one a line (declared in
// the topic headers below, which keep their foxi/model/ paths and say more):
//
//   load_model(path, overrides)                a model file as plain data in SI units, ParameterOverride
//   (model_file.hpp) build_structure(model, progress)           parts -> one conforming PLC, regions,
//   surfaces (structure.hpp) name_mesh(model, structure, mesh)          region, material and boundary names
//   on a mesh (structure.hpp) StructureCancelled                         building was cancelled
//   (structure.hpp) diagnose_model(model, structure)           what is unsound before meshing or solving
//   (diagnostics.hpp) warnings_for(diagnostics, physics)         the warnings that matter for one physics
//   (diagnostics.hpp) check_physics(model, physics)              what a solve of one physics needs is there
//   (physics.hpp) tag_selected_surfaces, check_conditions    named surfaces of the conditions (surfaces.hpp)
//   BoundaryCondition, condition_kind_name     conditions, loads and mesh controls (conditions.hpp)
//   evaluate_expression, evaluate_in           quantities with units: "die_w + 2 mm" (units.hpp)
//   ball_surface, read_stl                     closed triangle surfaces of parts (surface.hpp)
#pragma once

#include "foxi/model.hpp"
#include "foxi/model/conditions.hpp"
#include "foxi/model/diagnostics.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/structure.hpp"
#include "foxi/model/surface.hpp"
#include "foxi/model/surfaces.hpp"
#include "foxi/model/units.hpp"
