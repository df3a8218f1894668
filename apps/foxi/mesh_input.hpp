// The one gate every command's mesh passes: validation, the repair it allows, and refusal.
#pragma once

#include <string>

#include "foxi/model/mesh.hpp"
#include "foxi/model/validate.hpp"

namespace foxi::cli {

// Validates `mesh` (named `name` in messages) and re-orients its inverted tets, saying so on stderr
// as "foxi COMMAND: note: ..."; throws InputError (exit 3) naming the file and its first problems
// when validation calls it unusable (no tets, bad indices, non-finite or out-of-range geometry,
// flat or duplicate tets, coincident nodes). Returns the report (as found, before the repair).
ValidationReport require_usable(Mesh& mesh, const std::string& name, const char* command);

// read_mesh(path) (a .pvd collection: the field importer's mesh, every data set a step), then require_usable.
Mesh read_usable_mesh(const std::string& path, const char* command);

}  // namespace foxi::cli
