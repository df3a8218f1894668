// A box [0, lx] x [0, ly] x [0, lz] cut into horizontal layers at the given z levels, as a TetGen PLC
// meshed by the tetgen program: the test meshes of the thermoelastic tests.
//
// Boundary markers: 1 x = 0, 2 x = lx, 3 y = 0, 4 y = ly, 5 z = 0, 6 z = lz, 7 + i the interface at
// the i-th inner level. Region i + 1 is layer i (from the bottom).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "foxi/model/io_tetgen.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/validate.hpp"
#include "test_util.hpp"

namespace foxi::test {

// levels: z of the layer boundaries, from 0 to lz (at least {0, lz}).
inline std::string layered_box_poly(double lx, double ly, const std::vector<double>& levels) {
  std::ostringstream s;
  s.precision(17);
  const std::size_t nl = levels.size();
  s << 4 * nl << " 3 0 0\n";
  const double xy[4][2] = {{0, 0}, {lx, 0}, {lx, ly}, {0, ly}};
  for (std::size_t i = 0; i < nl; ++i)
    for (int c = 0; c < 4; ++c)
      s << 4 * i + c + 1 << ' ' << xy[c][0] << ' ' << xy[c][1] << ' ' << levels[i] << '\n';
  const std::size_t slabs = nl - 1;
  s << nl + 4 * slabs << " 1\n";
  auto quad = [&](std::size_t a, std::size_t b, std::size_t c, std::size_t d, int marker) {
    s << "1 0 " << marker << "\n4 " << a << ' ' << b << ' ' << c << ' ' << d << '\n';
  };
  for (std::size_t i = 0; i < nl; ++i)
    quad(4 * i + 1, 4 * i + 2, 4 * i + 3, 4 * i + 4, i == 0 ? 5 : i + 1 == nl ? 6 : static_cast<int>(6 + i));
  // Side c of the box joins corners c and c + 1: y = 0 (3), x = lx (2), y = ly (4), x = 0 (1).
  const int side_marker[4] = {3, 2, 4, 1};
  for (std::size_t i = 0; i < slabs; ++i)
    for (std::size_t c = 0; c < 4; ++c) {
      const std::size_t a = 4 * i + c + 1, b = 4 * i + (c + 1) % 4 + 1;
      quad(a, b, b + 4, a + 4, side_marker[c]);
    }
  s << "0\n" << slabs << '\n';
  for (std::size_t i = 0; i < slabs; ++i)
    s << i + 1 << ' ' << lx / 2 << ' ' << ly / 2 << ' ' << (levels[i] + levels[i + 1]) / 2 << ' ' << i + 1
      << " 0\n";
  return s.str();
}

// Meshes the layered box with tetgen (radius-edge 1.414, max volume `max_volume`) and reads it back.
inline Mesh layered_box_mesh(double lx, double ly, const std::vector<double>& levels, double max_volume) {
  TempDir dir;
  write_text(dir / "box.poly", layered_box_poly(lx, ly, levels));
  std::ostringstream cmd;
  cmd.precision(17);
  cmd << "tetgen -pq1.414AQa" << max_volume << " '" << (dir / "box.poly").string() << "'";
  if (run(cmd.str(), dir / "log") != 0) throw std::runtime_error("tetgen failed: " + read_text(dir / "log"));
  Mesh mesh = read_tetgen(dir / "box.1");
  validate_and_repair(mesh);
  return mesh;
}

}  // namespace foxi::test
