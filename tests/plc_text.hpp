// PLCs as TetGen .poly text, for the tests that run the tetgen program.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>
#include <string>

#include "test_util.hpp"

namespace foxi::test {

// An axis-aligned lx x ly x lz box with its corner at the origin, six unmarked facets.
inline std::string box_poly(double lx, double ly, double lz) {
  std::ostringstream s;
  s << "8 3 0 0\n";
  for (int i = 0; i < 8; ++i)
    s << i + 1 << ' ' << (i & 1 ? lx : 0) << ' ' << (i & 2 ? ly : 0) << ' ' << (i & 4 ? lz : 0) << '\n';
  s << "6 0\n";
  const int f[6][4] = {{1, 3, 7, 5}, {2, 4, 8, 6}, {1, 2, 6, 5}, {3, 4, 8, 7}, {1, 2, 4, 3}, {5, 6, 8, 7}};
  for (auto& q : f) s << "1\n4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
  s << "0\n0\n";
  return s.str();
}

// The seed paper's U-trench PLC (non-convex), shipped in examples/.
inline std::string trench_poly() { return read_text(data_dir() + "/../../examples/trench.poly"); }

// The whitespace-separated numbers of a TetGen output file (.node, .ele, .neigh), '#' comments
// skipped: a tiny reader of its own, so that tests can use TetGen's files as an oracle independent of
// foxi's TetGen reader.
inline std::vector<double> read_numbers(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::vector<double> out;
  std::string line;
  while (std::getline(in, line)) {
    auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream ls(line);
    double x;
    while (ls >> x) out.push_back(x);
  }
  return out;
}

}  // namespace foxi::test
