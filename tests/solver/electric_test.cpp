// Electrostatics and DC conduction against analytic values: parallel plates and layered dielectrics
// (exact with P1: the field is piecewise uniform), concentric spheres and a coaxial capacitor (gmsh
// meshes, error falling under refinement), bars in series and parallel (exact), Joule heat,
// fixed-current terminals, and the ill-posed problems.
#include "foxi/solver/electric.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "foxi/model/io_gmsh.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/solver/thermal.hpp"
#include "layered_box.hpp"
#include "test_util.hpp"

namespace foxi {
namespace {

constexpr double kEps0 = 8.8541878128e-12;

void expect_checks_pass(const std::vector<BalanceCheck>& checks) {
  EXPECT_FALSE(checks.empty());
  for (const BalanceCheck& c : checks)
    EXPECT_TRUE(c.passed) << c.name << ": " << c.figure << " > " << c.tolerance << " (" << c.what << ")";
}

// A box [0,lx] x [0,ly] x [0,lz] cut into n[0] x n[1] x n[2] cubes of 6 tets each (Kuhn split).
// Boundary tags: 1 at x = 0, 2 at x = lx, 3 at y = 0 and y = ly, 4 at z = 0 and z = lz. The region of a
// tet is region(centroid).
template <class RegionFn>
Mesh box(std::array<int, 3> n, std::array<double, 3> l, RegionFn region) {
  Mesh m;
  auto id = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>((k * (n[1] + 1) + j) * (n[0] + 1) + i);
  };
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i) {
        m.xyz.push_back(l[0] * i / n[0]);
        m.xyz.push_back(l[1] * j / n[1]);
        m.xyz.push_back(l[2] * k / n[2]);
      }
  // The 6 tets of the Kuhn split of a cube: paths from corner 0 to corner 7 along the axes.
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          double centroid[3] = {0, 0, 0};
          for (int s = 0; s < 4; ++s) {
            if (s > 0) ++c[p[s - 1]];
            m.tet.push_back(id(c[0], c[1], c[2]));
            for (int a = 0; a < 3; ++a) centroid[a] += 0.25 * l[a] * c[a] / n[a];
          }
          m.tet_region.push_back(region(centroid[0], centroid[1], centroid[2]));
        }
  auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, std::int32_t tag) {
    for (std::uint32_t v : {a, b, c, a, c, d}) m.bface.push_back(v);
    m.bface_tag.push_back(tag);
    m.bface_tag.push_back(tag);
  };
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j) {
      quad(id(0, j, k), id(0, j + 1, k), id(0, j + 1, k + 1), id(0, j, k + 1), 1);
      quad(id(n[0], j, k), id(n[0], j + 1, k), id(n[0], j + 1, k + 1), id(n[0], j, k + 1), 2);
    }
  for (int k = 0; k < n[2]; ++k)
    for (int i = 0; i < n[0]; ++i) {
      quad(id(i, 0, k), id(i + 1, 0, k), id(i + 1, 0, k + 1), id(i, 0, k + 1), 3);
      quad(id(i, n[1], k), id(i + 1, n[1], k), id(i + 1, n[1], k + 1), id(i, n[1], k + 1), 3);
    }
  for (int j = 0; j < n[1]; ++j)
    for (int i = 0; i < n[0]; ++i) {
      quad(id(i, j, 0), id(i + 1, j, 0), id(i + 1, j + 1, 0), id(i, j + 1, 0), 4);
      quad(id(i, j, n[2]), id(i + 1, j, n[2]), id(i + 1, j + 1, n[2]), id(i, j + 1, n[2]), 4);
    }
  std::vector<std::int32_t> ids(m.tet_region);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  for (std::int32_t r : ids) m.regions.push_back({r, "r" + std::to_string(r), kNone});
  validate_and_repair(m);
  return m;
}

Mesh box(std::array<int, 3> n, std::array<double, 3> l) {
  return box(n, l, [](double, double, double) { return 1; });
}

Electrode electrode(std::string name, std::vector<std::int32_t> tags, double volts = 0) {
  Electrode e;
  e.name = std::move(name);
  e.tags = std::move(tags);
  e.voltage = volts;
  return e;
}

