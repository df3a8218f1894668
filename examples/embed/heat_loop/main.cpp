// heat_loop: a host that meshes, solves and draws a structure of its own in a handful of calls, the
// whole loop the foxi CLI runs (foxi solve MODEL, then foxi render), through the installed package.
//
//   heat_loop MODEL.toml [OUT.png]
//
// The model (heatsink.toml beside this file) is the host's: a 2 W chip on a copper spreader on an
// aluminium plate held at 300 K below. mesh_model gives a certified mesh with the parts as named
// regions and their faces as named boundaries, thermal_params_from_model the model's conditions as
// solver parameters, solve_thermal the temperature (stored in the mesh as the field "temperature"),
// and draw_picture the field on the mesh, by the safe rule (a certified mesh: power order and
// painter).
//
// Checks, against what the physics says whatever the mesh: (1) the heat leaving through the held
// bottom equals the 2 W put in (energy balance, to 1e-6); (2) no temperature below the 300 K held
// (maximum principle: the only source is positive); (3) the hottest region is the chip; (4) the
// picture shows the mesh (a good part of its pixels show a tet).
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <tuple>

#include "foxi/mesher.hpp"
#include "foxi/solver.hpp"
#include "foxi/viz.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: heat_loop MODEL.toml [OUT.png]\n");
    return 2;
  }
  try {
    // Mesh, solve, draw.
    foxi::MeshedModel m = foxi::mesh_model(argv[1]);
    const foxi::ThermalReport heat =
        foxi::solve_thermal(m.mesh, foxi::thermal_params_from_model(m.model, m.mesh));

    const foxi::FieldChoice temperature = foxi::choose_field(m.mesh, "temperature");
    foxi::ColorScale scale;
    std::tie(scale.lo, scale.hi) = foxi::finite_range(temperature.field->values);
    foxi::PictureParams params;
    params.render.field = std::make_shared<const foxi::FieldPaint>(
        foxi::graded_field_paint(foxi::tet_corner_values(m.mesh, temperature), scale));
    double lo[3], hi[3];
    const double dir[3] = {-1, -1.4, -1}, up[3] = {0, 0, 1};
    foxi::mesh_bounds(m.mesh, lo, hi);
    const foxi::Camera camera = foxi::fit_camera(lo, hi, dir, up, true, 30, 800.0 / 600);
    foxi::Framebuffer fb(800, 600);
    const foxi::PictureReport picture =
        foxi::draw_picture(m.mesh, foxi::compute_spheres(m.mesh), camera, fb, params);
    foxi::write_png(argc > 2 ? argv[2] : "heat_loop.png", fb);

    // Checks.
    double out = 0;
    for (const foxi::BoundaryHeat& b : heat.boundaries) out -= b.heat_in;
    double t_min = INFINITY;
    for (double t : temperature.field->values) t_min = std::fmin(t_min, t);
    const foxi::RegionTemperature* hottest = nullptr;
    for (const foxi::RegionTemperature& r : heat.regions)
      if (hottest == nullptr || r.max_temperature > hottest->max_temperature) hottest = &r;
    std::size_t shown = 0;
    for (std::uint32_t id : fb.id) shown += id != foxi::kNone;
    const bool balance = std::abs(out - 2.0) < 2e-6, above = t_min >= 300 - 1e-9,
               chip = hottest != nullptr && hottest->region == foxi::region_id_of(m.mesh, "chip"),
               drawn = shown > fb.id.size() / 10;
    std::printf(
        "heat_loop: %zu tets (%s), T %.3f .. %.3f K, %.6f W out through %zu boundaries, hottest "
        "region %d (chip %s); drew %zu tets (%s), %zu px: %s\n",
        m.mesh.tet_count(), picture.delaunay ? "certified" : "NOT certified", t_min, heat.max_temperature,
        out, heat.boundaries.size(), hottest ? int(hottest->region) : -1, chip ? "yes" : "no",
        picture.tets_drawn, picture.method == foxi::OrderMethod::power ? "power order" : "MPVO", shown,
        balance && above && chip && drawn ? "ok" : "WRONG");
    return balance && above && chip && drawn ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "heat_loop: %s\n", e.what());
    return 1;
  }
}
