// Field transfer by id and by location (see transfer.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>

#include "foxi/fields/transfer.hpp"
#include "foxi/model/parallel.hpp"
#include "spatial_grid.hpp"

namespace foxi {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string count_text(std::size_t n, const char* what) { return std::to_string(n) + " " + what; }

double bbox_diagonal(const std::vector<double>& xyz) {
  if (xyz.empty()) return 0;
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = xyz[k];
  for (std::size_t i = 0; i < xyz.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], xyz[i + k]);
      hi[k] = std::max(hi[k], xyz[i + k]);
    }
  return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

// The source fields asked for, checked against the target.
std::vector<const Field*> chosen_fields(const FieldSource& src, const Mesh& target,
                                        const TransferParams& params) {
  std::vector<const Field*> out;
  if (params.names.empty()) {
    for (const Field& f : src.mesh.fields) out.push_back(&f);
  } else {
    for (const std::string& n : params.names) {
      const Field* f = src.mesh.find_field(n);
      if (!f) {
        std::string have;
        for (const Field& g : src.mesh.fields) have += (have.empty() ? "" : ", ") + g.name;
        throw FieldError(src.path + " has no field '" + n + "' (it has: " + (have.empty() ? "none" : have) +
                         ")");
      }
      out.push_back(f);
    }
  }
  if (out.empty()) throw FieldError(src.path + " holds no fields");
  for (const Field* f : out) {
    const std::size_t n = src.entity_count(*f);
    if (f->values.size() != f->step_count() * n * f->components)
      throw FieldError(src.path + ": field " + f->name + " has " + std::to_string(f->values.size()) +
                       " values, not steps x entities x components");
    if (const Field* g = target.find_field(f->name);
        g && !g->unit.empty() && !f->unit.empty() && g->unit != f->unit)
      throw FieldError("field " + f->name + " is in " + f->unit + " in " + src.path + " and in " + g->unit +
                       " on the target mesh: convert one, or import it under another name");
  }
  return out;
}

// A field over the target with the source field's name, unit, components and steps, all NaN.
Field empty_like(const Field& f, std::size_t entities) {
  Field g{f.name, f.location, f.components, f.unit, f.step_values, {}};
  g.values.assign(f.step_count() * entities * f.components, kNaN);
  return g;
}

// Copies entity `from` of `f` (all steps) to entity `to` of `g`.
void copy_entity(const Field& f, std::size_t from, std::size_t n_from, Field& g, std::size_t to,
                 std::size_t n_to) {
  const std::size_t c = f.components;
  for (std::size_t s = 0; s < f.step_count(); ++s)
    std::copy_n(f.values.data() + (s * n_from + from) * c, c, g.values.data() + (s * n_to + to) * c);
}

// The same tets in the same order, each as a set of nodes (a reader or a command may have
// re-oriented inverted tets of one of them).
bool same_tets(const Mesh& a, const Mesh& b) {
  if (a.tet.size() != b.tet.size()) return false;
  for (std::size_t t = 0; t < a.tet.size(); t += 4) {
    std::array<std::uint32_t, 4> p{a.tet[t], a.tet[t + 1], a.tet[t + 2], a.tet[t + 3]};
    std::array<std::uint32_t, 4> q{b.tet[t], b.tet[t + 1], b.tet[t + 2], b.tet[t + 3]};
    std::sort(p.begin(), p.end());
    std::sort(q.begin(), q.end());
    if (p != q) return false;
  }
  return true;
}

void check_coordinates(const FieldSource& src, const Mesh& target, const std::vector<std::uint32_t>& node_of,
                       const TransferParams& params) {
  if (src.mesh.xyz.empty()) return;  // a CSV keyed by id alone: nothing to compare
  const double tol = params.coordinate_tolerance * std::max(bbox_diagonal(target.xyz), 1e-300);
  for (std::size_t i = 0; i < node_of.size(); ++i) {
    const std::uint32_t t = node_of[i];
    if (t == kNone) continue;
    for (int k = 0; k < 3; ++k)
      if (!(std::abs(src.mesh.xyz[3 * i + k] - target.xyz[3 * std::size_t(t) + k]) <= tol))
        throw FieldError(src.path + ": node " + std::to_string(src.node_id.empty() ? i + 1 : src.node_id[i]) +
                         " is at another place than node " + std::to_string(t + 1) +
                         " of the target: a field over a different mesh (use --by location)");
  }
}

