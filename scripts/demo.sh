#!/usr/bin/env bash
# The main job on a fresh machine: installs what is missing, builds foxi, meshes the example
# package (a die on a substrate) with TetGen, and shows what foxi makes of it: counts, regions,
# boundaries, quality, the Delaunay certificate; then converts it to ParaView's and Gmsh's formats.
# Output goes to out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
foxi=build/apps/foxi/foxi
out=out/demo
mkdir -p "$out"
cp examples/die_on_substrate.poly "$out/"
# -p PLC, -q1.414 radius-edge bound, -a max volume (m^3), -A region attributes, -O0 no flips or
# smoothing (keeps the mesh Delaunay, see issue 6).
tetgen -pq1.414a1e-11AO0 -Q "$out/die_on_substrate.poly"
echo
"$foxi" info --check-delaunay "$out/die_on_substrate.1.ele"
echo
# The visibility order (power of the eye w.r.t. each circumsphere) from 4 random views, verified.
"$foxi" order "$out/die_on_substrate.1.ele" --views 4 --check
echo
"$foxi" convert "$out/die_on_substrate.1.ele" "$out/die_on_substrate.vtu"
"$foxi" convert "$out/die_on_substrate.1.ele" "$out/die_on_substrate.msh"
"$foxi" info "$out/die_on_substrate.msh" --json > "$out/die_on_substrate.json"
echo
echo "demo: wrote $out/die_on_substrate.vtu (ParaView), $out/die_on_substrate.msh (Gmsh), $out/die_on_substrate.json"
