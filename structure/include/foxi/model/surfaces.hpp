// Named surfaces of a built structure: the [surfaces] selectors of a model (conditions.hpp) turned
// into boundary markers, and the check that every condition names a surface that exists.
#pragma once

#include "foxi/api.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/structure.hpp"

namespace foxi {

// For each selector of model.surfaces, in order: appends a boundary marker named after it and moves
// to it every OUTER boundary facet (a part's .top/.bottom/.side, not an interface) whose vertices all
// lie in its plane or box (tolerance 1e-9 of the structure's size); the facet's area moves from its
// old boundary to the new one. Facets are taken whole: a box that cuts a facet leaves it alone.
// Throws IoError (model file, the selector's line) when a selector picks no facet or a facet another
// selector already took. build_structure calls it.
FOXI_API void tag_selected_surfaces(const Model& model, Structure& structure);

// Throws IoError (model file, the condition's line, naming the condition and the surface) when a
// condition names a boundary the structure lacks or whose facets all went to a selector, or when two
// conditions of one physics (thermal, electric, mechanical) share a surface. build_structure calls it.
FOXI_API void check_conditions(const Model& model, const Structure& structure);

}  // namespace foxi