TEST(Electrostatic, ParallelPlatesAreExactWithEnergyAndUniformField) {
  const double d = 2e-3, w = 10e-3, h = 5e-3, er = 4.5, v = 3;
  Mesh m = box({6, 5, 4}, {d, w, h});
  ElectrostaticParams p;
  p.permittivity = {{1, er}};
  p.conductors = {electrode("top", {2}, v), electrode("bottom", {1}, 0)};
  for (LinearSolverKind kind :
       {LinearSolverKind::direct, LinearSolverKind::cg_amg, LinearSolverKind::cg_ichol}) {
    p.solver.kind = kind;
    p.solver.relative_tolerance = 1e-13;
    const ElectrostaticReport r = solve_electrostatic(m, p);
    const double c = kEps0 * er * w * h / d;
    ASSERT_EQ(r.capacitance.size(), 2u);
    EXPECT_NEAR(r.capacitance[0][0], c, 1e-9 * c);
    EXPECT_NEAR(r.capacitance[1][1], c, 1e-9 * c);
    EXPECT_NEAR(r.capacitance[0][1], -c, 1e-9 * c);
    EXPECT_NEAR(r.field_energy, 0.5 * c * v * v, 1e-9 * c * v * v);
    EXPECT_NEAR(r.energy, 0.5 * c * v * v, 1e-9 * c * v * v);
    expect_checks_pass(r.checks);
    EXPECT_NEAR(r.conductors[0].charge, c * v, 1e-9 * c * v);
    EXPECT_NEAR(r.conductors[1].charge, -c * v, 1e-9 * c * v);
    EXPECT_NEAR(r.conductors[0].area, w * h, 1e-15);
    const Field* phi = m.find_field("potential");
    const Field* e = m.find_field("electric_field");
    ASSERT_TRUE(phi && e);
    EXPECT_EQ(phi->unit, "V");
    for (std::size_t n = 0; n < m.node_count(); ++n)
      EXPECT_NEAR(phi->values[n], v * m.xyz[3 * n] / d, 1e-9 * v);
    for (std::size_t t = 0; t < m.tet_count(); ++t) {
      EXPECT_NEAR(e->values[3 * t], -v / d, 1e-8 * v / d);
      EXPECT_NEAR(e->values[3 * t + 1], 0, 1e-8 * v / d);
    }
  }
}

// Two dielectric layers in series: C = eps0 A / (d1 / er1 + d2 / er2), exact (interface on a node plane).
TEST(Electrostatic, LayeredDielectricFromMaterials) {
  const double d = 1e-3, a = 4e-3;
  Mesh m = box({10, 3, 3}, {d, a, a}, [&](double x, double, double) { return x < 0.3 * d ? 1 : 2; });
  m.materials = {Material{}, Material{}};
  m.materials[0].relative_permittivity = 2;
  m.materials[1].relative_permittivity = 9.8;
  m.regions[0].material = 0;
  m.regions[1].material = 1;
  ElectrostaticParams p;
  p.conductors = {electrode("a", {1}, 1), electrode("b", {2})};
  const ElectrostaticReport r = solve_electrostatic(m, p);
  const double c = kEps0 * a * a / (0.3 * d / 2 + 0.7 * d / 9.8);
  EXPECT_NEAR(r.capacitance[0][0], c, 1e-9 * c);
  EXPECT_NEAR(r.field_energy, 0.5 * c, 1e-9 * c);
  expect_checks_pass(r.checks);
  p.permittivity = {{2, 2}};  // the parameter overrides the material
  const ElectrostaticReport r2 = solve_electrostatic(m, p);
  EXPECT_NEAR(r2.capacitance[0][0], kEps0 * 2 * a * a / d, 1e-9 * c);
}

// Three conductors (both plates and the y sides): the matrix is symmetric, its diagonal equals the
// energy capacitance, off-diagonals are negative, and the rows sum to zero: every boundary that is no
// conductor carries no flux, so the total charge is zero whatever the potentials.
TEST(Electrostatic, ThreeConductorMatrixIsSymmetric) {
  Mesh m = box({7, 6, 5}, {1e-3, 1.3e-3, 0.8e-3});
  ElectrostaticParams p;
  p.permittivity = {{1, 3}};
  p.conductors = {electrode("left", {1}), electrode("right", {2}), electrode("sides", {3})};
  p.conductors[0].voltage = 1;
  EXPECT_THROW(
      {
        try {
          solve_electrostatic(m, p);
        } catch (const SolverError& e) {
          EXPECT_NE(std::string(e.what()).find("touch"), std::string::npos) << e.what();
          throw;
        }
      },
      SolverError);
  // Tag 3 shares edges with tags 1 and 2: free the side triangles that touch x = 0 or x = lx (tag 5).
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    if (m.bface_tag[f] != 3) continue;
    for (int i = 0; i < 3; ++i) {
      const double x = m.xyz[3 * m.bface[3 * f + i]];
      if (x < 1e-9 || x > 1e-3 - 1e-9) m.bface_tag[f] = 5;
    }
  }
  const ElectrostaticReport r = solve_electrostatic(m, p);
  expect_checks_pass(r.checks);
  double big = 0;
  for (int i = 0; i < 3; ++i) big = std::max(big, r.capacitance[i][i]);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(r.capacitance[i][i], 0);
    double row = 0;
    for (int j = 0; j < 3; ++j) {
      row += r.capacitance[i][j];
      if (j != i) {
        EXPECT_LT(r.capacitance[i][j], 0);
        EXPECT_EQ(r.capacitance[i][j], r.capacitance[j][i]);
      }
    }
    EXPECT_NEAR(row, 0, 1e-9 * big);
  }
  // The operating field: 1 V on the left plate, 0 elsewhere; charge = C column 0.
  EXPECT_NEAR(r.conductors[1].charge, r.capacitance[1][0], 1e-12 * big);
}

