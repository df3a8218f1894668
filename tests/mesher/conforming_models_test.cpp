// Every shipped model (models/*.toml), the three-material stack and a 20 um die-attach layer
// under a 10 mm die, meshed by the conforming mesher: zero non-Delaunay tets (exact certificate,
// computed here again), each region's volume equal to the part's volume from the structure builder,
// each named boundary's area equal to the builder's facet area (so every boundary tag is present),
// and the thin layer's tet count bounded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "foxi/mesher/conforming.hpp"
#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/quality_report.hpp"
#include "foxi/mesher/size_field.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/structure.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

struct ModelCase {
  const char* path;  // relative to tests/data
  double max_size;   // target edge length (m), 0: none
  double radius_edge;
};

class Models : public ::testing::TestWithParam<ModelCase> {};

TEST_P(Models, ConformingMeshIsDelaunayWithExactRegionsAndBoundaries) {
  const ModelCase c = GetParam();
  const Model model = load_model(test::data_dir() + "/" + c.path);
  const Structure s = build_structure(model);
  MeshParams params;
  params.radius_edge = c.radius_edge;
  if (c.max_size > 0) params.max_volume = regular_tet_volume(c.max_size);
  ConformingReport report;
  Mesh m = mesh_conforming(s.plc, params, {}, &report);
  name_mesh(model, s, m);

  const DelaunayCertificate cert = compute_delaunay_certificate(m);
  EXPECT_TRUE(cert.delaunay) << cert.violating_tet_count << " of " << m.tet_count() << " tets violate";
  EXPECT_EQ(cert.degenerate_tet_count, 0u);
  EXPECT_TRUE(report.delaunay);
  // Points added for conformity: at most 15% of the -O0 mesh's points, or, where foxi refines by
  // itself around thin layers (the first mesh is the bare PLC), of the other points of the mesh.
  const double base = report.thin_layers.empty() ? double(report.first_mesh_points)
                                                 : double(m.node_count() - report.added_points);
  EXPECT_LE(double(report.added_points), std::max(100.0, 0.15 * base));

  const MeshQualityReport q = mesh_quality_report(m, report);
  ASSERT_EQ(q.regions.size(), s.part_volume.size());
  for (const RegionSize& r : q.regions) {
    ASSERT_GE(r.id, 1);
    const double expect = s.part_volume[std::size_t(r.id - 1)];
    EXPECT_NEAR(r.volume, expect, 1e-9 * expect) << "region " << r.id;
  }
  std::map<std::int32_t, double> area;
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    const double* p = &m.xyz[3 * m.bface[3 * f]];
    const double* a = &m.xyz[3 * m.bface[3 * f + 1]];
    const double* b = &m.xyz[3 * m.bface[3 * f + 2]];
    const double u[3] = {a[0] - p[0], a[1] - p[1], a[2] - p[2]},
                 w[3] = {b[0] - p[0], b[1] - p[1], b[2] - p[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    area[m.bface_tag[f]] += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  for (std::size_t k = 0; k < s.boundary_area.size(); ++k) {
    const std::int32_t tag = static_cast<std::int32_t>(k + 1);
    ASSERT_TRUE(area.count(tag)) << "boundary " << s.boundary_names[k] << " has no triangles";
    EXPECT_NEAR(area[tag], s.boundary_area[k], 1e-9 * s.boundary_area[k]) << s.boundary_names[k];
  }
  // The report's count of tets over the radius-edge bound, counted here again.
  std::size_t over = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    over += tet_quality(&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]).radius_edge >
            c.radius_edge * (1 + 1e-6);
  }
  if (report.thin_layers.empty()) {
    EXPECT_EQ(report.over_radius_edge, over);
  }
  // Histogram counts every tet once.
  std::size_t hist = 0;
  for (std::size_t h : q.min_dihedral_histogram) hist += h;
  EXPECT_EQ(hist, m.tet_count());
}

std::string model_case_name(const ::testing::TestParamInfo<ModelCase>& p) {
  std::string n = p.param.path;
  const std::string dir = n.substr(0, n.rfind('/'));
  n = dir.substr(dir.rfind('/') + 1) + "_" + n.substr(n.rfind('/') + 1);  // models_x, cdt_x
  return n.substr(0, n.find('.'));
}

