// Meshing PLCs through CGAL's Mesh_3: region volumes and boundary areas against analytic values and
// the model builder's own part volumes (every shipped model), the weighted Delaunay certificate
// (exact, global), the visibility order from many views (exact orientation tests), weights through a
// .vtu file, the minimum dihedral angle against TetGen's -O0 mesh of the same PLC, and the typed
// failures (bad input, time limit, cancel). Tests named *Slow* carry the CTest label `slow`.
#include "foxi/mesher/cgal_mesher.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <map>
#include <numbers>

#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/size_field.hpp"
#include "foxi/mesher/tetgen_mesher.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/plc.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/structure.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

std::string source_file(const std::string& name) { return test::data_dir() + "/../../" + name; }

std::map<std::int32_t, double> region_volumes(const Mesh& m) {
  std::map<std::int32_t, double> v;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* n = &m.tet[4 * t];
    const double vol =
        tet_quality(&m.xyz[3 * n[0]], &m.xyz[3 * n[1]], &m.xyz[3 * n[2]], &m.xyz[3 * n[3]]).volume;
    EXPECT_GT(vol, 0) << "tet " << t << " is not positively oriented";
    v[m.region_of(t)] += vol;
  }
  return v;
}

std::map<std::int32_t, double> tag_areas(const Mesh& m) {
  std::map<std::int32_t, double> area;
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    const double* p = &m.xyz[3 * m.bface[3 * f]];
    const double* q = &m.xyz[3 * m.bface[3 * f + 1]];
    const double* r = &m.xyz[3 * m.bface[3 * f + 2]];
    const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]},
                 w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    area[m.bface_tag[f]] += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  return area;
}

// A box [lo, hi]^3 as 6 facets with markers first_marker .. first_marker + 5 (bottom, top, -y, +x, +y, -x).
void add_box(Plc& plc, const double lo[3], const double hi[3], std::int32_t first_marker) {
  const auto base = static_cast<std::uint32_t>(plc.point_count());
  for (int k = 0; k < 8; ++k) {
    plc.points.push_back((k & 1) ^ ((k >> 1) & 1) ? hi[0] : lo[0]);
    plc.points.push_back(k & 2 ? hi[1] : lo[1]);
    plc.points.push_back(k & 4 ? hi[2] : lo[2]);
  }
  // Points 0..3 go round the bottom (x, y) = (lo,lo) (hi,lo) (hi,hi) (lo,hi); 4..7 the same on top.
  plc.add_facet({base, base + 1, base + 2, base + 3}, first_marker);
  plc.add_facet({base + 4, base + 5, base + 6, base + 7}, first_marker + 1);
  plc.add_facet({base, base + 1, base + 5, base + 4}, first_marker + 2);
  plc.add_facet({base + 1, base + 2, base + 6, base + 5}, first_marker + 3);
  plc.add_facet({base + 2, base + 3, base + 7, base + 6}, first_marker + 4);
  plc.add_facet({base + 3, base, base + 4, base + 7}, first_marker + 5);
}

Plc unit_box() {
  Plc plc;
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  add_box(plc, lo, hi, 1);
  plc.regions.push_back(RegionSeed{{0.5, 0.5, 0.5}, 7, 0});
  return plc;
}

// Eyes on a sphere twice the mesh's size around its centre and at its centre, and orthographic
// directions, spread on the sphere by the golden angle.
std::vector<View> views_around(const Mesh& m, int n) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < m.xyz.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], m.xyz[i]);
    hi[i % 3] = std::max(hi[i % 3], m.xyz[i]);
  }
  const double c[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
  const double r = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::vector<View> views{View::at(c[0] + 1e-3 * r, c[1] + 2e-3 * r, c[2] + 3e-3 * r)};
  for (int i = 1; i < n; ++i) {
    const double z = 1 - 2 * (i + 0.5) / n, s = std::sqrt(1 - z * z), phi = i * 2.399963229728653;
    const double d[3] = {s * std::cos(phi), s * std::sin(phi), z};
    views.push_back(i % 2 ? View::along(d[0], d[1], d[2])
                          : View::at(c[0] + r * d[0], c[1] + r * d[1], c[2] + r * d[2]));
  }
  return views;
}

