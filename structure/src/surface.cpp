// Faceted balls and STL files -> closed triangle surfaces (see surface.hpp).
#include "foxi/model/surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

#include "io_util.hpp"

namespace foxi {

void TriSurface::append(const TriSurface& other, double dx, double dy, double dz) {
  const auto base = static_cast<std::uint32_t>(vertex_count());
  for (std::size_t v = 0; v < other.vertex_count(); ++v)
    xyz.insert(xyz.end(), {other.xyz[3 * v] + dx, other.xyz[3 * v + 1] + dy, other.xyz[3 * v + 2] + dz});
  for (std::uint32_t i : other.tri) tri.push_back(base + i);
}

BallFaceting ball_faceting(const Ball& b) {
  if (!(b.radius > 0) || !(b.tolerance > 0))
    throw std::invalid_argument("ball radius and tolerance must be positive");
  const double r = b.radius, cz = b.center[2];
  const double z1 = std::min(b.z1, cz + r), z0 = std::max(b.z0, cz - r);
  if (!(z0 < z1)) throw std::invalid_argument("the ball's z range misses the sphere");
  // largest angle step whose chord stays within tolerance / 2 of its arc: r (1 - cos(step / 2))
  const double s = 0.5 * b.tolerance / r;
  const double step = s >= 1 ? std::numbers::pi : 2 * std::acos(1 - s);
  BallFaceting f;
  // a multiple of 4, so the facets are symmetric about the planes x = cx and y = cy
  f.around = 4 * static_cast<std::uint32_t>(std::max(2.0, std::ceil(0.5 * std::numbers::pi / step)));
  const double t1 = std::acos(std::clamp((z1 - cz) / r, -1.0, 1.0));
  const double t0 = std::acos(std::clamp((z0 - cz) / r, -1.0, 1.0));
  const auto rings = static_cast<std::size_t>(std::max(1.0, std::ceil((t0 - t1) / step)));
  for (std::size_t k = 0; k <= rings; ++k) {
    // the end rings at exactly z1 and z0 (they meet the pads), the others at equal polar steps
    const double t = t1 + (t0 - t1) * static_cast<double>(k) / static_cast<double>(rings);
    const double z = k == 0 ? z1 : k == rings ? z0 : cz + r * std::cos(t);
    const double h = z - cz;
    f.ring_z.push_back(z);
    f.ring_radius.push_back(k == 0 || k == rings ? std::sqrt(std::max(0.0, r * r - h * h)) : r * std::sin(t));
  }
  return f;
}

TriSurface ball_surface(const Ball& b) {
  const BallFaceting f = ball_faceting(b);
  const std::uint32_t n = f.around;
  TriSurface s;
  auto add = [&](double x, double y, double z) {
    s.xyz.insert(s.xyz.end(), {x, y, z});
    return static_cast<std::uint32_t>(s.vertex_count() - 1);
  };
  auto tri = [&](std::uint32_t a, std::uint32_t c, std::uint32_t d) { s.tri.insert(s.tri.end(), {a, c, d}); };
  // first vertex of each ring; a ring of radius 0 (a pole) is one vertex
  std::vector<std::uint32_t> first;
  for (std::size_t k = 0; k < f.ring_z.size(); ++k) {
    first.push_back(static_cast<std::uint32_t>(s.vertex_count()));
    if (f.ring_radius[k] == 0) {
      add(b.center[0], b.center[1], f.ring_z[k]);
      continue;
    }
    for (std::uint32_t j = 0; j < n; ++j) {
      const double a = 2 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(n);
      add(b.center[0] + f.ring_radius[k] * std::cos(a), b.center[1] + f.ring_radius[k] * std::sin(a),
          f.ring_z[k]);
    }
  }
  auto at = [&](std::size_t k, std::uint32_t j) {
    return f.ring_radius[k] == 0 ? first[k] : first[k] + j % n;
  };
  // sides: ring k (above) and k + 1 (below); counter-clockwise from outside is
  // below j -> below j+1 -> above j+1 -> above j (azimuth grows to the right)
  for (std::size_t k = 0; k + 1 < f.ring_z.size(); ++k)
    for (std::uint32_t j = 0; j < n; ++j) {
      const std::uint32_t a0 = at(k, j), a1 = at(k, j + 1), b0 = at(k + 1, j), b1 = at(k + 1, j + 1);
      if (f.ring_radius[k + 1] > 0) tri(b0, b1, a1);
      if (f.ring_radius[k] > 0) tri(b0, a1, a0);
    }
  // flat ends, fanned from their centres
  const std::size_t last = f.ring_z.size() - 1;
  if (f.ring_radius[0] > 0) {
    const std::uint32_t c = add(b.center[0], b.center[1], f.ring_z[0]);
    for (std::uint32_t j = 0; j < n; ++j) tri(c, at(0, j), at(0, j + 1));
  }
  if (f.ring_radius[last] > 0) {
    const std::uint32_t c = add(b.center[0], b.center[1], f.ring_z[last]);
    for (std::uint32_t j = 0; j < n; ++j) tri(c, at(last, j + 1), at(last, j));
  }
  return s;
}

namespace {

// Merges vertices with identical coordinates while triangles are added.
class SoupBuilder {
 public:
  explicit SoupBuilder(double scale) : scale_(scale) {}
  // Adds a triangle; returns false if two of its corners are the same point.
  bool add(const std::array<std::array<double, 3>, 3>& corner) {
    std::uint32_t id[3];
    for (int i = 0; i < 3; ++i) {
      auto [it, fresh] =
          ids_.emplace(corner[static_cast<std::size_t>(i)], static_cast<std::uint32_t>(ids_.size()));
      if (fresh)
        for (double c : corner[static_cast<std::size_t>(i)]) s_.xyz.push_back(c * scale_);
      id[i] = it->second;
    }
    if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2]) return false;
    s_.tri.insert(s_.tri.end(), {id[0], id[1], id[2]});
    return true;
  }
  TriSurface take() { return std::move(s_); }

