// CalculiX deck writer and .frd reader (see calculix.hpp). Formats: CalculiX 2.20 manual, sections
// *NODE, *ELEMENT (C3D4: faces 1 = 1-2-3, 2 = 1-4-2, 3 = 2-4-3, 4 = 3-4-1), *BOUNDARY (degree of
// freedom 11 is the temperature), *DFLUX (S<face> surface flux into the body, BF body flux per
// volume), *FILM (F<face>, sink temperature, film coefficient), *NODE OUTPUT / *ELEMENT OUTPUT (the
// same results as *NODE FILE / *EL FILE, but ccx writes the .frd binary: float32 values, about one
// digit more than the ASCII file's E12.5); the .frd is read by foxi::fields (read_frd.cpp).
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <limits>
#include <vector>

#include "foxi/fields.hpp"
#include "foxi/model/durable_file.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/solver/calculix.hpp"
#include "elastic_setup.hpp"
#include "p1_assembly.hpp"

namespace foxi {

namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};

std::string elset_name(std::size_t region_index) { return "R" + std::to_string(region_index + 1); }

// A deck being written, durably (durable_file.hpp): a temporary beside the target, written through a
// stdio stream on a duplicate of its descriptor, and renamed over the target by close(); an error or
// an exception before that leaves the target as it was and no temporary. IoError names the file.
class DeckFile {
 public:
  explicit DeckFile(const std::filesystem::path& path) : path_(path), durable_(path) {
    const int fd = ::dup(durable_.fd());
    if (fd < 0 || !(file_ = std::unique_ptr<std::FILE, FileCloser>(::fdopen(fd, "w")))) {
      if (fd >= 0) ::close(fd);
      throw IoError(path_.string(), 0, IoError::kNoOffset, "cannot open for writing");
    }
  }
  std::FILE* get() const { return file_.get(); }
  void close() {
    if (std::ferror(file_.get()) || std::fclose(file_.release()) != 0)
      throw IoError(path_.string(), 0, IoError::kNoOffset, "write failed");
    durable_.commit();
  }

 private:
  std::filesystem::path path_;
  DurableFile durable_;
  std::unique_ptr<std::FILE, FileCloser> file_;
};

// *NODE (node i is CalculiX node i + 1, set NALL) and one C3D4 *ELEMENT block per region of `ids`
// (elset R<index + 1>, tet t is element t + 1). With `edges`, the mid-edge nodes follow (edge e is node
// node_count + e + 1, at the edge's midpoint) and the elements are C3D10 (corners, then the edges in
// kTetEdge order, which is CalculiX's: 1-2, 2-3, 3-1, 1-4, 2-4, 3-4). Coordinates with 14 significant
// digits: ccx reads at most 20 characters per field and rejects "-5.8690046200254745E-05".
void write_nodes_and_elements(std::FILE* out, const Mesh& mesh, const std::vector<std::int32_t>& ids,
                              const detail::TetEdges* edges = nullptr) {
  const std::size_t nn = mesh.node_count();
  std::fprintf(out, "*NODE, NSET=NALL\n");
  for (std::size_t v = 0; v < nn; ++v)
    std::fprintf(out, "%zu, %.14g, %.14g, %.14g\n", v + 1, mesh.xyz[3 * v], mesh.xyz[3 * v + 1],
                 mesh.xyz[3 * v + 2]);
  for (std::size_t e = 0; edges && e < edges->size(); ++e) {
    const double* a = &mesh.xyz[3 * std::size_t{edges->a[e]}];
    const double* b = &mesh.xyz[3 * std::size_t{edges->b[e]}];
    std::fprintf(out, "%zu, %.14g, %.14g, %.14g\n", nn + e + 1, (a[0] + b[0]) / 2, (a[1] + b[1]) / 2,
                 (a[2] + b[2]) / 2);
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    std::fprintf(out, "*ELEMENT, TYPE=%s, ELSET=%s\n", edges ? "C3D10" : "C3D4", elset_name(i).c_str());
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      if (mesh.region_of(t) != ids[i]) continue;
      const std::uint32_t* tv = &mesh.tet[4 * t];
      std::fprintf(out, "%zu, %u, %u, %u, %u", t + 1, tv[0] + 1, tv[1] + 1, tv[2] + 1, tv[3] + 1);
      for (std::size_t k = 0; edges && k < 6; ++k)
        std::fprintf(out, ", %zu", nn + edges->tet_edge[6 * t + k] + 1);
      std::fprintf(out, "\n");
    }
  }
}

