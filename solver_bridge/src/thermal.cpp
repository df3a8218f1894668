// Steady heat conduction with P1 tets. The stiffness matrix is assembled row by row over a node
// adjacency pattern (each thread owns whole rows, so no locks and a deterministic sum), Dirichlet
// nodes are eliminated into the right-hand side, and the reactions K T - f at the fixed nodes give
// the heat through the fixed-temperature boundaries.
#include "foxi/solver/thermal.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "linear_solve.hpp"
#include "p1_assembly.hpp"

namespace foxi {

namespace {

using detail::parallel_for;

std::string region_label(const Mesh& mesh, std::int32_t id) {
  std::string s = "region " + std::to_string(id);
  if (const Region* r = mesh.find_region(id); r && !r->name.empty()) s += " ('" + r->name + "')";
  return s;
}

std::string tag_label(const Mesh& mesh, std::int32_t tag) {
  std::string s = "boundary tag " + std::to_string(tag);
  if (const Boundary* b = mesh.find_boundary(tag); b && !b->name.empty()) s += " ('" + b->name + "')";
  return s;
}

void check_finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw SolverError(what + " is not a finite number");
}

void set_field(Mesh& mesh, Field field) {
  for (Field& f : mesh.fields)
    if (f.name == field.name) {
      f = std::move(field);
      return;
    }
  mesh.fields.push_back(std::move(field));
}

enum class BcKind : std::uint8_t { none, fixed, flux, convection };

struct TagBc {
  BcKind kind = BcKind::none;
  double a = 0, b = 0;  // fixed: T; flux: q; convection: h, T_inf
  std::size_t report = 0;
};

}  // namespace

