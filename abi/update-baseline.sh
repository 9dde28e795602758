#!/usr/bin/env bash
# Regenerate the abidw baselines abi/<lib>.abi from a build tree (see ABI.md: only when
# a release deliberately fixes a new ABI, or after a major-version bump).
#   bash abi/update-baseline.sh [build-dir]      (default: build/default)
# The build must have debug information (RelWithDebInfo, the default preset) and should
# be made with the Debian compiler CI uses.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
build=${1:-build/default}
command -v abidw >/dev/null || { echo "update-baseline.sh: abidw not found (apt-get install abigail-tools)" >&2; exit 1; }

write() {  # write <library file> <baseline name> <header dir>...
  local lib=$1 name=$2
  shift 2
  local hdr=()
  for d in "$@"; do hdr+=(--headers-dir "$d"); done
  if [[ ! -f "$lib" ]]; then
    echo "update-baseline.sh: $lib not built, $name left unchanged" >&2
    return 0
  fi
  # Only the exported interface, with the types of the public headers (the handles'
  # C++ definitions stay declarations); no build paths, so the file is reproducible.
  abidw --no-corpus-path --short-locs --no-comp-dir-path --exported-interfaces-only \
        --drop-private-types "${hdr[@]}" --out-file "abi/$name" "$lib"
  echo "wrote abi/$name from $lib"
}
write "$build/src/libmfree.so" libmfree.abi include "$build/include"
write "$build/adapters/suitesparse/libmfree_suitesparse.so" libmfree_suitesparse.abi \
      adapters/suitesparse/include include "$build/include"
write "$build/adapters/sundials/libmfree_sundials.so" libmfree_sundials.abi \
      adapters/sundials/include include "$build/include"
write "$build/adapters/mpi/libmfree_mpi.so" libmfree_mpi.abi \
      adapters/mpi/include include "$build/include"
write "$build/adapters/petsc/libmfree_petsc.so" libmfree_petsc.abi \
      adapters/petsc/include include "$build/include"
