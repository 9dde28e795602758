#!/usr/bin/env bash
# Install missing build packages, then build and run every test twice: with the
# "default" preset (including the installed-tree consumer tests) and with the "asan"
# preset (AddressSanitizer + UndefinedBehaviorSanitizer). Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

start=$SECONDS
jobs=$(nproc)
bash scripts/deps.sh

for preset in default asan; do
  echo "==== preset $preset: configure, build, test"
  cmake --preset "$preset"
  cmake --build --preset "$preset" -j"$jobs"
  ctest --preset "$preset" -j"$jobs"
done
echo "==== all tests passed (default and asan) in $((SECONDS - start)) s"
