#!/usr/bin/env python3
"""DDS spectral purity measured from the RTL (fmt_dds_bank simulated by cocotb).

For each table width SINE_BITS it simulates the bank at a sensor size with the reset
(exact-bin) comb, PN off, captures three N-sample windows, checks that they are
identical and bit-exact with the model, and prints:
  - row: worst spur of any single row's window (rectangular FFT, all non-tone bins
    but DC) relative to its tone, dBc;
  - comb: sum of all rows, worst non-comb bin relative to the weakest comb tone, dBc.
Table-width rows use DAC_BITS = SINE_BITS + AMP_BITS (the table's own purity: the
amplitude product is exact); the last row is the default build (16-bit table, 12-bit
DAC words), where the DAC word's rounding dominates.

    python scripts/dds_purity.py [--cfg default] [--sim icarus] [--bits 10 12 14 16] [--rpe 3]
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "sim"), str(ROOT / "tb")]

from fmt import dds_bank, params  # noqa: E402
from fmt_dds_bank.dds_driver import run  # noqa: E402


def measure(sim: str, cfg, sine_bits: int, dac_bits: int, rpe: int = 1) -> dict:
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "purity.json"
        import os
        os.environ["DDS_PURITY_OUT"] = str(out)
        try:
            run(sim, cfg, sine_bits=sine_bits, dac_bits=dac_bits, testcase="exact_comb_and_purity",
                rpe=rpe)
        finally:
            del os.environ["DDS_PURITY_OUT"]
        return json.loads(out.read_text())


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cfg", default="default", help="sensor config (default, medium, small)")
    ap.add_argument("--sim", default="icarus", choices=["icarus", "verilator"])
    ap.add_argument("--bits", type=int, nargs="*", default=[10, 12, 14, 16])
    ap.add_argument("--rpe", type=int, default=1,
                    help="ROWS_PER_ENGINE of the simulated bank (ce every RPE clk; same words)")
    a = ap.parse_args(argv)
    cfg = params.get(a.cfg)
    runs = [(b, b + cfg.amp_bits) for b in a.bits] + [(cfg.sine_bits, cfg.dac_bits)]
    rows = []
    for s_bits, d_bits in runs:
        if (dds_bank.TABLE_ADDR, s_bits) not in dds_bank.HEX_TABLES:
            print(f"no committed table for SINE_BITS {s_bits}; skipped", file=sys.stderr)
            continue
        rows.append(measure(a.sim, cfg, s_bits, d_bits, a.rpe))
    print(f"\nDDS purity from the RTL ({a.sim}), sensor '{cfg.name}': {cfg.rows} rows, N = {cfg.n_fft}, "
          f"bins {cfg.bin_lo}..{cfg.bin_hi}, table 2^{dds_bank.TABLE_ADDR} entries, full amplitude, PN off")
    print("| SINE_BITS | DAC_BITS | worst row spur (dBc) | bound -6B | comb: worst non-comb bin (dBc) "
          "| bound -6B+10log10(rows) | max abs(rtl - float) (LSB) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['sine_bits']} | {r['dac_bits']} | {r['row_spur_dbc']:.1f} | {r['row_bound_dbc']:.0f} "
              f"| {r['comb_spur_dbc']:.1f} (bin {r['comb_spur_bin']}) | {r['comb_bound_dbc']:.1f} "
              f"| {r['max_err_lsb']:.3f} (bound {r['err_bound_lsb']:.3f}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