// Spherical shell r1 = 1 < r < r2 = 2 (gmsh, first order): C = 4 pi eps r1 r2 / (r2 - r1).
TEST(Electrostatic, ConcentricSpheresConverge) {
  if (!test::have_program("gmsh")) GTEST_SKIP() << "gmsh not installed";
  const double r1 = 1, r2 = 2, er = 2;
  const double exact = 4 * std::numbers::pi * kEps0 * er * r1 * r2 / (r2 - r1);
  test::TempDir dir;
  test::write_text(dir / "shell.geo",
                   "SetFactory(\"OpenCASCADE\");\n"
                   "Sphere(1) = {0,0,0,2};\nSphere(2) = {0,0,0,1};\n"
                   "BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };\n"
                   "Physical Volume(1) = {3};\nb() = Boundary{ Volume{3}; };\n"
                   "Physical Surface(1) = {b(0)};\nPhysical Surface(2) = {b(1)};\n"
                   "Mesh.CharacteristicLengthMax = 0.25;\n");
  std::vector<double> errors, sizes;
  for (double scale : {1.6, 1.0, 0.6}) {
    std::ostringstream cmd;
    cmd << "gmsh -3 -v 0 -clscale " << scale << " -format msh22 -o '" << (dir / "shell.msh").string() << "' '"
        << (dir / "shell.geo").string() << "'";
    ASSERT_EQ(test::run(cmd.str(), dir / "log"), 0) << test::read_text(dir / "log");
    Mesh m = read_gmsh(dir / "shell.msh");
    validate_and_repair(m);
    // Which tag is the inner sphere: the one whose nodes lie at radius 1.
    std::int32_t inner = 1, outer = 2;
    {
      const std::uint32_t v = m.bface[0];
      const double rad = std::hypot(m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]);
      if ((rad < 1.5) != (m.bface_tag[0] == 1)) std::swap(inner, outer);
    }
    ElectrostaticParams p;
    p.permittivity = {{1, er}};
    p.conductors = {electrode("inner", {inner}, 1), electrode("outer", {outer})};
    const ElectrostaticReport r = solve_electrostatic(m, p);
    const double err = std::abs(r.capacitance[0][0] - exact) / exact;
    errors.push_back(err);
    sizes.push_back(
        std::cbrt(4.0 / 3 * std::numbers::pi * (r2 * r2 * r2 - r1 * r1 * r1) / double(m.tet_count())));
    expect_checks_pass(r.checks);
    EXPECT_NEAR(r.capacitance[0][1], -r.capacitance[0][0], 1e-8 * exact);
    std::printf("[ spheres ] clscale %.2f: %zu tets, C = %.6e F (exact %.6e), relative error %.3e\n", scale,
                m.tet_count(), r.capacitance[0][0], exact, err);
  }
  EXPECT_LT(errors[1], errors[0]);
  EXPECT_LT(errors[2], errors[1]);
  // The error of C is of second order in h (P1 energy error and the polyhedral boundaries); measured
  // rates are 1.5 to 1.9 on these meshes.
  const double rate = std::log(errors[0] / errors[2]) / std::log(sizes[0] / sizes[2]);
  std::printf("[ spheres ] observed order %.2f in h = (volume / tets)^(1/3)\n", rate);
  EXPECT_GT(rate, 1.3);
  EXPECT_LT(errors[2], 0.01);
}

