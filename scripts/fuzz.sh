#!/usr/bin/env bash
# A fuzzing campaign: every libFuzzer harness of fuzz/ in turn for MINUTES minutes each
# (default 5), under nice -n 19 (a shared machine: one harness at a time, one process).
#   scripts/fuzz.sh [minutes] [harness...]
# Builds the fuzz preset (clang, libFuzzer, ASan+UBSan) first. New inputs go to
# build/fuzz/tests/robustness/fuzz/corpus/<harness> (the repository's corpus is read only: copy inputs
# worth keeping to fuzz/corpus/<harness>); a crash leaves build/fuzz/tests/robustness/fuzz/<harness>-crash-*
# (copy it to fuzz/regressions/<harness>/, fix the bug, commit both). Prints, per
# harness, the executions, the edges libFuzzer counted (whole binary), the edges covered
# in the harness's target files (libFuzzer's -print_coverage) and the crashes, and keeps
# the logs in build/fuzz/campaign/. With COVERAGE=1 it then replays every corpus in a
# coverage build (build/fuzz-cov: clang source-based coverage, no sanitizers) and prints
# the region and branch coverage of each harness's target files (llvm-cov).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

minutes=${1:-5}
shift || true
harnesses=("$@")
if ((${#harnesses[@]} == 0)); then
  harnesses=(particles approximant mpfem assembly system adapters)
fi

# The files each harness targets (its API family), for the coverage figures.
target_files() {
  case $1 in
    particles) echo "src/core/particles/particles.cpp src/core/particles/neighbors.cpp src/capi/particles.cpp" ;;
    approximant) echo "src/core/shape/approximant.cpp src/core/shape/apply.cpp src/core/shape/local.cpp src/core/shape/shape_fast.cpp src/capi/approximant.cpp" ;;
    mpfem) echo "src/core/shape/mpfem.cpp src/capi/mesh.cpp" ;;
    assembly) echo "src/core/discretize/assembler.cpp src/core/discretize/matrix.cpp src/capi/assembler.cpp src/capi/matrix.cpp" ;;
    system) echo "src/core/systems/fluid.cpp src/core/systems/fluid_tables.cpp src/core/systems/fluid_accel.cpp src/core/systems/fluid_wall.cpp src/core/systems/elastodynamics.cpp src/capi/system.cpp" ;;
    adapters) echo "adapters/suitesparse/src/suitesparse.cpp adapters/sundials/src/sundials.cpp" ;;
  esac
}

# Edges covered / instrumented in the target files, from libFuzzer's -print_coverage=1
# lines "(UN)COVERED_FUNC: hits: H edges: C/T function file:line".
edge_coverage() {  # edge_coverage <log> <files...>
  local log=$1
  shift
  awk -v files="$*" '
    BEGIN { n = split(files, f, " ") }
    /COVERED_FUNC: hits:/ {
      split($5, e, "/"); loc = $NF; sub(/:[0-9]+$/, "", loc)
      for (i = 1; i <= n; ++i) if (index(loc, f[i]) && substr(loc, length(loc) - length(f[i]) + 1) == f[i]) { c += e[1]; t += e[2]; break }
    }
    END { if (t > 0) printf "%d/%d (%.1f %%)", c, t, 100 * c / t; else printf "?" }' "$log"
}

cmake --preset fuzz >/dev/null
nice -n 19 cmake --build --preset fuzz -j"${MFREE_FUZZ_JOBS:-1}"