// The properties every CGAL mesh must have: valid, weighted, certified regular, and ordered without a
// single face pair in the wrong order from many views.
void expect_certified(const Mesh& m, int views) {
  EXPECT_TRUE(validate(m).ok());
  ASSERT_EQ(m.weight.size(), m.node_count());
  const DelaunayCertificate cert = compute_delaunay_certificate(m);
  EXPECT_TRUE(cert.weighted);
  EXPECT_TRUE(cert.delaunay) << cert.violating_tet_count << " tets violate the weighted certificate, "
                             << cert.degenerate_tet_count << " degenerate";
  const SphereTable table = compute_spheres(m);
  std::size_t checked = 0;
  for (const View& v : views_around(m, views)) {
    const auto order = visibility_order(m, table, v);
    ASSERT_EQ(order.size(), m.tet_count());
    const ViolationReport r = count_violations(m, v, order);
    EXPECT_EQ(r.violations, 0u);
    checked += r.pairs_checked;
  }
  EXPECT_GT(checked, m.tet_count());  // the views really compared face pairs
}

double min_dihedral(const Mesh& m) { return summarize_quality(m).min_dihedral_deg.min; }

TEST(CgalMesher, UnitBoxKeepsItsCornersTagsAndIsCertified) {
  const Plc plc = unit_box();
  CgalMeshParams params;
  params.max_size = 0.15;
  CgalMeshReport report;
  const Mesh m = mesh_plc_cgal(plc, params, &report);
  EXPECT_GT(m.tet_count(), 200u);
  EXPECT_EQ(report.cells, 1u);
  EXPECT_EQ(report.patches, 6u);
  const auto vol = region_volumes(m);
  ASSERT_EQ(vol.size(), 1u);
  EXPECT_NEAR(vol.at(7), 1.0, 1e-9);  // protected edges: the box is not rounded
  const auto area = tag_areas(m);
  ASSERT_EQ(area.size(), 6u);
  for (std::int32_t tag = 1; tag <= 6; ++tag) EXPECT_NEAR(area.at(tag), 1.0, 1e-9) << "tag " << tag;
  // Every corner of the box is a mesh vertex.
  for (std::size_t k = 0; k < 8; ++k) {
    bool found = false;
    for (std::size_t i = 0; i < m.node_count() && !found; ++i)
      found = m.xyz[3 * i] == plc.points[3 * k] && m.xyz[3 * i + 1] == plc.points[3 * k + 1] &&
              m.xyz[3 * i + 2] == plc.points[3 * k + 2];
    EXPECT_TRUE(found) << "corner " << k;
  }
  expect_certified(m, 40);
}

// Circumradius of the tet's four points (unweighted), from the circumcentre solved by Cramer's rule.
double circumradius(const Mesh& m, std::size_t t) {
  const double* a = &m.xyz[3 * m.tet[4 * t]];
  double r[3][3], rhs[3];
  for (int i = 0; i < 3; ++i) {
    const double* p = &m.xyz[3 * m.tet[4 * t + 1 + i]];
    rhs[i] = 0;
    for (int k = 0; k < 3; ++k) {
      r[i][k] = p[k] - a[k];
      rhs[i] += 0.5 * r[i][k] * r[i][k];
    }
  }
  auto det = [](const double(*q)[3]) {
    return q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1]) -
           q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0]) +
           q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0]);
  };
  const double d = det(r);
  double c2 = 0;
  for (int k = 0; k < 3; ++k) {
    double q[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) q[i][j] = j == k ? rhs[i] : r[i][j];
    c2 += std::pow(det(q) / d, 2);
  }
  return std::sqrt(c2);
}