// Coaxial cylinders a = 1 < r < b = 2, a slice of height H with the ends left free (zero normal field,
// which the exact field satisfies): C / H = 2 pi eps / ln(b / a), the 2D answer (gmsh, first order).
// The curved surfaces are faceted: their nodes lie on the circles, the flat triangles inside them,
// which moves each radius by O(h^2) and lowers C by as much as the P1 energy error raises it, so the
// error against the circles is not monotone (it partly cancels). The convergence order is therefore
// measured against the faceted geometry's own capacity, 2 pi eps / ln(b_eff / a_eff) with the radii
// of the circles of equal enclosed area (to first order in the facet error, the capacity of a
// near-circle); the finest mesh must also be within 1% of the exact circles.
TEST(Electrostatic, CoaxialCapacitorConverges) {
  if (!test::have_program("gmsh")) GTEST_SKIP() << "gmsh not installed";
  const double a = 1, b = 2, height = 0.4, er = 3;
  const double exact = 2 * std::numbers::pi * kEps0 * er / std::log(b / a);  // F/m
  test::TempDir dir;
  std::ostringstream geo;
  geo << "SetFactory(\"OpenCASCADE\");\nCylinder(1) = {0,0,0, 0,0," << height << ", " << b << "};\n"
      << "Cylinder(2) = {0,0,0, 0,0," << height << ", " << a << "};\n";
  test::write_text(dir / "coax.geo",
                   geo.str() +
                       "BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };\n"
                       "Physical Volume(1) = {3};\nb() = Boundary{ Volume{3}; };\n"
                       "For i In {0:#b()-1}\n  Physical Surface(i+1) = {b(i)};\nEndFor\n");
  std::vector<double> errors, sizes;  // against the faceted geometry
  double exact_error = 0;             // of the last (finest) mesh against the circles
  for (double lc : {0.4, 0.28, 0.2, 0.14}) {
    std::ostringstream cmd;
    cmd << "gmsh -3 -v 0 -clmax " << lc << " -format msh22 -o '" << (dir / "coax.msh").string() << "' '"
        << (dir / "coax.geo").string() << "'";
    ASSERT_EQ(test::run(cmd.str(), dir / "log"), 0) << test::read_text(dir / "log");
    Mesh m = read_gmsh(dir / "coax.msh");
    validate_and_repair(m);
    // Sort the tags by where their triangles are: on r = a, on r = b, or on an end (z = 0 or H). For
    // the lateral surfaces sum (x, y) . n dA over the triangles (n outward from the axis): by the
    // divergence theorem that is 2 H times the area the faceted circle encloses, pi r_eff^2.
    std::vector<std::int32_t> inner, outer;
    double flux_in = 0, flux_out = 0;
    for (std::size_t f = 0; f < m.bface_count(); ++f) {
      const std::uint32_t* v = &m.bface[3 * f];
      double c[3] = {0, 0, 0}, e1[3], e2[3];
      for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 3; ++i) c[k] += m.xyz[3 * v[i] + k] / 3;
        e1[k] = m.xyz[3 * v[1] + k] - m.xyz[3 * v[0] + k];
        e2[k] = m.xyz[3 * v[2] + k] - m.xyz[3 * v[0] + k];
      }
      const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                           e1[0] * e2[1] - e1[1] * e2[0]};  // twice the area times the normal
      const double radial = std::abs(c[0] * n[0] + c[1] * n[1]) / 2;
      if (std::abs(n[2]) > 0.5 * std::hypot(n[0], n[1], n[2])) continue;  // an end
      const bool is_inner = std::hypot(c[0], c[1]) < (a + b) / 2;
      (is_inner ? flux_in : flux_out) += radial;
      std::vector<std::int32_t>& tags = is_inner ? inner : outer;
      if (std::find(tags.begin(), tags.end(), m.bface_tag[f]) == tags.end()) tags.push_back(m.bface_tag[f]);
    }
    ASSERT_EQ(inner.size(), 1u);
    ASSERT_EQ(outer.size(), 1u);
    const double a_eff = std::sqrt(flux_in / (2 * height * std::numbers::pi));
    const double b_eff = std::sqrt(flux_out / (2 * height * std::numbers::pi));
    const double faceted = 2 * std::numbers::pi * kEps0 * er / std::log(b_eff / a_eff);
    ElectrostaticParams p;
    p.permittivity = {{1, er}};
    p.conductors = {electrode("inner", inner, 1), electrode("outer", outer)};
    const ElectrostaticReport r = solve_electrostatic(m, p);
    const double c = r.capacitance[0][0] / height;
    exact_error = std::abs(c - exact) / exact;
    errors.push_back((c - faceted) / faceted);
    sizes.push_back(std::cbrt(std::numbers::pi * (b * b - a * a) * height / double(m.tet_count())));
    expect_checks_pass(r.checks);
    EXPECT_NEAR(r.capacitance[0][1], -r.capacitance[0][0], 1e-8 * exact * height);
    // The P1 energy is minimal over fewer functions, so the discrete capacity lies above the
    // faceted geometry's own (the first-order estimate, whose own error is far below this margin).
    EXPECT_GT(c, faceted);
    std::printf(
        "[ coax ] clmax %.2f: %zu tets, C/H = %.6e F/m (exact %.6e), error %.3e; faceted radii %.5f %.5f, "
        "faceted C/H %.6e, error against it %.3e\n",
        lc, m.tet_count(), c, exact, exact_error, a_eff, b_eff, faceted, errors.back());
  }
  for (std::size_t i = 1; i < errors.size(); ++i) EXPECT_LT(errors[i], errors[i - 1]);
  const std::size_t last = errors.size() - 1;
  const double rate = std::log(errors[0] / errors[last]) / std::log(sizes[0] / sizes[last]);
  std::printf(
      "[ coax ] observed order %.2f (against the faceted geometry) in h = (volume / tets)^(1/3) over %zu "
      "meshes\n",
      rate, errors.size());
  EXPECT_GT(rate, 1.5);
  EXPECT_LT(exact_error, 0.01);
}

