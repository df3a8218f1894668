#include "layer_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "foxi/model/delaunay.hpp"
#include "facet_triangulation.hpp"
#include "plc_edit.hpp"
#include "refinement_round.hpp"

namespace foxi::detail {

namespace {

// Target edge length of a size field near p: the size at the nearest background node.
class SizeLookup {
 public:
  explicit SizeLookup(const SizeField* sf) : sf_(sf) {
    if (!sf_ || sf_->empty()) return;
    std::vector<std::uint32_t> all(sf_->size.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    grid_.emplace_back(sf_->xyz, all);
  }
  bool active() const { return !grid_.empty(); }
  double at(const Vec& p) const {
    const PointGrid& g = grid_.front();
    for (double r = g.cell;; r *= 2) {
      double best = std::numeric_limits<double>::infinity(), size = 0;
      g.for_each_in_box(p, r, [&](std::uint32_t v) {
        const double d = norm2(sub(detail::at(sf_->xyz, v), p));
        if (d < best) {
          best = d;
          size = sf_->size[v];
        }
      });
      if (best <= r * r || r > 1e6 * g.cell) return size;
    }
  }

 private:
  const SizeField* sf_;
  std::vector<PointGrid> grid_;  // empty or one
};

// "Is p inside the meshed domain": the tets bucketed by their boxes in the vertex grid's cells.
class TetLocator {
 public:
  TetLocator(const Mesh& mesh, const PointGrid& grid) : mesh_(mesh), grid_(grid) {
    const std::size_t cells = grid.dim[0] * grid.dim[1] * grid.dim[2];
    begin_.assign(cells + 1, 0);
    auto cover = [&](std::size_t t, auto&& visit) {
      const std::uint32_t* v = &mesh.tet[4 * t];
      Vec lo = at(mesh.xyz, v[0]), hi = lo;
      for (int i = 1; i < 4; ++i)
        for (std::size_t k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], mesh.xyz[3 * v[i] + k]);
          hi[k] = std::max(hi[k], mesh.xyz[3 * v[i] + k]);
        }
      const std::array<std::size_t, 3> a{grid.coord(lo[0], 0), grid.coord(lo[1], 1), grid.coord(lo[2], 2)};
      const std::array<std::size_t, 3> b{grid.coord(hi[0], 0), grid.coord(hi[1], 1), grid.coord(hi[2], 2)};
      if ((b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1) > 512) return false;
      for (std::size_t z = a[2]; z <= b[2]; ++z)
        for (std::size_t y = a[1]; y <= b[1]; ++y)
          for (std::size_t x = a[0]; x <= b[0]; ++x) visit(grid.index({x, y, z}));
      return true;
    };
    std::vector<char> big(mesh.tet_count(), 0);
    for (std::size_t t = 0; t < mesh.tet_count(); ++t)
      if (!cover(t, [&](std::size_t c) { ++begin_[c + 1]; })) {
        big[t] = 1;
        big_.push_back(static_cast<std::uint32_t>(t));
      }
    for (std::size_t i = 1; i < begin_.size(); ++i) begin_[i] += begin_[i - 1];
    items_.resize(begin_.back());
    std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
    for (std::size_t t = 0; t < mesh.tet_count(); ++t)
      if (!big[t]) cover(t, [&](std::size_t c) { items_[fill[c]++] = static_cast<std::uint32_t>(t); });
  }

  // Whether p lies inside (or on) some tet.
  bool inside(const Vec& p) const {
    for (std::uint32_t t : big_)
      if (in_tet(t, p)) return true;
    const std::size_t c = grid_.index({grid_.coord(p[0], 0), grid_.coord(p[1], 1), grid_.coord(p[2], 2)});
    for (std::uint32_t k = begin_[c]; k < begin_[c + 1]; ++k)
      if (in_tet(items_[k], p)) return true;
    return false;
  }

