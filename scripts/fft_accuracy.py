#!/usr/bin/env python3
"""Accuracy of the fixed-point FFT (sim/fmt/fft_r22sdf.py = rtl/fmt_fft_r22sdf.v bit for
bit) against a floating-point FFT of the SAME integer samples, per N.

SQNR = 10 log10(sum |X_float|^2 / sum |X_fixed - X_float|^2), X_float scaled by 2^-SHIFT
like the RTL output.  Signals (13-bit despread samples, both quadratures, as the
receiver pairs two real columns):
  comb      30 tones (fewer where N cannot hold 30: bins lo .. 2 lo - 1 below N/2),
            lo = 33 N / 256 (bins 33..62 at N = 256), random phases, 98 % of full scale;
            SQNR over the tone bins k and N - k; mean and worst over --seeds seeds
  in-phase  the same comb with every tone at phase 0 (worst crest factor), tone bins
  noise     uniform full-scale complex noise, all bins

    python scripts/fft_accuracy.py [--seeds 20] [--frac-w 3] [--tw-w 18] [--sweep]
--sweep prints the comb SQNR at N = 256 against FRAC_W and TW_W (the design choice).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))
from fmt import fft_r22sdf as F  # noqa: E402

IN_W = 13


def comb_bins(log2_n: int) -> list[int]:
    n = 1 << log2_n
    lo = round(33 * n / 256)
    rows = min(30, lo, n // 2 - lo)
    return list(range(lo, lo + rows))


def comb_sqnr(log2_n, bins, seed, tw_w, frac_w, in_phase=False, windows=4):
    n = 1 << log2_n
    xr, xi = F.comb_input(log2_n, bins, IN_W, windows=windows, seed=seed, in_phase=in_phase)
    yr, yi, ovf = F.fft_fixed(xr, xi, log2_n, IN_W, tw_w=tw_w, frac_w=frac_w)
    ref = F.fft_float(xr, xi, log2_n, IN_W, frac_w=frac_w)
    b = list(bins) + [n - k for k in bins]
    return F.sqnr_db(ref[:, b], (yr + 1j * yi)[:, b]), ovf


def noise_sqnr(log2_n, seed, tw_w, frac_w, windows=4):
    n = 1 << log2_n
    rng = np.random.default_rng(seed)
    lo, hi = -(1 << (IN_W - 1)), 1 << (IN_W - 1)
    xr, xi = rng.integers(lo, hi, (windows, n)), rng.integers(lo, hi, (windows, n))
    yr, yi, ovf = F.fft_fixed(xr, xi, log2_n, IN_W, tw_w=tw_w, frac_w=frac_w)
    ref = F.fft_float(xr, xi, log2_n, IN_W, frac_w=frac_w)
    return F.sqnr_db(ref, yr + 1j * yi), ovf


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--frac-w", type=int, default=F.FRAC_W)
    ap.add_argument("--tw-w", type=int, default=F.TW_W)
    ap.add_argument("--sweep", action="store_true")
    a = ap.parse_args(argv)
    print(f"fft_fixed accuracy: IN_W = {IN_W}, TW_W = {a.tw_w}, FRAC_W = {a.frac_w}, "
          f"{a.seeds} seeds x 4 windows")
    print(f"{'N':>5s} {'OUT_W':>5s} {'SHIFT':>5s} {'lat0':>4s} {'comb bins':>10s} "
          f"{'comb mean':>9s} {'comb worst':>10s} {'in-phase':>8s} {'noise mean':>10s} "
          f"{'noise worst':>11s} ovf")
    worst_all = np.inf
    for log2_n in range(6, 11):
        bins = comb_bins(log2_n)
        c = [comb_sqnr(log2_n, bins, s, a.tw_w, a.frac_w) for s in range(a.seeds)]
        p = comb_sqnr(log2_n, bins, 0, a.tw_w, a.frac_w, in_phase=True)
        z = [noise_sqnr(log2_n, s, a.tw_w, a.frac_w) for s in range(a.seeds)]
        cs = np.array([v for v, _ in c])
        zs = np.array([v for v, _ in z])
        ovf = any(o for _, o in c) or p[1] or any(o for _, o in z)
        worst_all = min(worst_all, cs.min())
        print(f"{1 << log2_n:5d} {F.full_width(log2_n, IN_W, a.frac_w):5d} "
              f"{F.out_shift(log2_n, IN_W, None, a.frac_w):5d} {F.latency0(log2_n):4d} "
              f"{bins[0]:4d}..{bins[-1]:<4d} {cs.mean():9.2f} {cs.min():10.2f} {p[0]:8.2f} "
              f"{zs.mean():10.2f} {zs.min():11.2f} {int(ovf)}")
    print(f"worst comb SQNR over all N: {worst_all:.2f} dB (target >= 90 dB)")
    if a.sweep:
        print("\ncomb SQNR at N = 256 (mean over seeds) vs FRAC_W (rows) and TW_W (columns)")
        tws = (14, 16, 18, 20)
        print("FRAC_W " + " ".join(f"TW_W={t:<3d}" for t in tws))
        for fw in range(0, 6):
            row = []
            for tw in tws:
                v = np.mean([comb_sqnr(8, comb_bins(8), s, tw, fw)[0] for s in range(min(a.seeds, 8))])
                row.append(f"{v:8.2f}")
            print(f"{fw:6d} " + " ".join(row))
    return 0


if __name__ == "__main__":
    sys.exit(main())
