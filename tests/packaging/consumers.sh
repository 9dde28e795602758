#!/usr/bin/env bash
# Build and run host programs against an *installed* mfree, the way users consume it.
#
# usage: consumers.sh BUILD_DIR SCRATCH_DIR SOURCE_DIR C_COMPILER [MODE]
#   MODE  pkgconfig  cc + pkg-config, shared and forced-static (default: all modes)
#         cmake      find_package(mfree) with mfree::mfree and mfree::mfree_static
#         serial     find_package(mfree) in hosts where MPI cannot be found (C with
#                    CMAKE_DISABLE_FIND_PACKAGE_MPI, C++ alone), from the same tree as
#                    the adapters: mfree::mfree and mfree::mfree_static, no MPI target,
#                    the mpi and sundials_mpi components refused by name (or left out
#                    when optional)
#   SCRATCH_DIR must lie under BUILD_DIR; it is wiped first, so reruns start clean.
# The cmake consumer uses $CMAKE (default: cmake on PATH).
set -euo pipefail

if [[ $# -lt 4 || $# -gt 5 ]]; then
  echo "usage: $0 BUILD_DIR SCRATCH_DIR SOURCE_DIR C_COMPILER [pkgconfig|cmake|serial]" >&2
  exit 2
fi
build=$(cd "$1" && pwd)
scratch=$2
src=$(cd "$3" && pwd)
cc=$4
mode=${5:-all}
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
consumer=$src/tests/packaging/consumer

step "install $build into $prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
  { cat "$scratch/install.log" >&2; fail "cmake --install"; }

# GNUInstallDirs may choose lib, lib64 or lib/<multiarch>: find what was installed.
pc=$(find "$prefix" -path '*/pkgconfig/mfree.pc' -print -quit)
[[ -n "$pc" ]] || fail "no pkgconfig/mfree.pc under $prefix"
pcdir=$(dirname "$pc")
libdir=$(dirname "$pcdir")
[[ -e "$libdir/libmfree.so" ]] || fail "libmfree.so is not next to pkgconfig/ in $libdir"
[[ -e "$libdir/libmfree.a" ]] || fail "libmfree.a is not next to pkgconfig/ in $libdir"
[[ -f "$prefix/include/mfree.h" && -f "$prefix/include/mfree_version.h" ]] ||
  fail "headers missing from $prefix/include"

needs_libmfree() { readelf -d "$1" | grep -q 'NEEDED.*\[libmfree\.so'; }

run_consumer() { # name binary [env...]
  local name=$1 bin=$2
  shift 2
  local out
  if ! out=$(env "$@" "$bin" 2>&1); then
    printf '%s\n' "$out" >&2
    fail "$name: consumer program exited non-zero"
  fi
  printf '%s\n' "$out"
  grep -q ': ok$' <<<"$out" || fail "$name: consumer program did not report success"
}

consumer_pkgconfig() {
  local out=$scratch/pkgconfig
  mkdir -p "$out"
  export PKG_CONFIG_PATH=$pcdir
  local cflags libs ldirs static_private
  cflags=$(pkg-config --cflags mfree) || fail "pkg-config --cflags mfree"
  libs=$(pkg-config --libs mfree) || fail "pkg-config --libs mfree"
  ldirs=$(pkg-config --libs-only-L mfree) || fail "pkg-config --libs-only-L mfree"
  # The private libraries are what the archive itself needs (the C++ runtime).
  static_private=$(pkg-config --static --libs-only-l mfree | sed 's/-lmfree\b//')
  grep -qx 'License: BSD-3-Clause' "$pcdir/mfree.pc" || fail "mfree.pc names no BSD-3-Clause licence"

  step "pkg-config, shared: cc main.c $cflags $libs"
  # shellcheck disable=SC2086
  "$cc" -std=c99 -Wall -Wextra -Werror -o "$out/shared" "$consumer/main.c" $cflags $libs ||
    fail "pkg-config shared: compiling or linking the consumer"
  needs_libmfree "$out/shared" || fail "pkg-config shared: binary does not need libmfree.so"
  run_consumer "pkg-config shared" "$out/shared" LD_LIBRARY_PATH="$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

  step "pkg-config, static: libmfree.a forced with -Wl,-Bstatic, then $static_private"
  # shellcheck disable=SC2086
  "$cc" -std=c99 -Wall -Wextra -Werror -o "$out/static" "$consumer/main.c" $cflags \
    $ldirs -Wl,-Bstatic -lmfree -Wl,-Bdynamic $static_private ||
    fail "pkg-config static: compiling or linking the consumer against libmfree.a"
  ! needs_libmfree "$out/static" || fail "pkg-config static: binary still needs libmfree.so"
  # No LD_LIBRARY_PATH: the binary must run without finding libmfree.so.
  run_consumer "pkg-config static" "$out/static"
  unset PKG_CONFIG_PATH
}

consumer_cmake() {
  local out=$scratch/cmake
  step "CMake: find_package(mfree) with CMAKE_PREFIX_PATH=$prefix"
  "$cmake_cmd" -S "$consumer" -B "$out" -DCMAKE_PREFIX_PATH="$prefix" \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_BUILD_TYPE=Release >"$scratch/cmake-configure.log" 2>&1 ||
    { cat "$scratch/cmake-configure.log" >&2; fail "configuring the CMake consumer"; }
  "$cmake_cmd" --build "$out" >"$scratch/cmake-build.log" 2>&1 ||
    { cat "$scratch/cmake-build.log" >&2; fail "building the CMake consumer"; }
  needs_libmfree "$out/consumer_shared" || fail "mfree::mfree: binary does not need libmfree.so"
  ! needs_libmfree "$out/consumer_static" || fail "mfree::mfree_static: binary needs libmfree.so"
  # consumer_shared finds libmfree.so through the build-tree RPATH CMake gives it.
  run_consumer "CMake mfree::mfree" "$out/consumer_shared"
  run_consumer "CMake mfree::mfree_static" "$out/consumer_static"
}

consumer_serial() {
  local cfg cfgdir lang out
  cfg=$(find "$prefix" -name mfreeConfig.cmake -print -quit)
  [[ -n "$cfg" ]] || fail "no mfreeConfig.cmake under $prefix"
  cfgdir=$(dirname "$cfg")
  step "the core's targets file names no adapter and no adapter's dependency"
  if grep -nE 'MPI::|PkgConfig::|SUNDIALS::|mfree_(mpi|petsc|suitesparse|sundials)' \
    "$cfgdir"/mfreeTargets*.cmake; then
    fail "mfreeTargets.cmake names an adapter or a dependency of one"
  fi
  for lang in C CXX; do
    out=$scratch/serial-$lang
    local args=("-DCONSUMER_LANGUAGE=$lang" -DEXPECT_SERIAL=ON)
    if [[ $lang == C ]]; then
      args+=(-DCMAKE_C_COMPILER="$cc" -DCMAKE_DISABLE_FIND_PACKAGE_MPI=ON)
    fi
    step "CMake, $lang only (${args[*]}): find_package(mfree), mfree::mfree"
    "$cmake_cmd" -S "$consumer" -B "$out" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release "${args[@]}" >"$out.log" 2>&1 ||
      { cat "$out.log" >&2; fail "configuring the $lang-only consumer"; }
    "$cmake_cmd" --build "$out" >>"$out.log" 2>&1 ||
      { cat "$out.log" >&2; fail "building the $lang-only consumer"; }
    run_consumer "$lang-only mfree::mfree" "$out/consumer_shared"
    run_consumer "$lang-only mfree::mfree_static" "$out/consumer_static"
  done

  # The components over MPI (mpi, sundials_mpi) in a C host where MPI is disabled:
  # optional, each is left out; required, the package is not found and says why (not
  # CMake's error for a REQUIRED search of a disabled package).
  local comp=$scratch/serial-components expected c
  mkdir -p "$comp"
  cat >"$comp/CMakeLists.txt" <<'END'
cmake_minimum_required(VERSION 3.16)
project(mfree_serial_components LANGUAGES C)
if(REQUIRE_MPI)
  find_package(mfree REQUIRED COMPONENTS ${COMP})
else()
  find_package(mfree REQUIRED OPTIONAL_COMPONENTS ${COMP})
endif()
if(mfree_${COMP}_FOUND OR TARGET mfree::mfree_${COMP} OR NOT TARGET mfree::mfree)
  message(FATAL_ERROR "OPTIONAL_COMPONENTS ${COMP} without MPI: mfree_${COMP}_FOUND '${mfree_${COMP}_FOUND}'")
endif()
END
  for c in mpi sundials_mpi; do
    step "CMake, C with MPI disabled: find_package(mfree OPTIONAL_COMPONENTS $c)"
    "$cmake_cmd" -S "$comp" -B "$comp/optional-$c" -DCMAKE_PREFIX_PATH="$prefix" -DCOMP=$c \
      -DCMAKE_C_COMPILER="$cc" -DCMAKE_DISABLE_FIND_PACKAGE_MPI=ON >"$comp/optional-$c.log" 2>&1 ||
      { cat "$comp/optional-$c.log" >&2; fail "find_package(mfree OPTIONAL_COMPONENTS $c) without MPI"; }
    step "CMake, C with MPI disabled: find_package(mfree REQUIRED COMPONENTS $c) refused"
    if "$cmake_cmd" -S "$comp" -B "$comp/required-$c" -DCMAKE_PREFIX_PATH="$prefix" -DCOMP=$c \
      -DCMAKE_C_COMPILER="$cc" -DCMAKE_DISABLE_FIND_PACKAGE_MPI=ON -DREQUIRE_MPI=ON \
      >"$comp/required-$c.log" 2>&1; then
      fail "find_package(mfree REQUIRED COMPONENTS $c) succeeded without MPI"
    fi
    expected="this installation was built without libmfree_$c"
    if [[ -f "$cfgdir/mfree_${c}Targets.cmake" ]]; then
      expected="component '$c' needs MPI::MPI_C"
    fi
    grep -qF "$expected" "$comp/required-$c.log" ||
      { cat "$comp/required-$c.log" >&2; fail "the refusal does not say: $expected"; }
  done
}

case "$mode" in
  pkgconfig) consumer_pkgconfig ;;
  cmake) consumer_cmake ;;
  serial) consumer_serial ;;
  all) consumer_pkgconfig; consumer_cmake; consumer_serial ;;
  *) fail "unknown mode '$mode' (pkgconfig, cmake or serial)" ;;
esac
echo "consumers.sh: $mode consumers passed"
