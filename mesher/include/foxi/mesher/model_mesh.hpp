// A model file taken to a certified, named mesh in one call: load (with parameter overrides), check
// what a physics needs (before meshing), build the structure's PLC, refuse a mesh estimated past a
// tet limit, apply the model's [mesh] controls (sizes, part sizes, refinement boxes as a size field)
// and mesh it by the conforming Delaunay path (conforming.hpp), so that the solver gets a certified
// mesh and the painter an exact order. The mesh's regions are named after the parts, its boundaries
// after the structure's surfaces, and the model carries the materials.
//
// The options say what `foxi mesh` can say (it is a thin user of these calls): the mesher (TetGen with
// the conforming refinement, or CGAL Mesh_3's regular mesh, cgal_mesher.hpp), sizes and bounds over
// the model's [mesh] (global, per part, per region id, refinement boxes), a size field from the error
// of a solved field (refine from a result), TetGen's mesh as it is (no conforming rounds), a progress
// function that can cancel every path. A PLC without a model (a TetGen .poly, a host's own) takes
// the same options through mesh_plc_with_options.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/mesher/cgal_mesher.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/size_field.hpp"
#include "foxi/mesher/tet_estimate.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/physics.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/model/structure.hpp"

namespace foxi {

enum class Mesher {
  tetgen,  // TetGen, then the conforming Delaunay refinement (conforming.hpp): a certified mesh
  cgal,    // CGAL Mesh_3 (cgal_mesher.hpp): a regular mesh with vertex weights, certified by orthospheres
};

// A solved mesh to refine from: target sizes from the Zienkiewicz-Zhu error of one of its node
// fields (size_field.hpp's zz_error_indicator and size_field_from_error), so that the new mesh's
// relative gradient error comes near `target_error`. The solved mesh is the background mesh.
struct RefineFrom {
  const Mesh* mesh = nullptr;              // null: no refinement from a result; else it must outlive the call
  std::string field;                       // a node field of it (refine_field); empty: its first node field
  double target_error = 0;                 // relative gradient error, > 0 (e.g. 0.05)
  std::string origin = "the solved mesh";  // named in messages (its file, say)
};

// What refining from a result found (MeshedModel::refined).
struct RefinedFrom {
  std::string field;                   // the field used
  double relative_error = 0;           // its Zienkiewicz-Zhu relative gradient error on the solved mesh
  std::size_t tets = 0;                // tets of the solved mesh
  std::size_t tets_without_value = 0;  // of which with a node of no value (NaN): they keep their size
};

struct MeshedModel {
  Model model;          // empty for mesh_plc_with_options
  Structure structure;  // likewise
  Mesh mesh;            // regions named after the parts, boundaries after the structure's surfaces
  Mesher mesher = Mesher::tetgen;
  MeshReport report;  // the last TetGen run (TetGen only)
  // TetGen: the conforming refinement (certificate, thin layers). With conform off: the certificate
  // of TetGen's mesh in delaunay, first_mesh_violations and violations. CGAL: the weighted
  // certificate the same way and seconds, so that mesh_quality_report tells either mesher's mesh.
  ConformingReport conforming;
  CgalMeshReport cgal;                 // CGAL only
  std::optional<RefinedFrom> refined;  // when options.refine_from gave a mesh
};

struct ModelMeshOptions {
  // Checked before meshing (check_physics): the conditions and materials a solve of it needs; after
  // meshing, parts touching the rest only along an edge or at a point are refused (IoError: the mesh
  // would join them through nodes).
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
  // Asked while TetGen or CGAL runs (tetgen_mesher.hpp, cgal_mesher.hpp) and between the conforming
  // rounds; returning false stops it with MesherCancelled.
  ProgressFn progress;

  Mesher mesher = Mesher::tetgen;
  // Sizes and bounds over the model's [mesh] table (edge lengths in metres; PLC units without a
  // model). None of them applies when coarse.
  std::optional<double> max_size;  // replaces [mesh] max_size (> 0)
  // The largest tet volume (m^3; 0: none). TetGen: the smaller of it and max_size's regular tet;
  // CGAL: the circumradius of the regular tet of that volume, before any max_size.
  double max_volume = 0;
  // Replace the [mesh] part size of the same part, or add one (names: the model's parts; an unknown
  // name is an IoError on the model file). Needs a model.
  std::vector<PartSize> part_sizes;
  // Added to the model's: region sizes by region id (a model's part i is region i + 1; where a part
  // size gives the same region one too, the smaller wins; an id with no seed in the PLC is a
  // MesherError) and refinement boxes (TetGen: a size field; CGAL: CgalMeshParams::boxes, as the
  // model's). sizes.max_size is not read: use max_size.
  SizeControls sizes;
  // The radius-edge bound: TetGen's (0: no quality refinement, else at least kMinRadiusEdgeBound;
  // unset: the model's quality, else 1.414); CGAL's cell radius-edge bound (unset: cgal.radius_edge;
  // the model's quality, a TetGen bound, does not apply).
  std::optional<double> quality;
  std::optional<double> min_dihedral;  // TetGen's dihedral bound in [0, 30) degrees; unset: the model's
  RefineFrom refine_from;              // TetGen only
  // TetGen: false gives TetGen's mesh as it is (its certificate reported, no conforming rounds).
  bool conform = true;
  bool optimize = false;  // TetGen's flips and smoothing; implies conform = false
  // The CGAL path's own parameters (perturb, resample, feature_angle, time_limit, radius_edge, ...);
  // max_size and progress are set from the options above, and the boxes of the model and of `sizes`
  // are added to cgal.boxes.
  CgalMeshParams cgal;
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

// The same for a model already loaded (load_model): a caller that needs the model before meshing
// (its length unit, to read sizes given in it) loads it once. Errors as mesh_model; `model.file`
// is the file named in them.
FOXI_API MeshedModel mesh_loaded_model(Model model, const ModelMeshOptions& options = {});

// A PLC without a model (a TetGen .poly, a host's own) under the same options (no part sizes, no
// physics check; the regions and boundaries keep their ids, unnamed). `origin` is named in errors
// (the .poly file). Errors as mesh_model.
FOXI_API MeshedModel mesh_plc_with_options(Plc plc, const ModelMeshOptions& options = {},
                                           const std::string& origin = "the PLC");

// The options' values the meshers cannot take (a size not > 0, a box with lo > hi, a quality or
// dihedral bound out of range, refine-from with CGAL, a target error not > 0): MesherError
// (MesherFailure::bad_input) with the reason. mesh_model checks them first; a host checks as its user
// types. Part names are checked against the model when meshing.
FOXI_API void check_mesh_options(const ModelMeshOptions& options);

// The node field refining from `mesh` uses: the one named `name`, or the first node field when
// `name` is empty; null when there is none.
FOXI_API const Field* refine_field(const Mesh& mesh, std::string_view name);

}  // namespace foxi
