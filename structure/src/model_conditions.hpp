// Reading the [surfaces], [[conditions]], [[loads]] and [mesh] tables of a model file (conditions.hpp)
// once its parameters and parts are loaded; kept apart from the part shapes of model_file.cpp.
#pragma once

#include <map>
#include <string_view>
#include <toml.hpp>
#include <vector>

#include "foxi/model/model_file.hpp"

namespace foxi {

using ModelToml = toml::basic_value<toml::discard_comments, std::map, std::vector>;

// True for the top-level keys read here: surfaces, conditions, loads, mesh.
bool is_conditions_key(std::string_view key);

// Fills model.surfaces, conditions, loads and mesh from `root`. Needs model.parameters (evaluated),
// parts, length_scale and file. Throws IoError (model.file, the line, a reason naming the entity).
void read_model_conditions(const ModelToml& root, Model& model);

}  // namespace foxi
