// Size control: per-region and box sizes reach TetGen (measured element sizes), and remeshing from a
// solved temperature field concentrates elements where the field's gradient is large (measured from
// the solution itself: tet density in the high-gradient zone against a low-gradient zone).
#include "foxi/mesher/size_field.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "foxi/mesher/conforming.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/model_file.hpp"
#include "foxi/model/quality.hpp"
#include "foxi/model/structure.hpp"
#include "foxi/solver/thermal.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

Structure die_on_substrate(Model& model) {
  model = load_model(test::data_dir() + "/../../models/die_on_substrate.toml");
  return build_structure(model);
}

void centroid(const Mesh& m, std::size_t t, double c[3]) {
  for (int k = 0; k < 3; ++k) {
    c[k] = 0;
    for (int i = 0; i < 4; ++i) c[k] += 0.25 * m.xyz[3 * m.tet[4 * t + std::size_t(i)] + std::size_t(k)];
  }
}

// Tets per m^3 of substrate (region 1) whose centroid is in the box [lo, hi] (x, y; all z).
double density(const Mesh& m, double x0, double y0, double x1, double y1) {
  double vol = 0;
  std::size_t n = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    if (m.region_of(t) != 1) continue;
    double c[3];
    centroid(m, t, c);
    if (c[0] < x0 || c[0] > x1 || c[1] < y0 || c[1] > y1) continue;
    const std::uint32_t* v = &m.tet[4 * t];
    vol +=
        std::abs(tet_quality(&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]).volume);
    ++n;
  }
  return vol > 0 ? double(n) / vol : 0;
}

std::int32_t tag_named(const Mesh& m, const std::string& name) {
  for (const Boundary& b : m.boundaries)
    if (b.name == name) return b.tag;
  return -1;
}

TEST(SizeField, RegionSizeShrinksOnlyThatRegion) {
  Model model;
  const Structure s = die_on_substrate(model);
  SizeControls c;
  c.region_ids = {2};
  c.region_sizes = {0.2e-3};
  const Plc plc = with_region_sizes(s.plc, c);
  MeshParams params;
  params.max_volume = regular_tet_volume(1e-3);
  const Mesh m = mesh_plc(plc, params);
  double vmax[3] = {0, 0, 0};
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* v = &m.tet[4 * t];
    const double vol =
        std::abs(tet_quality(&m.xyz[3 * v[0]], &m.xyz[3 * v[1]], &m.xyz[3 * v[2]], &m.xyz[3 * v[3]]).volume);
    vmax[m.region_of(t)] = std::max(vmax[m.region_of(t)], vol);
  }
  EXPECT_LE(vmax[2], regular_tet_volume(0.2e-3) * (1 + 1e-9));
  EXPECT_GT(vmax[1], 10 * regular_tet_volume(0.2e-3));  // the substrate keeps the global size
  SizeControls bad;
  bad.region_ids = {9};
  bad.region_sizes = {1e-3};
  EXPECT_THROW(with_region_sizes(s.plc, bad), MesherError);
}

TEST(SizeField, RefinementBoxConcentratesElementsInsideIt) {
  Model model;
  const Structure s = die_on_substrate(model);
  MeshParams params;
  params.max_volume = regular_tet_volume(1e-3);
  SizeControls c;
  c.max_size = 1e-3;
  RefinementBox box;
  box.lo[0] = 0, box.lo[1] = 0, box.lo[2] = 0;
  box.hi[0] = 2e-3, box.hi[1] = 2e-3, box.hi[2] = 1e-3;
  box.size = 0.2e-3;
  c.boxes = {box};
  const SizeField f = box_size_field(s.plc, params, c);
  params.size_field = &f;
  ConformingReport report;
  const Mesh m = mesh_conforming(s.plc, params, {}, &report);
  EXPECT_TRUE(compute_delaunay_certificate(m).delaunay);
  const double in = density(m, 0, 0, 2e-3, 2e-3), out = density(m, 6e-3, 4e-3, 10e-3, 8e-3);
  // (1 mm / 0.2 mm)^3 = 125 times more tets per volume in theory; TetGen grades (measured 25), so
  // ask for 10.
  EXPECT_GT(in, 10 * out) << "box " << in << " / m^3, far " << out << " / m^3";
}

// Mean edge length of the tets whose centroid lies in [lo, hi], and how many there are.
std::pair<double, std::size_t> mean_edge_in(const Mesh& m, const double lo[3], const double hi[3]) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    double c[3];
    centroid(m, t, c);
    if (c[0] < lo[0] || c[0] > hi[0] || c[1] < lo[1] || c[1] > hi[1] || c[2] < lo[2] || c[2] > hi[2])
      continue;
    const std::uint32_t* v = &m.tet[4 * t];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) {
          const double e = m.xyz[3 * v[j] + std::size_t(k)] - m.xyz[3 * v[i] + std::size_t(k)];
          d2 += e * e;
        }
        sum += std::sqrt(d2) / 6;
      }
    ++n;
  }
  return {n > 0 ? sum / double(n) : 0, n};
}

