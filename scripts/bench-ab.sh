#!/usr/bin/env bash
# One bench/ workload of two commits in one process: scripts/bench-ab.sh [options] OLD NEW CASE...
#
# For judging a few figures on a shared machine, where scripts/bench-compare.sh's whole
# programs, minutes apart, see different loads. The libraries are bench-compare's builds
# (scripts/bench-compare.sh --build-only, same scratch directory); scripts/bench-ab/case.c
# is compiled against each one's header and linked to it, and scripts/bench-ab/driver.c
# loads both copies into one process (each in its own link-map namespace) and alternates
# single iterations, old, new | new, old | ..., so that the two sides share every moment of
# the machine's load. Prints one markdown row per case: best of each side (ms), best new/old,
# medians and their ratio, the median of the per-round ratios (what a drift of the load
# does not move), minor page faults per iteration of each side.
#
# With --callgrind, instead: valgrind's instruction count of one iteration of each side
# (after an uncounted warm-up; the two run at once), the same on any load: a change of the
# count is a change of the work, and an equal count points at memory, pages or threads.
#
# CASE (one argument each, quoted), the workloads of bench/ at 10^5 particles (case.c):
#   "pairs DIM METHOD THREADS"                       bench_pairs' step
#   "shape DIM METHOD ORDER setup|update THREADS GRADONLY"  bench_shape's setup or update
#   "apply DIM NCOMP THREADS"                        bench_apply's gradient
#   "neighbors DIM first|repeat THREADS"             bench_neighbors' setup of a new set / again
# METHOD: SPH, RL, KB1, MLS, SSPH; ORDER 0 for methods without one; THREADS 0 = all cores.
#
# Options:
#   -k, --rounds N   alternations (default 20)
#   --callgrind      instruction counts instead of times
#   --scratch DIR    bench-compare's scratch directory (default <repository>/build/bench-compare)
# The clock is bench/'s: MFREE_BENCH_CLOCK=cpu for process CPU time (OMP_WAIT_POLICY=passive
# is then set unless set already).
#
# Example:
#   MFREE_BENCH_CLOCK=cpu scripts/bench-ab.sh -k 30 beb1e93 main "pairs 3 MLS 1" "shape 2 MLS 2 update 1 0"
set -euo pipefail
{
die() { echo "bench-ab: $*" >&2; exit 2; }
rounds=20
callgrind=0
scratch=""
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    -k|--rounds) rounds="$2"; shift 2 ;;
    --callgrind) callgrind=1; shift ;;
    --scratch) scratch="$2"; shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | grep -v '^set' | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) die "unknown option $1 (--help)" ;;
    *) args+=("$1"); shift ;;
  esac
done
[[ "$rounds" =~ ^[1-9][0-9]*$ ]] || die "--rounds takes a positive number"
[ ${#args[@]} -ge 3 ] || die "usage: scripts/bench-ab.sh [options] OLD NEW CASE... (--help)"
repo="$(git rev-parse --show-toplevel 2>/dev/null)" || die "run inside the mfree repository"
here="$repo/scripts"
scratch="${scratch:-$repo/build/bench-compare}"
if [ "$callgrind" = 1 ]; then command -v valgrind >/dev/null || die "--callgrind needs valgrind"; fi

# the two libraries (bench-compare's worktrees and builds; -b apply builds one small program)
"$here/bench-compare.sh" --build-only --scratch "$scratch" -b apply "${args[0]}" "${args[1]}"
scratch="$(cd "$scratch" && pwd)"
exec 9>"$scratch/.lock"
flock -n 9 || die "another bench-compare or bench-ab is using $scratch"
ab="$scratch/ab"
mkdir -p "$ab"
for side in old new; do
  wt="$scratch/$side"
  bd="$wt/build/default"
  def=()
  grep -q mfree_context_set_page_hints "$wt/include/mfree.h" && def=(-DMFREE_BENCH_HAVE_PAGE_HINTS)
  ver="$(dirname "$(find "$bd" -name mfree_version.h -print -quit)")"
  # bench/bench_util.h of this checkout on both sides, like case.c
  cc -O2 -fPIC -shared -Wall -Wextra -Werror=implicit-function-declaration "${def[@]}" -I"$repo/bench" -I"$wt/include" -I"$ver" \
     -o "$ab/case-$side.so" "$here/bench-ab/case.c" -L"$bd/src" -lmfree -lm -Wl,-rpath,"$bd/src"
done
cc -O2 -Wall -Wextra -o "$ab/driver" "$here/bench-ab/driver.c" -ldl

old_s="$(git -C "$scratch/old" rev-parse --short HEAD)"
new_s="$(git -C "$scratch/new" rev-parse --short HEAD)"
export MFREE_BENCH_CLOCK="${MFREE_BENCH_CLOCK:-wall}"
if [ "$MFREE_BENCH_CLOCK" = cpu ] && [ -z "${OMP_WAIT_POLICY:-}" ]; then export OMP_WAIT_POLICY=passive; fi
if [ "$callgrind" = 1 ]; then
  echo "Instructions of one iteration (callgrind): old $old_s, new $new_s, $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo
  echo "| case | old | new | new/old |"
  echo "| --- | --- | --- | --- |"
  for c in "${args[@]:2}"; do
    read -r -a cw <<<"$c"
    for side in old new; do
      valgrind --tool=callgrind --toggle-collect=ab_iter --callgrind-out-file="$ab/cg-$side.out" \
        "$ab/driver" "$ab/case-$side.so" 1 "${cw[@]}" >"$ab/cg-$side.log" 2>&1 &
    done
    wait
    # the total from the profile's summary line (an early exit of a reader of
    # callgrind_annotate's output killed it by SIGPIPE, and set -o pipefail the script)
    n_old="$(awk '/^summary:/ {print $2}' "$ab/cg-old.out")"
    n_new="$(awk '/^summary:/ {print $2}' "$ab/cg-new.out")"
    [ -n "$n_old" ] && [ -n "$n_new" ] || die "callgrind failed, see $ab/cg-*.log"
    awk -v c="$c" -v a="$n_old" -v b="$n_new" 'BEGIN { printf("| %s | %.4g | %.4g | %.4f |\n", c, a, b, b / a) }'
  done
else
  echo "One process, $rounds alternations: old $old_s, new $new_s, $(date -u '+%Y-%m-%d %H:%M UTC'), clock $MFREE_BENCH_CLOCK, load $(cut -d' ' -f1-3 /proc/loadavg)"
  echo
  echo "| case | old best ms | new best ms | best new/old | old median | new median | median new/old | per-round ratio, median | faults/iteration old / new |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
  for c in "${args[@]:2}"; do
    read -r -a cw <<<"$c"
    "$ab/driver" "$ab/case-old.so" "$ab/case-new.so" "$rounds" "${cw[@]}" || die "the case '$c' failed"
  done
fi
exit 0
}
