// Linear thermoelasticity with P1 tets (see thermoelastic.hpp). The stiffness is assembled in 3x3
// node blocks row by row over the node adjacency pattern (each thread owns whole rows: no locks and a
// deterministic sum). Constraints are per node: the fixed components and the normals of sliding planes
// are orthonormalised into a local frame whose first m axes are constrained; the node's blocks are
// rotated into that frame (R K R^T), so every constraint becomes a fixed unknown that is eliminated.
// The well-posedness check counts, per connected part, the rigid-body motions that no constraint
// resists (the null space of the 6x6 Gram matrix of the constraints' rigid-body rows).
// Quadratic (P2) tets add one node per unique edge (numbered after the mesh's nodes) and assemble
// element by element into the same node-block structure; constraints, elimination, the rigid-body
// near-null space and the solve are shared with P1.
#include "foxi/solver/thermoelastic.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

#include "foxi/model/adjacency.hpp"
#include "elastic_setup.hpp"
#include "linear_solve.hpp"

namespace foxi {

namespace {

using detail::cross;
using detail::dot;
using detail::parallel_for;
using detail::point;
using detail::region_label;
using detail::Vec3;

// B <- R_left B R_right^T for 3x3 row-major blocks (either rotation may be null: identity).
void rotate_block(double* b, const double* left, const double* right) {
  double t[9];
  if (left) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        t[3 * i + j] = left[3 * i] * b[j] + left[3 * i + 1] * b[3 + j] + left[3 * i + 2] * b[6 + j];
    std::copy(t, t + 9, b);
  }
  if (right) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        t[3 * i + j] =
            b[3 * i] * right[3 * j] + b[3 * i + 1] * right[3 * j + 1] + b[3 * i + 2] * right[3 * j + 2];
    std::copy(t, t + 9, b);
  }
}

// Throws SolverError when a connected part of the mesh still has rigid-body motions that the node
// frames do not constrain: rigid motion u = a + w x (x - c); constraint d . u = 0 gives the row
// [d, ((x - c) x d) / L]; the motions left are the null space of the sum of the rows' outer products.
void check_rigid_modes(const Mesh& mesh, const detail::NodeFrames& fr, const std::vector<char>& used) {
  const std::size_t nn = mesh.node_count();
  const std::vector<std::uint32_t> part = detail::node_components(mesh);
  auto root = [&](std::uint32_t v) { return part[v]; };
  std::map<std::uint32_t, std::array<double, 6>> box;  // part -> lo[3], hi[3]
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    auto [it, fresh] = box.try_emplace(root(static_cast<std::uint32_t>(v)));
    const Vec3 x = point(mesh, v);
    for (int i = 0; i < 3; ++i) {
      if (fresh || x[i] < it->second[i]) it->second[i] = x[i];
      if (fresh || x[i] > it->second[3 + i]) it->second[3 + i] = x[i];
    }
  }
  std::map<std::uint32_t, Eigen::Matrix<double, 6, 6>> gram;
  for (const auto& [r, b] : box) gram[r].setZero();
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v] || fr.m[v] == 0) continue;
    const std::uint32_t r = root(static_cast<std::uint32_t>(v));
    const auto& b = box[r];
    const Vec3 c{(b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2};
    const double len = std::max(1e-300, std::hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]));
    const Vec3 x = point(mesh, v);
    const Vec3 rel{(x[0] - c[0]) / len, (x[1] - c[1]) / len, (x[2] - c[2]) / len};
    for (int a = 0; a < fr.m[v]; ++a) {
      const Vec3 d{fr.r[9 * v + 3 * a], fr.r[9 * v + 3 * a + 1], fr.r[9 * v + 3 * a + 2]};
      const Vec3 w = cross(rel, d);
      Eigen::Matrix<double, 6, 1> row;
      row << d[0], d[1], d[2], w[0], w[1], w[2];
      gram[r] += row * row.transpose();
    }
  }
  for (auto& [r, gm] : gram) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(gm);
    const auto& ev = eig.eigenvalues();
    const double top = std::max(ev.maxCoeff(), 0.0);
    std::string modes;
    int left = 0;
    for (int k = 0; k < 6; ++k) {
      if (top > 0 && ev[k] > 1e-9 * top) continue;
      ++left;
      const auto vec = eig.eigenvectors().col(k);
      const double t = vec.head<3>().norm(), w = vec.tail<3>().norm();
      Eigen::Vector3d dir = t >= w ? Eigen::Vector3d(vec.head<3>() / t) : Eigen::Vector3d(vec.tail<3>() / w);
      if (dir[0] + dir[1] + dir[2] < 0) dir = -dir;
      for (double& c : dir)
        if (std::abs(c) < 1e-9) c = 0;
      char text[96];
      std::snprintf(text, sizeof text, "%s (%.3g, %.3g, %.3g)",
                    t >= w ? "translation along" : "rotation about", dir[0], dir[1], dir[2]);
      modes += (modes.empty() ? "" : "; ") + std::string(text);
    }
    if (left == 0) continue;
    std::size_t tet = 0;
    while (root(mesh.tet[4 * tet]) != r) ++tet;
    throw SolverInputError("ill-posed thermoelastic problem: the connected part containing tet " +
                           std::to_string(tet) + " (" + region_label(mesh, mesh.region_of(tet)) +
                           ") can still move rigidly, " + std::to_string(left) + " rigid-body mode" +
                           (left > 1 ? "s" : "") + " left (" + modes +
                           "); fix displacements or add sliding planes that hold it");
  }
}

