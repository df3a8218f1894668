#!/usr/bin/env bash
# Installs foxi from a build folder into a temporary prefix (BUILD/embed-test, removed afterwards),
# then configures, builds and runs each host program of examples/embed/ against that prefix alone
# (find_package(foxi) with CMAKE_PREFIX_PATH=prefix; the build tree exports no package, and the
# script checks that foxi_DIR lies in the prefix). Checks that nothing installed names the source or
# the build folder, and that grid_png's PNG is there and not blank. Prints the time of each step
# and the size of the install tree.
#   scripts/embed_test.sh [BUILD]    (default build; e.g. a -DBUILD_SHARED_LIBS=ON build folder)
# FOXI_KEEP_EMBED_TEST=1 keeps BUILD/embed-test (grid.png, field.ppm) to look at.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$PWD
build=$(cd "${1:-build}" && pwd)
work=$build/embed-test
rm -rf "$work"
trap '[ -n "${FOXI_KEEP_EMBED_TEST:-}" ] || rm -rf "$work"' EXIT
prefix=$work/prefix
generator=$(sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "$build/CMakeCache.txt")

t0=$(date +%s%N)
step() {  # step NAME: prints NAME and the seconds since the last step
  local t
  t=$(date +%s%N)
  printf '  %-38s %4d.%01d s\n' "$1" $(((t - t0) / 1000000000)) $(((t - t0) / 100000000 % 10))
  t0=$t
}

echo "embed test: $build -> $prefix"
cmake --install "$build" --prefix "$prefix" > "$work.install.log" 2>&1 || { cat "$work.install.log"; exit 1; }
rm -f "$work.install.log"
step "install"
printf '  install tree: %s (%s files)\n' "$(du -sh "$prefix" | cut -f1)" "$(find "$prefix" -type f | wc -l)"

# No path of this machine's source or build folder in the installed files (headers, CMake files,
# libraries, programs): a host's machine has neither.
if grep -rlF -e "$src" -e "$build" "$prefix"; then
  echo "embed test: the files above name $src or $build" >&2
  exit 1
fi

# The installed programs run from the prefix (a shared build's find lib/ through their rpath), and
# foxi demo finds its default model there, not in the source tree.
"$prefix/bin/foxi" --version
model=$(cd "$work" && FOXI_MODELS_DIR= timeout 3 stdbuf -oL "$prefix/bin/foxi" demo -o "$work/demo" 2>&1 | sed -n 's/^1\. model //p' || true)
if [ "$model" != "$prefix/share/foxi/models/flip_chip.toml" ]; then
  echo "embed test: foxi demo took its default model from '$model'" >&2
  exit 1
fi
step "installed foxi: --version, demo model"