out=build/fuzz/campaign
mkdir -p "$out"
summary="$out/summary.txt"
: >"$summary"
for h in "${harnesses[@]}"; do
  bin=build/fuzz/tests/robustness/fuzz/mfree_fuzz_$h
  [[ -x "$bin" ]] || { echo "no harness $h (adapters need SuiteSparse and SUNDIALS)"; continue; }
  work=build/fuzz/tests/robustness/fuzz/corpus/$h
  mkdir -p "$work"
  log="$out/$h.log"
  # (libFuzzer exits on a missing directory: a harness may have no regression inputs yet)
  inputs=("$work" "fuzz/corpus/$h")
  [[ -d fuzz/regressions/$h ]] && inputs+=("fuzz/regressions/$h")
  echo "==== $h: $minutes min"
  set +e
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=print_stacktrace=1 \
    nice -n 19 "$bin" -max_total_time=$((minutes * 60)) -timeout=20 -rss_limit_mb=3072 \
    -print_final_stats=1 -print_coverage=1 -artifact_prefix="build/fuzz/tests/robustness/fuzz/$h-" \
    "${inputs[@]}" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || true)
  edges=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || true)
  crashes=$( (ls build/fuzz/tests/robustness/fuzz/"$h"-crash-* build/fuzz/tests/robustness/fuzz/"$h"-leak-* build/fuzz/tests/robustness/fuzz/"$h"-timeout-* 2>/dev/null || true) | wc -l)
  # shellcheck disable=SC2046
  tcov=$(edge_coverage "$log" $(target_files "$h"))
  printf '%-12s exit %-3s executions %-10s edges (whole binary) %-6s edges in its target files %-22s crash/leak/timeout files %s\n' \
    "$h" "$rc" "${execs:-?}" "${edges:-?}" "$tcov" "$crashes" | tee -a "$summary"
done

if [[ "${COVERAGE:-0}" == 1 ]]; then
  # Source-based coverage of the corpora, per harness and its target files.
  cov=build/fuzz-cov
  CC=clang CXX=clang++ cmake -S . -B "$cov" -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_C_FLAGS="-fprofile-instr-generate -fcoverage-mapping" \
    -DCMAKE_CXX_FLAGS="-fprofile-instr-generate -fcoverage-mapping" \
    -DCMAKE_EXE_LINKER_FLAGS="-fprofile-instr-generate" -DCMAKE_SHARED_LINKER_FLAGS="-fprofile-instr-generate" \
    -DCMAKE_DISABLE_FIND_PACKAGE_OpenMP=ON -DMFREE_WITH_FORTRAN=OFF -DMFREE_BUILD_EXAMPLES=OFF \
    -DMFREE_BUILD_BENCH=OFF -DMFREE_TEST_PACKAGING=OFF >/dev/null
  llvm_bin=$(dirname "$(readlink -f "$(command -v clang)")")
  for h in "${harnesses[@]}"; do
    nice -n 19 cmake --build "$cov" -j"${MFREE_FUZZ_JOBS:-1}" --target "mfree_fuzz_replay_$h" >/dev/null || continue
    files=$(target_files "$h")
    rm -f "$cov"/"$h".prof*
    find build/fuzz/tests/robustness/fuzz/corpus/"$h" fuzz/corpus/"$h" fuzz/regressions/"$h" -type f -print0 2>/dev/null |
      xargs -0 -r -n 500 env LLVM_PROFILE_FILE="$cov/$h.prof-%p.profraw" nice -n 19 "$cov/tests/robustness/fuzz/mfree_fuzz_replay_$h" >/dev/null 2>&1 || true
    "$llvm_bin/llvm-profdata" merge -o "$cov/$h.profdata" "$cov"/"$h".prof-*.profraw
    objs=("$cov/tests/robustness/fuzz/mfree_fuzz_replay_$h" -object "$cov/src/libmfree.so")
    [[ $h == adapters ]] && objs+=(-object "$cov/adapters/suitesparse/libmfree_suitesparse.so" -object "$cov/adapters/sundials/libmfree_sundials.so")
    echo "---- $h: coverage of its target files" | tee -a "$summary"
    # shellcheck disable=SC2086
    "$llvm_bin/llvm-cov" report "${objs[@]}" -instr-profile="$cov/$h.profdata" $files | tee -a "$summary"
  done
fi
echo "summary: $summary"
