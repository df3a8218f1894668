// Shared by foxi solve, foxi model show and foxi demo: a model file taken to a named mesh, and the
// report of its conditions, loads and mesh controls.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cli.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/structure.hpp"

namespace foxi::cli {

// True for a path naming a model file (.toml) rather than a mesh.
bool is_model_path(const std::string& path);

// --max-tets N (a whole number >= 1; UsageError otherwise), or kDefaultMaxTets.
double max_tets_option(Args& args);

// The --set texts (NAME=VALUE) of the model file `file` as overrides; messages name --set.
std::vector<ParameterOverride> set_overrides(const std::string& file, std::span<const std::string> sets);

// foxi::mesh_model (mesher/model_mesh.hpp) with the --set texts, messages naming --set.
MeshedModel mesh_model_from_sets(const std::string& file, std::span<const std::string> sets,
                                 ModelMeshOptions options = {});

// The message of a tet-limit refusal as the CLI says it (naming --max-tets).
std::string tet_limit_message(const TetLimitError& e);

// mesh_model for foxi solve MODEL --physics NAME: prints one line on the model and its mesh.
MeshedModel mesh_model_for_solve(const std::string& file, std::span<const std::string> sets,
                                 const std::string& physics, double size_scale = 1,
                                 double max_tets = kDefaultMaxTets);

// Prints the model's [surfaces], conditions, loads and mesh controls (lengths in its unit).
void print_model_conditions(const Model& model);

}  // namespace foxi::cli
