#!/usr/bin/env python3
"""Replay heat maps through the RTL touch processing (fmt_touch under Verilator, fed
from Python through cocotb) and write the touch events as JSON lines.

    source scripts/env.sh
    python scripts/replay_touch.py --in heatmaps.npy --out events.jsonl
                                   [--config default|small|medium] [--settings s.json] [--check]
    python scripts/replay_touch.py --in recording.npz --out events.jsonl [--check]

heatmaps.npy: (frames, ROWS, COLS) unsigned heat-map counts (e.g. the output of
scripts/replay_rx.py).  recording.npz: a recording of ``fmtctl record`` (docs/host.md):
its heat-map snapshots in order, its sensor config, its settings (TouchSettings from the
registers; --config / --settings override them) and its frame period (M windows).  Rows are fed in the receive chain's order, one frame per window
(3 N clocks at 3 x fs), identity calibration, blobs off.  --settings: a JSON object of
fmt.settings.TouchSettings fields.  Each line of events.jsonl is one event: frame, id,
type (new/move/lift/blob), x_q, y_q (Q8.8 cells), strength, axis_major_q, axis_minor_q,
angle, flags, cycle.  --check compares with the bit-exact model
(fmt.touch.process_frames) and exits 1 on a difference.  Bad input (a dtype other than
integer, a shape other than (frames, ROWS, COLS) of the config, a value outside
0 .. 2^HM_W - 1, a bad settings key) gives one line and exit 2 before any build; a failed
simulation or model one line and exit 1.  events.jsonl is renamed from a temporary name
only when the simulation passed.
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
    from fmt.inputs import InputError, OneLineParser
    ap = OneLineParser(description=__doc__.splitlines()[0])
    ap.add_argument("--in", dest="inp", required=True,
                    help="heat maps .npy (frames x rows x cols) or a recording .npz (fmtctl record)")
    ap.add_argument("--out", required=True, help="events .jsonl")
    ap.add_argument("--config", default=None, choices=["default", "small", "medium"],
                    help="sensor config (default: the recording's, else default)")
    ap.add_argument("--settings", default="", help="TouchSettings fields as a JSON file")
    ap.add_argument("--check", action="store_true", help="compare with process_frames (bit-exact)")
    a = ap.parse_args(argv)
    try:
        return run(a)
    except InputError as e:
        print(f"replay_touch: {e}", file=sys.stderr)
        return 2


def run(a) -> int:
    from common.runner import SimulationFailed, run_cocotb, sources
    from fmt import inputs, params
    from fmt import settings as _settings
    from fmt.inputs import InputError
    from fmt.settings import TouchSettings
    from fmt_touch.touch_driver import build_args

    inp, out = Path(a.inp).resolve(), Path(a.out).resolve()
    if not inp.exists():
        raise InputError(f"no such file: {inp}")
    if not out.parent.is_dir():
        raise InputError(f"--out {a.out}: no such directory {out.parent}")
    # settings: checked (unknown keys, types, ranges) before anything runs
    st = _settings.load(a.settings) if a.settings else None
    period = None
    if inp.suffix == ".npz":                   # a recording of fmtctl record
        from fmt.host import recording as R
        try:
            rec = R.load(inp)
        except ValueError as e:
            raise InputError(f"{inp}: {inputs.one_line(e)}") from None
        cfg_rec = rec.config()
        if a.config is None:
            if cfg_rec is None:
                raise InputError(f"no sensor config of {rec.rows} x {rec.cols}: give --config")
            a.config = cfg_rec.name
        cfg = params.get(a.config)
        maps = inputs.check_int_array(rec.heatmaps, f"heat maps of {inp.name}",
                                      (None, cfg.rows, cfg.cols), 0, (1 << cfg.hm_width) - 1)
        npy = out.with_suffix(".heatmaps.npy")
        np.save(npy, maps.astype(np.uint32))
        if st is None:
            d = dict(rec.meta["settings"])
            if d.get("blobs"):
                print("replay_touch: the recording has blob detection on; the replay runs it off",
                      file=sys.stderr)
                d["blobs"] = False
            if not rec.meta.get("settings_exact", True):
                print("replay_touch: the recording's tracking registers differ from its settings' "
                      "conversion: the replay uses the settings", file=sys.stderr)
            st = TouchSettings.from_dict(d, where=f"settings of {inp.name}")
        m = max(1, int(rec.meta.get("registers", {}).get("WINDOWS_M", 1)))
        period = cfg.window_s * m
        print(f"replay_touch: recording {inp.name}: {len(rec.heatmaps)} heat maps, "
              f"{len(rec.events)} recorded events, config {a.config}, M = {m}")
        inp = npy
    else:
        a.config = a.config or "default"
        cfg = params.get(a.config)
        # integers only (floats refused, not truncated), (frames, rows, cols) of the config,
        # 0 .. 2^HM_W - 1 (no wrap)
        maps = inputs.load_int_array(inp, "heat maps", (None, cfg.rows, cfg.cols), 0,
                                     (1 << cfg.hm_width) - 1)
    settings_path = Path(a.settings).resolve() if a.settings else ""
    if st is not None and not a.settings:             # the recording's (checked) settings
        settings_path = out.with_suffix(".settings.json")
        settings_path.write_text(json.dumps(st.as_dict()))
    st = st or TouchSettings()
    tmp = inputs.temp_output(out)
    inputs.remove_quietly(tmp)
    env = {"CFG": a.config, "REPLAY_IN": inp, "REPLAY_OUT": tmp,
           "REPLAY_SETTINGS": settings_path}
    if period is not None:
        env["REPLAY_FRAME_PERIOD_S"] = repr(period)
    try:
        run_cocotb(
            sim="verilator", toplevel="fmt_touch", sources=sources("fmt_touch"),
            test_module="replay_cocotb", test_dir=ROOT / "tb" / "fmt_touch",
            parameters={"ROWS": cfg.rows, "COLS": cfg.cols, "HM_W": cfg.hm_width,
                        "MAX_TOUCHES": cfg.max_touches, "EV_DEPTH": 256},
            extra_env=env, build_args=build_args("verilator"), tag=f"replay-{a.config}")
        events = [json.loads(line) for line in tmp.read_text().splitlines() if line.strip()]
    except (SimulationFailed, RuntimeError, OSError, ValueError, SystemExit) as e:
        inputs.remove_quietly(tmp)
        sys.stdout.flush()
        print(f"replay_touch: the simulation failed ({inputs.one_line(e)}); {out} not written",
              file=sys.stderr)
        return 1
    inputs.commit_output(tmp, out)
    print(f"replay_touch: {len(events)} events from {len(maps)} heat maps -> {out}")
    if a.check:
        from fmt.touch import process_frames
        try:
            exp = process_frames(maps, cfg, st, fixed=True, frame_period_s=period or cfg.window_s)
        except Exception as e:  # noqa: BLE001 -- a model error is a failed check, one line
            print(f"replay_touch: the model failed ({inputs.one_line(e)})", file=sys.stderr)
            return 1
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
