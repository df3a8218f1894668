// Internal pieces shared by foxi's scalar P1 solvers (heat conduction, electrostatics, DC
// conduction): region tables and coefficients, the -div(c grad u) stiffness over the node pattern,
// Dirichlet values from boundary tags, the well-posedness check, the reduced system and reactions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "foxi/model/mesh.hpp"
#include "linear_solve.hpp"
#include "p1_assembly.hpp"

namespace foxi::detail {

std::string region_label(const Mesh& mesh, std::int32_t id);
std::string tag_label(const Mesh& mesh, std::int32_t tag);
void check_finite(double v, const std::string& what);
// Stores `field` in mesh.fields, replacing a field of the same name.
void set_field(Mesh& mesh, Field field);
// Throws SolverError when the mesh is inconsistent or has no tets.
void check_mesh(const Mesh& mesh);
// Calls options.progress, throwing SolverCancelled when it returns false.
void report_progress(const LinearSolverOptions& options, std::string_view stage, double fraction);

// The regions that have tets, sorted, and each tet's index into them.
struct RegionTable {
  std::vector<std::int32_t> ids;
  std::vector<std::uint32_t> tet_rix;
  std::size_t size() const { return ids.size(); }
  std::size_t index(std::int32_t id) const;  // SIZE_MAX when the region has no tets
};
RegionTable region_table(const Mesh& mesh);

// A positive coefficient per region: the material's value (`from_material`), replaced by `overrides`
// (region id, value). Throws SolverError naming the region and `what` ("thermal conductivity") when one
// is missing, non-positive or given for a region without tets; `hint` says how to set it.
std::vector<double> region_coefficients(const Mesh& mesh, const RegionTable& regions,
                                        const std::function<double(const Material&)>& from_material,
                                        const std::vector<std::pair<std::int32_t, double>>& overrides,
                                        const std::string& what, const std::string& hint);
// The same with another condition than "positive": `valid` says whether a value is acceptable and
// `requirement` how ("in (-1, 0.5)").
std::vector<double> region_values(const Mesh& mesh, const RegionTable& regions,
                                  const std::function<double(const Material&)>& from_material,
                                  const std::vector<std::pair<std::int32_t, double>>& overrides,
                                  const std::string& what, const std::string& hint,
                                  const std::function<bool(double)>& valid, const std::string& requirement);

// Tet volumes (and their sum per region); SolverError on a non-positive one.
std::vector<double> tet_volumes(const Mesh& mesh, const RegionTable& regions, unsigned threads,
                                std::vector<double>& region_volume);

// The matrix of sum_t c_t int grad(phi_i) . grad(phi_j) on the node pattern (rows split over threads).
// Of the node-to-tet map only node_start is kept after assembly (ntets.item is released: it is as
// large as the tets, and a big solve needs that memory for the multigrid hierarchy).
struct P1Stiffness {
  NodeTets ntets;
  CsrPattern pat;
  std::vector<double> val;
  bool has_tets(std::size_t v) const { return ntets.node_start[v + 1] > ntets.node_start[v]; }
};
P1Stiffness assemble_stiffness(const Mesh& mesh, const std::vector<double>& tet_coefficient,
                               unsigned threads);

// Fixed values from boundary tags: each node on a fixed tag takes the lumped-area mean of its tags'
// values (the plain mean where that area is zero). `slot` of a tag says where its reaction goes.
struct FixedTag {
  double value = 0;
  std::size_t slot = 0;
};
struct Dirichlet {
  std::vector<char> fixed;    // per node
  std::vector<double> value;  // per node, NaN where free
  std::vector<double> area;   // per slot, m^2
  struct Share {
    std::uint32_t node;
    std::uint32_t slot;
    double area;
  };
  std::vector<Share> shares;
};
Dirichlet dirichlet_from_tags(const Mesh& mesh, const P1Stiffness& k,
                              const std::map<std::int32_t, FixedTag>& tags, std::size_t slots);

// Per node, the smallest node of its connected part (parts joined through tets); unused nodes are
// their own part.
std::vector<std::uint32_t> node_components(const Mesh& mesh);
// Per node, the smallest node of its connected set of the tets `keep` accepts (all when empty),
// joined through shared nodes; UINT32_MAX for a node of no such tet.
std::vector<std::uint32_t> tet_set_components(const Mesh& mesh, const std::function<bool(std::size_t)>& keep);
// The distinct boundary tags of the mesh's triangles, sorted.
std::vector<std::int32_t> boundary_tag_list(const Mesh& mesh);

// Throws SolverError("<problem>: the connected part containing tet T (region R) <what>") when a
// connected part of the mesh has no node with anchored[node] set.
void check_anchored(const Mesh& mesh, const std::vector<char>& anchored, const std::string& problem,
                    const std::string& what);

// The system on the free nodes (nodes with tets that are not fixed), rows split over `threads`.
struct ReducedSystem {
  std::vector<int> dof;  // per node, -1 when fixed or without tets
  SymmetricCsr a;
};
ReducedSystem reduce(const P1Stiffness& k, const std::vector<char>& fixed, unsigned threads = 1);
// Right-hand side load - K_free,fixed u_fixed.
std::vector<double> reduced_rhs(const P1Stiffness& k, const ReducedSystem& r, const std::vector<double>& load,
                                const std::vector<char>& fixed, const std::vector<double>& u_fixed,
                                unsigned threads = 1);
// Writes the free values x into u.
void scatter(const ReducedSystem& r, const std::vector<double>& x, std::vector<double>& u);
// (K u - load) at the fixed nodes (0 elsewhere), summed into the slots by lumped-area shares; in
// difference form, with row_sum the exact sum of each row of K (per node; empty: every row sums to 0).
// `magnitude`: per slot, the same shares of sum_j |K_vj u_j| (what round-off of u is relative to);
// `squares`: of sum_j (K_vj u_j)^2, the shares squared (for independent rounding errors of u).
std::vector<double> slot_reactions(const P1Stiffness& k, const Dirichlet& d, const std::vector<double>& load,
                                   const std::vector<double>& u, const std::vector<double>& row_sum,
                                   std::size_t slots, std::vector<double>* magnitude = nullptr,
                                   std::vector<double>* squares = nullptr);

// Per tet: coefficient * gradient of the P1 field u (3 values), and volume * c |grad u|^2 summed per
// region into `energy` (twice the energy), on threads.
std::vector<double> cell_gradients(const Mesh& mesh, const RegionTable& regions,
                                   const std::vector<double>& region_coefficient,
                                   const std::vector<double>& u, double scale, unsigned threads,
                                   std::vector<double>* energy);

}  // namespace foxi::detail
