#include "scalar_p1.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace foxi::detail {

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
  if (!std::isfinite(v)) throw SolverInputError(what + " is not a finite number");
}

void set_field(Mesh& mesh, Field field) {
  for (Field& f : mesh.fields)
    if (f.name == field.name) {
      f = std::move(field);
      return;
    }
  mesh.fields.push_back(std::move(field));
}

void check_mesh(const Mesh& mesh) {
  if (std::string problem = check_sizes(mesh); !problem.empty())
    throw SolverInputError("inconsistent mesh: " + problem);
  if (mesh.tet_count() == 0) throw SolverInputError("the mesh has no tetrahedra");
}

void report_progress(const LinearSolverOptions& options, std::string_view stage, double fraction) {
  if (options.progress && !options.progress(stage, fraction))
    throw SolverCancelled("solve cancelled during '" + std::string(stage) + "'");
}

std::size_t RegionTable::index(std::int32_t id) const {
  auto it = std::lower_bound(ids.begin(), ids.end(), id);
  return (it != ids.end() && *it == id) ? static_cast<std::size_t>(it - ids.begin()) : SIZE_MAX;
}

RegionTable region_table(const Mesh& mesh) {
  RegionTable t;
  const std::size_t nt = mesh.tet_count();
  for (std::size_t i = 0; i < nt; ++i) {
    const std::int32_t r = mesh.region_of(i);
    if (t.ids.empty() || t.ids.back() != r) t.ids.push_back(r);
  }
  std::sort(t.ids.begin(), t.ids.end());
  t.ids.erase(std::unique(t.ids.begin(), t.ids.end()), t.ids.end());
  t.tet_rix.resize(nt);
  for (std::size_t i = 0; i < nt; ++i) t.tet_rix[i] = static_cast<std::uint32_t>(t.index(mesh.region_of(i)));
  return t;
}

std::vector<double> region_coefficients(const Mesh& mesh, const RegionTable& regions,
                                        const std::function<double(const Material&)>& from_material,
                                        const std::vector<std::pair<std::int32_t, double>>& overrides,
                                        const std::string& what, const std::string& hint) {
  return region_values(
      mesh, regions, from_material, overrides, what, hint, [](double v) { return v > 0 && std::isfinite(v); },
      "positive and finite");
}

std::vector<double> region_values(const Mesh& mesh, const RegionTable& regions,
                                  const std::function<double(const Material&)>& from_material,
                                  const std::vector<std::pair<std::int32_t, double>>& overrides,
                                  const std::string& what, const std::string& hint,
                                  const std::function<bool(double)>& valid, const std::string& requirement) {
  const std::size_t nr = regions.size();
  std::vector<double> c(nr, Material::kUnset);
  for (std::size_t i = 0; i < nr; ++i)
    if (const Region* r = mesh.find_region(regions.ids[i]); r && r->material < mesh.materials.size())
      c[i] = from_material(mesh.materials[r->material]);
  for (const auto& [id, value] : overrides) {
    const std::size_t i = regions.index(id);
    if (i == SIZE_MAX)
      throw SolverInputError(what + " given for " + region_label(mesh, id) + ", which has no tets");
    c[i] = value;
  }
  for (std::size_t i = 0; i < nr; ++i) {
    if (std::isnan(c[i]))
      throw SolverInputError(region_label(mesh, regions.ids[i]) + " has no " + what +
                             ": its material gives none; set it in " + hint + " " +
                             std::to_string(regions.ids[i]) + "=VALUE)");
    if (!valid(c[i]))
      throw SolverInputError(what + " of " + region_label(mesh, regions.ids[i]) + " must be " + requirement +
                             ", not " + std::to_string(c[i]));
  }
  return c;
}