// The stiffness in 3x3 node blocks over `pat` (rows = solver nodes: the mesh's nodes, then for P2 the
// mid-edge nodes), the thermal load, and the solver nodes' coordinates.
struct BlockSystem {
  detail::CsrPattern pat;
  std::vector<double> kval, load;  // 9 per pattern entry, 3 per node
  std::vector<double> xyz;         // 3 per node
  std::vector<char> used;          // per node: in some tet
  std::size_t nodes() const { return used.size(); }
};

// Lame constants and thermal expansion per region; the region index per tet.
struct ElasticCoefficients {
  const std::vector<double>&lambda, &mu, &expansion;
  const std::vector<std::uint32_t>& tet_rix;
};

// Adds the isotropic block lam ga gc^T + mu gc ga^T + mu (ga . gc) I (integration weights folded into
// lam and mu) to the row-major 3x3 block blk.
inline void add_block(double* blk, const std::array<double, 3>& ga, const std::array<double, 3>& gc,
                      double lam, double mu) {
  const double gg = ga[0] * gc[0] + ga[1] * gc[1] + ga[2] * gc[2];
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      blk[3 * x + y] += lam * ga[x] * gc[y] + mu * ga[y] * gc[x] + (x == y ? mu * gg : 0.0);
}

BlockSystem assemble_p1(const Mesh& mesh, const ElasticCoefficients& co, const std::vector<double>& tet_dt,
                        unsigned threads) {
  const std::size_t nn = mesh.node_count();
  const detail::NodeTets ntets = detail::node_tets(mesh);
  BlockSystem sys;
  sys.pat = detail::node_pattern(mesh, ntets, threads);
  sys.xyz = mesh.xyz;
  sys.used.assign(nn, 0);
  for (std::size_t v = 0; v < nn; ++v) sys.used[v] = ntets.node_start[v + 1] > ntets.node_start[v];
  const detail::CsrPattern& pat = sys.pat;
  sys.kval.assign(9 * pat.col.size(), 0.0);
  sys.load.assign(3 * nn, 0.0);
  parallel_for(nn, threads, [&](std::size_t b, std::size_t e, unsigned) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t v = b; v < e; ++v) {
      const std::size_t rs = pat.row_start[v], re = pat.row_start[v + 1];
      for (std::size_t i = ntets.node_start[v]; i < ntets.node_start[v + 1]; ++i) {
        const std::size_t t = ntets.item[i] >> 2;
        const unsigned a = ntets.item[i] & 3u;
        const double vol = detail::p1_gradients(mesh, t, g);
        const std::size_t r = co.tet_rix[t];
        // Thermal stress (3 lambda + 2 mu) alpha dT I against the gradient of the test function.
        const double sigma_th = (3 * co.lambda[r] + 2 * co.mu[r]) * co.expansion[r] * tet_dt[t] * vol;
        for (int c = 0; c < 3; ++c) sys.load[3 * v + c] += sigma_th * g[a][c];
        for (unsigned c = 0; c < 4; ++c) {
          const std::uint32_t col = mesh.tet[4 * t + c];
          std::size_t pos = rs;
          while (pos < re && pat.col[pos] != col) ++pos;
          add_block(&sys.kval[9 * pos], g[a], g[c], co.lambda[r] * vol, co.mu[r] * vol);
        }
      }
    }
  });
  return sys;
}

// The 10 solver nodes of tet t: its corners, then its mid-edge nodes in kTetEdge order.
std::array<std::uint32_t, 10> p2_nodes(const Mesh& mesh, const detail::TetEdges& edges, std::size_t t) {
  std::array<std::uint32_t, 10> n;
  for (int k = 0; k < 4; ++k) n[static_cast<std::size_t>(k)] = mesh.tet[4 * t + static_cast<std::size_t>(k)];
  for (int k = 0; k < 6; ++k)
    n[4 + static_cast<std::size_t>(k)] =
        static_cast<std::uint32_t>(mesh.node_count() + edges.tet_edge[6 * t + static_cast<std::size_t>(k)]);
  return n;
}

