// The Delaunay certificate: a global empty-sphere (or, with weights, empty-orthosphere) check.
//
// The used vertices go into a uniform grid (a counting sort on cells, x fastest, so one row of cells is
// one contiguous run of points). For each tet the circumcentre (orthocentre) is computed in double
// relative to its first vertex, with an a-priori bound on its error (Higham-style: terms bounded by
// a constant times the unit roundoff times the "permanent", the same expression with absolute values,
// as in Shewchuk's adaptive predicates). Every vertex in the cells that the sphere's box (enlarged by
// that bound) overlaps is first tested in double against the sphere enlarged by the bound: a vertex
// outside is certainly outside the exact sphere. The rest (the tet's own vertices skipped) are decided
// by CGAL's filtered exact predicates, so cospherical points (on the sphere) are never violations.
#include "foxi/model/delaunay.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include "derived.hpp"
#include "foxi/model/parallel.hpp"

namespace foxi {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using WPoint = K::Weighted_point_3;

constexpr double kU = 0x1p-53;  // unit roundoff of double

struct GridPoint {
  double x, y, z;
  double w;  // weight (0 when unweighted)
  std::uint32_t id;
};

// The used, finite vertices sorted into uniform cubic cells.
struct PointGrid {
  double lo[3] = {0, 0, 0};
  double inv_h = 1;
  std::int64_t dims[3] = {1, 1, 1};
  std::vector<std::uint32_t> cell_start;  // dims product + 1
  std::vector<GridPoint> pts;             // in cell order
  double wmax = 0;                        // largest weight (0 when unweighted)
  std::vector<std::uint32_t> cell_of;     // per node: its cell (0 for nodes not in the grid)
  // When the points crowd into a few cells (coordinates mixing magnitudes, 1e-20 next to 1e20: the
  // cells are sized by the bounding box, so nearly all points share the cell at the origin and every
  // tet scanned them all, 26 s for 130k tets), a k-d tree over them instead: `kd` holds the same
  // points in tree order, node k covering kd[node.begin, node.end).
  struct KdNode {
    std::uint32_t begin, end;  // points
    std::uint32_t left;        // children left and left + 1 (0: a leaf)
    int dim;                   // split dimension; points of the left child have p[dim] <= split
    double split;
  };
  std::vector<GridPoint> kd;
  std::vector<KdNode> kd_nodes;

  // Monotone in v (rounding is monotone), so a box's cell range holds every point inside the box.
  std::int64_t cell(double v, int d) const {
    double f = (v - lo[d]) * inv_h;
    if (!(f >= 0)) return 0;
    if (f >= static_cast<double>(dims[d])) return dims[d] - 1;
    return static_cast<std::int64_t>(f);
  }
};

bool finite3(const double* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

double coord(const GridPoint& p, int d) { return d == 0 ? p.x : d == 1 ? p.y : p.z; }

// A k-d tree of g.pts: median splits on the dimension of widest extent, leaves of at most 16 points.
void build_kd(PointGrid& g) {
  g.kd = g.pts;
  g.kd_nodes.clear();
  g.kd_nodes.push_back({0, static_cast<std::uint32_t>(g.kd.size()), 0, 0, 0.0});
  for (std::size_t k = 0; k < g.kd_nodes.size(); ++k) {
    const std::uint32_t begin = g.kd_nodes[k].begin, end = g.kd_nodes[k].end;
    if (end - begin <= 16) continue;
    double lo[3], hi[3];
    for (int d = 0; d < 3; ++d) lo[d] = hi[d] = coord(g.kd[begin], d);
    for (std::uint32_t i = begin; i < end; ++i)
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], coord(g.kd[i], d));
        hi[d] = std::max(hi[d], coord(g.kd[i], d));
      }
    int dim = 0;
    for (int d = 1; d < 3; ++d)
      if (hi[d] - lo[d] > hi[dim] - lo[dim]) dim = d;
    if (!(hi[dim] > lo[dim])) continue;  // all at one point: a leaf
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(g.kd.begin() + begin, g.kd.begin() + mid, g.kd.begin() + end,
                     [dim](const GridPoint& p, const GridPoint& q) { return coord(p, dim) < coord(q, dim); });
    // Left: [begin, mid], every point there <= the median; right: (mid, end), every one >= it.
    const double split = coord(g.kd[mid], dim);
    const std::uint32_t left = static_cast<std::uint32_t>(g.kd_nodes.size());
    g.kd_nodes[k].left = left;
    g.kd_nodes[k].dim = dim;
    g.kd_nodes[k].split = split;
    g.kd_nodes.push_back({begin, mid + 1, 0, 0, 0.0});
    g.kd_nodes.push_back({mid + 1, end, 0, 0, 0.0});
  }
}