void transfer_by_id(const FieldSource& src, const Mesh& target, const std::vector<const Field*>& fields,
                    const TransferParams& params, TransferReport& rep) {
  const std::size_t nn = target.node_count(), nt = target.tet_count();
  // Source entity -> target entity, per location.
  std::vector<std::uint32_t> node_of, cell_of;
  auto by_ids = [&](const std::vector<std::uint64_t>& ids, std::size_t count, const char* what) {
    std::vector<std::uint32_t> map(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] == 0 || ids[i] > count)
        throw FieldError(src.path + ": " + what + " id " + std::to_string(ids[i]) +
                         " does not exist in the target (" + std::to_string(count) + " " + what +
                         "s, ids 1.." + std::to_string(count) + ")");
      map[i] = static_cast<std::uint32_t>(ids[i] - 1);
    }
    return map;
  };
  switch (src.key) {
    case SourceKey::position: {
      if (src.mesh.node_count() != nn || src.mesh.tet_count() != nt)
        throw FieldError(src.path + " has " + count_text(src.mesh.node_count(), "nodes") + " and " +
                         count_text(src.mesh.tet_count(), "tets") + ", the target " +
                         count_text(nn, "nodes") + " and " + count_text(nt, "tets") +
                         ": a field over a different mesh (use --by location)");
      node_of.resize(nn);
      std::iota(node_of.begin(), node_of.end(), 0u);
      check_coordinates(src, target, node_of, params);
      if (!same_tets(src.mesh, target))
        throw FieldError(
            src.path +
            " has the target's nodes but other tets: a field over a different mesh (use --by location)");
      cell_of = node_of;
      cell_of.resize(nt);
      std::iota(cell_of.begin(), cell_of.end(), 0u);
      break;
    }
    case SourceKey::node_id:
      node_of = by_ids(src.node_id, nn, "node");
      check_coordinates(src, target, node_of, params);
      break;
    case SourceKey::cell_id:
      cell_of = by_ids(src.cell_id, nt, "tet");
      break;
    case SourceKey::coordinates: {
      // Each source point to the target node at its coordinates, through a grid over the target.
      const double tol = params.coordinate_tolerance * std::max(bbox_diagonal(target.xyz), 1e-300);
      const PointGrid grid(target.xyz);
      node_of.resize(src.mesh.node_count());
      for (std::size_t i = 0; i < node_of.size(); ++i) {
        const double* p = &src.mesh.xyz[3 * i];
        const std::uint32_t t = grid.nearest(p, [](std::uint32_t) { return true; });
        double d = 0;
        for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(target.xyz[3 * std::size_t(t) + k] - p[k]));
        if (!(d <= tol))
          throw FieldError(
              src.path + ": row " + std::to_string(i + 1) + " (" + std::to_string(p[0]) + ", " +
              std::to_string(p[1]) + ", " + std::to_string(p[2]) +
              ") is at no node of the target: values over other points (use --by location with a mesh)");
        node_of[i] = t;
      }
      break;
    }
  }
  std::vector<char> node_hit(nn, 0), cell_hit(nt, 0);
  for (std::uint32_t t : node_of) {
    if (node_hit[t])
      throw FieldError(src.path + ": two source rows give target node " + std::to_string(t + 1));
    node_hit[t] = 1;
  }
  for (std::uint32_t t : cell_of) cell_hit[t] = 1;
  for (const Field* f : fields) {
    const bool node = f->location == FieldLocation::node;
    const std::vector<std::uint32_t>& map = node ? node_of : cell_of;
    if (map.empty() && src.entity_count(*f) > 0)
      throw FieldError(src.path + ": field " + f->name + " is over " + (node ? "nodes" : "cells") +
                       " and the file keys only " + (node ? "cells" : "nodes"));
    const std::size_t n_to = node ? nn : nt;
    Field g = empty_like(*f, n_to);
    for (std::size_t i = 0; i < map.size(); ++i) copy_entity(*f, i, map.size(), g, map[i], n_to);
    rep.fields.push_back(std::move(g));
  }
  rep.nodes_missing = nn - static_cast<std::size_t>(std::count(node_hit.begin(), node_hit.end(), 1));
  rep.cells_missing = nt - static_cast<std::size_t>(std::count(cell_hit.begin(), cell_hit.end(), 1));
  bool any_node = false, any_cell = false;
  for (const Field* f : fields) (f->location == FieldLocation::node ? any_node : any_cell) = true;
  if (!any_node) rep.nodes_missing = 0;
  if (!any_cell) rep.cells_missing = 0;
}