// Tet t's 10-node element stiffness (ke: 10 x 10 blocks of 3 x 3, block (a, b) at 9 (10 a + b)), its
// thermal load (fe: 3 per node) and the positions of its blocks in `pat` (pos, 100). The gradients
// are linear, so the stiffness (quadratic integrand) and the load with a P1 temperature (quadratic
// too) are exact with the degree-2 4-point Gauss rule.
void p2_element(const Mesh& mesh, const detail::TetEdges& edges, const ElasticCoefficients& co,
                const std::vector<double>& node_dt, const detail::CsrPattern& pat, std::size_t t, double* ke,
                double* fe, std::size_t* pos) {
  std::array<std::array<double, 3>, 4> g;
  std::array<std::array<double, 3>, 10> dn;
  const double vol = detail::p1_gradients(mesh, t, g);
  const auto nodes = p2_nodes(mesh, edges, t);
  for (std::size_t i = 0; i < 10; ++i)
    for (std::size_t j = 0; j < 10; ++j) pos[10 * i + j] = pat.find(nodes[i], nodes[j]);
  std::fill(ke, ke + 900, 0.0);
  std::fill(fe, fe + 30, 0.0);
  const std::size_t r = co.tet_rix[t];
  const double w = vol / 4, qa = 0.5854101966249685, qb = 0.1381966011250105;
  for (int q = 0; q < 4; ++q) {
    double l[4] = {qb, qb, qb, qb};
    l[q] = qa;
    for (std::size_t k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c) dn[k][c] = (4 * l[k] - 1) * g[k][c];
    for (std::size_t k = 0; k < 6; ++k) {
      const int i = detail::kTetEdge[k][0], j = detail::kTetEdge[k][1];
      for (int c = 0; c < 3; ++c) dn[4 + k][c] = 4 * (l[i] * g[j][c] + l[j] * g[i][c]);
    }
    double dt = 0;
    for (std::size_t k = 0; k < 4; ++k) dt += l[k] * node_dt[mesh.tet[4 * t + k]];
    const double sigma_th = (3 * co.lambda[r] + 2 * co.mu[r]) * co.expansion[r] * dt * w;
    for (std::size_t a = 0; a < 10; ++a) {
      for (std::size_t c = 0; c < 3; ++c) fe[3 * a + c] += sigma_th * dn[a][c];
      for (std::size_t b = 0; b < 10; ++b)
        add_block(&ke[9 * (10 * a + b)], dn[a], dn[b], co.lambda[r] * w, co.mu[r] * w);
    }
  }
}

