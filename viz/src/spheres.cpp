#include "foxi/viz/spheres.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <thread>
#include <utility>

#include "exact.hpp"
#include "order_geometry.hpp"
#include "huge_page_allocator.hpp"
#include "foxi/model/adjacency.hpp"
#include "foxi/model/assert.hpp"
#include "foxi/model/parallel.hpp"

namespace foxi {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// A centre computed in double whose estimated relative error exceeds this is recomputed exactly.
constexpr double kRecomputeAbove = 0x1p-40;

struct UnionFind {
  std::vector<std::uint32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// The fixed-point keys of the non-wide items (see spheres.hpp): units of 2^-31 of the largest
// |c| component and |s|, rounded up to powers of two so that scaling is exact. A rounded value is
// off by at most half a unit (a whole one where the int32 range clamps it); the key s - 2 c.p (or
// c.d) evaluated from them in double is then off by at most that times (1, 2 |p|_1) plus its own
// rounding (a few ulps of the largest terms). The window of near ties grows with this bound, so
// it is kept tight.
void make_key_blocks(SphereTable& t, const double half[3]);

void make_fixed_keys(SphereTable& t, const double half[3]) {
  const std::size_t m = t.all_rep.size();
  double cmax_part[2] = {0, 0}, smax_part[2] = {0, 0};
  detail::parallel_for_balanced(m, [&](std::size_t begin, std::size_t end, int part) {
    double cm = cmax_part[part], sm = smax_part[part];
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t rep = t.all_rep[i];
      const double* c = t.c.data() + 3 * std::size_t(rep);
      cm = std::max({cm, std::abs(c[0]), std::abs(c[1]), std::abs(c[2])});
      sm = std::max(sm, std::abs(t.s[rep]));
    }
    cmax_part[part] = cm;
    smax_part[part] = sm;
  });
  const double cmax = std::max(cmax_part[0], cmax_part[1]), smax = std::max(smax_part[0], smax_part[1]);
  if (!std::isfinite(cmax) || !std::isfinite(smax)) return;  // no fixed keys: the double path
  // Units such that |x| / unit < 2^31 for every value (|x| < 2^e).
  const double c_unit = std::ldexp(1.0, (cmax > 0 ? std::ilogb(cmax) + 1 : -1000) - 31);
  const double s_unit = std::ldexp(1.0, (smax > 0 ? std::ilogb(smax) + 1 : -1000) - 31);
  // Rounded half away from zero (x / unit is exact, and so is adding a half below 2^52), by a
  // truncating conversion.
  std::atomic<bool> clamped{false}, not_finite{false};
  auto fix = [&clamped, &not_finite](double x, double unit) {
    if (!std::isfinite(x)) not_finite = true;
    const double y = x / unit + (x < 0 ? -0.5 : 0.5);
    if (!(std::abs(y) < 2147483647.0)) {
      clamped = true;
      return static_cast<std::int32_t>(x < 0 ? -0x7FFFFFFF : 0x7FFFFFFF);
    }
    return static_cast<std::int32_t>(y);
  };
  t.fixed_keys.reserve(m);
  advise_huge_pages(t.fixed_keys.data(), m * sizeof(SphereTable::FixedKey));
  t.fixed_keys.resize(m);
  detail::parallel_for_balanced(m, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t rep = t.all_rep[i];
      const double* c = t.c.data() + 3 * std::size_t(rep);
      SphereTable::FixedKey& k = t.fixed_keys[i];
      for (int j = 0; j < 3; ++j) k.c[j] = fix(c[j], c_unit);
      k.s = fix(t.s[rep], s_unit);
    }
  });
  if (not_finite) {  // (a broken table) no fixed keys: the double path, which clamps it
    t.fixed_keys.clear();
    return;
  }
  const double off = clamped ? 1.0 : 0.5;  // the rounding, in units
  t.c_unit = c_unit;
  t.s_unit = s_unit;
  t.fixed_a = off * s_unit + 8 * kEps * smax;
  t.fixed_b = 2 * off * c_unit + 32 * kEps * cmax;
  make_key_blocks(t, half);
}

