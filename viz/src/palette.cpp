// Material colours and the exploded view (palette.hpp).
#include "foxi/viz/palette.hpp"

#include <algorithm>
#include <map>
#include <utility>

#include "foxi/viz/framebuffer.hpp"
#include "foxi/viz/rasterizer.hpp"

namespace foxi {

std::uint32_t material_color(std::string_view name, std::size_t index) {
  struct Known {
    const char* name;
    std::uint32_t rgba;
  };
  static const Known kKnown[] = {
      {"copper", pack_rgba(200, 117, 51)},       {"silicon", pack_rgba(96, 110, 160)},
      {"polysilicon", pack_rgba(150, 100, 170)}, {"sac305", pack_rgba(175, 180, 185)},
      {"fr4", pack_rgba(70, 140, 70)},           {"mold_compound", pack_rgba(80, 80, 85)},
      {"underfill", pack_rgba(225, 190, 110)},   {"sio2", pack_rgba(150, 215, 230)},
      {"aluminium", pack_rgba(210, 210, 215)},   {"alumina", pack_rgba(240, 235, 215)},
  };
  for (const Known& k : kKnown)
    if (name == k.name) return k.rgba;
  return region_color(static_cast<std::int32_t>(index));
}

Mesh exploded_mesh(const Mesh& mesh, double gap) {
  Mesh out;
  out.regions = mesh.regions;
  std::map<std::pair<std::uint32_t, std::int32_t>, std::uint32_t> copy;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const std::int32_t r = mesh.region_of(t);
    for (int v = 0; v < 4; ++v) {
      const std::uint32_t n = mesh.tet[4 * t + v];
      auto [it, fresh] = copy.emplace(std::make_pair(n, r), static_cast<std::uint32_t>(out.xyz.size() / 3));
      if (fresh) {
        const double* p = &mesh.xyz[3 * std::size_t{n}];
        out.xyz.insert(out.xyz.end(), {p[0], p[1], p[2] + gap * std::max(0, r - 1)});
      }
      out.tet.push_back(it->second);
    }
    out.tet_region.push_back(r);
  }
  return out;
}

}  // namespace foxi
