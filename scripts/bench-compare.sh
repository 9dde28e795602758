#!/usr/bin/env bash
# Side-by-side benchmarks of two commits: scripts/bench-compare.sh [options] OLD NEW
#
# Builds libmfree at OLD and at NEW (each in its own git worktree and build directory
# under a scratch directory, configure preset "default" = RelWithDebInfo, ccache when
# installed), runs every selected bench/ program alternately against the two libraries
# for k rounds on this machine (old, new | new, old | old, new ...: each pair of runs of
# one program lies within the same minute or two, and neither library always runs
# first), keeps each figure's best over the rounds, and prints a markdown table: figure,
# old (best), new (best), new/old, and whether within the bound (5 %; the dam-break step
# 10 %; a ratio below 1 is a gain); also the ratio of the medians over the rounds, which a
# lucky run on either side does not move (on a busy machine compare the two). Figures
# whose name starts with "reference" are not mfree (nanoflann, the STREAM triad, the
# host's dwdx loop): their ratio is the noise of the run, not a verdict.
#
# What is compared, and why it is the honest comparison: the SAME benchmark sources
# (bench/ of --bench-from, default NEW) are compiled against each library's own header
# and linked to that library; only the library differs. The programs use only the public
# C API, which a change may extend but never break (abi/), so sources that compile
# against NEW compile against OLD unless they call a function added since; then say
# --bench-from=OLD-or-later commit that has the machine-readable output. Running each
# commit's own bench/ instead would mix changes of the workload or of the timing loop
# into the library's figures, and OLD commits before the machine-readable mode
# (MFREE_BENCH_FORMAT=tsv, bench/bench_util.h) print only human text.
#
# Default sizes (about 10 minutes on an idle 2-core machine with builds from ccache: the
# runs use about 80 s of CPU per round): the documented problem sizes (10^5 particles,
# the 25,088-particle dam break, Table IV at 300 x 300, 2 MPI ranks x 2.5e5) with fewer
# repetitions inside each program
# (MFREE_BENCH_REPS=2 for bench_shape, 3 for bench_neighbors, bench_pairs 2 repeats,
# bench_mpi_weak 10 steps): the rounds repeat the whole programs instead. --full runs the
# programs' own defaults (1e4 too, 7 pair repeats, 20 MPI steps, 1/2/4 ranks; about
# twice as long per round: take fewer rounds).
#
# Options:
#   -k, --rounds N      rounds (default 6): each program runs 2N times; an even count
#                       lets each library run first equally often
#   -b, --bench LIST    comma-separated programs, without "bench_" (default
#                       neighbors,shape,apply,dambreak,table4,pairs,mpi_weak; also
#                       verlet, for two commits that both have the Verlet skin, which
#                       beb1e93 lacks)
#   --clock wall|cpu    MFREE_BENCH_CLOCK for the programs (default: $MFREE_BENCH_CLOCK, else
#                       wall). cpu = process CPU time, for a shared machine: one-thread
#                       figures stay meaningful; OMP_WAIT_POLICY=passive is then set (unless
#                       set already) so that threaded figures count work, not spinning;
#                       they still sum the threads' times (marked in the table);
#                       bench_mpi_weak always times by MPI_Wtime (wall clock; not judged)
#   -t, --threads N     MFREE_BENCH_THREADS, the programs' second thread count (default:
#                       $MFREE_BENCH_THREADS, else 0 = all cores)
#   --ranks LIST        MPI ranks for bench_mpi_weak, e.g. "1 2" (default "2", --full "1 2 4")
#   --full              the programs' own default sizes and repetitions
#   --bench-from REF    bench/ sources of REF for both builds (default NEW)
#   --scratch DIR       worktrees, builds and logs (default <repository>/build/bench-compare;
#                       kept between runs, so that a second run rebuilds nothing)
#   --preset NAME       configure preset (default "default")
#   -j, --jobs N        build jobs (default 2)
#   --out FILE          also write the table to FILE
#   --build-only        build both and stop
#   --remove            remove the scratch worktrees (git worktree remove) and stop
# Exit status: 0 all figures within their bounds, 3 some beyond, 1-2 errors.
#
# Examples:
#   scripts/bench-compare.sh beb1e93 main                          # idle machine, wall clock
#   MFREE_BENCH_CLOCK=cpu scripts/bench-compare.sh -t 1 -b shape,dambreak beb1e93 HEAD
set -euo pipefail
# The whole script is one compound command, read before it runs: editing or checking out
# another version of this file during a run cannot change the running one.
{

usage() { sed -n '2,/^set -euo/p' "$0" | grep -v '^set' | sed 's/^# \{0,1\}//'; exit "${1:-2}"; }
die() { echo "bench-compare: $*" >&2; exit 2; }
say() { echo "bench-compare: $*" >&2; }

rounds=6
benches="neighbors,shape,apply,dambreak,table4,pairs,mpi_weak"
clock="${MFREE_BENCH_CLOCK:-wall}"
threads="${MFREE_BENCH_THREADS:-0}"
ranks=""
full=0
bench_from=""
scratch=""
preset="default"
jobs=2
out=""
build_only=0
remove=0
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    -k|--rounds) rounds="$2"; shift 2 ;;
    --rounds=*) rounds="${1#*=}"; shift ;;
    -b|--bench) benches="$2"; shift 2 ;;
    --bench=*) benches="${1#*=}"; shift ;;
    --clock) clock="$2"; shift 2 ;;
    --clock=*) clock="${1#*=}"; shift ;;
    -t|--threads) threads="$2"; shift 2 ;;
    --threads=*) threads="${1#*=}"; shift ;;
    --ranks) ranks="$2"; shift 2 ;;
    --ranks=*) ranks="${1#*=}"; shift ;;
    --full) full=1; shift ;;
    --bench-from) bench_from="$2"; shift 2 ;;
    --bench-from=*) bench_from="${1#*=}"; shift ;;
    --scratch) scratch="$2"; shift 2 ;;
    --scratch=*) scratch="${1#*=}"; shift ;;
    --preset) preset="$2"; shift 2 ;;
    --preset=*) preset="${1#*=}"; shift ;;
    -j|--jobs) jobs="$2"; shift 2 ;;
    --jobs=*) jobs="${1#*=}"; shift ;;
    --out) out="$2"; shift 2 ;;
    --out=*) out="${1#*=}"; shift ;;
    --build-only) build_only=1; shift ;;
    --remove) remove=1; shift ;;
    -h|--help) usage 0 ;;
    -*) die "unknown option $1 (--help)" ;;
    *) args+=("$1"); shift ;;
  esac