// SphereTable::key_order and key_blocks: a counting sort of the fixed keys by the Morton code of
// their centre's cell in a grid of about 16 items a cell over the bounding box (half sizes `half`,
// local frame) widened by a quarter; centres beyond it (slivers' spheres) go to its border cells.
// Both cores: each codes, counts and bounds (per cell: box of c, range of s) its half of the items,
// then places them in its own slots of every cell. A block's bounds are those of the cells it
// meets (consecutive in Morton order): a little wider than its own keys', found without reading
// them again at scattered places.
void make_key_blocks(SphereTable& t, const double half[3]) {
  using KeyBlock = SphereTable::KeyBlock;
  const std::size_t m = t.fixed_keys.size();
  int bits = 1;  // per axis
  while (bits < 7 && (std::size_t(1) << (3 * (bits + 1))) * 16 <= m) ++bits;
  const std::uint32_t side = 1u << bits;
  const std::size_t cells = std::size_t(1) << (3 * bits);
  double scale[3], offset[3];  // cell coordinate = c * scale + offset
  for (int k = 0; k < 3; ++k) {
    const double h = 1.25 * half[k] / t.c_unit;
    scale[k] = h > 0 ? double(side) / (2 * h) : 0.0;
    offset[k] = h > 0 ? double(side) / 2 : 0.0;
  }
  std::array<std::uint32_t, 128> spread{};  // bit b of x to bit 3b
  for (std::uint32_t x = 0; x < 128; ++x)
    for (int b = 0; b < 7; ++b) spread[x] |= ((x >> b) & 1u) << (3 * b);
  constexpr std::int32_t kMax = std::numeric_limits<std::int32_t>::max(),
                         kMin = std::numeric_limits<std::int32_t>::min();
  const KeyBlock empty = {{kMax, kMax, kMax}, {kMin, kMin, kMin}, kMax, kMin};
  auto merge = [](KeyBlock& into, const KeyBlock& b) {
    for (int c = 0; c < 3; ++c) {
      into.c_lo[c] = std::min(into.c_lo[c], b.c_lo[c]);
      into.c_hi[c] = std::max(into.c_hi[c], b.c_hi[c]);
    }
    into.s_lo = std::min(into.s_lo, b.s_lo);
    into.s_hi = std::max(into.s_hi, b.s_hi);
  };
  std::vector<std::uint32_t> codes(m);
  std::vector<std::uint32_t> slots[2] = {std::vector<std::uint32_t>(cells, 0),
                                         std::vector<std::uint32_t>(cells, 0)};
  std::vector<KeyBlock> cell_box[2] = {std::vector<KeyBlock>(cells, empty),
                                       std::vector<KeyBlock>(m < 20000 ? 0 : cells, empty)};
  detail::parallel_for(m, 2, [&](std::size_t begin, std::size_t end, int part) {
    std::uint32_t* count = slots[part].data();
    KeyBlock* box = cell_box[part].data();
    for (std::size_t i = begin; i < end; ++i) {
      const SphereTable::FixedKey& key = t.fixed_keys[i];
      std::uint32_t code = 0;
      for (int k = 0; k < 3; ++k) {
        const double x = std::min(std::max(double(key.c[k]) * scale[k] + offset[k], 0.0), double(side - 1));
        code |= spread[static_cast<std::uint32_t>(x)] << k;
      }
      codes[i] = code;
      ++count[code];
      merge(box[code], {{key.c[0], key.c[1], key.c[2]}, {key.c[0], key.c[1], key.c[2]}, key.s, key.s});
    }
  });
  if (!cell_box[1].empty())
    for (std::size_t c = 0; c < cells; ++c) merge(cell_box[0][c], cell_box[1][c]);
  std::uint32_t acc = 0;
  for (std::size_t c = 0; c < cells; ++c)
    for (auto& part : slots) acc += std::exchange(part[c], acc);
  t.key_order.resize(m);
  detail::parallel_for(m, 2, [&](std::size_t begin, std::size_t end, int part) {
    std::uint32_t* next = slots[part].data();
    for (std::size_t i = begin; i < end; ++i) t.key_order[next[codes[i]]++] = static_cast<std::uint32_t>(i);
  });
  const std::size_t block = SphereTable::kKeyBlock, blocks = (m + block - 1) / block;
  t.key_blocks.resize(blocks);
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::uint32_t first = codes[t.key_order[b * block]],
                        last = codes[t.key_order[std::min(m, (b + 1) * block) - 1]];
    KeyBlock box = empty;
    for (std::uint32_t c = first; c <= last; ++c) merge(box, cell_box[0][c]);
    t.key_blocks[b] = box;
  }
}

