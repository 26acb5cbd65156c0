#!/usr/bin/env bash
# Lint every synthesizable RTL file: `verilator --lint-only -Wall` (the file as top,
# submodules found in rtl/ by name) and an Icarus Verilog-2005 parse.  Waivers live in
# the RTL as `/* verilator lint_off RULE */` with a comment saying why.
set -euo pipefail
cd "$(dirname "$0")/.."
fail=0
shopt -s nullglob
files=(rtl/*.v)
if [ ${#files[@]} -eq 0 ]; then echo "lint: no RTL files"; exit 1; fi
for f in "${files[@]}"; do
  top=$(basename "$f" .v)
  if ! out=$(verilator --lint-only -Wall -Irtl -y rtl --top-module "$top" "$f" 2>&1); then
    echo "verilator lint FAILED: $f"; echo "$out"; fail=1
  fi
  if ! out=$(iverilog -g2005 -Irtl -yrtl -s "$top" -o /dev/null "$f" 2>&1) || [ -n "$out" ]; then
    echo "iverilog parse FAILED: $f"; echo "$out"; fail=1
  fi
done
# generated files must match their sources
if ! out=$(python -m fmt.regmap --check 2>&1); then
  echo "register map: generated files are stale (python -m fmt.regmap --write)"; echo "$out"; fail=1
fi
if [ $fail -ne 0 ]; then exit 1; fi
echo "lint: ${#files[@]} RTL files clean (verilator -Wall, iverilog -g2005)"
