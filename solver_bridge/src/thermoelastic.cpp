// Linear thermoelasticity with P1 tets (see thermoelastic.hpp). The stiffness is assembled in 3x3
// node blocks row by row over the node adjacency pattern (each thread owns whole rows: no locks and a
// deterministic sum). Constraints are per node: the fixed components and the normals of sliding planes
// are orthonormalised into a local frame whose first m axes are constrained; the node's blocks are
// rotated into that frame (R K R^T), so every constraint becomes a fixed unknown that is eliminated.
// The well-posedness check counts, per connected part, the rigid-body motions that no constraint
// resists (the null space of the 6x6 Gram matrix of the constraints' rigid-body rows).
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

using detail::parallel_for;
using detail::region_label;
using detail::Vec3;
using detail::cross;
using detail::dot;
using detail::point;

// B <- R_left B R_right^T for 3x3 row-major blocks (either rotation may be null: identity).
void rotate_block(double* b, const double* left, const double* right) {
  double t[9];
  if (left) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) t[3 * i + j] = left[3 * i] * b[j] + left[3 * i + 1] * b[3 + j] + left[3 * i + 2] * b[6 + j];
    std::copy(t, t + 9, b);
  }
  if (right) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        t[3 * i + j] = b[3 * i] * right[3 * j] + b[3 * i + 1] * right[3 * j + 1] + b[3 * i + 2] * right[3 * j + 2];
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
      std::snprintf(text, sizeof text, "%s (%.3g, %.3g, %.3g)", t >= w ? "translation along" : "rotation about",
                    dir[0], dir[1], dir[2]);
      modes += (modes.empty() ? "" : "; ") + std::string(text);
    }
    if (left == 0) continue;
    std::size_t tet = 0;
    while (root(mesh.tet[4 * tet]) != r) ++tet;
    throw SolverError("ill-posed thermoelastic problem: the connected part containing tet " + std::to_string(tet) +
                      " (" + region_label(mesh, mesh.region_of(tet)) + ") can still move rigidly, " +
                      std::to_string(left) + " rigid-body mode" + (left > 1 ? "s" : "") + " left (" + modes +
                      "); fix displacements or add sliding planes that hold it");
  }
}

}  // namespace

