// The CGAL Mesh_3 path. Mesh_3 translation units are heavy (minutes of compile time, GBs of memory):
// all Mesh_3 code of foxi stays in this one file.
#include "foxi/mesher/cgal_mesher.hpp"
#include "foxi/mesher/size_field.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_polyhedron_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polyhedral_complex_mesh_domain_3.h>
#include <CGAL/make_mesh_3.h>

#include <algorithm>
#include <array>
#include <iterator>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <tuple>
#include <unordered_map>

#include "child_process.hpp"
#include "plc_edit.hpp"
#include "plc_surface.hpp"
#include "union_find.hpp"

namespace foxi {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Polyhedron = CGAL::Mesh_polyhedron_3<K>::type;
using ComplexDomain = CGAL::Polyhedral_complex_mesh_domain_3<K>;

// The domain, telling which input polyhedron a surface patch index comes from (feature detection
// renumbers the patches).
class Domain : public ComplexDomain {
 public:
  template <class... Args>
  explicit Domain(Args&&... args) : ComplexDomain(std::forward<Args>(args)...) {}
  std::size_t polyhedron_of_patch(Surface_patch_index patch) const {
    return patch_id_to_polyhedron_id.at(static_cast<std::size_t>(patch));
  }
};

using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

// The refinement boxes (CgalMeshParams::boxes) as size bounds: each box's target edge length as the
// circumradius of the regular tet of that edge, the conversion of the region sizes (TetGen takes the
// same edge length as its sizing function inside the box).
struct BoxSizes {
  struct Box {
    double lo[3], hi[3];
    double radius;
  };
  std::vector<Box> boxes;
  explicit BoxSizes(const std::vector<RefinementBox>& in) {
    for (const RefinementBox& b : in)
      boxes.push_back({{b.lo[0], b.lo[1], b.lo[2]},
                       {b.hi[0], b.hi[1], b.hi[2]},
                       regular_tet_circumradius(regular_tet_volume(b.size))});
  }
  // `bound` lowered to the radius of every box that holds p.
  double at(const K::Point_3& p, double bound) const {
    for (const Box& b : boxes)
      if (b.radius < bound && p.x() >= b.lo[0] && p.x() <= b.hi[0] && p.y() >= b.lo[1] && p.y() <= b.hi[1] &&
          p.z() >= b.lo[2] && p.z() <= b.hi[2])
        bound = b.radius;
    return bound;
  }
};

// A size bound: the global one, lowered in the refinement boxes. The cell, facet and edge sizes below
// are this with their own exceptions (subdomains, corners).
struct BoxedSize {
  using FT = K::FT;
  using Point_3 = K::Point_3;
  using Index = Domain::Index;
  double global = 0;
  BoxSizes boxes;
  double at(const Point_3& p) const { return boxes.at(p, global); }
};

// Cell size bound: lowered further in subdomains whose region seed sets a max volume (the boxes at the
// cell's orthocentre, where Mesh_3 asks).
struct CellSize : BoxedSize {
  const Domain* domain = nullptr;
  std::vector<double> per_subdomain;  // by subdomain index
  FT operator()(const Point_3& p, int dim, const Index& index) const {
    if (dim != 3) return at(p);
    const auto sd = static_cast<std::size_t>(domain->subdomain_index(index));
    return boxes.at(p, sd < per_subdomain.size() ? per_subdomain[sd] : global);
  }
};

// Surface Delaunay ball radius bound (the boxes at the ball's centre on the surface), so that a box's
// part of the boundary is as fine as the tets behind it.
struct FacetSize : BoxedSize {
  FT operator()(const Point_3& p, int, const Index&) const { return at(p); }
};

// The protecting ball radius at corners (dim 0) and along features. Mesh_3 caps a corner's ball at a
// third of the distance to the nearest other corner: on a faceted cylinder every wall facet is a
// narrow rectangle whose four corners then get equal balls, four co-planar weighted points on one
// orthocircle, and so a flat tet (dihedral angle 0) that no optimiser removes (exudation does not
// pump protecting balls). Here each corner's ball is below that cap by a factor in (0.7, 0.95] drawn
// from a hash of its coordinates: deterministic, and different at mirror-image corners. Inside a
// refinement box the bound is at most the box's (features there are sampled as finely as its facets).
struct EdgeSize : BoxedSize {
  std::map<std::array<double, 3>, double> corner_size;  // by the corner's coordinates
  FT operator()(const Point_3& p, int dim, const Index&) const {
    const auto it = dim == 0 ? corner_size.find({p.x(), p.y(), p.z()}) : corner_size.end();
    return it == corner_size.end() ? at(p) : it->second;
  }
};

double hash01(const std::array<double, 3>& p) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (double x : p) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &x, sizeof bits);
    h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 29;
  }
  return static_cast<double>(h >> 11) * 0x1p-53;
}

