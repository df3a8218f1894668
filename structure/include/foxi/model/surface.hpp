// Closed triangle surfaces of the parts that are not vertical prisms: faceted balls (sphere segments,
// solder balls) and STL files; the structure builder carves and joins them (structure.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

// A triangle surface: 3 doubles per vertex (metres), 3 vertex indices per triangle, counter-clockwise
// seen from outside when the surface is closed. Several closed components may share one surface.
struct FOXI_API TriSurface {
  std::vector<double> xyz;
  std::vector<std::uint32_t> tri;
  std::size_t vertex_count() const { return xyz.size() / 3; }
  std::size_t triangle_count() const { return tri.size() / 3; }
  // Appends `other`'s vertices and triangles (re-indexed) shifted by (dx, dy, dz).
  void append(const TriSurface& other, double dx = 0, double dy = 0, double dz = 0);
};

// A sphere (center, radius) cut by the horizontal planes z = z0 and z = z1 (z0 < z1, both clipped to
// the sphere's extent): a solder ball between two pads, or a whole sphere.
struct Ball {
  double center[3] = {0, 0, 0};
  double radius = 1;
  double z0 = -1, z1 = 1;
  double tolerance = 0.01;  // largest distance of a facet from the sphere (metres)
};

// How a ball is faceted: `around` vertices on each horizontal ring, all at the same azimuths
// 2 pi k / around, on rings at heights ring_z (from z1 down to z0, equal steps of polar angle) with
// radii ring_radius (0 at a pole, which is then one vertex). Neighbouring rings bound planar
// trapezoids, so the faceted ball is a stack of frusta of regular `around`-gon pyramids. `around`
// (a multiple of 4, at least 8, so the faceted ball is symmetric about its vertical planes x = cx
// and y = cy) and the ring count (at least 1 step) are the smallest with chord sagittas of at most
// tolerance / 2 each, so no facet is farther than the tolerance from the sphere.
struct BallFaceting {
  std::uint32_t around = 0;
  std::vector<double> ring_z, ring_radius;
};
FOXI_API BallFaceting ball_faceting(const Ball& ball);

// The closed, outward oriented surface of the faceted ball: side trapezoids split in two, flat ends
// (where z0 or z1 cuts the sphere) fanned from their centres. Throws std::invalid_argument for a
// radius or tolerance that is not positive, or z0 >= z1 after clipping.
FOXI_API TriSurface ball_surface(const Ball& ball);

// Reads an STL file, ASCII ("solid ... facet normal ... outer loop vertex x y z ... endloop endfacet
// ... endsolid") or binary (80-byte header, uint32 count, 50 bytes per triangle; told apart by its
// size), coordinates multiplied by `scale`. Vertices with identical coordinates are merged; the
// normals are ignored (the vertex order gives the orientation). Checks sizes before allocating.
// Throws IoError naming the file and the line (ASCII) or byte offset (binary) for malformed input,
// non-finite coordinates, triangles with repeated vertices, and files without triangles. Whether the
// surface is closed, oriented and free of self-intersections is checked by the structure builder.
FOXI_API TriSurface read_stl(const std::filesystem::path& path, double scale = 1);

}  // namespace foxi