PointGrid build_grid(const MeshView& mesh, bool weighted) {
  PointGrid g;
  const std::size_t nv = mesh.node_count();
  std::vector<std::uint8_t> used(nv, 0);
  for (std::uint32_t v : mesh.tet)
    if (v < nv) used[v] = 1;
  std::size_t m = 0;
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (std::size_t v = 0; v < nv; ++v) {
    const double* p = &mesh.xyz[3 * v];
    if (!used[v] || !finite3(p) || (weighted && !std::isfinite(mesh.weight[v]))) {
      used[v] = 0;
      continue;
    }
    ++m;
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
    if (weighted) g.wmax = std::max(g.wmax, mesh.weight[v]);
  }
  g.cell_start.assign(2, 0);
  if (m == 0) return g;
  double emax = 0;
  for (int d = 0; d < 3; ++d) {
    g.lo[d] = lo[d];
    emax = std::max(emax, hi[d] - lo[d]);
  }
  if (emax > 0) {
    // Cubic cells, about one point per cell.
    // The volume relative to emax^3, so that it neither overflows nor underflows for coordinates
    // near 1e160 or 1e-160 (then h was inf or 0 and the cell counts inf: UBSan, converting to int).
    double vol = 1;
    for (int d = 0; d < 3; ++d) vol *= std::max((hi[d] - lo[d]) / emax, 1e-3);
    double h = emax * std::cbrt(vol / static_cast<double>(m));
    if (!(h > 0) || !std::isfinite(h))
      h = std::numeric_limits<double>::infinity();  // extent overflows: one cell
    for (int d = 0; d < 3; ++d) {
      const double n = std::ceil((hi[d] - lo[d]) / h);  // (NaN for an infinite extent: one cell)
      g.dims[d] = n >= 1 ? static_cast<std::int64_t>(std::min(n, 4096.0)) : 1;
    }
    g.inv_h = 1 / h;
  }
  const std::size_t cells = static_cast<std::size_t>(g.dims[0] * g.dims[1] * g.dims[2]);
  std::vector<std::uint32_t>& cell_of = g.cell_of;
  cell_of.assign(nv, 0);
  g.cell_start.assign(cells + 1, 0);
  for (std::size_t v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    const double* p = &mesh.xyz[3 * v];
    std::size_t c = static_cast<std::size_t>((g.cell(p[2], 2) * g.dims[1] + g.cell(p[1], 1)) * g.dims[0] +
                                             g.cell(p[0], 0));
    cell_of[v] = static_cast<std::uint32_t>(c);
    ++g.cell_start[c + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) g.cell_start[c + 1] += g.cell_start[c];
  g.pts.resize(m);
  std::vector<std::uint32_t> fill(g.cell_start.begin(), g.cell_start.end() - 1);
  for (std::size_t v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    const double* p = &mesh.xyz[3 * v];
    g.pts[fill[cell_of[v]]++] = {p[0], p[1], p[2], weighted ? mesh.weight[v] : 0.0,
                                 static_cast<std::uint32_t>(v)};
  }
  std::uint32_t crowded = 0;
  for (std::size_t c = 0; c < cells; ++c) crowded = std::max(crowded, g.cell_start[c + 1] - g.cell_start[c]);
  if (crowded > 256) build_kd(g);
  return g;
}

struct ThreadResult {
  std::vector<std::uint32_t> violating;
  std::size_t violating_count = 0;
  std::size_t degenerate = 0;
  std::size_t checked = 0;
  double max_depth = 0;
};

class Checker {
 public:
  Checker(const MeshView& mesh, const PointGrid& grid, bool weighted)
      : mesh_(mesh), grid_(grid), weighted_(weighted) {}

  void check_tet(std::size_t t, ThreadResult& out) const {
    const std::size_t nv = mesh_.node_count();
    std::uint32_t v[4];
    for (int j = 0; j < 4; ++j) v[j] = mesh_.tet[4 * t + j];
    for (int j = 0; j < 4; ++j)
      if (v[j] >= nv || !finite3(&mesh_.xyz[3 * v[j]]) || (weighted_ && !std::isfinite(mesh_.weight[v[j]]))) {
        ++out.degenerate;
        return;
      }
    const double* a = &mesh_.xyz[3 * v[0]];
    const double* pb = &mesh_.xyz[3 * v[1]];
    const double* pc = &mesh_.xyz[3 * v[2]];
    const double* pd = &mesh_.xyz[3 * v[3]];
    const double B[3] = {pb[0] - a[0], pb[1] - a[1], pb[2] - a[2]};
    const double C[3] = {pc[0] - a[0], pc[1] - a[1], pc[2] - a[2]};
    const double D[3] = {pd[0] - a[0], pd[1] - a[1], pd[2] - a[2]};
    auto cross = [](const double* p, const double* q, double* r) {
      r[0] = p[1] * q[2] - p[2] * q[1];
      r[1] = p[2] * q[0] - p[0] * q[2];
      r[2] = p[0] * q[1] - p[1] * q[0];
    };
    auto cross_abs = [](const double* p, const double* q, double* r) {
      r[0] = std::abs(p[1] * q[2]) + std::abs(p[2] * q[1]);
      r[1] = std::abs(p[2] * q[0]) + std::abs(p[0] * q[2]);
      r[2] = std::abs(p[0] * q[1]) + std::abs(p[1] * q[0]);
    };
    double CD[3], DB[3], BC[3], CDa[3], DBa[3], BCa[3];
    cross(C, D, CD);
    cross(D, B, DB);
    cross(B, C, BC);
    cross_abs(C, D, CDa);
    cross_abs(D, B, DBa);
    cross_abs(B, C, BCa);
    const double den = B[0] * CD[0] + B[1] * CD[1] + B[2] * CD[2];  // 6 x signed volume
    const double den_perm = std::abs(B[0]) * CDa[0] + std::abs(B[1]) * CDa[1] + std::abs(B[2]) * CDa[2];
    const double den_err = 32 * kU * den_perm;

    // Orientation: from the double value when its error bound decides it, else exactly.
    const Point P[4] = {Point(a[0], a[1], a[2]), Point(pb[0], pb[1], pb[2]), Point(pc[0], pc[1], pc[2]),
                        Point(pd[0], pd[1], pd[2])};
    int sign = den > den_err ? 1 : den < -den_err ? -1 : 0;
    if (sign == 0) {
      CGAL::Orientation o = CGAL::orientation(P[0], P[1], P[2], P[3]);
      if (o == CGAL::COPLANAR) {
        ++out.degenerate;
        return;
      }
      sign = o == CGAL::POSITIVE ? 1 : -1;
    }
    ++out.checked;

    // Orthocentre relative to a: 2 [B;C;D] x = (lifted B, C, D), lifted B = |B|^2 - (w_b - w_a).
    double wv[4] = {0, 0, 0, 0};
    if (weighted_)
      for (int j = 0; j < 4; ++j) wv[j] = mesh_.weight[v[j]];
    const double lB = B[0] * B[0] + B[1] * B[1] + B[2] * B[2] - (wv[1] - wv[0]);
    const double lC = C[0] * C[0] + C[1] * C[1] + C[2] * C[2] - (wv[2] - wv[0]);
    const double lD = D[0] * D[0] + D[1] * D[1] + D[2] * D[2] - (wv[3] - wv[0]);
    const double LB = B[0] * B[0] + B[1] * B[1] + B[2] * B[2] + std::abs(wv[1]) + std::abs(wv[0]);
    const double LC = C[0] * C[0] + C[1] * C[1] + C[2] * C[2] + std::abs(wv[2]) + std::abs(wv[0]);
    const double LD = D[0] * D[0] + D[1] * D[1] + D[2] * D[2] + std::abs(wv[3]) + std::abs(wv[0]);
    bool reliable = std::abs(den) > 4 * den_err;
    double x[3] = {0, 0, 0}, ex = 0;
    if (reliable) {
      double ex2 = 0;
      for (int i = 0; i < 3; ++i) {
        const double N = lB * CD[i] + lC * DB[i] + lD * BC[i];
        const double eN = 32 * kU * (LB * CDa[i] + LC * DBa[i] + LD * BCa[i]);
        x[i] = N / (2 * den);
        const double e =
            (eN * std::abs(den) + std::abs(N) * den_err) / (2 * std::abs(den) * (std::abs(den) - den_err)) +
            4 * kU * std::abs(x[i]);
        ex2 += e * e;
      }
      ex = std::sqrt(ex2) * 1.01;
      reliable = std::isfinite(ex) && std::isfinite(x[0] + x[1] + x[2]);
    }

    // Candidates: the cells of the sphere's box (or every point when the centre is unreliable).
    const double xn = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    // The rounding of dq = (q - a) - x: q - a is one correctly rounded subtraction (error <= u|q - a|
    // per coordinate, whatever the size of a), and so is the second, so |error| <= u (2|dq| + |x|)
    // (a little more for the second-order terms). Near the sphere |dq| ~ |x|, so 4u|x| covers it
    // there; the weighted test below adds the 2u|dq| term itself. The bound is local to the tet: a
    // global one (4u times the largest coordinate) made every point a candidate for exact tests on
    // meshes that mix magnitudes (1e-40 next to 1e40), minutes of exact arithmetic (issue 22).
    const double eq = 4 * kU * xn;
    const double e1 = eq + ex;
    const double amax = std::max({std::abs(a[0]), std::abs(a[1]), std::abs(a[2])});
    // Largest possible power radius^2 (with room for the rounding of the weight terms).
    const double rmax =
        (xn + ex) * (xn + ex) + grid_.wmax - wv[0] + 8 * kU * (std::abs(grid_.wmax) + std::abs(wv[0]));
    double half = e1 + std::sqrt(std::max(0.0, rmax));
    // The box's corners a + x +- half are rounded twice: within 2u (|a| + |x| + half) each.
    half = half * (1 + 1e-9) + 8 * kU * (amax + xn + half);
    std::int64_t c0[3] = {0, 0, 0}, c1[3] = {grid_.dims[0] - 1, grid_.dims[1] - 1, grid_.dims[2] - 1};
    if (reliable && std::isfinite(half)) {
      for (int d = 0; d < 3; ++d) {
        const double centre = a[d] + x[d];
        c0[d] = grid_.cell(centre - half, d);
        c1[d] = grid_.cell(centre + half, d);
      }
    }
    // Unweighted: outside when |q' - x| > |x| + ex + e1 (squared, with a relative margin).
    const double t_out = (xn + ex + e1) * (xn + ex + e1) * (1 + 1e-12);
    const double wa = wv[0];

    const int s2 = sign > 0 ? 2 : 3, s3 = sign > 0 ? 3 : 2;  // positively oriented order
    bool violated = false;
    double depth = 0;
    auto visit = [&](const GridPoint* q) {
      if (reliable) {
        const double dx = q->x - a[0] - x[0], dy = q->y - a[1] - x[1], dz = q->z - a[2] - x[2];
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (!weighted_) {
          if (d2 > t_out) return;
        } else {
          const double dl = std::sqrt(d2) * (1 - 8 * kU) - e1;  // the 2u|dq| rounding term
          if (dl > 0) {
            const double lower = dl * dl - q->w - (xn + ex) * (xn + ex) + wa;
            const double margin = 1e-12 * (d2 + (xn + ex) * (xn + ex) + std::abs(q->w) + std::abs(wa));
            if (lower > margin) return;
          }
        }
      }
      if (q->id == v[0] || q->id == v[1] || q->id == v[2] || q->id == v[3]) return;
      const Point pq(q->x, q->y, q->z);
      CGAL::Oriented_side side;
      if (!weighted_) {
        side = CGAL::side_of_oriented_sphere(P[0], P[1], P[s2], P[s3], pq);
      } else {
        const WPoint W[4] = {WPoint(P[0], wv[0]), WPoint(P[1], wv[1]), WPoint(P[2], wv[2]),
                             WPoint(P[3], wv[3])};
        side = K().power_side_of_oriented_power_sphere_3_object()(W[0], W[1], W[s2], W[s3], WPoint(pq, q->w));
      }
      if (side == CGAL::ON_POSITIVE_SIDE) {
        violated = true;
        if (!weighted_ && reliable && xn > 0) {
          const double dx = q->x - a[0] - x[0], dy = q->y - a[1] - x[1], dz = q->z - a[2] - x[2];
          depth = std::max(depth, (xn - std::sqrt(dx * dx + dy * dy + dz * dz)) / xn);
        }
      }
    };
    if (!grid_.kd_nodes.empty()) {
      // The k-d tree: the subtrees whose half-spaces meet the sphere's box (all points when the
      // centre is unreliable).
      const bool boxed = reliable && std::isfinite(half);
      double blo[3], bhi[3];
      for (int d = 0; d < 3; ++d) {
        blo[d] = a[d] + x[d] - half;
        bhi[d] = a[d] + x[d] + half;
      }
      std::uint32_t stack[128];
      int top = 0;
      stack[top++] = 0;
      while (top > 0) {
        const PointGrid::KdNode& node = grid_.kd_nodes[stack[--top]];
        if (node.left == 0 || !boxed || top + 2 > 128) {
          for (std::uint32_t i = node.begin; i < node.end; ++i) visit(&grid_.kd[i]);
          continue;
        }
        if (blo[node.dim] <= node.split) stack[top++] = node.left;
        if (bhi[node.dim] >= node.split) stack[top++] = node.left + 1;
      }
    } else {
      for (std::int64_t cz = c0[2]; cz <= c1[2]; ++cz)
        for (std::int64_t cy = c0[1]; cy <= c1[1]; ++cy) {
          const std::size_t row = static_cast<std::size_t>((cz * grid_.dims[1] + cy) * grid_.dims[0]);
          const GridPoint* first = grid_.pts.data() + grid_.cell_start[row + static_cast<std::size_t>(c0[0])];
          const GridPoint* last =
              grid_.pts.data() + grid_.cell_start[row + static_cast<std::size_t>(c1[0]) + 1];
          for (const GridPoint* q = first; q < last; ++q) visit(q);
        }
    }
    if (violated) {
      ++out.violating_count;
      out.violating.push_back(static_cast<std::uint32_t>(t));
      out.max_depth = std::max(out.max_depth, depth);
    }
  }

 private:
  const MeshView mesh_;
  const PointGrid& grid_;
  bool weighted_;
};

}  // namespace