// ccx stops on an element whose Jacobian determinant is below 1e-20 in the deck's units (its
// "nonpositive jacobian determinant"), and foxi writes decks in metres: a micrometre model's tets
// (6 V of 3.5e-23 m^3 in trench.toml) failed inside ccx (an outside probe). Refused here, naming
// the smallest.
void refuse_tets_too_small_for_ccx(const Mesh& mesh) {
  double smallest = std::numeric_limits<double>::infinity();
  std::size_t at = 0;
  std::array<std::array<double, 3>, 4> g;
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const double six_v = std::abs(6 * detail::p1_gradients(mesh, t, g));
    if (six_v < smallest) smallest = six_v, at = t;
  }
  if (smallest < 1e-19) {
    char figure[64];
    std::snprintf(figure, sizeof figure, "%.3g", smallest);
    throw SolverInputError(
        "tet " + std::to_string(at) + " has 6 V = " + figure +
        " m^3: ccx refuses elements whose Jacobian determinant is below 1e-20 in the deck's "
        "units, and foxi writes the deck in metres (the model is too small for ccx)");
  }
}

}  // namespace

void write_calculix_thermal(const Mesh& mesh, const ThermalParams& params, const std::filesystem::path& inp) {
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count(), nf = mesh.bface_count();
  if (std::string problem = check_sizes(mesh); !problem.empty())
    throw SolverInputError("inconsistent mesh: " + problem);
  refuse_tets_too_small_for_ccx(mesh);
  // Regions and conductivities, checked as solve_thermal checks them.
  std::vector<std::int32_t> ids;
  for (std::size_t t = 0; t < nt; ++t) ids.push_back(mesh.region_of(t));
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  auto index_of = [&](std::int32_t id) -> std::size_t {
    auto it = std::lower_bound(ids.begin(), ids.end(), id);
    if (it == ids.end() || *it != id) throw SolverInputError("region " + std::to_string(id) + " has no tets");
    return static_cast<std::size_t>(it - ids.begin());
  };
  std::vector<double> k(ids.size(), Material::kUnset), q(ids.size(), 0.0), volume(ids.size(), 0.0);
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (const Region* r = mesh.find_region(ids[i]); r && r->material < mesh.materials.size())
      k[i] = mesh.materials[r->material].thermal_conductivity;
  for (const RegionConductivity& c : params.conductivity) k[index_of(c.region)] = c.k;
  for (std::size_t i = 0; i < ids.size(); ++i)
    if (!(k[i] > 0) || !std::isfinite(k[i]))
      throw SolverInputError("region " + std::to_string(ids[i]) + " has no valid thermal conductivity");
  std::array<std::array<double, 3>, 4> g;
  for (std::size_t t = 0; t < nt; ++t)
    volume[index_of(mesh.region_of(t))] += detail::p1_gradients(mesh, t, g);
  for (const HeatSource& s : params.sources) {
    const std::size_t i = index_of(s.region);
    q[i] = s.total ? s.value / volume[i] : s.value;
  }

  // Each boundary triangle as (element, face) of the tet that has it.
  const detail::NodeTets ntets = detail::node_tets(mesh);
  auto element_face = [&](std::size_t f) -> std::pair<std::size_t, int> {
    const std::uint32_t* v = &mesh.bface[3 * f];
    for (std::size_t k2 = ntets.node_start[v[0]]; k2 < ntets.node_start[v[0] + 1]; ++k2) {
      const std::size_t t = ntets.item[k2] >> 2;
      const std::uint32_t* tv = &mesh.tet[4 * t];
      int missing = -1, found = 0;
      for (int a = 0; a < 4; ++a) {
        if (tv[a] == v[0] || tv[a] == v[1] || tv[a] == v[2])
          ++found;
        else
          missing = a;
      }
      if (found == 3) {
        static const int kFaceOpposite[4] = {3, 4, 2, 1};  // C3D4 face opposite local vertex 0..3
        return {t, kFaceOpposite[missing]};
      }
    }
    throw SolverInputError("boundary triangle " + std::to_string(f) + " is not a face of any tet");
  };

  enum Kind { kFixed, kFlux, kFilm };
  struct Bc {
    Kind kind;
    double a, b;
  };
  std::map<std::int32_t, Bc> bc;
  auto add = [&](std::int32_t tag, Bc b) {
    if (std::find(mesh.bface_tag.begin(), mesh.bface_tag.end(), tag) == mesh.bface_tag.end())
      throw SolverInputError("boundary tag " + std::to_string(tag) + " tags no boundary triangle");
    if (!bc.emplace(tag, b).second)
      throw SolverInputError("boundary tag " + std::to_string(tag) + " has more than one boundary condition");
  };
  for (const FixedTemperature& f : params.fixed) add(f.tag, {kFixed, f.temperature, 0});
  for (const HeatFlux& f : params.flux) add(f.tag, {kFlux, f.flux, 0});
  for (const Convection& c : params.convection) add(c.tag, {kFilm, c.h, c.ambient});

  DeckFile file(inp);
  std::FILE* out = file.get();
  std::fprintf(out, "** foxi: steady heat conduction, %zu nodes, %zu C3D4 elements, SI units\n", nn, nt);
  write_nodes_and_elements(out, mesh, ids);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    std::fprintf(out, "*MATERIAL, NAME=M%zu\n*CONDUCTIVITY\n%.17g\n", i + 1, k[i]);
    std::fprintf(out, "*SOLID SECTION, ELSET=%s, MATERIAL=M%zu\n", elset_name(i).c_str(), i + 1);
  }
  std::fprintf(out, "*STEP\n*HEAT TRANSFER, STEADY STATE\n");
  // Fixed nodes: the lumped-area mean of the fixed tags around each node (as solve_thermal does).
  std::vector<double> sum(nn, 0.0), weight(nn, 0.0), plain(nn, 0.0);
  std::vector<std::uint32_t> count(nn, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = bc.find(mesh.bface_tag[f]);
    if (it == bc.end() || it->second.kind != kFixed) continue;
    const double area = detail::triangle_area(mesh, f);
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t v = mesh.bface[3 * f + i];
      sum[v] += area / 3 * it->second.a;
      weight[v] += area / 3;
      plain[v] += it->second.a;
      ++count[v];
    }
  }
  bool any_fixed = false;
  for (std::size_t v = 0; v < nn; ++v) {
    if (!count[v]) continue;
    if (!any_fixed) std::fprintf(out, "*BOUNDARY\n");
    any_fixed = true;
    std::fprintf(out, "%zu, 11, 11, %.17g\n", v + 1,
                 weight[v] > 0 ? sum[v] / weight[v] : plain[v] / count[v]);
  }
  bool header = false;
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = bc.find(mesh.bface_tag[f]);
    if (it == bc.end() || it->second.kind != kFlux) continue;
    if (!header) std::fprintf(out, "*DFLUX\n");
    header = true;
    const auto [t, face] = element_face(f);
    std::fprintf(out, "%zu, S%d, %.17g\n", t + 1, face, it->second.a);
  }
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (q[i] == 0) continue;
    if (!header) std::fprintf(out, "*DFLUX\n");
    header = true;
    std::fprintf(out, "%s, BF, %.17g\n", elset_name(i).c_str(), q[i]);
  }
  header = false;
  for (std::size_t f = 0; f < nf; ++f) {
    auto it = bc.find(mesh.bface_tag[f]);
    if (it == bc.end() || it->second.kind != kFilm) continue;
    if (!header) std::fprintf(out, "*FILM\n");
    header = true;
    const auto [t, face] = element_face(f);
    std::fprintf(out, "%zu, F%d, %.17g, %.17g\n", t + 1, face, it->second.b, it->second.a);
  }
  std::fprintf(out, "*NODE OUTPUT\nNT\n*END STEP\n");
  file.close();
}