// 10-node tets: N_i = L_i (2 L_i - 1) at the corners, N_ij = 4 L_i L_j at the edges.
BlockSystem assemble_p2(const Mesh& mesh, const detail::TetEdges& edges, const ElasticCoefficients& co,
                        const std::vector<double>& node_dt, const LinearSolverOptions& options,
                        unsigned threads) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), n = nn + edges.size();
  BlockSystem sys;
  sys.used.assign(n, 0);
  sys.xyz.resize(3 * n);
  std::copy(mesh.xyz.begin(), mesh.xyz.end(), sys.xyz.begin());
  for (std::size_t e = 0; e < edges.size(); ++e)
    for (std::size_t i = 0; i < 3; ++i)
      sys.xyz[3 * (nn + e) + i] =
          (mesh.xyz[3 * std::size_t{edges.a[e]} + i] + mesh.xyz[3 * std::size_t{edges.b[e]} + i]) / 2;
  // Pattern: the sorted distinct (row, column) pairs of the tets' 10 x 10 node couplings.
  std::vector<std::uint64_t> pairs;
  pairs.reserve(100 * nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto nodes = p2_nodes(mesh, edges, t);
    for (std::uint32_t r : nodes) {
      sys.used[r] = 1;
      for (std::uint32_t c : nodes) pairs.push_back((std::uint64_t{r} << 32) | c);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  detail::CsrPattern& pat = sys.pat;
  pat.row_start.assign(n + 1, 0);
  pat.col.resize(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    ++pat.row_start[(pairs[i] >> 32) + 1];
    pat.col[i] = static_cast<std::uint32_t>(pairs[i] & 0xffffffffu);
  }
  for (std::size_t r = 0; r < n; ++r) pat.row_start[r + 1] += pat.row_start[r];
  std::vector<std::uint64_t>().swap(pairs);
  sys.kval.assign(9 * pat.col.size(), 0.0);
  sys.load.assign(3 * n, 0.0);

  // Element matrices and loads in parallel batches, then added serially (a deterministic sum).
  constexpr std::size_t kBatch = 2048;
  const std::size_t batch = std::min(kBatch, nt);
  std::vector<double> ke(900 * batch), fe(30 * batch);  // 10 x 10 blocks of 3 x 3; 10 x 3
  std::vector<std::size_t> kpos(100 * batch);
  for (std::size_t t0 = 0; t0 < nt; t0 += batch) {
    const std::size_t nb = std::min(batch, nt - t0);
    detail::report_progress(options, "assemble", 0.4 * static_cast<double>(t0) / static_cast<double>(nt));
    parallel_for(
        nb, threads,
        [&](std::size_t b, std::size_t e, unsigned) {
          for (std::size_t i = b; i < e; ++i)
            p2_element(mesh, edges, co, node_dt, pat, t0 + i, &ke[900 * i], &fe[30 * i], &kpos[100 * i]);
        },
        256);
    for (std::size_t i = 0; i < nb; ++i) {
      const auto nodes = p2_nodes(mesh, edges, t0 + i);
      for (std::size_t k = 0; k < 100; ++k)
        for (std::size_t c = 0; c < 9; ++c) sys.kval[9 * kpos[100 * i + k] + c] += ke[900 * i + 9 * k + c];
      for (std::size_t k = 0; k < 10; ++k)
        for (std::size_t c = 0; c < 3; ++c) sys.load[3 * nodes[k] + c] += fe[30 * i + 3 * k + c];
    }
  }
  return sys;
}

// Sums of forces and of their moments about `centre` (moments divided by `extent`, so that both are
// forces), and the sum of the forces' magnitudes.
struct ForceSums {
  Vec3 force{0, 0, 0}, moment{0, 0, 0};
  double magnitude = 0;
  void add(const double* x, const Vec3& f, const Vec3& centre, double extent) {
    const Vec3 arm{(x[0] - centre[0]) / extent, (x[1] - centre[1]) / extent, (x[2] - centre[2]) / extent};
    const Vec3 m = cross(arm, f);
    for (int i = 0; i < 3; ++i) force[i] += f[i], moment[i] += m[i];
    magnitude += std::sqrt(dot(f, f));
  }
  double net() const { return std::max(std::sqrt(dot(force, force)), std::sqrt(dot(moment, moment))); }
};

// The nodal forces of the thermal strain, sum_tets int sigma_th grad N_a, sum to zero in force and
// moment (sum_a grad N_a = 0 at every point; sigma_th = c dT I is symmetric), whatever the mesh and
// the temperature: what is left is rounding. Summing n terms loses at most about n eps of their sum
// of magnitudes, 1e-9 at 10^7 nodes (random-sign rounding gives about sqrt(n) eps, 1e-13): a larger
// figure is an assembly error, not rounding. `load` is in global coordinates (before the rotation).
BalanceCheck thermal_load_check(const BlockSystem& sys, const Vec3& centre, double extent) {
  ForceSums s;
  for (std::size_t v = 0; v < sys.nodes(); ++v)
    if (sys.used[v])
      s.add(&sys.xyz[3 * v], {sys.load[3 * v], sys.load[3 * v + 1], sys.load[3 * v + 2]}, centre, extent);
  return make_check("thermal load",
                    "|net force and moment of the thermal strain's nodal forces| / their sum of magnitudes",
                    s.magnitude > 0 ? s.net() / s.magnitude : 0.0, 1e-9);
}

// Global equilibrium: with no applied forces (the thermal load is self-equilibrated), the reactions at
// the constrained nodes (K u - f in the constrained directions) must sum to zero in force and moment.
// Their net is minus the sum of the free rows' residuals (K's rows sum to zero against rigid motions),
// so it measures how far the solve is from equilibrium as a whole, against the forces in play (the
// thermal load's and the reactions' magnitudes). A converged CG solve (|r| <= tol |b|) leaves at most
// sqrt(n) tol |b|, in practice far less: the tolerance is 100 tol as for the heat balance, at least 1e-6
// (the rounding of a direct solve and of these sums is far below that) and at most 1e-3: a net support
// force of more than 0.1 % of the forces in the body is no equilibrium, whatever tolerance was asked.
// `in_frames`: `kval`, `load` and `u` are in the node frames (after solve_blocks' rotation), else in
// global coordinates. `precision` > 0: `u` was given rounded to that relative precision (ccx's .frd),
// and the tolerance takes in the largest net force that rounding can make, sum |K_vw| precision |u_w|
// over the constrained rows (rounding's net over all rows is zero: K's columns sum to zero).
BalanceCheck reaction_check(const BlockSystem& sys, const detail::NodeFrames& fr,
                            const std::vector<double>& u, bool in_frames, const Vec3& centre, double extent,
                            double tolerance, double precision, unsigned threads) {
  const std::size_t nn = sys.nodes();
  const detail::CsrPattern& pat = sys.pat;
  std::vector<double> reaction(3 * nn, 0.0), rounding(nn, 0.0);  // global coordinates
  parallel_for(nn, threads, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t v = b; v < e; ++v) {
      if (!sys.used[v] || fr.m[v] == 0) continue;
      double r[3];  // K u - f at v, in v's frame or global
      for (std::size_t i = 0; i < 3; ++i) {
        r[i] = -sys.load[3 * v + i];
        for (std::size_t p = pat.row_start[v]; p < pat.row_start[v + 1]; ++p) {
          const double* blk = &sys.kval[9 * p + 3 * i];
          const double* uw = &u[3 * std::size_t{pat.col[p]}];
          r[i] += blk[0] * uw[0] + blk[1] * uw[1] + blk[2] * uw[2];
          if (precision > 0)
            rounding[v] +=
                precision * (std::abs(blk[0] * uw[0]) + std::abs(blk[1] * uw[1]) + std::abs(blk[2] * uw[2]));
        }
      }
      for (int c = 0; c < fr.m[v]; ++c) {
        const double* axis = &fr.r[9 * v + 3 * static_cast<std::size_t>(c)];
        const double rc = in_frames ? r[c] : axis[0] * r[0] + axis[1] * r[1] + axis[2] * r[2];
        for (std::size_t i = 0; i < 3; ++i) reaction[3 * v + i] += rc * axis[i];
      }
    }
  });
  ForceSums s;
  double load = 0, rounded = 0;
  for (std::size_t v = 0; v < nn; ++v) {
    if (!sys.used[v]) continue;
    const double* f = &sys.load[3 * v];  // a rotation keeps its magnitude
    load += std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    rounded += rounding[v];
    if (fr.m[v])
      s.add(&sys.xyz[3 * v], {reaction[3 * v], reaction[3 * v + 1], reaction[3 * v + 2]}, centre, extent);
  }
  const double scale = load + s.magnitude;
  if (scale > 0) tolerance = std::max(tolerance, rounded / scale);
  return make_check("force balance",
                    "|net force and moment of the reactions at the constrained nodes| / (thermal load + "
                    "reactions)",
                    scale > 0 ? s.net() / scale : 0.0, tolerance);
}

// The middle of the used nodes' bounding box and its diagonal (the moments' centre and lever scale).
std::pair<Vec3, double> node_bounds(const BlockSystem& sys) {
  Vec3 centre{0, 0, 0}, lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t v = 0; v < sys.nodes(); ++v)
    for (std::size_t i = 0; i < 3 && sys.used[v]; ++i) {
      lo[i] = std::min(lo[i], sys.xyz[3 * v + i]);
      hi[i] = std::max(hi[i], sys.xyz[3 * v + i]);
    }
  for (int i = 0; i < 3; ++i) centre[i] = (lo[i] + hi[i]) / 2;
  return {centre, std::max(1e-300, std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]))};
}

