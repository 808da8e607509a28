#!/usr/bin/env bash
# Regenerates the VCD seeds of `slotforge-fuzz vcd` from real waveforms
# written by `slotforge sim` (model back end).  `<mix>__<window>.vcd` is
# checked against `<mix>.toml` (looked up in mixes/, testkit/mixes).
# Usage: fuzz/seeds/make-vcd-seeds.sh [path/to/slotforge]
set -euo pipefail
cd "$(dirname "$0")/../.."
SF=${1:-target/release/slotforge}
OUT=fuzz/seeds/vcd
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
mkdir -p "$OUT"

# tiny: one whole 4000-cycle frame, clk dumped.
"$SF" sim testkit/mixes/tiny.toml --backend model --frames 1 --vcd "$TMP/tiny.vcd" >/dev/null
cp "$TMP/tiny.vcd" "$OUT/tiny__frame0.vcd"

# tiny without clk: the reader infers the clock from output changes.
clk=$(awk '$1=="$var" && $5=="clk" {print $4; exit}' "$TMP/tiny.vcd")
awk -v id="$clk" '!($1=="$var" && $4==id) && $0!=("0" id) && $0!=("1" id)' "$TMP/tiny.vcd" \
  > "$OUT/tiny__frame0-noclk.vcd"

# eskin34: the first ~100 kB of frame 0 (a few thousand cycles), cut before a timestamp.
"$SF" sim mixes/eskin34.toml --backend model --frames 1 --vcd "$TMP/eskin34.vcd" >/dev/null
awk 'BEGIN{n=0} /^#/ && n>100000 {exit} {print; n+=length($0)+1}' "$TMP/eskin34.vcd" \
  > "$OUT/eskin34__head100k.vcd"

wc -c "$OUT"/*.vcd
