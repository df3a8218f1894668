// Steady heat conduction with P1 tets. The stiffness matrix is assembled row by row over a node
// adjacency pattern (each thread owns whole rows, so no locks and a deterministic sum), Dirichlet
// nodes are eliminated into the right-hand side, and the reactions K T - f at the fixed nodes give
// the heat through the fixed-temperature boundaries.
#include "foxi/solver/thermal.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

#include "linear_solve.hpp"
#include "scalar_p1.hpp"
#include "thermal_setup.hpp"

namespace foxi {

namespace {

using detail::check_finite;
using detail::parallel_for;
using detail::region_label;
using detail::tag_label;

using detail::BcKind;
using detail::TagBc;

const char* probe_name(ThermalProbeKind kind) {
  switch (kind) {
    case ThermalProbeKind::region_max:
      return "maximum temperature";
    case ThermalProbeKind::region_mean:
      return "mean temperature";
    case ThermalProbeKind::boundary_mean:
      return "mean surface temperature";
    case ThermalProbeKind::ambient:
      return "ambient temperature";
  }
  return "temperature";
}

bool is_region_probe(ThermalProbeKind kind) {
  return kind == ThermalProbeKind::region_max || kind == ThermalProbeKind::region_mean;
}

// Throws SolverError when the probe names a region without tets, a tag on no boundary triangle, or
// the ambient of a tag that does not convect.
void check_probe(const Mesh& mesh, const ThermalProbe& probe, const detail::RegionTable& regions,
                 const std::vector<std::int32_t>& tags, const std::map<std::int32_t, TagBc>& bc) {
  const std::string what = std::string("thermal resistance: the ") + probe_name(probe.kind) + " of ";
  if (is_region_probe(probe.kind)) {
    if (regions.index(probe.id) == SIZE_MAX)
      throw SolverInputError(what + region_label(mesh, probe.id) + ", which has no tets");
    return;
  }
  if (!std::binary_search(tags.begin(), tags.end(), probe.id))
    throw SolverInputError(what + tag_label(mesh, probe.id) + ", which tags no boundary triangle");
  if (probe.kind == ThermalProbeKind::ambient) {
    auto it = bc.find(probe.id);
    if (it == bc.end() || it->second.kind != BcKind::convection)
      throw SolverInputError(what + tag_label(mesh, probe.id) + ": it has no convection condition");
  }
}

// Area mean of the P1 temperature over the triangles of `tag` (the plain mean of their nodes when
// they all have zero area).
double boundary_mean_temperature(const Mesh& mesh, std::int32_t tag, const std::vector<double>& temp) {
  double sum = 0, area = 0, plain = 0;
  std::size_t n = 0;
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    if (mesh.bface_tag[f] != tag) continue;
    const std::uint32_t* v = &mesh.bface[3 * f];
    const double a = detail::triangle_area(mesh, f), t = temp[v[0]] + temp[v[1]] + temp[v[2]];
    sum += a * t / 3;
    area += a;
    plain += t;
    n += 3;
  }
  return area > 0 ? sum / area : plain / static_cast<double>(n);
}

// The probe's temperature from the solved nodal temperatures and the region table of the report.
double probe_temperature(const Mesh& mesh, const ThermalProbe& probe, const ThermalReport& rep,
                         const std::vector<double>& temp, const std::map<std::int32_t, TagBc>& bc) {
  if (is_region_probe(probe.kind)) {
    for (const RegionTemperature& r : rep.regions)
      if (r.region == probe.id)
        return probe.kind == ThermalProbeKind::region_max ? r.max_temperature : r.mean_temperature;
  }
  if (probe.kind == ThermalProbeKind::ambient) return bc.at(probe.id).b;
  return boundary_mean_temperature(mesh, probe.id, temp);
}

ThermalResistance evaluate_resistance(const Mesh& mesh, const ThermalResistanceSpec& spec,
                                      const ThermalReport& rep, const std::vector<double>& temp,
                                      const std::map<std::int32_t, TagBc>& bc) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ThermalResistance r;
  r.spec = spec;
  r.junction_temperature = probe_temperature(mesh, spec.junction, rep, temp, bc);
  r.reference_temperature = probe_temperature(mesh, spec.reference, rep, temp, bc);
  r.delta_t = r.junction_temperature - r.reference_temperature;
  r.power = rep.total_power;
  for (const BoundaryHeat& b : rep.boundaries)
    if (b.kind == "flux") r.power += b.heat_in;
  r.theta = r.power != 0 ? r.delta_t / r.power : nan;
  // An insulated reference boundary takes no heat; a region reference has no boundary heat at all.
  r.reference_heat_out = is_region_probe(spec.reference.kind) ? nan : 0.0;
  for (const BoundaryHeat& b : rep.boundaries)
    if (!is_region_probe(spec.reference.kind) && b.tag == spec.reference.id)
      r.reference_heat_out = -b.heat_in;
  // A difference of round-off (no power: 6.8e-12 K over 6.6e-13 W of round-off heat gave 10.3 K/W)
  // is none: the ratio is undefined.
  const bool differs = std::abs(r.delta_t) >
                       1e-12 * std::max(std::abs(r.junction_temperature), std::abs(r.reference_temperature));
  r.path_theta = r.reference_heat_out != 0 && differs ? r.delta_t / r.reference_heat_out : nan;
  return r;
}