// The tolerance of the force balance for a solve to relative residual `solver_tolerance` (above).
double force_balance_tolerance(double solver_tolerance) {
  return std::min(1e-3, std::max(1e-6, 100 * solver_tolerance));
}

// Rotates the constrained nodes' blocks into their frames, eliminates the constrained unknowns, solves
// the free system (AMG with the rigid-body modes of every solver node as near-null space) and returns
// the displacement of every solver node in global coordinates (NaN on unused ones).
std::vector<double> solve_blocks(BlockSystem& sys, const detail::NodeFrames& fr,
                                 const LinearSolverOptions& options, unsigned threads,
                                 ThermoelasticReport& rep) {
  const std::size_t nn = sys.nodes();
  const detail::CsrPattern& pat = sys.pat;
  std::vector<double>&kval = sys.kval, &load = sys.load;
  const std::vector<char>& used = sys.used;
  const auto [centre, extent] = node_bounds(sys);
  rep.checks.push_back(thermal_load_check(sys, centre, extent));
  // Rotate the constrained nodes' rows and columns into their frames.
  parallel_for(nn, threads, [&](std::size_t b, std::size_t e, unsigned) {
    for (std::size_t v = b; v < e; ++v) {
      const double* rv = fr.m[v] ? &fr.r[9 * v] : nullptr;
      for (std::size_t p = pat.row_start[v]; p < pat.row_start[v + 1]; ++p) {
        const std::uint32_t w = pat.col[p];
        rotate_block(&kval[9 * p], rv, fr.m[w] ? &fr.r[9 * w] : nullptr);
      }
      if (rv) {
        double f[3];
        for (int i = 0; i < 3; ++i)
          f[i] = rv[3 * i] * load[3 * v] + rv[3 * i + 1] * load[3 * v + 1] + rv[3 * i + 2] * load[3 * v + 2];
        std::copy(f, f + 3, &load[3 * v]);
      }
    }
  });

  // Free unknowns: local components m..2 of each used node, numbered node by node.
  std::vector<int> base(nn, -1);
  int nfree = 0;
  for (std::size_t v = 0; v < nn; ++v)
    if (used[v]) {
      base[v] = nfree;
      nfree += 3 - fr.m[v];
    }
  detail::SymmetricCsr a;
  std::vector<double> rhs(static_cast<std::size_t>(nfree));
  detail::NearNullSpace nns;
  nns.nodes = nn;
  nns.vectors = 6;
  nns.node.reserve(static_cast<std::size_t>(nfree));
  nns.values.reserve(6 * static_cast<std::size_t>(nfree));
  a.start.reserve(static_cast<std::size_t>(nfree) + 1);
  a.start.push_back(0);
  a.col.reserve(9 * pat.col.size());
  a.val.reserve(9 * pat.col.size());
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    const int mv = fr.m[v];
    // Rigid-body modes at v in global coordinates (3 x 6), then in the node's frame.
    const double x = (sys.xyz[3 * v] - centre[0]) / extent, y = (sys.xyz[3 * v + 1] - centre[1]) / extent,
                 z = (sys.xyz[3 * v + 2] - centre[2]) / extent;
    const double modes[3][6] = {{1, 0, 0, 0, z, -y}, {0, 1, 0, -z, 0, x}, {0, 0, 1, y, -x, 0}};
    for (int c = mv; c < 3; ++c) {
      double s = load[3 * v + c];
      for (std::size_t p = pat.row_start[v]; p < pat.row_start[v + 1]; ++p) {
        const std::uint32_t w = pat.col[p];
        const double* blk = &kval[9 * p + 3 * static_cast<std::size_t>(c)];
        for (int c2 = 0; c2 < fr.m[w]; ++c2) s -= blk[c2] * fr.g[3 * w + c2];
        for (int c2 = fr.m[w]; c2 < 3; ++c2) {
          a.col.push_back(base[w] + c2 - fr.m[w]);
          a.val.push_back(blk[c2]);
        }
      }
      a.start.push_back(static_cast<int>(a.col.size()));
      rhs[static_cast<std::size_t>(base[v] + c - mv)] = s;
      nns.node.push_back(static_cast<std::uint32_t>(v));
      for (int k = 0; k < 6; ++k) {
        double val = modes[c][k];
        if (mv) {
          const double* rv = &fr.r[9 * v + 3 * c];
          val = rv[0] * modes[0][k] + rv[1] * modes[1][k] + rv[2] * modes[2][k];
        }
        nns.values.push_back(val);
      }
    }
  }
  rep.unknowns = static_cast<std::size_t>(nfree);
  rep.nonzeros = a.val.size();
  for (std::size_t v = 0; v < nn; ++v) rep.constrained_nodes += fr.m[v] > 0;
  detail::report_progress(options, "assemble", 1.0);

  std::vector<double> x;
  const auto t_solve = std::chrono::steady_clock::now();
  const detail::LinearSolveResult lin = detail::solve_spd(a, rhs, x, options, &nns);
  rep.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_solve).count();
  rep.solver = lin.solver;
  rep.iterations = lin.iterations;
  rep.relative_residual = lin.relative_residual;
  rep.amg_levels = lin.levels;

  // Displacements in the node frames (0 on unused nodes), then back in global coordinates.
  std::vector<double> local(3 * nn, 0.0);
  std::vector<double> u(3 * nn, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    const int mv = fr.m[v];
    double* l = &local[3 * v];
    for (int c = 0; c < 3; ++c)
      l[c] = c < mv ? fr.g[3 * v + c] : x[static_cast<std::size_t>(base[v] + c - mv)];
    for (int i = 0; i < 3; ++i)
      u[3 * v + i] =
          mv ? fr.r[9 * v + i] * l[0] + fr.r[9 * v + 3 + i] * l[1] + fr.r[9 * v + 6 + i] * l[2] : l[i];
  }
  rep.checks.push_back(reaction_check(sys, fr, local, true, centre, extent,
                                      force_balance_tolerance(options.relative_tolerance), 0, threads));
  return u;
}

