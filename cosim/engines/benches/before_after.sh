#!/usr/bin/env bash
# Simulation speed of the emitted gateware against an earlier commit's, side by
# side in one run (`make bench-before`; docs/performance.md, "Co-simulation
# engines"). The default BASE is the last commit before the lean gateware.
#
#   bash cosim/engines/benches/before_after.sh [BASE] [FRAMES] [ROUNDS]
#
# Builds `cargo bench -p engines --bench cosim` at BASE (a temporary git
# worktree with a target directory of its own: cargo would take the one
# build for the other, their paths inside the workspace being the same) and
# at the working tree,
# runs the two alternately ROUNDS times on FRAMES frames of eskin34, and
# prints each round's throughputs and their ratios (now / BASE) with the
# median over the rounds. The unchecked figures are the gateware's own
# speed; the checked ones include the judge's changes between the commits.
set -euo pipefail

BASE=${1:-cc7b699}
FRAMES=${2:-5}
ROUNDS=${3:-3}
root=$(git rev-parse --show-toplevel)
target=${CARGO_TARGET_DIR:-$root/target}
tmp=$(mktemp -d)
wt=$tmp/base
git -C "$root" worktree add --detach -q "$wt" "$BASE"
trap 'git -C "$root" worktree remove --force "$wt"; rm -rf "$tmp"' EXIT

# The bench executable cargo builds in directory $1 into target directory
# $3, copied to $2.
bench_exe() {
  local exe
  exe=$( (cd "$1" && CARGO_TARGET_DIR=$3 cargo bench --locked -p engines --bench cosim --no-run 2>&1) |
    sed -n 's/.*Executable .*(\(.*\))$/\1/p' | tail -1)
  [ -x "$exe" ] || { echo "the bench did not build in $1" >&2; exit 1; }
  cp "$exe" "$2"
}
now_exe=$tmp/cosim-now
base_exe=$tmp/cosim-base
bench_exe "$root" "$now_exe" "$target"
bench_exe "$wt" "$base_exe" "$target/before-bench"

# "verilator checked unchecked rusthdl-checked rusthdl-unchecked" (Mcycles/s)
# from one run of the bench executable $1 in directory $2.
rates() {
  (cd "$2" && "$1" "$FRAMES") | awk '
    /^verilator: checked/ { vc = $3; vu = $6 }
    /^rusthdl: checked/   { rc = $3; ru = $7 }
    END { if (vc == "" || rc == "") exit 1; print vc, vu, rc, ru }'
}

echo "eskin34, $FRAMES frames (rusthdl: $(( FRAMES / 5 > 0 ? FRAMES / 5 : 1 ))), $ROUNDS rounds; now = $(git -C "$root" rev-parse --short HEAD) (working tree), base = $BASE"
echo "round  verilator checked/unchecked Mcycles/s now | base   rusthdl checked/RtlSim unchecked now | base"
ratios=()
for r in $(seq 1 "$ROUNDS"); do
  read -r nvc nvu nrc nru < <(rates "$now_exe" "$root/cosim/engines")
  read -r bvc bvu brc bru < <(rates "$base_exe" "$wt/cosim/engines")
  [ -n "$nvc" ] && [ -n "$bvc" ] || { echo "a bench run failed" >&2; exit 1; }
  echo "$r      $nvc/$nvu | $bvc/$bvu      $nrc/$nru | $brc/$bru"
  ratios+=("$(awk -v a="$nvc" -v b="$bvc" -v c="$nvu" -v d="$bvu" -v e="$nrc" -v f="$brc" -v g="$nru" -v h="$bru" \
    'BEGIN { printf "%.3f %.3f %.3f %.3f", a/b, c/d, e/f, g/h }')")
done
printf '%s\n' "${ratios[@]}" | python3 -c '
import statistics, sys
rows = [list(map(float, l.split())) for l in sys.stdin if l.strip()]
names = ["verilator checked", "verilator unchecked", "rusthdl checked", "RtlSim unchecked"]
for i, name in enumerate(names):
    print(f"{name}: now / base {statistics.median(r[i] for r in rows):.2f}x (median of {len(rows)} rounds)")
'