// Energy balance against the heat that flows (what enters, or what leaves if more): with no sources
// the net boundary heat is ~0 and no scale for itself. Each boundary's heat is known to its bound
// (BoundaryHeat::heat_bound): a fixed tag's reaction sums terms K_vj T_j, each T_j known to 4 eps of
// itself, a convection tag's heat
// h A (T_inf - T) likewise; temperatures given rounded to a relative `precision` (another program's
// printout) add precision |T_j| to each term, independently: 3 times the root of the sum of squares.
// The balance counts the imbalance beyond the bounds' sum (a body held at one temperature, or at
// its convective ambient, balances to round-off; the old floor, 1e-9 of sum K_vv T_v, grew with the
// conductivity and hid an imbalance of 3e-4 of the flow).
void energy_check(const Mesh& mesh, const std::vector<double>& temp, const std::vector<double>& magnitude,
                  const std::vector<double>& squares, double solver_tolerance, double precision,
                  ThermalReport& rep) {
  double in = std::max(0.0, rep.total_power), out = std::max(0.0, -rep.total_power);
  rep.imbalance = rep.total_power;
  for (const BoundaryHeat& b : rep.boundaries) {
    rep.imbalance += b.heat_in;
    (b.heat_in > 0 ? in : out) += std::abs(b.heat_in);
  }
  rep.heat_flow = std::max(in, out);
  // heat_bound: round-off (4 eps of the temperatures, a printout's precision). A heat is measured
  // when it passes that plus 1e-9 of its terms (an iterative solve's noise, ten times its default
  // tolerance): a body held at one temperature by AMG moves 1.5e-11 W of noise, no flow. (The
  // solve's relative residual times the terms, as a bound, refused AMG runs of 1e-4 W whose heats
  // agree with a direct solve's to 1e-6.) Where nothing is measured, the balance is held against
  // that noise too (a body at its convective ambient failed on 2.4e-15 W).
  double bounds = 0, noise = 0, measured_in = std::max(0.0, rep.total_power),
         measured_out = std::max(0.0, -rep.total_power);
  for (std::size_t b = 0; b < rep.boundaries.size(); ++b) {
    BoundaryHeat& h = rep.boundaries[b];
    h.heat_bound = 4 * std::numeric_limits<double>::epsilon() * magnitude[b] +
                   3 * std::max(precision, 0.0) * std::sqrt(squares[b]);
    bounds += h.heat_bound;
    const double heat_noise = h.heat_bound + 1e-9 * magnitude[b];
    noise += heat_noise;
    if (std::abs(h.heat_in) > heat_noise) (h.heat_in > 0 ? measured_in : measured_out) += std::abs(h.heat_in);
  }
  const bool flows = std::max(measured_in, measured_out) > 0;
  const double unexplained = std::max(0.0, std::abs(rep.imbalance) - (flows ? bounds : noise));
  const double tolerance =
      std::min(1e-3, std::max(1e-6, 100 * solver_tolerance));  // a loose --tol is no check
  rep.checks.push_back(
      make_check("energy",
                 "(|sources + boundary heat in| less the heats' round-off bounds) / the heat "
                 "that flows through the body",
                 unexplained > 0 ? unexplained / rep.heat_flow : 0.0, tolerance));
  // Resolution: each boundary's heat known to 1% of itself, or to 1e-6 of the heat that flows where it
  // is a small part of it. Conductivities 1e12 apart in series gave a heat 6.8% off, and 1e10 apart a
  // small heat of the wrong sign (+1.6e-4 W for -5e-5 W of a 1 W flow), the balance passing.
  const double flowing = std::max(measured_in, measured_out);
  double resolution = 0;
  if (flowing > 0)
    for (const BoundaryHeat& h : rep.boundaries)
      if (h.heat_bound > 0)
        resolution = std::max(resolution, h.heat_bound / std::max(std::abs(h.heat_in), 1e-4 * flowing));
  const double resolution_figure = resolution;
  // Linear conduction does not bound the temperatures: a power drawn out (negative) past what the
  // conditions can supply gives temperatures at or below 0 K, which no body has (-8e6 K was printed
  // with every check passed). The figure: minus the lowest temperature used by a tet, which must be
  // below 0.
  double lowest = std::numeric_limits<double>::infinity();
  for (const std::uint32_t v : mesh.tet) lowest = std::min(lowest, temp[v]);
  rep.checks.push_back(BalanceCheck{"absolute zero",
                                    "minus the lowest temperature, K: below 0 (else the powers or conditions "
                                    "are not physical)",
                                    -lowest, 0, -lowest < 0});
  // The bound adds every term's error with one sign, so it is tens of times the error seen (1e9:1
  // conductivities: bound 6.5e-4 of the flow, error 1.5e-5).
  rep.checks.push_back(
      make_check("resolution",
                 "largest round-off bound of a boundary's heat / that heat (or 1e-4 of the heat "
                 "that flows, if more): too large where conductivities differ by many orders",
                 resolution_figure, 1e-2));
}

}  // namespace