// A bar of length L and section A: R = L / (sigma A), exact; Joule heat V^2 / R = I^2 R.
TEST(Current, StraightBarResistanceAndJouleHeat) {
  const double l = 5e-3, a = 0.5e-3, b = 0.2e-3, sigma = 5.8e7, v = 0.01;
  Mesh m = box({10, 3, 2}, {l, a, b});
  CurrentParams p;
  p.conductivity = {{1, sigma}};
  p.terminals = {electrode("in", {1}, v), electrode("out", {2}, 0)};
  const CurrentReport r = solve_current(m, p);
  const double rr = l / (sigma * a * b), i = v / rr;
  EXPECT_NEAR(r.resistance, rr, 1e-9 * rr);
  EXPECT_NEAR(r.terminals[0].charge, i, 1e-9 * i);
  EXPECT_NEAR(r.terminals[1].charge, -i, 1e-9 * i);
  EXPECT_NEAR(1 / r.conductance[0][0], rr, 1e-9 * rr);
  EXPECT_NEAR(r.total_power, i * i * rr, 1e-9 * i * i * rr);
  ASSERT_EQ(r.regions.size(), 1u);
  EXPECT_NEAR(r.regions[0].power, i * i * rr, 1e-9 * i * i * rr);
  const Field* j = m.find_field("current_density");
  const Field* q = m.find_field("joule_heat");
  ASSERT_TRUE(j && q);
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    EXPECT_NEAR(j->values[3 * t], i / (a * b), 1e-8 * i / (a * b));  // from x = 0 (at v) to x = l
    EXPECT_NEAR(q->values[t], i * i * rr / (l * a * b), 1e-8 * i * i * rr / (l * a * b));
  }
  const std::vector<HeatSource> s = joule_heat_sources(r);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_TRUE(s[0].total);
  EXPECT_NEAR(s[0].value, i * i * rr, 1e-9 * i * i * rr);

  // A fixed current on the far terminal: V = I R.
  p.terminals[0].voltage = 0;
  p.terminals[1].fixed_current = true;
  p.terminals[1].current = 2.0;
  const CurrentReport c = solve_current(m, p);
  EXPECT_NEAR(c.terminals[1].voltage, 2.0 * rr, 1e-9 * 2.0 * rr);
  EXPECT_NEAR(c.terminals[1].charge, 2.0, 1e-9);
  EXPECT_NEAR(c.terminals[0].charge, -2.0, 1e-9);
  EXPECT_NEAR(c.total_power, 4.0 * rr, 1e-9 * 4.0 * rr);

  // Both terminals at one voltage: no current, the bar's resistance still L / (sigma A) (it was
  // 0 / round-off = -0), and the energy check passes (the round-off power failed it against itself).
  p.terminals = {electrode("in", {1}, 1.0), electrode("out", {2}, 1.0)};
  const CurrentReport e = solve_current(m, p);
  EXPECT_NEAR(e.resistance, rr, 1e-9 * rr);
  EXPECT_LE(std::abs(e.terminals[0].charge), 1e-9 * i);
  for (const BalanceCheck& k : e.checks) EXPECT_TRUE(k.passed) << k.name << " " << k.figure;
}

// The Joule heat feeds a thermal run: with both ends held at 300 K the heat leaving through them is I^2 R,
// and the mid-bar temperature rise of the uniform source q = I^2 R / V is q L^2 / (8 k) (1D parabola).
TEST(Current, JouleHeatIsAThermalLoad) {
  const double l = 1e-2, a = 1e-3, sigma = 1e7, v = 0.05, k = 400;
  Mesh m = box({16, 2, 2}, {l, a, a});
  CurrentParams p;
  p.conductivity = {{1, sigma}};
  p.terminals = {electrode("in", {1}, v), electrode("out", {2}, 0)};
  const CurrentReport c = solve_current(m, p);
  const double power = v * v * sigma * a * a / l;
  ThermalParams t;
  t.conductivity = {{1, k}};
  t.fixed = {{1, 300}, {2, 300}};
  t.sources = joule_heat_sources(c);
  const ThermalReport r = solve_thermal(m, t);
  EXPECT_NEAR(r.total_power, power, 1e-9 * power);
  EXPECT_NEAR(r.boundaries[0].heat_in + r.boundaries[1].heat_in, -power, 1e-9 * power);
  const double rise = power / (l * a * a) * l * l / (8 * k);
  EXPECT_NEAR(r.max_temperature - 300, rise, 0.01 * rise);
}

TEST(Current, BarsInSeriesAndInParallel) {
  const double l = 4e-3, a = 1e-3, s1 = 1e6, s2 = 3.5e7;
  CurrentParams p;
  p.conductivity = {{1, s1}, {2, s2}};
  p.terminals = {electrode("in", {1}, 1), electrode("out", {2}, 0)};
  {
    Mesh m = box({8, 2, 2}, {l, a, a}, [&](double x, double, double) { return x < l / 4 ? 1 : 2; });
    const CurrentReport r = solve_current(m, p);
    const double r1 = (l / 4) / (s1 * a * a), r2 = (3 * l / 4) / (s2 * a * a), i = 1 / (r1 + r2);
    EXPECT_NEAR(r.resistance, r1 + r2, 1e-9 * (r1 + r2));
    EXPECT_NEAR(r.regions[0].power, i * i * r1, 1e-9 * i * i * r1);
    EXPECT_NEAR(r.regions[1].power, i * i * r2, 1e-9 * i * i * r2);
  }
  {
    Mesh m = box({5, 4, 2}, {l, a, a}, [&](double, double y, double) { return y < a / 4 ? 1 : 2; });
    const CurrentReport r = solve_current(m, p);
    const double g = s1 * a * a / 4 / l + s2 * 3 * a * a / 4 / l;
    EXPECT_NEAR(r.resistance, 1 / g, 1e-9 / g);
    EXPECT_NEAR(r.regions[0].power, s1 * a * a / 4 / l, 1e-9 * g);
    EXPECT_NEAR(r.total_power, g, 1e-9 * g);
  }
}

