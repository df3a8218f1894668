// foxi-view's script mode and picture saving: see viewer.hpp.
#include "viewer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "foxi/viz/view_options.hpp"
#include "foxi/viz/png.hpp"

namespace foxi::view {

std::filesystem::path save_next(const Viewer& viewer, const std::string& prefix, bool dump) {
  std::string base;
  for (int i = 1;; ++i) {
    char num[16];
    std::snprintf(num, sizeof num, "-%03d", i);
    base = prefix + num;
    if (!std::filesystem::exists(base + ".png")) break;
  }
  const std::filesystem::path png = base + ".png";
  viewer.save_png(png);
  if (dump) {
    const Framebuffer& fb = viewer.framebuffer();
    std::ofstream ids(base + ".ids", std::ios::binary);
    for (std::uint32_t id : fb.id) {
      unsigned char b[4] = {static_cast<unsigned char>(id), static_cast<unsigned char>(id >> 8),
                            static_cast<unsigned char>(id >> 16), static_cast<unsigned char>(id >> 24)};
      ids.write(reinterpret_cast<const char*>(b), 4);
    }
    std::ofstream tets(base + ".tets");
    for (std::uint32_t t : viewer.drawn()) tets << t << '\n';
    if (!ids || !tets) throw std::runtime_error("cannot write " + base + ".ids/.tets");
  }
  std::printf("saved %s  %s  (%s)\n", png.c_str(), viewer.status().c_str(), viewer.camera_options().c_str());
  std::fflush(stdout);
  return png;
}

void run_script(Viewer& viewer, const std::string& script, const std::string& prefix, bool dump) {
  std::istringstream in(script);
  std::string cmd;
  while (in >> cmd) {
    const std::size_t colon = cmd.find(':');
    const std::string name = cmd.substr(0, colon),
                      arg = colon == std::string::npos ? "" : cmd.substr(colon + 1);
    auto args = [&](std::size_t count) {
      auto v = parse_number_list(arg, name);
      if (v.size() != count)
        throw std::invalid_argument("script command '" + cmd + "' takes " + std::to_string(count) +
                                    " numbers");
      return v;
    };
    if (cmd == "d") {
      viewer.restart();
      viewer.finish();
    } else if (cmd == "c") {
      viewer.restart();
    } else if (cmd == "n") {
      viewer.step();
    } else if (cmd == "f") {
      viewer.set_undrawing(false);
      viewer.finish();
    } else if (name == "u") {
      if (!viewer.set_undrawing(true)) throw std::invalid_argument("script: 'u' needs the painter (a Delaunay mesh) and no --no-undo");
      if (arg.empty()) {
        while (viewer.step()) {
        }
      } else {
        const double k = args(1)[0];
        if (!(k >= 0 && k == std::floor(k))) throw std::invalid_argument("u:N takes a whole number of tets");
        viewer.undraw(std::size_t(k));
      }
    } else if (cmd == "r") {
      if (!viewer.push_region()) throw std::invalid_argument("script: 'r' with no tets drawn");
    } else if (cmd == "b") {
      viewer.pop_region();
    } else if (cmd == "s") {
      save_next(viewer, prefix, dump);
    } else if (name == "orbit") {
      auto v = args(2);
      viewer.orbit(v[0], v[1]);
    } else if (name == "zoom") {
      auto v = args(1);
      if (!(v[0] > 0)) throw std::invalid_argument("zoom takes a factor > 0");
      viewer.zoom(v[0]);
    } else if (name == "pan") {
      auto v = args(2);
      viewer.pan(v[0], v[1]);
    } else {
      throw std::invalid_argument("unknown script command '" + cmd +
                                  "' (d c n f u u:N r b s orbit:Y,P zoom:F pan:X,Y)");
    }
  }
}

}  // namespace foxi::view
