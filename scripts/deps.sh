#!/usr/bin/env bash
# Install the Debian 12 packages that building and testing mfree needs, only those that
# are missing (apt-get update runs only then). Works as root or through sudo.
# Later capabilities add their packages here (gfortran, libsuitesparse-dev,
# libsundials-dev, ...). abigail-tools: the abidiff check against abi/*.abi (ABI.md);
# clang: the libFuzzer harness (fuzz/); valgrind: the memory-check label; doxygen: the
# API reference and guide (docs target, test t908); gnuplot-nox: the examples' plots;
# libopenmpi-dev, openmpi-bin: libmfree_mpi and the mpi tests; libtrilinos-zoltan-dev:
# partitions in the MPI examples and tests; libpetsc-real-dev: libmfree_petsc.
set -euo pipefail

MFREE_DEB_PACKAGES="build-essential cmake pkg-config libeigen3-dev libcmocka-dev libsuitesparse-dev gfortran libsundials-dev abigail-tools clang valgrind libnanoflann-dev doxygen gnuplot-nox libopenmpi-dev openmpi-bin libtrilinos-zoltan-dev libpetsc-real-dev"

if ! command -v dpkg-query >/dev/null 2>&1; then
  echo "deps.sh: dpkg-query not found: this script is for Debian/Ubuntu." >&2
  echo "deps.sh: install by hand the equivalents of: $MFREE_DEB_PACKAGES" >&2
  exit 1
fi

missing=()
for pkg in $MFREE_DEB_PACKAGES; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$pkg" 2>/dev/null || true)
  [[ "$status" == "installed" ]] || missing+=("$pkg")
done
((${#missing[@]} > 0)) || exit 0

if [[ "$(id -u)" -eq 0 ]]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "deps.sh: missing packages: ${missing[*]}" >&2
  echo "deps.sh: installing them needs root, and sudo is not available; as root run:" >&2
  echo "  apt-get update && apt-get install -y ${missing[*]}" >&2
  exit 1
fi

echo "deps.sh: installing ${missing[*]}"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
run_apt() {
  if ! "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get "$@" >>"$log" 2>&1; then
    cat "$log" >&2
    echo "deps.sh: apt-get $* failed" >&2
    exit 1
  fi
}
run_apt -q update
run_apt -q -y install --no-install-recommends "${missing[@]}"
echo "deps.sh: installed ${missing[*]}"
