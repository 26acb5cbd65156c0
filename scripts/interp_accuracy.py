#!/usr/bin/env python3
"""Accuracy of the fine-touch fits (fmt.interp) against the scene's true positions.

Contacts of the disk profile (paper Eq. 2, touched area) and of the Gaussian profile
(fmt.sensor) at random sub-cell positions inside the MEDIUM sensor (>= 2 cells from the
edges), heat map z = round(SCALE * (coupling + noise)), noise N(0, sigma) per cell with
sigma = (peak cell of a centred 8 mm disk finger) / 10^(snr/20), the definition of
fmt.channel.noise_sigma_for_snr (30 dB per window at M = 1).  The candidate
is the 3x3 around the strongest cell.  Reports the RMS position error in mm (pitch 5 mm)
of both fits, float and fixed, with and without bias correction, and the angle error of
elliptical contacts (Moore fit).

    python scripts/interp_accuracy.py [--n 2000] [--seed 1]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))
from fmt import interp, params, sensor  # noqa: E402
from fmt.localmax import Candidate, neighbourhood3x3  # noqa: E402

SCALE = 4096


def peak_coupling(cfg, diameter=8.0):
    """Peak-cell coupling of a centred disk finger (the noise reference, as channel.py)."""
    r, c = cfg.rows // 2, cfg.cols // 2
    return float(sensor.contact_map(cfg, [(c * cfg.pitch_mm, r * cfg.pitch_mm, diameter, 1.0)])[r, c])


def make_cands(cfg, ct, profile, snr_db, rng):
    maps = sensor.contact_maps(cfg, ct, profile=profile)
    if snr_db is not None:
        maps = maps + rng.normal(0, peak_coupling(cfg) / 10 ** (snr_db / 20), maps.shape)
    z = np.clip(np.round(maps * SCALE), 0, (1 << cfg.hm_width) - 1).astype(np.int64)
    out = []
    for k in range(z.shape[0]):
        r, c = np.unravel_index(int(np.argmax(z[k])), z[k].shape)
        z3, miss = neighbourhood3x3(z[k], int(r), int(c))
        out.append(Candidate(int(r), int(c), z3, miss))
    return out


def position_table(cfg, n, seed, diameter=8.0):
    rng = np.random.default_rng(seed)
    p = cfg.pitch_mm
    xs = rng.uniform(2, cfg.cols - 3, n) * p
    ys = rng.uniform(2, cfg.rows - 3, n) * p
    ct = np.stack([xs, ys, np.full(n, diameter), np.ones(n)], axis=1)
    rows = []
    for profile in sensor.PROFILES:
        for snr in (None, 30.0):
            cands = make_cands(cfg, ct, profile, snr, rng)
            for moore in (False, True):
                for bias in (False, True):
                    res = {}
                    for kind, fn, sc in (("float", interp.interp_float, 1.0),
                                         ("fixed", interp.interp_fixed, 256.0)):
                        tp = [fn(c, cfg, moore=moore, bias=bias) for c in cands]
                        ex = np.array([t.x / sc for t in tp]) * p - xs
                        ey = np.array([t.y / sc for t in tp]) * p - ys
                        res[kind] = math.sqrt(np.mean(ex ** 2 + ey ** 2))
                    rows.append((profile, "noiseless" if snr is None else f"{snr:.0f} dB",
                                 "moore" if moore else "vn", "on" if bias else "off",
                                 res["float"], res["fixed"]))
    return rows


def angle_table(cfg, n, seed, major=14.0, minor=7.0):
    rng = np.random.default_rng(seed + 1)
    p = cfg.pitch_mm
    xs = rng.uniform(2, cfg.cols - 3, n) * p
    ys = rng.uniform(2, cfg.rows - 3, n) * p
    th = rng.uniform(0, math.pi, n)
    ct = np.stack([xs, ys, np.full(n, major), np.ones(n), np.full(n, minor), th], axis=1)
    rows = []
    for profile in sensor.PROFILES:
        for snr in (None, 30.0):
            cands = make_cands(cfg, ct, profile, snr, rng)
            fl = [interp.interp_float(c, cfg, moore=True) for c in cands]
            fx = [interp.interp_fixed(c, cfg, moore=True) for c in cands]
            def err(a):
                d = (np.asarray(a) - th + math.pi / 2) % math.pi - math.pi / 2
                return math.degrees(math.sqrt(np.mean(d ** 2))), math.degrees(np.max(np.abs(d)))
            ef = err([t.angle for t in fl])
            ex = err([t.angle * math.pi / 256 for t in fx])
            ratio = np.mean([t.axis_major / max(t.axis_minor, 1e-9) for t in fl if t.axis_minor > 0])
            rows.append((f"{major:g} x {minor:g} mm", profile,
                         "noiseless" if snr is None else f"{snr:.0f} dB", ef, ex, ratio))
    return rows


def edge_table_rows(cfg, n, seed, diameter=8.0):
    """Contacts centred in the first column's cells (x in [-2.5, 2.5] mm, the left half
    over the sensor's border strip), rows inside: RMS / max x error, fixed model."""
    rng = np.random.default_rng(seed + 2)
    p = cfg.pitch_mm
    xs = rng.uniform(-0.5, 0.5, n) * p
    ys = rng.uniform(2, cfg.rows - 3, n) * p
    ct = np.stack([xs, ys, np.full(n, diameter), np.ones(n)], axis=1)
    rows = []
    for profile in sensor.PROFILES:
        for snr in (None, 30.0):
            cands = make_cands(cfg, ct, profile, snr, rng)
            tp = [interp.interp_fixed(c, cfg, moore=True) for c in cands]
            ex = np.array([t.x / 256 for t in tp]) * p - xs
            inner = xs >= 0
            rows.append((profile, "noiseless" if snr is None else f"{snr:.0f} dB",
                         math.sqrt(np.mean(ex ** 2)), np.max(np.abs(ex)),
                         math.sqrt(np.mean(ex[inner] ** 2)), np.max(np.abs(ex[inner]))))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args(argv)
    cfg = params.MEDIUM
    print(f"RMS position error (mm), 8 mm contacts, {a.n} random positions, pitch {cfg.pitch_mm} mm")
    print("| profile | noise | fit | bias corr. | float | fixed |")
    print("|---|---|---|---|---|---|")
    for r in position_table(cfg, a.n, a.seed):
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | {r[4]:.3f} | {r[5]:.3f} |")
    print()
    print(f"Angle error (deg) of elliptical contacts at random angles, Moore fit, {a.n} contacts each")
    print("| contact | profile | noise | float RMS | float max | fixed RMS | fixed max | mean axis ratio (float) |")
    print("|---|---|---|---|---|---|---|---|")
    for major, minor in ((14.0, 7.0), (20.0, 10.0)):
        for r in angle_table(cfg, a.n, a.seed, major, minor):
            print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3][0]:.2f} | {r[3][1]:.2f} | {r[4][0]:.2f} | "
                  f"{r[4][1]:.2f} | {r[5]:.2f} |")
    print()
    print(f"Edge column (one-sided estimate along x), {a.n} contacts, x error in mm")
    print("| profile | noise | RMS, x in [-2.5, 2.5] | max | RMS, x in [0, 2.5] (inner half) | max |")
    print("|---|---|---|---|---|---|")
    for r in edge_table_rows(cfg, a.n, a.seed):
        print(f"| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]:.2f} | {r[4]:.2f} | {r[5]:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