done
case "$clock" in wall|cpu) ;; c*) clock=cpu ;; *) die "--clock wall or cpu, not '$clock'" ;; esac
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || die "--rounds takes a positive number"
[[ "$threads" =~ ^[0-9]+$ ]] || die "--threads takes a number (0 = all cores)"

repo="$(git rev-parse --show-toplevel 2>/dev/null)" || die "run inside the mfree repository"
scratch="${scratch:-$repo/build/bench-compare}"
mkdir -p "$scratch"
scratch="$(cd "$scratch" && pwd)"
# one run per scratch directory: a second one would rebuild a library under the first
exec 9>"$scratch/.lock"
flock -n 9 || die "another bench-compare is using $scratch (wait, or pass --scratch)"

if [ "$remove" = 1 ]; then
  for side in old new; do
    if [ -d "$scratch/$side" ]; then git -C "$repo" worktree remove --force "$scratch/$side"; fi
  done
  rm -rf "$scratch"
  git -C "$repo" worktree prune
  exit 0
fi
[ ${#args[@]} -eq 2 ] || usage
commit() { git -C "$repo" rev-parse --verify --quiet "$1^{commit}" || die "'$1' is not a commit"; }
old_c="$(commit "${args[0]}")"
new_c="$(commit "${args[1]}")"
from_c="$(commit "${bench_from:-${args[1]}}")"
git -C "$repo" cat-file -e "$from_c:bench/bench_util.h" 2>/dev/null &&
  git -C "$repo" show "$from_c:bench/bench_util.h" | grep -q MFREE_BENCH_FORMAT ||
  die "bench/ of $(git -C "$repo" rev-parse --short "$from_c") has no MFREE_BENCH_FORMAT=tsv mode: pass --bench-from=<a later commit>"

IFS=, read -r -a sel <<<"$benches"
for b in "${sel[@]}"; do
  case "$b" in neighbors|shape|apply|dambreak|table4|pairs|mpi_weak|verlet) ;;
    *) die "unknown benchmark '$b' (neighbors, shape, apply, dambreak, table4, pairs, mpi_weak, verlet)" ;; esac