ThermalReport solve_thermal(Mesh& mesh, const ThermalParams& params) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  if (std::string problem = check_sizes(mesh); !problem.empty())
    throw SolverError("inconsistent mesh: " + problem);
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nf = mesh.bface_count();
  if (nt == 0) throw SolverError("the mesh has no tetrahedra");
  const unsigned threads = detail::thread_count(params.solver.threads);
  auto progress = [&](std::string_view stage, double fraction) {
    if (params.solver.progress && !params.solver.progress(stage, fraction))
      throw SolverCancelled("solve cancelled during '" + std::string(stage) + "'");
  };
  progress("assemble", 0.0);

  // Regions with tets, dense indices, conductivity.
  std::vector<std::int32_t> region_ids;
  for (std::size_t t = 0; t < nt; ++t) {
    const std::int32_t r = mesh.region_of(t);
    if (region_ids.empty() || region_ids.back() != r) region_ids.push_back(r);
  }
  std::sort(region_ids.begin(), region_ids.end());
  region_ids.erase(std::unique(region_ids.begin(), region_ids.end()), region_ids.end());
  const std::size_t nr = region_ids.size();
  auto region_index = [&](std::int32_t id) -> std::size_t {
    auto it = std::lower_bound(region_ids.begin(), region_ids.end(), id);
    return (it != region_ids.end() && *it == id) ? static_cast<std::size_t>(it - region_ids.begin())
                                                 : SIZE_MAX;
  };
  std::vector<double> region_k(nr, Material::kUnset);
  for (std::size_t i = 0; i < nr; ++i)
    if (const Region* r = mesh.find_region(region_ids[i]); r && r->material < mesh.materials.size())
      region_k[i] = mesh.materials[r->material].thermal_conductivity;
  for (const RegionConductivity& c : params.conductivity) {
    const std::size_t i = region_index(c.region);
    if (i == SIZE_MAX)
      throw SolverError("conductivity given for " + region_label(mesh, c.region) + ", which has no tets");
    region_k[i] = c.k;
  }
  for (std::size_t i = 0; i < nr; ++i) {
    if (std::isnan(region_k[i]))
      throw SolverError(
          region_label(mesh, region_ids[i]) +
          " has no thermal conductivity: its material gives none; set it in ThermalParams::conductivity "
          "(foxi solve --k " +
          std::to_string(region_ids[i]) + "=K)");
    if (!(region_k[i] > 0) || !std::isfinite(region_k[i]))
      throw SolverError("thermal conductivity of " + region_label(mesh, region_ids[i]) +
                        " must be positive and finite, not " + std::to_string(region_k[i]));
  }
  std::vector<std::uint32_t> tet_rix(nt);
  for (std::size_t t = 0; t < nt; ++t)
    tet_rix[t] = static_cast<std::uint32_t>(region_index(mesh.region_of(t)));

  // Boundary conditions by tag.
  std::vector<std::int32_t> tags(mesh.bface_tag.begin(), mesh.bface_tag.end());
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
  std::map<std::int32_t, TagBc> bc;
  ThermalReport rep;
  auto add_bc = [&](std::int32_t tag, BcKind kind, double a, double b, const char* kind_name) {
    if (!std::binary_search(tags.begin(), tags.end(), tag))
      throw SolverError(std::string(kind_name) + " condition on " + tag_label(mesh, tag) +
                        ", which tags no boundary triangle");
    TagBc& t = bc[tag];
    if (t.kind != BcKind::none)
      throw SolverError(tag_label(mesh, tag) + " has more than one boundary condition");
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
      throw SolverError("convection coefficient h on " + tag_label(mesh, c.tag) +
                        " must be positive and finite");
    add_bc(c.tag, BcKind::convection, c.h, c.ambient, "convection");
    has_convection = true;
  }
  if (params.fixed.empty() && !has_convection)
    throw SolverError(
        "ill-posed thermal problem: no boundary has a fixed temperature or convection, so the "
        "temperature is determined only up to a constant (and a net heat input has no way out); "
        "fix a temperature or add convection on at least one boundary tag");
  for (auto& [tag, t] : bc) {
    t.report = rep.boundaries.size();
    BoundaryHeat h;
    h.tag = tag;
    h.kind = t.kind == BcKind::fixed ? "fixed" : t.kind == BcKind::flux ? "flux" : "convection";
    rep.boundaries.push_back(h);
  }

  // Tet volumes, region volumes, source densities.
  std::vector<double> vol(nt);
  {
    std::vector<std::vector<double>> part(threads, std::vector<double>(nr, 0.0));
    parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned th) {
      std::array<std::array<double, 3>, 4> g;
      for (std::size_t t = b; t < e; ++t) {
        vol[t] = detail::p1_gradients(mesh, t, g);
        part[th][tet_rix[t]] += vol[t];
      }
    });
    rep.regions.resize(nr);
    for (std::size_t i = 0; i < nr; ++i) {
      rep.regions[i].region = region_ids[i];
      rep.regions[i].conductivity = region_k[i];
      for (unsigned th = 0; th < threads; ++th) rep.regions[i].volume += part[th][i];
    }
  }
  for (std::size_t t = 0; t < nt; ++t)
    if (!(vol[t] > 0))
      throw SolverError("tet " + std::to_string(t) + " has non-positive volume " + std::to_string(vol[t]) +
                        " (inverted or flat; validate_and_repair() re-orients inverted tets)");
  std::vector<double> region_q(nr, 0.0);  // W/m^3
  std::vector<bool> source_given(nr, false);
  for (const HeatSource& s : params.sources) {
    const std::size_t i = region_index(s.region);
    if (i == SIZE_MAX)
      throw SolverError("heat source given for " + region_label(mesh, s.region) + ", which has no tets");
    check_finite(s.value, "heat source of " + region_label(mesh, s.region));
    if (source_given[i]) throw SolverError(region_label(mesh, s.region) + " has more than one heat source");
    source_given[i] = true;
    region_q[i] = s.total ? s.value / rep.regions[i].volume : s.value;
  }
  for (std::size_t i = 0; i < nr; ++i) {
    rep.regions[i].power = region_q[i] * rep.regions[i].volume;
    rep.total_power += rep.regions[i].power;
  }

  // Stiffness (row-wise over the node pattern) and source load.
  const detail::NodeTets ntets = detail::node_tets(mesh);
  const detail::CsrPattern pat = detail::node_pattern(mesh, ntets, threads);
  std::vector<double> kval(pat.col.size(), 0.0);
  std::vector<double> load(nn, 0.0);
  parallel_for(nn, threads, [&](std::size_t b, std::size_t e, unsigned) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t v = b; v < e; ++v) {
      const std::size_t rs = pat.row_start[v], re = pat.row_start[v + 1];
      for (std::size_t k = ntets.node_start[v]; k < ntets.node_start[v + 1]; ++k) {
        const std::size_t t = ntets.item[k] >> 2;
        const unsigned a = ntets.item[k] & 3u;
        const double volume = detail::p1_gradients(mesh, t, g);
        const double kv = region_k[tet_rix[t]] * volume;
        load[v] += region_q[tet_rix[t]] * volume * 0.25;
        for (unsigned c = 0; c < 4; ++c) {
          const std::uint32_t col = mesh.tet[4 * t + c];
          std::size_t pos = rs;
          while (pos < re && pat.col[pos] != col) ++pos;
          kval[pos] += kv * (g[a][0] * g[c][0] + g[a][1] * g[c][1] + g[a][2] * g[c][2]);
        }
      }
    }
  });
  progress("assemble", 0.5);

  // Boundary triangles: Robin mass, flux and convection loads, fixed values (lumped-area mean).
  std::vector<double> fix_sum(nn, 0.0), fix_w(nn, 0.0);
  std::vector<std::uint32_t> fix_count(nn, 0);
  struct FixShare {
    std::uint32_t node;
    std::uint32_t report;
    double area;
  };
  std::vector<FixShare> fix_share;
  std::vector<double> bface_area(nf, 0.0);
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = bc.find(mesh.bface_tag[f]);
    if (it == bc.end()) continue;
    const TagBc& t = it->second;
    const double area = detail::triangle_area(mesh, f);
    bface_area[f] = area;
    rep.boundaries[t.report].area += area;
    const std::uint32_t* v = &mesh.bface[3 * f];
    switch (t.kind) {
      case BcKind::fixed:
        for (int i = 0; i < 3; ++i) {
          fix_sum[v[i]] += area / 3 * t.a;
          fix_w[v[i]] += area / 3;
          ++fix_count[v[i]];
          fix_share.push_back({v[i], static_cast<std::uint32_t>(t.report), area / 3});
        }
        break;
      case BcKind::flux:
        for (int i = 0; i < 3; ++i) load[v[i]] += t.a * area / 3;
        break;
      case BcKind::convection:
        for (int i = 0; i < 3; ++i) {
          load[v[i]] += t.a * t.b * area / 3;
          for (int j = 0; j < 3; ++j) {
            const std::size_t pos = pat.find(v[i], v[j]);
            if (pos == SIZE_MAX)
              throw SolverError("boundary triangle " + std::to_string(f) + " (" +
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
  std::vector<double> temp(nn, std::numeric_limits<double>::quiet_NaN());
  std::vector<char> fixed(nn, 0);
  if (!params.fixed.empty()) {
    std::vector<double> plain(nn, 0.0);
    for (std::size_t f = 0; f < nf; ++f) {
      auto it = bc.find(mesh.bface_tag[f]);
      if (it == bc.end() || it->second.kind != BcKind::fixed) continue;
      for (int i = 0; i < 3; ++i) plain[mesh.bface[3 * f + i]] += it->second.a;
    }
    for (std::size_t v = 0; v < nn; ++v)
      if (fix_count[v] && ntets.node_start[v + 1] > ntets.node_start[v]) {
        fixed[v] = 1;
        temp[v] = fix_w[v] > 0 ? fix_sum[v] / fix_w[v] : plain[v] / fix_count[v];
      }
  }

  // Every connected part needs a fixed or convective node, else its temperature is undetermined.
  {
    std::vector<std::uint32_t> parent(nn);
    for (std::size_t v = 0; v < nn; ++v) parent[v] = static_cast<std::uint32_t>(v);
    auto root = [&](std::uint32_t v) {
      while (parent[v] != v) v = parent[v] = parent[parent[v]];
      return v;
    };
    for (std::size_t t = 0; t < nt; ++t)
      for (int a = 1; a < 4; ++a) {
        const std::uint32_t r0 = root(mesh.tet[4 * t]), r1 = root(mesh.tet[4 * t + a]);
        if (r0 != r1) parent[std::max(r0, r1)] = std::min(r0, r1);
      }
    std::vector<char> anchored(nn, 0);
    for (std::size_t v = 0; v < nn; ++v)
      if (fixed[v]) anchored[root(static_cast<std::uint32_t>(v))] = 1;
    for (std::size_t f = 0; f < nf; ++f) {
      auto it = bc.find(mesh.bface_tag[f]);
      if (it != bc.end() && it->second.kind == BcKind::convection) anchored[root(mesh.bface[3 * f])] = 1;
    }
    for (std::size_t t = 0; t < nt; ++t)
      if (!anchored[root(mesh.tet[4 * t])])
        throw SolverError("ill-posed thermal problem: the connected part containing tet " +
                          std::to_string(t) + " (" + region_label(mesh, mesh.region_of(t)) +
                          ") touches no fixed-temperature or convection boundary, so its temperature is "
                          "undetermined");
  }

  // Free unknowns and the reduced system.
  std::vector<int> dof(nn, -1);
  int nfree = 0;
  for (std::size_t v = 0; v < nn; ++v)
    if (!fixed[v] && ntets.node_start[v + 1] > ntets.node_start[v]) dof[v] = nfree++;
  detail::SymmetricCsr sys;
  sys.start.reserve(static_cast<std::size_t>(nfree) + 1);
  sys.start.push_back(0);
  sys.col.reserve(pat.col.size());
  sys.val.reserve(pat.col.size());
  std::vector<double> rhs(static_cast<std::size_t>(nfree));
  for (std::size_t v = 0; v < nn; ++v) {
    if (dof[v] < 0) continue;
    double r = load[v];
    for (std::size_t k = pat.row_start[v]; k < pat.row_start[v + 1]; ++k) {
      const std::uint32_t c = pat.col[k];
      if (dof[c] >= 0) {
        sys.col.push_back(dof[c]);
        sys.val.push_back(kval[k]);
      } else if (fixed[c]) {
        r -= kval[k] * temp[c];
      }
    }
    rhs[static_cast<std::size_t>(dof[v])] = r;
    sys.start.push_back(static_cast<int>(sys.col.size()));
  }
  rep.unknowns = static_cast<std::size_t>(nfree);
  rep.nonzeros = sys.val.size();
  progress("assemble", 1.0);
  const auto t_assembled = clock::now();

  std::vector<double> x;
  const detail::LinearSolveResult lin = detail::solve_spd(sys, rhs, x, params.solver);
  rep.solver = lin.solver;
  rep.iterations = lin.iterations;
  rep.relative_residual = lin.relative_residual;
  const auto t_solved = clock::now();
  for (std::size_t v = 0; v < nn; ++v)
    if (dof[v] >= 0) temp[v] = x[static_cast<std::size_t>(dof[v])];

  // Heat through the boundaries.
  if (!fix_share.empty()) {
    std::vector<double> reaction(nn, 0.0), share_w(nn, 0.0);
    std::vector<std::uint32_t> share_n(nn, 0);
    for (std::size_t v = 0; v < nn; ++v) {
      if (!fixed[v]) continue;
      double s = -load[v];
      for (std::size_t k = pat.row_start[v]; k < pat.row_start[v + 1]; ++k) s += kval[k] * temp[pat.col[k]];
      reaction[v] = s;
    }
    for (const FixShare& s : fix_share) {
      share_w[s.node] += s.area;
      ++share_n[s.node];
    }
    for (const FixShare& s : fix_share) {
      if (!fixed[s.node]) continue;
      const double w = share_w[s.node] > 0 ? s.area / share_w[s.node] : 1.0 / share_n[s.node];
      rep.boundaries[s.report].heat_in += w * reaction[s.node];
    }
  }
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = bc.find(mesh.bface_tag[f]);
    if (it == bc.end()) continue;
    const TagBc& t = it->second;
    const std::uint32_t* v = &mesh.bface[3 * f];
    if (t.kind == BcKind::flux) {
      rep.boundaries[t.report].heat_in += t.a * bface_area[f];
    } else if (t.kind == BcKind::convection) {
      const double mean = (temp[v[0]] + temp[v[1]] + temp[v[2]]) / 3;
      rep.boundaries[t.report].heat_in += t.a * (t.b - mean) * bface_area[f];
    }
  }

  // Cell heat flux and per-region temperatures.
  Field flux_field;
  flux_field.name = "heat_flux";
  flux_field.location = FieldLocation::cell;
  flux_field.components = 3;
  flux_field.unit = "W/m^2";
  flux_field.values.resize(3 * nt);
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

  Field temp_field;
  temp_field.name = "temperature";
  temp_field.location = FieldLocation::node;
  temp_field.components = 1;
  temp_field.unit = "K";
  temp_field.values = std::move(temp);
  set_field(mesh, std::move(temp_field));
  set_field(mesh, std::move(flux_field));
  rep.assembly_seconds = std::chrono::duration<double>(t_assembled - t_start).count();
  rep.solve_seconds = std::chrono::duration<double>(t_solved - t_assembled).count();
  return rep;
}

}  // namespace foxi
