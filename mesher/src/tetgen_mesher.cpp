#include "foxi/mesher/tetgen_mesher.hpp"

#define TETLIBRARY
#include <tetgen.h>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/model/cleanup.hpp"

namespace foxi {

namespace {

std::string tetgen_message(int code) {
  switch (code) {
    case 1:
      return "TetGen ran out of memory";
    case 2:
      return "TetGen met an internal error";
    case 3:
      return "the PLC has self-intersecting facets";
    case 4:
      return "the PLC has a feature smaller than TetGen's tolerance";
    case 5:
      return "the PLC has two facets too close to each other";
    case 10:
      return "TetGen rejected the input PLC";
    default:
      return "TetGen failed with code " + std::to_string(code);
  }
}

bool write_all(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    ssize_t n = ::write(fd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

// The mesh TetGen returns, as it crosses the pipe from the child process.
struct Result {
  std::int64_t status = 0;  // 0 = ok, else TetGen's error code
  std::vector<double> points;
  std::vector<int> tets, trifaces, trimarkers;
  std::vector<double> attributes;  // one per tet (first attribute), or empty
};

// Runs TetGen in a child process: TetGen 1.5's library frees its memory twice when it stops on an
// error (terminatetetgen() then the mesh destructor), which crashes the caller; in a child the crash
// becomes an error message.
Result run_isolated(tetgenio& in, tetgenio* background, char* switches, const ProgressFn& progress,
                    double time_limit) {
  int fds[2];
  if (::pipe(fds) != 0) throw MesherError(1, std::string("cannot create a pipe: ") + std::strerror(errno));
  std::fflush(nullptr);
  // Tracked (foxi/model/cleanup.hpp): a program stopped by a signal kills it, and it dies with
  // its parent even if the parent is killed outright.
  pid_t pid = cleanup::fork_tracked();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw MesherError(1, std::string("cannot start TetGen: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    std::int64_t status = 0;
    tetgenio out;
    try {
      tetrahedralize(switches, &in, &out, nullptr, background);
    } catch (int code) {
      status = code == 0 ? 2 : code;
    } catch (...) {
      status = 1;
    }
    bool ok = write_all(fds[1], &status, sizeof status);
    if (ok && status == 0) {
      std::int64_t head[5] = {out.numberofpoints, out.numberoftetrahedra, out.numberofcorners,
                              out.numberoftrifaces, out.numberoftetrahedronattributes};
      ok = write_all(fds[1], head, sizeof head) &&
           write_all(fds[1], out.pointlist, sizeof(double) * 3 * std::size_t(out.numberofpoints)) &&
           write_all(fds[1], out.tetrahedronlist,
                     sizeof(int) * std::size_t(out.numberofcorners) * std::size_t(out.numberoftetrahedra)) &&
           write_all(fds[1], out.trifacelist, sizeof(int) * 3 * std::size_t(out.numberoftrifaces));
      std::vector<int> markers(std::size_t(out.numberoftrifaces), 0);
      if (out.trifacemarkerlist)
        std::copy(out.trifacemarkerlist, out.trifacemarkerlist + out.numberoftrifaces, markers.begin());
      std::vector<double> attr(std::size_t(out.numberoftetrahedra), 0.0);
      if (out.numberoftetrahedronattributes > 0)
        for (std::size_t t = 0; t < attr.size(); ++t)
          attr[t] = out.tetrahedronattributelist[t * std::size_t(out.numberoftetrahedronattributes)];
      ok = ok && write_all(fds[1], markers.data(), sizeof(int) * markers.size()) &&
           write_all(fds[1], attr.data(), sizeof(double) * attr.size());
    }
    ::close(fds[1]);
    ::_exit(ok ? 0 : 3);
  }
  ::close(fds[1]);
  std::vector<char> buf;
  char chunk[1 << 16];
  const auto start = std::chrono::steady_clock::now();
  // Reaped and forgotten with the cleanup list locked: an interrupt never kills a process id that
  // was already reaped (and could be reused), nor misses a live child.
  auto reap = [&](int* ws) {
    cleanup::with_lock([&] {
      while (::waitpid(pid, ws, 0) < 0 && errno == EINTR) {
      }
      cleanup::untrack_child(pid);
    });
  };
  auto stop_child = [&] {
    ::kill(pid, SIGKILL);
    ::close(fds[0]);
    int ws = 0;
    reap(&ws);
  };
  for (;;) {
    if (time_limit > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > time_limit) {
      stop_child();
      throw MesherError(2,
                        "TetGen did not finish within " + std::to_string(int(time_limit)) + " s on this PLC");
    }
    if (progress || time_limit > 0) {
      // TetGen reports no progress of its own: the callback is asked every 100 ms (fraction -1,
      // "unknown") so that a user can cancel, which stops the child.
      pollfd pfd{fds[0], POLLIN, 0};
      int ready = ::poll(&pfd, 1, 100);
      // A signal (the app's Ctrl-C handler) interrupts poll: ask the callback now rather than
      // blocking in read() until TetGen ends.
      if (ready == 0 || (ready < 0 && errno == EINTR)) {
        if (progress && !progress("meshing", -1.0)) {
          stop_child();
          throw MesherCancelled("meshing cancelled");
        }
        continue;
      }
    }
    ssize_t n = ::read(fds[0], chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    buf.insert(buf.end(), chunk, chunk + n);
  }
  ::close(fds[0]);
  int wstatus = 0;
  reap(&wstatus);
  Result r;
  std::size_t at = 0;
  auto take = [&](void* dst, std::size_t bytes) {
    if (buf.size() - at < bytes) return false;
    if (bytes > 0) std::memcpy(dst, buf.data() + at, bytes);  // an empty list's data() may be null
    at += bytes;
    return true;
  };
  if (!take(&r.status, sizeof r.status)) {
    if (WIFSIGNALED(wstatus))
      throw MesherError(2, "TetGen crashed (signal " + std::to_string(WTERMSIG(wstatus)) + ") on this PLC");
    throw MesherError(2, "TetGen stopped without a result");
  }
  if (r.status != 0) return r;
  std::int64_t head[5];
  if (!take(head, sizeof head) || head[2] != 4)
    throw MesherError(2, "TetGen returned an incomplete or unexpected mesh");
  r.points.resize(3 * std::size_t(head[0]));
  r.tets.resize(4 * std::size_t(head[1]));
  r.trifaces.resize(3 * std::size_t(head[3]));
  r.trimarkers.resize(std::size_t(head[3]));
  r.attributes.resize(std::size_t(head[1]));
  if (!take(r.points.data(), sizeof(double) * r.points.size()) ||
      !take(r.tets.data(), sizeof(int) * r.tets.size()) ||
      !take(r.trifaces.data(), sizeof(int) * r.trifaces.size()) ||
      !take(r.trimarkers.data(), sizeof(int) * r.trimarkers.size()) ||
      !take(r.attributes.data(), sizeof(double) * r.attributes.size()))
    throw MesherError(2, "TetGen's result was cut short");
  if (head[4] == 0) r.attributes.clear();
  return r;
}

std::string format_number(double v);

// TetGen 1.5 crashes on some self-intersecting PLCs instead of saying so: its self-intersection check
// (-d) names them. Returns "; TetGen's self-intersection check finds ..." or "" (none found, or the
// check itself failed).
std::string intersections_found(tetgenio& in, const MeshParams& params) {
  char switches[] = "pdzQ";
  Result r;
  try {
    r = run_isolated(in, nullptr, switches, params.progress, params.time_limit);
  } catch (const MesherError& e) {
    if (e.tetgen_code() == -1) throw;  // cancelled
    return "";
  }
  const std::size_t nf = r.trifaces.size() / 3, np = r.points.size() / 3;
  if (r.status != 0 || nf < 2) return "";
  auto triangle = [&](std::size_t f) {
    std::string t;
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(r.trifaces[3 * f + std::size_t(k)]);
      if (v >= np) return std::string("(?)");
      t += (k ? " (" : "(") + format_number(r.points[3 * v]) + ", " + format_number(r.points[3 * v + 1]) +
           ", " + format_number(r.points[3 * v + 2]) + ")";
    }
    return t;
  };
  return "; TetGen's self-intersection check finds " + std::to_string(nf) +
         " facet triangles that intersect others, e.g. " + triangle(0) + " and " + triangle(1);
}

std::string format_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

}  // namespace

Mesh mesh_plc(const Plc& plc, const MeshParams& params, MeshReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!(params.radius_edge == 0 ||
        (params.radius_edge >= kMinRadiusEdgeBound && std::isfinite(params.radius_edge))))
    throw MesherError(10, "the radius-edge bound must be 0 (no quality refinement) or at least " +
                              format_number(kMinRadiusEdgeBound) + ", not " +
                              format_number(params.radius_edge) +
                              " (TetGen's refinement does not finish below it on thin layers)");
  if (plc.point_count() < 4) throw MesherError(10, "a PLC needs at least 4 points");
  if (plc.facet_count() < 4) throw MesherError(10, "a PLC needs at least 4 facets");
  for (std::uint32_t v : plc.polygon_vertices)
    if (v >= plc.point_count())
      throw MesherError(
          10, "a facet names point " + std::to_string(v) + " of " + std::to_string(plc.point_count()));

  // tetgenio owns its arrays and frees them with delete[]: fill it with new[] allocations.
  tetgenio in;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(plc.point_count());
  in.pointlist = new REAL[plc.points.size()];
  std::copy(plc.points.begin(), plc.points.end(), in.pointlist);
  in.numberoffacets = static_cast<int>(plc.facet_count());
  in.facetlist = new tetgenio::facet[plc.facet_count()];
  in.facetmarkerlist = new int[plc.facet_count()];
  for (std::size_t f = 0; f < plc.facet_count(); ++f) {
    tetgenio::facet& fc = in.facetlist[f];
    tetgenio::init(&fc);
    const std::uint32_t p0 = plc.facet_polygon_begin[f], p1 = plc.facet_polygon_begin[f + 1];
    fc.numberofpolygons = static_cast<int>(p1 - p0);
    fc.polygonlist = new tetgenio::polygon[p1 - p0];
    for (std::uint32_t p = p0; p < p1; ++p) {
      tetgenio::polygon& pg = fc.polygonlist[p - p0];
      tetgenio::init(&pg);
      const std::uint32_t v0 = plc.polygon_vertex_begin[p], v1 = plc.polygon_vertex_begin[p + 1];
      pg.numberofvertices = static_cast<int>(v1 - v0);
      pg.vertexlist = new int[v1 - v0];
      for (std::uint32_t v = v0; v < v1; ++v)
        pg.vertexlist[v - v0] = static_cast<int>(plc.polygon_vertices[v]);
    }
    const std::uint32_t h0 = plc.facet_hole_begin[f], h1 = plc.facet_hole_begin[f + 1];
    if (h1 > h0) {
      fc.numberofholes = static_cast<int>(h1 - h0);
      fc.holelist = new REAL[3 * (h1 - h0)];
      std::copy(plc.facet_holes.begin() + 3 * h0, plc.facet_holes.begin() + 3 * h1, fc.holelist);
    }
    in.facetmarkerlist[f] = plc.facet_marker[f];
  }
  if (!plc.holes.empty()) {
    in.numberofholes = static_cast<int>(plc.holes.size() / 3);
    in.holelist = new REAL[plc.holes.size()];
    std::copy(plc.holes.begin(), plc.holes.end(), in.holelist);
  }
  if (!plc.regions.empty()) {
    in.numberofregions = static_cast<int>(plc.regions.size());
    in.regionlist = new REAL[5 * plc.regions.size()];
    for (std::size_t r = 0; r < plc.regions.size(); ++r) {
      const RegionSeed& s = plc.regions[r];
      in.regionlist[5 * r] = s.point[0];
      in.regionlist[5 * r + 1] = s.point[1];
      in.regionlist[5 * r + 2] = s.point[2];
      in.regionlist[5 * r + 3] = s.id;
      in.regionlist[5 * r + 4] = s.max_volume > 0 ? s.max_volume : -1;
    }
  }

  // p: PLC (boundary and interface triangles come out with their markers); z: 0-based; Q: quiet; A: regions;
  // q: quality; a: volume limits; O0: no flips or smoothing.
  std::string sw = "pzQ";
  if (params.regions && !plc.regions.empty()) sw += "A";
  if (params.radius_edge > 0) {
    sw += "q" + format_number(params.radius_edge);
    if (params.min_dihedral > 0) sw += "/" + format_number(params.min_dihedral);
  }
  bool any_region_volume = false;
  for (const RegionSeed& s : plc.regions) any_region_volume = any_region_volume || s.max_volume > 0;
  if (params.max_volume > 0) sw += "a" + format_number(params.max_volume);
  if (any_region_volume) sw += "a";
  if (!params.optimize) sw += "O0";
  tetgenio background;
  const bool sized = params.size_field && !params.size_field->empty();
  if (sized) {
    const SizeField& sf = *params.size_field;
    const std::size_t nb = sf.xyz.size() / 3;
    if (sf.size.size() != nb || sf.tet.size() % 4 != 0 || sf.tet.empty())
      throw MesherError(10, "the size field's background mesh is inconsistent");
    for (std::uint32_t v : sf.tet)
      if (v >= nb) throw MesherError(10, "the size field's background mesh has a node index out of range");
    background.firstnumber = 0;
    background.numberofpoints = static_cast<int>(nb);
    background.pointlist = new REAL[sf.xyz.size()];
    std::copy(sf.xyz.begin(), sf.xyz.end(), background.pointlist);
    background.numberofpointmtrs = 1;
    background.pointmtrlist = new REAL[nb];
    std::copy(sf.size.begin(), sf.size.end(), background.pointmtrlist);
    background.numberoftetrahedra = static_cast<int>(sf.tet.size() / 4);
    background.numberofcorners = 4;
    background.tetrahedronlist = new int[sf.tet.size()];
    for (std::size_t i = 0; i < sf.tet.size(); ++i)
      background.tetrahedronlist[i] = static_cast<int>(sf.tet[i]);
    sw += "m";
  }
  std::vector<char> switches(sw.begin(), sw.end());
  switches.push_back('\0');
  Result res;
  try {
    res =
        run_isolated(in, sized ? &background : nullptr, switches.data(), params.progress, params.time_limit);
  } catch (const MesherError& e) {
    // The child died (a signal; under a sanitizer, an exit after its report) without a result.
    const std::string_view what = e.what();
    if (e.tetgen_code() != 2 ||
        (what.find("crashed") == what.npos && what.find("without a result") == what.npos))
      throw;
    throw MesherError(2, e.what() + intersections_found(in, params));
  }
  if (res.status != 0)
    throw MesherError(static_cast<int>(res.status), tetgen_message(static_cast<int>(res.status)));

  Mesh m;
  const std::size_t np = res.points.size() / 3;
  m.xyz = std::move(res.points);
  const std::size_t nt = res.tets.size() / 4;
  m.tet.resize(4 * nt);
  for (std::size_t i = 0; i < 4 * nt; ++i) {
    if (res.tets[i] < 0 || std::size_t(res.tets[i]) >= np)
      throw MesherError(2, "TetGen returned a tet index out of range");
    m.tet[i] = static_cast<std::uint32_t>(res.tets[i]);
  }
  m.tet_region.assign(nt, 0);
  for (std::size_t t = 0; t < res.attributes.size(); ++t)
    m.tet_region[t] = static_cast<std::int32_t>(std::lround(res.attributes[t]));
  const std::size_t nf = res.trifaces.size() / 3;
  m.bface.resize(3 * nf);
  for (std::size_t i = 0; i < 3 * nf; ++i) {
    if (res.trifaces[i] < 0 || std::size_t(res.trifaces[i]) >= np)
      throw MesherError(2, "TetGen returned a face index out of range");
    m.bface[i] = static_cast<std::uint32_t>(res.trifaces[i]);
  }
  m.bface_tag.assign(res.trimarkers.begin(), res.trimarkers.end());
  std::vector<std::int32_t> ids(m.tet_region);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  for (std::int32_t id : ids) m.regions.push_back(Region{id, {}, kNone});
  std::vector<std::int32_t> tags(m.bface_tag);
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());
  for (std::int32_t tag : tags) m.boundaries.push_back(Boundary{tag, {}});
  if (report) {
    report->switches = sw;
    report->input_points = plc.point_count();
    report->steiner_points = np > plc.point_count() ? np - plc.point_count() : 0;
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return m;
}

}  // namespace foxi