// Packaging contrasts: copper 5.96e7 S/m against FR-4 1e-14 S/m (6e21). Every solver must resolve the
// insulator's small currents as well as the metal's large ones, and every balance check must pass.
template <class Fn>
void expect_error(Fn fn, const std::string& part) {
  try {
    fn();
    ADD_FAILURE() << "no error; expected one containing '" << part << "'";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

constexpr double kCopper = 5.96e7, kFr4 = 1e-14;
constexpr LinearSolverKind kAllSolvers[] = {LinearSolverKind::automatic, LinearSolverKind::direct,
                                            LinearSolverKind::cg_amg, LinearSolverKind::cg_ichol};
const char* solver_name(LinearSolverKind k) {
  return k == LinearSolverKind::automatic ? "auto"
         : k == LinearSolverKind::direct  ? "direct"
         : k == LinearSolverKind::cg_amg  ? "amg"
                                          : "ichol";
}

// A copper bar (the middle of the upper half) on an FR-4 slab, terminals on the bar's end faces only:
// R = L / (sigma_cu A_bar); the slab adds 1e-21 of the conductance.
TEST(Current, CopperBarOnFr4SlabAtContrast1e21) {
  const double l = 5e-3, w = 1e-3, h = 1e-3;
  auto in_bar = [&](double y, double z) { return z > h / 2 && y > w / 4 && y < 3 * w / 4; };
  Mesh m = box({10, 4, 4}, {l, w, h}, [&](double, double y, double z) { return in_bar(y, z) ? 1 : 2; });
  for (std::size_t f = 0; f < m.bface_count(); ++f) {
    if (m.bface_tag[f] != 1 && m.bface_tag[f] != 2) continue;
    double c[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i)
      for (int a = 0; a < 3; ++a) c[a] += m.xyz[3 * m.bface[3 * f + i] + a] / 3;
    if (in_bar(c[1], c[2])) m.bface_tag[f] += 10;
  }
  CurrentParams p;
  p.conductivity = {{1, kCopper}, {2, kFr4}};
  p.terminals = {electrode("in", {11}, 1), electrode("out", {12}, 0)};
  const double r_cu = l / (kCopper * (w / 2) * (h / 2));
  for (LinearSolverKind kind : kAllSolvers) {
    SCOPED_TRACE(solver_name(kind));
    p.solver.kind = kind;
    const CurrentReport r = solve_current(m, p);
    EXPECT_NEAR(r.resistance, r_cu, 1e-6 * r_cu);
    EXPECT_NEAR(r.terminals[0].charge, 1 / r_cu, 1e-6 / r_cu);
    EXPECT_NEAR(r.terminals[1].charge, -1 / r_cu, 1e-6 / r_cu);
    EXPECT_NEAR(r.total_power, 1 / r_cu, 1e-6 / r_cu);
    expect_checks_pass(r.checks);
  }
}

// Copper then FR-4 along the bar, terminals on the whole ends: R = L1 / (s1 A) + L2 / (s2 A), the
// FR-4's alone to 1e-21; the currents in and out (1e-11 A) balance. Then side by side: G = (s1 + s2) A / 2L,
// and the FR-4 half's own Joule heat, 1e-21 of the total, is still resolved.
TEST(Current, SeriesAndParallelPairsAtContrast1e21) {
  const double l = 4e-3, a = 1e-3;
  for (LinearSolverKind kind : kAllSolvers) {
    SCOPED_TRACE(solver_name(kind));
    CurrentParams p;
    p.solver.kind = kind;
    p.conductivity = {{1, kCopper}, {2, kFr4}};
    for (int flip = 0; flip < 2; ++flip) {
      // flip 0: 1 V on the copper end; flip 1: on the FR-4 end.
      p.terminals = {electrode("in", {flip ? 2 : 1}, 1), electrode("out", {flip ? 1 : 2}, 0)};
      Mesh m = box({8, 3, 3}, {l, a, a}, [&](double x, double, double) { return x < l / 4 ? 1 : 2; });
      const CurrentReport r = solve_current(m, p);
      const double r1 = (l / 4) / (kCopper * a * a), r2 = (3 * l / 4) / (kFr4 * a * a), i = 1 / (r1 + r2);
      EXPECT_NEAR(r.resistance, r1 + r2, 1e-9 * (r1 + r2));
      EXPECT_NEAR(r.terminals[0].charge, i, 1e-9 * i);
      EXPECT_NEAR(r.terminals[1].charge, -i, 1e-9 * i);
      EXPECT_NEAR(r.regions[1].power, i * i * r2, 1e-9 * i * i * r2);
      expect_checks_pass(r.checks);
    }
    p.terminals = {electrode("in", {1}, 1), electrode("out", {2}, 0)};
    Mesh m = box({5, 4, 2}, {l, a, a}, [&](double, double y, double) { return y < a / 2 ? 1 : 2; });
    const CurrentReport r = solve_current(m, p);
    const double g1 = kCopper * a * a / 2 / l, g2 = kFr4 * a * a / 2 / l;
    EXPECT_NEAR(r.resistance, 1 / (g1 + g2), 1e-9 / g1);
    EXPECT_NEAR(r.regions[0].power, g1, 1e-9 * g1);
    EXPECT_NEAR(r.regions[1].power, g2, 1e-6 * g2);
    expect_checks_pass(r.checks);
  }
}

// The same on an unstructured TetGen mesh big enough for the automatic choice to take AMG: copper,
// FR-4 and copper layers between terminals on the bottom and top faces. The field is linear in each
// layer, so P1 is exact: R = sum t_i / (sigma_i A), the FR-4's to 1e-21.
TEST(Current, TetgenCopperFr4CopperStackAtContrast1e21) {
  if (!test::have_program("tetgen")) GTEST_SKIP() << "tetgen not installed";
  const double w = 1e-3, t = 0.2e-3;
  Mesh m = test::layered_box_mesh(w, w, {0, t, 2 * t, 3 * t}, 2e-14);
  CurrentParams p;
  p.conductivity = {{1, kCopper}, {2, kFr4}, {3, kCopper}};
  p.terminals = {electrode("bottom", {5}, 1), electrode("top", {6}, 0)};
  const double r = 2 * t / (kCopper * w * w) + t / (kFr4 * w * w);
  for (LinearSolverKind kind : {LinearSolverKind::automatic, LinearSolverKind::cg_ichol}) {
    SCOPED_TRACE(solver_name(kind));
    p.solver.kind = kind;
    const CurrentReport c = solve_current(m, p);
    if (kind == LinearSolverKind::automatic) {
      EXPECT_GT(c.unknowns, p.solver.direct_max_unknowns);
      EXPECT_EQ(c.solver, "CG+SmoothedAggregationAMG");
    }
    // 1e-8: both solvers give the same 2.6e-9 off, the geometry as TetGen's files round it.
    EXPECT_NEAR(c.resistance, r, 1e-8 * r);
    EXPECT_NEAR(c.terminals[0].charge, 1 / r, 1e-8 / r);
    EXPECT_NEAR(c.terminals[1].charge, -1 / r, 1e-8 / r);
    EXPECT_NEAR(c.regions[1].power, 1 / r, 1e-8 / r);
    expect_checks_pass(c.checks);
  }
}

// A metal slab (copper, whose own relative permittivity 1 must not matter) of thickness t between the
// plates of an FR-4 capacitor of gap d: C = eps0 eps_r A / (d - t), exact with P1 (the field is
// piecewise uniform). Floating, it takes the potential that leaves it uncharged; touching a plate, it
// is part of that plate's conductor; touching both, the plates are shorted.
TEST(Electrostatic, MetalSlabBetweenThePlates) {
  const double d = 2e-3, w = 3e-3, er = 4.4;
  auto mesh = [&](double lo, double hi, double y_max = 1) {
    Mesh m = box({8, 3, 3}, {d, w, w},
                 [&](double x, double y, double) { return x > lo && x < hi && y < y_max ? 2 : 1; });
    m.materials = {Material{}, Material{}};
    m.materials[0].relative_permittivity = er;
    m.materials[0].electrical_conductivity = kFr4;
    m.materials[1].relative_permittivity = 1;
    m.materials[1].electrical_conductivity = kCopper;
    m.regions[0].material = 0;
    m.regions[1].material = 1;
    return m;
  };
  ElectrostaticParams p;
  p.conductors = {electrode("a", {1}, 1), electrode("b", {2}, 0)};
  for (LinearSolverKind kind : kAllSolvers) {
    SCOPED_TRACE(solver_name(kind));
    p.solver.kind = kind;
    {
      Mesh m = mesh(0.25 * d, 0.5 * d);  // floating, gaps d/4 and d/2
      const ElectrostaticReport r = solve_electrostatic(m, p);
      const double c = kEps0 * er * w * w / (0.75 * d);
      EXPECT_NEAR(r.capacitance[0][0], c, 1e-9 * c);
      EXPECT_NEAR(r.capacitance[0][1], -c, 1e-9 * c);
      ASSERT_EQ(r.floating.size(), 1u);
      EXPECT_EQ(r.floating[0].regions, std::vector<std::int32_t>{2});
      EXPECT_NEAR(r.floating[0].voltage, 2.0 / 3, 1e-9);
      EXPECT_TRUE(r.conductors[0].metal_regions.empty());
      EXPECT_NEAR(r.field_energy, 0.5 * c, 1e-9 * c);
      expect_checks_pass(r.checks);
      // The field in the metal is zero, in the gaps uniform.
      const Field* e = m.find_field("electric_field");
      ASSERT_TRUE(e);
      for (std::size_t t = 0; t < m.tet_count(); ++t)
        EXPECT_NEAR(e->values[3 * t], m.tet_region[t] == 2 ? 0.0 : 1 / (0.75 * d), 1e-6 / d);
    }
    {
      Mesh m = mesh(-1, 0.25 * d);  // on plate a
      const ElectrostaticReport r = solve_electrostatic(m, p);
      const double c = kEps0 * er * w * w / (0.75 * d);
      EXPECT_NEAR(r.capacitance[1][1], c, 1e-9 * c);
      EXPECT_TRUE(r.floating.empty());
      EXPECT_EQ(r.conductors[0].metal_regions, std::vector<std::int32_t>{2});
      EXPECT_TRUE(r.conductors[1].metal_regions.empty());
      expect_checks_pass(r.checks);
    }
  }
  Mesh shorted = mesh(-1, 2 * d, w / 2);  // a metal strip across the gap
  expect_error([&] { solve_electrostatic(shorted, p); }, "joined by metal");
  // Below the threshold (or with a permittivity given) the slab is a dielectric of eps_r 1.
  Mesh m = mesh(0.25 * d, 0.5 * d);
  p.metal_conductivity = 1e8;
  const ElectrostaticReport r = solve_electrostatic(m, p);
  const double c = kEps0 * w * w / (0.75 * d / er + 0.25 * d);
  EXPECT_NEAR(r.capacitance[0][0], c, 1e-9 * c);
  EXPECT_TRUE(r.floating.empty());
}

// The checks fail loudly on the kind of numbers the reaction currents gave at contrast: the flip chip's
// 1.5e-11 A in against 5.1e-16 A out; AMG's two terminal currents of one sign; a row of the via's
// conductance matrix 0.13 % off zero; a poor residual.
TEST(Electric, MaxwellChecksCatchWrongMatrices) {
  auto passed = [](const std::vector<BalanceCheck>& checks, const std::string& name) {
    for (const BalanceCheck& c : checks)
      if (c.name == name) return c.passed;
    ADD_FAILURE() << "no check " << name;
    return false;
  };
  const auto good = maxwell_matrix_checks({{2e-3, -2e-3}, {-2e-3, 2e-3}}, 1e-12, 1e-6, "the currents");
  EXPECT_TRUE(passed(good, "Kirchhoff") && passed(good, "Maxwell signs") && passed(good, "residual"));
  EXPECT_FALSE(
      passed(maxwell_matrix_checks({{1.5e-11, -5.1e-16}, {-5.1e-16, 5.1e-16}}, 0, 1e-6, "x"), "Kirchhoff"));
  const auto same_sign = maxwell_matrix_checks({{1e-15, 2e-16}, {2e-16, 1e-15}}, 0, 1e-6, "x");
  EXPECT_FALSE(passed(same_sign, "Maxwell signs"));
  EXPECT_FALSE(passed(same_sign, "Kirchhoff"));
  EXPECT_FALSE(passed(maxwell_matrix_checks({{1, -0.9987}, {-0.9987, 1}}, 0, 1e-6, "x"), "Kirchhoff"));
  EXPECT_FALSE(passed(maxwell_matrix_checks({{-1, 1}, {1, -1}}, 0, 1e-6, "x"), "Maxwell signs"));
  EXPECT_FALSE(passed(maxwell_matrix_checks({{1, -1}, {-1, 1}}, 1e-3, 1e-6, "x"), "residual"));
  EXPECT_FALSE(passed(maxwell_matrix_checks({{1, -1}, {-1, 1}}, std::nan(""), 1e-6, "x"), "residual"));
}

TEST(Electric, IllPosedProblemsAreClearErrors) {
  Mesh m = box({3, 2, 2}, {1, 1, 1});
  ElectrostaticParams p;
  p.permittivity = {{1, 1}};
  expect_error([&] { solve_electrostatic(m, p); }, "no conductor");
  p.conductors = {electrode("a", {1}), electrode("b", {9})};
  expect_error([&] { solve_electrostatic(m, p); }, "tags no boundary triangle");
  p.conductors = {electrode("a", {1}), electrode("b", {1, 2})};
  expect_error([&] { solve_electrostatic(m, p); }, "belongs to two conductors");
  p.conductors = {electrode("a", {1}), electrode("b", {3})};
  expect_error([&] { solve_electrostatic(m, p); }, "touch");
  p.conductors = {electrode("a", {1}), electrode("b", {2})};
  p.permittivity.clear();
  expect_error([&] { solve_electrostatic(m, p); }, "has no relative permittivity");
  p.permittivity = {{1, -1}};
  expect_error([&] { solve_electrostatic(m, p); }, "must be positive");
  p.permittivity = {{7, 1}};
  expect_error([&] { solve_electrostatic(m, p); }, "which has no tets");

  // A second, disjoint box that touches no conductor.
  Mesh two = box({3, 2, 2}, {1, 1, 1});
  {
    Mesh other = box({3, 2, 2}, {1, 1, 1});
    const auto off = static_cast<std::uint32_t>(two.node_count());
    for (std::size_t i = 0; i < other.xyz.size(); i += 3) {
      two.xyz.push_back(other.xyz[i] + 5);
      two.xyz.push_back(other.xyz[i + 1]);
      two.xyz.push_back(other.xyz[i + 2]);
    }
    for (std::uint32_t v : other.tet) two.tet.push_back(v + off);
    for (std::size_t t = 0; t < other.tet_count(); ++t) two.tet_region.push_back(1);
    for (std::uint32_t v : other.bface) two.bface.push_back(v + off);
    for (std::int32_t t : other.bface_tag) two.bface_tag.push_back(t + 10);
  }
  p.permittivity = {{1, 1}};
  expect_error([&] { solve_electrostatic(two, p); }, "touches no conductor");

  CurrentParams c;
  c.conductivity = {{1, 1}};
  c.terminals = {electrode("a", {1}), electrode("b", {2})};
  c.terminals[0].fixed_current = c.terminals[1].fixed_current = true;
  expect_error([&] { solve_current(m, c); }, "fixed voltage");
  c.terminals[0].fixed_current = false;
  expect_error([&] { solve_current(two, c); }, "touches no terminal");
  c.conductivity.clear();
  expect_error([&] { solve_current(m, c); }, "has no electrical conductivity");

  // Cancel from the progress callback.
  c.conductivity = {{1, 1}};
  c.solver.progress = [](std::string_view stage, double) { return stage != "solve"; };
  EXPECT_THROW(solve_current(m, c), SolverCancelled);
}

}  // namespace
}  // namespace foxi