std::vector<double> tet_volumes(const Mesh& mesh, const RegionTable& regions, unsigned threads,
                                std::vector<double>& region_volume) {
  const std::size_t nt = mesh.tet_count(), nr = regions.size();
  std::vector<double> vol(nt);
  std::vector<std::vector<double>> part(threads, std::vector<double>(nr, 0.0));
  parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned th) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t t = b; t < e; ++t) {
      vol[t] = p1_gradients(mesh, t, g);
      part[th][regions.tet_rix[t]] += vol[t];
    }
  });
  region_volume.assign(nr, 0.0);
  for (std::size_t i = 0; i < nr; ++i)
    for (unsigned th = 0; th < threads; ++th) region_volume[i] += part[th][i];
  for (std::size_t t = 0; t < nt; ++t)
    if (!(vol[t] > 0) || !std::isfinite(vol[t]))
      throw SolverInputError(
          "tet " + std::to_string(t) + " has " +
          (vol[t] > 0 ? "a volume beyond the range of double (" + std::to_string(vol[t]) +
                            "; rescale the coordinates)"
                      : "non-positive volume " + std::to_string(vol[t]) +
                            " (inverted or flat; validate_and_repair() re-orients inverted tets)"));
  return vol;
}

P1Stiffness assemble_stiffness(const Mesh& mesh, const std::vector<double>& tet_coefficient,
                               unsigned threads) {
  P1Stiffness k;
  k.ntets = node_tets(mesh);
  k.pat = node_pattern(mesh, k.ntets, threads);
  k.val.assign(k.pat.col.size(), 0.0);
  parallel_for(mesh.node_count(), threads, [&](std::size_t b, std::size_t e, unsigned) {
    std::array<std::array<double, 3>, 4> g;
    // Position of each column of the current row in val (a dense map, set row by row: O(1) lookups).
    std::vector<std::size_t> slot(mesh.node_count());
    for (std::size_t v = b; v < e; ++v) {
      for (std::size_t pos = k.pat.row_start[v]; pos < k.pat.row_start[v + 1]; ++pos)
        slot[k.pat.col[pos]] = pos;
      for (std::size_t i = k.ntets.node_start[v]; i < k.ntets.node_start[v + 1]; ++i) {
        const std::size_t t = k.ntets.item[i] >> 2;
        const unsigned a = k.ntets.item[i] & 3u;
        const double cv = tet_coefficient[t] * p1_gradients(mesh, t, g);
        for (unsigned c = 0; c < 4; ++c)
          k.val[slot[mesh.tet[4 * t + c]]] +=
              cv * (g[a][0] * g[c][0] + g[a][1] * g[c][1] + g[a][2] * g[c][2]);
      }
    }
  });
  std::vector<std::uint32_t>().swap(k.ntets.item);
  return k;
}

Dirichlet dirichlet_from_tags(const Mesh& mesh, const P1Stiffness& k,
                              const std::map<std::int32_t, FixedTag>& tags, std::size_t slots) {
  const std::size_t nn = mesh.node_count(), nf = mesh.bface_count();
  Dirichlet d;
  d.fixed.assign(nn, 0);
  d.value.assign(nn, std::numeric_limits<double>::quiet_NaN());
  d.area.assign(slots, 0.0);
  if (tags.empty()) return d;
  std::vector<double> sum(nn, 0.0), w(nn, 0.0), plain(nn, 0.0);
  std::vector<std::uint32_t> count(nn, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = tags.find(mesh.bface_tag[f]);
    if (it == tags.end()) continue;
    const double area = triangle_area(mesh, f);
    d.area[it->second.slot] += area;
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = mesh.bface[3 * f + i];
      sum[v] += area / 3 * it->second.value;
      w[v] += area / 3;
      plain[v] += it->second.value;
      ++count[v];
      d.shares.push_back({v, static_cast<std::uint32_t>(it->second.slot), area / 3});
    }
  }
  for (std::size_t v = 0; v < nn; ++v)
    if (count[v] && k.has_tets(v)) {
      d.fixed[v] = 1;
      d.value[v] = w[v] > 0 ? sum[v] / w[v] : plain[v] / count[v];
    }
  return d;
}

std::vector<std::uint32_t> tet_set_components(const Mesh& mesh,
                                              const std::function<bool(std::size_t)>& keep) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  std::vector<std::uint32_t> parent(nn);
  for (std::size_t v = 0; v < nn; ++v) parent[v] = static_cast<std::uint32_t>(v);
  std::vector<char> used(nn, 0);
  auto root = [&](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (std::size_t t = 0; t < nt; ++t) {
    if (keep && !keep(t)) continue;
    for (int a = 0; a < 4; ++a) used[mesh.tet[4 * t + a]] = 1;
    for (int a = 1; a < 4; ++a) {
      const std::uint32_t r0 = root(mesh.tet[4 * t]), r1 = root(mesh.tet[4 * t + a]);
      if (r0 != r1) parent[std::max(r0, r1)] = std::min(r0, r1);
    }
  }
  for (std::size_t v = 0; v < nn; ++v) parent[v] = used[v] ? root(static_cast<std::uint32_t>(v)) : UINT32_MAX;
  return parent;
}

