#!/usr/bin/env bash
# Install missing build packages, build mfree with the "default" preset and run the demo
# (arguments are passed to it: mfree_demo [particles-per-side]).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/deps.sh
cmake --preset default
cmake --build --preset default -j"$(nproc)"
build/default/examples/demo/mfree_demo "$@"