namespace detail {

ThermalSystem assemble_thermal(const Mesh& mesh, const ThermalParams& params, ThermalReport& rep,
                               bool require_anchor) {
  check_mesh(mesh);
  ThermalSystem sys;
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nf = mesh.bface_count();
  const unsigned threads = sys.threads = thread_count(params.solver.threads);
  auto progress = [&](std::string_view stage, double fraction) {
    report_progress(params.solver, stage, fraction);
  };
  progress("assemble", 0.0);

  // Regions with tets, dense indices, conductivity.
  sys.regions = region_table(mesh);
  const RegionTable& regions = sys.regions;
  const std::size_t nr = regions.size();
  std::vector<std::pair<std::int32_t, double>> overrides;
  for (const RegionConductivity& c : params.conductivity) overrides.emplace_back(c.region, c.k);
  sys.region_k = region_coefficients(
      mesh, regions, [](const Material& m) { return m.thermal_conductivity; }, overrides,
      "thermal conductivity", "ThermalParams::conductivity (foxi solve --k");
  const std::vector<double>& region_k = sys.region_k;
  const std::vector<std::uint32_t>& tet_rix = regions.tet_rix;
  auto region_index = [&](std::int32_t id) { return regions.index(id); };

  // Boundary conditions by tag.
  const std::vector<std::int32_t> tags = boundary_tag_list(mesh);
  std::map<std::int32_t, TagBc>& bc = sys.bc;
  auto add_bc = [&](std::int32_t tag, BcKind kind, double a, double b, const char* kind_name) {
    if (!std::binary_search(tags.begin(), tags.end(), tag))
      throw SolverInputError(std::string(kind_name) + " condition on " + tag_label(mesh, tag) +
                             ", which tags no boundary triangle");
    TagBc& t = bc[tag];
    if (t.kind != BcKind::none)
      throw SolverInputError(tag_label(mesh, tag) + " has more than one boundary condition");
    t = {kind, a, b, 0};
  };
  for (const FixedTemperature& f : params.fixed) {
    check_finite(f.temperature, "fixed temperature on " + tag_label(mesh, f.tag));
    add_bc(f.tag, BcKind::fixed, f.temperature, 0, "fixed-temperature");
  }
  for (const HeatFlux& f : params.flux) {
    check_finite(f.flux, "heat flux on " + tag_label(mesh, f.tag));
    add_bc(f.tag, BcKind::flux, f.flux, 0, "heat-flux");
  }
  bool has_convection = false;
  for (const Convection& c : params.convection) {
    check_finite(c.ambient, "ambient temperature on " + tag_label(mesh, c.tag));
    if (!(c.h > 0) || !std::isfinite(c.h))
      throw SolverInputError("convection coefficient h on " + tag_label(mesh, c.tag) +
                             " must be positive and finite");
    add_bc(c.tag, BcKind::convection, c.h, c.ambient, "convection");
    has_convection = true;
  }
  if (require_anchor && params.fixed.empty() && !has_convection)
    throw SolverInputError(
        "ill-posed thermal problem: no boundary has a fixed temperature or convection, so the "
        "temperature is determined only up to a constant (and a net heat input has no way out); "
        "fix a temperature or add convection on at least one boundary tag");
  for (const ThermalResistanceSpec& spec : params.resistances) {
    check_probe(mesh, spec.junction, regions, tags, bc);
    check_probe(mesh, spec.reference, regions, tags, bc);
  }
  for (auto& [tag, t] : bc) {
    t.report = rep.boundaries.size();
    BoundaryHeat h;
    h.tag = tag;
    h.kind = t.kind == BcKind::fixed ? "fixed" : t.kind == BcKind::flux ? "flux" : "convection";
    rep.boundaries.push_back(h);
  }

  // Tet volumes, region volumes, source densities.
  {
    std::vector<double> region_volume;
    (void)tet_volumes(mesh, regions, threads, region_volume);
    rep.regions.resize(nr);
    for (std::size_t i = 0; i < nr; ++i) {
      rep.regions[i].region = regions.ids[i];
      rep.regions[i].conductivity = region_k[i];
      rep.regions[i].volume = region_volume[i];
    }
  }
  sys.region_q.assign(nr, 0.0);  // W/m^3
  std::vector<double>& region_q = sys.region_q;
  std::vector<bool> source_given(nr, false);
  for (const HeatSource& s : params.sources) {
    const std::size_t i = region_index(s.region);
    if (i == SIZE_MAX)
      throw SolverInputError("heat source given for " + region_label(mesh, s.region) + ", which has no tets");
    check_finite(s.value, "heat source of " + region_label(mesh, s.region));
    if (source_given[i])
      throw SolverInputError(region_label(mesh, s.region) + " has more than one heat source");
    source_given[i] = true;
    region_q[i] = s.total ? s.value / rep.regions[i].volume : s.value;
  }
  for (std::size_t i = 0; i < nr; ++i) {
    rep.regions[i].power = region_q[i] * rep.regions[i].volume;
    rep.total_power += rep.regions[i].power;
  }

  // Stiffness (row-wise over the node pattern) and source load.
  std::vector<double> tet_k(nt);
  for (std::size_t t = 0; t < nt; ++t) tet_k[t] = region_k[tet_rix[t]];
  sys.stiff = assemble_stiffness(mesh, tet_k, threads);
  P1Stiffness& stiff = sys.stiff;
  std::vector<double>().swap(tet_k);  // not needed again; the solve needs the memory
  const CsrPattern& pat = stiff.pat;
  std::vector<double>& kval = stiff.val;
  sys.load.assign(nn, 0.0);
  std::vector<double>& load = sys.load;
  {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t t = 0; t < nt; ++t) {
      const double q = region_q[tet_rix[t]];
      if (q == 0) continue;
      const double share = q * p1_gradients(mesh, t, g) * 0.25;
      for (int a = 0; a < 4; ++a) load[mesh.tet[4 * t + a]] += share;
    }
  }
  progress("assemble", 0.5);

