#!/usr/bin/env python3
"""Ghost contacts in fast alternating taps (issue #11 item 4), through the fixed-point model.

Two 8 mm fingers A and B, `spacing` mm apart (along x, or at 34 degrees), tap in turn: A
down for `on` frames, then `off` frames with neither, then B, ...; each landing and lift
falls inside a window (31 and 57 samples further each tap), so the transition frames
carry the spectral leakage of a half-window tone.  Counted per scene by `fmt.run_sim`'s
evaluation: ghosts (reported contacts matched to no finger, with their frames), ID
swaps, lost IDs and missed finger-frames, at 30 dB per window, M = 1.

    python scripts/tap_ghosts.py [--spacings 8 10 ...] [--seeds 1 2] [--settings FILE]
    python scripts/tap_ghosts.py --finger-peaks

Prints one line per scene and a total; exits 1 if any scene has a ghost or a swap.
--finger-peaks prints instead the peak strength range (the tracker's touch strength) of
a 6 mm and an 8 mm finger sliding 400 frames across a cell diagonal (every sub-cell
position) at 30 dB: the weakest finger an activation threshold must still let in.
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "sim"))

from fmt import params, run_sim  # noqa: E402
from fmt import settings as _settings  # noqa: E402
from fmt.scene import Contact, Scene  # noqa: E402

TIMINGS = ((20, 20), (20, 0), (40, 3))          # (on, off) frames
ANGLES = (0.0, 0.6)                            # radians


def taps_scene(spacing_mm: float, on: int, off: int, angle: float, seed: int, taps: int = 4,
               snr_db: float = 30.0) -> Scene:
    cfg = params.DEFAULT
    f = lambda k: k * cfg.window_s
    x0, y0 = 80.0, 70.0
    xb, yb = x0 + spacing_mm * math.cos(angle), y0 + spacing_mm * math.sin(angle)
    rep = lambda first, step: {"repeat": {"first_s": f(first), "period_s": f(2 * (on + off)),
                                          "on_s": f(on), "count": taps, "step_samples": step}}
    return Scene(name=f"taps_{spacing_mm:g}mm_{on}_{off}_{angle:g}_{seed}", sensor="default",
                 frames=2 * (on + off) * taps + 40, seed=seed,
                 effects={"noise": {"snr_db": snr_db}, "pn": {"enable": True, "chip_len": 1}},
                 contacts=[Contact(name="A", path=[[0.0, x0, y0]], active=rep(10, 31)),
                           Contact(name="B", path=[[0.0, xb, yb]], active=rep(10 + on + off, 57))])


def run(spacings, seeds, settings=None, timings=TIMINGS, angles=ANGLES, quiet=False) -> dict:
    tot = {"scenes": 0, "ghosts": 0, "swaps": 0, "lost": 0, "missed": 0}
    for sp in spacings:
        for on, off in timings:
            for ang in angles:
                for seed in seeds:
                    rep = run_sim.run(taps_scene(sp, on, off, ang, seed), settings=settings,
                                      quiet=True, plot=False)
                    tr = rep["tracking"]
                    tot["scenes"] += 1
                    tot["ghosts"] += tr["ghosts"]
                    tot["swaps"] += tr["id_swaps"]
                    tot["lost"] += tr["ids_lost"]
                    tot["missed"] += rep["missed"]
                    if not quiet:
                        print(f"{sp:5g} mm  on {on:2d} off {off:2d}  angle {ang:3.1f}  seed {seed}:  "
                              f"ghosts {tr['ghosts']} {tr['ghost_frames'][:6]}  swaps {tr['id_swaps']}  "
                              f"lost {tr['ids_lost']}  missed {rep['missed']}", flush=True)
    return tot


def finger_peaks(diameter_mm: float, snr_db: float = 30.0, frames: int = 400) -> list:
    """Per frame, the strongest fine touch's strength of one finger sliding diagonally
    across a cell (80, 70) -> (85, 75) mm, through the signal chain and the fixed-point
    touch pipeline (calibrated like fmt.run_sim)."""
    import numpy as np
    from fmt import chain, touch
    cfg = params.DEFAULT
    sc = Scene(name=f"peak{diameter_mm:g}", sensor="default", frames=frames, seed=3,
               effects={"noise": {"snr_db": snr_db}, "pn": {"enable": True, "chip_len": 1}},
               contacts=[Contact(name="A", diameter_mm=diameter_mm,
                                 path=[[0.0, 80.0, 70.0], [frames * cfg.window_s, 85.0, 75.0]])])
    res = chain.heatmaps_float(sc)
    pp = touch.TouchPipeline(cfg, _settings.TouchSettings(), fixed=True,
                             flatten_cal=run_sim.calibration(sc, mode="noiseless"),   # as measured
                             frame_period_s=sc.frame_period_s)
    flat = pp.flatten(np.rint(res.heatmaps).astype(np.int64))
    return [max([t.strength for t in pp.touches(flat[k], k)[0]], default=0)
            for k in range(flat.shape[0])]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacings", type=float, nargs="+", default=[8, 10, 12, 15, 20, 25, 30])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--settings", default=None, help="TouchSettings JSON (default: the defaults)")
    ap.add_argument("--finger-peaks", action="store_true",
                    help="print the peak strength range of a 6 mm and an 8 mm finger instead")
    a = ap.parse_args(argv)
    if a.finger_peaks:
        for d in (6.0, 8.0):
            v = sorted(finger_peaks(d))
            print(f"{d:g} mm finger, 30 dB: peak strength min {v[0]}, 1st percentile "
                  f"{v[len(v) // 100]}, median {v[len(v) // 2]}, max {v[-1]}")
        return 0
    try:
        st = _settings.load(a.settings) if a.settings else None
    except Exception as e:  # one line, non-zero exit
        print(f"tap_ghosts: {e}", file=sys.stderr)
        return 2
    tot = run(a.spacings, a.seeds, st)
    print(f"total: {tot['scenes']} scenes, ghost frames {tot['ghosts']}, swaps {tot['swaps']}, "
          f"lost IDs {tot['lost']}, missed finger-frames {tot['missed']}")
    return 1 if tot["ghosts"] or tot["swaps"] else 0


if __name__ == "__main__":
    sys.exit(main())
