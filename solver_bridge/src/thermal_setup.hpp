// Internal: the steady heat-conduction system of thermal.cpp in pieces, so that the transient solver
// (transient.cpp) assembles and post-processes exactly what the steady one does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "foxi/solver/thermal.hpp"
#include "scalar_p1.hpp"

namespace foxi::detail {

enum class BcKind : std::uint8_t { none, fixed, flux, convection };

struct TagBc {
  BcKind kind = BcKind::none;
  double a = 0, b = 0;  // fixed: T; flux: q; convection: h, T_inf
  std::size_t report = 0;
};

// K (conductivity plus the convection "mass"), the load of the sources, fluxes and convection, the
// fixed values, per region the conductivity and source density (W/m^3).
struct ThermalSystem {
  unsigned threads = 1;
  RegionTable regions;
  std::vector<double> region_k, region_q;
  std::map<std::int32_t, TagBc> bc;
  P1Stiffness stiff;
  // Per node, the sum of its row of stiff in exact arithmetic: conduction rows sum to 0, a convection
  // triangle adds h A / 3 to each of its nodes (the reactions' difference form).
  std::vector<double> row_sum;
  std::vector<double> load;
  std::vector<double> bface_area;  // per boundary triangle with a condition, else 0
  Dirichlet dir;
};

// Checks `params` against the mesh (SolverError naming what is wrong) and assembles; fills
// rep.boundaries (tag, kind, area), rep.regions (region, volume, conductivity, power), rep.total_power.
// `require_anchor`: every connected part must touch a fixed or convective boundary (a steady solve;
// a transient one is well posed without, its heat capacity anchors it).
ThermalSystem assemble_thermal(const Mesh& mesh, const ThermalParams& params, ThermalReport& rep,
                               bool require_anchor = true);

// Throws SolverError when nothing but convection holds the body and so weakly that double precision
// cannot fix its temperature to 1e-3 of itself, an estimate tens to hundreds of times the error seen
// (h = 1e-8 W/(m^2 K) on a cube of k 1e4 printed 431.9 K for its 300 K ambient with every check
// passing; an outside probe). `what` names the solve.
void require_anchored(const ThermalSystem& sys, const std::string& what);

// Sets boundaries[i].heat_in (W) for the nodal temperatures `temp`: reactions (K temp - load) at the
// fixed nodes, q A on flux tags, h (T_inf - T) A on convection tags. `magnitude` (per boundary, W/K
// times K): what each heat's round-off is relative to, the fixed nodes' sum |K_vj temp_j| and a
// convection tag's h A (|T| + |T_inf|) (a relative error d of the temperatures errs a heat by at
// most d times it).
// `squares`: the sums of the squares of those terms (independent rounding errors add so).
void boundary_heat(const Mesh& mesh, const ThermalSystem& sys, const std::vector<double>& load,
                   const std::vector<double>& temp, std::vector<BoundaryHeat>& boundaries,
                   std::vector<double>* magnitude = nullptr, std::vector<double>* squares = nullptr);

// Per-region mean and max temperatures, the overall max, boundary mean temperatures and the
// resistances of params.resistances into `rep`; returns the cell field "heat_flux".
// Puts the node temperature (K) and the flux field on the mesh, replacing earlier ones: the steady
// and the transient solver's last state alike.
void store_temperature(Mesh& mesh, std::vector<double> temp, Field flux);

Field region_results(const Mesh& mesh, const ThermalParams& params, const ThermalSystem& sys,
                     const std::vector<double>& temp, ThermalReport& rep);

}  // namespace foxi::detail