// A box narrower than the first mesh's tets holds none of its nodes: sampled at those nodes alone it
// was lost (a trench PLC kept 0.17 edges in a 0.2-wide box asking 0.05). The graded sizes around it
// refine there until it holds nodes and its size.
TEST(SizeField, BoxNarrowerThanTheFirstMeshsTetsStillRefines) {
  Model model;
  const Structure s = die_on_substrate(model);
  MeshParams params;
  params.max_volume = regular_tet_volume(2e-3);
  SizeControls c;
  c.max_size = 2e-3;
  RefinementBox box;
  const double lo[3] = {7.6e-3, 1.6e-3, 0.3e-3}, hi[3] = {8.0e-3, 2.0e-3, 0.7e-3};
  for (int k = 0; k < 3; ++k) box.lo[k] = lo[k], box.hi[k] = hi[k];
  box.size = 0.1e-3;
  c.boxes = {box};
  auto nodes_in_box = [&](const Mesh& m) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < m.node_count(); ++i) {
      const double* p = &m.xyz[3 * i];
      n += p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] && p[2] <= hi[2];
    }
    return n;
  };
  ASSERT_EQ(nodes_in_box(mesh_plc(s.plc, params)), 0u) << "the first mesh must miss the box for this test";
  const SizeField f = box_size_field(s.plc, params, c);
  params.size_field = &f;
  const Mesh m = mesh_plc(s.plc, params);
  EXPECT_TRUE(compute_delaunay_certificate(m).delaunay);
  EXPECT_GT(nodes_in_box(m), 8u);
  const auto [inside, n_inside] = mean_edge_in(m, lo, hi);
  ASSERT_GT(n_inside, 0u);
  EXPECT_LT(inside, 2.5 * box.size) << n_inside << " tets in the box";
  const double far_lo[3] = {0, 4e-3, 0}, far_hi[3] = {3e-3, 8e-3, 1e-3};
  EXPECT_GT(mean_edge_in(m, far_lo, far_hi).first, 5 * box.size);  // far from it, the global size
}

TEST(SizeField, RefinementFromASolvedFieldFollowsTheGradient) {
  Model model;
  const Structure s = die_on_substrate(model);
  MeshParams params;
  params.max_volume = regular_tet_volume(1e-3);
  Mesh coarse = mesh_conforming(s.plc, params);
  name_mesh(model, s, coarse);
  // 1 W in the die, substrate bottom at 300 K: the heat spreads through the FR-4 under the die.
  ThermalParams tp;
  tp.fixed = {{tag_named(coarse, "substrate.bottom"), 300}};
  tp.sources = {{2, 1.0, true}};
  solve_thermal(coarse, tp);
  const Field* temp = nullptr;
  for (const Field& f : coarse.fields)
    if (f.name == "temperature") temp = &f;
  ASSERT_NE(temp, nullptr);

  // The oracle for "where the gradient is large": |grad T| of the solution, averaged over the tets
  // of two zones of the substrate: under the die (x 3..7 mm, y 2.5..5.5 mm) and a far corner.
  auto mean_gradient = [&](double x0, double y0, double x1, double y1) {
    double sum = 0, vol = 0;
    for (std::size_t t = 0; t < coarse.tet_count(); ++t) {
      double c[3];
      centroid(coarse, t, c);
      if (coarse.region_of(t) != 1 || c[0] < x0 || c[0] > x1 || c[1] < y0 || c[1] > y1) continue;
      const std::uint32_t* v = &coarse.tet[4 * t];
      const double* p[4] = {&coarse.xyz[3 * v[0]], &coarse.xyz[3 * v[1]], &coarse.xyz[3 * v[2]],
                            &coarse.xyz[3 * v[3]]};
      // |q| = k |grad T| from the solver's heat_flux cell field: k is constant in the substrate.
      const double w = std::abs(tet_quality(p[0], p[1], p[2], p[3]).volume);
      double g2 = 0;
      for (const Field& f : coarse.fields)
        if (f.name == "heat_flux" && f.location == FieldLocation::cell)
          for (int k = 0; k < 3; ++k)
            g2 += f.values[3 * t + std::size_t(k)] * f.values[3 * t + std::size_t(k)];
      sum += std::sqrt(g2) * w;
      vol += w;
    }
    return sum / vol;
  };
  const double g_near = mean_gradient(3e-3, 2.5e-3, 7e-3, 5.5e-3), g_far = mean_gradient(0, 0, 2e-3, 2e-3);
  ASSERT_GT(g_near, 3 * g_far) << "the test problem should have its gradient under the die";

  const ErrorIndicator e = zz_error_indicator(coarse, *temp);
  EXPECT_EQ(e.tet_error.size(), coarse.tet_count());
  EXPECT_GT(e.relative_error(), 0);
  const SizeField f = size_field_from_error(coarse, *temp, 0.5 * e.relative_error());
  params.size_field = &f;
  ConformingReport report;
  const Mesh fine = mesh_conforming(s.plc, params, {}, &report);
  EXPECT_TRUE(compute_delaunay_certificate(fine).delaunay);
  EXPECT_GT(fine.tet_count(), coarse.tet_count());

  const double before = density(coarse, 3e-3, 2.5e-3, 7e-3, 5.5e-3) / density(coarse, 0, 0, 2e-3, 2e-3);
  const double after = density(fine, 3e-3, 2.5e-3, 7e-3, 5.5e-3) / density(fine, 0, 0, 2e-3, 2e-3);
  // Measured: 0.79 before, 79 after (3,738 -> 30,915 tets); ask for a tenfold concentration.
  EXPECT_GT(after, 10 * before) << "density ratio under the die / far corner: before " << before << ", after "
                                << after << " (" << coarse.tet_count() << " -> " << fine.tet_count()
                                << " tets)";
}