done
want_mpi=0
for b in "${sel[@]}"; do [ "$b" = mpi_weak ] && want_mpi=1; done
[ -n "$ranks" ] || { [ "$full" = 1 ] && ranks="1 2 4" || ranks="2"; }

# --- worktrees and builds ---------------------------------------------------------------
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
build() {  # side commit
  # the build directory is the preset's own (build/<preset> in the worktree), so that the
  # compiler sees the same relative paths as in a developer's tree and ccache hits
  local side="$1" c="$2" wt="$scratch/$1" bd="$scratch/$1/build/$preset"
  if [ -d "$wt" ]; then
    git -C "$wt" checkout --quiet --force --detach "$c"
  else
    git -C "$repo" worktree add --quiet --force --detach "$wt" "$c"
  fi
  # the same benchmark sources on both sides (see the header)
  rm -rf "$wt/bench"
  git -C "$repo" archive "$from_c" bench | tar -x -C "$wt"
  say "$side: $(git -C "$wt" log -1 --format='%h %s' | cut -c1-90)"
  (cd "$wt" && cmake --preset "$preset" "${launcher[@]}" \
      -DMFREE_BUILD_BENCH=ON -DMFREE_BUILD_TESTS=OFF -DMFREE_BUILD_EXAMPLES=OFF \
      -DMFREE_TEST_PACKAGING=OFF -DMFREE_WITH_SUITESPARSE=OFF -DMFREE_WITH_SUNDIALS=OFF \
      -DMFREE_WITH_FORTRAN=OFF -DMFREE_WITH_PETSC=OFF -DMFREE_WITH_MPI="$([ $want_mpi = 1 ] && echo ON || echo OFF)" \
      >"$scratch/logs/$side-configure.log" 2>&1) ||
    die "$side: configure failed, see $scratch/logs/$side-configure.log"
  [ -f "$bd/CMakeCache.txt" ] || die "$side: preset $preset does not build in build/$preset"
  local targets=()
  for b in "${sel[@]}"; do
    if [ "$b" = mpi_weak ] && ! grep -q '^MFREE_WITH_MPI:BOOL=ON' "$bd/CMakeCache.txt"; then
      continue
    fi
    targets+=("bench_$b")
  done
  nice -n 5 cmake --build "$bd" -j "$jobs" --target "${targets[@]}" >"$scratch/logs/$side-build.log" 2>&1 ||
    die "$side: build failed, see $scratch/logs/$side-build.log (if bench/ of --bench-from calls a function OLD lacks, pass --bench-from=OLD or a commit between)"
  # each program must load its own side's library (the build tree's RPATH)
  for t in "${targets[@]}"; do
    local lib
    lib="$(ldd "$bd/bench/$t" | awk '/libmfree\.so/ {print $3; exit}')"
    case "$lib" in "$bd"/*) ;; *) die "$side: $t loads libmfree from '$lib', not from $bd" ;; esac
  done
}
mkdir -p "$scratch/logs"
t_start=$(date +%s)
build old "$old_c"
build new "$new_c"
say "built in $(( $(date +%s) - t_start )) s"
[ "$build_only" = 1 ] && exit 0

# --- runs -------------------------------------------------------------------------------
export MFREE_BENCH_FORMAT=tsv MFREE_BENCH_CLOCK="$clock" MFREE_BENCH_THREADS="$threads"
if [ "$clock" = cpu ] && [ -z "${OMP_WAIT_POLICY:-}" ]; then export OMP_WAIT_POLICY=passive; fi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # containers run as root
skipped=""
run_one() {  # side bench log
  local bd="$scratch/$1/build/$preset/bench" b="$2" log="$3"
  case "$b" in
    neighbors) if [ "$full" = 1 ]; then "$bd/bench_neighbors"; else MFREE_BENCH_REPS=3 "$bd/bench_neighbors" 1e5; fi ;;
    shape) if [ "$full" = 1 ]; then "$bd/bench_shape"; else MFREE_BENCH_REPS=2 "$bd/bench_shape"; fi ;;
    apply) "$bd/bench_apply" ;;
    dambreak) "$bd/bench_dambreak" ;;
    table4) "$bd/bench_table4" ;;
    verlet) if [ "$full" = 1 ]; then "$bd/bench_verlet"; else MFREE_BENCH_REPS=2 "$bd/bench_verlet"; fi ;;
    pairs) if [ "$full" = 1 ]; then "$bd/bench_pairs"; else "$bd/bench_pairs" 1e5 2; fi ;;
    mpi_weak)
      for p in $ranks; do
        if [ "$full" = 1 ]; then
          mpirun --oversubscribe -np "$p" "$bd/bench_mpi_weak"
        else
          mpirun --oversubscribe -np "$p" "$bd/bench_mpi_weak" --steps=10
        fi
      done ;;
  esac >"$log" 2>&1 || die "$1: bench_$b failed, see $log"
}
runs="$scratch/logs/runs.tsv"  # side, round, name, value, unit
# CPU seconds (user + system) of all finished children so far: the shell's `times`
# (run in this shell, not in a subshell, whose count would start at zero)
child_cpu() { tail -n 1 "$1" | awk '{ s = 0; for (i = 1; i <= 2; ++i) { split($i, a, "m"); s += 60 * a[1] + a[2] } printf("%.0f", s) }'; }
times >"$scratch/logs/cpu-before"
t_runs=$(date +%s)
: >"$runs"
for ((r = 1; r <= rounds; ++r)); do
  if ((r % 2)); then order="old new"; else order="new old"; fi
  for b in "${sel[@]}"; do
    if [ "$b" = mpi_weak ]; then
      if [ ! -x "$scratch/old/build/$preset/bench/bench_mpi_weak" ] || [ ! -x "$scratch/new/build/$preset/bench/bench_mpi_weak" ]; then
        skipped="bench_mpi_weak: not built (no MPI found at configure time, see $scratch/logs/*-configure.log)"
        continue
      fi
      if ! command -v mpirun >/dev/null; then skipped="bench_mpi_weak: no mpirun on PATH"; continue; fi
    fi
    for side in $order; do
      say "round $r/$rounds: $side bench_$b ($(( $(date +%s) - t_start )) s)"
      log="$scratch/logs/$side-$b-r$r.txt"
      run_one "$side" "$b" "$log"
      awk -F'\t' -v s="$side" -v r="$r" 'NF == 3 {print s "\t" r "\t" $0}' "$log" >>"$runs"
    done
  done
done

# --- table ------------------------------------------------------------------------------
times >"$scratch/logs/cpu-after"
cpu_runs=$(( $(child_cpu "$scratch/logs/cpu-after") - $(child_cpu "$scratch/logs/cpu-before") ))
table="$scratch/table.md"
old_s="$(git -C "$repo" rev-parse --short "$old_c")"
new_s="$(git -C "$repo" rev-parse --short "$new_c")"
{
  echo "Side by side: old $old_s, new $new_s (bench/ of $(git -C "$repo" rev-parse --short "$from_c")), $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg),"
  echo "clock $clock, second thread count $threads, $rounds rounds ($([ "$full" = 1 ] && echo full sizes || echo default sizes)), best of the rounds;"
  echo "$(( $(date +%s) - t_start )) s in all, the runs $(( $(date +%s) - t_runs )) s using $cpu_runs s of CPU (on an idle machine the runs take about that, less the threaded passes' overlap)."
  echo
  echo "| figure | old (best) | new (best) | new/old | medians | within |"
  echo "| --- | --- | --- | --- | --- | --- |"
  awk -F'\t' -v clock="$clock" '
    function fmt(v, u) {
      if (u == "s") return v >= 1 ? sprintf("%.3f s", v) : sprintf("%.3f ms", 1e3 * v)
      return sprintf("%.0f %s", v, u)
    }
    function median(side, k,    m, i, j, a, t) {  # of the values of figure k on one side
      m = cnt[side, k]
      for (i = 1; i <= m; ++i) a[i] = val[side, k, i]
      for (i = 2; i <= m; ++i) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; --j) a[j + 1] = a[j]; a[j + 1] = t }
      return m % 2 ? a[(m + 1) / 2] : 0.5 * (a[m / 2] + a[m / 2 + 1])
    }
    {
      key = $3
      if (!(key in unit)) { order[++n] = key; unit[key] = $5 }
      v = $4 + 0
      val[$1, key, ++cnt[$1, key]] = v
      if ($1 == "old") { if (!(key in old) || v < old[key]) old[key] = v }
      else { if (!(key in nw) || v < nw[key]) nw[key] = v }
    }
    END {
      beyond = 0; within = 0; refs = ""
      for (i = 1; i <= n; ++i) {
        k = order[i]
        if (!(k in old) || !(k in nw)) { printf("| %s | %s | %s | - | - | only one side |\n", k, (k in old) ? fmt(old[k], unit[k]) : "-", (k in nw) ? fmt(nw[k], unit[k]) : "-"); continue }
        mo = median("old", k)
        mratio = mo > 0 ? median("new", k) / mo : 1
        ratio = old[k] > 0 ? nw[k] / old[k] : 1
        bound = (k ~ /^dambreak/) ? 1.10 : 1.05
        if (k ~ /^reference/) verdict = "(reference: noise)"
        else if (clock == "cpu" && k ~ /^mpi_weak/) verdict = "(not judged: MPI_Wtime, wall clock)"
        else {
          verdict = ratio <= bound ? "yes" : sprintf("**no** (> %d %%)", 100 * (bound - 1) + 0.5)
          if (ratio <= bound) ++within; else { ++beyond; bad = bad "\n  " k sprintf(" %.3f", ratio) }
          if (clock == "cpu" && k ~ /(all threads|[0-9] threads|second count)/) verdict = verdict ", CPU time of all threads"
        }
        printf("| %s | %s | %s | %.3f | %.3f | %s |\n", k, fmt(old[k], unit[k]), fmt(nw[k], unit[k]), ratio, mratio, verdict)
      }
      printf("\n%d figures within their bounds, %d beyond.\n", within, beyond)
      if (beyond) printf("Beyond:%s\n", bad) > "/dev/stderr"
      exit beyond ? 3 : 0
    }' "$runs" && status=0 || status=$?
  [ -n "$skipped" ] && echo "Skipped: $skipped."
  echo "Logs: $scratch/logs (one file per run; the TSV lines are the figures)."
} >"$table" || status=$?
cat "$table"
[ -n "$out" ] && cp "$table" "$out"
exit "${status:-0}"
}
