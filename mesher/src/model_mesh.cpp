// A model file to a certified, named mesh (model_mesh.hpp).
#include "foxi/mesher/model_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "foxi/mesher/model_mesh_params.hpp"
#include "foxi/mesher/size_field.hpp"
#include "foxi/model/diagnostics.hpp"
#include "foxi/model/io_error.hpp"
#include "foxi/model/delaunay.hpp"

namespace foxi {

namespace {

std::string tet_limit_reason(double estimate, double limit) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "the mesh would have about %.3g tets (from the volumes and the size bounds), over the limit "
                "of %.0f; use a larger size, or raise the limit",
                estimate, limit);
  return buf;
}

}  // namespace

TetLimitError::TetLimitError(const std::string& file, double estimate, double limit)
    : IoError(file, 0, IoError::kNoOffset, tet_limit_reason(estimate, limit)),
      estimate_(estimate),
      limit_(limit) {}

void check_tet_estimate(const std::string& file, const Plc& plc, const MeshParams& params,
                        std::span<const double> region_volume, double max_tets) {
  const double est = estimate_tet_count(plc, params, region_volume);
  if (est > max_tets) throw TetLimitError(file, est, max_tets);
}

const Field* refine_field(const Mesh& mesh, std::string_view name) {
  for (const Field& f : mesh.fields)
    if (f.location == FieldLocation::node && (name.empty() || f.name == name)) return &f;
  return nullptr;
}

namespace {

[[noreturn]] void bad_option(const std::string& what) { throw MesherError(MesherFailure::bad_input, what); }

bool positive_length(double h) { return h > 0 && std::isfinite(h); }

}  // namespace

void check_mesh_options(const ModelMeshOptions& o) {
  if (o.max_size && !positive_length(*o.max_size)) bad_option("the global mesh size must be > 0");
  if (!(o.max_volume >= 0) || !std::isfinite(o.max_volume)) bad_option("the largest tet volume must be >= 0");
  for (const PartSize& p : o.part_sizes)
    if (!positive_length(p.max_size)) bad_option("the mesh size of part '" + p.part + "' must be > 0");
  for (double h : o.sizes.region_sizes)
    if (!positive_length(h)) bad_option("a region's mesh size must be > 0");
  if (o.sizes.region_ids.size() != o.sizes.region_sizes.size())
    bad_option("region sizes need one size per region id");
  for (const RefinementBox& b : o.sizes.boxes) {
    if (!positive_length(b.size)) bad_option("a refinement box's size must be > 0");
    for (int k = 0; k < 3; ++k)
      if (!(b.lo[k] <= b.hi[k]) || !std::isfinite(b.lo[k]) || !std::isfinite(b.hi[k]))
        bad_option("a refinement box needs finite corners with lo <= hi");
  }
  if (o.mesher == Mesher::tetgen) {
    if (o.quality && !(*o.quality == 0 || *o.quality >= kMinRadiusEdgeBound))
      bad_option(
          "the radius-edge bound must be 0 (no quality refinement) or at least 1.414 (TetGen's "
          "refinement does not finish below it on thin layers)");
    if (o.min_dihedral && !(*o.min_dihedral >= 0 && *o.min_dihedral < 30))
      bad_option("the dihedral bound must be 0 to 30 degrees (larger bounds do not terminate)");
  } else {
    if (o.quality && !(*o.quality >= 0 && std::isfinite(*o.quality)))
      bad_option("the radius-edge bound must be >= 0");
    if (o.refine_from.mesh) bad_option("refining from a result needs the TetGen mesher");
  }
  if (o.refine_from.mesh && !(o.refine_from.target_error > 0 && std::isfinite(o.refine_from.target_error)))
    bad_option("the target error must be > 0");
}