EdgeSize edge_size_field(const Domain& domain, double global, const BoxSizes& boxes) {
  std::vector<std::pair<Domain::Corner_index, K::Point_3>> corners;
  domain.get_corners(std::back_inserter(corners));
  EdgeSize e{{.global = global, .boxes = boxes}, {}};
  // The nearest other corner, by sorting along x and scanning while the x gap can still beat the best.
  std::vector<std::array<double, 3>> pts;
  for (const auto& c : corners) pts.push_back({c.second.x(), c.second.y(), c.second.z()});
  std::sort(pts.begin(), pts.end());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const K::Point_3 p(pts[i][0], pts[i][1], pts[i][2]);
    double best = HUGE_VAL;
    auto dx2 = [&](std::size_t j) { return (pts[j][0] - pts[i][0]) * (pts[j][0] - pts[i][0]); };
    auto d2 = [&](std::size_t j) {
      return CGAL::squared_distance(p, K::Point_3(pts[j][0], pts[j][1], pts[j][2]));
    };
    for (std::size_t j = i + 1; j < pts.size() && dx2(j) < best; ++j) best = std::min(best, d2(j));
    for (std::size_t j = i; j-- > 0 && dx2(j) < best;) best = std::min(best, d2(j));
    const double here = e.at(p);
    const double cap = std::min(here, std::isfinite(best) ? std::sqrt(best) / 3 : here);
    e.corner_size[pts[i]] = cap * (0.7 + 0.25 * (1 - hash01(pts[i])));
  }
  return e;
}

// The PLC surface grouped into the domain's input polyhedra: one per plane region (per_facet) or per
// facet marker, and pair of cells. A patch's borders are protected features (detect_borders /
// detect_features), so plane-region patches protect every facet edge where the surface bends, a marker
// or a material changes, or another facet meets.
struct Patches {
  std::vector<Polyhedron> polyhedra;
  std::vector<std::pair<int, int>> subdomains;  // (behind the normals, in front of them), Mesh_3's order
  std::vector<std::int32_t> marker;             // the facet marker of each polyhedron
  std::size_t facets_joined = 0;                // PLC facets that joined a coplanar neighbour's patch
};