void write_calculix_thermoelastic(const Mesh& mesh, const ThermoelasticParams& params,
                                  const std::filesystem::path& inp) {
  if (std::string problem = check_sizes(mesh); !problem.empty())
    throw SolverInputError("inconsistent mesh: " + problem);
  refuse_tets_too_small_for_ccx(mesh);
  if (params.order != 1 && params.order != 2)
    throw SolverInputError("thermoelastic element order must be 1 or 2, not " + std::to_string(params.order));
  const bool quadratic = params.order == 2;
  const std::size_t nn = mesh.node_count(), nt = mesh.tet_count();
  const detail::ElasticMaterials mat = detail::elastic_materials(mesh, params);
  (void)detail::tet_temperature_change(mesh, params);  // checks the temperature field
  // Quadratic: the mid-edge nodes (nn + e) with the constraints solve_thermoelastic gives them.
  const detail::TetEdges edges = quadratic ? detail::tet_edges(mesh) : detail::TetEdges{};
  const std::size_t n = nn + edges.size();
  std::vector<char> used(n, 0);
  for (std::uint32_t v : mesh.tet) used[v] = 1;
  std::fill(used.begin() + static_cast<std::ptrdiff_t>(nn), used.end(), 1);
  const detail::NodeFrames fr =
      quadratic ? detail::displacement_frames(detail::quadratic_boundary(mesh, edges), params, used)
                : detail::displacement_frames(mesh, params, used);

  DeckFile file(inp);
  std::FILE* out = file.get();
  std::fprintf(out, "** foxi: linear thermoelasticity, %zu nodes, %zu %s elements, SI units\n", n, nt,
               quadratic ? "C3D10" : "C3D4");
  write_nodes_and_elements(out, mesh, mat.regions.ids, quadratic ? &edges : nullptr);
  for (std::size_t i = 0; i < mat.regions.size(); ++i) {
    std::fprintf(out, "*MATERIAL, NAME=M%zu\n*ELASTIC\n%.14g, %.14g\n*EXPANSION\n%.14g\n", i + 1,
                 mat.young[i], mat.poisson[i], mat.expansion[i]);
    std::fprintf(out, "*SOLID SECTION, ELSET=%s, MATERIAL=M%zu\n", elset_name(i).c_str(), i + 1);
  }
  // Values with 14 significant digits: ccx reads at most 20 characters per field.
  // Constraints: frame axes along a coordinate axis as *BOUNDARY, others (sliding planes of other
  // orientations) as homogeneous *EQUATIONs whose dependent term is the largest free component.
  std::string boundary, equation;
  char line[256];
  for (std::size_t v = 0; v < n; ++v) {
    bool taken[3] = {false, false, false};
    std::vector<int> general;
    for (int a = 0; a < fr.m[v]; ++a) {
      const double* q = &fr.r[9 * v + 3 * a];
      int axis = -1;
      for (int c = 0; c < 3; ++c)
        if (std::abs(q[c]) == 1 && q[(c + 1) % 3] == 0 && q[(c + 2) % 3] == 0) axis = c;
      if (axis < 0) {
        general.push_back(a);
        continue;
      }
      taken[axis] = true;
      std::snprintf(line, sizeof line, "%zu, %d, %d, %.14g\n", v + 1, axis + 1, axis + 1,
                    q[axis] * fr.g[3 * v + a]);
      boundary += line;
    }
    for (int a : general) {
      const double* q = &fr.r[9 * v + 3 * a];
      if (fr.g[3 * v + a] != 0)
        throw SolverInputError(
            "CalculiX deck: node " + std::to_string(v) +
            " has a non-zero displacement prescribed along a direction that is no coordinate axis");
      int dep = -1;
      for (int c = 0; c < 3; ++c)
        if (!taken[c] && std::abs(q[c]) > 1e-3 && (dep < 0 || std::abs(q[c]) > std::abs(q[dep]))) dep = c;
      if (dep < 0)
        throw SolverInputError("CalculiX deck: no free component for the constraint at node " +
                               std::to_string(v));
      taken[dep] = true;
      int terms = 0;
      std::string row;
      for (int k = 0; k < 3; ++k) {
        const int c = (dep + k) % 3;
        if (q[c] == 0) continue;
        std::snprintf(line, sizeof line, "%s%zu, %d, %.14g", terms ? ", " : "", v + 1, c + 1, q[c]);
        row += line;
        ++terms;
      }
      equation += std::to_string(terms) + "\n" + row + "\n";
    }
  }
  if (!boundary.empty()) std::fprintf(out, "*BOUNDARY\n%s", boundary.c_str());
  if (!equation.empty()) std::fprintf(out, "*EQUATION\n%s", equation.c_str());
  // Thermal strain alpha (T - T_initial): the reference temperature is the initial condition.
  const double tref = params.temperature.empty() ? 0.0 : params.reference_temperature;
  std::fprintf(out, "*INITIAL CONDITIONS, TYPE=TEMPERATURE\nNALL, %.14g\n*STEP\n*STATIC\n*TEMPERATURE\n",
               tref);
  if (params.temperature.empty()) {
    std::fprintf(out, "NALL, %.14g\n", tref + params.delta_t);
  } else {
    for (std::size_t v = 0; v < nn; ++v)
      if (used[v]) std::fprintf(out, "%zu, %.14g\n", v + 1, params.temperature[v]);
    for (std::size_t e = 0; e < edges.size(); ++e)  // the P1 interpolation, as solve_thermoelastic uses
      std::fprintf(out, "%zu, %.14g\n", nn + e + 1,
                   (params.temperature[edges.a[e]] + params.temperature[edges.b[e]]) / 2);
  }
  std::fprintf(out, "*NODE OUTPUT\nU\n*ELEMENT OUTPUT\nS\n");
  // C3D10: the stresses at the 4 integration points in the .dat (their mean is the centroid stress).
  for (std::size_t i = 0; quadratic && i < mat.regions.size(); ++i)
    std::fprintf(out, "*EL PRINT, ELSET=%s\nS\n", elset_name(i).c_str());
  std::fprintf(out, "*END STEP\n");
  file.close();
}