namespace {

// The model's [mesh] controls (an empty model's for a PLC) with the options' replacements, cleared
// when coarse, every size scaled by size_scale; as the mesher's size controls, the options' region
// sizes and boxes added.
SizeControls merged_controls(const std::string& file, const Plc& plc, const Model* model,
                             const ModelMeshOptions& o, ModelMeshControls& mc, double& max_volume) {
  Model controls;
  if (model) controls = *model;
  SizeControls extra;
  max_volume = 0;
  if (o.coarse) {
    // coarse (a picture of the parts): no sizes, no quality refinement and no conforming rounds, so
    // the tets follow the PLC's points and TetGen's boundary recovery alone; the picture takes the
    // power order where that mesh is Delaunay, else a depth buffer (picture.hpp). With the quality
    // bounds, power_module's thin solders took 612k tets and 44 s; the conforming rounds alone, 185k
    // tets and 90 s; this way 377 tets in 0.1 s.
    controls.mesh = {.max_size = 0, .quality = 0, .min_dihedral = 0, .part_sizes = {}, .refine = {}};
  } else {
    if (o.max_size) controls.mesh.max_size = *o.max_size;
    for (const PartSize& ps : o.part_sizes) {
      if (!model) bad_option("part sizes need a model (a PLC's regions take sizes by id)");
      if (std::none_of(model->parts.begin(), model->parts.end(),
                       [&](const Part& p) { return p.name == ps.part; }))
        throw IoError(file, 0, IoError::kNoOffset, "no part named '" + ps.part + "' for its mesh size");
      auto it = std::find_if(controls.mesh.part_sizes.begin(), controls.mesh.part_sizes.end(),
                             [&](const PartSize& p) { return p.part == ps.part; });
      if (it != controls.mesh.part_sizes.end())
        it->max_size = ps.max_size;
      else
        controls.mesh.part_sizes.push_back(ps);
    }
    extra = o.sizes;
    max_volume = o.max_volume;
  }
  const double size_scale = o.size_scale;
  if (size_scale != 1 && !o.coarse) {
    if (controls.mesh.max_size <= 0) {
      double d2 = 0;
      for (int i = 0; i < 3; ++i) {
        double lo = INFINITY, hi = -INFINITY;
        for (std::size_t p = 0; p < plc.point_count(); ++p) {
          lo = std::min(lo, plc.points[3 * p + i]);
          hi = std::max(hi, plc.points[3 * p + i]);
        }
        d2 += (hi - lo) * (hi - lo);
      }
      controls.mesh.max_size = std::sqrt(d2) / 10;
    }
    controls.mesh.max_size *= size_scale;
    for (PartSize& p : controls.mesh.part_sizes) p.max_size *= size_scale;
    for (RefineBox& b : controls.mesh.refine) b.max_size *= size_scale;
    for (double& h : extra.region_sizes) h *= size_scale;
    for (RefinementBox& b : extra.boxes) b.size *= size_scale;
    max_volume *= size_scale * size_scale * size_scale;
  }
  mc = controls.mesh;
  SizeControls sz = size_controls_from_model(controls);
  sz.region_ids.insert(sz.region_ids.end(), extra.region_ids.begin(), extra.region_ids.end());
  sz.region_sizes.insert(sz.region_sizes.end(), extra.region_sizes.begin(), extra.region_sizes.end());
  sz.boxes.insert(sz.boxes.end(), extra.boxes.begin(), extra.boxes.end());
  return sz;
}

// The CGAL path: the global size as a circumradius bound, part and region sizes on the seeds, the
// model's and the options' refinement boxes as CGAL's (cgal_mesher.hpp), the estimate at the regular
// tet of those bounds, and the weighted certificate in m.conforming.
void mesh_cgal(const std::string& file, Plc plc, std::span<const double> volumes, const ModelMeshOptions& o,
               const SizeControls& sz, double max_volume, MeshedModel& m) {
  CgalMeshParams cp = o.cgal;
  cp.progress = o.progress;
  // The circumradius of the regular tet of that volume: CGAL bounds tet sizes by circumradius.
  if (max_volume > 0) cp.max_size = regular_tet_circumradius(max_volume);
  if (cp.max_size == 0 && sz.max_size > 0)
    cp.max_size = regular_tet_circumradius(regular_tet_volume(sz.max_size));
  if (o.quality) cp.radius_edge = *o.quality;
  cp.boxes.insert(cp.boxes.end(), sz.boxes.begin(), sz.boxes.end());
  plc = with_region_sizes(plc, sz);
  {  // the tet count estimated as for TetGen, at the regular tet of the circumradius bound
    MeshParams estimate;
    if (cp.max_size > 0) estimate.max_volume = regular_tet_volume(4 * cp.max_size / std::sqrt(6.0));
    double est = estimate_tet_count(plc, estimate, volumes);
    if (!cp.boxes.empty()) est += estimate_box_tet_count(plc, cp.boxes);
    if (est > o.max_tets) throw TetLimitError(file, est, o.max_tets);
  }
  m.mesh = mesh_plc_cgal(plc, cp, &m.cgal);
  const DelaunayCertificate& cert = delaunay_certificate(m.mesh);
  ConformingReport& c = m.conforming;
  c.first_mesh_points = m.mesh.node_count();
  c.first_mesh_violations = cert.violating_tet_count;
  c.violations.push_back(cert.violating_tet_count);
  c.delaunay = cert.delaunay;
  c.seconds = m.cgal.seconds;
}

// `plc` meshed under the options into m.mesh and its reports; `model` (null: none) gives the [mesh]
// controls and the part names; `volumes` the regions' volumes for the estimate (may be empty).
void mesh_under_options(const std::string& file, Plc plc, const Model* model, std::span<const double> volumes,
                        const ModelMeshOptions& o, MeshedModel& m) {
  check_mesh_options(o);
  ModelMeshControls mc;
  double max_volume = 0;
  const SizeControls sz = merged_controls(file, plc, model, o, mc, max_volume);
  m.mesher = o.coarse ? Mesher::tetgen : o.mesher;  // a picture of the parts: TetGen alone
  if (m.mesher == Mesher::cgal) return mesh_cgal(file, std::move(plc), volumes, o, sz, max_volume, m);

  MeshParams params;
  params.max_volume = max_volume;
  if (o.quality && !o.coarse)
    params.radius_edge = *o.quality;
  else if (mc.quality >= 0)
    params.radius_edge = mc.quality;
  params.min_dihedral = o.min_dihedral && !o.coarse ? *o.min_dihedral : mc.min_dihedral;
  params.optimize = o.optimize && !o.coarse;
  params.progress = o.progress;
  if (sz.max_size > 0) {
    const double v = regular_tet_volume(sz.max_size);
    params.max_volume = params.max_volume > 0 ? std::min(params.max_volume, v) : v;
  }
  plc = with_region_sizes(plc, sz);
  SizeField field;
  if (o.refine_from.mesh && !o.coarse) {
    const RefineFrom& rf = o.refine_from;
    const Field* f = refine_field(*rf.mesh, rf.field);
    if (!f)
      bad_option(rf.origin + " has no node field" + (rf.field.empty() ? "" : " named '" + rf.field + "'"));
    const ErrorIndicator e = zz_error_indicator(*rf.mesh, *f);
    field = size_field_from_error(*rf.mesh, *f, rf.target_error, 0, sz.max_size);
    m.refined = RefinedFrom{f->name, e.relative_error(), rf.mesh->tet_count(), e.tets_without_value};
  } else {
    // The refinement boxes as a size field: box_size_field meshes with params first, then with the
    // boxes' sizes, so both are estimated before it (a box over the whole 10 mm bar at 0.01 mm, 85M
    // tets, was meshed until killed before the field's own estimate below).
    double est = estimate_tet_count(plc, params, volumes);
    if (!sz.boxes.empty()) est += estimate_box_tet_count(plc, sz.boxes);
    if (est > o.max_tets) throw TetLimitError(file, est, o.max_tets);
    if (!sz.boxes.empty()) field = box_size_field(plc, params, sz);
  }
  if (!field.empty()) {
    params.size_field = &field;
    check_tet_estimate(file, plc, params, volumes, o.max_tets);
  }
  if (o.coarse) {
    m.mesh = mesh_plc(plc, params, &m.conforming.tetgen);
  } else if (o.conform && !o.optimize) {
    // The conforming Delaunay path (thin layers included), so that the mesh the solver gets is
    // certified and the viewer's order is exact.
    m.mesh = mesh_conforming(plc, params, {}, &m.conforming);
  } else {
    ConformingReport& c = m.conforming;
    m.mesh = mesh_plc(plc, params, &c.tetgen);
    c.first_mesh_points = m.mesh.node_count();
    c.seconds = c.tetgen.seconds;
    const DelaunayCertificate& cert = delaunay_certificate(m.mesh);
    c.delaunay = cert.delaunay;
    c.first_mesh_violations = cert.violating_tet_count;
    c.violations.push_back(cert.violating_tet_count);
  }
  m.report = m.conforming.tetgen;
}

// A group of parts that touches the rest of the model only along an edge or at a point (the
// diagnostics' "isolated": no area of contact) still shares mesh nodes with it there, and a solve
// would pass heat, current and force through them: a mesh-dependent amount (a bar joined at one
// edge conducted 8e-5 ohm, at a corner 7e-4 ohm, with every check passed), where a contact of zero
// area passes none. Refused before solving, naming the part and the nodes.
void refuse_contacts_through_nodes(const MeshedModel& m, Physics physics) {
  for (const ModelWarning& w : warnings_for(diagnose_model(m.model, m.structure), physics)) {
    if (w.kind != ModelWarningKind::isolated) continue;
    std::vector<std::int32_t> group;  // region ids: part i is region i + 1
    std::uint64_t line = 0;
    for (const std::string& name : w.parts)
      for (std::size_t i = 0; i < m.model.parts.size(); ++i)
        if (m.model.parts[i].name == name) {
          group.push_back(static_cast<std::int32_t>(i + 1));
          if (line == 0) line = m.model.parts[i].line;
        }
    std::vector<std::uint8_t> side(m.mesh.node_count(), 0);  // bit 1: a tet of the group, bit 2: another
    for (std::size_t t = 0; t < m.mesh.tet_count(); ++t) {
      const bool in = std::find(group.begin(), group.end(), m.mesh.region_of(t)) != group.end();
      for (int k = 0; k < 4; ++k) side[m.mesh.tet[4 * t + std::size_t(k)]] |= in ? 1 : 2;
    }
    std::size_t shared = 0, first = 0;
    for (std::size_t v = 0; v < side.size(); ++v)
      if (side[v] == 3 && shared++ == 0) first = v;
    if (shared == 0) continue;
    const double s = m.model.length_scale;
    char at[160];
    std::snprintf(at, sizeof at, "(%g, %g, %g) %s", m.mesh.xyz[3 * first] / s, m.mesh.xyz[3 * first + 1] / s,
                  m.mesh.xyz[3 * first + 2] / s, m.model.length_unit.c_str());
    std::string names;
    for (const std::string& name : w.parts) names += (names.empty() ? "'" : ", '") + name + "'";
    throw IoError(m.model.file, line, IoError::kNoOffset,
                  std::string(w.parts.size() > 1 ? "parts " : "part ") + names +
                      (w.parts.size() > 1 ? " touch" : " touches") +
                      " the rest of the model only along an edge or at a point, where the mesh joins " +
                      (w.parts.size() > 1 ? "them" : "it") + " to the rest through " +
                      std::to_string(shared) + (shared == 1 ? " shared node" : " shared nodes") + " (at " +
                      at + (shared > 1 ? " and more" : "") + "): a " + physics_name(physics) +
                      " solve would pass a mesh-dependent heat, current or force through those nodes, where "
                      "a contact of no area passes none; give the parts a face in common, or a gap");
  }
}

}  // namespace

MeshedModel mesh_loaded_model(Model model, const ModelMeshOptions& options) {
  MeshedModel m;
  m.model = std::move(model);
  if (options.physics) check_physics(m.model, *options.physics);
  m.structure = build_structure(m.model);
  mesh_under_options(m.model.file, m.structure.plc, &m.model, m.structure.part_volume, options, m);
  name_mesh(m.model, m.structure, m.mesh);
  if (options.physics) refuse_contacts_through_nodes(m, *options.physics);
  return m;
}

MeshedModel mesh_model(const std::filesystem::path& path, std::span<const ParameterOverride> overrides,
                       const ModelMeshOptions& options) {
  return mesh_loaded_model(load_model(path, overrides, options.override_origin), options);
}

MeshedModel mesh_plc_with_options(Plc plc, const ModelMeshOptions& options, const std::string& origin) {
  MeshedModel m;
  mesh_under_options(origin, std::move(plc), nullptr, {}, options, m);
  return m;
}

}  // namespace foxi
