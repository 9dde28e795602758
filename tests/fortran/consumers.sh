#!/usr/bin/env bash
# Build and run Fortran hosts against an *installed* mfree, the way users consume it:
#  1. pkg-config, shared:  $FC app.f90 $(pkg-config --cflags --libs mfree-fortran), run
#     with LD_LIBRARY_PATH, and again linked with -Wl,-rpath,<libdir> and run without
#  2. pkg-config, static:  the archives libmfree_fortran.a and libmfree.a forced with
#     -Wl,-Bstatic, then what they need (pkg-config --static: -lstdc++ -lm); the binary
#     must not need any libmfree*.so
#  3. the same two for module mfree_suitesparse (mfree-fortran-suitesparse), when
#     installed
#  4. CMake: find_package(mfree) with mfree::mfree_fortran (and _static,
#     mfree::mfree_fortran_suitesparse)
#
# usage: consumers.sh BUILD_DIR SCRATCH_DIR SOURCE_DIR FORTRAN_COMPILER
#   SCRATCH_DIR must lie under BUILD_DIR; it is wiped first. $CMAKE (default cmake).
set -euo pipefail

if [[ $# -ne 4 ]]; then
  echo "usage: $0 BUILD_DIR SCRATCH_DIR SOURCE_DIR FORTRAN_COMPILER" >&2
  exit 2
fi
build=$(cd "$1" && pwd)
scratch=$2
src=$(cd "$3" && pwd)
fc=$4
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
consumer=$src/tests/fortran/consumer

step "install $build into $prefix"
"$cmake_cmd" --install "$build" --prefix "$prefix" >"$scratch/install.log" 2>&1 ||
  { cat "$scratch/install.log" >&2; fail "cmake --install"; }

pc=$(find "$prefix" -path '*/pkgconfig/mfree-fortran.pc' -print -quit)
[[ -n "$pc" ]] || fail "no pkgconfig/mfree-fortran.pc under $prefix"
pcdir=$(dirname "$pc")
libdir=$(dirname "$pcdir")
for f in libmfree_fortran.so libmfree_fortran.a; do
  [[ -e "$libdir/$f" ]] || fail "$f is not next to pkgconfig/ in $libdir"
done
# The modules sit beside the C headers.
[[ -f "$prefix/include/mfree.mod" && -f "$prefix/include/mfree.h" ]] ||
  fail "mfree.mod is not beside mfree.h in $prefix/include"

needs_shared_mfree() { readelf -d "$1" | grep -q 'NEEDED.*\[libmfree'; }

run() { # name binary expected-ok-lines [env...]
  local name=$1 bin=$2 want=$3
  shift 3
  local out
  if ! out=$(env "$@" "$bin" 2>&1); then
    printf '%s\n' "$out" >&2
    fail "$name: consumer program exited non-zero"
  fi
  printf '%s\n' "$out"
  [[ $(grep -c ': ok *$' <<<"$out") -eq $want ]] || fail "$name: the program did not report ok"
}

export PKG_CONFIG_PATH=$pcdir
pkgconfig_pair() { # pc-name source binary-stem ok-lines archives...
  local pcname=$1 source=$2 stem=$3 want=$4
  shift 4
  local cflags libs ldirs static_libs strip
  cflags=$(pkg-config --cflags "$pcname") || fail "pkg-config --cflags $pcname"
  libs=$(pkg-config --libs "$pcname") || fail "pkg-config --libs $pcname"
  ldirs=$(pkg-config --static --libs-only-L "$pcname")

  step "pkg-config, shared: $fc $(basename "$source") $cflags $libs"
  # shellcheck disable=SC2086
  (cd "$scratch" && "$fc" -std=f2008 -Wall -Werror "$source" -o "$stem-shared" $cflags $libs) ||
    fail "$pcname shared: compiling or linking the consumer"
  readelf -d "$scratch/$stem-shared" | grep -q "NEEDED.*\[libmfree_fortran" ||
    fail "$pcname shared: the binary does not need libmfree_fortran*.so"
  run "$pcname shared" "$scratch/$stem-shared" "$want" \
    LD_LIBRARY_PATH="$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
  # With an rpath instead of LD_LIBRARY_PATH: the binary records only the Fortran
  # library (--as-needed), which finds libmfree*.so beside itself (RUNPATH $ORIGIN).
  step "pkg-config, shared with -Wl,-rpath,$libdir (no LD_LIBRARY_PATH)"
  # shellcheck disable=SC2086
  (cd "$scratch" && "$fc" "$source" -o "$stem-rpath" $cflags $libs "-Wl,-rpath,$libdir") ||
    fail "$pcname shared with rpath: compiling or linking the consumer"
  run "$pcname shared, rpath" "$scratch/$stem-rpath" "$want" LD_LIBRARY_PATH=

  # The private libraries are what the archives themselves need (C++ runtime,
  # SuiteSparse); the mfree archives are forced static, the rest stays as pkg-config says.
  static_libs=$(pkg-config --static --libs-only-l "$pcname")
  for a in "$@"; do
    static_libs=$(sed "s/-l$a\b//g" <<<"$static_libs")
  done
  local forced=""
  for a in "$@"; do forced+=" -l$a"; done
  step "pkg-config, static: -Wl,-Bstatic$forced -Wl,-Bdynamic $static_libs"
  # shellcheck disable=SC2086
  (cd "$scratch" && "$fc" -std=f2008 -Wall -Werror "$source" -o "$stem-static" $cflags $ldirs \
    -Wl,-Bstatic $forced -Wl,-Bdynamic $static_libs) ||
    fail "$pcname static: compiling or linking the consumer against the archives"
  ! needs_shared_mfree "$scratch/$stem-static" ||
    fail "$pcname static: the binary still needs a shared libmfree*"
  run "$pcname static" "$scratch/$stem-static" "$want"  # no LD_LIBRARY_PATH
}

pkgconfig_pair mfree-fortran "$consumer/app.f90" app 1 mfree_fortran mfree
with_ss=OFF
if [[ -n "$(find "$prefix" -path '*/pkgconfig/mfree-fortran-suitesparse.pc' -print -quit)" ]]; then
  [[ -f "$prefix/include/mfree_suitesparse.mod" ]] || fail "mfree_suitesparse.mod not installed"
  pkgconfig_pair mfree-fortran-suitesparse "$consumer/app_suitesparse.f90" app_ss 3 \
    mfree_fortran_suitesparse mfree_fortran mfree_suitesparse mfree
  with_ss=ON
fi
unset PKG_CONFIG_PATH

step "CMake: find_package(mfree) with mfree::mfree_fortran and mfree::mfree_fortran_static"
"$cmake_cmd" -S "$consumer" -B "$scratch/cmake" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_Fortran_COMPILER="$fc" -DCMAKE_BUILD_RPATH="$libdir" -DWITH_SUITESPARSE=$with_ss \
  >"$scratch/cmake.log" 2>&1 || { cat "$scratch/cmake.log" >&2; fail "configure the CMake consumer"; }
"$cmake_cmd" --build "$scratch/cmake" >>"$scratch/cmake.log" 2>&1 ||
  { cat "$scratch/cmake.log" >&2; fail "build the CMake consumer"; }
run "CMake mfree::mfree_fortran" "$scratch/cmake/app_shared" 1
! needs_shared_mfree "$scratch/cmake/app_static" ||
  fail "mfree::mfree_fortran_static: the binary needs a shared libmfree*"
run "CMake mfree::mfree_fortran_static" "$scratch/cmake/app_static" 1
if [[ $with_ss == ON ]]; then
  run "CMake mfree::mfree_fortran_suitesparse" "$scratch/cmake/app_ss_shared" 3
fi
echo "consumers.sh: ok"