// Mean edge length of the tets with all four vertices in [lo, hi] (inside) and of those with none
// (outside), and of the boundary triangles with all three in it; the circumradii of the tets inside.
struct BoxEdges {
  double inside = 0, outside = 0, surface_inside = 0;
  std::size_t inside_tets = 0, outside_tets = 0;
  std::vector<double> circumradii_inside;
};
BoxEdges box_edges(const Mesh& m, const double lo[3], const double hi[3]) {
  auto in = [&](std::uint32_t n) {
    const double* p = &m.xyz[3 * n];
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] && p[2] <= hi[2];
  };
  auto len = [&](std::uint32_t a, std::uint32_t b) {
    return std::hypot(m.xyz[3 * a] - m.xyz[3 * b], m.xyz[3 * a + 1] - m.xyz[3 * b + 1],
                      m.xyz[3 * a + 2] - m.xyz[3 * b + 2]);
  };
  BoxEdges e;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    int n_in = 0;
    double sum = 0;
    for (int i = 0; i < 4; ++i) {
      n_in += in(m.tet[4 * t + i]);
      for (int j = i + 1; j < 4; ++j) sum += len(m.tet[4 * t + i], m.tet[4 * t + j]) / 6;
    }
    if (n_in == 4) {
      e.inside += sum;
      ++e.inside_tets;
      e.circumradii_inside.push_back(circumradius(m, t));
    } else if (n_in == 0) {
      e.outside += sum;
      ++e.outside_tets;
    }
  }
  std::size_t faces = 0;
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    const std::uint32_t* v = &m.bface[3 * f];
    if (!in(v[0]) || !in(v[1]) || !in(v[2])) continue;
    e.surface_inside += (len(v[0], v[1]) + len(v[1], v[2]) + len(v[2], v[0])) / 3;
    ++faces;
  }
  if (e.inside_tets) e.inside /= double(e.inside_tets);
  if (e.outside_tets) e.outside /= double(e.outside_tets);
  if (faces) e.surface_inside /= double(faces);
  return e;
}

// A refinement box at a corner of the unit box: the tets inside it (all four vertices in it) and its
// part of the boundary are finer than outside it and than the same place meshed without the box,
// nine in ten tets there keep within the box's circumradius bound (h sqrt6 / 4), and
// the mesh keeps its volume and its weighted certificate. Edges measured here, brute force.
TEST(CgalMesher, RefinementBoxRefinesItsCellsAndFacetsOnly) {
  const Plc plc = unit_box();
  CgalMeshParams params;
  params.max_size = 0.2;
  const double lo[3] = {0, 0, 0}, hi[3] = {0.4, 0.4, 0.4};
  const Mesh plain = mesh_plc_cgal(plc, params);
  RefinementBox box;
  std::copy(lo, lo + 3, box.lo);
  std::copy(hi, hi + 3, box.hi);
  box.size = 0.08;  // an edge length: circumradius bound 0.049
  params.boxes = {box};
  CgalMeshReport report;
  const Mesh m = mesh_plc_cgal(plc, params, &report);
  EXPECT_EQ(report.boxes, 1u);
  EXPECT_TRUE(report.volumes_match);
  EXPECT_NEAR(region_volumes(m).at(7), 1.0, 1e-9);
  const auto area = tag_areas(m);
  for (std::int32_t tag = 1; tag <= 6; ++tag) EXPECT_NEAR(area.at(tag), 1.0, 1e-9) << "tag " << tag;
  expect_certified(m, 8);

  const BoxEdges with = box_edges(m, lo, hi), without = box_edges(plain, lo, hi);
  ASSERT_GT(with.inside_tets, 100u);
  ASSERT_GT(without.inside_tets, 0u);
  const double bound = box.size * std::sqrt(6.0) / 4;
  // Mesh_3 bounds the circumradius where the orthocentre lies in the box, before exudation pumps
  // the weights: a tet along the box's faces may have its orthocentre outside. Measured: median
  // 0.042, 90th percentile 0.047, largest 0.106 against the bound 0.049.
  std::vector<double> radii = with.circumradii_inside;
  std::sort(radii.begin(), radii.end());
  EXPECT_LT(radii[radii.size() * 9 / 10], 1.05 * bound) << "circumradius bound " << bound;
  // Measured: mean edges 0.065 inside, 0.232 outside, 0.240 inside without the box; boundary
  // triangles in the box 0.058, without it 0.206.
  EXPECT_LT(with.inside, 0.5 * with.outside) << with.inside << " inside, " << with.outside << " outside";
  EXPECT_LT(with.inside, 0.5 * without.inside)
      << with.inside << " with the box, " << without.inside << " without";
  EXPECT_LT(with.surface_inside, 0.5 * without.surface_inside)
      << "boundary triangles in the box: " << with.surface_inside << " with it, " << without.surface_inside
      << " without";
  // Away from the box the mesh is as coarse as without it.
  EXPECT_GT(with.outside, 0.8 * without.outside) << with.outside << " with the box, " << without.outside;

  CgalMeshParams inverted = params;
  std::swap(inverted.boxes[0].lo[1], inverted.boxes[0].hi[1]);
  try {
    mesh_plc_cgal(plc, inverted);
    FAIL() << "a box with lo > hi was accepted";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::bad_input);
    EXPECT_NE(std::string(e.what()).find("refinement box 1"), std::string::npos) << e.what();
  }
}