// Regions as sorted id lists per node (CSR): the regions of the tets around each node.
struct NodeRegions {
  std::vector<std::uint32_t> start;
  std::vector<std::int32_t> ids;
  std::span<const std::int32_t> of(std::size_t v) const {
    return {ids.data() + start[v], ids.data() + start[v + 1]};
  }
};
NodeRegions node_regions(const Mesh& m) {
  NodeRegions r;
  const std::size_t nn = m.node_count();
  std::vector<std::vector<std::int32_t>> lists(nn);
  for (std::size_t t = 0; t < m.tet_count(); ++t)
    for (int j = 0; j < 4; ++j) {
      auto& l = lists[m.tet[4 * t + j]];
      const std::int32_t id = m.region_of(t);
      if (std::find(l.begin(), l.end(), id) == l.end()) l.push_back(id);
    }
  r.start.resize(nn + 1, 0);
  for (std::size_t v = 0; v < nn; ++v)
    r.start[v + 1] = r.start[v] + static_cast<std::uint32_t>(lists[v].size());
  r.ids.reserve(r.start[nn]);
  for (auto& l : lists) r.ids.insert(r.ids.end(), l.begin(), l.end());
  return r;
}

bool contains(std::span<const std::int32_t> set, std::int32_t id) {
  return std::find(set.begin(), set.end(), id) != set.end();
}

void transfer_by_location(const FieldSource& src, const Mesh& target, const std::vector<const Field*>& fields,
                          const TransferParams& params, TransferReport& rep) {
  const Mesh& sm = src.mesh;
  if (src.key != SourceKey::position && src.key != SourceKey::node_id)
    throw FieldError(src.path + " has no mesh (a table keyed by " +
                     std::string(src.key == SourceKey::cell_id ? "cell ids" : "coordinates") +
                     "): match it with --by id");
  if (sm.tet_count() == 0)
    throw FieldError(src.path + " has no tets to locate points in: match it with --by id");
  for (const Field* f : fields)
    if (src.entity_count(*f) != (f->location == FieldLocation::node ? sm.node_count() : sm.tet_count()))
      throw FieldError(src.path + ": field " + f->name + " does not cover the file's mesh");
  const bool regions = !sm.tet_region.empty() && !target.tet_region.empty() && params.match_regions;
  if (regions) {
    for (std::size_t t = 0; t < target.tet_count(); ++t) {
      const std::int32_t id = target.tet_region[t];
      if (std::find(sm.tet_region.begin(), sm.tet_region.end(), id) == sm.tet_region.end())
        throw FieldError("the target has region " + std::to_string(id) + " and " + src.path +
                         " has none of that id: regions cannot be matched (ignore them with --no-regions)");
      // One check per distinct id is enough; skip the run of equal ids.
      while (t + 1 < target.tet_count() && target.tet_region[t + 1] == id) ++t;
    }
  }
  const TetGrid grid(sm);
  const std::size_t nn = target.node_count(), nt = target.tet_count();
  const unsigned threads = detail::thread_count(params.threads);
  bool any_node = false, any_cell = false;
  for (const Field* f : fields) (f->location == FieldLocation::node ? any_node : any_cell) = true;

  // Nodes: the tet and barycentric coordinates of each, or the nearest source node.
  std::vector<std::uint32_t> node_tet, node_near;
  std::vector<double> node_bary;
  if (any_node) {
    const NodeRegions allowed = regions ? node_regions(target) : NodeRegions{};
    const NodeRegions source_regions =
        regions && params.outside == Outside::nearest ? node_regions(sm) : NodeRegions{};
    node_tet.assign(nn, kNone);
    node_bary.assign(4 * nn, 0);
    detail::parallel_for(
        nn, threads,
        [&](std::size_t b, std::size_t e, unsigned) {
          for (std::size_t v = b; v < e; ++v) {
            // A node of no target tet has no region to keep to.
            auto ok = [&](std::uint32_t t) {
              return !regions || allowed.of(v).empty() || contains(allowed.of(v), sm.tet_region[t]);
            };
            node_tet[v] =
                grid.locate(&target.xyz[3 * v], params.barycentric_tolerance, ok, &node_bary[4 * v]);
          }
        },
        2048);
    rep.nodes_outside = static_cast<std::size_t>(std::count(node_tet.begin(), node_tet.end(), kNone));
    if (params.outside == Outside::nearest && rep.nodes_outside > 0) {
      const PointGrid pts(sm.xyz);
      node_near.assign(nn, kNone);
      for (std::size_t v = 0; v < nn; ++v) {
        if (node_tet[v] != kNone) continue;
        node_near[v] = pts.nearest(&target.xyz[3 * v], [&](std::uint32_t s) {
          if (!regions || allowed.of(v).empty()) return true;
          for (std::int32_t id : source_regions.of(s))
            if (contains(allowed.of(v), id)) return true;
          return false;
        });
      }
    }
  }
  // Cells: the source tet holding each target centroid, or the nearest source centroid.
  std::vector<std::uint32_t> cell_tet;
  if (any_cell) {
    std::vector<double> centroid(3 * nt);
    for (std::size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        double s = 0;
        for (int j = 0; j < 4; ++j) s += target.xyz[3 * std::size_t(target.tet[4 * t + j]) + k];
        centroid[3 * t + k] = s / 4;
      }
    cell_tet.assign(nt, kNone);
    detail::parallel_for(
        nt, threads,
        [&](std::size_t b, std::size_t e, unsigned) {
          double bary[4];
          for (std::size_t t = b; t < e; ++t) {
            auto ok = [&](std::uint32_t s) { return !regions || sm.tet_region[s] == target.tet_region[t]; };
            cell_tet[t] = grid.locate(&centroid[3 * t], params.barycentric_tolerance, ok, bary);
          }
        },
        2048);
    rep.cells_outside = static_cast<std::size_t>(std::count(cell_tet.begin(), cell_tet.end(), kNone));
    if (params.outside == Outside::nearest && rep.cells_outside > 0) {
      std::vector<double> source_centroid(3 * sm.tet_count());
      for (std::size_t t = 0; t < sm.tet_count(); ++t)
        for (int k = 0; k < 3; ++k) {
          double s = 0;
          for (int j = 0; j < 4; ++j) s += sm.xyz[3 * std::size_t(sm.tet[4 * t + j]) + k];
          source_centroid[3 * t + k] = s / 4;
        }
      const PointGrid pts(source_centroid);
      for (std::size_t t = 0; t < nt; ++t)
        if (cell_tet[t] == kNone)
          cell_tet[t] = pts.nearest(&centroid[3 * t], [&](std::uint32_t s) {
            return !regions || sm.tet_region[s] == target.tet_region[t];
          });
    }
  }
  for (const Field* f : fields) {
    const std::size_t c = f->components;
    if (f->location == FieldLocation::node) {
      Field g = empty_like(*f, nn);
      const std::size_t ns = sm.node_count();
      for (std::size_t s = 0; s < f->step_count(); ++s) {
        const double* in = f->values.data() + s * ns * c;
        double* out = g.values.data() + s * nn * c;
        detail::parallel_for(nn, threads, [&](std::size_t b, std::size_t e, unsigned) {
          for (std::size_t v = b; v < e; ++v) {
            const std::uint32_t t = node_tet[v];
            if (t != kNone) {
              const double* w = &node_bary[4 * v];
              for (std::size_t k = 0; k < c; ++k) {
                double sum = 0;
                for (int j = 0; j < 4; ++j)
                  sum += w[j] * in[std::size_t(sm.tet[4 * std::size_t(t) + j]) * c + k];
                out[v * c + k] = sum;
              }
            } else if (!node_near.empty() && node_near[v] != kNone) {
              std::copy_n(in + std::size_t(node_near[v]) * c, c, out + v * c);
            }
          }
        });
      }
      rep.fields.push_back(std::move(g));
    } else {
      Field g = empty_like(*f, nt);
      for (std::size_t t = 0; t < nt; ++t)
        if (cell_tet[t] != kNone) copy_entity(*f, cell_tet[t], sm.tet_count(), g, t, nt);
      rep.fields.push_back(std::move(g));
    }
  }
}

}  // namespace