 private:
  double scale_;
  std::map<std::array<double, 3>, std::uint32_t> ids_;
  TriSurface s_;
};

TriSurface read_ascii_stl(const std::string& file, std::string_view text, double scale) {
  io::TextCursor in(text, file);
  in.expect("solid");
  in.rest_of_line();  // the solid's name
  SoupBuilder soup(scale);
  for (;;) {
    const std::size_t at = (in.skip_space(), in.pos());
    const std::string_view word = in.token("'facet' or 'endsolid'");
    if (word == "endsolid") {
      in.rest_of_line();
      if (in.at_end()) break;
      in.expect("solid");  // another solid follows
      in.rest_of_line();
      continue;
    }
    if (word != "facet") {
      in.set_pos(at);
      in.fail("expected 'facet' or 'endsolid', found '" + io::TextCursor::shorten(word) + "'");
    }
    in.expect("normal");
    for (int i = 0; i < 3; ++i) in.real("a normal component");
    in.expect("outer");
    in.expect("loop");
    std::array<std::array<double, 3>, 3> c{};
    for (auto& v : c) {
      in.expect("vertex");
      for (double& x : v) {
        const std::size_t xat = (in.skip_space(), in.pos());
        x = in.real("a vertex coordinate");
        if (!std::isfinite(x)) in.fail_at(xat, "the vertex coordinate is not finite");
      }
    }
    in.expect("endloop");
    in.expect("endfacet");
    if (!soup.add(c)) in.fail_at(at, "the facet has two equal vertices (a degenerate triangle)");
  }
  TriSurface s = soup.take();
  if (s.tri.empty()) in.fail("the STL file has no facets");
  return s;
}

TriSurface read_binary_stl(const std::string& file, std::string_view data, double scale) {
  std::uint32_t count = 0;
  std::memcpy(&count, data.data() + 80, 4);
  if (count == 0) io::fail_binary(file, 80, "the binary STL file has no triangles");
  SoupBuilder soup(scale);
  for (std::uint32_t t = 0; t < count; ++t) {
    const std::size_t at = 84 + 50 * static_cast<std::size_t>(t);
    std::array<std::array<double, 3>, 3> c{};
    for (std::size_t v = 0; v < 3; ++v)
      for (std::size_t i = 0; i < 3; ++i) {
        float x = 0;
        std::memcpy(&x, data.data() + at + 12 + 12 * v + 4 * i, 4);
        if (!std::isfinite(x))
          io::fail_binary(file, at + 12 + 12 * v + 4 * i,
                          "triangle " + std::to_string(t) + ": a vertex coordinate is not finite");
        c[v][i] = static_cast<double>(x);
      }
    if (!soup.add(c))
      io::fail_binary(file, at,
                      "triangle " + std::to_string(t) + " has two equal vertices (a degenerate triangle)");
  }
  return soup.take();
}

}  // namespace

TriSurface read_stl(const std::filesystem::path& path, double scale) {
  const std::string file = path.string();
  const std::string data = io::read_file(path);
  std::uint32_t count = 0;
  if (data.size() >= 84) std::memcpy(&count, data.data() + 80, 4);
  // binary when the size is exactly what the header's count says (ASCII files may start with
  // "solid" and binary headers often do too, so the size decides first)
  if (data.size() >= 84 && data.size() - 84 == 50 * static_cast<std::uint64_t>(count))
    return read_binary_stl(file, data, scale);
  std::size_t b = 0;
  while (b < data.size() && std::isspace(static_cast<unsigned char>(data[b]))) ++b;
  if (data.compare(b, 5, "solid") == 0) return read_ascii_stl(file, data, scale);
  if (data.size() >= 84)
    io::fail_binary(file, 80,
                    "binary STL: the header says " + std::to_string(count) + " triangles (" +
                        std::to_string(84 + 50 * static_cast<std::uint64_t>(count)) +
                        " bytes), the file has " + std::to_string(data.size()) + " bytes");
  throw IoError(file, 1, 0, "not an STL file: neither 'solid' (ASCII) nor a binary header and count");
}

}  // namespace foxi
