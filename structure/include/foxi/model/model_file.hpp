// Parametrized structure models: a TOML file of parameters (with units and expressions), materials
// and parts (boxes, z-axis cylinders, layer stacks, arrays), loaded into plain data in SI units.
//
//   units.length = "mm"              # bare numbers in part fields are in this unit
//   library = "materials.toml"       # optional material library, relative to this file's folder
//   [parameters]
//   die_w = "4 mm"                   # strings are expressions with units; bare numbers dimensionless
//   sub_w = "die_w + 6 mm"
//   [materials.glue]                 # SI numbers, or expressions with units ("2 W/(m*K)")
//   thermal_conductivity = 2.0
//   [[parts]]
//   name = "die"  material = "silicon"  shape = "box"  origin = [...]  size = ["die_w", 3, 0.5]
//   shape = "cylinder": center (of the base), radius, height, segments (default 16)
//   shape = "extrusion": points = [[x, y], ...] (a simple polygon, convex or not, either orientation),
//     z (of the base), height
//   shape = "ball": center, radius, z_range = [z0, z1] (optional: the planes that cut the sphere, e.g.
//     the pads of a solder ball), tolerance (optional, default radius / 100: the largest distance of a
//     facet from the sphere; see surface.hpp for the faceting)
//   shape = "stl": file (ASCII or binary STL, relative to this file, coordinates in units.length; a
//     closed, consistently oriented surface without self-intersections)
//   shape = "layers": origin, footprint = [w, d], thicknesses = [...], names = [...], materials = [...]
//   shape = "array": count = [nx, ny], pitch = [px, py], item = { shape = "box" | "cylinder" | ..., ... }
//   [surfaces.NAME], [[conditions]], [[loads]], [mesh]: see conditions.hpp
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "foxi/api.hpp"
#include "foxi/model/conditions.hpp"
#include "foxi/model/mesh.hpp"
#include "foxi/model/surface.hpp"
#include "foxi/model/units.hpp"

namespace foxi {

// The bounds a model keeps (README, "Model limits"); load_model refuses a model past any of them with
// an error that names the entity and the bound. They keep hostile or mistyped values from crashing the
// TOML parser, CGAL or GMP (stack depth, overflow, degenerate geometry) and from hanging the structure
// builder or the mesher (counts).
namespace model_limits {
inline constexpr std::uintmax_t kFileBytes = 4u << 20;    // a model or materials library file
inline constexpr std::uintmax_t kStlBytes = 64u << 20;    // an STL file
inline constexpr std::size_t kLineBytes = 64u << 10;      // a line of a model or library file
inline constexpr int kTomlDepth = 32;                     // nested arrays, inline tables and dotted key parts
inline constexpr std::size_t kParameterChain = 64;        // parameters whose values need each other, in a row
inline constexpr std::size_t kParts = 1000;               // parts (each layer of a stack counts)
inline constexpr long kArrayItems = 10000;                // nx * ny of one array
inline constexpr long kSegments = 1000;                   // of a cylinder
inline constexpr std::size_t kOutlinePoints = 2000;       // of an extrusion
inline constexpr std::size_t kOutlineVertices = 100000;   // of all prisms (array items included)
inline constexpr std::size_t kSurfaceTriangles = 200000;  // of all balls and STL surfaces
inline constexpr double kBallTolerance = 1e-3;  // a ball's tolerance is at least this times its radius
inline constexpr double kMaxLength = 1e3;       // m: every coordinate and size, and the model's extent
inline constexpr double kMinExtent = 1e-9;      // m: the model's extent (largest side of its box)
inline constexpr double kMinFeature = 1e-6;     // times the extent: every edge, height and ball radius
}  // namespace model_limits

// A vertical prism: a simple (convex or not) counter-clockwise polygon in xy (2 doubles per vertex, metres)
// extruded over z in [z0, z1].
struct FOXI_API Prism {
  std::vector<double> xy;
  double z0 = 0, z1 = 0;
  double area() const;  // of the polygon (m^2)
};

struct Part {
  std::string name;
  std::string material;       // a name in Model::materials
  std::string shape;          // box, cylinder, extrusion, ball, stl, layers (one part per layer), array
  std::vector<Prism> prisms;  // an array part has one prism per item
  TriSurface surface;         // balls and STL surfaces (an array: one closed component per item)
  std::string source;         // the STL file of an stl part
  std::uint64_t line = 0;     // of its [[parts]] entry (0: unknown)
};

struct Parameter {
  std::string name;
  std::string expression;  // as written (or as given by an override)
  Quantity value;
  bool overridden = false;
};

struct Model {
  std::string file;
  std::string length_unit = "m";
  double length_scale = 1;                    // metres per length unit
  std::vector<Parameter> parameters;          // sorted by name
  std::vector<Material> materials;            // those the parts use, in order of first use
  std::vector<Part> parts;                    // layer stacks expanded; region id of parts[i] = i + 1
  std::vector<SurfaceSelector> surfaces;      // [surfaces], in name order
  std::vector<BoundaryCondition> conditions;  // [[conditions]], in file order
  std::vector<Load> loads;                    // [[loads]], in file order
  ModelMeshControls mesh;                     // [mesh]
};

// A parameter replaced from outside the model file (a host's input, a command-line option): the
// parameter's name and the expression that replaces the file's (units included, as the file would
// write it, e.g. "8 mm" or "2 * die_w").
struct ParameterOverride {
  std::string name;
  std::string expression;
};

// Loads a model file. `overrides` replace the parameters of their names; `origin` names where they
// came from in messages ("parameter 'w' (from ORIGIN): ...", "ORIGIN: unknown parameter 'w'"). Throws IoError
// (file, line when known, and a reason naming the entity: parameter, part, material) for TOML syntax errors,
// unknown parameters, unit mismatches, circular expressions, sizes that are not positive, unknown materials,
// and unknown shapes or keys; for conditions and loads: unknown types, units that do not fit the type,
// surfaces that name no part face, interface or [surfaces] entry, unknown parts; for numbers that are not
// finite, and models past model_limits (degenerate geometry included: a feature below kMinFeature of the
// model's extent). Referenced files (library, STL) are named relative to the model's folder, must be regular
// files of the expected kind, and their content is never quoted in an error.
FOXI_API Model load_model(const std::filesystem::path& path, std::span<const ParameterOverride> overrides,
                          std::string_view origin = "an override");
// The same with the overrides written "name=expression" (IoError, line 0, for one without a name
// and '=').
FOXI_API Model load_model(const std::filesystem::path& path, std::span<const std::string> overrides = {},
                          std::string_view origin = "an override");
// Splits "name=expression" texts into overrides of the model file `path`; IoError (line 0) naming
// `origin` and the text for one without a name and '='.
FOXI_API std::vector<ParameterOverride> split_overrides(const std::filesystem::path& path,
                                                        std::span<const std::string> texts,
                                                        std::string_view origin = "an override");

}  // namespace foxi