TEST(CgalMesher, NestedShellsAndVolumeHolesFindTheirCells) {
  // A box floating inside a box, touching nothing: the outer region's boundary has two shells.
  Plc plc;
  const double lo[3] = {0, 0, 0}, hi[3] = {2, 2, 2}, ilo[3] = {0.5, 0.5, 0.5}, ihi[3] = {1.5, 1.5, 1.5};
  add_box(plc, lo, hi, 1);
  add_box(plc, ilo, ihi, 7);
  plc.regions.push_back(RegionSeed{{0.25, 0.25, 0.25}, 1, 0});
  plc.regions.push_back(RegionSeed{{1, 1, 1}, 2, 0});
  CgalMeshParams params;
  params.max_size = 0.3;
  const Mesh m = mesh_plc_cgal(plc, params);
  auto vol = region_volumes(m);
  ASSERT_EQ(vol.size(), 2u);
  EXPECT_NEAR(vol.at(1), 7.0, 1e-9);
  EXPECT_NEAR(vol.at(2), 1.0, 1e-9);
  auto area = tag_areas(m);
  for (std::int32_t tag = 7; tag <= 12; ++tag) EXPECT_NEAR(area.at(tag), 1.0, 1e-9);  // the interface
  expect_certified(m, 10);

  // The inner box as a volume hole: not meshed, and the outer region keeps its 7 units.
  plc.regions.pop_back();
  plc.holes = {1, 1, 1};
  const Mesh h = mesh_plc_cgal(plc, params);
  vol = region_volumes(h);
  ASSERT_EQ(vol.size(), 1u);
  EXPECT_NEAR(vol.at(1), 7.0, 1e-9);
  area = tag_areas(h);
  for (std::int32_t tag = 7; tag <= 12; ++tag) EXPECT_NEAR(area.at(tag), 1.0, 1e-9);  // now a boundary
}

TEST(CgalMesher, DieOnSubstrateModelMatchesThePartVolumesAndBeatsTetgenAngles) {
  const Model model = load_model(source_file("models/die_on_substrate.toml"));
  const Structure st = build_structure(model);
  CgalMeshParams params;
  CgalMeshReport report;
  Mesh m = mesh_plc_cgal(st.plc, params, &report);
  const auto vol = region_volumes(m);
  ASSERT_EQ(vol.size(), st.part_volume.size());
  for (std::size_t p = 0; p < st.part_volume.size(); ++p)
    EXPECT_NEAR(vol.at(static_cast<std::int32_t>(p + 1)), st.part_volume[p], 1e-9 * st.part_volume[p])
        << "part " << p;
  const auto area = tag_areas(m);
  ASSERT_EQ(area.size(), st.boundary_area.size());  // every named surface is covered
  for (std::size_t b = 0; b < st.boundary_area.size(); ++b)
    EXPECT_NEAR(area.at(static_cast<std::int32_t>(b + 1)), st.boundary_area[b], 1e-8 * st.boundary_area[b])
        << st.boundary_names[b];
  expect_certified(m, 30);

  // TetGen -O0 (no flips or smoothing) with a similar tet count: CGAL's exuded mesh has better angles.
  MeshParams tp;
  double total = 0;
  for (double v : st.part_volume) total += v;
  tp.max_volume = 1.5 * total / static_cast<double>(m.tet_count());
  const Mesh t = mesh_plc(st.plc, tp);
  const double cgal_min = min_dihedral(m), tetgen_min = min_dihedral(t);
  std::printf(
      "die on substrate: CGAL %zu tets, min dihedral %.2f deg; TetGen -O0 %zu tets, min dihedral %.2f deg\n",
      m.tet_count(), cgal_min, t.tet_count(), tetgen_min);
  EXPECT_GT(cgal_min, tetgen_min);
}

