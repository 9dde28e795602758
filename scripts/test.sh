#!/usr/bin/env bash
# Install missing build packages, then build and run every test twice: with the
# "default" preset (including the installed-tree consumer tests) and with the "asan"
# preset (AddressSanitizer + UndefinedBehaviorSanitizer, -O1); then the thread-safety
# tests under the "tsan" preset (ThreadSanitizer) when the run so far leaves room in the
# 30-minute CI budget. Exits non-zero on any failure.
#   MFREE_CI_TSAN=1 always runs the tsan stage, 0 never; unset: only when the default and
#   asan stages took less than MFREE_CI_TSAN_BEFORE seconds (default 1200).
# Then the replay of every fuzz corpus and regression input under clang with ASan+UBSan
# (configure preset fuzz, build and test presets fuzz-replay: the library, the adapters
# and the replay programs only), which flags what the GCC replay in the default and asan
# presets does not (e.g. pointer arithmetic on NULL); MFREE_CI_FUZZ_REPLAY=0 skips it.
# Not run here (see ABI.md / README): the libFuzzer campaign (scripts/fuzz.sh) and
# valgrind (scripts/valgrind.sh).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

start=$SECONDS
jobs=$(nproc)
bash scripts/deps.sh

stage() {  # stage <preset>
  local t0=$SECONDS
  echo "==== preset $1: configure, build, test"
  cmake --preset "$1"
  cmake --build --preset "$1" -j"$jobs"
  ctest --preset "$1" -j"$jobs"
  echo "==== preset $1 passed in $((SECONDS - t0)) s"
}

stage default
stage asan

tsan=${MFREE_CI_TSAN:-auto}
if [[ "$tsan" == auto ]]; then
  if ((SECONDS - start < ${MFREE_CI_TSAN_BEFORE:-1200})); then tsan=1; else tsan=0; fi
fi
if [[ "$tsan" == 1 ]]; then
  stage tsan
else
  echo "==== preset tsan skipped ($((SECONDS - start)) s used; MFREE_CI_TSAN=1 forces it)"
fi
if [[ "${MFREE_CI_FUZZ_REPLAY:-1}" == 1 ]]; then
  t0=$SECONDS
  echo "==== preset fuzz: configure, build the replay programs, replay every corpus"
  cmake --preset fuzz
  cmake --build --preset fuzz-replay -j"$jobs"
  ctest --preset fuzz-replay -j"$jobs"
  echo "==== preset fuzz (replay) passed in $((SECONDS - t0)) s"
fi
echo "==== all tests passed in $((SECONDS - start)) s"