// The plane regions: facets of one marker and pair of cells that share an edge (used by no third
// triangle) and lie in one plane (exact test) are joined. A structure built with corefinement booleans
// (the ball grid array) tiles every plane with sliver triangles, each a facet: protecting their edges
// would put tiny protecting balls all over the flat faces, and they are no feature of the geometry.
std::vector<std::uint32_t> plane_regions(const detail::PlcSurface& s, const Plc& plc) {
  detail::UnionFind groups(plc.facet_count());
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edge_tris;
  for (std::uint32_t t = 0; t < s.tri_facet.size(); ++t) {
    if (s.side_cell[2 * t] == s.side_cell[2 * t + 1]) continue;
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = s.tri[3 * t + i], b = s.tri[3 * t + (i + 1) % 3];
      edge_tris[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  }
  auto pt = [&](std::uint32_t v) {
    return K::Point_3(s.points[3 * v], s.points[3 * v + 1], s.points[3 * v + 2]);
  };
  auto cells = [&](std::uint32_t t) { return std::minmax(s.side_cell[2 * t], s.side_cell[2 * t + 1]); };
  for (const auto& [edge, tris] : edge_tris) {
    if (tris.size() != 2) continue;
    const std::uint32_t t = tris[0], u = tris[1], f = s.tri_facet[t], g = s.tri_facet[u];
    if (f == g || plc.facet_marker[f] != plc.facet_marker[g] || cells(t) != cells(u)) continue;
    std::uint32_t apex = s.tri[3 * u];
    for (int i = 0; i < 3; ++i)
      if (s.tri[3 * u + i] != edge.first && s.tri[3 * u + i] != edge.second) apex = s.tri[3 * u + i];
    if (CGAL::coplanar(pt(s.tri[3 * t]), pt(s.tri[3 * t + 1]), pt(s.tri[3 * t + 2]), pt(apex)))
      groups.unite(f, g);
  }
  std::vector<std::uint32_t> root(plc.facet_count());
  for (std::uint32_t f = 0; f < root.size(); ++f) root[f] = groups.find(f);
  return root;
}

Patches make_patches(const Plc& plc, const detail::PlcSurface& s, bool per_facet) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  // Triangles of one facet (or marker) with the same cells on their sides: facets of one patch are
  // oriented alike (their normals point into the same cell), so the group is a consistently oriented surface.
  const std::vector<std::uint32_t> region = per_facet ? plane_regions(s, plc) : std::vector<std::uint32_t>{};
  std::map<std::tuple<std::int32_t, std::uint32_t, std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>>
      groups;
  for (std::uint32_t t = 0; t < s.tri_facet.size(); ++t) {
    const std::uint32_t front = s.side_cell[2 * t], back = s.side_cell[2 * t + 1];
    if (front == back) continue;
    const std::int32_t marker = plc.facet_marker[s.tri_facet[t]];
    const std::uint32_t facet = per_facet ? region[s.tri_facet[t]] : 0;
    // Facets of a patch may face either way: orient every triangle from the lower cell index to the higher.
    if (front < back)
      groups[{marker, facet, front, back}].push_back(t | 0x80000000u);  // flipped
    else
      groups[{marker, facet, back, front}].push_back(t);
  }
  Patches out;
  for (const auto& [key, tris] : groups) {
    const auto [marker, facet, back, front] = key;
    const std::string which =
        per_facet ? "facet " + std::to_string(facet + 1) : "the facets of marker " + std::to_string(marker);
    std::vector<K::Point_3> pts;
    std::vector<std::vector<std::size_t>> polys;
    std::unordered_map<std::uint32_t, std::size_t> local;
    for (std::uint32_t tf : tris) {
      const std::uint32_t t = tf & 0x7fffffffu;
      std::vector<std::size_t> poly;
      for (int i = 0; i < 3; ++i) {
        const std::uint32_t v = s.tri[3 * t + ((tf & 0x80000000u) ? 2 - i : i)];
        const auto [it, fresh] = local.emplace(v, pts.size());
        if (fresh) pts.emplace_back(s.points[3 * v], s.points[3 * v + 1], s.points[3 * v + 2]);
        poly.push_back(it->second);
      }
      polys.push_back(std::move(poly));
    }
    if (!PMP::is_polygon_soup_a_polygon_mesh(polys)) {
      const auto before = polys;
      PMP::orient_polygon_soup(pts, polys);  // splits non-manifold vertices; must not flip a triangle
      if (polys.size() != before.size())
        throw MesherError(MesherFailure::bad_input, which + (per_facet ? " overlaps itself" : " overlap"));
      for (std::size_t i = 0; i < polys.size(); ++i) {
        const auto& a = before[i];
        const auto& b = polys[i];
        const bool same = (pts[a[0]] == pts[b[0]] && pts[a[1]] == pts[b[1]]) ||
                          (pts[a[0]] == pts[b[1]] && pts[a[1]] == pts[b[2]]) ||
                          (pts[a[0]] == pts[b[2]] && pts[a[1]] == pts[b[0]]);
        if (!same)
          throw MesherError(MesherFailure::bad_input,
                            which + (per_facet ? " meets itself" : " meet") + " in a non-manifold way");
      }
    }
    Polyhedron poly;
    PMP::polygon_soup_to_polygon_mesh(pts, polys, poly);
    out.polyhedra.push_back(std::move(poly));
    out.subdomains.emplace_back(static_cast<int>(back), static_cast<int>(front));
    out.marker.push_back(marker);
  }
  if (out.polyhedra.empty())
    throw MesherError(MesherFailure::bad_input,
                      "the PLC encloses no volume (no facet has different cells on its sides)");
  if (per_facet) {
    std::vector<char> used(plc.facet_count(), 0);
    for (std::uint32_t f : s.tri_facet) used[f] = 1;
    for (std::uint32_t f = 0; f < plc.facet_count(); ++f) out.facets_joined += used[f] && region[f] != f;
  }
  return out;
}