TEST(CgalMesher, CylinderViaThroughALayerHasAnalyticVolumes) {
  const Plc plc = read_poly(source_file("examples/via_in_dielectric.poly"));
  CgalMeshParams params;
  params.max_size = 0.12;
  CgalMeshReport report;
  const Mesh m = mesh_plc_cgal(plc, params, &report);
  const double via = 0.5 * 8 * 0.2 * 0.2 * std::sin(std::numbers::pi / 8);  // 16-gon prism, r 0.2, height 0.5
  const double wall = 16 * 2 * 0.2 * std::sin(std::numbers::pi / 16) * 0.5;  // its side area
  const auto vol = region_volumes(m);
  ASSERT_EQ(vol.size(), 3u);
  // Every facet edge is protected: the 16-gon's wall keeps its facets, so every volume and area is the
  // PLC's (the .poly's coordinates are the 16-gon's to 1e-16).
  EXPECT_NEAR(vol.at(1), 0.5, 1e-9);
  EXPECT_NEAR(vol.at(2), 0.5 - via, 1e-9);
  EXPECT_NEAR(vol.at(3), via, 1e-9 * via);
  const auto area = tag_areas(m);
  EXPECT_EQ(area.size(), 8u);
  EXPECT_NEAR(area.at(1), 1.0, 1e-9);            // bottom
  EXPECT_NEAR(area.at(7), 1.0 - 2 * via, 1e-9);  // dielectric top
  EXPECT_NEAR(area.at(8), 2 * via, 1e-9);        // via top = its footprint
  EXPECT_NEAR(area.at(6), wall, 1e-9 * wall);
  // The report's PLC volumes (divergence theorem) are the analytic ones, its mesh volumes ours.
  ASSERT_EQ(report.volumes.size(), 3u);
  EXPECT_NEAR(report.volumes[2].plc, via, 1e-12);
  EXPECT_NEAR(report.volumes[2].mesh, vol.at(3), 1e-12);
  EXPECT_TRUE(report.volumes_match);
  EXPECT_LT(report.worst_volume_change, 1e-9);
  expect_certified(m, 30);

  MeshParams tp;
  tp.max_volume = 1.5 / static_cast<double>(m.tet_count());
  const Mesh t = mesh_plc(plc, tp);
  std::printf(
      "via: CGAL %zu tets, min dihedral %.2f deg, via volume error %.2e; TetGen -O0 %zu tets, min dihedral "
      "%.2f deg\n",
      m.tet_count(), min_dihedral(m), vol.at(3) / via - 1, t.tet_count(), min_dihedral(t));
  EXPECT_GT(min_dihedral(m), min_dihedral(t));
}

TEST(CgalMesher, ResamplingCutsTheViaAndReportsByHowMuch) {
  const Plc plc = read_poly(source_file("examples/via_in_dielectric.poly"));
  CgalMeshParams params;
  params.max_size = 0.12;
  params.resample = true;
  CgalMeshReport report;
  const Mesh m = mesh_plc_cgal(plc, params, &report);
  const double via = 0.5 * 8 * 0.2 * 0.2 * std::sin(std::numbers::pi / 8);
  const auto vol = region_volumes(m);
  ASSERT_EQ(vol.size(), 3u);
  // The box-shaped substrate keeps its sharp edges; the via's wall is one smooth patch whose rims'
  // protecting balls need not fall on the 16-gon's corners: chords cut it (a few percent at this size).
  EXPECT_NEAR(vol.at(1), 0.5, 1e-9);
  EXPECT_NEAR(vol.at(2) + vol.at(3), 0.5, 1e-9);
  EXPECT_NEAR(vol.at(3), via, 0.05 * via);
  EXPECT_TRUE(report.resampled);
  ASSERT_EQ(report.volumes.size(), 3u);
  for (const CgalRegionVolume& v : report.volumes) {
    EXPECT_NEAR(v.mesh, vol.at(v.region), 1e-12) << "region " << v.region;
    EXPECT_NEAR(v.relative_change(), vol.at(v.region) / v.plc - 1, 1e-12);
  }
  EXPECT_NEAR(report.volumes[2].plc, via, 1e-12);
  EXPECT_NE(vol.at(3), via);  // resampled: the via really changed
  EXPECT_NEAR(report.worst_volume_change,
              std::max(std::abs(vol.at(3) / via - 1), std::abs(vol.at(2) / (0.5 - via) - 1)), 1e-12);
  std::printf("via resampled: volume change %+.3f%%\n", 100 * (vol.at(3) / via - 1));
  expect_certified(m, 10);
}

