// Field sampling for colouring: components and derived scalars against hand values (von Mises of
// uniaxial stress and pure shear), centroid values of a linear field equal the field at the centroid,
// graded corners of a cell field never blend across regions, display units, bad selections refused.
#include "foxi/viz/field_paint.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "mesh_factory.hpp"

namespace foxi {
namespace {

double linear(const double* p) { return 3 * p[0] - 2 * p[1] + 0.5 * p[2] + 7; }

Mesh grid_with_fields() {
  Mesh m = test::grid_mesh(3, 2, 2, 1, 1, 1, 6);
  test::regions_along_x(m, 1, 2);  // three regions along x
  Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
  Field u{"displacement", FieldLocation::node, 3, "m", {}, {}};
  for (std::size_t n = 0; n < m.node_count(); ++n) {
    t.values.push_back(linear(&m.xyz[3 * n]));
    for (int k = 0; k < 3; ++k) u.values.push_back(double(k + 1) * linear(&m.xyz[3 * n]));
  }
  Field s{"stress", FieldLocation::cell, 6, "Pa", {}, {}};
  for (std::size_t e = 0; e < m.tet_count(); ++e) {
    const double r = m.region_of(e);
    for (double v : {r, 0.0, 0.0, 0.0, 0.0, 0.0}) s.values.push_back(v * 1e6);  // uniaxial r MPa
  }
  m.fields = {t, u, s};
  return m;
}

TEST(FieldPaint, ChoosesScalarsAndDerivedQuantities) {
  const Mesh m = grid_with_fields();
  EXPECT_EQ(choose_field(m, "temperature").scalar.kind, FieldScalar::Kind::component);
  EXPECT_EQ(choose_field(m, "displacement").scalar.kind, FieldScalar::Kind::magnitude);
  EXPECT_EQ(choose_field(m, "displacement:y").scalar.component, 1u);
  EXPECT_EQ(choose_field(m, "displacement:2").scalar.component, 2u);
  EXPECT_EQ(choose_field(m, "stress").scalar.kind, FieldScalar::Kind::von_mises);
  EXPECT_EQ(choose_field(m, "stress:xy").scalar.component, 3u);
  EXPECT_THROW(choose_field(m, "pressure"), FieldSelectError);
  EXPECT_THROW(choose_field(m, "displacement:w"), FieldSelectError);
  EXPECT_THROW(choose_field(m, "displacement:3"), FieldSelectError);
  EXPECT_THROW(choose_field(m, "temperature:x"), FieldSelectError);
  try {
    choose_field(m, "pressure");
  } catch (const FieldSelectError& e) {
    EXPECT_NE(std::string(e.what()).find("temperature, displacement, stress"), std::string::npos) << e.what();
  }
  EXPECT_THROW(field_scalar_values(m, choose_field(m, "temperature"), 1), FieldSelectError);
}

TEST(FieldPaint, VonMisesOfUniaxialStressAndPureShear) {
  Mesh m = test::grid_mesh(1, 1, 1, 1, 1, 1, 5);
  Field s{"stress", FieldLocation::cell, 6, "Pa", {}, {}};
  const double tau = 2.5e6;
  for (std::size_t e = 0; e < m.tet_count(); ++e)
    for (double v : {e == 0 ? 7e6 : 0.0, 0.0, 0.0, e == 0 ? 0.0 : tau, 0.0, 0.0}) s.values.push_back(v);
  Field full{"sigma", FieldLocation::cell, 9, "Pa", {}, {}};
  for (std::size_t e = 0; e < m.tet_count(); ++e)
    for (double v : {0.0, tau, 0.0, tau, 0.0, 0.0, 0.0, 0.0, 0.0}) full.values.push_back(v);
  m.fields = {s, full};
  const std::vector<double> vm = field_scalar_values(m, choose_field(m, "stress"));
  EXPECT_NEAR(vm[0], 7e6, 1e-6);                   // uniaxial: sigma itself
  EXPECT_NEAR(vm[1], std::sqrt(3.0) * tau, 1e-6);  // pure shear: sqrt(3) tau
  EXPECT_NEAR(field_scalar_values(m, choose_field(m, "sigma"))[2], std::sqrt(3.0) * tau, 1e-6);
}

TEST(FieldPaint, PrincipalValuesAreTheEigenvaluesOfRotatedDiagonalTensors) {
  // A = R diag(l) R^T for random rotations R and eigenvalues l (some repeated): p1 >= p2 >= p3 are l.
  Mesh m = test::grid_mesh(2, 2, 2, 1, 1, 1, 6);
  std::mt19937 rng(12);
  std::normal_distribution<double> g(0, 1);
  Field s{"s", FieldLocation::cell, 6, "Pa", {}, {}};
  std::vector<std::array<double, 3>> want;
  for (std::size_t e = 0; e < m.tet_count(); ++e) {
    double l[3] = {g(rng) * 1e6, g(rng) * 1e6, g(rng) * 1e6};
    if (e % 5 == 0) l[1] = l[0];               // a double eigenvalue
    if (e % 7 == 0) l[1] = l[2] = l[0] = 3e5;  // isotropic
    // A random rotation: Gram-Schmidt on three Gaussian vectors.
    double r[3][3];
    for (auto& row : r)
      for (double& v : row) v = g(rng);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < i; ++j) {
        const double d = r[i][0] * r[j][0] + r[i][1] * r[j][1] + r[i][2] * r[j][2];
        for (int k = 0; k < 3; ++k) r[i][k] -= d * r[j][k];
      }
      const double n = std::sqrt(r[i][0] * r[i][0] + r[i][1] * r[i][1] + r[i][2] * r[i][2]);
      for (int k = 0; k < 3; ++k) r[i][k] /= n;
    }
    auto a = [&](int i, int j) {
      return r[0][i] * l[0] * r[0][j] + r[1][i] * l[1] * r[1][j] + r[2][i] * l[2] * r[2][j];
    };
    for (double v : {a(0, 0), a(1, 1), a(2, 2), a(0, 1), a(1, 2), a(0, 2)}) s.values.push_back(v);
    std::sort(l, l + 3, [](double x, double y) { return x > y; });
    want.push_back({l[0], l[1], l[2]});
  }
  m.fields = {s};
  for (int k = 0; k < 3; ++k) {
    const std::vector<double> p = field_scalar_values(m, choose_field(m, std::string("s:p") + char('1' + k)));
    for (std::size_t e = 0; e < m.tet_count(); ++e)  // the closed form loses digits near double roots
      EXPECT_NEAR(p[e], want[e][std::size_t(k)], 1e-7 * 5e6) << "tet " << e << " p" << k + 1;
  }
  EXPECT_THROW(choose_field(m, "s:p4"), FieldSelectError);
}