# Every imported target links in a host (a static build's private dependencies found by the
# package: TetGen, CGAL with GMP/MPFR, ...): a program that calls into each library.
mkdir -p "$work/all_targets.src"
cat > "$work/all_targets.src/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.22)
project(foxi_all_targets LANGUAGES CXX)
find_package(foxi 0.1 REQUIRED)
add_executable(all_targets main.cpp)
target_compile_features(all_targets PRIVATE cxx_std_20)
target_link_libraries(all_targets PRIVATE foxi::model foxi::structure foxi::mesher foxi::solver foxi::viz foxi::fields)
CMAKE
cat > "$work/all_targets.src/main.cpp" <<'CPP'
#include <cmath>
#include <cstdio>
#include "foxi/fields.hpp"
#include "foxi/mesher.hpp"
#include "foxi/model.hpp"
#include "foxi/solver.hpp"
#include "foxi/structure.hpp"
#include "foxi/viz.hpp"
#include "foxi/version.hpp"
int main() {
  // Addresses of the heavy entry points make the linker resolve their dependencies (TetGen, CGAL).
  void* volatile entry[] = {reinterpret_cast<void*>(&foxi::mesh_plc), reinterpret_cast<void*>(&foxi::mesh_plc_cgal),
                            reinterpret_cast<void*>(&foxi::solve_thermal), reinterpret_cast<void*>(static_cast<foxi::Model (*)(const std::filesystem::path&, std::span<const foxi::ParameterOverride>, std::string_view)>(&foxi::load_model)),
                            reinterpret_cast<void*>(&foxi::compute_spheres),
                            reinterpret_cast<void*>(&foxi::read_field_source)};
  const double mm = foxi::evaluate_in("2 mm + 500 um", "m");       // structure
  const double v = foxi::regular_tet_volume(1.0);                   // mesher
  const foxi::FieldSource csv = foxi::parse_csv_source("id,t [K]\n1,300\n", "host.csv");  // fields
  const bool ok = entry[0] != nullptr && std::abs(mm - 2.5e-3) < 1e-15 && std::abs(v - std::sqrt(2.0) / 12) < 1e-15 &&
                  csv.mesh.fields.size() == 1 && csv.mesh.fields[0].unit == "K";
  std::printf("all_targets: foxi %s, 2 mm + 500 um = %g m, regular tet volume %.6f: %s\n", FOXI_VERSION_STRING, mm, v,
              ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
CPP

for example in grid_png field_buffer heat_loop all_targets; do
  dir=$work/$example
  source_dir=examples/embed/$example
  [ -d "$source_dir" ] || source_dir=$work/$example.src
  cmake -S "$source_dir" -B "$dir" -G "$generator" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF > "$dir.log" 2>&1 ||
    { cat "$dir.log"; exit 1; }
  found=$(sed -n 's/^foxi_DIR:PATH=//p' "$dir/CMakeCache.txt")
  case "$found" in
    "$prefix"/*) ;;
    *) echo "embed test: $example found foxi at '$found', not in $prefix" >&2; exit 1 ;;
  esac
  step "$example: configure"
  cmake --build "$dir" > "$dir.log" 2>&1 || { cat "$dir.log"; exit 1; }
  step "$example: build"
done

"$work/grid_png/grid_png" "$work/grid.png" 16
step "grid_png: run"
# A PNG of the requested size, and far from blank (a 640 x 480 picture of one colour is under 2 kB).
python3 - "$work/grid.png" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
w, h = struct.unpack('>II', data[16:24])
assert (w, h) == (640, 480), f'size {w} x {h}'
assert len(data) > 20000, f'only {len(data)} bytes: blank?'
print(f'  grid.png: {w} x {h}, {len(data)} bytes')
PY
"$work/field_buffer/field_buffer" "$work/field.ppm"
step "field_buffer: run"
"$work/heat_loop/heat_loop" examples/embed/heat_loop/heatsink.toml "$work/heat_loop.png"
step "heat_loop: run"
"$work/all_targets/all_targets"

# The Qt host (examples/qt): a window embedding foxi::qt, where foxi was built with Qt5. Offscreen:
# it meshes the installed model, draws it in the widget and saves the widget's picture.
if [ -f "$prefix/lib/cmake/foxi/foxiQtTargets.cmake" ] || ls "$prefix"/lib*/cmake/foxi/foxiQtTargets.cmake > /dev/null 2>&1; then
  dir=$work/qt_window
  cmake -S examples/qt -B "$dir" -G "$generator" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF > "$dir.log" 2>&1 ||
    { cat "$dir.log"; exit 1; }
  found=$(sed -n 's/^foxi_DIR:PATH=//p' "$dir/CMakeCache.txt")
  case "$found" in
    "$prefix"/*) ;;
    *) echo "embed test: qt_window found foxi at '$found', not in $prefix" >&2; exit 1 ;;
  esac
  cmake --build "$dir" > "$dir.log" 2>&1 || { cat "$dir.log"; exit 1; }
  step "qt_window: configure, build"
  QT_QPA_PLATFORM=offscreen "$dir/qt_window" "$prefix/share/foxi/models/die_on_substrate.toml" --save "$work/qt_window.png" \
    2> "$dir.run.log" || { cat "$dir.run.log"; exit 1; }
  step "qt_window: run"
  python3 - "$work/qt_window.png" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
w, h = struct.unpack('>II', data[16:24])
assert w >= 640 and h >= 480, f'size {w} x {h}'
assert len(data) > 20000, f'only {len(data)} bytes: blank?'
print(f'  qt_window.png: {w} x {h}, {len(data)} bytes')
PY
else
  echo "  (foxi built without Qt5: examples/qt not built)"
fi
echo "embed test: passed"