INSTANTIATE_TEST_SUITE_P(
    Shipped, Models,
    ::testing::Values(ModelCase{"../../models/die_on_substrate.toml", 1e-3, 1.414},
                      ModelCase{"../../models/flip_chip.toml", 0, 1.414},
                      ModelCase{"../../models/multi_chip.toml", 0, 1.414},
                      ModelCase{"../../models/via_in_dielectric.toml", 0, 1.414},
                      ModelCase{"../../models/trench.toml", 0, 1.414},
                      ModelCase{"cdt/three_material_stack.toml", 0.1e-3, 1.414},
                      // The 20 um layer is meshed flat by foxi's own refinement (TetGen's would fill
                      // it with 0.8 M tets of its thickness at -q1.414).
                      ModelCase{"cdt/die_attach.toml", 0, 1.414}),
    model_case_name);

// Corefined faceted balls (bga: TetGen 1.5.0 fails on the refined PLC, the surface rounds certify it)
// and the shipped die attach: labelled slow (the suite name), about 4 minutes and 45 s under the
// sanitizers, so only the Release pass runs them.
INSTANTIATE_TEST_SUITE_P(ShippedSlow, Models,
                         ::testing::Values(ModelCase{"../../models/bga.toml", 1e-3, 1.414},
                                           ModelCase{"../../models/die_attach.toml", 1.5e-3, 1.414}),
                         model_case_name);

// The power module shrunk (its own [mesh] controls): the ceramic overhangs the copper under and over
// it, and tets in the overhang have circumspheres reaching round the copper's edge to vertices hidden
// behind a boundary triangle that none of them encroaches. Only splitting that separating triangle
// certifies it (without it 2 tets stay non-Delaunay).
TEST(Models, OverhangingCeramicIsCertified) {
  const std::vector<std::string> shrink{"base_w=16 mm", "base_d=12 mm", "dbc_w=12 mm", "dbc_d=8 mm",
                                        "pad1_w=6 mm",  "die_w=3 mm",   "pad_gap=1 mm"};
  const Model model = load_model(test::data_dir() + "/../../models/power_module.toml", shrink);
  const Structure s = build_structure(model);
  Plc plc = s.plc;
  const ModelMeshParams mp = mesh_params_from_model(model, plc);
  ConformingReport report;
  const Mesh m = mesh_conforming(plc, mp.params, {}, &report);
  const DelaunayCertificate cert = compute_delaunay_certificate(m);
  EXPECT_TRUE(cert.delaunay) << cert.violating_tet_count << " of " << m.tet_count() << " tets violate";
  EXPECT_EQ(cert.degenerate_tet_count, 0u);
  const MeshQualityReport q = mesh_quality_report(m, report);
  ASSERT_EQ(q.regions.size(), s.part_volume.size());
  for (const RegionSize& r : q.regions) {
    const double expect = s.part_volume[std::size_t(r.id - 1)];
    EXPECT_NEAR(r.volume, expect, 1e-9 * expect) << "region " << r.id;
  }
}

TEST(Models, ThinDieAttachLayerDoesNotExplode) {
  const Model model = load_model(test::data_dir() + "/cdt/die_attach.toml");
  const Structure s = build_structure(model);
  MeshParams params;  // the default radius-edge bound, 1.414
  ConformingReport report;
  const Mesh m = mesh_conforming(s.plc, params, {}, &report);
  ASSERT_TRUE(report.delaunay);
  ASSERT_EQ(report.thin_layers.size(), 1u);
  std::size_t layer = 0, flat_outside = 0;
  double worst_outside = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    const TetQuality q = tet_quality(&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]);
    // The layer by its region id and z range, not by the mesher's own layer test.
    bool in_layer = m.region_of(t) == 2;
    for (int i = 0; i < 4; ++i)
      in_layer = in_layer && m.xyz[3 * v[i] + 2] >= 1e-3 - 1e-12 && m.xyz[3 * v[i] + 2] <= 1.02e-3 + 1e-12;
    if (in_layer) {
      ++layer;
      continue;
    }
    worst_outside = std::max(worst_outside, q.radius_edge);
    flat_outside += q.min_dihedral_deg < 1;
  }
  // TetGen's own refinement puts 0.8 M tets in the layer (2.7 M in all); the layer's tets span its
  // thickness and are as wide as the die's surface mesh, and the bound holds everywhere else.
  EXPECT_GT(layer, 0u);
  EXPECT_LE(layer, 20000u) << layer << " tets in the 20 um layer";
  EXPECT_LE(m.tet_count(), 100000u);
  EXPECT_LE(worst_outside, 1.414 * (1 + 1e-6));
  EXPECT_EQ(flat_outside, 0u);
  EXPECT_EQ(report.quality_unmet, 0u);
  std::printf("die attach: %zu tets, %zu in the layer, radius-edge max %.3f outside it, %zu rounds\n",
              m.tet_count(), layer, worst_outside, report.iterations);
}

}  // namespace
}  // namespace foxi
