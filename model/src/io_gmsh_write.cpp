// Gmsh .msh 2.2 and 4.1 writer, ASCII and binary (the reader and its choices are io_gmsh_read.cpp).
#include "foxi/model/io_gmsh.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "foxi/model/io_error.hpp"
#include "io_util.hpp"

namespace foxi {
namespace {

class Out {
 public:
  explicit Out(io::AtomicFile& f) : f_(f) { buf_.reserve(kChunk + 4096); }
  std::string& buf() { return buf_; }
  void text(std::string_view s) { buf_.append(s); }
  template <class T>
  void raw(const T& v) {
    buf_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void raw_bytes(const void* p, std::size_t n) { buf_.append(static_cast<const char*>(p), n); }
  void maybe_flush() {
    if (buf_.size() >= kChunk) flush();
  }
  void flush() {
    f_.write(buf_);
    buf_.clear();
  }

 private:
  static constexpr std::size_t kChunk = 1 << 20;
  io::AtomicFile& f_;
  std::string buf_;
};

std::string clean_name(const std::string& s) {
  std::string r = s;
  for (char& c : r) {
    if (c == '"' || c == '\n' || c == '\r') c = '_';
  }
  return r;
}

struct Run {
  std::size_t begin, end;  // element range
  std::size_t entity;      // index into the entity list (0-based)
};

// Maximal runs of equal tags, so that the file keeps the element order of the mesh.
std::vector<Run> runs_of(std::size_t count, const std::vector<std::int32_t>& tags,
                         const std::vector<std::int32_t>& ids) {
  std::vector<Run> runs;
  std::size_t b = 0;
  auto entity = [&](std::int32_t t) {
    return static_cast<std::size_t>(std::lower_bound(ids.begin(), ids.end(), t) - ids.begin());
  };
  while (b < count) {
    std::int32_t t = tags.empty() ? 0 : tags[b];
    std::size_t e = b + 1;
    while (e < count && (tags.empty() ? 0 : tags[e]) == t) ++e;
    runs.push_back({b, e, entity(t)});
    b = e;
  }
  return runs;
}

void write_impl(const Mesh& mesh, const std::filesystem::path& path, const GmshWriteOptions& opt) {
  const std::string name = path.string();
  if (opt.version != 22 && opt.version != 41) {
    throw IoError(name, 0, IoError::kNoOffset,
                  "cannot write Gmsh version " + std::to_string(opt.version) + " (only 22 and 41)");
  }
  std::string problem = check_sizes(mesh);
  if (!problem.empty()) throw IoError(name, 0, IoError::kNoOffset, "inconsistent mesh: " + problem);
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nb = mesh.bface_count();
  for (std::uint32_t v : mesh.tet) {
    if (v >= nn)
      throw IoError(name, 0, IoError::kNoOffset,
                    "a tet refers to node " + std::to_string(v) + " of " + std::to_string(nn));
  }
  for (std::uint32_t v : mesh.bface) {
    if (v >= nn)
      throw IoError(name, 0, IoError::kNoOffset,
                    "a boundary triangle refers to node " + std::to_string(v) + " of " + std::to_string(nn));
  }
  if (nn > 0x7fffffffu || nt + nb > 0x7fffffffu) {
    throw IoError(name, 0, IoError::kNoOffset, "too many nodes or elements for a Gmsh file");
  }
  const bool bin = opt.binary;
  const bool v41 = opt.version == 41;

  // Entities: one volume per region id, one surface per boundary tag (sorted ids).
  std::vector<std::int32_t> vol_ids, surf_ids;
  for (std::size_t t = 0; t < nt; ++t) vol_ids.push_back(mesh.region_of(t));
  for (const Region& r : mesh.regions) vol_ids.push_back(r.id);
  std::sort(vol_ids.begin(), vol_ids.end());
  vol_ids.erase(std::unique(vol_ids.begin(), vol_ids.end()), vol_ids.end());
  if (vol_ids.empty()) vol_ids.push_back(0);
  surf_ids = mesh.bface_tag;
  for (const Boundary& b : mesh.boundaries) surf_ids.push_back(b.tag);
  std::sort(surf_ids.begin(), surf_ids.end());
  surf_ids.erase(std::unique(surf_ids.begin(), surf_ids.end()), surf_ids.end());
  const std::vector<Run> tet_runs = runs_of(nt, mesh.tet_region, vol_ids);
  const std::vector<Run> tri_runs = runs_of(nb, mesh.bface_tag, surf_ids);

  io::AtomicFile file(path);
  Out o(file);
  std::string& s = o.buf();
  auto line_int = [&](auto v) {
    io::append_int(s, v);
    s += '\n';
  };

  // $MeshFormat
  s += v41 ? "$MeshFormat\n4.1 " : "$MeshFormat\n2.2 ";
  s += bin ? "1 8\n" : "0 8\n";
  if (bin) {
    o.raw(std::int32_t{1});
    s += '\n';
  }
  s += "$EndMeshFormat\n";

  // $PhysicalNames
  std::size_t named = 0;
  for (const Boundary& b : mesh.boundaries) named += !b.name.empty() && b.tag != 0;
  for (const Region& r : mesh.regions) named += !r.name.empty() && r.id != 0;
  if (named > 0) {
    s += "$PhysicalNames\n";
    line_int(named);
    for (const Boundary& b : mesh.boundaries) {
      if (b.name.empty() || b.tag == 0) continue;
      s += "2 ";
      io::append_int(s, b.tag);
      s += " \"" + clean_name(b.name) + "\"\n";
    }
    for (const Region& r : mesh.regions) {
      if (r.name.empty() || r.id == 0) continue;
      s += "3 ";
      io::append_int(s, r.id);
      s += " \"" + clean_name(r.name) + "\"\n";
    }
    s += "$EndPhysicalNames\n";
  }

  if (v41) {
    // Bounding box of all nodes (entities carry one; gmsh does not rely on it for discrete ones).
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    bool any = false;
    for (std::size_t i = 0; i < nn; ++i) {
      for (int k = 0; k < 3; ++k) {
        double x = mesh.xyz[3 * i + k];
        if (!std::isfinite(x)) continue;
        if (!any) {
          lo[k] = hi[k] = x;
        } else {
          lo[k] = std::min(lo[k], x);
          hi[k] = std::max(hi[k], x);
        }
      }
      any = true;
    }
    s += "$Entities\n";
    auto entity = [&](std::size_t tag, std::int32_t phys) {
      if (bin) {
        o.raw(static_cast<std::int32_t>(tag));
        o.raw_bytes(lo, 24);
        o.raw_bytes(hi, 24);
        o.raw(static_cast<std::uint64_t>(phys != 0));
        if (phys != 0) o.raw(phys);
        o.raw(std::uint64_t{0});
      } else {
        io::append_int(s, tag);
        for (double x : lo) s += ' ', io::append_double(s, x);
        for (double x : hi) s += ' ', io::append_double(s, x);
        s += phys != 0 ? " 1 " : " 0";
        if (phys != 0) io::append_int(s, phys);
        s += " 0\n";
      }
    };
    if (bin) {
      const std::uint64_t counts[4] = {0, 0, surf_ids.size(), vol_ids.size()};
      o.raw_bytes(counts, sizeof counts);
    } else {
      s += "0 0 ";
      io::append_int(s, surf_ids.size());
      s += ' ';
      line_int(vol_ids.size());
    }
    for (std::size_t i = 0; i < surf_ids.size(); ++i) entity(i + 1, surf_ids[i]);
    for (std::size_t i = 0; i < vol_ids.size(); ++i) entity(i + 1, vol_ids[i]);
    s += bin ? "\n$EndEntities\n" : "$EndEntities\n";

    // $Nodes: one block in the first volume entity, tags 1..n in mesh order.
    s += "$Nodes\n";
    if (bin) {
      const std::uint64_t h[4] = {1, nn, nn ? 1u : 0u, nn};
      o.raw_bytes(h, sizeof h);
      const std::int32_t bh[3] = {3, 1, 0};
      o.raw_bytes(bh, sizeof bh);
      o.raw(static_cast<std::uint64_t>(nn));
      for (std::uint64_t i = 1; i <= nn; ++i) {
        o.raw(i);
        o.maybe_flush();
      }
      o.flush();
      file.write(mesh.xyz.data(), mesh.xyz.size() * sizeof(double));
      s += '\n';
    } else {
      s += "1 ";
      io::append_int(s, nn);
      s += nn ? " 1 " : " 0 ";
      line_int(nn);
      s += "3 1 0 ";
      line_int(nn);
      for (std::size_t i = 1; i <= nn; ++i) {
        line_int(i);
        o.maybe_flush();
      }
      for (std::size_t i = 0; i < nn; ++i) {
        io::append_double(s, mesh.xyz[3 * i]);
        s += ' ';
        io::append_double(s, mesh.xyz[3 * i + 1]);
        s += ' ';
        io::append_double(s, mesh.xyz[3 * i + 2]);
        s += '\n';
        o.maybe_flush();
      }
    }
    s += "$EndNodes\n";

    // $Elements: triangles tagged nt+1.., tets tagged 1..nt, one block per run.
    s += "$Elements\n";
    const std::uint64_t ne = nt + nb;
    const std::uint64_t head[4] = {tri_runs.size() + tet_runs.size(), ne, ne ? 1u : 0u, ne};
    if (bin) {
      o.raw_bytes(head, sizeof head);
    } else {
      for (int k = 0; k < 4; ++k) {
        io::append_int(s, head[k]);
        s += k < 3 ? ' ' : '\n';
      }
    }
    auto block = [&](const Run& r, int dim, int type, int nv, const std::vector<std::uint32_t>& conn,
                     std::uint64_t tag0) {
      if (bin) {
        const std::int32_t bh[3] = {dim, static_cast<std::int32_t>(r.entity + 1), type};
        o.raw_bytes(bh, sizeof bh);
        o.raw(static_cast<std::uint64_t>(r.end - r.begin));
        for (std::size_t e = r.begin; e < r.end; ++e) {
          std::uint64_t rec[5];
          rec[0] = tag0 + e;
          for (int k = 0; k < nv; ++k) rec[1 + k] = std::uint64_t{conn[nv * e + k]} + 1;
          o.raw_bytes(rec, 8 * (1 + nv));
          o.maybe_flush();
        }
      } else {
        io::append_int(s, dim);
        s += ' ';
        io::append_int(s, r.entity + 1);
        s += ' ';
        io::append_int(s, type);
        s += ' ';
        line_int(r.end - r.begin);
        for (std::size_t e = r.begin; e < r.end; ++e) {
          io::append_int(s, tag0 + e);
          for (int k = 0; k < nv; ++k) {
            s += ' ';
            io::append_int(s, std::uint64_t{conn[nv * e + k]} + 1);
          }
          s += '\n';
          o.maybe_flush();
        }
      }
    };
    for (const Run& r : tri_runs) block(r, 2, 2, 3, mesh.bface, nt + 1);
    for (const Run& r : tet_runs) block(r, 3, 4, 4, mesh.tet, 1);
    s += bin ? "\n$EndElements\n" : "$EndElements\n";
  } else {
    // 2.2
    s += "$Nodes\n";
    line_int(nn);
    if (bin) {
      for (std::size_t i = 0; i < nn; ++i) {
        o.raw(static_cast<std::int32_t>(i + 1));
        o.raw_bytes(&mesh.xyz[3 * i], 24);
        o.maybe_flush();
      }
      s += '\n';
    } else {
      for (std::size_t i = 0; i < nn; ++i) {
        io::append_int(s, i + 1);
        for (int k = 0; k < 3; ++k) {
          s += ' ';
          io::append_double(s, mesh.xyz[3 * i + k]);
        }
        s += '\n';
        o.maybe_flush();
      }
    }
    s += "$EndNodes\n$Elements\n";
    line_int(nt + nb);
    auto elements = [&](std::size_t count, int type, int nv, const std::vector<std::uint32_t>& conn,
                        const std::vector<std::int32_t>& tags, const std::vector<std::int32_t>& ids,
                        std::size_t tag0) {
      if (count == 0) return;
      if (bin) {
        const std::int32_t h[3] = {type, static_cast<std::int32_t>(count), 2};
        o.raw_bytes(h, sizeof h);
      }
      for (std::size_t e = 0; e < count; ++e) {
        const std::int32_t phys = tags.empty() ? 0 : tags[e];
        const std::int32_t ent =
            static_cast<std::int32_t>(std::lower_bound(ids.begin(), ids.end(), phys) - ids.begin() + 1);
        if (bin) {
          std::int32_t rec[7] = {static_cast<std::int32_t>(tag0 + e), phys, ent};
          for (int k = 0; k < nv; ++k) rec[3 + k] = static_cast<std::int32_t>(conn[nv * e + k] + 1);
          o.raw_bytes(rec, 4 * (3 + nv));
        } else {
          io::append_int(s, tag0 + e);
          s += ' ';
          io::append_int(s, type);
          s += " 2 ";
          io::append_int(s, phys);
          s += ' ';
          io::append_int(s, ent);
          for (int k = 0; k < nv; ++k) {
            s += ' ';
            io::append_int(s, conn[nv * e + k] + 1);
          }
          s += '\n';
        }
        o.maybe_flush();
      }
    };
    elements(nb, 2, 3, mesh.bface, mesh.bface_tag, surf_ids, nt + 1);
    elements(nt, 4, 4, mesh.tet, mesh.tet_region, vol_ids, 1);
    s += bin ? "\n$EndElements\n" : "$EndElements\n";
  }

  // Fields: one $NodeData / $ElementData block per step; entities whose values are all NaN are left
  // out (the reader gives NaN for entities not listed).
  for (const Field& f : mesh.fields) {
    const bool node = f.location == FieldLocation::node;
    const std::size_t ne = node ? nn : nt;
    const std::size_t nc = f.components;
    for (std::size_t st = 0; st < f.step_count(); ++st) {
      std::span<const double> v = f.step(st, ne);
      std::size_t listed = 0;
      auto listed_entity = [&](std::size_t e) {
        for (std::size_t k = 0; k < nc; ++k) {
          if (!std::isnan(v[nc * e + k])) return true;
        }
        return false;
      };
      for (std::size_t e = 0; e < ne; ++e) listed += listed_entity(e);
      s += node ? "$NodeData\n1\n\"" : "$ElementData\n1\n\"";
      s += clean_name(f.name);
      s += "\"\n1\n";
      io::append_double(s, f.step_values.empty() ? 0.0 : f.step_values[st]);
      s += "\n3\n";
      line_int(st);
      line_int(nc);
      line_int(listed);
      for (std::size_t e = 0; e < ne; ++e) {
        if (!listed_entity(e)) continue;
        if (bin) {
          o.raw(static_cast<std::int32_t>(e + 1));
          o.raw_bytes(&v[nc * e], 8 * nc);
        } else {
          io::append_int(s, e + 1);
          for (std::size_t k = 0; k < nc; ++k) {
            s += ' ';
            io::append_double(s, v[nc * e + k]);
          }
          s += '\n';
        }
        o.maybe_flush();
      }
      if (bin) s += '\n';
      s += node ? "$EndNodeData\n" : "$EndElementData\n";
    }
  }
  o.flush();
  file.commit();
}

}  // namespace

void write_gmsh(const Mesh& mesh, const std::filesystem::path& path, const GmshWriteOptions& options) {
  write_impl(mesh, path, options);
}

}  // namespace foxi
