// Fuzz target: any small mesh through validation, the Delaunay certificate, the visibility order and
// a small render. The input decodes to up to 16 nodes (on a lattice at one of several scales, or raw
// doubles), up to 24 tets naming them, optional regions and vertex weights, and a view. A mesh that
// validation refuses stops there; one it accepts (re-oriented) must then go through the rest without
// a crash, a hang or an exception, and the results are checked against independent oracles:
// - the certificate against a brute-force test of every tet's circumsphere against every vertex
//   (CGAL's exact side_of_bounded_sphere, unweighted meshes);
// - every order is a permutation of what was asked for;
// - for a certified mesh the power order draws no face-adjacent pair in the wrong order
//   (count_violations), and the undoable painter, undrawing half of the picture, leaves the picture
//   of the other half drawn from scratch (rasterizer.hpp);
// - the volume painter (volume.hpp) on the same view and order, a field from the input (per tet
//   corner, so it may jump between tets): drawn in one call and in two batches, the same picture
//   and front ids pixel for pixel and the same segment count (each pixel sees its tets in order
//   whatever the batches), and no more segments in closed form than in all. For one input in 64
//   (by a hash of all its bytes, which mutations scatter, so the fuzzer cannot make every input
//   pay): two painters cost some 7 ms an input under the sanitizers (the transfer function's
//   tables), 30 times the rest of the pipeline.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "foxi/model/delaunay.hpp"
#include "foxi/model/validate.hpp"
#include "foxi/viz/camera.hpp"
#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"
#include "foxi/viz/spheres.hpp"
#include "foxi/viz/visibility_order.hpp"
#include "foxi/viz/volume.hpp"
#include "fuzz_util.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using foxi::fuzz::ByteReader;

// Scales of the lattice: ordinary, small and large meshes, and the extremes where squared lengths
// and volumes leave the double range.
constexpr double kScales[8] = {1, 1e-3, 1e3, 0.37, 1e-100, 1e100, 1e-160, 1e160};

foxi::Mesh decode(ByteReader& in, foxi::View& view) {
  const std::uint8_t mode = in.u8();
  const bool raw = (mode & 1) != 0, weighted = (mode & 2) != 0, regions = (mode & 4) != 0;
  const double scale = kScales[(mode >> 4) & 7];
  // Lattice coordinates in [-4, 4] in quarter steps with an offset: many cospherical and coplanar
  // sets (the hard cases of the certificate and the order), and a whole mesh far from the origin.
  const double offset = scale * double(std::int8_t(in.u8())) * ((mode & 8) != 0 ? 1000.0 : 1.0);
  auto coordinate = [&] {
    if (raw) return in.f64();
    const std::uint8_t b = in.u8();
    return offset + scale * (double(b % 9) - 4 + double(b / 9 % 4) * 0.25);
  };
  foxi::Mesh m;
  const std::size_t nodes = 4 + in.u8() % 13, tets = 1 + in.u8() % 24;
  for (std::size_t i = 0; i < 3 * nodes; ++i) m.xyz.push_back(coordinate());
  for (std::size_t t = 0; t < tets; ++t)
    for (int k = 0; k < 4; ++k) m.tet.push_back(static_cast<std::uint32_t>(in.u8() % nodes));
  if (regions)
    for (std::size_t t = 0; t < tets; ++t) m.tet_region.push_back(in.u8() % 3);
  if (weighted)
    for (std::size_t i = 0; i < nodes; ++i) m.weight.push_back(scale * scale * double(in.u8() % 5) * 0.125);
  const std::uint8_t v = in.u8();
  view.perspective = (v & 1) == 0;
  double* p = view.perspective ? view.eye : view.dir;
  for (int k = 0; k < 3; ++k) p[k] = offset + scale * (double(std::int8_t(in.u8())) / 8);
  if (!view.perspective && p[0] == 0 && p[1] == 0 && p[2] == 0) p[2] = 1;
  return m;
}

void check_permutation(std::span<const std::uint32_t> order, std::vector<std::uint32_t> expected) {
  std::vector<std::uint32_t> got(order.begin(), order.end());
  std::sort(got.begin(), got.end());
  std::sort(expected.begin(), expected.end());
  FOXI_FUZZ_CHECK(got == expected, "the order is not a permutation of the tets asked for");
}

// The certificate by brute force: every tet against every vertex (used node), exact predicates.
std::size_t brute_force_violations(const foxi::Mesh& m) {
  std::vector<char> used(m.node_count(), 0);
  for (std::uint32_t v : m.tet) used[v] = 1;
  auto point = [&](std::uint32_t v) { return K::Point_3(m.xyz[3 * v], m.xyz[3 * v + 1], m.xyz[3 * v + 2]); };
  std::size_t violating = 0;
  for (std::size_t t = 0; t < m.tet_count(); ++t) {
    const std::uint32_t* q = &m.tet[4 * t];
    for (std::uint32_t v = 0; v < m.node_count(); ++v)
      if (used[v] && CGAL::side_of_bounded_sphere(point(q[0]), point(q[1]), point(q[2]), point(q[3]),
                                                  point(v)) == CGAL::ON_BOUNDED_SIDE) {
        ++violating;
        break;
      }
  }
  return violating;
}