// Lame's lambda and mu per region from E and nu.
std::pair<std::vector<double>, std::vector<double>> lame_parameters(const std::vector<double>& young,
                                                                    const std::vector<double>& poisson) {
  std::vector<double> lambda(young.size()), mu(young.size());
  for (std::size_t i = 0; i < young.size(); ++i) {
    mu[i] = young[i] / (2 * (1 + poisson[i]));
    lambda[i] = young[i] * poisson[i] / ((1 + poisson[i]) * (1 - 2 * poisson[i]));
  }
  return {lambda, mu};
}

// The displacement `u` (3 per solver node: the mesh's, then for order 2 the mid-edge nodes of
// `edges`) into the report: the largest displacement, stress, von Mises and principal stresses per
// tet, per-region and per-interface maxima; stores the fields. `error`: the displacements' relative
// round-off (or a printout's precision), for the resolution check.
void finish_report(Mesh& mesh, const ThermoelasticParams& params, const detail::TetEdges& edges,
                   const detail::ElasticMaterials& mat, const std::vector<double>& tet_dt,
                   const std::vector<char>& used, std::vector<double> u, double error, unsigned threads,
                   ThermoelasticReport& rep) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  const detail::RegionTable& regions = mat.regions;
  const std::vector<double>&young = mat.young, &poisson = mat.poisson, &expansion = mat.expansion;
  const std::size_t nr = regions.size();
  const auto [lame_lambda, lame_mu] = lame_parameters(young, poisson);
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    const double len =
        std::sqrt(u[3 * v] * u[3 * v] + u[3 * v + 1] * u[3 * v + 1] + u[3 * v + 2] * u[3 * v + 2]);
    if (len >= rep.max_displacement) {
      rep.max_displacement = len;
      rep.max_displacement_node = static_cast<std::uint32_t>(v);
    }
  }

  // Stress, von Mises and principal stresses per tet.
  Field stress{"stress", FieldLocation::cell, 6, "Pa", {}, std::vector<double>(6 * nt)};
  Field mises{"von_mises", FieldLocation::cell, 1, "Pa", {}, std::vector<double>(nt)};
  Field principal{"principal_stress", FieldLocation::cell, 3, "Pa", {}, std::vector<double>(3 * nt)};
  // Per thread, the largest bound of a tet's von Mises error from its displacements' error: the
  // displacement gradient errs by at most error * sum_a |u_a| |g_a|, von Mises (deviatoric: lambda,
  // 166 E at nu = 0.499, and the isotropic thermal strain do not enter) by 3 mu times that. Where
  // moduli differ by 1e14 the stiff part's displacements cannot carry its stress (1128 Pa against
  // about 628, the force balance passing; an outside probe). `measured`: the largest von Mises that
  // is a stress, not noise: over 100 times its tet's bound (known to 1%) and over 1e-7 of its tet's
  // thermal stress scale 3 mu |alpha dT| (a body free to expand is stress-free to round-off: 4e-5 Pa
  // of noise in a polymer layer on a metal one, from the solve, above that layer's own tiny bound;
  // an outside probe).
  std::vector<double> worst_bound(threads, 0.0), measured(threads, 0.0);
  parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned thread) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t t = b; t < e; ++t) {
      (void)detail::p1_gradients(mesh, t, g);
      // Displacement gradient (P2: at the centroid, where the corner functions have zero gradient and
      // the edge function ij has g_i + g_j; the gradient is linear, so this is also its tet mean).
      double h[3][3] = {}, size = 0;  // size: sum |u| |g| over the terms of h
      auto norm = [](const double* x) { return std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]); };
      if (params.order == 1) {
        for (int a2 = 0; a2 < 4; ++a2) {
          const double* ua = &u[3 * std::size_t{mesh.tet[4 * t + a2]}];
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) h[i][j] += ua[i] * g[a2][j];
          size += norm(ua) * norm(g[a2].data());
        }
      } else {
        for (std::size_t k = 0; k < 6; ++k) {
          const double* ue = &u[3 * (nn + edges.tet_edge[6 * t + k])];
          const auto& gi = g[static_cast<std::size_t>(detail::kTetEdge[k][0])];
          const auto& gj = g[static_cast<std::size_t>(detail::kTetEdge[k][1])];
          const double gij[3] = {gi[0] + gj[0], gi[1] + gj[1], gi[2] + gj[2]};
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) h[i][j] += ue[i] * gij[j];
          size += norm(ue) * norm(gij);
        }
      }
      const std::size_t r = regions.tet_rix[t];
      const double th = expansion[r] * tet_dt[t];
      const double tet_bound = error * 3 * lame_mu[r] * size;
      worst_bound[thread] = std::max(worst_bound[thread], tet_bound);
      const double exx = h[0][0] - th, eyy = h[1][1] - th, ezz = h[2][2] - th;
      const double lam = lame_lambda[r], mu = lame_mu[r], tr = exx + eyy + ezz;
      double* s = &stress.values[6 * t];
      s[0] = lam * tr + 2 * mu * exx;
      s[1] = lam * tr + 2 * mu * eyy;
      s[2] = lam * tr + 2 * mu * ezz;
      s[3] = mu * (h[0][1] + h[1][0]);
      s[4] = mu * (h[1][2] + h[2][1]);
      s[5] = mu * (h[0][2] + h[2][0]);
      mises.values[t] = std::sqrt(0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) +
                                         (s[2] - s[0]) * (s[2] - s[0])) +
                                  3 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
      if (mises.values[t] > 100 * tet_bound && mises.values[t] > 1e-7 * 3 * lame_mu[r] * std::abs(th))
        measured[thread] = std::max(measured[thread], mises.values[t]);
      Eigen::Matrix3d m;
      m << s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2];
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m, Eigen::EigenvaluesOnly);
      for (int i = 0; i < 3; ++i) principal.values[3 * t + i] = eig.eigenvalues()[2 - i];
    }
  });

  // Per-region and per-interface maxima.
  {
    std::vector<double> region_volume;
    const std::vector<double> vol = detail::tet_volumes(mesh, regions, threads, region_volume);
    rep.regions.resize(nr);
    for (std::size_t i = 0; i < nr; ++i)
      rep.regions[i] = {regions.ids[i], region_volume[i], young[i], poisson[i], expansion[i], -1.0, kNone};
    for (std::size_t t = 0; t < nt; ++t) {
      RegionStress& r = rep.regions[regions.tet_rix[t]];
      if (mises.values[t] > r.max_von_mises) {
        r.max_von_mises = mises.values[t];
        r.max_tet = static_cast<std::uint32_t>(t);
      }
    }
    rep.max_von_mises = -1;
    for (const RegionStress& r : rep.regions)
      if (r.max_von_mises > rep.max_von_mises) {
        rep.max_von_mises = r.max_von_mises;
        rep.max_tet = r.max_tet;
      }
  }
  if (nr > 1) {
    const FaceAdjacency& adj = face_adjacency(mesh);
    std::map<std::pair<std::int32_t, std::int32_t>, InterfaceStress> found;
    for (std::size_t t = 0; t < nt; ++t)
      for (int f = 0; f < 4; ++f) {
        const std::uint32_t nb = adj.neighbour[4 * t + f];
        if (nb == kNone) continue;
        const std::size_t o = nb >> 2;
        const std::int32_t ra = mesh.region_of(t), rb = mesh.region_of(o);
        if (ra == rb || o < t) continue;
        InterfaceStress& s = found[{std::min(ra, rb), std::max(ra, rb)}];
        s.region_a = std::min(ra, rb);
        s.region_b = std::max(ra, rb);
        Vec3 p[3];
        for (int k = 0, j = 0; k < 4; ++k)
          if (k != f) p[j++] = point(mesh, mesh.tet[4 * t + k]);
        const Vec3 n = cross({p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]},
                             {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]});
        s.area += 0.5 * std::sqrt(dot(n, n));
        for (std::size_t side : {t, o})
          if (s.max_tet == kNone || mises.values[side] > s.max_von_mises) {
            s.max_von_mises = mises.values[side];
            s.max_tet = static_cast<std::uint32_t>(side);
          }
      }
    for (auto& [key, s] : found) rep.interfaces.push_back(s);
  }

  // The bound adds every term's error with one sign: tens to hundreds of times the error seen (moduli
  // 1e14 apart in series: bound 1.3 of the largest stress, error 0.8; 1e12 apart: 0.013, error 3e-4),
  // against the largest von Mises measured; none measured: stress-free to round-off. An iterative
  // solve's residual is the force balance's to see.
  const double bound = *std::max_element(worst_bound.begin(), worst_bound.end());
  const double largest = *std::max_element(measured.begin(), measured.end());
  rep.checks.push_back(
      make_check("resolution",
                 "largest round-off bound of a tet's von Mises stress (the displacements' "
                 "round-off times 3 mu sum |u_a| |g_a|) / the largest von Mises stress above "
                 "its bound: too large where moduli differ by many orders",
                 largest > 0 ? bound / largest : 0.0, 1e-2));

  u.resize(3 * nn);  // the mesh's nodes only
  Field disp{"displacement", FieldLocation::node, 3, "m", {}, std::move(u)};
  detail::set_field(mesh, std::move(disp));
  detail::set_field(mesh, std::move(stress));
  detail::set_field(mesh, std::move(mises));
  detail::set_field(mesh, std::move(principal));
}

