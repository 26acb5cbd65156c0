#!/usr/bin/env python3
"""Crowding above the contact limit (issue #11 item 3), through the fixed-point model.

Three cases per seed, each with N the contact limit (`--limits`, default 16 and 6):

* ``together``: N + 1 fingers land in the same frame;
* ``one_lands``: N fingers, then one more (the largest and strongest of all) lands 150
  frames later among them;
* ``relands``: N fingers lift after 150 frames and N others land elsewhere 5 frames
  later, while the first N are still in hold-off (33 frames): the new ones take the
  slots of the contacts in hold-off.

The fingers sit on a jittered 20 mm grid (random places, 7-10 mm, strength 0.85-1.0,
some drifting at up to 0.2 m/s), 30 dB per window, M = 1.  Counted after the contacts
have settled (the landing frame + 10): frames in which the number of reported contacts
(new or move events) is not N, new IDs, and lifts (``relands``: from 5 frames after
the second landing on, counting the N new IDs and N lifts there as expected).  With
continuing contacts ranked first and hold-off slots given up to new touches, every
count is 0: the same N contacts in every frame.

    python scripts/crowding.py [--seeds 1 2 3] [--limits 16 6] [--frames 400]

Prints one line per scene and a total; exits 1 if any count is not 0.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "sim"))

from fmt import chain, run_sim, touch  # noqa: E402
from fmt import settings as _settings  # noqa: E402
from fmt.scene import LAND, LATE, RELAND, crowd_scene  # noqa: E402


def count(frame_events: list, n: int, settle: int, first: int | None = None) -> dict:
    """Frames (index >= settle) whose reported contacts are not n; new IDs and lifts from
    frame ``first`` (default settle) on."""
    first = settle if first is None else first
    bad = new = lifts = 0
    for k, ev in enumerate(frame_events):
        live = {e.id for e in ev if e.type in ("new", "move")}
        bad += k >= settle and len(live) != n
        new += k >= first and sum(e.type == "new" for e in ev)
        lifts += k >= first and sum(e.type == "lift" for e in ev)
    return {"frames_not_n": bad, "new_ids": new, "lifts": lifts}


def events(sc, st) -> list:
    """Per frame, the fixed-point pipeline's events (calibrated as fmt.run_sim did when the
    figures were measured: noiseless)."""
    res = chain.heatmaps_float(sc)
    return touch.process_frames(np.rint(res.heatmaps).astype(np.int64), sc.cfg, st, fixed=True,
                                flatten_cal=run_sim.calibration(sc, mode="noiseless"),   # as measured
                                frame_period_s=sc.frame_period_s)


def run(seeds, limits, frames: int, quiet: bool = False) -> dict:
    tot = {"scenes": 0, "frames_not_n": 0, "new_ids": 0, "lifts": 0}
    for n in limits:
        st = _settings.TouchSettings(max_touches=n)
        for case in ("together", "one_lands", "relands"):
            for seed in seeds:
                sc = crowd_scene(case, n, seed, frames)
                evs = events(sc, st)
                if case == "relands":
                    settle = LAND + LATE + RELAND + 5
                    c = count(evs, n, settle, LAND + LATE)
                    c["new_ids"] -= n           # the second set's N, and the first set's lifts
                    c["lifts"] -= n
                else:
                    settle = LAND + 10
                    c = count(evs, n, settle)
                tot["scenes"] += 1
                for k in c:
                    tot[k] += c[k]
                if not quiet:
                    print(f"limit {n:2d}  {case:9s}  seed {seed}:  frames without {n} contacts "
                          f"{c['frames_not_n']} of {frames - settle}, new IDs {c['new_ids']}, "
                          f"lifts {c['lifts']}", flush=True)
    return tot


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--limits", type=int, nargs="+", default=[16, 6])
    ap.add_argument("--frames", type=int, default=400)
    a = ap.parse_args(argv)
    if any(not 1 <= n <= 16 for n in a.limits) or a.frames <= LAND + LATE + 20:
        print(f"crowding: limits must be 1..16 and frames > {LAND + LATE + 20}", file=sys.stderr)
        return 2
    tot = run(a.seeds, a.limits, a.frames)
    print(f"total: {tot['scenes']} scenes, frames without N contacts {tot['frames_not_n']}, "
          f"new IDs {tot['new_ids']}, lifts {tot['lifts']}")
    return 1 if tot["frames_not_n"] or tot["new_ids"] or tot["lifts"] else 0


if __name__ == "__main__":
    sys.exit(main())
