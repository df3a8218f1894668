#!/usr/bin/env bash
# Checks, in a static build, that the programs and tests call into the libraries only through
# exported symbols (FOXI_API, foxi/api.hpp), so that a shared build (-DBUILD_SHARED_LIBS=ON) links
# too: no symbol defined with hidden visibility in a libfoxi_*.a may be undefined in an object of
# apps/, tests/ or bench/. The tests of internals, which a shared build leaves out,
# are left out here as well; and no library may use another's hidden symbols (libfoxi_structure.so
# calls libfoxi_model.so). A public entry point without FOXI_API fails here, in seconds, without a
# second (shared) build.
#   scripts/check_exports.sh [BUILD]    (default build)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
libs=$(find "$build" -name 'libfoxi_*.a' -not -name 'libfoxi_view_core.a')
[ -n "$libs" ] || { echo "check_exports: no static foxi libraries in $build" >&2; exit 1; }
# Defined, global or weak, hidden: Num Value Size Type Bind Vis Ndx Name.
readelf -sW $libs | awk '($5 == "GLOBAL" || $5 == "WEAK") && $6 == "HIDDEN" && $7 != "UND" {print $8}' |
  sort -u > "$tmp/hidden"
find "$build/apps" "$build/tests" "$build/bench" -name '*.o' 2>/dev/null |
  grep -v -e 'plc_cleanup_test' -e 'exact_key_test' > "$tmp/objects" || true
[ -s "$tmp/objects" ] || { echo "check_exports: no objects of apps, tests or bench in $build" >&2; exit 1; }
xargs nm -u < "$tmp/objects" | awk '{print $NF}' | sort -u > "$tmp/used"
comm -12 "$tmp/hidden" "$tmp/used" > "$tmp/missing"
# Each library's own needs from the others: undefined in it, not defined in it, hidden in another.
for lib in $libs; do
  readelf -sW "$lib" | awk '($5 == "GLOBAL" || $5 == "WEAK") && $7 != "UND" {print $8}' | sort -u > "$tmp/own"
  nm -u "$lib" | awk '$1 == "U" {print $2}' | sort -u | comm -23 - "$tmp/own" > "$tmp/needs"
  readelf -sW $(echo "$libs" | grep -vxF "$lib") |
    awk '($5 == "GLOBAL" || $5 == "WEAK") && $6 == "HIDDEN" && $7 != "UND" {print $8}' | sort -u |
    comm -12 - "$tmp/needs" >> "$tmp/missing"
done
if [ -s "$tmp/missing" ]; then
  echo "check_exports: used outside the libraries but not exported (add FOXI_API to the declaration):" >&2
  c++filt < "$tmp/missing" | sed 's/^/  /' >&2
  exit 1
fi
echo "check_exports: $(wc -l < "$tmp/objects") objects use only exported symbols of $(echo $libs | wc -w) libraries"
