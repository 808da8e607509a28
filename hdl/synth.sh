#!/usr/bin/env bash
# Synthesize and place-and-route the gateware of a mix for an iCE40-HX8K
# (ct256) and print logic cells and Fmax.
#
#   hdl/synth.sh [MIX.toml ...]      (default: mixes/*.toml hdl/tests/data/*.toml)
#
# Uses: cargo (emits the Verilog through hdl::emit), yosys, nextpnr-ice40.
# Work files go to target/synth/<mix>/.
set -euo pipefail
cd "$(dirname "$0")/.."
for t in yosys nextpnr-ice40; do
  command -v "$t" >/dev/null || { echo "synth.sh: $t is not installed (make installs it)" >&2; exit 2; }
done
mixes=("$@")
[ ${#mixes[@]} -gt 0 ] || mixes=(mixes/*.toml hdl/tests/data/*.toml)
board=constraints/ice40-hx8k-breakout.toml
cargo build -q -p hdl --example emit
printf '%-12s %10s %6s %6s %6s %10s %10s %s\n' mix clock_MHz LCs LUT4 DFF BRAM Fmax_MHz "Fmax/clock"
for mix in "${mixes[@]}"; do
  name=$(basename "$mix" .toml)
  out=target/synth/$name
  rm -rf "$out"; mkdir -p "$out"
  "${CARGO_TARGET_DIR:-target}/debug/examples/emit" "$mix" "$out" "$board"
  clock_hz=$(sed -n 's/.*"clock_hz": \([0-9]*\).*/\1/p' "$out/ports.json")
  clock_mhz=$(awk -v h="$clock_hz" 'BEGIN{printf "%.3f", h/1e6}')
  (cd "$out" && yosys -q -l yosys.log -p "read_verilog slotforge_top.v; synth_ice40 -top slotforge_top -json slotforge.json; check -assert; tee -q -o stat.txt stat" >/dev/null)
  (cd "$out" && nextpnr-ice40 --hx8k --package ct256 --json slotforge.json --pcf slotforge.pcf \
      --freq "$clock_mhz" --seed 1 --asc slotforge.asc --report report.json >nextpnr.log 2>&1) \
    || { echo "nextpnr failed for $name, see $out/nextpnr.log" >&2; tail -20 "$out/nextpnr.log" >&2; exit 1; }
  lcs=$(sed -n 's/.*ICESTORM_LC: *\([0-9]*\)\/.*/\1/p' "$out/nextpnr.log" | tail -1)
  bram=$(sed -n 's/.*ICESTORM_RAM: *\([0-9]*\)\/.*/\1/p' "$out/nextpnr.log" | tail -1)
  lut=$(awk '/SB_LUT4/{print $2}' "$out/stat.txt" | tail -1)
  dff=$(awk '/SB_DFF/{s+=$2} END{print s+0}' "$out/stat.txt")
  fmax=$(grep "Max frequency for clock" "$out/nextpnr.log" | tail -1 | sed -n 's/.*: \([0-9.]*\) MHz.*/\1/p')
  ratio=$(awk -v f="$fmax" -v c="$clock_mhz" 'BEGIN{printf "%.2f", f/c}')
  printf "%-12s %10s %6s %6s %6s %10s %10s %s\n" "$name" "$clock_mhz" "$lcs" "$lut" "$dff" "$bram" "$fmax" "$ratio"
done