  // Boundary triangles: Robin mass, flux and convection loads, fixed values (lumped-area mean).
  sys.bface_area.assign(nf, 0.0);
  sys.row_sum.assign(nn, 0.0);
  std::vector<double>& bface_area = sys.bface_area;
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = bc.find(mesh.bface_tag[f]);
    if (it == bc.end()) continue;
    const TagBc& t = it->second;
    const double area = triangle_area(mesh, f);
    bface_area[f] = area;
    rep.boundaries[t.report].area += area;
    const std::uint32_t* v = &mesh.bface[3 * f];
    switch (t.kind) {
      case BcKind::fixed:
        break;
      case BcKind::flux:
        for (int i = 0; i < 3; ++i) load[v[i]] += t.a * area / 3;
        break;
      case BcKind::convection:
        for (int i = 0; i < 3; ++i) {
          load[v[i]] += t.a * t.b * area / 3;
          sys.row_sum[v[i]] += t.a * area / 3;
          for (int j = 0; j < 3; ++j) {
            const std::size_t pos = pat.find(v[i], v[j]);
            if (pos == SIZE_MAX)
              throw SolverInputError("boundary triangle " + std::to_string(f) + " (" +
                                     tag_label(mesh, mesh.bface_tag[f]) + ") is not a face of any tet");
            kval[pos] +=
                params.convection_centroid_rule ? t.a * area / 9 : t.a * area / 12 * (i == j ? 2.0 : 1.0);
          }
        }
        break;
      case BcKind::none:
        break;
    }
  }
  // Fixed values; a zero-area neighbourhood falls back to the plain mean of the tags' values.
  std::map<std::int32_t, FixedTag> fixed_tags;
  for (const auto& [tag, t] : bc)
    if (t.kind == BcKind::fixed) fixed_tags[tag] = {t.a, t.report};
  sys.dir = dirichlet_from_tags(mesh, stiff, fixed_tags, rep.boundaries.size());
  const std::vector<char>& fixed = sys.dir.fixed;

  // Every connected part needs a fixed or convective node, else its temperature is undetermined.
  if (require_anchor) {
    std::vector<char> anchored = fixed;
    for (std::size_t f = 0; f < nf; ++f) {
      auto it = bc.find(mesh.bface_tag[f]);
      if (it != bc.end() && it->second.kind == BcKind::convection) anchored[mesh.bface[3 * f]] = 1;
    }
    check_anchored(mesh, anchored, "ill-posed thermal problem",
                   "touches no fixed-temperature or convection boundary, so its temperature is undetermined");
  }
  return sys;
}