// The volume of every cell of the PLC by the divergence theorem over the triangles bounding it (each
// side of a triangle bounds the cell there; coordinates relative to the first point for accuracy).
std::vector<double> cell_volumes(const detail::PlcSurface& s) {
  std::vector<double> vol(s.cell_count, 0.0);
  if (s.points.empty()) return vol;
  const double o[3] = {s.points[0], s.points[1], s.points[2]};
  for (std::size_t t = 0; t < s.tri_facet.size(); ++t) {
    const std::uint32_t front = s.side_cell[2 * t], back = s.side_cell[2 * t + 1];
    if (front == back) continue;
    double p[3][3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) p[i][k] = s.points[3 * s.tri[3 * t + i] + k] - o[k];
    // The tet (origin, a, b, c): positive when the normal (right hand rule) points away from the origin.
    const double v = (p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
                      p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
                      p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0])) /
                     6;
    vol[back] += v;  // the normal points out of the cell behind it
    vol[front] -= v;
  }
  return vol;
}

// The meshed tets, crossing the pipe from the child process.
struct Result {
  std::vector<std::uint64_t> relabelled;  // one count: cells whose centroid's part is not Mesh_3's label
  std::vector<double> xyz, weight;
  std::vector<std::uint32_t> tet, bface;
  std::vector<std::int32_t> tet_region, bface_tag;
};

template <class T>
void put(std::vector<char>& out, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  const char* p = reinterpret_cast<const char*>(&n);
  out.insert(out.end(), p, p + sizeof n);
  p = reinterpret_cast<const char*>(v.data());
  out.insert(out.end(), p, p + sizeof(T) * v.size());
}

template <class T>
void get(const std::vector<char>& in, std::size_t& at, std::vector<T>& v) {
  std::uint64_t n = 0;
  if (in.size() - at < sizeof n)
    throw MesherError(MesherFailure::internal_error, "CGAL's result was cut short");
  std::memcpy(&n, in.data() + at, sizeof n);
  at += sizeof n;
  if (n > (in.size() - at) / sizeof(T))
    throw MesherError(MesherFailure::internal_error, "CGAL's result was cut short");
  v.resize(n);
  std::memcpy(v.data(), in.data() + at, sizeof(T) * n);
  at += sizeof(T) * n;
}