// Node-block stiffness with the thermal load; the constraints per solver node (fixed components and
// sliding normals, orthonormalised into node frames; for P2 from the boundary split through the
// mid-edge nodes, so a mid-edge node gets the constraints of the tagged triangles it lies on).
void build_system(const Mesh& mesh, const ThermoelasticParams& params, const ElasticCoefficients& co,
                  const std::vector<double>& tet_dt, unsigned threads, BlockSystem& sys,
                  detail::NodeFrames& fr, detail::TetEdges& edges) {
  const std::size_t nn = mesh.node_count();
  if (params.order == 1) {
    sys = assemble_p1(mesh, co, tet_dt, threads);
    detail::report_progress(params.solver, "assemble", 0.4);
    fr = detail::displacement_frames(mesh, params, sys.used);
  } else {
    edges = detail::tet_edges(mesh);
    std::vector<double> node_dt(nn, params.delta_t);
    if (!params.temperature.empty())  // sizes and values on used nodes checked by tet_temperature_change
      for (std::size_t v = 0; v < nn; ++v) node_dt[v] = params.temperature[v] - params.reference_temperature;
    sys = assemble_p2(mesh, edges, co, node_dt, params.solver, threads);
    detail::report_progress(params.solver, "assemble", 0.4);
    fr = detail::displacement_frames(detail::quadratic_boundary(mesh, edges), params, sys.used);
  }
}

}  // namespace

