// foxi/model.hpp: the common mesh database and what reads, writes and checks it (foxi::model), in one
// include. The entry points, one a line (declared in the topic headers below, which say more):
//
//   Mesh, Region, Boundary, Material, Field    the mesh database: plain arrays, SI units (mesh.hpp)
//   MeshView, DerivedCache                     a mesh over the host's own arrays, no copy (mesh_view.hpp)
//   check_sizes(mesh)                          the array sizes agree with each other (mesh.hpp)
//   region_id_of, boundary_tag_of              a region or boundary by name or number (mesh.hpp)
//   invalidate_derived(mesh)                   drop cached adjacency, spheres, certificate (mesh.hpp)
//   validate(mesh), validate_and_repair(mesh)  indices, flat, inverted, duplicate tets... (validate.hpp)
//   describe(report)                           a validation report as lines for a user (validate.hpp)
//   delaunay_certificate(mesh)                 exact empty-circumsphere test, cached (delaunay.hpp)
//   compute_delaunay_certificate(mesh, opts)   the same with progress, cancel, listing (delaunay.hpp)
//   face_adjacency(mesh)                       the neighbour across each tet face, cached (adjacency.hpp)
//   tet_quality(p0..p3), summarize_quality(m)  radius-edge ratio, dihedral angles (quality.hpp)
//   read_mesh(path), write_mesh(mesh, path)    any format, chosen from the file name (mesh_io.hpp)
//   read_/parse_/write_gmsh, _vtu, _vtk_legacy, _tetgen, _medit   one format each (io_*.hpp)
//   Cancelled                                  what a cancelled mesher, solver or movie throws (progress.hpp)
//   IoError                                    a reader's or writer's error: file, place, reason
//   (io_error.hpp) DurableFile, check_output_path             files that appear whole or not at all
//   (durable_file.hpp) cleanup::track, cleanup::interrupt         what an interrupted run must remove
//   (cleanup.hpp) Plc, read_poly, parse_poly, write_poly     the piecewise linear complex for the mesher
//   (plc.hpp) ProgressFn                                 progress and cancel callback (progress.hpp)
//
// The structure modelling (model files, parts, conditions) is foxi::structure: foxi/structure.hpp.
#pragma once

#include "foxi/api.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/cleanup.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/io_gmsh.hpp"
#include "foxi/model/io_medit.hpp"
#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/io_vtk.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/progress.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/version.hpp"
