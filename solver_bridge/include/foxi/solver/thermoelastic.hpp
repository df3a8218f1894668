// Linear thermoelasticity (thermal stress) on the common mesh database: linear (P1) tetrahedra,
// isotropic material per region (Young's modulus E, Poisson ratio nu, thermal expansion alpha), a
// uniform temperature change or a nodal temperature field (e.g. from solve_thermal) against a
// stress-free reference temperature.
//
//   div sigma = 0,  sigma = D (eps(u) - alpha dT I),  D isotropic (Lame lambda, mu),
//   u_i = value on fixed tags (all or chosen components), u . n = 0 on sliding tags (planar, any
//   orientation), traction-free elsewhere.
//
// The results go into Mesh::fields ("displacement" on nodes in m, 3 components; "stress" on cells in
// Pa, 6 components xx yy zz xy yz xz; "von_mises" and "principal_stress" (3, descending) on cells in
// Pa), replacing fields of those names. The library never prints; errors throw foxi::SolverError.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/solver/solver.hpp"

namespace foxi {

// Displacement prescribed on the nodes of a boundary tag, per component (x, y, z); components with
// fix[c] false stay free. Where fixed tags meet, a node takes the lumped-area mean of their values.
struct FixedDisplacement {
  std::int32_t tag = 0;
  bool fix[3] = {true, true, true};
  double value[3] = {0, 0, 0};  // m
};

// Zero normal displacement on a tag whose triangles lie in one plane (of any orientation). The
// constraint u . n = 0 is imposed exactly by rotating the nodes' unknowns into a frame (n, t1, t2) and
// removing the first: the system stays symmetric positive definite and no penalty is involved.
struct SlidingBoundary {
  std::int32_t tag = 0;
};

// Material of a region; NaN fields come from the region's material (youngs_modulus, poisson_ratio,
// thermal_expansion).
struct RegionElasticity {
  std::int32_t region = 0;
  double youngs_modulus = Material::kUnset;     // Pa, > 0
  double poisson_ratio = Material::kUnset;      // in (-1, 0.5)
  double thermal_expansion = Material::kUnset;  // 1/K, finite
};

struct ThermoelasticParams {
  std::vector<RegionElasticity> materials;
  std::vector<FixedDisplacement> fixed;
  std::vector<SlidingBoundary> sliding;
  // Temperature change dT (K) everywhere, used when `temperature` is empty.
  double delta_t = 0;
  // Nodal temperatures (K, one per mesh node, e.g. the "temperature" field of solve_thermal); dT =
  // temperature - reference_temperature. The thermal strain of a tet uses the mean dT of its 4 nodes
  // (exact for the load of a P1 element with a P1 temperature; also what CalculiX C3D4 does).
  std::vector<double> temperature;
  double reference_temperature = 293.15;  // K
  // Element order: 1 = linear 4-node tets, 2 = quadratic 10-node tets (for stress accuracy: P2
  // reproduces quadratic displacements, i.e. linear stress, exactly). With order 2 the mid-edge nodes
  // are the solver's own unknowns (with the constraints of the tagged boundary triangles they lie on);
  // the displacement is still written at the mesh's nodes, the stress per tet at its centroid (equal
  // to the tet's volume average for straight-sided P2 tets with a P1 temperature), and the thermal
  // strain uses the P1-interpolated temperature (integrated exactly by a 4-point Gauss rule).
  int order = 1;
  LinearSolverOptions solver;  // cg_amg uses the 6 rigid-body modes as AMG's near-null space
};

struct RegionStress {
  std::int32_t region = 0;
  double volume = 0;  // m^3
  double youngs_modulus = 0, poisson_ratio = 0, thermal_expansion = 0;
  double max_von_mises = 0;  // Pa, over the region's tets
  std::uint32_t max_tet = kNone;
};

// Tets on both sides of the faces shared by two regions (a material interface).
struct InterfaceStress {
  std::int32_t region_a = 0, region_b = 0;  // region_a < region_b
  double area = 0;                          // m^2
  double max_von_mises = 0;                 // Pa, over the tets that have a face on the interface
  std::uint32_t max_tet = kNone;
};

struct ThermoelasticReport {
  std::vector<RegionStress> regions;        // one per region with tets, by id
  std::vector<InterfaceStress> interfaces;  // one per pair of regions that share faces, by ids
  double max_von_mises = 0;                 // Pa
  std::uint32_t max_tet = kNone;
  double max_displacement = 0;  // m, largest |u| over the nodes
  std::uint32_t max_displacement_node = kNone;
  std::size_t constrained_nodes = 0;  // solver nodes (mid-edge ones too) with a constrained direction
  std::string solver;
  std::size_t unknowns = 0, nonzeros = 0;
  std::size_t iterations = 0;    // CG iterations (0 for the direct solver)
  std::size_t amg_levels = 0;    // 0 unless AMG
  double relative_residual = 0;  // |b - A x| / |b| of the free system
  double assembly_seconds = 0, solve_seconds = 0;
  // "thermal load": the thermal strain's nodal forces sum to zero in force and moment (rounding only);
  // "force balance": the reactions at the constrained nodes sum to zero in force and moment (no
  // applied forces), against the thermal load's and the reactions' magnitudes.
  std::vector<BalanceCheck> checks;
};

// Solves linear thermoelasticity on `mesh` (tets positively oriented, see validate.hpp) and stores the
// fields listed above. Nodes used by no tet get NaN displacement. Throws SolverError when a region has
// no E, nu or alpha (or an invalid one), a tag or region in `params` is unknown, a tag has two
// conditions, a sliding tag is not planar, constraints at a node contradict each other, `temperature`
// has the wrong size or a NaN on a used node, `order` is not 1 or 2, a connected part of the mesh can still
// move rigidly (the message names the part and the free modes: translations and rotations), the factorization
// fails or CG does not converge; SolverCancelled when the progress callback returns false.
FOXI_API ThermoelasticReport solve_thermoelastic(Mesh& mesh, const ThermoelasticParams& params);

// The report of solve_thermoelastic for displacements solved elsewhere (CalculiX): the same stress,
// von Mises and principal stress per tet from `displacement` (3 per node: the mesh's nodes, then for
// order 2 the mid-edge nodes in the order of the CalculiX deck's C3D10 nodes), the same maxima per
// region and interface, the same fields stored, and the same checks. The solver figures stay 0,
// `solver` is "given". `precision` > 0: the displacements are rounded to that relative precision
// (ccx's binary .frd: float32, 6e-8; an ASCII one: 5e-6), and the force balance's tolerance takes in
// the net force that rounding can make. Throws SolverError as solve_thermoelastic does for `params`
// (a body free to move rigidly aside), and when `displacement` has the wrong size or a non-finite
// value at a node of a tet.
FOXI_API ThermoelasticReport thermoelastic_report(Mesh& mesh, const ThermoelasticParams& params,
                                                  std::vector<double> displacement, double precision = 0);

}  // namespace foxi