TransferReport transfer_fields(const FieldSource& source, const Mesh& target, const TransferParams& params) {
  if (target.node_count() == 0) throw FieldError("the target mesh has no nodes");
  TransferReport rep;
  rep.target_nodes = target.node_count();
  rep.target_cells = target.tet_count();
  const std::vector<const Field*> fields = chosen_fields(source, target, params);
  if (params.by == MatchBy::id) {
    transfer_by_id(source, target, fields, params, rep);
  } else {
    transfer_by_location(source, target, fields, params, rep);
  }
  for (const Field& f : rep.fields)
    rep.nan_values += static_cast<std::size_t>(
        std::count_if(f.values.begin(), f.values.end(), [](double v) { return std::isnan(v); }));
  return rep;
}

PointLocation locate_points(const Mesh& mesh, const std::vector<double>& xyz, double barycentric_tolerance) {
  PointLocation r;
  const std::size_t n = xyz.size() / 3;
  r.tet.assign(n, kNone);
  r.bary.assign(4 * n, 0);
  if (mesh.tet_count() == 0) return r;
  const TetGrid grid(mesh);
  detail::parallel_for(
      n, 0,
      [&](std::size_t b, std::size_t e, unsigned) {
        for (std::size_t i = b; i < e; ++i)
          r.tet[i] = grid.locate(
              &xyz[3 * i], barycentric_tolerance, [](std::uint32_t) { return true; }, &r.bary[4 * i]);
      },
      2048);
  return r;
}

}  // namespace foxi
