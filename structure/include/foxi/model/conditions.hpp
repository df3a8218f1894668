// Boundary conditions, loads, named geometric surfaces and mesh controls of a model file, as plain
// data in SI units (read by load_model, model_file.hpp; checked against the built structure by
// check_conditions, surfaces.hpp).
//
//   [surfaces.cold_plate]                       # a named surface picked by geometry: every OUTER
//   plane = { point = [0, 0, 0], normal = [0, 0, 1] }   # boundary facet lying in the plane, or
//   [surfaces.pad]                              # every outer boundary facet inside the box
//   box = { min = [x, y, z], max = [x, y, z] }  # (lengths in units.length or with units)
//
//   [[conditions]]
//   type = "temperature" | "heat_flux" | "convection" | "voltage" | "ground" | "current"
//        | "displacement" | "sliding"
//   surface = "die.top"   or  ["die.top", "die.side"]   # part faces, interfaces "A/B", [surfaces]
//   value = "25 degC"     # temperature (K or degC), heat_flux (W/m^2 into the body), voltage (V),
//                         # current (A into the body), displacement ([ux, uy, uz], lengths)
//   h = "10 W/(m^2*K)"  ambient = "25 degC"            # convection
//   name = "anode"        # optional: the electrode's name (voltage, ground, current)
//   physics = "current"   # optional, voltage and ground: only that physics ("electrostatic" or
//                         # "current"; default both), e.g. a terminal on a bump's end that would
//                         # short an electrostatic conductor through the metal
//
//   [[loads]]
//   type = "power"  part = "die"  value = "0.5 W"      # or a density, "2e9 W/m^3"
//   type = "temperature_change"  value = "-100 K"      # uniform, for thermal stress; part optional
//
//   [mesh]
//   max_size = "0.5 mm"          # global maximum element edge length
//   quality = 1.414              # radius-edge bound (0: no quality refinement)
//   min_dihedral = 10            # degrees: no slivers (flat tets make the FEM matrix ill-conditioned)
//   parts = { die = "0.1 mm" }   # per-part maximum edge length
//   [[mesh.refine]]
//   min = [x, y, z]  max = [x, y, z]  max_size = "0.05 mm"
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

enum class ConditionKind : std::uint8_t {
  temperature,   // value: K
  heat_flux,     // value: W/m^2, positive into the body
  convection,    // h: W/(m^2 K), ambient: K
  voltage,       // value: V ("ground" is a voltage of 0)
  current,       // value: A, total current into the body through the surfaces
  displacement,  // displacement: m, all three components fixed
  sliding,       // zero normal displacement, free tangential
};

// "temperature", "heat_flux", ... as written in model files.
FOXI_API const char* condition_kind_name(ConditionKind kind);

struct BoundaryCondition {
  ConditionKind kind = ConditionKind::temperature;
  std::vector<std::string> surfaces;  // boundary names; interfaces as "A/B" with A earlier in the file
  std::string name;                   // the electrode's name (defaults to the surfaces joined by ',')
  std::string physics;                // voltage: "electrostatic" or "current" only; empty: both
  double value = 0;
  double h = 0, ambient = 0;
  double displacement[3] = {0, 0, 0};
  std::uint64_t line = 0;  // of its [[conditions]] entry
};

enum class LoadKind : std::uint8_t {
  power,               // value: W for the whole part (total) or W/m^3
  temperature_change,  // value: K, uniform
};

struct Load {
  LoadKind kind = LoadKind::power;
  std::string part;  // empty: every part (temperature_change only)
  double value = 0;
  bool total = true;  // power: value is W for the part, not W/m^3
  std::uint64_t line = 0;
};

// A surface named in [surfaces]: the outer boundary facets of the structure lying in a plane or
// inside an axis-aligned box (whole facets only). The structure builder gives it its own boundary
// marker and takes those facets away from the part faces that held them.
struct SurfaceSelector {
  std::string name;
  bool plane = false;  // true: point/normal; false: box lo/hi
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  double point[3] = {0, 0, 0}, normal[3] = {0, 0, 1};  // normal: unit length
  std::uint64_t line = 0;
};

struct PartSize {
  std::string part;
  double max_size = 0;  // m, edge length
  std::uint64_t line = 0;
};

struct RefineBox {
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  double max_size = 0;  // m
  std::uint64_t line = 0;
};

struct ModelMeshControls {
  double max_size = 0;      // m, edge length; 0: none
  double quality = -1;      // radius-edge bound; negative: the mesher's default
  double min_dihedral = 0;  // degrees; 0: the mesher's default
  std::vector<PartSize> part_sizes;
  std::vector<RefineBox> refine;
};

}  // namespace foxi