void require_anchored(const ThermalSystem& sys, const std::string& what) {
  if (std::find(sys.dir.fixed.begin(), sys.dir.fixed.end(), char(1)) != sys.dir.fixed.end()) return;
  // Held by convection alone, the body's mean temperature is fixed by sum h A against the conduction
  // rows' round-off (about eps sum_j |K_vj| T per row, independent: their root sum of squares): the
  // ratio is the mean's relative error (a 10 mm cube of k 1e4: h 1e-6 estimate 0.036, error 3e-4;
  // h 1e-5 3.6e-3 and 1.4e-4; h 1e-4 3.6e-4 and 5e-5).
  double rows = 0, held = 0;
  for (std::size_t v = 0; v + 1 < sys.stiff.pat.row_start.size(); ++v) {
    double row = 0;
    for (std::size_t i = sys.stiff.pat.row_start[v]; i < sys.stiff.pat.row_start[v + 1]; ++i)
      row += std::abs(sys.stiff.val[i]);
    rows += row * row;
  }
  rows = std::sqrt(rows);
  for (const double h : sys.row_sum) held += h;
  const double error = 4 * std::numeric_limits<double>::epsilon() * rows / held;
  if (!(error > 1e-3)) return;
  char figure[160];
  std::snprintf(figure, sizeof figure,
                "its convection, sum h A = %.3g W/K, holds its temperature to %.2g of itself against the "
                "round-off of its conduction (sum |K| = %.3g W/K)",
                held, error, rows);
  throw SolverError(what + ": the body is held too weakly for double precision: " + figure +
                    "; give a larger h or a fixed temperature");
}

