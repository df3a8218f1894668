// Validation of the mesh database: sizes, indices, repeated vertices, non-finite coordinates, exact
// orientation of every tet (CGAL's filtered exact predicate), unused nodes.
#include "foxi/model/validate.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <cmath>
#include <utility>

namespace foxi {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;

constexpr std::size_t kMaxMessages = 20;

void note(ValidationReport& r, std::string message) {
  if (r.messages.size() < kMaxMessages) r.messages.push_back(std::move(message));
}

std::string ids(const std::uint32_t* v, int count) {
  std::string s = "(";
  for (int j = 0; j < count; ++j) s += (j ? " " : "") + std::to_string(v[j]);
  return s + ")";
}

// Checks everything; collects the inverted tets when `inverted` is not null.
ValidationReport check(const Mesh& mesh, std::vector<std::size_t>* inverted) {
  ValidationReport r;
  r.size_problem = check_sizes(mesh);
  if (!r.size_problem.empty()) {
    note(r, r.size_problem);
    return r;
  }
  const std::size_t nv = mesh.node_count();
  std::vector<std::uint8_t> finite(nv, 1);
  for (std::size_t v = 0; v < nv; ++v) {
    const double* p = &mesh.xyz[3 * v];
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) {
      finite[v] = 0;
      ++r.nonfinite_nodes;
      note(r, "node " + std::to_string(v) + ": non-finite coordinate");
    } else if (!mesh.weight.empty() && !std::isfinite(mesh.weight[v])) {
      // A weight (read from a .vtu/.vtk 'weight' array) that is NaN or infinite has no orthosphere.
      finite[v] = 0;
      ++r.nonfinite_nodes;
      note(r, "node " + std::to_string(v) + ": non-finite weight");
    }
  }
  std::vector<std::uint8_t> used(nv, 0);
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::uint32_t* v = &mesh.tet[4 * t];
    bool in_range = true;
    for (int j = 0; j < 4; ++j)
      if (v[j] >= nv)
        in_range = false;
      else
        used[v[j]] = 1;
    if (!in_range) {
      ++r.index_out_of_range;
      note(r,
           "tet " + std::to_string(t) + " " + ids(v, 4) + ": node index >= node count " + std::to_string(nv));
      continue;
    }
    if (v[0] == v[1] || v[0] == v[2] || v[0] == v[3] || v[1] == v[2] || v[1] == v[3] || v[2] == v[3]) {
      ++r.repeated_vertex;
      note(r, "tet " + std::to_string(t) + " " + ids(v, 4) + ": repeated node");
      continue;
    }
    if (!(finite[v[0]] && finite[v[1]] && finite[v[2]] && finite[v[3]])) continue;
    auto pt = [&](std::uint32_t i) {
      return Point(mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]);
    };
    const CGAL::Orientation o = CGAL::orientation(pt(v[0]), pt(v[1]), pt(v[2]), pt(v[3]));
    if (o == CGAL::COPLANAR) {
      ++r.zero_volume;
      note(r, "tet " + std::to_string(t) + " " + ids(v, 4) + ": zero volume");
    } else if (o == CGAL::NEGATIVE) {
      ++r.inverted;
      if (inverted) inverted->push_back(t);
      note(r, "tet " + std::to_string(t) + " " + ids(v, 4) + ": inverted (negative orientation)");
    }
  }
  for (std::size_t f = 0; f < mesh.bface_count(); ++f) {
    const std::uint32_t* v = &mesh.bface[3 * f];
    if (v[0] >= nv || v[1] >= nv || v[2] >= nv) {
      ++r.index_out_of_range;
      note(r, "boundary triangle " + std::to_string(f) + " " + ids(v, 3) + ": node index >= node count " +
                  std::to_string(nv));
    } else if (v[0] == v[1] || v[0] == v[2] || v[1] == v[2]) {
      ++r.repeated_vertex;
      note(r, "boundary triangle " + std::to_string(f) + " " + ids(v, 3) + ": repeated node");
    }
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (!used[v]) {
      if (r.unused_nodes == 0)
        note(r, "node " + std::to_string(v) + ": used by no tet (first of the unused)");
      ++r.unused_nodes;
    }
  return r;
}

}  // namespace

ValidationReport validate(const Mesh& mesh) { return check(mesh, nullptr); }

ValidationReport validate_and_repair(Mesh& mesh) {
  std::vector<std::size_t> inverted;
  ValidationReport r = check(mesh, &inverted);
  for (std::size_t t : inverted) std::swap(mesh.tet[4 * t + 2], mesh.tet[4 * t + 3]);
  if (!inverted.empty()) invalidate_derived(mesh);
  return r;
}

}  // namespace foxi