TEST(FieldPaint, CentroidValuesOfALinearFieldAreTheFieldAtTheCentroid) {
  const Mesh m = grid_with_fields();
  const std::vector<double> t = tet_centroid_values(m, choose_field(m, "temperature"));
  const std::vector<double> mag = tet_centroid_values(m, choose_field(m, "displacement"));
  for (std::size_t e = 0; e < m.tet_count(); ++e) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j)
        c[j] += 0.25 * m.xyz[3 * std::size_t(m.tet[4 * e + std::size_t(k)]) + std::size_t(j)];
    EXPECT_NEAR(t[e], linear(c), 1e-12);
    EXPECT_NEAR(mag[e], std::sqrt(14.0) * std::abs(linear(c)), 1e-11);  // |(1, 2, 3) f|
  }
}

// An infinite node value is no value (NaN) in the pictures' samples: its corners, and the centroids
// of the tets that have it (an isosurface through it would sit at the finite end of every edge).
TEST(FieldPaint, InfiniteValuesAreNoValues) {
  Mesh m = grid_with_fields();
  std::vector<double>& t = m.fields[0].values;
  t[3] = std::numeric_limits<double>::infinity();
  t[5] = -std::numeric_limits<double>::infinity();
  const FieldChoice c = choose_field(m, "temperature");
  const std::vector<double> corner = tet_corner_values(m, c), centre = tet_centroid_values(m, c);
  for (std::size_t i = 0; i < corner.size(); ++i)
    EXPECT_EQ(std::isnan(corner[i]), m.tet[i] == 3 || m.tet[i] == 5) << i;
  for (std::size_t e = 0; e < m.tet_count(); ++e) {
    bool touches = false;
    for (int k = 0; k < 4; ++k)
      touches = touches || m.tet[4 * e + std::size_t(k)] == 3 || m.tet[4 * e + std::size_t(k)] == 5;
    EXPECT_EQ(std::isnan(centre[e]), touches) << e;
  }
  EXPECT_THROW(choose_field(m, "temperature:"), FieldSelectError);
  EXPECT_THROW(choose_field(m, "displacement:"), FieldSelectError);
}

