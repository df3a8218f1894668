// The camera of the renderer: perspective (an eye point, which may lie inside the mesh) or
// orthographic (a view direction), with fit-to-bounds and orbit / pan / zoom helpers, and the
// projection of world points to pixel coordinates used by the rasterizer.
//
// Pixel coordinates: x to the right, y down, pixel (i, j) covers [i, i+1) x [j, j+1) and is sampled
// at its centre (i + 0.5, j + 0.5). Camera coordinates: x along `right`, y along `up` (orthogonalised),
// z along `forward` (from the eye into the scene); z is the depth.
#pragma once

#include <cstdint>
#include <span>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/mesh_view.hpp"
#include "foxi/viz/view.hpp"

namespace foxi {

struct Camera {
  bool perspective = true;
  double eye[3] = {0, -1, 0};  // world point; orthographic: only eye - at matters (the direction)
  double at[3] = {0, 0, 0};    // the point looked at (centre of the image)
  double up[3] = {0, 0, 1};    // view-up; need not be orthogonal to at - eye, must not be parallel
  double fov_deg = 30;         // perspective: vertical field of view in degrees, in (0, 180)
  double ortho_height = 1;     // orthographic: world height shown by the image (> 0)
};

// Axis-aligned bounds of the nodes used by tets (all nodes if there are no tets). lo > hi if none.
FOXI_API void mesh_bounds(const MeshView& mesh, double lo[3], double hi[3]);
// Axis-aligned bounds of the corners of the tets in `subset` (tet indices < tet_count); an empty
// subset: mesh_bounds. What a camera is fitted to when only part of a mesh is drawn.
FOXI_API void tets_bounds(const MeshView& mesh, std::span<const std::uint32_t> subset, double lo[3],
                          double hi[3]);

// A camera looking along `dir` (from the eye into the scene) at the centre of the box [lo, hi], far
// enough that the box's 8 corners project within `fill` (0..1] of the half-width and half-height of
// an image of width/height `aspect` (and, perspective, the eye outside the box's bounding sphere).
// Perspective with vertical field of view `fov_deg`, or orthographic. `up` is used as given when not parallel
// to dir, else another axis is chosen.
FOXI_API Camera fit_camera(const double lo[3], const double hi[3], const double dir[3], const double up[3],
                           bool perspective = true, double fov_deg = 30, double aspect = 1,
                           double fill = 0.95);

// The camera the front ends (foxi render, foxi-view) build from partly given options, so that they
// agree: any of eye, at, up, dir may be null (not given); fov_deg <= 0 means 30 degrees; up defaults
// to +z. With dir: orthographic, fitted along dir, then moved to `at`. Otherwise perspective, fitted
// from an oblique direction (front-right, above); `at` replaces the target and `eye` the eye; with
// `at` but no `eye` the fitted eye's offset from the box centre is kept.
FOXI_API Camera camera_from_options(const double lo[3], const double hi[3], double aspect, const double* eye,
                                    const double* at, const double* up, double fov_deg, const double* dir);

// Turns the eye about `at`: by yaw_deg about the up axis, then by pitch_deg about the right axis.
// Up is kept (re-orthogonalised). Distance to `at` is unchanged.
FOXI_API Camera orbit(const Camera& camera, double yaw_deg, double pitch_deg);
// Moves eye and at together by (dx, dy) fractions of the visible height at `at` (right, up).
FOXI_API Camera pan(const Camera& camera, double dx, double dy);
// factor > 1 magnifies: perspective moves the eye toward `at` (distance / factor); orthographic
// divides ortho_height by factor.
FOXI_API Camera zoom(const Camera& camera, double factor);

// The per-image projection of a camera. Throws std::invalid_argument for a degenerate camera
// (eye == at, up parallel to the view direction, fov outside (0, 180), size < 1).
struct FOXI_API Projector {
  bool perspective = true;
  double eye[3] = {0, 0, 0};
  double right[3] = {1, 0, 0}, up[3] = {0, 1, 0}, forward[3] = {0, 0, 1};  // orthonormal
  int width = 1, height = 1;
  double cx = 0.5, cy = 0.5;  // pixel coordinates of the image centre (width/2, height/2)
  double focal = 1;           // perspective: pixels per unit of x/z (height / 2 / tan(fov / 2))
  double scale = 1;           // orthographic: pixels per world unit (height / ortho_height)

  Projector(const Camera& camera, int width, int height);
  // World point -> camera coordinates (x right, y up, z depth along forward from the eye).
  void to_camera(const double p[3], double c[3]) const;
  // Camera coordinates -> pixel coordinates; perspective needs c[2] > 0.
  void camera_to_pixel(const double c[3], double px[2]) const;
  // World point -> pixel coordinates (x, y) and depth; returns false (px untouched) if the point is
  // not in front of the eye (perspective, depth <= 0).
  bool project(const double p[3], double px[2], double* depth = nullptr) const;
};

// Where the ray through the centre of pixel (x, y) (row 0 at the top) of a width x height image
// enters tet `t` of `mesh` (for a perspective eye inside the tet: the eye): its barycentric
// coordinates in the tet's node order, the point the pixel shows of that tet (unshrunk). The ray is
// clamped to the tet where it passes just outside it (a pixel centre past an edge the tet was
// rasterized on). False if the camera is degenerate or the ray runs the other way. `shrink`: the
// tet was drawn scaled about its centroid by it (RenderParams::shrink): the ray then meets the shrunk
// tet, and bary are that point's coordinates in the shrunk tet, which are those of the true point it
// shows in the tet itself (the shrink is affine), the point whose value the pixel's colour shows.
FOXI_API bool pixel_point_in_tet(const MeshView& mesh, const Camera& camera, int width, int height,
                                 std::uint32_t t, int x, int y, double bary[4], double shrink = 1);

// The ordering viewpoint of a camera: perspective -> View::at(eye), orthographic -> View::along(at - eye).
FOXI_API View view_of(const Camera& camera);

}  // namespace foxi