// A cluster the mesh covers only in part: a cospherical cell (whose tets all share one sphere and
// fill a convex polytope when the whole cell is meshed) cut by the mesh's boundary, say a Kuhn cube
// with a tet missing. Its faces then no longer order its tets: two tets that share no face may face
// each other across the missing part (fuzz finding undraw_kuhn_cube_missing_tet). In a Delaunay mesh
// only a boundary face of the mesh can cut a cell (a face between two cells lies on both cells'
// hulls), so a cluster without one is convex and left as it is; one with a boundary face beyond
// which a vertex of the cluster lies gets, for each pair of its tets that share no face, a plane
// through three of their vertices with one tet on each side, listed with the cluster's faces (the
// eye's side of it orders the pair as a shared face would; an eye on it sees no ray through both).
// Clusters of more than 64 tets are left as they are (a limitation: their faces alone order them).
// Pairs of tets with a face on the mesh's boundary whose sphere centres agree within their error
// bounds (compute_spheres: candidates for pieces of one cut cell). The usual ones (bounds at most
// 256 x the median) are sorted by x and cut where consecutive centres are further apart than twice
// the largest bound, each part again by y and by z where it is large, and the pairs of each final
// part compared (a grid's parts are the tets of one cube); the few with wider bounds are compared
// with the others whose x is close enough.
std::vector<std::pair<std::uint32_t, std::uint32_t>> sphere_candidates(
    const SphereTable& t, const std::vector<std::uint32_t>& neighbour) {
  const std::size_t n = t.flat.size();
  std::vector<std::uint32_t> cut;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t* nb = neighbour.data() + 4 * i;
    if (!t.flat[i] && (nb[0] == kNone || nb[1] == kNone || nb[2] == kNone || nb[3] == kNone))
      cut.push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  if (cut.size() < 2) return pairs;
  std::vector<float> bounds;
  for (std::uint32_t i : cut) bounds.push_back(t.key_b[i]);
  std::nth_element(bounds.begin(), bounds.begin() + std::ptrdiff_t(bounds.size() / 2), bounds.end());
  const double cap = 256.0 * std::max(double(bounds[bounds.size() / 2]), 1e-300);
  double widest = 0;
  std::vector<std::uint32_t> usual, wide;
  for (std::uint32_t i : cut) {
    if (double(t.key_b[i]) > cap) {
      wide.push_back(i);
    } else {
      usual.push_back(i);
      widest = std::max(widest, double(t.key_b[i]));
    }
  }
  auto coord = [&](std::uint32_t i, int a) { return t.c[3 * std::size_t(i) + std::size_t(a)]; };
  auto close = [&](std::uint32_t i, std::uint32_t u) {
    return std::max({std::abs(coord(i, 0) - coord(u, 0)), std::abs(coord(i, 1) - coord(u, 1)),
                     std::abs(coord(i, 2) - coord(u, 2))}) <= double(t.key_b[i]) + double(t.key_b[u]);
  };
  const double gap = 2 * widest;
  // Sorts [b, e) of `usual` by axis a and splits it where neighbours are more than `gap` apart.
  auto split = [&](std::size_t b, std::size_t e, int a, auto&& self) -> void {
    std::sort(usual.begin() + std::ptrdiff_t(b), usual.begin() + std::ptrdiff_t(e),
              [&](std::uint32_t x, std::uint32_t y) { return coord(x, a) < coord(y, a); });
    for (std::size_t p = b; p < e;) {
      std::size_t q = p + 1;
      while (q < e && coord(usual[q], a) - coord(usual[q - 1], a) <= gap) ++q;
      if (q - p > 8 && a < 2) {
        self(p, q, a + 1, self);
      } else {
        for (std::size_t x = p; x < q; ++x)
          for (std::size_t y = x + 1; y < q; ++y)
            if (close(usual[x], usual[y])) pairs.emplace_back(usual[x], usual[y]);
      }
      p = q;
    }
  };
  split(0, usual.size(), 0, split);
  // The wide ones: against the usual ones (sorted by x again) within their reach, and each other.
  if (!wide.empty()) {
    std::sort(usual.begin(), usual.end(),
              [&](std::uint32_t x, std::uint32_t y) { return coord(x, 0) < coord(y, 0); });
    for (std::size_t k = 0; k < wide.size(); ++k) {
      const std::uint32_t i = wide[k];
      const double reach = double(t.key_b[i]) + widest;
      auto at = std::lower_bound(usual.begin(), usual.end(), coord(i, 0) - reach,
                                 [&](std::uint32_t x, double v) { return coord(x, 0) < v; });
      for (; at != usual.end() && coord(*at, 0) <= coord(i, 0) + reach; ++at)
        if (close(i, *at)) pairs.emplace_back(i, *at);
      for (std::size_t m = k + 1; m < wide.size(); ++m)
        if (close(i, wide[m])) pairs.emplace_back(i, wide[m]);
    }
  }
  return pairs;
}

bool shares_face(const std::vector<std::uint32_t>& neighbour, std::uint32_t x, std::uint32_t y) {
  for (int f = 0; f < 4; ++f)
    if (neighbour[4 * std::size_t(x) + f] != kNone && neighbour[4 * std::size_t(x) + f] >> 2 == y)
      return true;
  return false;
}

