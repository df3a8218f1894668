// Shared by foxi solve, foxi model show and foxi demo: a model file taken to a named mesh, and the
// report of its conditions, loads and mesh controls.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "cli.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/tet_estimate.hpp"
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

// --max-tets N (a whole number >= 1; UsageError otherwise), or kDefaultMaxTets.
double max_tets_option(Args& args);

// Refuses with IoError (on `input`) a mesh of `plc` with `params` whose estimated tet count
// (tet_estimate.hpp) is over `max_tets`; the message gives both and says how to raise the limit.
void check_tet_estimate(const std::string& input, const Plc& plc, const MeshParams& params,
                        std::span<const double> region_volume, double max_tets);

// Loads `file` with the --set overrides, checks what `physics` needs (before meshing), builds the
// PLC and meshes it with the model's [mesh] controls; `coarse` meshes for a picture: TetGen alone, no
// sizes, no quality refinement, no conforming rounds (the mesh may not be Delaunay).
// A mesh estimated past `max_tets` is refused before meshing (check_tet_estimate). `size_scale`
// multiplies every size of the model's [mesh] (max_size, the parts' sizes, the refinement boxes'):
// 1/r meshes about r^3 times as many tets (foxi solve --convergence, --size-scale); a model with no
// max_size gets one from its bounding box's diagonal / 10 first, so that every level is bounded.
// Errors: IoError from the model, MesherError from TetGen.
MeshedModel mesh_model(const std::string& file, std::span<const std::string> sets,
                       std::optional<Physics> physics, bool coarse = false, double max_tets = kDefaultMaxTets,
                       double size_scale = 1);

// mesh_model for foxi solve MODEL --physics NAME: prints one line on the model and its mesh.
MeshedModel mesh_model_for_solve(const std::string& file, std::span<const std::string> sets,
                                 const std::string& physics, double size_scale = 1,
                                 double max_tets = kDefaultMaxTets);

// Prints the model's [surfaces], conditions, loads and mesh controls (lengths in its unit).
void print_model_conditions(const Model& model);

}  // namespace foxi::cli