TEST(SizeField, ErrorIndicatorVanishesForALinearField) {
  Model model;
  const Structure s = die_on_substrate(model);
  MeshParams params;
  params.max_volume = regular_tet_volume(1e-3);
  const Mesh m = mesh_plc(s.plc, params);
  Field f;
  f.name = "linear";
  f.values.resize(m.node_count());
  for (std::size_t n = 0; n < m.node_count(); ++n)
    f.values[n] = 3 * m.xyz[3 * n] - 2 * m.xyz[3 * n + 1] + m.xyz[3 * n + 2];
  const ErrorIndicator e = zz_error_indicator(m, f);
  // Recovery reproduces a linear field's constant gradient exactly: no error anywhere.
  EXPECT_NEAR(e.gradient_norm, std::sqrt(14.0 * summarize_quality(m).total_volume), 1e-9);
  EXPECT_LT(e.total_error, 1e-9 * e.gradient_norm);
  EXPECT_EQ(e.tets_without_value, 0u);
  // Without a value (NaN, as an imported field outside its source) for the nodes with x beyond the
  // middle: the tets touching them are counted and left out, the rest is still the exact gradient
  // (over the valued tets' volume) and no error; their sizes stay their own.
  Field part = f;
  std::size_t expect_nan = 0;
  double valued_volume = 0;
  const double mid = 0.5 * 10e-3;
  for (std::size_t n = 0; n < m.node_count(); ++n)
    if (m.xyz[3 * n] > mid) part.values[n] = NAN;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    bool nan = false;
    for (int i = 0; i < 4; ++i) nan = nan || m.xyz[3 * m.tet[4 * t + std::size_t(i)]] > mid;
    if (nan) {
      ++expect_nan;
    } else {
      double p[4][3];
      for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) p[i][k] = m.xyz[3 * m.tet[4 * t + std::size_t(i)] + std::size_t(k)];
      double a[3], b[3], c[3];
      for (int k = 0; k < 3; ++k)
        a[k] = p[1][k] - p[0][k], b[k] = p[2][k] - p[0][k], c[k] = p[3][k] - p[0][k];
      valued_volume += std::abs(a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                                a[2] * (b[0] * c[1] - b[1] * c[0])) /
                       6;
    }
  }
  ASSERT_GT(expect_nan, 0u);
  ASSERT_LT(expect_nan, m.tet_count());
  const ErrorIndicator ep = zz_error_indicator(m, part);
  EXPECT_EQ(ep.tets_without_value, expect_nan);
  EXPECT_NEAR(ep.gradient_norm, std::sqrt(14.0 * valued_volume), 1e-9);
  EXPECT_LT(ep.total_error, 1e-9 * ep.gradient_norm);
  const SizeField sf = size_field_from_error(m, part, 0.1);
  for (double h : sf.size) EXPECT_TRUE(std::isfinite(h) && h > 0);
  std::fill(part.values.begin(), part.values.end(), NAN);
  EXPECT_THROW(size_field_from_error(m, part, 0.1), MesherError);
  f.location = FieldLocation::cell;
  EXPECT_THROW(zz_error_indicator(m, f), MesherError);
  EXPECT_THROW(size_field_from_error(m, Field{}, 0.1), MesherError);
}

}  // namespace
}  // namespace foxi
