// Shared by foxi solve, foxi model show and foxi demo: a model file taken to a named mesh, and the
// report of its conditions, loads and mesh controls.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/structure.hpp"

namespace foxi::cli {

// True for a path naming a model file (.toml) rather than a mesh.
bool is_model_path(const std::string& path);

struct MeshedModel {
  Model model;
  Structure structure;
  Mesh mesh;  // regions named after the parts, boundaries after the structure's surfaces
  MeshReport report;            // the last TetGen run
  ConformingReport conforming;  // the conforming refinement (certificate, thin layers)
};

// Loads `file` with the --set overrides, checks what `physics` needs (before meshing), builds the
// PLC and meshes it with the model's [mesh] controls; `coarse` keeps only its quality bounds.
// Errors: IoError from the model, MesherError from TetGen.
MeshedModel mesh_model(const std::string& file, std::span<const std::string> sets,
                       std::optional<Physics> physics, bool coarse = false);

// mesh_model for foxi solve MODEL --physics NAME: prints one line on the model and its mesh.
MeshedModel mesh_model_for_solve(const std::string& file, std::span<const std::string> sets,
                                 const std::string& physics);

// Prints the model's [surfaces], conditions, loads and mesh controls (lengths in its unit).
void print_model_conditions(const Model& model);

}  // namespace foxi::cli