std::vector<std::uint32_t> node_components(const Mesh& mesh) {
  std::vector<std::uint32_t> part = tet_set_components(mesh, {});
  for (std::size_t v = 0; v < part.size(); ++v)
    if (part[v] == UINT32_MAX) part[v] = static_cast<std::uint32_t>(v);
  return part;
}

std::vector<std::int32_t> boundary_tag_list(const Mesh& mesh) {
  std::vector<std::int32_t> tags(mesh.bface_tag.begin(), mesh.bface_tag.end());
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
  return tags;
}

void check_anchored(const Mesh& mesh, const std::vector<char>& anchored_node, const std::string& problem,
                    const std::string& what) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  const std::vector<std::uint32_t> part = node_components(mesh);
  std::vector<char> anchored(nn, 0);
  for (std::size_t v = 0; v < nn; ++v)
    if (anchored_node[v]) anchored[part[v]] = 1;
  for (std::size_t t = 0; t < nt; ++t)
    if (!anchored[part[mesh.tet[4 * t]]])
      throw SolverInputError(problem + ": the connected part containing tet " + std::to_string(t) + " (" +
                             region_label(mesh, mesh.region_of(t)) + ") " + what);
}

ReducedSystem reduce(const P1Stiffness& k, const std::vector<char>& fixed, unsigned threads) {
  const std::size_t nn = k.pat.rows();
  ReducedSystem r;
  r.dof.assign(nn, -1);
  int nfree = 0;
  for (std::size_t v = 0; v < nn; ++v)
    if (!fixed[v] && k.has_tets(v)) r.dof[v] = nfree++;
  const auto nf = static_cast<std::size_t>(nfree);
  std::vector<std::size_t> node(nf);  // the node of each free row
  for (std::size_t v = 0; v < nn; ++v)
    if (r.dof[v] >= 0) node[static_cast<std::size_t>(r.dof[v])] = v;
  // Two passes over the rows on threads: the length of each reduced row, then its entries in place.
  r.a.start.assign(nf + 1, 0);
  parallel_for(nf, threads, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t i = b; i < e; ++i) {
      int n = 0;
      for (std::size_t j = k.pat.row_start[node[i]]; j < k.pat.row_start[node[i] + 1]; ++j)
        n += r.dof[k.pat.col[j]] >= 0;
      r.a.start[i + 1] = n;
    }
  });
  std::size_t total = 0;
  for (std::size_t i = 0; i < nf; ++i) {
    total += static_cast<std::size_t>(r.a.start[i + 1]);
    if (total > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw SolverError("the system has more than 2^31 nonzeros");
    r.a.start[i + 1] = static_cast<int>(total);
  }
  r.a.col.resize(total);
  r.a.val.resize(total);
  parallel_for(nf, threads, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t i = b; i < e; ++i) {
      auto at = static_cast<std::size_t>(r.a.start[i]);
      for (std::size_t j = k.pat.row_start[node[i]]; j < k.pat.row_start[node[i] + 1]; ++j)
        if (const int c = r.dof[k.pat.col[j]]; c >= 0) {
          r.a.col[at] = c;
          r.a.val[at++] = k.val[j];
        }
    }
  });
  return r;
}

std::vector<double> reduced_rhs(const P1Stiffness& k, const ReducedSystem& r, const std::vector<double>& load,
                                const std::vector<char>& fixed, const std::vector<double>& u_fixed,
                                unsigned threads) {
  std::vector<double> rhs(r.a.rows());
  parallel_for(r.dof.size(), threads, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t v = b; v < e; ++v) {
      if (r.dof[v] < 0) continue;
      double s = load.empty() ? 0.0 : load[v];
      for (std::size_t i = k.pat.row_start[v]; i < k.pat.row_start[v + 1]; ++i)
        if (fixed[k.pat.col[i]]) s -= k.val[i] * u_fixed[k.pat.col[i]];
      rhs[static_cast<std::size_t>(r.dof[v])] = s;
    }
  });
  return rhs;
}

