#include "facet_triangulation.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <cmath>
#include <deque>

#include "plc_edit.hpp"

namespace foxi::detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<int, K>;  // 1 inside the facet, 0 outside, -1 unknown
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

}  // namespace

std::size_t triangulate_facets(Plc& plc) {
  Plc out;
  out.points = plc.points;
  out.holes = plc.holes;
  out.regions = plc.regions;
  std::size_t triangles = 0;
  auto add_polygon = [&](std::initializer_list<std::uint32_t> v) {
    out.polygon_vertices.insert(out.polygon_vertices.end(), v);
    out.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(out.polygon_vertices.size()));
  };
  auto close_facet = [&](std::int32_t marker) {
    out.facet_polygon_begin.push_back(static_cast<std::uint32_t>(out.polygon_vertex_begin.size() - 1));
    out.facet_hole_begin.push_back(static_cast<std::uint32_t>(out.facet_holes.size() / 3));
    out.facet_marker.push_back(marker);
  };
  auto copy_facet = [&](std::size_t f) {
    for (std::uint32_t g = plc.facet_polygon_begin[f]; g < plc.facet_polygon_begin[f + 1]; ++g) {
      out.polygon_vertices.insert(out.polygon_vertices.end(),
                                  plc.polygon_vertices.begin() + plc.polygon_vertex_begin[g],
                                  plc.polygon_vertices.begin() + plc.polygon_vertex_begin[g + 1]);
      out.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(out.polygon_vertices.size()));
    }
    out.facet_holes.insert(out.facet_holes.end(),
                           plc.facet_holes.begin() + 3 * std::ptrdiff_t(plc.facet_hole_begin[f]),
                           plc.facet_holes.begin() + 3 * std::ptrdiff_t(plc.facet_hole_begin[f + 1]));
    close_facet(plc.facet_marker[f]);
  };
  for (std::size_t f = 0; f < plc.facet_count(); ++f) {
    const std::uint32_t g0 = plc.facet_polygon_begin[f], g1 = plc.facet_polygon_begin[f + 1];
    const bool plain = g1 == g0 + 1 && plc.polygon_vertex_begin[g0 + 1] - plc.polygon_vertex_begin[g0] == 3;
    bool area = false;
    for (std::uint32_t g = g0; g < g1; ++g)
      area = area || plc.polygon_vertex_begin[g + 1] - plc.polygon_vertex_begin[g] >= 3;
    if (plain || !area) {
      copy_facet(f);
      continue;
    }
    // The plane of the largest projection (Newell's normal of the polygons).
    Vec n{0, 0, 0};
    for (std::uint32_t g = g0; g < g1; ++g) {
      const std::uint32_t b = plc.polygon_vertex_begin[g], e = plc.polygon_vertex_begin[g + 1];
      if (e - b >= 3) add_newell_normal(plc.points, plc.polygon_vertices.data() + b, e - b, n);
    }
    std::size_t drop = 0;
    for (std::size_t k = 1; k < 3; ++k)
      if (std::abs(n[k]) > std::abs(n[drop])) drop = k;
    const std::size_t u = (drop + 1) % 3, w = (drop + 2) % 3;
    Cdt cdt;
    auto vertex = [&](std::uint32_t i) {
      const double* p = &plc.points[3 * std::size_t(i)];
      Cdt::Vertex_handle h = cdt.insert(K::Point_2(p[u], p[w]));
      h->info() = i;
      return h;
    };
    for (std::uint32_t g = g0; g < g1; ++g) {
      const std::uint32_t b = plc.polygon_vertex_begin[g], e = plc.polygon_vertex_begin[g + 1];
      if (e - b == 1) {
        vertex(plc.polygon_vertices[b]);
        continue;
      }
      Cdt::Vertex_handle first = vertex(plc.polygon_vertices[b]), prev = first;
      for (std::uint32_t i = b + 1; i < e; ++i) {
        Cdt::Vertex_handle h = vertex(plc.polygon_vertices[i]);
        if (h != prev) cdt.insert_constraint(prev, h);
        prev = h;
      }
      if (e - b >= 3 && prev != first) cdt.insert_constraint(prev, first);
    }
    // Inside: reached from the outside across an odd number of constrained edges.
    for (auto fit = cdt.all_faces_begin(); fit != cdt.all_faces_end(); ++fit) fit->info() = -1;
    std::deque<std::pair<Cdt::Face_handle, int>> queue{{cdt.infinite_face(), 0}};
    while (!queue.empty()) {
      const auto [fh, level] = queue.front();
      queue.pop_front();
      if (fh->info() != -1) continue;
      fh->info() = level;
      for (int i = 0; i < 3; ++i) {
        Cdt::Face_handle nb = fh->neighbor(i);
        if (nb->info() != -1) continue;
        if (cdt.is_constrained({fh, i}))
          queue.push_back({nb, 1 - level});
        else
          queue.push_front({nb, level});
      }
    }
    // A hole point clears the region around it, up to the constrained edges.
    for (std::uint32_t h = plc.facet_hole_begin[f]; h < plc.facet_hole_begin[f + 1]; ++h) {
      const double* p = &plc.facet_holes[3 * std::size_t(h)];
      std::vector<Cdt::Face_handle> stack{cdt.locate(K::Point_2(p[u], p[w]))};
      while (!stack.empty()) {
        Cdt::Face_handle fh = stack.back();
        stack.pop_back();
        if (cdt.is_infinite(fh) || fh->info() != 1) continue;
        fh->info() = 0;
        for (int i = 0; i < 3; ++i)
          if (!cdt.is_constrained({fh, i})) stack.push_back(fh->neighbor(i));
      }
    }
    for (auto fit = cdt.finite_faces_begin(); fit != cdt.finite_faces_end(); ++fit) {
      if (fit->info() != 1) continue;
      add_polygon({fit->vertex(0)->info(), fit->vertex(1)->info(), fit->vertex(2)->info()});
      close_facet(plc.facet_marker[f]);
      ++triangles;
    }
  }
  plc = std::move(out);
  return triangles;
}

}  // namespace foxi::detail
