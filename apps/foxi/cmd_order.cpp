// foxi order MESH: the visibility order of the tets for one or many views, verified.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "cli.hpp"
#include "exit_codes.hpp"
#include "mesh_input.hpp"
#include "solve_options.hpp"
#include "foxi/model/delaunay.hpp"
#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/picture.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/view_options.hpp"
#include "foxi/viz/visibility_order.hpp"

namespace foxi::cli {

namespace {

const char* kOrderUsage =
    "foxi order MESH (--eye x,y,z | --dir x,y,z | --views N) [--subset SPEC] [--front-to-back]\n"
    "                [--method auto|power|mpvo|centroid] [--seed S] [--check]\n"
    "  Orders the tets back to front for each view and counts ordering violations: face-adjacent\n"
    "  pairs drawn in the wrong order (exact orientation tests). Prints the time per view.\n"
    "  --eye x,y,z     a perspective eye point (may be inside the mesh)\n"
    "  --dir x,y,z     an orthographic view direction (from the eye into the scene)\n"
    "  --views N       N random views: half eye points (inside and around the bounding box),\n"
    "                  half directions\n"
    "  --subset SPEC   order only some tets: regions:1,3 | random:FRACTION | box:x0,y0,z0,x1,y1,z1\n"
    "                  (tets whose centroid lies in the box)\n"
    "  --method        auto (default): power order if the mesh is Delaunay (certificate), MPVO\n"
    "                  otherwise; power, mpvo, centroid (the VTK-style baseline) force one\n"
    "  --check         exit status 4 (a result that failed its own check) if any view has a violation\n"
    "  The mesh is validated first: inverted tets are re-oriented (a note says so), an unusable\n"
    "  mesh (see foxi info) is refused with exit status 3.";

}  // namespace

int cmd_order(Args args) {
  if (args.flag("--help") || args.flag("-h")) {
    std::puts(kOrderUsage);
    return kExitOk;
  }
  const std::string eye_s = args.option("--eye"), dir_s = args.option("--dir"),
                    views_s = args.option("--views");
  const std::string subset_s = args.option("--subset"), method = args.option("--method", "auto");
  // Whole numbers or a usage error naming the option (std::stoi said "stoi" with exit 1, and read
  // "1e3" as 1 and "12abc" as 12; an outside probe).
  std::int32_t seed_value = 0;
  const std::string seed_s = args.option("--seed", "1");
  if (!parse_int(seed_s, seed_value) || seed_value < 0)
    throw UsageError("--seed takes a whole number from 0 to 2147483647, not '" + seed_s + "'");
  const auto seed = static_cast<unsigned>(seed_value);
  const bool ftb = args.flag("--front-to-back"), check = args.flag("--check");
  const std::string path = args.positional(1, 1, kOrderUsage)[0];
  if (int(!eye_s.empty()) + int(!dir_s.empty()) + int(!views_s.empty()) != 1)
    throw UsageError("give exactly one of --eye, --dir, --views\nusage: " + std::string(kOrderUsage));
  if (method != "auto" && method != "power" && method != "mpvo" && method != "centroid")
    throw UsageError("--method takes auto, power, mpvo or centroid");

  const Mesh mesh = read_usable_mesh(path, "order");
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < mesh.node_count(); ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.xyz[3 * i + k]);
      hi[k] = std::max(hi[k], mesh.xyz[3 * i + k]);
    }

  std::vector<View> views;
  if (!eye_s.empty()) {
    auto e = parse_numbers(eye_s, "--eye");
    if (e.size() != 3) throw UsageError("--eye takes x,y,z");
    views.push_back(View::at(e[0], e[1], e[2]));
  } else if (!dir_s.empty()) {
    auto d = parse_numbers(dir_s, "--dir");
    if (d.size() != 3 || (d[0] == 0 && d[1] == 0 && d[2] == 0))
      throw UsageError("--dir takes a nonzero x,y,z");
    views.push_back(View::along(d[0], d[1], d[2]));
  } else {
    std::int32_t n = 0;
    if (!parse_int(views_s, n) || n < 1 || n > 1000000)
      throw UsageError("--views takes a whole number from 1 to 1000000, not '" + views_s + "'");
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::normal_distribution<double> g(0, 1);
    double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                            (hi[2] - lo[2]) * (hi[2] - lo[2]));
    for (int i = 0; i < n; ++i) {
      if (i % 2 == 0) {
        // Eye points: every other one inside the bounding box, the rest 1 to 3 diagonals away.
        double p[3];
        if (i % 4 == 0) {
          for (int k = 0; k < 3; ++k) p[k] = lo[k] + u(rng) * (hi[k] - lo[k]);
        } else {
          double d[3] = {g(rng), g(rng), g(rng)};
          double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
          double r = diag * (1 + 2 * u(rng));
          for (int k = 0; k < 3; ++k) p[k] = 0.5 * (lo[k] + hi[k]) + r * d[k] / len;
        }
        views.push_back(View::at(p[0], p[1], p[2]));
      } else {
        views.push_back(View::along(g(rng), g(rng), g(rng)));
      }
    }
  }

  std::vector<std::uint32_t> subset;
  if (!subset_s.empty()) subset = parse_subset(mesh, subset_s, seed + 7);

  auto t0 = std::chrono::steady_clock::now();
  const DelaunayCertificate cert = compute_delaunay_certificate(mesh);
  auto t1 = std::chrono::steady_clock::now();
  const SphereTable table = compute_spheres(mesh);
  auto t2 = std::chrono::steady_clock::now();
  std::string use = method;
  if (use == "auto") use = safe_order_method(cert) == OrderMethod::power ? "power" : "mpvo";
  std::printf("mesh        %s: %zu tets, %zu ordered\n", path.c_str(), mesh.tet_count(),
              subset.empty() ? mesh.tet_count() : subset.size());
  std::printf("certificate %s (%zu of %zu tets violated, %.1f ms)\n",
              cert.delaunay ? (cert.weighted ? "regular (weighted Delaunay)" : "Delaunay") : "NOT Delaunay",
              cert.violating_tet_count, mesh.tet_count(),
              std::chrono::duration<double, std::milli>(t1 - t0).count());
  std::printf(
      "precompute  %.1f ms: %zu cospherical clusters holding %zu tets, %zu centres recomputed exactly, "
      "%zu flat tets\n",
      std::chrono::duration<double, std::milli>(t2 - t1).count(), table.cluster_count(),
      table.cluster_tets.size(), table.recomputed_exactly, table.flat_count);
  std::printf("method      %s%s\n", use.c_str(),
              use == "mpvo" ? " (face-adjacency topological sort seeded by the power order)" : "");
  if (!cert.delaunay && use == "power")
    std::printf(
        "warning     the mesh is not Delaunay: the power order is not guaranteed to be a visibility order\n");

  std::size_t total_violations = 0;
  double total_ms = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const View& v = views[i];
    std::vector<std::uint32_t> order;
    OrderStats stats;
    std::size_t cycles = 0;
    auto a = std::chrono::steady_clock::now();
    if (use == "power") {
      order = visibility_order(mesh, table, v, subset, ftb, &stats);
    } else if (use == "mpvo") {
      order = mpvo_order(mesh, table, v, subset, &cycles);
      if (ftb) std::reverse(order.begin(), order.end());
    } else {
      order = centroid_order(mesh, v, subset);
      if (ftb) std::reverse(order.begin(), order.end());
    }
    auto b = std::chrono::steady_clock::now();
    double ms = std::chrono::duration<double, std::milli>(b - a).count();
    total_ms += ms;
    if (ftb) std::reverse(order.begin(), order.end());  // violations are counted back to front
    ViolationReport r = count_violations(mesh, v, order);
    total_violations += r.violations;
    if (v.perspective)
      std::printf("view %3zu  eye (%g, %g, %g)", i + 1, v.eye[0], v.eye[1], v.eye[2]);
    else
      std::printf("view %3zu  dir (%g, %g, %g)", i + 1, v.dir[0], v.dir[1], v.dir[2]);
    std::printf("  %zu violations of %zu face pairs  %.2f ms", r.violations, r.pairs_checked, ms);
    if (use == "power")
      std::printf("  (%zu near-tie runs of %zu items, bound %.2g of the key range, %zu wide)",
                  stats.near_tie_runs, stats.near_tie_items,
                  stats.key_range > 0 ? stats.key_bound / stats.key_range : 0.0, stats.wide_items);
    if (use == "mpvo") std::printf("  (%zu cycles broken)", cycles);
    std::printf("\n");
  }
  std::printf("total       %zu violations over %zu views, %.2f ms per view\n", total_violations, views.size(),
              total_ms / double(views.size()));
  return check && total_violations > 0 ? kExitUnreliable : kExitOk;
}

}  // namespace foxi::cli
