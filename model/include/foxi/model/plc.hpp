// A piecewise linear complex (PLC): what the model hands the mesher. Points, polygonal facets (each
// a set of polygons with optional hole points, and a boundary marker that becomes the boundary tag of
// the triangles meshed on it), volume holes, and region seeds (a point inside each region, its
// region id, and an optional maximum tet volume). Read and written as TetGen .poly files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

struct RegionSeed {
  double point[3] = {0, 0, 0};
  std::int32_t id = 0;
  double max_volume = 0;  // 0 or negative: no own limit
};

struct FOXI_API Plc {
  std::vector<double> points;  // 3 per point
  // Facets: facet f owns polygons [facet_polygon_begin[f], facet_polygon_begin[f+1]); polygon p owns
  // polygon_vertices[polygon_vertex_begin[p] .. polygon_vertex_begin[p+1]) (0-based point indices).
  std::vector<std::uint32_t> facet_polygon_begin = {0};
  std::vector<std::uint32_t> polygon_vertex_begin = {0};
  std::vector<std::uint32_t> polygon_vertices;
  std::vector<std::int32_t> facet_marker;             // 1 per facet (0 = unmarked)
  std::vector<std::uint32_t> facet_hole_begin = {0};  // hole points inside facets, 3 doubles each
  std::vector<double> facet_holes;
  std::vector<double> holes;  // volume hole points, 3 each
  std::vector<RegionSeed> regions;

  std::size_t point_count() const { return points.size() / 3; }
  std::size_t facet_count() const { return facet_marker.size(); }

  // Appends a facet of one polygon (0-based point indices) with a marker.
  void add_facet(std::initializer_list<std::uint32_t> polygon, std::int32_t marker);
};

// TetGen .poly: `# comments`, 0- or 1-based numbering (from the first point index). The points must
// be in the .poly itself. Throws IoError (file, line, reason) on malformed input.
FOXI_API Plc read_poly(const std::filesystem::path& path);
FOXI_API Plc parse_poly(std::string_view text, const std::string& name);
// Writes 1-based .poly (through a temporary file and a rename).
FOXI_API void write_poly(const Plc& plc, const std::filesystem::path& path);

}  // namespace foxi
