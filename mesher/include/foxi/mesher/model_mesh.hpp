// A model file taken to a certified, named mesh in one call: load (with parameter overrides), check
// what a physics needs (before meshing), build the structure's PLC, refuse a mesh estimated past a
// tet limit, apply the model's [mesh] controls (sizes, part sizes, refinement boxes as a size field)
// and mesh it by the conforming Delaunay path (conforming.hpp), so that the solver gets a certified
// mesh and the painter an exact order. The mesh's regions are named after the parts, its boundaries
// after the structure's surfaces, and the model carries the materials.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include "foxi/api.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/tet_estimate.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/model/structure.hpp"

namespace foxi {

struct MeshedModel {
  Model model;
  Structure structure;
  Mesh mesh;                    // regions named after the parts, boundaries after the structure's surfaces
  MeshReport report;            // the last TetGen run
  ConformingReport conforming;  // the conforming refinement (certificate, thin layers)
};

struct ModelMeshOptions {
  // Checked before meshing (check_physics): the conditions and materials a solve of it needs.
  std::optional<Physics> physics;
  // A mesh for a picture of the parts: TetGen alone, no sizes, no quality refinement, no conforming
  // rounds (the mesh follows the PLC's points and may not be Delaunay; draw_picture copes).
  bool coarse = false;
  // A mesh estimated past this many tets (tet_estimate.hpp) is refused before meshing.
  double max_tets = kDefaultMaxTets;
  // Multiplies every size of the model's [mesh] (max_size, part sizes, refinement boxes): 1/r meshes
  // about r^3 times as many tets (convergence studies); a model with no max_size gets one from its
  // bounding box's diagonal / 10 first, so that every level is bounded. Ignored when coarse.
  double size_scale = 1;
  // Where the parameter overrides came from, named in messages (load_model).
  std::string override_origin = "an override";
  // Asked while TetGen runs (tetgen_mesher.hpp); returning false stops it with MesherCancelled.
  ProgressFn progress;
};

// The tet-count estimate over the limit: IoError on the model (or PLC) file, line 0, with both
// numbers; the message says to use a larger size or raise the limit.
class FOXI_API TetLimitError : public IoError {
 public:
  TetLimitError(const std::string& file, double estimate, double limit);
  double estimate() const { return estimate_; }
  double limit() const { return limit_; }

 private:
  double estimate_, limit_;
};

// Throws TetLimitError (on `file`) when meshing `plc` with `params` is estimated past `max_tets`;
// region_volume as for estimate_tet_count.
FOXI_API void check_tet_estimate(const std::string& file, const Plc& plc, const MeshParams& params,
                                 std::span<const double> region_volume, double max_tets);

// The model file `file` with `overrides` to a certified mesh (see the top of this file). Errors:
// IoError from the model (TetLimitError past the limit), MesherError from the mesher
// (MesherCancelled when progress says stop).
FOXI_API MeshedModel mesh_model(const std::filesystem::path& file,
                                std::span<const ParameterOverride> overrides = {},
                                const ModelMeshOptions& options = {});

}  // namespace foxi