void add_separating_planes(SphereTable& t, const double* X, const std::uint32_t* T,
                           const std::vector<std::uint32_t>& neighbour, std::uint32_t clusters) {
  using order_detail::fast_orientation;
  auto P = [X](std::uint32_t v) { return X + 3 * std::size_t(v); };
  struct Extra {
    std::uint32_t cluster, a, b, v[3];
  };
  std::vector<Extra> extra;
  std::vector<std::uint32_t> verts;
  for (std::uint32_t k = 0; k < clusters; ++k) {
    const std::uint32_t cb = t.cluster_begin[k], ce = t.cluster_begin[k + 1];
    if (ce - cb > 64) continue;
    bool cut = false;
    for (std::uint32_t i = cb; i < ce && !cut; ++i)
      for (int f = 0; f < 4; ++f) cut = cut || neighbour[4 * std::size_t(t.cluster_tets[i]) + f] == kNone;
    if (!cut) continue;
    verts.clear();
    for (std::uint32_t i = cb; i < ce; ++i)
      for (int c = 0; c < 4; ++c) verts.push_back(T[4 * std::size_t(t.cluster_tets[i]) + c]);
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    bool convex = true;
    for (std::uint32_t i = cb; i < ce && convex; ++i) {
      const std::uint32_t* v = T + 4 * std::size_t(t.cluster_tets[i]);
      for (int f = 0; f < 4 && convex; ++f) {
        if (neighbour[4 * std::size_t(t.cluster_tets[i]) + f] != kNone) continue;
        const std::uint32_t a = v[order_detail::kFace[f][0]], b = v[order_detail::kFace[f][1]],
                            c = v[order_detail::kFace[f][2]];
        for (std::uint32_t w : verts)  // the tet's own vertex f is on the negative side: inside
          if (w != a && w != b && w != c && fast_orientation(P(a), P(b), P(c), P(w)) > 0) {
            convex = false;
            break;
          }
      }
    }
    if (convex) continue;
    for (std::uint32_t i = cb; i < ce; ++i)
      for (std::uint32_t j = i + 1; j < ce; ++j) {
        const std::uint32_t x = t.cluster_tets[i], y = t.cluster_tets[j];
        if (shares_face(neighbour, x, y)) continue;
        std::uint32_t u[8];
        int nu = 0;
        for (int c = 0; c < 4; ++c) u[nu++] = T[4 * std::size_t(x) + c];
        for (int c = 0; c < 4; ++c)
          if (std::find(u, u + nu, T[4 * std::size_t(y) + c]) == u + nu) u[nu++] = T[4 * std::size_t(y) + c];
        // Signs of x's and y's vertices for each plane through three of the vertices: x on one
        // side (or on it), y on the other (or on it), each with a vertex off the plane.
        bool found = false;
        for (int p = 0; p < nu && !found; ++p)
          for (int q = p + 1; q < nu && !found; ++q)
            for (int r = q + 1; r < nu && !found; ++r) {
              int lo_x = 1, hi_x = -1, lo_y = 1, hi_y = -1;
              for (int c = 0; c < 4; ++c) {
                const std::uint32_t wx = T[4 * std::size_t(x) + c], wy = T[4 * std::size_t(y) + c];
                const int sx = (wx == u[p] || wx == u[q] || wx == u[r])
                                   ? 0
                                   : fast_orientation(P(u[p]), P(u[q]), P(u[r]), P(wx));
                const int sy = (wy == u[p] || wy == u[q] || wy == u[r])
                                   ? 0
                                   : fast_orientation(P(u[p]), P(u[q]), P(u[r]), P(wy));
                lo_x = std::min(lo_x, sx), hi_x = std::max(hi_x, sx);
                lo_y = std::min(lo_y, sy), hi_y = std::max(hi_y, sy);
              }
              if (lo_x >= 0 && hi_x > 0 && hi_y <= 0 && lo_y < 0) {
                extra.push_back({k, x, y, {u[p], u[q], u[r]}});
                found = true;
              } else if (hi_x <= 0 && lo_x < 0 && lo_y >= 0 && hi_y > 0) {
                extra.push_back({k, y, x, {u[p], u[q], u[r]}});
                found = true;
              }
            }
      }
  }
  if (extra.empty()) return;
  // The cluster faces again, each cluster's separating planes after its shared faces.
  std::vector<std::uint32_t> begin(clusters + 1, 0), face_tet, face_vertex;
  for (std::uint32_t k = 0; k < clusters; ++k)
    begin[k + 1] = t.cluster_face_begin[k + 1] - t.cluster_face_begin[k];
  for (const Extra& e : extra) ++begin[e.cluster + 1];
  for (std::uint32_t k = 0; k < clusters; ++k) begin[k + 1] += begin[k];
  face_tet.reserve(2 * std::size_t(begin[clusters]));
  face_vertex.reserve(3 * std::size_t(begin[clusters]));
  std::size_t e = 0;
  for (std::uint32_t k = 0; k < clusters; ++k) {
    for (std::uint32_t f = t.cluster_face_begin[k]; f < t.cluster_face_begin[k + 1]; ++f) {
      face_tet.insert(face_tet.end(), {t.face_tet[2 * std::size_t(f)], t.face_tet[2 * std::size_t(f) + 1]});
      face_vertex.insert(face_vertex.end(), t.face_vertex.begin() + 3 * std::ptrdiff_t(f),
                         t.face_vertex.begin() + 3 * std::ptrdiff_t(f) + 3);
    }
    for (; e < extra.size() && extra[e].cluster == k; ++e) {
      face_tet.insert(face_tet.end(), {extra[e].a, extra[e].b});
      face_vertex.insert(face_vertex.end(), extra[e].v, extra[e].v + 3);
    }
  }
  FOXI_ASSERT(face_tet.size() == 2 * std::size_t(begin[clusters]), "separating planes miscounted");
  t.cluster_face_begin = std::move(begin);
  t.face_tet = std::move(face_tet);
  t.face_vertex = std::move(face_vertex);
  t.separating_planes = extra.size();
}

}  // namespace