Result export_complex(const C3t3& c3t3, const Domain& domain, const Patches& patches,
                      const std::vector<std::int32_t>& cell_region) {
  Result r;
  std::unordered_map<Tr::Vertex_handle, std::uint32_t, CGAL::Handle_hash_function> index;
  auto node = [&](Tr::Vertex_handle v) {
    const auto [it, fresh] = index.emplace(v, static_cast<std::uint32_t>(r.weight.size()));
    if (fresh) {
      const auto& wp = v->point();
      r.xyz.insert(r.xyz.end(), {wp.x(), wp.y(), wp.z()});
      r.weight.push_back(wp.weight());
    }
    return it->second;
  };
  // Mesh_3 labels a cell by the subdomain its circumcentre (orthocentre) lies in. In a thin layer the
  // circumcentre of a flat cell can lie across an interface, in the next part (the power module's die
  // attach took 1.25% of the die's volume): the cells of the complex are labelled here by their
  // centroid, with the domain's own point location. Where the mesh's boundary facets lie on the PLC, a
  // cell lies inside one part and its centroid says which. Which cells are meshed stays Mesh_3's
  // choice: outside the complex lie flat cells on the boundary, whose centroid is on a facet.
  const auto locate = domain.is_in_domain_object();
  std::uint64_t relabelled = 0;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    const auto& p0 = c->vertex(0)->point();
    const auto& p1 = c->vertex(1)->point();
    const auto& p2 = c->vertex(2)->point();
    const auto& p3 = c->vertex(3)->point();
    const K::Point_3 centroid((p0.x() + p1.x() + p2.x() + p3.x()) / 4,
                              (p0.y() + p1.y() + p2.y() + p3.y()) / 4,
                              (p0.z() + p1.z() + p2.z() + p3.z()) / 4);
    const auto where = locate(centroid);
    auto sd = static_cast<std::size_t>(c3t3.subdomain_index(c));
    if (where && static_cast<std::size_t>(*where) != sd) {
      sd = static_cast<std::size_t>(*where);
      ++relabelled;
    }
    // CGAL's cells are positively oriented, as foxi's tets.
    for (int i = 0; i < 4; ++i) r.tet.push_back(node(c->vertex(i)));
    r.tet_region.push_back(sd < cell_region.size() ? cell_region[sd] : 0);
  }
  r.relabelled = {relabelled};
  for (auto f = c3t3.facets_in_complex_begin(); f != c3t3.facets_in_complex_end(); ++f) {
    std::uint32_t v[3];
    bool in_mesh = true;
    for (int k = 0; k < 3; ++k) {
      const auto it = index.find(f->first->vertex((f->second + 1 + k) % 4));
      in_mesh = in_mesh && it != index.end();
      v[k] = in_mesh ? it->second : 0;
    }
    if (!in_mesh) continue;
    r.bface.insert(r.bface.end(), v, v + 3);
    r.bface_tag.push_back(patches.marker.at(domain.polyhedron_of_patch(c3t3.surface_patch_index(*f))));
  }
  return r;
}

using Clock = std::chrono::steady_clock;

