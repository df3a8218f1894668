#include "foxi/model/plc.hpp"

#include <cmath>

#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {

void Plc::add_facet(std::initializer_list<std::uint32_t> polygon, std::int32_t marker) {
  polygon_vertices.insert(polygon_vertices.end(), polygon.begin(), polygon.end());
  polygon_vertex_begin.push_back(static_cast<std::uint32_t>(polygon_vertices.size()));
  facet_polygon_begin.push_back(static_cast<std::uint32_t>(polygon_vertex_begin.size() - 1));
  facet_marker.push_back(marker);
  facet_hole_begin.push_back(static_cast<std::uint32_t>(facet_holes.size() / 3));
}

Plc read_poly(const std::filesystem::path& path) { return parse_poly(io::read_file(path), path.string()); }

Plc parse_poly(std::string_view text, const std::string& name) {
  io::TextCursor in(text, name);
  constexpr char kComment = '#';
  Plc plc;
  auto count = [&](const char* what, std::uint64_t min_bytes) {
    std::int64_t n = in.integer(what, kComment);
    if (n < 0) in.fail(std::string(what) + " is negative");
    if (!io::count_fits(std::uint64_t(n), min_bytes, in.remaining()))
      in.fail("declares " + std::to_string(n) + " " + what + " but the file has only " +
              std::to_string(in.remaining()) + " bytes left");
    return static_cast<std::uint64_t>(n);
  };
  auto real = [&](const char* what) {
    double v = in.real(what, kComment);
    if (!std::isfinite(v)) in.fail(std::string(what) + " is not finite");
    return v;
  };
  // Points.
  const std::uint64_t np = count("points", 8);
  if (np == 0) in.fail("the points are not in the .poly file (a separate .node file is not supported)");
  const std::int64_t dim = in.integer("dimension", kComment);
  if (dim != 3) in.fail("dimension must be 3, not " + std::to_string(dim));
  const std::int64_t nattr = in.integer("number of point attributes", kComment);
  const std::int64_t nmark = in.integer("point boundary marker flag", kComment);
  if (nattr < 0 || nmark < 0 || nmark > 1) in.fail("bad point attribute or marker counts");
  plc.points.reserve(3 * np);
  std::int64_t base = 0;
  for (std::uint64_t i = 0; i < np; ++i) {
    std::int64_t idx = in.integer("point index", kComment);
    if (i == 0) {
      if (idx != 0 && idx != 1) in.fail("the first point index must be 0 or 1, not " + std::to_string(idx));
      base = idx;
    } else if (idx != base + std::int64_t(i)) {
      in.fail("point index " + std::to_string(idx) + " out of sequence (expected " +
              std::to_string(base + std::int64_t(i)) + ")");
    }
    for (int k = 0; k < 3; ++k) plc.points.push_back(real("coordinate"));
    for (std::int64_t a = 0; a < nattr + nmark; ++a) in.real("point attribute or marker", kComment);
  }
  auto vertex = [&]() {
    std::int64_t v = in.integer("vertex index", kComment) - base;
    if (v < 0 || std::uint64_t(v) >= np)
      in.fail("vertex index " + std::to_string(v + base) + " out of range (" + std::to_string(np) +
              " points)");
    return static_cast<std::uint32_t>(v);
  };
  // Facets.
  const std::uint64_t nf = count("facets", 4);
  const std::int64_t fmark = in.integer("facet marker flag", kComment);
  if (fmark != 0 && fmark != 1) in.fail("facet marker flag must be 0 or 1");
  for (std::uint64_t f = 0; f < nf; ++f) {
    const std::uint64_t npoly = count("polygons", 4);
    if (npoly == 0) in.fail("a facet needs at least one polygon");
    std::uint64_t nholes = 0;
    std::int32_t marker = 0;
    if (!in.at_line_end(kComment)) nholes = count("facet holes", 6);
    if (fmark == 1 && !in.at_line_end(kComment))
      marker = static_cast<std::int32_t>(in.integer("facet marker", kComment));
    for (std::uint64_t p = 0; p < npoly; ++p) {
      const std::uint64_t nv = count("polygon vertices", 2);
      if (nv == 0) in.fail("a polygon needs at least one vertex");
      for (std::uint64_t v = 0; v < nv; ++v) plc.polygon_vertices.push_back(vertex());
      plc.polygon_vertex_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertices.size()));
    }
    for (std::uint64_t h = 0; h < nholes; ++h) {
      in.integer("facet hole index", kComment);
      for (int k = 0; k < 3; ++k) plc.facet_holes.push_back(real("facet hole coordinate"));
    }
    plc.facet_polygon_begin.push_back(static_cast<std::uint32_t>(plc.polygon_vertex_begin.size() - 1));
    plc.facet_marker.push_back(marker);
    plc.facet_hole_begin.push_back(static_cast<std::uint32_t>(plc.facet_holes.size() / 3));
  }
  // Volume holes (optional section at the end of a file).
  if (in.at_end()) return plc;
  const std::uint64_t nh = count("holes", 8);
  for (std::uint64_t h = 0; h < nh; ++h) {
    in.integer("hole index", kComment);
    for (int k = 0; k < 3; ++k) plc.holes.push_back(real("hole coordinate"));
  }
  if (in.at_end()) return plc;
  const std::uint64_t nr = count("regions", 10);
  for (std::uint64_t r = 0; r < nr; ++r) {
    in.integer("region index", kComment);
    RegionSeed s;
    for (double& x : s.point) x = real("region point coordinate");
    double attr = real("region attribute");
    if (std::abs(attr) > 2e9) in.fail("region attribute out of range");
    s.id = static_cast<std::int32_t>(std::lround(attr));
    if (!in.at_line_end(kComment)) s.max_volume = real("region maximum volume");
    plc.regions.push_back(s);
  }
  if (!in.at_end()) in.fail("unexpected data after the region list");
  return plc;
}

