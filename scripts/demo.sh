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
# TetGen through its library: radius-edge bound 1.414, tets of at most 1e-11 m^3, no flips or
# smoothing (they break the Delaunay property; see issue 6), then the exact certificate.
"$foxi" mesh examples/die_on_substrate.poly -o "$out/die_on_substrate.node" --max-volume 1e-11 --check-delaunay
echo
"$foxi" info --check-delaunay "$out/die_on_substrate.node"
echo
# The visibility order (power of the eye w.r.t. each circumsphere) from 4 random views, verified.
"$foxi" order "$out/die_on_substrate.node" --views 4 --check
echo
"$foxi" convert "$out/die_on_substrate.node" "$out/die_on_substrate.vtu"
"$foxi" convert "$out/die_on_substrate.node" "$out/die_on_substrate.msh"
"$foxi" info "$out/die_on_substrate.msh" --json > "$out/die_on_substrate.json"
echo
echo "demo: wrote $out/die_on_substrate.vtu (ParaView), $out/die_on_substrate.msh (Gmsh), $out/die_on_substrate.json"
