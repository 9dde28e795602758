#!/usr/bin/env bash
# Build and run a host program against an *installed* adapter library libmfree_ADAPTER
# (sundials, suitesparse, mpi, petsc): with pkg-config (shared, and the archives forced)
# and with find_package(mfree COMPONENTS ADAPTER), which must also refuse an unknown
# component by name. The host program is tests/ADAPTER/consumer; it prints one
# "...: ok" line per solver or integrator, and its CMake project builds
# BIN_PREFIX_consumer_shared and BIN_PREFIX_consumer_static. EXTRA_LIBS are linked after
# the pkg-config flags (SUNDIALS ships no pkg-config file: its host links it itself).
# An adapter named a_b has the pkg-config module mfree-a-b; $CONSUMER_DIR (relative to
# SOURCE_DIR, default tests/ADAPTER/consumer) names another host program's folder.
#
# usage: adapter_consumers.sh BUILD_DIR SCRATCH_DIR SOURCE_DIR C_COMPILER ADAPTER
#          BIN_PREFIX EXPECTED_OK [EXTRA_LIBS...]
#   SCRATCH_DIR must lie under BUILD_DIR; it is wiped first. $CMAKE (default cmake).
set -euo pipefail

if [[ $# -lt 7 ]]; then
  echo "usage: $0 BUILD_DIR SCRATCH_DIR SOURCE_DIR C_COMPILER ADAPTER BIN_PREFIX EXPECTED_OK [EXTRA_LIBS...]" >&2
  exit 2
fi
build=$(cd "$1" && pwd)
scratch=$2
src=$(cd "$3" && pwd)
cc=$4
adapter=$5
bin_prefix=$6
expected_ok=$7
shift 7
extra_libs="$*"
pkg=mfree-${adapter//_/-}
lib=mfree_$adapter
cmake_cmd=${CMAKE:-cmake}

fail() {
  echo "adapter_consumers.sh ($adapter): FAILED: $*" >&2
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
consumer=$src/${CONSUMER_DIR:-tests/$adapter/consumer}

step "install $build into $prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
  { cat "$scratch/install.log" >&2; fail "cmake --install"; }

pc=$(find "$prefix" -path "*/pkgconfig/$pkg.pc" -print -quit)
[[ -n "$pc" ]] || fail "no pkgconfig/$pkg.pc under $prefix"
pcdir=$(dirname "$pc")
libdir=$(dirname "$pcdir")
for f in lib$lib.so lib$lib.a; do
  [[ -e "$libdir/$f" ]] || fail "$f is not next to pkgconfig/ in $libdir"
done
[[ -f "$prefix/include/$lib.h" ]] || fail "$lib.h missing from $prefix/include"

run() { # name binary
  local out
  if ! out=$("$2" 2>&1); then
    printf '%s\n' "$out" >&2
    fail "$1: consumer program exited non-zero"
  fi
  printf '%s\n' "$out"
  [[ $(grep -c ': ok$' <<<"$out") -eq "$expected_ok" ]] || fail "$1: not every solver reported ok"
}

export PKG_CONFIG_PATH=$pcdir
cflags=$(pkg-config --cflags $pkg) || fail "pkg-config --cflags $pkg"
libs=$(pkg-config --libs $pkg) || fail "pkg-config --libs $pkg"
ldirs=$(pkg-config --libs-only-L $pkg)
step "pkg-config, shared: cc main.c $cflags $libs $extra_libs"
# shellcheck disable=SC2086
"$cc" "$consumer/main.c" -o "$scratch/pc_shared" $cflags $libs $extra_libs -lm \
  "-Wl,-rpath,$libdir" || fail "pkg-config shared build"
readelf -d "$scratch/pc_shared" | grep -q "NEEDED.*\\[lib$lib\\.so" ||
  fail "pkg-config shared build does not use lib$lib.so"
run pkgconfig-shared "$scratch/pc_shared"

# Every mfree library the module requires (-lmfree_X, then -lmfree_Y it builds on, then
# -lmfree), in pkg-config's order, forced static; the rest as pkg-config gives them.
all_static=$(pkg-config --static --libs-only-l $pkg)
mfree_static=$(tr ' ' '\n' <<<"$all_static" | { grep -E '^-lmfree(_[a-z_]+)?$' || true; } | tr '\n' ' ')
static_libs=$(tr ' ' '\n' <<<"$all_static" | { grep -vE '^-lmfree(_[a-z_]+)?$' || true; } | tr '\n' ' ')
static_ldirs=$(pkg-config --static --libs-only-L $pkg)
step "pkg-config, static archives: -Wl,-Bstatic $mfree_static-Wl,-Bdynamic $static_libs"
# shellcheck disable=SC2086
"$cc" "$consumer/main.c" -o "$scratch/pc_static" $cflags $ldirs $static_ldirs \
  -Wl,-Bstatic $mfree_static -Wl,-Bdynamic $static_libs $extra_libs -lm ||
  fail "pkg-config static build"
if readelf -d "$scratch/pc_static" | grep -q 'NEEDED.*\[libmfree'; then
  fail "static build still needs a shared libmfree*"
fi
run pkgconfig-static "$scratch/pc_static"

step "find_package(mfree COMPONENTS $adapter), and an unknown component refused by name"
comp=$scratch/components
mkdir -p "$comp"
cat >"$comp/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.16)
project(mfree_components LANGUAGES C)
find_package(mfree REQUIRED COMPONENTS \${WANT})
foreach(t mfree::$lib mfree::${lib}_static)
  if(NOT TARGET \${t})
    message(FATAL_ERROR "find_package(mfree COMPONENTS $adapter) gave no \${t}")
  endif()
endforeach()
EOF
"$cmake_cmd" -S "$comp" -B "$comp/ok" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" \
  -DWANT="$adapter" >"$comp/ok.log" 2>&1 || { cat "$comp/ok.log" >&2; fail "find_package(mfree COMPONENTS $adapter)"; }
if "$cmake_cmd" -S "$comp" -B "$comp/bad" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" \
  "-DWANT=$adapter;nonesuch" >"$comp/bad.log" 2>&1; then
  fail "find_package(mfree COMPONENTS $adapter nonesuch) succeeded"
fi
grep -q "unknown component 'nonesuch'" "$comp/bad.log" ||
  { cat "$comp/bad.log" >&2; fail "the unknown component is not named"; }

step "find_package(mfree COMPONENTS $adapter): mfree::$lib and mfree::${lib}_static"
"$cmake_cmd" -S "$consumer" -B "$scratch/cmake" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_RPATH="$libdir" >"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "configure the CMake consumer"; }
"$cmake_cmd" --build "$scratch/cmake" >>"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "build the CMake consumer"; }
run cmake-shared "$scratch/cmake/${bin_prefix}_consumer_shared"
if readelf -d "$scratch/cmake/${bin_prefix}_consumer_static" | grep -q 'NEEDED.*\[libmfree'; then
  fail "mfree::${lib}_static still needs a shared libmfree*"
fi
run cmake-static "$scratch/cmake/${bin_prefix}_consumer_static"
echo "adapter_consumers.sh ($adapter): ok"
