#!/usr/bin/env bash
# The mfree demo: install missing build packages, build the library and the dam-break
# example with the "default" preset, and run the dam break of paper 003 against Martin &
# Moyce (1952) at 30 x 60 particles (about half a minute on two cores): a progress bar
# while it runs, then the surge front against the experiment (a terminal plot when
# gnuplot is installed, which also writes the PNG), and the paths of the PNG, the CSV and
# the VTU series (open dam_break.pvd in ParaView).
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
echo "== Dam break (paper 003 Galerkin SPH) vs Martin & Moyce (1952)"
args=(--nx 30 --out "$out")
[[ -f "$data" ]] && args+=(--data "$data")
"$root/build/default/examples/dam_break/mfree_dam_break" "${args[@]}" "$@"

echo
if command -v gnuplot >/dev/null 2>&1; then
  plot="plot '$out/front.csv' using 1:2 with lines title 'mfree front'"
  [[ -f "$data" ]] && plot+=", '$data' using 1:2 with points pt 7 title 'Martin & Moyce'"
  gnuplot -e "set terminal dumb size 90,28; set datafile separator ','; set key top left; \
set xlabel 'T = t sqrt(2g/a)'; set ylabel 'Z = z/a'; set xrange [0:3.5]; $plot" 2>/dev/null || true
  echo "plot (PNG):  $out/front.png"
else
  echo "(gnuplot not installed: no plot; the front is in the CSV below)"
fi
echo "front (CSV): $out/front.csv"
echo "VTU series:  $out/dam_break.pvd  (open in ParaView)"