 private:
  bool in_tet(std::uint32_t t, const Vec& p) const {
    const std::uint32_t* v = &mesh_.tet[4 * std::size_t(t)];
    const Vec d = at(mesh_.xyz, v[3]);
    const Vec a = sub(at(mesh_.xyz, v[0]), d), b = sub(at(mesh_.xyz, v[1]), d),
              c = sub(at(mesh_.xyz, v[2]), d), q = sub(p, d);
    const double det = dot(a, cross(b, c));
    if (!(std::abs(det) > 0)) return false;
    const double l0 = dot(q, cross(b, c)) / det, l1 = dot(a, cross(q, c)) / det,
                 l2 = dot(a, cross(b, q)) / det;
    const double eps = -1e-12;
    return l0 >= eps && l1 >= eps && l2 >= eps && 1 - l0 - l1 - l2 >= eps;
  }
  const Mesh& mesh_;
  const PointGrid& grid_;
  std::vector<std::uint32_t> begin_, items_, big_;
};

// Whether any dihedral angle of the tet is below the bound whose cosine is cos_min.
bool dihedral_below(const Vec& a0, const Vec& b0, const Vec& c0, const Vec& d, double cos_min) {
  const Vec a = sub(a0, d), b = sub(b0, d), c = sub(c0, d);
  // Gradients of the barycentric coordinates (up to the common factor 1/det).
  const Vec g[4] = {cross(b, c), cross(c, a), cross(a, b),
                    scale(add(add(cross(b, c), cross(c, a)), cross(a, b)), -1.0)};
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (-dot(g[i], g[j]) > cos_min * std::sqrt(norm2(g[i]) * norm2(g[j]))) return true;
  return false;
}

bool all_in(const ThinLayer& l, const Vec (&x)[4]) {
  return l.contains(x[0].data()) && l.contains(x[1].data()) && l.contains(x[2].data()) &&
         l.contains(x[3].data());
}

}  // namespace

