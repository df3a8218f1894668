// Meshing a PLC with TetGen 1.5 through its library (tetgenio / tetrahedralize), into the common
// mesh database: region seeds become tet regions, facet markers the boundary tags of the boundary
// and interface triangles.
//
// Note (issue 6): TetGen's mesh optimisation (flips and smoothing, on by default in TetGen) breaks
// the empty-sphere property, so `optimize` is off by default; even then TetGen does not promise a
// Delaunay mesh at material interfaces. Check with delaunay_certificate() (foxi/model/delaunay.hpp).
#pragma once

#include <string>

#include "foxi/api.hpp"
#include "foxi/mesher/mesher.hpp"  // MesherError, MesherFailure
#include "foxi/mesher/size_field.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

// The least radius-edge bound mesh_plc accepts (besides 0, off): TetGen 1.5's refinement ran past 5
// minutes below it on the shipped models with thin layers (1.3 on die_attach, 1.2 on power_module),
// though Shewchuk's termination proof needs 2; every shipped model meshes at it in seconds.
inline constexpr double kMinRadiusEdgeBound = 1.414;

struct MeshParams {
  double max_volume = 0;       // global maximum tet volume (m^3); 0: none
  double radius_edge = 1.414;  // radius-edge bound for quality refinement; 0: no quality refinement
  double min_dihedral = 0;     // minimum dihedral angle bound (degrees, TetGen's -q/<angle>); 0: TetGen's
  bool optimize = false;       // TetGen's flips and smoothing (breaks the Delaunay property)
  bool regions = true;         // region seeds give tet regions (TetGen -A)
  // A sizing function (TetGen -m with a background mesh, size_field.hpp); null or empty: none. It must
  // outlive the call.
  const SizeField* size_field = nullptr;
  // Asked about every 100 ms while TetGen runs (fraction -1: TetGen tells no progress); returning
  // false stops TetGen and mesh_plc throws MesherError (code -1, "meshing cancelled").
  ProgressFn progress;
  // Wall-clock limit for the TetGen run in seconds (0: none). TetGen 1.5.0 can loop forever on a PLC
  // with almost collinear points; past the limit it is stopped and mesh_plc throws MesherError (code
  // 2, as for a TetGen failure). The refinement rounds set it from their first run's time.
  double time_limit = 0;
};

struct MeshReport {
  std::string switches;  // the TetGen switches used
  std::size_t input_points = 0;
  std::size_t steiner_points = 0;  // points TetGen added
  double seconds = 0;
};

FOXI_API Mesh mesh_plc(const Plc& plc, const MeshParams& params = {}, MeshReport* report = nullptr);

}  // namespace foxi
