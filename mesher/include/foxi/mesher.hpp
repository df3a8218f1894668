// foxi/mesher.hpp: tetrahedral meshing of a PLC (foxi::mesher), in one include. The entry points,
// one a line (declared in the topic headers below, which say more):
//
// clang-format off
//   mesh_model(file, overrides, options)       a model file to a certified, named mesh (model_mesh.hpp)
//   mesh_loaded_model(model, options)          the same for a model already loaded (model_mesh.hpp)
//   mesh_plc_with_options(plc, options)        a PLC (a .poly) under the same options (model_mesh.hpp)
//   ModelMeshOptions, check_mesh_options       mesher, sizes, boxes, refine-from, quality (model_mesh.hpp)
//   mesh_plc(plc, params)                      TetGen's quality mesh of a PLC (tetgen_mesher.hpp)
//   mesh_conforming(plc, params, conforming)   a conforming Delaunay mesh, certified (conforming.hpp)
//   mesh_plc_cgal(plc, params)                 CGAL Mesh_3's mesh of a PLC (cgal_mesher.hpp)
//   MeshParams, MesherError, MesherCancelled   parameters, and why meshing failed (mesher.hpp)
//   estimate_tet_count(plc, params)            tets a mesh will have, before meshing (tet_estimate.hpp)
//   mesh_params_from_model(model, plc)         a model's [mesh] controls as parameters (model_mesh_params.hpp)
//   box_size_field, size_field_from_error      size control: boxes, per region, from an error (size_field.hpp)
//   zz_error_indicator(mesh, field)            Zienkiewicz-Zhu error estimate of a field (size_field.hpp)
//   find_thin_layers(plc)                      thin layers a radius-edge bound cannot hold (thin_layers.hpp)
//   mesh_quality_report(mesh, report)          shape and size quality of a mesh (quality_report.hpp)
// clang-format on
#pragma once

#include "foxi/mesher/cgal_mesher.hpp"
#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/mesher.hpp"
#include "foxi/mesher/model_mesh.hpp"
#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/quality_report.hpp"
#include "foxi/mesher/size_field.hpp"
#include "foxi/mesher/tet_estimate.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/mesher/thin_layers.hpp"
