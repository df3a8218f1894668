#!/usr/bin/env bash
# The main job on a fresh machine: installs what is missing, builds foxi, meshes the example
# package (a die on a substrate) with TetGen, shows what foxi makes of it (counts, regions,
# boundaries, quality, the Delaunay certificate, the verified visibility order), solves its steady
# heat conduction, renders its inside to a PNG, and converts it to ParaView's and Gmsh's formats.
# Output goes to out/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
foxi=build/apps/foxi/foxi
out=out/demo
mkdir -p "$out"
# The parametrized model (TOML: parameters with units, parts, materials) and its PLC.
"$foxi" model check models/die_on_substrate.toml --set die_w=5mm
"$foxi" model plc models/die_on_substrate.toml --set die_w=5mm -o "$out/die_on_substrate.poly"
echo
# TetGen through its library: radius-edge bound 1.414, tets of at most 1e-11 m^3, no flips or
# smoothing (they break the Delaunay property; see issue 6), then the exact certificate.
"$foxi" mesh "$out/die_on_substrate.poly" -o "$out/die_on_substrate.node" --max-volume 1e-11 --check-delaunay
echo
"$foxi" info --check-delaunay "$out/die_on_substrate.node"
echo
# The visibility order (power of the eye w.r.t. each circumsphere) from 4 random views, verified.
"$foxi" order "$out/die_on_substrate.node" --views 4 --check
echo
# Steady heat with the model's own conditions and loads: 0.5 W in the die, the substrate bottom
# held at 300 K, the free faces cooled by air (h = 10 W/m^2K at 300 K); FR-4 and silicon
# (models/materials.toml). foxi solve meshes the model itself ([mesh] in the model file).
"$foxi" solve models/die_on_substrate.toml --physics thermal --set die_w=5mm -o "$out/die_on_substrate_thermal.vtu"
echo
# The inside of the mesh: the far 60% of the tets, back to front, each shrunk a little.
"$foxi" render "$out/die_on_substrate.node" --stop 60% --shrink 0.85 --size 1280x960 -o "$out/die_on_substrate.png"
echo
# The solved temperature inside: the far 60%, graded facets, a legend in degrees Celsius.
"$foxi" render "$out/die_on_substrate_thermal.vtu" --field temperature --graded --stop 60% --size 1280x960 \
  -o "$out/die_on_substrate_temperature.png"
echo
# Field movies: the solid hotter than an isotherm swept from 30 to 70 °C, cut at the isotherm (each
# frame what foxi render --iso draws; only the tets the isovalue reaches are ordered and drawn).
"$foxi" movie "$out/die_on_substrate_thermal.vtu" --field temperature --graded --sweep iso:30,70 --frames 12 \
  --size 640x400 -o "$out/die_on_substrate_isotherms.gif"
echo
"$foxi" convert "$out/die_on_substrate.node" "$out/die_on_substrate.vtu"
"$foxi" convert "$out/die_on_substrate.node" "$out/die_on_substrate.msh"
"$foxi" info "$out/die_on_substrate.msh" --json > "$out/die_on_substrate.json"
echo
# Another example end to end in one command (the flip chip: mesh, certificate, heat, pictures, then
# an isotherm, the isotherm swept as a movie, and von Mises stress on the deformed shape).
"$foxi" demo -o "$out"
"$foxi" model show models/power_module.toml --view exploded -o "$out/power_module_parts.png" --set solder_h=0.5mm \
  --set cu_h=0.5mm --set ceramic_h=0.6mm
echo
echo "demo: wrote $out/flip_chip.png, $out/flip_chip_parts.png, $out/flip_chip_temperature.png,"
echo "      $out/flip_chip_isotherm.png, $out/flip_chip_isotherms.gif and $out/flip_chip_von_mises.png (foxi demo),"
echo "      $out/power_module_parts.png, $out/die_on_substrate_temperature.png (the solved temperature inside),"
echo "      $out/die_on_substrate_isotherms.gif (an isotherm swept as a movie),"
echo "demo: wrote $out/die_on_substrate.png (the mesh inside), $out/die_on_substrate_thermal.vtu (temperature and"
echo "      heat flux, for ParaView), $out/die_on_substrate.vtu and .msh (the mesh), $out/die_on_substrate.json"
