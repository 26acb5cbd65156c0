#!/usr/bin/env python3
"""Replay heat maps through the RTL touch processing (fmt_touch under Verilator, fed
from Python through cocotb) and write the touch events as JSON lines.

    source scripts/env.sh
    python scripts/replay_touch.py --in heatmaps.npy --out events.jsonl
                                   [--config default|small|medium] [--settings s.json] [--check]

heatmaps.npy: (frames, ROWS, COLS) unsigned heat-map counts (e.g. the output of
scripts/replay_rx.py).  Rows are fed in the receive chain's order, one frame per window
(3 N clocks at 3 x fs), identity calibration, blobs off.  --settings: a JSON object of
fmt.settings.TouchSettings fields.  Each line of events.jsonl is one event: frame, id,
type (new/move/lift/blob), x_q, y_q (Q8.8 cells), strength, axis_major_q, axis_minor_q,
angle, flags, cycle.  --check compares with the bit-exact model
(fmt.touch.process_frames) and exits 1 on a difference.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "sim"), str(ROOT / "tb")]
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(ROOT / "sim"), str(ROOT / "tb")]
    + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])

import numpy as np  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--in", dest="inp", required=True, help="heat maps .npy (frames x rows x cols)")
    ap.add_argument("--out", required=True, help="events .jsonl")
    ap.add_argument("--config", default="default", choices=["default", "small", "medium"])
    ap.add_argument("--settings", default="", help="TouchSettings fields as a JSON file")
    ap.add_argument("--check", action="store_true", help="compare with process_frames (bit-exact)")
    a = ap.parse_args(argv)

    from common.runner import run_cocotb, sources
    from fmt import params
    from fmt_touch.touch_driver import build_args

    cfg = params.get(a.config)
    inp, out = Path(a.inp).resolve(), Path(a.out).resolve()
    if not inp.exists():
        print(f"replay_touch: no such file: {inp}", file=sys.stderr)
        return 2
    env = {"CFG": a.config, "REPLAY_IN": inp, "REPLAY_OUT": out,
           "REPLAY_SETTINGS": Path(a.settings).resolve() if a.settings else ""}
    run_cocotb(
        sim="verilator", toplevel="fmt_touch", sources=sources("fmt_touch"),
        test_module="replay_cocotb", test_dir=ROOT / "tb" / "fmt_touch",
        parameters={"ROWS": cfg.rows, "COLS": cfg.cols, "HM_W": cfg.hm_width,
                    "MAX_TOUCHES": cfg.max_touches, "EV_DEPTH": 256},
        extra_env=env, build_args=build_args("verilator"), tag=f"replay-{a.config}")
    events = [json.loads(line) for line in out.read_text().splitlines() if line.strip()]
    print(f"replay_touch: {len(events)} events from {np.load(inp).shape[0]} heat maps -> {out}")
    if a.check:
        from fmt.settings import TouchSettings
        from fmt.touch import process_frames
        st = TouchSettings(**json.loads(Path(a.settings).read_text())) if a.settings else TouchSettings()
        exp = process_frames(np.load(inp), cfg, st, fixed=True, frame_period_s=cfg.window_s)
        want = [(e.frame, e.id, e.type, e.x_q, e.y_q, e.strength, e.axis_major_q, e.axis_minor_q,
                 e.angle, e.flags) for fr in exp for e in fr]
        got = [(e["frame"], e["id"], e["type"], e["x_q"], e["y_q"], e["strength"], e["axis_major_q"],
                e["axis_minor_q"], e["angle"], e["flags"]) for e in events]
        if got != want:
            n = next((i for i, (g, w) in enumerate(zip(got, want)) if g != w), min(len(got), len(want)))
            print(f"replay_touch: MISMATCH with the model at event {n} "
                  f"(RTL {len(got)} events, model {len(want)})", file=sys.stderr)
            return 1
        print("replay_touch: bit-exact with fmt.touch.process_frames")
    return 0


if __name__ == "__main__":
    sys.exit(main())
