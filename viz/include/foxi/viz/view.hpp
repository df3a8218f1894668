// A viewpoint for ordering: a perspective eye point, or an orthographic view direction.
#pragma once

namespace foxi {

struct View {
  bool perspective = true;
  double eye[3] = {0, 0, 0};  // perspective: the eye point (may lie inside the mesh)
  double dir[3] = {0, 0, 1};  // orthographic: direction from the eye into the scene (any length > 0)

  static View at(double x, double y, double z) { return View{true, {x, y, z}, {0, 0, 1}}; }
  static View along(double dx, double dy, double dz) { return View{false, {0, 0, 0}, {dx, dy, dz}}; }
};

}  // namespace foxi