// One reader of .frd files in foxi: foxi::fields' (which checks the node block, the record lengths,
// every number, the steps); its fields here as the blocks of the file, step by step.
std::vector<FrdBlock> read_frd(const std::filesystem::path& frd) {
  const FieldSource src = read_frd_source(frd);
  std::size_t steps = 0;
  for (const Field& f : src.mesh.fields) steps = std::max(steps, f.step_count());
  std::vector<FrdBlock> blocks;
  const std::size_t n = src.node_id.size();
  for (std::size_t st = 0; st < steps; ++st)
    for (const Field& f : src.mesh.fields) {
      if (f.location != FieldLocation::node || st >= f.step_count()) continue;
      FrdBlock b;
      b.name = f.name;
      b.components = f.components;
      for (std::size_t i = 0; i < n; ++i) {
        const auto v = f.values.begin() + std::ptrdiff_t((st * n + i) * f.components);
        // a node the block leaves out has no values (NaN) in the source: not one of the block's
        if (std::all_of(v, v + f.components, [](double x) { return std::isnan(x); })) continue;
        b.node.push_back(static_cast<std::uint32_t>(src.node_id[i]));
        b.values.insert(b.values.end(), v, v + f.components);
      }
      blocks.push_back(std::move(b));
    }
  return blocks;
}

}  // namespace foxi