SphereTable compute_spheres(const MeshView& mesh, const ProgressFn& progress) {
  SphereTable t;
  const std::size_t n = mesh.tet_count();
  const bool weighted = !mesh.weight.empty();
  t.weighted = weighted;
  // The centres and s of near ties are read at random places per view: huge pages (no TLB miss).
  t.c.reserve(3 * n);
  t.s.reserve(n);
  advise_huge_pages(t.c.data(), 3 * n * sizeof(double));
  advise_huge_pages(t.s.data(), n * sizeof(double));
  t.c.resize(3 * n);
  t.s.resize(n);
  t.flat.assign(n, 0);
  // Relative error estimate of each centre offset, kept until the clusters are found.
  std::vector<float> rel_err(n, 0.f);
  const double* X = mesh.xyz.data();
  const std::uint32_t* T = mesh.tet.data();
  const double* W = weighted ? mesh.weight.data() : nullptr;

  // The local frame: the centre of the bounding box.
  double half[3] = {0, 0, 0};
  if (mesh.node_count() > 0) {
    double lo[3] = {X[0], X[1], X[2]}, hi[3] = {X[0], X[1], X[2]};
    for (std::size_t i = 1; i < mesh.node_count(); ++i)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], X[3 * i + k]);
        hi[k] = std::max(hi[k], X[3 * i + k]);
      }
    for (int k = 0; k < 3; ++k) {
      t.origin[k] = 0.5 * (lo[k] + hi[k]);
      half[k] = 0.5 * (hi[k] - lo[k]);
    }
  }
  const double org[3] = {t.origin[0], t.origin[1], t.origin[2]};
  t.key_a.resize(n);
  t.key_b.resize(n);

  std::size_t recomputed[2] = {0, 0}, flats[2] = {0, 0};
  detail::parallel_for_balanced(n, [&](std::size_t begin, std::size_t end, int part) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t* v = T + 4 * i;
      const double* pa = X + 3 * std::size_t(v[0]);
      const double* pb = X + 3 * std::size_t(v[1]);
      const double* pc = X + 3 * std::size_t(v[2]);
      const double* pd = X + 3 * std::size_t(v[3]);
      double a[3], b[3], c[3], d[3];
      for (int k = 0; k < 3; ++k) {
        a[k] = pa[k] - org[k];
        b[k] = pb[k] - pa[k];
        c[k] = pc[k] - pa[k];
        d[k] = pd[k] - pa[k];
      }
      double cd[3] = {c[1] * d[2] - c[2] * d[1], c[2] * d[0] - c[0] * d[2], c[0] * d[1] - c[1] * d[0]};
      double db[3] = {d[1] * b[2] - d[2] * b[1], d[2] * b[0] - d[0] * b[2], d[0] * b[1] - d[1] * b[0]};
      double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
      double det = b[0] * cd[0] + b[1] * cd[1] + b[2] * cd[2];
      double lb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
      double lc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
      double ld = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const double nb = std::sqrt(lb), nc = std::sqrt(lc), nd = std::sqrt(ld);
      double wb = lb, wc = lc, wd = ld, w0 = 0;
      if (W != nullptr) {
        w0 = W[v[0]];
        wb = lb - W[v[1]] + w0;
        wc = lc - W[v[2]] + w0;
        wd = ld - W[v[3]] + w0;
      }
      double num[3];
      for (int k = 0; k < 3; ++k) num[k] = wb * cd[k] + wc * db[k] + wd * bc[k];
      // Error estimates: a few ulps per operation times the magnitudes that were summed.
      const double det_err = 16 * kEps * nb * nc * nd;
      const double num_mag =
          std::abs(wb) * nc * nd + std::abs(wc) * nd * nb + std::abs(wd) * nb * nc +
          (W != nullptr ? (lb + lc + ld + 3 * std::abs(w0)) * (nc * nd + nd * nb + nb * nc) : 0);
      const double num_norm = std::sqrt(num[0] * num[0] + num[1] * num[1] + num[2] * num[2]);
      const double num_err = 16 * kEps * num_mag;
      double rel =
          std::abs(det) > 0 ? det_err / std::abs(det) + (num_norm > 0 ? num_err / num_norm : 1.0) : 1.0;
      double* cc = t.c.data() + 3 * i;
      double& s = t.s[i];
      if (!(rel <= kRecomputeAbove)) {  // NaN too (a non-finite weight): the exact path calls it flat
        const double* wv = nullptr;
        double wq[4];
        if (W != nullptr) {
          for (int k = 0; k < 4; ++k) wq[k] = W[v[k]];
          wv = wq;
        }
        ++recomputed[part];
        double cabs[3], sabs;
        if (exact::centre(pa, pb, pc, pd, wv, cabs, sabs)) {
          // Into the local frame: c - origin, and s - 2 c.origin + |origin|^2 (rounded, counted below).
          for (int k = 0; k < 3; ++k) cc[k] = cabs[k] - org[k];
          s = sabs - 2 * (cabs[0] * org[0] + cabs[1] * org[1] + cabs[2] * org[2]) +
              (org[0] * org[0] + org[1] * org[1] + org[2] * org[2]);
        } else {
          // Flat: a point sphere at the centroid, so the tet still has a place in the order.
          t.flat[i] = 1;
          ++flats[part];
          for (int k = 0; k < 3; ++k) cc[k] = 0.25 * (pa[k] + pb[k] + pc[k] + pd[k]) - org[k];
          s = cc[0] * cc[0] + cc[1] * cc[1] + cc[2] * cc[2];
        }
        rel = 0;
      } else {
        const double inv = 0.5 / det;
        double o[3] = {num[0] * inv, num[1] * inv, num[2] * inv};
        for (int k = 0; k < 3; ++k) cc[k] = a[k] + o[k];
        // s = |c|^2 - r^2 = |a|^2 + 2 a.o (+ w0): no cancellation of two large squares.
        s = a[0] * a[0] + a[1] * a[1] + a[2] * a[2] + 2 * (a[0] * o[0] + a[1] * o[1] + a[2] * o[2]) + w0;
      }
      rel_err[i] = static_cast<float>(rel);
      // Key bounds (see spheres.hpp), generous by a factor of about 2.
      const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
      const double ncc = std::sqrt(cc[0] * cc[0] + cc[1] * cc[1] + cc[2] * cc[2]);
      const double no = std::sqrt((cc[0] - a[0]) * (cc[0] - a[0]) + (cc[1] - a[1]) * (cc[1] - a[1]) +
                                  (cc[2] - a[2]) * (cc[2] - a[2]));
      const double norg = std::abs(org[0]) + std::abs(org[1]) + std::abs(org[2]);
      const double err_c = 8 * kEps * (na + ncc) + no * rel + (rel == 0 ? 4 * kEps * (ncc + norg) : 0);
      const double err_s = 32 * kEps * (na * na + 2 * na * no + std::abs(w0) + std::abs(s)) +
                           2 * na * no * rel +
                           (rel == 0 ? 16 * kEps * (std::abs(s) + 2 * (ncc + norg) * norg) : 0);
      t.key_a[i] = static_cast<float>(2 * (err_s + 8 * kEps * std::abs(s)));
      t.key_b[i] = static_cast<float>(2 * (2 * err_c + 16 * kEps * ncc));
    }
  });
  t.recomputed_exactly = recomputed[0] + recomputed[1];
  t.flat_count = flats[0] + flats[1];
  if (progress && !progress("spheres", 0.5)) return t;

  // Cospherical clusters: across each interior face, is the neighbour's far vertex on this tet's
  // sphere? Two filters in double reject the clear cases (centres apart, then the power of the far
  // vertex); CGAL's exact test decides the rest.
  const FaceAdjacency& adj = face_adjacency(mesh);
  std::vector<std::uint8_t> same(4 * n, 0);
  detail::parallel_for_balanced(n, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      if (t.flat[i]) continue;
      const std::uint32_t* v = T + 4 * i;
      const double* cc = t.c.data() + 3 * i;
      for (int f = 0; f < 4; ++f) {
        std::uint32_t nb = adj.neighbour[4 * i + f];
        if (nb == kNone) continue;
        std::uint32_t u = nb >> 2;
        if (u < i) continue;  // each face once, from its lower tet
        // Cospherical tets have one centre: centres apart by more than their error bounds (key_b
        // is at least 4 times the bound of each coordinate's error) are not, with no look at the
        // vertices (scattered over memory; the centres follow the tets).
        const double* cu = t.c.data() + 3 * std::size_t(u);
        const double apart =
            std::max({std::abs(cc[0] - cu[0]), std::abs(cc[1] - cu[1]), std::abs(cc[2] - cu[2])});
        if (apart > double(t.key_b[i]) + double(t.key_b[u]) || t.flat[u]) continue;
        const double* a = X + 3 * std::size_t(v[0]);
        const double o[3] = {cc[0] + org[0] - a[0], cc[1] + org[1] - a[1], cc[2] + org[2] - a[2]};
        const double no = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
        std::uint32_t qv = T[4 * std::size_t(u) + (nb & 3)];
        const double* q = X + 3 * std::size_t(qv);
        double qa[3] = {q[0] - a[0], q[1] - a[1], q[2] - a[2]};
        double lqa = qa[0] * qa[0] + qa[1] * qa[1] + qa[2] * qa[2];
        // power of q w.r.t. the sphere = |q-a|^2 - 2 (q-a).o (- w_q + w_a if weighted)
        double pw = lqa - 2 * (qa[0] * o[0] + qa[1] * o[1] + qa[2] * o[2]);
        double mag = lqa + 2 * std::sqrt(lqa) * no;
        if (W != nullptr) {
          pw += W[v[0]] - W[qv];
          mag += std::abs(W[v[0]]) + std::abs(W[qv]);
        }
        double bound =
            32 * kEps * mag + 4 * std::sqrt(lqa) * no * double(rel_err[i]) +
            8 * std::sqrt(lqa) * kEps * (std::abs(org[0]) + std::abs(org[1]) + std::abs(org[2]) + no);
        if (std::abs(pw) > bound) continue;
        double w4[4];
        const double* wv = nullptr;
        double wq = 0;
        if (W != nullptr) {
          for (int k = 0; k < 4; ++k) w4[k] = W[v[k]];
          wv = w4;
          wq = W[qv];
        }
        if (exact::in_sphere(a, X + 3 * std::size_t(v[1]), X + 3 * std::size_t(v[2]),
                             X + 3 * std::size_t(v[3]), q, wv, wq) == 0)
          same[4 * i + f] = 1;
      }
    }
  });
  if (progress && !progress("clusters", 0.8)) return t;

  // Pieces of one cospherical cell that share no face: a cell the mesh's boundary cuts (a Kuhn cube
  // with two opposite tets left out) falls apart into tets or clusters with one sphere, which may
  // face each other across the part left out, so they must be ordered together (one cluster, with
  // separating planes: add_separating_planes). Every such piece has a face on the mesh's boundary
  // inside the cell (in a Delaunay mesh a face between two cells lies on both cells' hulls), so
  // only tets with a boundary face are compared: their centres binned in cubes of side w (at least
  // twice the centres' error bounds, key_b), each against those in the cubes its bound reaches;
  // pairs not yet joined by faces are then tested exactly (all four vertices on the sphere). The
  // few tets with bounds far above the typical (a sliver's huge sphere) are compared with all.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> same_sphere = sphere_candidates(t, adj.neighbour);

  t.cluster_of.assign(n, kNone);
  t.cluster_of.assign(n, kNone);
  std::uint32_t clusters = 0;
  // Most unstructured meshes have no or few cospherical faces: no union-find over all tets then.
  if (!same_sphere.empty() || std::find(same.begin(), same.end(), std::uint8_t(1)) != same.end()) {
    UnionFind uf(n);
    for (std::size_t i = 0; i < n; ++i)
      for (int f = 0; f < 4; ++f)
        if (same[4 * i + f]) uf.unite(static_cast<std::uint32_t>(i), adj.neighbour[4 * i + f] >> 2);
    for (const auto& [i, u] : same_sphere) {
      if (uf.find(i) == uf.find(u)) continue;  // joined by faces already
      const std::uint32_t* v = T + 4 * std::size_t(i);
      double w4[4];
      const double* wv = nullptr;
      if (W != nullptr) {
        for (int k = 0; k < 4; ++k) w4[k] = W[v[k]];
        wv = w4;
      }
      bool on = true;
      for (int k = 0; k < 4 && on; ++k) {
        const std::uint32_t q = T[4 * std::size_t(u) + k];
        on = exact::in_sphere(X + 3 * std::size_t(v[0]), X + 3 * std::size_t(v[1]), X + 3 * std::size_t(v[2]),
                              X + 3 * std::size_t(v[3]), X + 3 * std::size_t(q), wv,
                              W != nullptr ? W[q] : 0.0) == 0;
      }
      if (on) uf.unite(i, u);
    }
    // Number the clusters of two or more tets in order of their smallest tet.
    std::vector<std::uint32_t> size(n, 0);
    for (std::size_t i = 0; i < n; ++i) ++size[uf.find(static_cast<std::uint32_t>(i))];
    std::vector<std::uint32_t> id_of_root(n, kNone);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t r = uf.find(static_cast<std::uint32_t>(i));
      if (size[r] < 2) continue;
      if (id_of_root[r] == kNone) id_of_root[r] = clusters++;
      t.cluster_of[i] = id_of_root[r];
    }
  }
  t.cluster_begin.assign(clusters + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (t.cluster_of[i] != kNone) ++t.cluster_begin[t.cluster_of[i] + 1];
  for (std::uint32_t k = 0; k < clusters; ++k) t.cluster_begin[k + 1] += t.cluster_begin[k];
  t.cluster_tets.resize(t.cluster_begin[clusters]);
  {
    std::vector<std::uint32_t> fill(t.cluster_begin.begin(), t.cluster_begin.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      if (t.cluster_of[i] != kNone) t.cluster_tets[fill[t.cluster_of[i]]++] = static_cast<std::uint32_t>(i);
    for (std::uint32_t k = 0; k < clusters; ++k)
      FOXI_ASSERT(fill[k] == t.cluster_begin[k + 1],
                  "cluster " << k << " filled " << fill[k] - t.cluster_begin[k] << " of its "
                             << t.cluster_begin[k + 1] - t.cluster_begin[k] << " tets");
  }
  // Faces inside clusters, oriented so that the first tet lies on the positive side of the triangle.
  static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  t.cluster_face_begin.assign(clusters + 1, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (int f = 0; f < 4; ++f)
      if (same[4 * i + f]) ++t.cluster_face_begin[t.cluster_of[i] + 1];
  for (std::uint32_t k = 0; k < clusters; ++k) t.cluster_face_begin[k + 1] += t.cluster_face_begin[k];
  const std::size_t faces = t.cluster_face_begin[clusters];
  t.face_tet.resize(2 * faces);
  t.face_vertex.resize(3 * faces);
  {
    std::vector<std::uint32_t> fill(t.cluster_face_begin.begin(), t.cluster_face_begin.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      for (int f = 0; f < 4; ++f) {
        if (!same[4 * i + f]) continue;
        std::uint32_t k = fill[t.cluster_of[i]]++;
        // Face f of a positively oriented tet, listed as kFace[f], has the tet's vertex f on its
        // negative side; reversed, it puts tet i on the positive side.
        const std::uint32_t* v = T + 4 * i;
        t.face_tet[2 * k] = static_cast<std::uint32_t>(i);
        t.face_tet[2 * k + 1] = adj.neighbour[4 * i + f] >> 2;
        t.face_vertex[3 * k] = v[kFace[f][0]];
        t.face_vertex[3 * k + 1] = v[kFace[f][2]];
        t.face_vertex[3 * k + 2] = v[kFace[f][1]];
      }
    for (std::uint32_t k = 0; k < clusters; ++k)
      FOXI_ASSERT(fill[k] == t.cluster_face_begin[k + 1],
                  "cluster " << k << " filled " << fill[k] - t.cluster_face_begin[k] << " of its "
                             << t.cluster_face_begin[k + 1] - t.cluster_face_begin[k] << " faces");
  }
  add_separating_planes(t, X, T, adj.neighbour, clusters);
  // Wide items: bounds far above the typical (256 x the median), so that a few slivers with huge
  // spheres do not widen the near-tie window of everyone else.
  t.wide.assign(n, 0);
  if (n > 0) {
    // The medians of a strided sample (under 2^17 bounds): the cap is a heuristic (any cap is
    // correct, bounds are kept per item), and a sample needs no copy of all n.
    const std::size_t stride = std::max<std::size_t>(1, n / 65536);
    std::vector<float> tmp;
    auto median = [&](const std::vector<float>& v) {
      tmp.clear();
      for (std::size_t i = 0; i < n; i += stride) tmp.push_back(v[i]);
      std::nth_element(tmp.begin(), tmp.begin() + tmp.size() / 2, tmp.end());
      return double(tmp[tmp.size() / 2]);
    };
    const double cap_a = 256.0 * std::max(median(t.key_a), 1e-300);
    const double cap_b = 256.0 * std::max(median(t.key_b), 1e-300);
    // Wide because of a poorly conditioned centre (not a huge sphere): recompute it exactly, which
    // shrinks its bound to rounding.
    for (std::size_t i = 0; i < n; ++i) {
      if ((t.key_a[i] > cap_a || t.key_b[i] > cap_b) && rel_err[i] > 0 && !t.flat[i]) {
        const std::uint32_t* v = T + 4 * i;
        const double* pa = X + 3 * std::size_t(v[0]);
        double w4[4];
        const double* wv = nullptr;
        if (W != nullptr) {
          for (int k = 0; k < 4; ++k) w4[k] = W[v[k]];
          wv = w4;
        }
        double cabs[3], sabs;
        if (!exact::centre(pa, X + 3 * std::size_t(v[1]), X + 3 * std::size_t(v[2]),
                           X + 3 * std::size_t(v[3]), wv, cabs, sabs))
          continue;
        ++t.recomputed_exactly;
        double* cc = t.c.data() + 3 * i;
        for (int k = 0; k < 3; ++k) cc[k] = cabs[k] - org[k];
        t.s[i] = sabs - 2 * (cabs[0] * org[0] + cabs[1] * org[1] + cabs[2] * org[2]) +
                 (org[0] * org[0] + org[1] * org[1] + org[2] * org[2]);
        const double ncc = std::sqrt(cc[0] * cc[0] + cc[1] * cc[1] + cc[2] * cc[2]);
        const double norg = std::abs(org[0]) + std::abs(org[1]) + std::abs(org[2]);
        const double w0 = W != nullptr ? std::abs(W[v[0]]) : 0.0;
        const double err_c = 8 * kEps * (ncc + norg);
        const double err_s = 32 * kEps * (std::abs(t.s[i]) + 2 * (ncc + norg) * norg + w0);
        t.key_a[i] = static_cast<float>(2 * (err_s + 8 * kEps * std::abs(t.s[i])));
        t.key_b[i] = static_cast<float>(2 * (2 * err_c + 16 * kEps * ncc));
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (t.key_a[i] > cap_a || t.key_b[i] > cap_b) {
        t.wide[i] = 1;
      } else {
        t.bound_a = std::max(t.bound_a, double(t.key_a[i]));
        t.bound_b = std::max(t.bound_b, double(t.key_b[i]));
      }
    }
  }
  auto add_item = [&t](std::uint32_t item, std::uint32_t rep) {
    if (t.wide[rep]) {
      t.wide_items.push_back(item);
      t.wide_a.push_back(t.key_a[rep]);
      t.wide_b.push_back(t.key_b[rep]);
    } else {
      t.all_items.push_back(item);
      t.all_rep.push_back(rep);
    }
  };
  // Planes and local indices of the cluster faces.
  const std::size_t all_faces = t.cluster_face_begin[clusters];  // with the separating planes
  t.face_test.resize(all_faces);
  {
    std::vector<std::uint32_t> local(n, 0);
    for (std::uint32_t k = 0; k < clusters; ++k)
      for (std::uint32_t i = t.cluster_begin[k]; i < t.cluster_begin[k + 1]; ++i)
        local[t.cluster_tets[i]] = i - t.cluster_begin[k];
    for (std::size_t f = 0; f < all_faces; ++f) {
      const double* p0 = X + 3 * std::size_t(t.face_vertex[3 * f]);
      const double* p1 = X + 3 * std::size_t(t.face_vertex[3 * f + 1]);
      const double* p2 = X + 3 * std::size_t(t.face_vertex[3 * f + 2]);
      double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
      double w[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
      double nn[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      SphereTable::ClusterFace& ft = t.face_test[f];
      ft.plane[0] = nn[0];
      ft.plane[1] = nn[1];
      ft.plane[2] = nn[2];
      ft.plane[3] = nn[0] * p0[0] + nn[1] * p0[1] + nn[2] * p0[2];
      ft.scale = static_cast<float>((std::abs(u[0]) + std::abs(u[1]) + std::abs(u[2])) *
                                    (std::abs(w[0]) + std::abs(w[1]) + std::abs(w[2])) * (1 + 1e-6));
      ft.anorm = static_cast<float>((std::abs(p0[0]) + std::abs(p0[1]) + std::abs(p0[2])) * (1 + 1e-6));
      std::uint32_t la = local[t.face_tet[2 * f]], lb = local[t.face_tet[2 * f + 1]];
      ft.local[0] = la < 0xFFFF ? static_cast<std::uint16_t>(la) : 0xFFFF;
      ft.local[1] = lb < 0xFFFF ? static_cast<std::uint16_t>(lb) : 0xFFFF;
      // The separating planes come after the cluster's shared faces (add_separating_planes).
      ft.separating = t.face_tet[2 * f] != t.face_tet[2 * f + 1] &&
                      !shares_face(adj.neighbour, t.face_tet[2 * f], t.face_tet[2 * f + 1]);
    }
  }
  t.clusters_split = clusters > 0 && t.cluster_tets.size() * SphereTable::kSplitClusters <= n;
  if (t.clusters_split) {
    t.all_items.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
      add_item(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i));
  } else {
    t.all_items.reserve(n - t.cluster_tets.size() + clusters);
    for (std::size_t i = 0; i < n; ++i)
      if (t.cluster_of[i] == kNone) add_item(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i));
    for (std::uint32_t k = 0; k < clusters; ++k)
      add_item(k | kClusterBit, t.cluster_tets[t.cluster_begin[k]]);
  }
  make_fixed_keys(t, half);
  if (progress) progress("clusters", 1.0);
  return t;
}

}  // namespace foxi