ThermoelasticReport solve_thermoelastic(Mesh& mesh, const ThermoelasticParams& params) {
  using clock = std::chrono::steady_clock;
  const auto t_start = clock::now();
  detail::check_mesh(mesh);
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  const unsigned threads = detail::thread_count(params.solver.threads);
  detail::report_progress(params.solver, "assemble", 0.0);

  const detail::ElasticMaterials mat = detail::elastic_materials(mesh, params);
  const detail::RegionTable& regions = mat.regions;
  const std::vector<double>&young = mat.young, &poisson = mat.poisson, &expansion = mat.expansion;
  const std::size_t nr = regions.size();
  std::vector<double> lame_lambda(nr), lame_mu(nr);
  for (std::size_t i = 0; i < nr; ++i) {
    lame_mu[i] = young[i] / (2 * (1 + poisson[i]));
    lame_lambda[i] = young[i] * poisson[i] / ((1 + poisson[i]) * (1 - 2 * poisson[i]));
  }
  const std::vector<double> tet_dt = detail::tet_temperature_change(mesh, params);

  // Node adjacency and the node-block stiffness with the thermal load, row by row.
  const detail::NodeTets ntets = detail::node_tets(mesh);
  const detail::CsrPattern pat = detail::node_pattern(mesh, ntets, threads);
  std::vector<char> used(nn, 0);
  for (std::size_t v = 0; v < nn; ++v) used[v] = ntets.node_start[v + 1] > ntets.node_start[v];
  {
    std::vector<double> region_volume;
    (void)detail::tet_volumes(mesh, regions, threads, region_volume);  // rejects flat and inverted tets
  }
  std::vector<double> kval(9 * pat.col.size(), 0.0), load(3 * nn, 0.0);
  parallel_for(nn, threads, [&](std::size_t b, std::size_t e, unsigned) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t v = b; v < e; ++v) {
      const std::size_t rs = pat.row_start[v], re = pat.row_start[v + 1];
      for (std::size_t i = ntets.node_start[v]; i < ntets.node_start[v + 1]; ++i) {
        const std::size_t t = ntets.item[i] >> 2;
        const unsigned a = ntets.item[i] & 3u;
        const double vol = detail::p1_gradients(mesh, t, g);
        const std::size_t r = regions.tet_rix[t];
        const double lam = lame_lambda[r] * vol, mu = lame_mu[r] * vol;
        // Thermal stress (3 lambda + 2 mu) alpha dT I against the gradient of the test function.
        const double sigma_th = (3 * lame_lambda[r] + 2 * lame_mu[r]) * expansion[r] * tet_dt[t] * vol;
        for (int c = 0; c < 3; ++c) load[3 * v + c] += sigma_th * g[a][c];
        for (unsigned c = 0; c < 4; ++c) {
          const std::uint32_t col = mesh.tet[4 * t + c];
          std::size_t pos = rs;
          while (pos < re && pat.col[pos] != col) ++pos;
          double* blk = &kval[9 * pos];
          const auto& ga = g[a];
          const auto& gc = g[c];
          const double gg = ga[0] * gc[0] + ga[1] * gc[1] + ga[2] * gc[2];
          for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y)
              blk[3 * x + y] += lam * ga[x] * gc[y] + mu * ga[y] * gc[x] + (x == y ? mu * gg : 0.0);
        }
      }
    }
  });
  detail::report_progress(params.solver, "assemble", 0.4);

  // Constraints per node: fixed components and sliding normals, orthonormalised into node frames.
  const detail::NodeFrames fr = detail::displacement_frames(mesh, params, used);
  check_rigid_modes(mesh, fr, used);

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
        for (int i = 0; i < 3; ++i) f[i] = rv[3 * i] * load[3 * v] + rv[3 * i + 1] * load[3 * v + 1] + rv[3 * i + 2] * load[3 * v + 2];
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
  Vec3 centre{0, 0, 0}, lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t v = 0; v < nn; ++v)
    for (int i = 0; i < 3 && used[v]; ++i) {
      lo[i] = std::min(lo[i], mesh.xyz[3 * v + i]);
      hi[i] = std::max(hi[i], mesh.xyz[3 * v + i]);
    }
  for (int i = 0; i < 3; ++i) centre[i] = (lo[i] + hi[i]) / 2;
  const double extent = std::max(1e-300, std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    const int mv = fr.m[v];
    // Rigid-body modes at v in global coordinates (3 x 6), then in the node's frame.
    const double x = (mesh.xyz[3 * v] - centre[0]) / extent, y = (mesh.xyz[3 * v + 1] - centre[1]) / extent,
                 z = (mesh.xyz[3 * v + 2] - centre[2]) / extent;
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
  ThermoelasticReport rep;
  rep.unknowns = static_cast<std::size_t>(nfree);
  rep.nonzeros = a.val.size();
  for (std::size_t v = 0; v < nn; ++v) rep.constrained_nodes += fr.m[v] > 0;
  detail::report_progress(params.solver, "assemble", 1.0);
  const auto t_assembled = clock::now();

  std::vector<double> x;
  const detail::LinearSolveResult lin = detail::solve_spd(a, rhs, x, params.solver, &nns);
  rep.solver = lin.solver;
  rep.iterations = lin.iterations;
  rep.relative_residual = lin.relative_residual;
  rep.amg_levels = lin.levels;
  const auto t_solved = clock::now();

  // Displacements back in global coordinates.
  std::vector<double> u(3 * nn, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t v = 0; v < nn; ++v) {
    if (!used[v]) continue;
    const int mv = fr.m[v];
    double local[3];
    for (int c = 0; c < 3; ++c)
      local[c] = c < mv ? fr.g[3 * v + c] : x[static_cast<std::size_t>(base[v] + c - mv)];
    for (int i = 0; i < 3; ++i)
      u[3 * v + i] = mv ? fr.r[9 * v + i] * local[0] + fr.r[9 * v + 3 + i] * local[1] + fr.r[9 * v + 6 + i] * local[2]
                        : local[i];
    const double len = std::sqrt(u[3 * v] * u[3 * v] + u[3 * v + 1] * u[3 * v + 1] + u[3 * v + 2] * u[3 * v + 2]);
    if (len >= rep.max_displacement) {
      rep.max_displacement = len;
      rep.max_displacement_node = static_cast<std::uint32_t>(v);
    }
  }

  // Stress, von Mises and principal stresses per tet.
  Field stress{"stress", FieldLocation::cell, 6, "Pa", {}, std::vector<double>(6 * nt)};
  Field mises{"von_mises", FieldLocation::cell, 1, "Pa", {}, std::vector<double>(nt)};
  Field principal{"principal_stress", FieldLocation::cell, 3, "Pa", {}, std::vector<double>(3 * nt)};
  parallel_for(nt, threads, [&](std::size_t b, std::size_t e, unsigned) {
    std::array<std::array<double, 3>, 4> g;
    for (std::size_t t = b; t < e; ++t) {
      (void)detail::p1_gradients(mesh, t, g);
      double h[3][3] = {};
      for (int a2 = 0; a2 < 4; ++a2) {
        const double* ua = &u[3 * std::size_t{mesh.tet[4 * t + a2]}];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) h[i][j] += ua[i] * g[a2][j];
      }
      const std::size_t r = regions.tet_rix[t];
      const double th = expansion[r] * tet_dt[t];
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

  Field disp{"displacement", FieldLocation::node, 3, "m", {}, std::move(u)};
  detail::set_field(mesh, std::move(disp));
  detail::set_field(mesh, std::move(stress));
  detail::set_field(mesh, std::move(mises));
  detail::set_field(mesh, std::move(principal));
  rep.assembly_seconds = std::chrono::duration<double>(t_assembled - t_start).count();
  rep.solve_seconds = std::chrono::duration<double>(t_solved - t_assembled).count();
  return rep;
}

}  // namespace foxi