void scatter(const ReducedSystem& r, const std::vector<double>& x, std::vector<double>& u) {
  for (std::size_t v = 0; v < r.dof.size(); ++v)
    if (r.dof[v] >= 0) u[v] = x[static_cast<std::size_t>(r.dof[v])];
}

std::vector<double> slot_reactions(const P1Stiffness& k, const Dirichlet& d, const std::vector<double>& load,
                                   const std::vector<double>& u, const std::vector<double>& row_sum,
                                   std::size_t slots, std::vector<double>* magnitude,
                                   std::vector<double>* squares) {
  const std::size_t nn = d.fixed.size();
  std::vector<double> out(slots, 0.0);
  if (magnitude) magnitude->assign(slots, 0.0);
  if (squares) squares->assign(slots, 0.0);
  if (d.shares.empty()) return out;
  std::vector<double> reaction(nn, 0.0), terms(magnitude ? nn : 0, 0.0), terms2(squares ? nn : 0, 0.0),
      share_w(nn, 0.0);
  std::vector<std::uint32_t> share_n(nn, 0);
  for (std::size_t v = 0; v < nn; ++v) {
    if (!d.fixed[v]) continue;
    // (K u)_v = sum_j K_vj (u_j - u_v) + (sum_j K_vj) u_v, the row's sum taken as it is in exact
    // arithmetic (row_sum; conduction rows sum to 0): the plain sum is round-off of terms K_vv u_v
    // where conductivities differ by 1e12 (a boundary's heat was 6.8% off).
    double s = (load.empty() ? 0.0 : -load[v]) + (row_sum.empty() ? 0.0 : row_sum[v] * u[v]);
    for (std::size_t i = k.pat.row_start[v]; i < k.pat.row_start[v + 1]; ++i)
      s += k.val[i] * (u[k.pat.col[i]] - u[v]);
    reaction[v] = s;
    if (magnitude || squares)
      for (std::size_t i = k.pat.row_start[v]; i < k.pat.row_start[v + 1]; ++i) {
        const double term = k.val[i] * u[k.pat.col[i]];
        if (magnitude) terms[v] += std::abs(term);
        if (squares) terms2[v] += term * term;
      }
  }
  for (const Dirichlet::Share& s : d.shares) {
    share_w[s.node] += s.area;
    ++share_n[s.node];
  }
  for (const Dirichlet::Share& s : d.shares) {
    if (!d.fixed[s.node]) continue;
    const double w = share_w[s.node] > 0 ? s.area / share_w[s.node] : 1.0 / share_n[s.node];
    out[s.slot] += w * reaction[s.node];
    if (magnitude) (*magnitude)[s.slot] += w * terms[s.node];
    if (squares) (*squares)[s.slot] += w * w * terms2[s.node];
  }
  return out;
}

std::vector<double> cell_gradients(const Mesh& mesh, const RegionTable& regions,
                                   const std::vector<double>& region_coefficient,
                                   const std::vector<double>& u, double scale, unsigned threads,
                                   std::vector<double>* energy) {
  const std::size_t nt = mesh.tet_count(), nr = regions.size();
  std::vector<double> out(3 * nt);
  std::vector<std::vector<double>> part(threads, std::vector<double>(nr, 0.0));
  parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned th) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t t = b; t < e; ++t) {
      const double volume = p1_gradients(mesh, t, g);
      const double c = region_coefficient[regions.tet_rix[t]];
      double grad[3] = {0, 0, 0};
      for (int a = 0; a < 4; ++a) {
        const double ua = u[mesh.tet[4 * t + a]];
        for (int i = 0; i < 3; ++i) grad[i] += ua * g[a][i];
      }
      for (int i = 0; i < 3; ++i) out[3 * t + i] = scale * c * grad[i];
      part[th][regions.tet_rix[t]] +=
          volume * c * (grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2]);
    }
  });
  if (energy) {
    energy->assign(nr, 0.0);
    for (std::size_t i = 0; i < nr; ++i)
      for (unsigned th = 0; th < threads; ++th) (*energy)[i] += part[th][i];
  }
  return out;
}

}  // namespace foxi::detail
