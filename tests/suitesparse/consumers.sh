#!/usr/bin/env bash
# Build and run a host program against an *installed* libmfree_suitesparse: with
# pkg-config (shared, and the archives forced) and with find_package(mfree).
#
# usage: consumers.sh BUILD_DIR SCRATCH_DIR SOURCE_DIR C_COMPILER
#   SCRATCH_DIR must lie under BUILD_DIR; it is wiped first. $CMAKE (default cmake).
set -euo pipefail

if [[ $# -ne 4 ]]; then
  echo "usage: $0 BUILD_DIR SCRATCH_DIR SOURCE_DIR C_COMPILER" >&2
  exit 2
fi
build=$(cd "$1" && pwd)
scratch=$2
src=$(cd "$3" && pwd)
cc=$4
cmake_cmd=${CMAKE:-cmake}

fail() {
  echo "consumers.sh: FAILED: $*" >&2
  exit 1
}
step() { echo "== $*"; }

case "$scratch" in
  /*) ;;
  *) scratch="$PWD/$scratch" ;;
esac
case "$scratch/" in
  "$build"/?*) ;;
  *) fail "scratch dir '$scratch' is not under the build dir '$build' (refusing to wipe it)" ;;
esac
rm -rf -- "$scratch"
mkdir -p -- "$scratch"
prefix=$scratch/prefix
consumer=$src/tests/suitesparse/consumer

step "install $build into $prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
  { cat "$scratch/install.log" >&2; fail "cmake --install"; }

pc=$(find "$prefix" -path '*/pkgconfig/mfree-suitesparse.pc' -print -quit)
[[ -n "$pc" ]] || fail "no pkgconfig/mfree-suitesparse.pc under $prefix"
pcdir=$(dirname "$pc")
libdir=$(dirname "$pcdir")
for f in libmfree_suitesparse.so libmfree_suitesparse.a; do
  [[ -e "$libdir/$f" ]] || fail "$f is not next to pkgconfig/ in $libdir"
done
[[ -f "$prefix/include/mfree_suitesparse.h" ]] || fail "mfree_suitesparse.h missing from $prefix/include"

run() { # name binary
  local out
  if ! out=$("$2" 2>&1); then
    printf '%s\n' "$out" >&2
    fail "$1: consumer program exited non-zero"
  fi
  printf '%s\n' "$out"
  [[ $(grep -c ': ok$' <<<"$out") -eq 3 ]] || fail "$1: not every solver reported ok"
}

export PKG_CONFIG_PATH=$pcdir
cflags=$(pkg-config --cflags mfree-suitesparse) || fail "pkg-config --cflags mfree-suitesparse"
libs=$(pkg-config --libs mfree-suitesparse) || fail "pkg-config --libs mfree-suitesparse"
ldirs=$(pkg-config --libs-only-L mfree-suitesparse)
step "pkg-config, shared: cc main.c $cflags $libs"
# shellcheck disable=SC2086
"$cc" "$consumer/main.c" -o "$scratch/pc_shared" $cflags $libs -lm "-Wl,-rpath,$libdir" ||
  fail "pkg-config shared build"
readelf -d "$scratch/pc_shared" | grep -q 'NEEDED.*\[libmfree_suitesparse\.so' ||
  fail "pkg-config shared build does not use libmfree_suitesparse.so"
run pkgconfig-shared "$scratch/pc_shared"

static_libs=$(pkg-config --static --libs-only-l mfree-suitesparse |
  sed -e 's/-lmfree_suitesparse\b//' -e 's/-lmfree\b//')
static_ldirs=$(pkg-config --static --libs-only-L mfree-suitesparse)
step "pkg-config, static archives: -Wl,-Bstatic -lmfree_suitesparse -lmfree -Wl,-Bdynamic $static_libs"
# shellcheck disable=SC2086
"$cc" "$consumer/main.c" -o "$scratch/pc_static" $cflags $ldirs $static_ldirs \
  -Wl,-Bstatic -lmfree_suitesparse -lmfree -Wl,-Bdynamic $static_libs -lm ||
  fail "pkg-config static build"
if readelf -d "$scratch/pc_static" | grep -q 'NEEDED.*\[libmfree'; then
  fail "static build still needs a shared libmfree*"
fi
run pkgconfig-static "$scratch/pc_static"

step "find_package(mfree): mfree::mfree_suitesparse and mfree::mfree_suitesparse_static"
"$cmake_cmd" -S "$consumer" -B "$scratch/cmake" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_RPATH="$libdir" >"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "configure the CMake consumer"; }
"$cmake_cmd" --build "$scratch/cmake" >>"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "build the CMake consumer"; }
run cmake-shared "$scratch/cmake/ss_consumer_shared"
if readelf -d "$scratch/cmake/ss_consumer_static" | grep -q 'NEEDED.*\[libmfree'; then
  fail "mfree::mfree_suitesparse_static still needs a shared libmfree*"
fi
run cmake-static "$scratch/cmake/ss_consumer_static"
echo "consumers.sh: ok"