Mesh refine_with_thin_layers(const MeshParams& params, const ConformingParams& conforming,
                             const std::vector<ThinLayer>& layers, Plc& current, ConformingReport& rep,
                             const Mesh* first_mesh) {
  MeshParams p = params;
  p.optimize = false;
  p.radius_edge = 0;
  p.min_dihedral = 0;
  p.max_volume = 0;
  p.size_field = nullptr;
  std::map<std::int32_t, double> region_volume;  // the seeds' own bounds, applied here, not by TetGen
  for (RegionSeed& s : current.regions) {
    if (s.max_volume > 0) region_volume[s.id] = s.max_volume;
    s.max_volume = 0;
  }
  const SizeLookup sizes(params.size_field);
  const double q2 = params.radius_edge * params.radius_edge;
  // Near-flat tets outside the layers (dihedral angle under 1 degree; four almost cocircular
  // coplanar points, which symmetric refinement makes) are always split: one would make a solver's
  // matrix singular in all but name.
  const double min_dihedral = std::max(params.min_dihedral, conforming.split_dihedral_deg);
  const double cos_min = min_dihedral > 0 ? std::cos(min_dihedral * 3.14159265358979323846 / 180) : 2.0;
  rep.thin_layers = layers;
  Mesh mesh;
  if (first_mesh) mesh = *first_mesh;
  RefinementRounds rounds(p, rep);
  for (std::size_t it = 0;; ++it) {
    const std::optional<DelaunayCertificate> round = rounds.run(it, current, mesh, first_mesh != nullptr);
    if (!round) break;
    const DelaunayCertificate& cert = *round;

    // Tets over a bound.
    const std::size_t nt = mesh.tet_count();
    std::vector<char> in_layer(nt, 0);
    std::vector<std::pair<double, std::uint32_t>> bad;  // (circumradius^2, tet)
    rep.thin_layer_tets = 0;
    for (std::size_t t = 0; t < nt; ++t) {
      const std::uint32_t* v = &mesh.tet[4 * t];
      const Vec x[4] = {at(mesh.xyz, v[0]), at(mesh.xyz, v[1]), at(mesh.xyz, v[2]), at(mesh.xyz, v[3])};
      in_layer[t] = tet_in_thin_layer(mesh, t, layers);
      rep.thin_layer_tets += in_layer[t];
      const Ball b = tet_ball(x[0], x[1], x[2], x[3]);
      if (b.r2 < 0) continue;
      double shortest2 = std::numeric_limits<double>::infinity(), longest2 = 0;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const double e = norm2(sub(x[i], x[j]));
          shortest2 = std::min(shortest2, e);
          longest2 = std::max(longest2, e);
        }
      const double vol = std::abs(dot(sub(x[1], x[0]), cross(sub(x[2], x[0]), sub(x[3], x[0])))) / 6;
      double vmax = params.max_volume;
      if (const auto r = region_volume.find(mesh.region_of(t)); r != region_volume.end())
        vmax = vmax > 0 ? std::min(vmax, r->second) : r->second;
      bool over = vmax > 0 && vol > vmax;
      if (!over && sizes.active()) {
        // TetGen's metric test (circumradius against the size); in a layer the longest edge instead.
        const double h = sizes.at(scale(add(add(x[0], x[1]), add(x[2], x[3])), 0.25));
        over = h > 0 && (in_layer[t] ? longest2 : b.r2) > h * h;
      }
      if (!over && !in_layer[t])
        over = (q2 > 0 && b.r2 > q2 * shortest2) ||
               (cos_min <= 1 && dihedral_below(x[0], x[1], x[2], x[3], cos_min));
      if (over) bad.push_back({b.r2, static_cast<std::uint32_t>(t)});
    }
    rep.quality_unmet = 0;
    for (const auto& [r2, t] : bad) rep.quality_unmet += !in_layer[t];
    if ((cert.delaunay && bad.empty()) || it >= conforming.max_layer_iterations) break;
    if (params.progress &&
        !params.progress(first_mesh ? "conforming refinement" : "refinement around thin layers",
                         double(it + 1) / double(conforming.max_layer_iterations + 1)))
      throw MesherCancelled("meshing cancelled");

    const MeshSearch search(mesh);
    const TetLocator locator(mesh, search.vertices);
    const std::size_t nf = mesh.bface_count();
    // Faces across a layer (its side walls) are never split: a split there makes vertices a layer's
    // thickness apart, and more splits to keep them Delaunay, all along the layer.
    std::vector<char> side_wall(nf, 0);
    for (std::size_t f = 0; f < nf; ++f) {
      const std::uint32_t* fv = &mesh.bface[3 * f];
      const Vec a = at(mesh.xyz, fv[0]), b = at(mesh.xyz, fv[1]), c = at(mesh.xyz, fv[2]);
      const Vec n = cross(sub(b, a), sub(c, a));
      for (const ThinLayer& l : layers)
        if (l.contains(a.data()) && l.contains(b.data()) && l.contains(c.data()) &&
            std::abs(dot(n, Vec{l.normal[0], l.normal[1], l.normal[2]})) < (1 - 1e-6) * std::sqrt(norm2(n)))
          side_wall[f] = 1;
    }
    rounds.keep(current, mesh);
    if (first_mesh) current = surface_plc(mesh, current);
    EditablePlc edit(current);
    if (first_mesh) edit.index_surface();
    edit.layers = layers;
    NearPoints added(search.vertices.cell);
    std::size_t n_conform = 0;
    if (!cert.delaunay) {
      std::vector<char> split(nf, 0);
      mark_faces_for_violations(search, cert.violating_tets, split);
      for (std::size_t f = 0; f < nf; ++f) split[f] = split[f] && !side_wall[f];
      n_conform = split_faces(mesh, search.face_ball, split, edit, added);
    }
    // Largest first; a new point keeps half its tet's circumradius from the others of this round,
    // so that one round does not crowd points (and make new bad tets) where many tets are bad.
    std::sort(bad.begin(), bad.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<char> split(nf, 0);
    std::vector<Vec> interior;
    std::size_t n_layer = 0;
    for (const auto& [r2, t] : bad) {
      const std::uint32_t* v = &mesh.tet[4 * std::size_t(t)];
      const Vec x[4] = {at(mesh.xyz, v[0]), at(mesh.xyz, v[1]), at(mesh.xyz, v[2]), at(mesh.xyz, v[3])};
      if (in_layer[t]) {
        // Too big in a layer: a vertex on the layer's face under its centroid, mirrored to the other.
        const Vec g = scale(add(add(x[0], x[1]), add(x[2], x[3])), 0.25);
        for (const ThinLayer& l : layers) {
          if (!all_in(l, x)) continue;
          const Vec onto = onto_layer_plane(l, g, l.lo);
          double longest2 = 0;
          for (int i = 0; i < 4; ++i)
            for (int j = i + 1; j < 4; ++j) longest2 = std::max(longest2, norm2(sub(x[i], x[j])));
          if (added.near(onto, 0.25 * std::sqrt(longest2)) || !edit.insert_surface_point(onto)) break;
          added.add(onto);
          ++n_layer;
          n_layer += edit.mirror(onto, [&](const Vec& m) {
            if (added.near(m, 1e-9 * std::sqrt(longest2))) return true;
            added.add(m);
            return false;
          });
          break;
        }
        continue;
      }
      const Ball b = tet_ball(x[0], x[1], x[2], x[3]);
      bool encroaches = false;
      search.for_each_encroached(b.c, [&](std::uint32_t f) {
        encroaches = true;
        if (!side_wall[f]) split[f] = 1;
      });
      if (encroaches) continue;
      bool in_any_layer = false;
      for (const ThinLayer& l : layers) in_any_layer = in_any_layer || l.contains(b.c.data());
      if (in_any_layer || added.near(b.c, 0.5 * std::sqrt(r2)) || !locator.inside(b.c)) continue;
      added.add(b.c);
      interior.push_back(b.c);
    }
    const std::size_t n_faces = split_faces(mesh, search.face_ball, split, edit, added, 0.5);
    edit.write_back();
    if (first_mesh) triangulate_facets(current);
    for (const Vec& c : interior) current.points.insert(current.points.end(), c.begin(), c.end());
    const std::size_t n_quality = n_faces + n_layer + interior.size();
    if (n_conform + n_quality == 0) break;
    rep.added_points += n_conform;
    rep.quality_points += n_quality;
    rep.iterations = it + 1;
  }
  return mesh;
}

}  // namespace foxi::detail