// The volume painter's check (see the header): corner values from the input's next bytes (past its
// end, 0), the colour scale 0..16 and an opacity curve across it, the unit length a quarter of the
// mesh's extent.
void volume_checks(const foxi::Mesh& m, const foxi::Camera& camera, int w, int h,
                   std::span<const std::uint32_t> order, ByteReader& in) {
  double lo[3], hi[3];
  foxi::mesh_bounds(m, lo, hi);
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(extent > 0) || !std::isfinite(extent)) return;
  std::vector<double> corner(m.tet.size());
  for (double& c : corner) c = double(in.u8()) / 16;
  foxi::VolumeParams p;
  p.scale.lo = 0;
  p.scale.hi = 16;
  p.opacity_curve = {{0, 0.05}, {8, 0.4}, {16, 0.9}};
  p.unit_length = extent / 4;
  p.threads = 1;
  foxi::VolumePainter whole(m, camera, w, h, corner, p), batches(m, camera, w, h, corner, p);
  whole.draw(order);
  const std::size_t cut = order.size() / 3;
  batches.draw(order.first(cut));
  batches.draw(order.subspan(cut));
  foxi::Framebuffer a, b;
  whole.resolve(a);
  batches.resolve(b);
  FOXI_FUZZ_CHECK(a.rgba == b.rgba && a.id == b.id,
                  "the volume picture drawn in two batches differs from the one drawn at once");
  FOXI_FUZZ_CHECK(whole.samples() == batches.samples(),
                  std::to_string(whole.samples()) + " segments against " + std::to_string(batches.samples()));
  FOXI_FUZZ_CHECK(whole.pre_integrated() <= whole.samples(), "more segments in closed form than in all");
}

void render_checks(const foxi::Mesh& m, const foxi::View& view, std::span<const std::uint32_t> order,
                   bool visibility_order, bool volume, ByteReader& in) {
  constexpr int kW = 24, kH = 16;
  double lo[3], hi[3];
  foxi::mesh_bounds(m, lo, hi);
  foxi::RenderParams params;
  params.undoable = visibility_order;
  try {
    const foxi::Camera camera =
        foxi::camera_from_options(lo, hi, double(kW) / kH, view.perspective ? view.eye : nullptr, nullptr,
                                  nullptr, 30, view.perspective ? nullptr : view.dir);
    foxi::TetRasterizer raster(m, camera, kW, kH, params);
    foxi::Framebuffer fb(kW, kH);
    raster.draw(fb, order);
    if (!visibility_order) return;
    if (volume) volume_checks(m, camera, kW, kH, order, in);
    const std::size_t half = order.size() / 2;
    raster.undraw(fb, order.size() - half);
    foxi::RenderParams fresh_params;
    const foxi::Framebuffer fresh = foxi::render_tets(m, camera, kW, kH, order.first(half), fresh_params);
    FOXI_FUZZ_CHECK(fresh.rgba == fb.rgba && fresh.id == fb.id, "undrawing to " + std::to_string(half) +
                                                                    " of " + std::to_string(order.size()) +
                                                                    " tets differs from drawing them afresh");
  } catch (const std::invalid_argument&) {
    // A degenerate camera (eye on the target point), bounds too large to fit a camera to, or one
    // zoomed past the fixed-point range: refused, which is the documented answer.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  foxi::View view;
  foxi::Mesh m = decode(in, view);
  if (!foxi::validate_and_repair(m).ok()) return 0;

  const foxi::DelaunayCertificate cert = foxi::compute_delaunay_certificate(m);
  FOXI_FUZZ_CHECK(cert.tets_checked == m.tet_count(), "");
  if (m.weight.empty()) {
    const std::size_t expected = brute_force_violations(m);
    FOXI_FUZZ_CHECK(cert.violating_tet_count == expected, std::to_string(cert.violating_tet_count) +
                                                              " violating tets, brute force " +
                                                              std::to_string(expected));
    FOXI_FUZZ_CHECK(cert.delaunay == (expected == 0 && cert.degenerate_tet_count == 0), "");
  }

  const foxi::SphereTable table = foxi::compute_spheres(m);
  std::vector<std::uint32_t> all(m.tet_count());
  for (std::uint32_t t = 0; t < all.size(); ++t) all[t] = t;
  std::vector<std::uint32_t> order;
  if (cert.delaunay) {
    order = foxi::visibility_order(m, table, view);
    check_permutation(order, all);
    const foxi::ViolationReport report = foxi::count_violations(m, view, order);
    FOXI_FUZZ_CHECK(report.violations == 0,
                    std::to_string(report.violations) + " face-adjacent pairs out of order");
  } else {
    std::size_t cycles = 0;
    order = foxi::mpvo_order(m, table, view, {}, &cycles);
    check_permutation(order, all);
  }
  // A subset (one region) in progressive batches.
  std::vector<std::uint32_t> subset;
  for (std::uint32_t t = 0; t < m.tet_count(); ++t)
    if (m.region_of(t) == 1) subset.push_back(t);
  if (!subset.empty()) {
    foxi::ProgressiveOrder progressive(m, table, view, subset);
    std::vector<std::uint32_t> got;
    for (auto batch = progressive.next(); !batch.empty(); batch = progressive.next())
      got.insert(got.end(), batch.begin(), batch.end());
    check_permutation(got, subset);
  }
  std::uint32_t hash = 2166136261u;  // FNV-1a
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 16777619u;
  render_checks(m, view, order, cert.delaunay, hash % 64 == 0, in);
  return 0;
}