// A shipped model meshed as `foxi mesh MODEL --mesher cgal` does (the model's max_size and part sizes):
// each region's volume against the model builder's own part volume and each tag's area against its
// boundary area (structure.cpp, from the parts, not from the PLC's facets) to 0.1%, and the mesh
// certified. The report's own checks must agree with these, always: with `may_be_refused` a mesh that
// misses them is accepted here as long as the report says so (the command then exits 4).
// The limit is the default's 300 s times three: the test machines are shared.
void expect_model_meshes(const std::string& name, double time_limit = 900, bool may_be_refused = false) {
  const Model model = load_model(source_file("models/" + name + ".toml"));
  const Structure st = build_structure(model);
  Plc plc = st.plc;
  const ModelMeshParams mp = mesh_params_from_model(model, plc);
  CgalMeshParams params;
  if (mp.params.max_volume > 0) params.max_size = regular_tet_circumradius(mp.params.max_volume);
  params.time_limit = time_limit;
  CgalMeshReport report;
  const auto t0 = std::chrono::steady_clock::now();
  const Mesh m = mesh_plc_cgal(plc, params, &report);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto vol = region_volumes(m);
  ASSERT_EQ(vol.size(), st.part_volume.size()) << name;
  double worst = 0;
  for (std::size_t p = 0; p < st.part_volume.size(); ++p) {
    const double v = vol.at(static_cast<std::int32_t>(p + 1)), want = st.part_volume[p];
    if (!may_be_refused) {
      EXPECT_NEAR(v, want, 1e-3 * want) << name << ": part " << model.parts[p].name;
    }
    worst = std::max(worst, std::abs(v / want - 1));
  }
  const auto area = tag_areas(m);
  double worst_area = 0;
  for (std::size_t b = 0; b < st.boundary_area.size(); ++b) {
    const auto it = area.find(static_cast<std::int32_t>(b + 1));
    const double a = it == area.end() ? 0.0 : it->second, want = st.boundary_area[b];
    if (!may_be_refused) {
      EXPECT_NEAR(a, want, 1e-3 * want) << name << ": " << st.boundary_names[b];
    }
    worst_area = std::max(worst_area, std::abs(a / want - 1));
  }
  EXPECT_EQ(report.volumes_match, worst <= 1e-3)
      << name << ": the report's volume check disagrees (worst change " << worst << ")";
  EXPECT_EQ(report.areas_match, worst_area <= 1e-3)
      << name << ": the report's area check disagrees (worst change " << worst_area << ")";
  std::printf(
      "%s: CGAL %zu tets in %.1f s, %zu patches (%zu facets joined, %zu without area), %zu points welded, "
      "%zu tets "
      "relabelled, worst part volume change %.2e, worst tag area change %.2e (tag %d), min dihedral %.2f "
      "deg%s\n",
      name.c_str(), m.tet_count(), seconds, report.patches, report.facets_joined, report.facets_without_area,
      report.points_welded, report.tets_relabelled, worst, worst_area, report.worst_area_marker,
      min_dihedral(m), report.volumes_match && report.areas_match ? "" : " (refused)");
  expect_certified(m, 6);
}

TEST(CgalMesher, ViaModelKeepsItsVolumes) { expect_model_meshes("via_in_dielectric"); }
TEST(CgalMesher, TrenchModelKeepsItsVolumes) { expect_model_meshes("trench"); }
TEST(CgalMesher, MultiChipModelKeepsItsVolumes) { expect_model_meshes("multi_chip"); }
// Thin solder layers under wide parts: about a million tets in 2 to 4 minutes. Mesh_3 does not recover
// the 10 x 10 mm interface between the 0.1 mm die attach and the 0.12 mm die (no boundary triangle has
// its tag; tets straddle it: 0.35% of the die's volume in the attach). Not solved: the report's checks
// must say so (the command refuses the mesh with exit 4), and agree with the builder's volumes and areas.
TEST(CgalMesherSlow, PowerModuleModelMeshesOrIsRefusedTruthfully) {
  expect_model_meshes("power_module", 900, true);
}
TEST(CgalMesherSlow, FlipChipBumpsKeepTheirVolumes) { expect_model_meshes("flip_chip"); }
// The bga's structure is a corefined triangle soup (balls cut by two boards); it failed with "facet
// 488 has no polygon with an area" before.
TEST(CgalMesherSlow, BgaModelMeshes) { expect_model_meshes("bga"); }

