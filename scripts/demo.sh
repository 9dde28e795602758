#!/usr/bin/env bash
# The mfree demo: install missing build packages, build the library and the dam-break
# example with the "default" preset, and run the dam break of Cueto-Felgueroso et al.
# (2004) against the experiment of Martin & Moyce (1952), whose data ship in
# data/martin_moyce_1952.csv, at 30 x 60 particles (about half a minute on two cores). A
# progress bar while it runs (on a terminal; one summary line in a log), then the surge
# front against the experiment drawn in the terminal, and the paths of the PNG, the CSV
# and the VTU series (open dam_break.pvd in ParaView). Without gnuplot it says so and
# still succeeds.
# Usage: scripts/demo.sh [--nx N] [other mfree_dam_break options]   (see --help)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

bash scripts/deps.sh
cmake --preset default >/dev/null
jobs="$(nproc 2>/dev/null || echo 2)"
cmake --build --preset default -j"$jobs" --target mfree_dam_break

out="$root/build/default/demo_dam_break"
data="$root/data/martin_moyce_1952.csv"
mkdir -p "$out"
echo
echo "== Dam break (Galerkin SPH) vs Martin & Moyce (1952)"
"$root/build/default/examples/dam_break/mfree_dam_break" --nx 30 --out "$out" --vtu "$out" --data "$data" "$@"

echo
if command -v gnuplot >/dev/null 2>&1; then
  gnuplot -e "set terminal dumb size 90,28; set datafile separator ','; set key top left; \
set xlabel 'T = t sqrt(2g/a)'; set ylabel 'Z = z/a'; set xrange [0:3.5]; \
plot '$out/front.csv' using 1:2 with lines title 'mfree front', \
'$data' using 1:2 with points pt 'O' title 'Martin & Moyce (1952)'" 2>/dev/null ||
    echo "(gnuplot could not draw the terminal plot)"
else
  echo "(gnuplot is not installed: no plot; scripts/deps.sh installs gnuplot-nox)"
fi
echo "front (CSV): $out/front.csv"
echo "VTU series:  $out/dam_break.pvd  (open in ParaView)"