void boundary_heat(const Mesh& mesh, const ThermalSystem& sys, const std::vector<double>& load,
                   const std::vector<double>& temp, std::vector<BoundaryHeat>& boundaries,
                   std::vector<double>* magnitude, std::vector<double>* squares) {
  const std::vector<double> heat =
      slot_reactions(sys.stiff, sys.dir, load, temp, sys.row_sum, boundaries.size(), magnitude, squares);
  for (std::size_t i = 0; i < heat.size(); ++i) boundaries[i].heat_in = heat[i];
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    auto it = sys.bc.find(mesh.bface_tag[f]);
    if (it == sys.bc.end()) continue;
    const TagBc& t = it->second;
    const std::uint32_t* v = &mesh.bface[3 * f];
    if (t.kind == BcKind::flux) {
      boundaries[t.report].heat_in += t.a * sys.bface_area[f];
    } else if (t.kind == BcKind::convection) {
      const double mean = (temp[v[0]] + temp[v[1]] + temp[v[2]]) / 3;
      boundaries[t.report].heat_in += t.a * (t.b - mean) * sys.bface_area[f];
      const double ha = t.a * sys.bface_area[f],
                   hot = std::max({std::abs(temp[v[0]]), std::abs(temp[v[1]]), std::abs(temp[v[2]])});
      if (magnitude) (*magnitude)[t.report] += ha * (hot + std::abs(t.b));
      if (squares) (*squares)[t.report] += ha * ha * (hot * hot + t.b * t.b);
    }
  }
}

void store_temperature(Mesh& mesh, std::vector<double> temp, Field flux) {
  Field temp_field;
  temp_field.name = "temperature";
  temp_field.location = FieldLocation::node;
  temp_field.components = 1;
  temp_field.unit = "K";
  temp_field.values = std::move(temp);
  set_field(mesh, std::move(temp_field));
  set_field(mesh, std::move(flux));
}

Field region_results(const Mesh& mesh, const ThermalParams& params, const ThermalSystem& sys,
                     const std::vector<double>& temp, ThermalReport& rep) {
  const std::size_t nt = mesh.tet_count();
  Field flux_field;
  flux_field.name = "heat_flux";
  flux_field.location = FieldLocation::cell;
  flux_field.components = 3;
  flux_field.unit = "W/m^2";
  flux_field.values.resize(3 * nt);
  const unsigned threads = sys.threads;
  const std::size_t nr = sys.regions.size();
  const std::vector<double>& region_k = sys.region_k;
  const std::vector<std::uint32_t>& tet_rix = sys.regions.tet_rix;
  std::vector<std::vector<double>> region_tv(threads, std::vector<double>(nr, 0.0));
  parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned th) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t t = b; t < e; ++t) {
      const double volume = detail::p1_gradients(mesh, t, g);
      const double k = region_k[tet_rix[t]];
      double grad[3] = {0, 0, 0}, mean = 0;
      for (int a = 0; a < 4; ++a) {
        const double ta = temp[mesh.tet[4 * t + a]];
        mean += 0.25 * ta;
        for (int c = 0; c < 3; ++c) grad[c] += ta * g[a][c];
      }
      for (int c = 0; c < 3; ++c) flux_field.values[3 * t + c] = -k * grad[c];
      region_tv[th][tet_rix[t]] += volume * mean;
    }
  });
  for (std::size_t i = 0; i < nr; ++i) {
    double s = 0;
    for (unsigned th = 0; th < threads; ++th) s += region_tv[th][i];
    rep.regions[i].mean_temperature = s / rep.regions[i].volume;
    rep.regions[i].max_temperature = -std::numeric_limits<double>::infinity();
  }
  rep.max_temperature = -std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < nt; ++t) {
    RegionTemperature& r = rep.regions[tet_rix[t]];
    for (int a = 0; a < 4; ++a) {
      const std::uint32_t v = mesh.tet[4 * t + a];
      if (temp[v] > r.max_temperature) {
        r.max_temperature = temp[v];
        r.max_node = v;
      }
    }
  }
  for (const RegionTemperature& r : rep.regions)
    if (r.max_temperature > rep.max_temperature) {
      rep.max_temperature = r.max_temperature;
      rep.max_node = r.max_node;
    }
  for (BoundaryHeat& b : rep.boundaries) b.mean_temperature = boundary_mean_temperature(mesh, b.tag, temp);
  for (const ThermalResistanceSpec& spec : params.resistances)
    rep.resistances.push_back(evaluate_resistance(mesh, spec, rep, temp, sys.bc));
  return flux_field;
}

}  // namespace detail

