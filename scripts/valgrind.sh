#!/usr/bin/env bash
# valgrind on the core tests (issue 9): configure a build tree with MFREE_VALGRIND=ON,
# build it and run the tests of label "valgrind" (memcheck, --leak-check=full, any
# invalid access or definite/possible leak fails). Usage:
#   bash scripts/valgrind.sh [build-dir]      (default: build/default, preset default)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
build=${1:-build/default}
command -v valgrind >/dev/null || { echo "valgrind.sh: valgrind not found (scripts/deps.sh installs it)" >&2; exit 1; }
if [[ -f "$build/CMakeCache.txt" ]]; then
  cmake -B "$build" -DMFREE_VALGRIND=ON >/dev/null
else
  cmake --preset default -B "$build" -DMFREE_VALGRIND=ON >/dev/null
fi
cmake --build "$build" -j"$(nproc)"
ctest --test-dir "$build" -L valgrind -j"$(nproc)" --output-on-failure