// Runs in the child process. `deadline` bounds the optimisers (the parent kills the child at it).
std::vector<char> run_mesh_3(const Patches& patches, const detail::PlcSurface& s, const Plc& plc,
                             const CgalMeshReport& sizes, const CgalMeshParams& params,
                             Clock::time_point deadline) {
  namespace P = CGAL::parameters;
  Domain domain(patches.polyhedra.begin(), patches.polyhedra.end(), patches.subdomains.begin(),
                patches.subdomains.end());
  if (params.resample) {
    // Patch borders (marker or material changes) and edges where the facets turn by more than
    // feature_angle. A faceted cylinder's wall is then one smooth patch whose rims are curves: their
    // protecting balls need not fall on the polygon's corners, so the cylinder is cut inside.
    domain.detect_features(params.feature_angle);
  } else {
    // Every patch is one plane region of the PLC's facets (plane_regions): its borders are the PLC's
    // facet edges, and nothing inside it is a feature.
    domain.detect_borders();
  }

  const BoxSizes boxes(params.boxes);
  CellSize cell_size{
      {.global = sizes.max_size, .boxes = boxes}, &domain, std::vector<double>(s.cell_count, sizes.max_size)};
  for (const RegionSeed& seed : plc.regions)
    if (seed.max_volume > 0)
      for (std::size_t c = 1; c < s.cell_count; ++c)
        if (s.cell_region[c] == seed.id)
          cell_size.per_subdomain[c] =
              std::min(cell_size.per_subdomain[c], regular_tet_circumradius(seed.max_volume));
  // Facets keep their vertices on one patch (or its bounding features): without it a coarse mesh of a thin
  // part takes facets that cut across its corners (the dual edge meets a patch, the facet does not lie in
  // it).
  const EdgeSize edge_size = edge_size_field(domain, sizes.edge_size, boxes);
  const FacetSize facet_size{{.global = sizes.facet_size, .boxes = boxes}};
  Criteria criteria(P::edge_size = edge_size, P::facet_angle = params.facet_angle, P::facet_size = facet_size,
                    P::facet_topology = CGAL::FACET_VERTICES_ON_SAME_SURFACE_PATCH_WITH_ADJACENCY_CHECK,
                    P::facet_distance = sizes.facet_distance, P::cell_radius_edge_ratio = params.radius_edge,
                    P::cell_size = cell_size);
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, P::no_perturb(), P::no_exude());
  // Each optimiser stops at its own limit or before the deadline with time left to export and send
  // the mesh, whichever is first (stopped, they leave a valid regular triangulation); with no time left
  // they are skipped.
  auto optimiser_limit = [&] {
    const double left = std::chrono::duration<double>(deadline - Clock::now()).count() -
                        std::max(2.0, 0.1 * params.time_limit);
    if (params.time_limit <= 0) return params.optimiser_seconds;
    return params.optimiser_seconds > 0 ? std::min(params.optimiser_seconds, left) : left;
  };
  if (params.perturb) {
    const double limit = optimiser_limit();
    if (params.time_limit <= 0 || limit > 0)
      CGAL::perturb_mesh_3(c3t3, domain, P::time_limit = limit, P::sliver_bound = params.sliver_bound);
  }
  if (params.exude) {
    const double limit = optimiser_limit();
    if (params.time_limit <= 0 || limit > 0)
      CGAL::exude_mesh_3(c3t3, P::time_limit = limit, P::sliver_bound = params.sliver_bound);
  }

  const Result r = export_complex(c3t3, domain, patches, s.cell_region);
  std::vector<char> out;
  put(out, r.relabelled);
  put(out, r.xyz);
  put(out, r.weight);
  put(out, r.tet);
  put(out, r.tet_region);
  put(out, r.bface);
  put(out, r.bface_tag);
  return out;
}

std::vector<std::int32_t> distinct(std::vector<std::int32_t> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

}  // namespace