ThermalReport solve_thermal(Mesh& mesh, const ThermalParams& params) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  ThermalReport rep;
  const detail::ThermalSystem sys = detail::assemble_thermal(mesh, params, rep);
  detail::require_anchored(sys, "steady heat conduction");
  auto progress = [&](std::string_view stage, double fraction) {
    detail::report_progress(params.solver, stage, fraction);
  };
  const unsigned threads = sys.threads;
  const detail::P1Stiffness& stiff = sys.stiff;
  const std::vector<double>& load = sys.load;
  const std::vector<char>& fixed = sys.dir.fixed;
  std::vector<double> temp = sys.dir.value;

  // Free unknowns and the reduced system.
  const detail::ReducedSystem red = detail::reduce(stiff, fixed, threads);
  const std::vector<double> rhs = detail::reduced_rhs(stiff, red, load, fixed, temp, threads);
  rep.unknowns = red.a.rows();
  rep.nonzeros = red.a.val.size();
  progress("assemble", 1.0);
  const auto t_assembled = clock::now();

  std::vector<double> x;
  const detail::LinearSolveResult lin = detail::solve_spd(red.a, rhs, x, params.solver);
  rep.solver = lin.solver;
  rep.iterations = lin.iterations;
  rep.relative_residual = lin.relative_residual;
  const auto t_solved = clock::now();
  detail::scatter(red, x, temp);

  // Heat through the boundaries, cell heat flux and per-region temperatures.
  std::vector<double> magnitude, squares;
  detail::boundary_heat(mesh, sys, load, temp, rep.boundaries, &magnitude, &squares);
  Field flux_field = detail::region_results(mesh, params, sys, temp, rep);

  energy_check(mesh, temp, magnitude, squares, params.solver.relative_tolerance, 0, rep);

  detail::store_temperature(mesh, std::move(temp), std::move(flux_field));
  rep.assembly_seconds = std::chrono::duration<double>(t_assembled - t_start).count();
  rep.solve_seconds = std::chrono::duration<double>(t_solved - t_assembled).count();
  return rep;
}

ThermalReport thermal_report(Mesh& mesh, const ThermalParams& params, std::vector<double> temperature,
                             double precision) {
  const auto t_start = std::chrono::steady_clock::now();
  ThermalReport rep;
  const detail::ThermalSystem sys = detail::assemble_thermal(mesh, params, rep);
  if (temperature.size() != mesh.node_count())
    throw SolverError("thermal_report: " + std::to_string(temperature.size()) + " temperatures for " +
                      std::to_string(mesh.node_count()) + " nodes");
  for (std::size_t t = 0; t < mesh.tet.size(); ++t)
    if (!std::isfinite(temperature[mesh.tet[t]]))
      throw SolverError("thermal_report: node " + std::to_string(mesh.tet[t]) +
                        " of a tet has no temperature");
  std::vector<double> magnitude, squares;
  detail::boundary_heat(mesh, sys, sys.load, temperature, rep.boundaries, &magnitude, &squares);
  Field flux_field = detail::region_results(mesh, params, sys, temperature, rep);
  energy_check(mesh, temperature, magnitude, squares, params.solver.relative_tolerance, precision, rep);
  detail::store_temperature(mesh, std::move(temperature), std::move(flux_field));
  rep.solver = "given";
  rep.assembly_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return rep;
}

}  // namespace foxi
