// Test helpers for structure models: mesh a model's PLC with the `tetgen` program (an outside
// oracle) and sum each region's tet volumes and each named boundary's triangle areas.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/structure.hpp"
#include "test_util.hpp"

namespace foxi::test {

inline const std::string kModels = std::string(FOXI_TEST_DATA_DIR) + "/../../models/";
constexpr double kMm = 1e-3, kMm2 = 1e-6, kMm3 = 1e-9;

// Regular n-gon inscribed in a circle of radius r: area and perimeter.
inline double ngon_area(int n, double r) { return 0.5 * n * r * r * std::sin(2 * std::numbers::pi / n); }
inline double ngon_perimeter(int n, double r) { return 2.0 * n * r * std::sin(std::numbers::pi / n); }

struct Meshed {
  std::map<std::string, double> region_volume;  // by part name
  std::map<std::string, double> boundary_area;  // by boundary name
};

inline double tet_volume(const foxi::Mesh& m, std::size_t t) {
  const double* p[4];
  for (int i = 0; i < 4; ++i) p[i] = &m.xyz[3 * m.tet[4 * t + i]];
  double a[3], b[3], c[3];
  for (int k = 0; k < 3; ++k) a[k] = p[1][k] - p[0][k], b[k] = p[2][k] - p[0][k], c[k] = p[3][k] - p[0][k];
  return std::abs(a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                  a[2] * (b[0] * c[1] - b[1] * c[0])) /
         6;
}

inline double tri_area(const foxi::Mesh& m, std::size_t f) {
  const double* p[3];
  for (int i = 0; i < 3; ++i) p[i] = &m.xyz[3 * m.bface[3 * f + i]];
  double a[3], b[3];
  for (int k = 0; k < 3; ++k) a[k] = p[1][k] - p[0][k], b[k] = p[2][k] - p[0][k];
  const double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}

// Writes the model's PLC, meshes it with the tetgen program, reads the mesh back.
// max_volume <= 0: no volume bound and no quality refinement (plain -pA).
inline Meshed mesh_model(const std::string& file, std::vector<std::string> sets, double max_volume) {
  Meshed out;
  if (!foxi::test::have_program("tetgen")) {
    ADD_FAILURE() << "the tetgen program is missing (scripts/install-deps.sh installs it)";
    return out;
  }
  const foxi::Model model = foxi::load_model(file, sets);
  const foxi::Structure s = foxi::build_structure(model);
  TempDir dir;
  foxi::write_poly(s.plc, dir / "m.poly");
  char vol[64];
  std::snprintf(vol, sizeof vol, "%.6g", max_volume);
  const std::string switches = max_volume > 0 ? std::string("-pq1.414a") + vol + "AVQ" : std::string("-pAVQ");
  const int rc =
      foxi::test::run("cd '" + dir.path().string() + "' && tetgen " + switches + " m.poly", dir / "log.txt");
  const std::string log = foxi::test::read_text(dir / "log.txt");
  EXPECT_EQ(rc, 0) << log;
  EXPECT_EQ(log.find("ntersect"), std::string::npos) << log;  // "self-intersection", "intersecting"
  if (rc != 0) return out;
  foxi::Mesh mesh = foxi::read_tetgen(dir / "m.1");
  foxi::name_mesh(model, s, mesh);
  std::map<std::int32_t, std::string> region, boundary;
  for (const auto& r : mesh.regions) region[r.id] = r.name;
  for (const auto& b : mesh.boundaries) boundary[b.tag] = b.name;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::int32_t id = mesh.region_of(t);
    EXPECT_TRUE(region.count(id) && !region[id].empty()) << "tet " << t << " in unnamed region " << id;
    out.region_volume[region[id]] += tet_volume(mesh, t);
  }
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    const std::int32_t tag = mesh.bface_tag[f];
    if (tag == 0) continue;
    out.boundary_area[boundary[tag]] += tri_area(mesh, f);
  }
  return out;
}

inline void expect_near_rel(double got, double want, const std::string& what) {
  EXPECT_NEAR(got, want, 1e-9 * std::abs(want)) << what;
}

inline void expect_volumes(const Meshed& m, const std::map<std::string, double>& want) {
  EXPECT_EQ(m.region_volume.size(), want.size());
  for (const auto& [name, v] : want) {
    ASSERT_TRUE(m.region_volume.count(name)) << "no tets in region " << name;
    expect_near_rel(m.region_volume.at(name), v, "volume of " + name);
  }
}

inline void expect_areas(const Meshed& m, const std::map<std::string, double>& want) {
  EXPECT_EQ(m.boundary_area.size(), want.size());
  for (const auto& [name, a] : want) {
    ASSERT_TRUE(m.boundary_area.count(name)) << "no triangles on boundary " << name;
    expect_near_rel(m.boundary_area.at(name), a, "area of " + name);
  }
}

// A model of boxes and cylinders given as (name, origin/centre, size) lines, in mm, material "a".
inline std::string boxes_model(const std::string& parts) {
  return "units.length = \"mm\"\n[materials.a]\nthermal_conductivity = 1\n" + parts;
}
inline std::string box(const std::string& name, double x, double y, double z, double w, double d, double h) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "[[parts]]\nname = \"%s\"\nmaterial = \"a\"\nshape = \"box\"\norigin = [%g, %g, %g]\n"
                "size = [%g, %g, %g]\n",
                name.c_str(), x, y, z, w, d, h);
  return buf;
}

inline Meshed mesh_text(const std::string& text, double max_volume) {
  TempDir dir;
  foxi::test::write_text(dir / "m.toml", text);
  return mesh_model((dir / "m.toml").string(), {}, max_volume);
}

}  // namespace foxi::test