void write_poly(const Plc& plc, const std::filesystem::path& path) {
  std::string out;
  out.reserve(64 * plc.point_count() + 32 * plc.polygon_vertices.size() + 256);
  out += "# written by foxi\n";
  io::append_int(out, plc.point_count());
  out += " 3 0 0\n";
  for (std::size_t i = 0; i < plc.point_count(); ++i) {
    io::append_int(out, i + 1);
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      io::append_double(out, plc.points[3 * i + k]);
    }
    out += '\n';
  }
  io::append_int(out, plc.facet_count());
  out += " 1\n";
  for (std::size_t f = 0; f < plc.facet_count(); ++f) {
    const std::uint32_t p0 = plc.facet_polygon_begin[f], p1 = plc.facet_polygon_begin[f + 1];
    const std::uint32_t h0 = plc.facet_hole_begin[f], h1 = plc.facet_hole_begin[f + 1];
    io::append_int(out, p1 - p0);
    out += ' ';
    io::append_int(out, h1 - h0);
    out += ' ';
    io::append_int(out, plc.facet_marker[f]);
    out += '\n';
    for (std::uint32_t p = p0; p < p1; ++p) {
      io::append_int(out, plc.polygon_vertex_begin[p + 1] - plc.polygon_vertex_begin[p]);
      for (std::uint32_t v = plc.polygon_vertex_begin[p]; v < plc.polygon_vertex_begin[p + 1]; ++v) {
        out += ' ';
        io::append_int(out, plc.polygon_vertices[v] + 1);
      }
      out += '\n';
    }
    for (std::uint32_t h = h0; h < h1; ++h) {
      io::append_int(out, h - h0 + 1);
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        io::append_double(out, plc.facet_holes[3 * h + k]);
      }
      out += '\n';
    }
  }
  io::append_int(out, plc.holes.size() / 3);
  out += '\n';
  for (std::size_t h = 0; h < plc.holes.size() / 3; ++h) {
    io::append_int(out, h + 1);
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      io::append_double(out, plc.holes[3 * h + k]);
    }
    out += '\n';
  }
  io::append_int(out, plc.regions.size());
  out += '\n';
  for (std::size_t r = 0; r < plc.regions.size(); ++r) {
    const RegionSeed& s = plc.regions[r];
    io::append_int(out, r + 1);
    for (double x : s.point) {
      out += ' ';
      io::append_double(out, x);
    }
    out += ' ';
    io::append_int(out, s.id);
    out += ' ';
    io::append_double(out, s.max_volume > 0 ? s.max_volume : -1.0);
    out += '\n';
  }
  io::AtomicFile file(path);
  file.write(out);
  file.commit();
}

}  // namespace foxi
