#!/usr/bin/env bash
# Synthesize and place-and-route the gateware of a mix for an iCE40-HX8K
# (ct256) and print logic cells and Fmax.
#
#   hdl/synth.sh [MIX.toml ...]      (default: mixes/*.toml hdl/tests/data/*.toml)
#
# The flow itself (yosys synth_ice40, nextpnr-ice40 with the board's pins) is
# measure::place_and_route, the same one `slotforge build` runs; this
# script only loops over mixes.  Work files go to target/synth/<mix>/.
set -euo pipefail
# mixes named on the command line are the caller's paths: made absolute
# before the script moves to the repository root
mixes=()
for m in "$@"; do mixes+=("$(realpath "$m")"); done
cd "$(dirname "$0")/.."
for t in yosys nextpnr-ice40; do
  command -v "$t" >/dev/null || { echo "synth.sh: $t is not installed (make installs it)" >&2; exit 2; }
done
[ ${#mixes[@]} -gt 0 ] || mixes=(mixes/*.toml hdl/tests/data/*.toml)
board=constraints/ice40-hx8k-breakout.toml
cargo build -q -p measure --example synth
printf '%-12s %10s %6s %6s %6s %10s %10s %s\n' mix clock_MHz LCs LUT4 DFF BRAM Fmax_MHz "Fmax/clock"
for mix in "${mixes[@]}"; do
  name=$(basename "$mix" .toml)
  out=target/synth/$name
  rm -rf "$out"; mkdir -p "$out"
  "${CARGO_TARGET_DIR:-target}/debug/examples/synth" "$mix" "$out" "$board"
done