ThermoelasticReport solve_thermoelastic(Mesh& mesh, const ThermoelasticParams& params) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  if (params.order != 1 && params.order != 2)
    throw SolverInputError("thermoelastic element order must be 1 or 2, not " + std::to_string(params.order));
  detail::check_mesh(mesh);
  const unsigned threads = detail::thread_count(params.solver.threads);
  detail::report_progress(params.solver, "assemble", 0.0);

  const detail::ElasticMaterials mat = detail::elastic_materials(mesh, params);
  const detail::RegionTable& regions = mat.regions;
  const std::vector<double>&young = mat.young, &poisson = mat.poisson, &expansion = mat.expansion;
  const auto [lame_lambda, lame_mu] = lame_parameters(young, poisson);
  const std::vector<double> tet_dt = detail::tet_temperature_change(mesh, params);
  {
    std::vector<double> region_volume;
    (void)detail::tet_volumes(mesh, regions, threads, region_volume);  // rejects flat and inverted tets
  }
  const ElasticCoefficients co{lame_lambda, lame_mu, expansion, regions.tet_rix};

  BlockSystem sys;
  detail::NodeFrames fr;
  detail::TetEdges edges;
  build_system(mesh, params, co, tet_dt, threads, sys, fr, edges);
  check_rigid_modes(mesh, fr, sys.used);  // the mesh's nodes come first among the solver nodes
  ThermoelasticReport rep;
  std::vector<double> u = solve_blocks(sys, fr, params.solver, threads, rep);
  // Assembly: everything before the linear solve, the elimination of the constraints included.
  rep.assembly_seconds =
      std::max(0.0, std::chrono::duration<double>(clock::now() - t_start).count() - rep.solve_seconds);
  finish_report(mesh, params, edges, mat, tet_dt, sys.used, std::move(u),
                4 * std::numeric_limits<double>::epsilon(), threads, rep);
  return rep;
}

ThermoelasticReport thermoelastic_report(Mesh& mesh, const ThermoelasticParams& params,
                                         std::vector<double> displacement, double precision) {
  if (params.order != 1 && params.order != 2)
    throw SolverInputError("thermoelastic element order must be 1 or 2, not " + std::to_string(params.order));
  detail::check_mesh(mesh);
  const std::size_t nn = mesh.node_count();
  const unsigned threads = detail::thread_count(params.solver.threads);
  const detail::ElasticMaterials mat = detail::elastic_materials(mesh, params);
  const std::vector<double> tet_dt = detail::tet_temperature_change(mesh, params);
  {
    std::vector<double> region_volume;
    (void)detail::tet_volumes(mesh, mat.regions, threads, region_volume);  // rejects flat and inverted tets
  }
  const auto [lame_lambda, lame_mu] = lame_parameters(mat.young, mat.poisson);
  const ElasticCoefficients co{lame_lambda, lame_mu, mat.expansion, mat.regions.tet_rix};
  BlockSystem sys;  // for the checks
  detail::NodeFrames fr;
  detail::TetEdges edges;
  build_system(mesh, params, co, tet_dt, threads, sys, fr, edges);
  const std::size_t solver_nodes = nn + edges.size();
  if (displacement.size() != 3 * solver_nodes)
    throw SolverInputError("thermoelastic_report: " + std::to_string(displacement.size()) +
                           " displacement values for " + std::to_string(solver_nodes) +
                           " nodes of 3 components");
  std::vector<char> used(solver_nodes, 0);
  for (std::uint32_t v : mesh.tet) used[v] = 1;
  for (std::size_t e = 0; e < edges.size(); ++e) used[nn + e] = 1;
  for (std::size_t v = 0; v < solver_nodes; ++v)
    if (used[v])
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(displacement[3 * v + c]))
          throw SolverInputError("thermoelastic_report: node " + std::to_string(v) +
                                 " of a tet has no displacement");
  ThermoelasticReport rep;
  rep.solver = "given";
  // The checks of solve_thermoelastic; the solve was another program's (a direct one: rounding only).
  const auto [centre, extent] = node_bounds(sys);
  rep.checks.push_back(thermal_load_check(sys, centre, extent));
  rep.checks.push_back(reaction_check(sys, fr, displacement, false, centre, extent,
                                      force_balance_tolerance(0), precision, threads));
  finish_report(mesh, params, edges, mat, tet_dt, used, std::move(displacement),
                4 * std::numeric_limits<double>::epsilon() + std::max(precision, 0.0), threads, rep);
  return rep;
}

}  // namespace foxi