// die_attach: a 20 um solder layer under a 10 mm die. Mesh_3 either meshes it or stops at its time
// limit with MesherFailure::time_limit; either way within the limit (and a little for the fork).
TEST(CgalMesherSlow, DieAttachFinishesOrStopsWithinItsTimeLimit) {
  const double limit = 60;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    expect_model_meshes("die_attach", limit);
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::time_limit) << e.what();
    EXPECT_NE(std::string(e.what()).find("time limit of 60 s"), std::string::npos) << e.what();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, limit + 30);  // the builder, the facets, the kill, the certificate
}

TEST(CgalMesher, WeightsSurviveAVtuFileAndStillCertify) {
  CgalMeshParams params;
  params.max_size = 0.2;
  const Mesh m = mesh_plc_cgal(unit_box(), params);
  std::size_t weighted = 0;
  for (double w : m.weight) weighted += w != 0;
  EXPECT_GT(weighted, 0u);  // protecting balls and exudation give non-zero weights
  test::TempDir dir;
  write_mesh(m, dir / "box.vtu");
  const Mesh r = read_mesh(dir / "box.vtu");
  ASSERT_EQ(r.weight.size(), m.weight.size());
  EXPECT_TRUE(std::equal(r.weight.begin(), r.weight.end(), m.weight.begin()));
  EXPECT_TRUE(compute_delaunay_certificate(r).delaunay);
  // For the record: what the weights are worth (the same tets, certified as if unweighted).
  Mesh bare = m;
  bare.weight.clear();
  const DelaunayCertificate c = compute_delaunay_certificate(bare);
  std::printf("unit box without its weights: %zu of %zu tets have a vertex inside their circumsphere\n",
              c.violating_tet_count, c.tets_checked);
}

TEST(CgalMesher, BadPlcsTimeLimitAndCancelGiveTypedMesherErrors) {
  Plc outside = unit_box();
  outside.regions[0].point[0] = 3;
  try {
    mesh_plc_cgal(outside);
    FAIL() << "a seed outside the PLC was accepted";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::bad_input);
    EXPECT_NE(std::string(e.what()).find("outside every closed surface"), std::string::npos) << e.what();
  }
  Plc crossing = unit_box();
  crossing.add_facet({0, 2, 1, 3}, 9);  // a bow tie: its edges cross
  try {
    mesh_plc_cgal(crossing);
    FAIL() << "a facet with crossing edges was accepted";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::bad_input);
    EXPECT_NE(std::string(e.what()).find("facet 7"), std::string::npos) << e.what();
  }
  CgalMeshParams bad;
  bad.facet_angle = 40;
  try {
    mesh_plc_cgal(unit_box(), bad);
    FAIL() << "a facet angle of 40 degrees was accepted";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::bad_input);
  }

  // A run far longer than its limit is stopped at it.
  CgalMeshParams slow;
  slow.max_size = 0.004;  // millions of tets
  slow.time_limit = 1;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    mesh_plc_cgal(unit_box(), slow);
    FAIL() << "not stopped at the time limit";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::time_limit) << e.what();
    EXPECT_NE(std::string(e.what()).find("time limit of 1 s"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
            10 * test::kTimeScale);

  CgalMeshParams params;
  params.max_size = 0.01;  // long enough to be cancelled
  params.progress = [](std::string_view, double) { return false; };
  try {
    mesh_plc_cgal(unit_box(), params);
    FAIL() << "not cancelled";
  } catch (const MesherError& e) {
    EXPECT_EQ(e.failure(), MesherFailure::cancelled);
    EXPECT_EQ(e.tetgen_code(), -1);
    EXPECT_NE(dynamic_cast<const Cancelled*>(&e), nullptr);  // the one cancellation outcome
  }
}

}  // namespace
}  // namespace foxi
