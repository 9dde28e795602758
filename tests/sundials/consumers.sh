#!/usr/bin/env bash
# Build and run a host program against an *installed* libmfree_sundials: with
# pkg-config (shared, and the archives forced) and with find_package(mfree). The host
# calls ARKODE and IDA itself and links them itself (SUNDIALS ships no pkg-config file).
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
consumer=$src/tests/sundials/consumer
sundials_libs="-lsundials_arkode -lsundials_ida -lsundials_nvecserial -lsundials_sunmatrixdense -lsundials_sunlinsoldense"

step "install $build into $prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
  { cat "$scratch/install.log" >&2; fail "cmake --install"; }

pc=$(find "$prefix" -path '*/pkgconfig/mfree-sundials.pc' -print -quit)
[[ -n "$pc" ]] || fail "no pkgconfig/mfree-sundials.pc under $prefix"
pcdir=$(dirname "$pc")
libdir=$(dirname "$pcdir")
for f in libmfree_sundials.so libmfree_sundials.a; do
  [[ -e "$libdir/$f" ]] || fail "$f is not next to pkgconfig/ in $libdir"
done
[[ -f "$prefix/include/mfree_sundials.h" ]] || fail "mfree_sundials.h missing from $prefix/include"

run() { # name binary
  local out
  if ! out=$("$2" 2>&1); then
    printf '%s\n' "$out" >&2
    fail "$1: consumer program exited non-zero"
  fi
  printf '%s\n' "$out"
  [[ $(grep -c ': ok$' <<<"$out") -eq 2 ]] || fail "$1: not every integrator reported ok"
}

export PKG_CONFIG_PATH=$pcdir
cflags=$(pkg-config --cflags mfree-sundials) || fail "pkg-config --cflags mfree-sundials"
libs=$(pkg-config --libs mfree-sundials) || fail "pkg-config --libs mfree-sundials"
ldirs=$(pkg-config --libs-only-L mfree-sundials)
step "pkg-config, shared: cc main.c $cflags $libs $sundials_libs"
# shellcheck disable=SC2086
"$cc" "$consumer/main.c" -o "$scratch/pc_shared" $cflags $libs $sundials_libs -lm \
  "-Wl,-rpath,$libdir" || fail "pkg-config shared build"
readelf -d "$scratch/pc_shared" | grep -q 'NEEDED.*\[libmfree_sundials\.so' ||
  fail "pkg-config shared build does not use libmfree_sundials.so"
run pkgconfig-shared "$scratch/pc_shared"

static_libs=$(pkg-config --static --libs-only-l mfree-sundials |
  sed -e 's/-lmfree_sundials\b//' -e 's/-lmfree\b//')
static_ldirs=$(pkg-config --static --libs-only-L mfree-sundials)
step "pkg-config, static archives: -Wl,-Bstatic -lmfree_sundials -lmfree -Wl,-Bdynamic $static_libs"
# shellcheck disable=SC2086
"$cc" "$consumer/main.c" -o "$scratch/pc_static" $cflags $ldirs $static_ldirs \
  -Wl,-Bstatic -lmfree_sundials -lmfree -Wl,-Bdynamic $static_libs $sundials_libs -lm ||
  fail "pkg-config static build"
if readelf -d "$scratch/pc_static" | grep -q 'NEEDED.*\[libmfree'; then
  fail "static build still needs a shared libmfree*"
fi
run pkgconfig-static "$scratch/pc_static"

step "find_package(mfree): mfree::mfree_sundials and mfree::mfree_sundials_static"
"$cmake_cmd" -S "$consumer" -B "$scratch/cmake" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_RPATH="$libdir" >"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "configure the CMake consumer"; }
"$cmake_cmd" --build "$scratch/cmake" >>"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "build the CMake consumer"; }
run cmake-shared "$scratch/cmake/sun_consumer_shared"
if readelf -d "$scratch/cmake/sun_consumer_static" | grep -q 'NEEDED.*\[libmfree'; then
  fail "mfree::mfree_sundials_static still needs a shared libmfree*"
fi
run cmake-static "$scratch/cmake/sun_consumer_static"
echo "consumers.sh: ok"