Mesh mesh_plc_cgal(const Plc& input, const CgalMeshParams& params, CgalMeshReport* report) {
  const auto t0 = Clock::now();
  if (!(params.max_size >= 0 && params.facet_size >= 0 && params.edge_size >= 0 && params.radius_edge >= 0 &&
        params.facet_angle >= 0 && params.facet_angle <= 30 && params.optimiser_seconds >= 0 &&
        params.sliver_bound >= 0 && params.sliver_bound < 70 && params.facet_distance >= 0 &&
        params.feature_angle >= 0 && params.feature_angle <= 180 && params.time_limit >= 0 &&
        params.volume_tolerance > 0 && std::isfinite(params.max_size) && std::isfinite(params.facet_size) &&
        std::isfinite(params.edge_size) && std::isfinite(params.facet_distance) &&
        std::isfinite(params.radius_edge) && std::isfinite(params.optimiser_seconds) &&
        std::isfinite(params.time_limit)))
    throw MesherError(MesherFailure::bad_input,
                      "CGAL mesh parameters out of range (finite sizes >= 0, facet angle in [0, 30], sliver "
                      "bound in [0, 70), "
                      "feature angle in [0, 180] degrees, time limit >= 0, volume tolerance > 0)");
  for (std::size_t i = 0; i < params.boxes.size(); ++i) {
    const RefinementBox& b = params.boxes[i];
    bool ok = b.size > 0 && std::isfinite(b.size);
    for (int k = 0; k < 3; ++k)
      ok = ok && std::isfinite(b.lo[k]) && std::isfinite(b.hi[k]) && b.lo[k] <= b.hi[k];
    if (!ok)
      throw MesherError(MesherFailure::bad_input, "refinement box " + std::to_string(i + 1) +
                                                      " needs finite corners with lo <= hi and a size > 0");
  }
  CgalMeshReport rep;
  rep.resampled = params.resample;
  // Coordinates that differ by rounding alone made equal, points that coincide to rounding made one (a
  // corefined structure has corners 1 ulp apart): every protected facet edge between two such points
  // would ask Mesh_3 for protecting balls 1e-19 wide. Facet numbers stay those of the input.
  Plc plc = input;
  rep.coordinates_snapped = detail::snap_coordinates(plc);
  rep.points_welded = detail::weld_coincident_points(plc);
  const detail::PlcSurface s = detail::plc_surface(plc);
  const Patches patches = make_patches(plc, s, !params.resample);

  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], s.points[i]);
    hi[i % 3] = std::max(hi[i % 3], s.points[i]);
  }
  const double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  rep.max_size = params.max_size > 0 ? params.max_size : diag / 20;
  rep.facet_size = params.facet_size > 0 ? params.facet_size : rep.max_size;
  rep.edge_size = params.edge_size > 0 ? params.edge_size : rep.facet_size;
  rep.facet_distance = params.facet_distance > 0 ? params.facet_distance : rep.facet_size / 20;
  rep.boxes = params.boxes.size();
  rep.input_points = plc.point_count();
  rep.facet_triangles = s.tri_facet.size();
  rep.patches = patches.polyhedra.size();
  rep.facets_joined = patches.facets_joined;
  rep.facets_without_area = s.facets_without_area;
  rep.cells = s.cell_count - 1;

  // The time limit: the parent asks `progress` every 100 ms while the child runs; past the deadline
  // it says stop (the child is killed) and the cancellation is reported as the time limit.
  const auto deadline =
      t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(params.time_limit));
  bool timed_out = false;
  const ProgressFn progress = [&](std::string_view stage, double fraction) {
    if (params.time_limit > 0 && Clock::now() >= deadline) {
      timed_out = true;
      return false;
    }
    return !params.progress || params.progress(stage, fraction);
  };
  std::vector<char> bytes;
  try {
    bytes = detail::run_in_child(
        [&] {
          try {
            return run_mesh_3(patches, s, plc, rep, params, deadline);
          } catch (const MesherError&) {
            throw;
          } catch (const std::exception& e) {
            throw MesherError(MesherFailure::internal_error, std::string("CGAL Mesh_3 failed: ") + e.what());
          }
        },
        progress, "meshing (CGAL)", "CGAL Mesh_3");
  } catch (...) {
    if (!timed_out) throw;
    char limit[64];
    std::snprintf(limit, sizeof limit, "%g", params.time_limit);
    throw MesherError(
        MesherFailure::time_limit,
        std::string("CGAL Mesh_3 did not finish within the time limit of ") + limit +
            " s and was stopped. Mesh_3 has no bound of its own on its work: a part much thinner than it is "
            "wide "
            "(a die attach or solder layer) is sampled at its thickness all over, millions of tets at "
            "radius-edge 2. "
            "Raise the time limit, or mesh with TetGen (the default mesher), which grades thin layers");
  }
  Result r;
  std::size_t at = 0;
  get(bytes, at, r.relabelled);
  get(bytes, at, r.xyz);
  get(bytes, at, r.weight);
  get(bytes, at, r.tet);
  get(bytes, at, r.tet_region);
  get(bytes, at, r.bface);
  get(bytes, at, r.bface_tag);
  const std::size_t nn = r.weight.size();
  if (r.relabelled.size() != 1 || r.xyz.size() != 3 * nn || r.tet.size() != 4 * r.tet_region.size() ||
      r.bface.size() != 3 * r.bface_tag.size())
    throw MesherError(MesherFailure::internal_error, "CGAL's result is inconsistent");
  for (std::uint32_t v : r.tet)
    if (v >= nn) throw MesherError(MesherFailure::internal_error, "CGAL returned a tet index out of range");
  if (r.tet.empty())
    throw MesherError(MesherFailure::internal_error,
                      "CGAL Mesh_3 returned no tets (sizes too large for the PLC?)");

  Mesh m;
  m.xyz = std::move(r.xyz);
  m.weight = std::move(r.weight);
  m.tet = std::move(r.tet);
  m.tet_region = std::move(r.tet_region);
  m.bface = std::move(r.bface);
  m.bface_tag = std::move(r.bface_tag);
  for (std::int32_t id : distinct(m.tet_region)) m.regions.push_back(Region{id, {}, kNone});
  for (std::int32_t tag : distinct(m.bface_tag)) m.boundaries.push_back(Boundary{tag, {}});

  // Each region's volume: the PLC's cells (divergence theorem) against the mesh's tets.
  std::map<std::int32_t, CgalRegionVolume> volumes;
  const std::vector<double> cell_volume = cell_volumes(s);
  for (std::size_t c = 1; c < s.cell_count; ++c) {
    CgalRegionVolume& v = volumes[s.cell_region[c]];
    v.region = s.cell_region[c];
    v.plc += cell_volume[c];
  }
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const double* p[4];
    for (int i = 0; i < 4; ++i) p[i] = &m.xyz[3 * m.tet[4 * t + i]];
    const double a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double c[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
    CgalRegionVolume& v = volumes[m.tet_region[t]];
    v.region = m.tet_region[t];
    v.mesh += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
               a[2] * (b[0] * c[1] - b[1] * c[0])) /
              6;
  }
  rep.volumes_match = true;
  for (const auto& [id, v] : volumes) {
    rep.volumes.push_back(v);
    const double change = std::abs(v.relative_change());
    rep.worst_volume_change = std::max(rep.worst_volume_change, change);
    if (!(change <= params.volume_tolerance)) rep.volumes_match = false;
  }
  // Each facet marker's area: the PLC's triangles between two different cells against the mesh's
  // boundary triangles. A surface Mesh_3 did not recover (an interface inside a thin stack) is missing.
  std::map<std::int32_t, std::pair<double, double>> areas;  // marker -> (PLC, mesh)
  auto tri_area = [](const double* a, const double* b, const double* c) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]},
                 w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  };
  for (std::size_t t = 0; t < s.tri_facet.size(); ++t)
    if (s.side_cell[2 * t] != s.side_cell[2 * t + 1])
      areas[plc.facet_marker[s.tri_facet[t]]].first += tri_area(
          &s.points[3 * s.tri[3 * t]], &s.points[3 * s.tri[3 * t + 1]], &s.points[3 * s.tri[3 * t + 2]]);
  for (std::size_t f = 0; f < m.bface_count(); ++f)
    areas[m.bface_tag[f]].second +=
        tri_area(&m.xyz[3 * m.bface[3 * f]], &m.xyz[3 * m.bface[3 * f + 1]], &m.xyz[3 * m.bface[3 * f + 2]]);
  rep.areas_match = true;
  for (const auto& [marker, a] : areas) {
    const double change = a.first > 0 ? std::abs(a.second / a.first - 1) : (a.second > 0 ? 1.0 : 0.0);
    if (!(change <= params.volume_tolerance) && (rep.areas_match || change > rep.worst_area_change))
      rep.worst_area_marker = marker;
    if (!(change <= params.volume_tolerance)) rep.areas_match = false;
    rep.worst_area_change = std::max(rep.worst_area_change, change);
  }
  rep.tets_relabelled = static_cast<std::size_t>(r.relabelled[0]);
  rep.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (report) *report = rep;
  return m;
}

}  // namespace foxi