DelaunayCertificate compute_delaunay_certificate(const MeshView& mesh, const CertificateOptions& options) {
  DelaunayCertificate cert;
  const bool weighted = !mesh.weight.empty();
  cert.weighted = weighted;
  if (weighted && mesh.weight.size() != mesh.node_count()) {
    // Sizes do not match (see check_sizes): nothing can be certified.
    cert.degenerate_tet_count = mesh.tet_count();
    return cert;
  }
  const std::size_t n = mesh.tet_count();
  if (options.progress && !options.progress("delaunay certificate", 0.0)) {
    cert.cancelled = true;
    return cert;
  }
  const PointGrid grid = build_grid(mesh, weighted);
  const Checker checker(mesh, grid, weighted);

  // Visit the tets in the grid order of their first vertex (a counting sort): neighbouring tets
  // share vertices and candidate cells, so coordinates stay in cache whatever the mesh's numbering.
  std::vector<std::uint32_t> order(n);
  {
    const std::size_t cells = grid.cell_start.size() - 1;
    std::vector<std::uint32_t> start(cells + 1, 0);
    auto cell_of_tet = [&](std::size_t t) {
      const std::uint32_t v = mesh.tet[4 * t];
      return v < grid.cell_of.size() ? grid.cell_of[v] : 0u;
    };
    for (std::size_t t = 0; t < n; ++t) ++start[cell_of_tet(t) + 1];
    for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    for (std::size_t t = 0; t < n; ++t) order[start[cell_of_tet(t)]++] = static_cast<std::uint32_t>(t);
  }

  const unsigned threads = n >= 20000 ? std::clamp(std::thread::hardware_concurrency(), 1u, 8u) : 1u;
  constexpr std::size_t kChunk = 4096;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::atomic<std::size_t> next{0}, done{0};
  std::atomic<bool> cancel{false};
  std::vector<ThreadResult> results(threads);
  auto work = [&](unsigned i) {
    ThreadResult& r = results[i];
    for (;;) {
      if (cancel.load(std::memory_order_relaxed)) return;
      const std::size_t c = next.fetch_add(1);
      if (c >= chunks) return;
      const std::size_t end = std::min(n, (c + 1) * kChunk);
      for (std::size_t k = c * kChunk; k < end; ++k) checker.check_tet(order[k], r);
      const std::size_t finished = done.fetch_add(1) + 1;
      // Only the calling thread reports progress, so the callback never runs on a worker.
      if (i == 0 && options.progress &&
          !options.progress("delaunay certificate",
                            static_cast<double>(finished) / static_cast<double>(chunks)))
        cancel = true;
    }
  };
  detail::parallel_for(
      threads, threads, [&](std::size_t, std::size_t, unsigned i) { work(i); }, 0);

  for (ThreadResult& r : results) {
    cert.tets_checked += r.checked + r.degenerate;
    cert.violating_tet_count += r.violating_count;
    cert.degenerate_tet_count += r.degenerate;
    cert.max_relative_depth = std::max(cert.max_relative_depth, r.max_depth);
    cert.violating_tets.insert(cert.violating_tets.end(), r.violating.begin(), r.violating.end());
  }
  std::sort(cert.violating_tets.begin(), cert.violating_tets.end());
  if (cert.violating_tets.size() > options.max_listed) cert.violating_tets.resize(options.max_listed);
  cert.cancelled = cancel.load();
  cert.delaunay = !cert.cancelled && cert.violating_tet_count == 0 && cert.degenerate_tet_count == 0;
  if (!cert.cancelled && options.progress) options.progress("delaunay certificate", 1.0);
  return cert;
}

const DelaunayCertificate& delaunay_certificate(const MeshView& mesh) {
  DerivedData& d = derived_of(mesh);
  std::lock_guard<std::mutex> g(d.lock);
  if (!d.certificate)
    d.certificate = std::make_unique<DelaunayCertificate>(compute_delaunay_certificate(mesh));
  return *d.certificate;
}

}  // namespace foxi
