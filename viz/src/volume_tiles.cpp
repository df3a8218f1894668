// The volume renderer's screen tiles (volume_impl.hpp): which tiles a tet's projection can touch, and
// a batch's tets binned to the tiles, each tile's list in the batch's order.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <utility>

#include "volume_impl.hpp"

namespace foxi {

// The tiles tet t's projection can touch (the bounds of its nodes' pixels, a pixel wider); none off
// screen. A tet with a node not in front of the eye: the bounds of its part at depth >= nb, nb the
// least clipping plane draw_tet can use for it (that part holds the part draw_tet's spans cover).
std::array<std::uint16_t, 4> VolumePainter::Impl::tiles_of(std::uint32_t t) const {
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  auto add = [&](const double* q) {
    x_lo = std::min(x_lo, q[0]);
    x_hi = std::max(x_hi, q[0]);
    y_lo = std::min(y_lo, q[1]);
    y_hi = std::max(y_hi, q[1]);
  };
  const std::uint32_t* node = &mesh->tet[4 * std::size_t(t)];
  bool behind = false;
  for (int k = 0; k < 4; ++k) behind = behind || std::isnan(node_px[2 * std::size_t(node[k])]);
  if (!behind) {
    for (int k = 0; k < 4; ++k) add(&node_px[2 * std::size_t(node[k])]);
  } else {
    const double* P[4];
    double dmin = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 4; ++k) {
      P[k] = &cam_xyz[3 * std::size_t(node[k])];
      dmin = std::min(dmin, std::sqrt(P[k][0] * P[k][0] + P[k][1] * P[k][1] + P[k][2] * P[k][2]));
    }
    // clip_near: a face's plane is max(near, dmax * focal / kMaxPixel), dmax over its corners.
    const double nb = std::max(params.near, dmin * proj.focal / kMaxPixel);
    if (!(nb > 0)) return {0, std::uint16_t(tiles_x - 1), 0, std::uint16_t(tiles_y - 1)};
    for (int i = 0; i < 4; ++i) {
      double q[2];
      if (P[i][2] >= nb) {
        proj.camera_to_pixel(P[i], q);
        add(q);
      }
      for (int j = i + 1; j < 4; ++j)
        if ((P[i][2] < nb) != (P[j][2] < nb)) {
          const double u = (nb - P[i][2]) / (P[j][2] - P[i][2]);
          const double c[3] = {P[i][0] + u * (P[j][0] - P[i][0]), P[i][1] + u * (P[j][1] - P[i][1]), nb};
          proj.camera_to_pixel(c, q);
          add(q);
        }
    }
    // Snapping and the rounding of the cut points: a few pixels more.
    x_lo -= 4;
    y_lo -= 4;
    x_hi += 4;
    y_hi += 4;
  }
  if (!(x_hi >= -1 && y_hi >= -1 && x_lo <= proj.width + 1 && y_lo <= proj.height + 1)) return {1, 0, 1, 0};
  auto tile = [](double p, int size, int count) {
    return std::uint16_t(std::clamp(int(std::floor(std::clamp(p, -2.0, 1e7) / size)), 0, count - 1));
  };
  return {tile(x_lo - 1, kTileW, tiles_x), tile(x_hi + 1, kTileW, tiles_x), tile(y_lo - 1, kTileH, tiles_y),
          tile(y_hi + 1, kTileH, tiles_y)};
}

// The batch's tets into the tiles' lists (tile_start, tile_tets), each list in the batch's order:
// the batch cut into `lanes` consecutive parts, each part's tets counted per tile and then written
// by its own thread after the earlier parts' (so the order holds within each tile).
void VolumePainter::Impl::bin(std::span<const std::uint32_t> tets) {
  const std::size_t n_tiles = std::size_t(tiles_x) * std::size_t(tiles_y);
  const std::size_t parts = std::size_t(lanes);
  tet_tiles.resize(tets.size());
  cursor.assign(parts * n_tiles, 0);  // per part: its count per tile, then where it writes next
  auto part_range = [&](std::size_t part) {
    return std::pair{tets.size() * part / parts, tets.size() * (part + 1) / parts};
  };
  auto each_tile = [&](const std::array<std::uint16_t, 4>& b, auto&& fn) {
    for (int ty = b[2]; ty <= b[3]; ++ty)
      for (int tx = b[0]; tx <= b[1]; ++tx) fn(std::size_t(ty) * std::size_t(tiles_x) + std::size_t(tx));
  };
  run_parts(lanes, [&](int lane) {
    const auto [i0, i1] = part_range(std::size_t(lane));
    std::uint32_t* count = &cursor[std::size_t(lane) * n_tiles];
    for (std::size_t i = i0; i < i1; ++i) {
      // Fetched ahead as in draw(): the order's tets lie far apart in memory.
      if (i + 8 < i1) __builtin_prefetch(&mesh->tet[4 * std::size_t(tets[i + 8])]);
      if (i + 4 < i1) {
        const std::uint32_t* node = &mesh->tet[4 * std::size_t(tets[i + 4])];
        for (int j = 0; j < 4; ++j) __builtin_prefetch(&node_px[2 * std::size_t(node[j])]);
      }
      each_tile(tet_tiles[i] = tiles_of(tets[i]), [&](std::size_t k) { ++count[k]; });
    }
  });
  tile_start.assign(n_tiles + 1, 0);
  std::uint32_t total = 0;
  for (std::size_t k = 0; k < n_tiles; ++k) {
    tile_start[k] = total;
    for (std::size_t part = 0; part < parts; ++part) {
      const std::uint32_t c = cursor[part * n_tiles + k];
      cursor[part * n_tiles + k] = total;
      total += c;
    }
  }
  tile_start[n_tiles] = total;
  tile_tets.resize(total);
  run_parts(lanes, [&](int lane) {
    const auto [i0, i1] = part_range(std::size_t(lane));
    std::uint32_t* next = &cursor[std::size_t(lane) * n_tiles];
    for (std::size_t i = i0; i < i1; ++i)
      each_tile(tet_tiles[i], [&](std::size_t k) { tile_tets[next[k]++] = tets[i]; });
  });
}

}  // namespace foxi
