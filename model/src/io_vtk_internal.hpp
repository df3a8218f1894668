// Internal to the VTK readers and writers (io_vtk_assemble.cpp, io_vtu_read.cpp, io_vtu_write.cpp,
// io_vtk_legacy.cpp): decoded arrays, the pieces a reader hands over, and the Assembler that builds
// the mesh from them.
//
// Decisions (see also io_vtk.hpp):
// - NaN or infinite coordinates and values are accepted as read; validate() reports them.
// - Region and boundary names and field units / step values are not part of the VTK formats. The
//   .vtu writer keeps them in attributes that VTK, ParaView and meshio ignore: foxi_region_names
//   and foxi_boundary_names on the "region" DataArray ("id=name;id=name", names %-escaped), and
//   foxi_unit / foxi_step_value on each field array. Each region's material (name and properties)
//   goes into foxi_region_materials on the region array ("id=name|k|sigma|eps|E|nu|alpha;...", NaN
//   for a property not set), so that a mesh written from a model solves without restating them.
//   The reader restores them when present; the legacy format keeps none of them (multi-step fields
//   get step values 0, 1, 2, ...).
// - A field with several steps is written as arrays "name", "name@2", "name@3", ...; the reader
//   groups such a consecutive run (same location and components) back into one field.
// - Cell fields keep the values of the tet cells only; the writer gives boundary triangle cells NaN.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "foxi/model/io_vtk.hpp"
#include "io_util.hpp"
#include "io_vtk_codec.hpp"

namespace foxi::vtk {

constexpr bool kHostLittle = std::endian::native == std::endian::little;
constexpr std::uint64_t kUnknown = ~std::uint64_t{0};
// zlib cannot expand data by more than about 1032:1; used to bound declared sizes.
constexpr std::uint64_t kZlibMaxRatio = 1032;

// ------------------------------------------------------------------------------------------------
// Decoded arrays: bytes of `count` values of `type`, either lent (a view into the file) or owned.
struct ArrayData {
  VType type = VType::f64;
  std::uint64_t count = 0;  // values (tuples * components)
  std::string_view lent;    // count * type_size(type) bytes in the file, or
  std::string owned;        // the same, owned (is_owned)
  bool is_owned = false;
  bool swap = false;  // bytes are in the other byte order

  // Never a stored view of `owned`: a moved std::string may move its (short) buffer.
  const char* data() const { return is_owned ? owned.data() : lent.data(); }
  void own(std::string s) {
    owned = std::move(s);
    is_owned = true;
  }
};

ArrayData make_owned_f64(std::vector<double>& v);
ArrayData make_owned_i64(std::vector<std::int64_t>& v);

template <class T>
struct Acc {
  const char* p;
  bool swap;
  T operator[](std::size_t i) const { return io::load<T>(p + i * sizeof(T), swap); }
};

template <class F>
decltype(auto) dispatch(const ArrayData& a, F&& f) {
  const char* p = a.data();
  switch (a.type) {
    case VType::i8:
      return f(Acc<std::int8_t>{p, a.swap});
    case VType::u8:
      return f(Acc<std::uint8_t>{p, a.swap});
    case VType::i16:
      return f(Acc<std::int16_t>{p, a.swap});
    case VType::u16:
      return f(Acc<std::uint16_t>{p, a.swap});
    case VType::i32:
      return f(Acc<std::int32_t>{p, a.swap});
    case VType::u32:
      return f(Acc<std::uint32_t>{p, a.swap});
    case VType::i64:
      return f(Acc<std::int64_t>{p, a.swap});
    case VType::u64:
      return f(Acc<std::uint64_t>{p, a.swap});
    case VType::f32:
      return f(Acc<float>{p, a.swap});
    case VType::f64:
      break;
  }
  return f(Acc<double>{p, a.swap});
}

// Appends values [first, first + n) of `a` as doubles to `out`.
void append_doubles(const ArrayData& a, std::size_t first, std::size_t n, std::vector<double>& out);

// An integer array as int32 or int64 in host order (converted when it is anything else). Throws via
// `fail` (a callable taking a reason) if a value is not an integer that fits in int64.
template <class Fail>
ArrayData normalize_ints(ArrayData a, Fail&& fail) {
  if ((a.type == VType::i32 || a.type == VType::i64) && !a.swap) return a;
  std::vector<std::int64_t> v(a.count);
  dispatch(a, [&](auto acc) {
    using T = std::decay_t<decltype(acc[0])>;
    for (std::size_t i = 0; i < a.count; ++i) {
      T x = acc[i];
      if constexpr (std::is_floating_point_v<T>) {
        if (!(x >= -9.2e18 && x <= 9.2e18) || std::trunc(x) != x)
          fail("value " + std::to_string(x) + " at index " + std::to_string(i) + " is not an integer");
      } else if constexpr (std::is_same_v<T, std::uint64_t>) {
        if (x > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
          fail("value " + std::to_string(x) + " at index " + std::to_string(i) + " is too large");
      }
      v[i] = static_cast<std::int64_t>(x);
    }
  });
  return make_owned_i64(v);
}

template <class F>
decltype(auto) dispatch_int(const ArrayData& a, F&& f) {
  if (a.type == VType::i32) return f(Acc<std::int32_t>{a.data(), false});
  return f(Acc<std::int64_t>{a.data(), false});
}

// ------------------------------------------------------------------------------------------------
// What a reader hands to the assembler, piece by piece.
struct NamedArray {
  std::string name;
  std::uint32_t components = 1;
  ArrayData data;
  std::string unit;
  std::optional<double> step_value;
  std::string region_names;      // foxi_region_names attribute (region array only)
  std::string region_materials;  // foxi_region_materials attribute (region array only)
  std::string boundary_names;    // foxi_boundary_names attribute
  std::size_t at = 0;            // file offset of its declaration (for errors)
};

struct Piece {
  std::uint64_t npoints = 0, ncells = 0;
  std::size_t at = 0, cells_at = 0;  // file offsets of the piece and its cells (for errors)
  ArrayData points;                  // 3 * npoints values
  ArrayData conn;                    // connectivity
  ArrayData offsets;                 // ncells values: end of each cell in conn
  ArrayData types;                   // ncells values
  std::vector<NamedArray> point_arrays, cell_arrays;
};

struct CollectedArray {
  std::string name;
  FieldLocation location;
  std::uint32_t components;
  std::vector<double> values;
  std::string unit;
  std::optional<double> step_value;
  std::size_t pieces = 0;
};

std::string percent_decode(std::string_view s);
std::string percent_encode(std::string_view s, std::string_view special);

// Builds the mesh from pieces: appends nodes, tets, boundary triangles and arrays.
class Assembler {
 public:
  Assembler(const std::string& file, std::string_view text) : file_(file), text_(text) {}

  void add(Piece& p, std::size_t piece_index);
  Mesh finish();

 private:
  CollectedArray& collect(NamedArray& na, FieldLocation loc, std::size_t piece_index);

  const std::string& file_;
  std::string_view text_;
  Mesh mesh_;
  bool have_region_ = false;
  std::size_t piece_count_ = 0;
  std::vector<CollectedArray> arrays_;
  std::map<std::pair<std::string, FieldLocation>, std::size_t> index_;
  std::map<std::int32_t, std::string> region_names_, boundary_names_;
  std::map<std::int32_t, Material> region_materials_;
};

}  // namespace foxi::vtk