TEST(FieldPaint, GradedCellFieldsAverageWithinTheirRegionOnly) {
  const Mesh m = grid_with_fields();
  // The stress is uniaxial r MPa in region r: every corner of a region-r tet is exactly r MPa, even at
  // nodes shared with other regions (blending across the interface would give a value in between).
  const std::vector<double> c = tet_corner_values(m, choose_field(m, "stress:xx"));
  for (std::size_t e = 0; e < m.tet_count(); ++e)
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(c[4 * e + std::size_t(k)], m.region_of(e) * 1e6, 1e-6);
  // A node field's corners are its node values.
  const std::vector<double> tc = tet_corner_values(m, choose_field(m, "temperature"));
  for (std::size_t i = 0; i < tc.size(); ++i) EXPECT_EQ(tc[i], m.fields[0].values[m.tet[i]]);
}

TEST(FieldPaint, GradedCellFieldCornerLiesBetweenItsTetsValues) {
  // A cell field sampled from a linear function at each tet's centroid, averaged to the nodes with
  // volume weights: a weighted mean, so each corner lies within the values of the tets around its node.
  Mesh m = test::grid_mesh(4, 4, 4, 1, 1, 1, 6);
  Field f{"q", FieldLocation::cell, 1, "", {}, {}};
  for (std::size_t e = 0; e < m.tet_count(); ++e) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j)
        c[j] += 0.25 * m.xyz[3 * std::size_t(m.tet[4 * e + std::size_t(k)]) + std::size_t(j)];
    f.values.push_back(linear(c));
  }
  m.fields = {f};
  const std::vector<double> corner = tet_corner_values(m, choose_field(m, "q"));
  std::vector<double> lo(m.node_count(), 1e300), hi(m.node_count(), -1e300);
  for (std::size_t i = 0; i < corner.size(); ++i) {
    lo[m.tet[i]] = std::min(lo[m.tet[i]], f.values[i / 4]);
    hi[m.tet[i]] = std::max(hi[m.tet[i]], f.values[i / 4]);
  }
  for (std::size_t i = 0; i < corner.size(); ++i) {
    EXPECT_GE(corner[i], lo[m.tet[i]] - 1e-12);
    EXPECT_LE(corner[i], hi[m.tet[i]] + 1e-12);
  }
}

TEST(FieldPaint, DisplayUnits) {
  EXPECT_NEAR(display_unit("K", "degC")->to_display(300), 26.85, 1e-12);
  EXPECT_EQ(display_unit("K", "degC")->symbol, "°C");
  EXPECT_NEAR(display_unit("Pa", "MPa")->to_display(2.5e8), 250, 1e-9);
  EXPECT_NEAR(display_unit("m", "um")->to_display(3e-6), 3, 1e-12);
  EXPECT_NEAR(display_unit("V", "mV")->to_si(12), 0.012, 1e-15);
  EXPECT_FALSE(display_unit("K", "MPa").has_value());
  EXPECT_EQ(default_display_unit("K", 400).symbol, "°C");
  EXPECT_EQ(default_display_unit("W/m^2", 4).symbol, "W/m^2");
}

TEST(FieldPaint, PaintsPlaceValuesOnTheScale) {
  ColorScale s;
  s.lo = 10;
  s.hi = 20;
  const std::vector<double> v = {10, 15, 20, std::nan("")};
  const FieldPaint flat = flat_field_paint(v, s);
  EXPECT_FALSE(flat.graded);
  EXPECT_EQ(flat.tet_color[1], color_map_entry(s.map, 128));
  EXPECT_EQ(flat.tet_color[3], s.nan_color);
  const FieldPaint graded = graded_field_paint(v, s);
  EXPECT_TRUE(graded.graded);
  EXPECT_EQ(graded.corner_position[1], 0.5f);
  EXPECT_TRUE(std::isnan(graded.corner_position[3]));
  const auto r = finite_range(v);
  EXPECT_EQ(r.first, 10);
  EXPECT_EQ(r.second, 20);
}

}  // namespace
}  // namespace foxi
