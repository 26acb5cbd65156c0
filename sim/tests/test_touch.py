"""Pipeline glue: heat maps rendered from contacts -> events (fixed and float)."""
from __future__ import annotations

import time

import numpy as np
import pytest

from fmt import params, sensor
from fmt.settings import TouchSettings
from fmt.touch import process_frames

SCALE = 20000.0        # counts per coupling unit (a fully covered cell)


def render(cfg, contacts_per_frame, profile="disk"):
    hm = np.zeros((len(contacts_per_frame), cfg.rows, cfg.cols), dtype=np.int64)
    for k, cts in enumerate(contacts_per_frame):
        if cts:
            m = sensor.contact_map(cfg, cts, profile)
            hm[k] = np.clip(np.rint(m * SCALE), 0, (1 << cfg.hm_width) - 1)
    return hm


@pytest.mark.parametrize("fixed", [True, False])
def test_one_finger_moving(fixed):
    cfg = params.DEFAULT
    n = 40
    path = [(50 + 0.3 * k, 60 + 0.1 * k) for k in range(n)]
    hm = render(cfg, [[(x, y, 8.0, 1.0)] for x, y in path] + [[]] * 40)
    out = process_frames(hm, cfg, TouchSettings(), fixed=fixed)
    types = [[e.type for e in f] for f in out]
    # default confirmation: the contact is reported ('new') in its second frame
    assert types[0] == [] and types[1] == ["new"] and all(t == ["move"] for t in types[2:n])
    ids = {e.id for f in out for e in f}
    assert len(ids) == 1
    assert sum(t == ["lift"] for t in types) == 1
    err = [abs(e.x_q / 256 * 5 - path[k][0]) + abs(e.y_q / 256 * 5 - path[k][1])
           for k, f in enumerate(out[:n]) for e in f]
    assert max(err) < 1.0          # mm, L1 (disk profile, bias-corrected fit)


def test_fixed_vs_float_positions():
    """Fixed vs float pipeline on the same integer heat maps: same events; positions
    within 2 Q8.8 units (fit rounding + bias-table interpolation)."""
    cfg = params.DEFAULT
    rng = np.random.default_rng(4)
    frames = []
    for k in range(30):
        frames.append([(rng.uniform(20, 180), rng.uniform(20, 130), 8.0, 1.0),
                       (rng.uniform(20, 180), rng.uniform(20, 130), 9.0, 0.8)])
    hm = render(cfg, frames)
    st = TouchSettings()
    a = process_frames(hm, cfg, st, fixed=True)
    b = process_frames(hm.astype(float), cfg, st, fixed=False)
    worst = 0
    for fa, fb in zip(a, b):
        assert sorted(e.type for e in fa) == sorted(e.type for e in fb)
        pa = sorted((e.x_q, e.y_q) for e in fa if e.type != "lift")
        pb = sorted((e.x_q, e.y_q) for e in fb if e.type != "lift")
        for (xa, ya), (xb, yb) in zip(pa, pb):
            worst = max(worst, abs(xa - xb), abs(ya - yb))
    print(f"fixed vs float pipeline: worst position difference {worst} Q8.8 units")
    assert worst <= 2


def test_two_fingers_and_small_config():
    cfg = params.MEDIUM
    hm = render(cfg, [[(10, 10, 8.0, 1.0), (35, 25, 8.0, 1.0)]] * 5)
    out = process_frames(hm, cfg, TouchSettings(), fixed=True)
    assert out[0] == [] and sorted(e.type for e in out[1]) == ["new", "new"]
    assert all(sorted(e.type for e in f) == ["move", "move"] for f in out[2:])
    one = process_frames(hm, cfg, TouchSettings(confirm_frames=1), fixed=True)
    assert sorted(e.type for e in one[0]) == ["new", "new"]
    assert all(e.frame == k for k, f in enumerate(out) for e in f)


def test_blob_stage_model_only():
    cfg = params.DEFAULT
    palm = [(100, 75, 40.0, 1.0), (30, 30, 8.0, 1.0)]
    hm = render(cfg, [palm] * 2)
    out = process_frames(hm, cfg, TouchSettings(), fixed=True, blobs=True)
    assert [e.type for e in out[0]].count("blob") == 1
    assert [e.type for e in out[0]] == ["blob"]          # the finger: reported from frame 1
    fingers = [e for e in out[1] if e.type != "blob"]
    assert len(fingers) == 1 and abs(fingers[0].x_q / 256 * 5 - 30) < 1


def test_throughput_report():
    """frames/s of process_frames on the default sensor (printed; -s to see)."""
    cfg = params.DEFAULT
    n = 200
    path = [[(50 + 0.05 * k, 60, 8.0, 1.0), (120, 80 - 0.05 * k, 8.0, 1.0)] for k in range(n)]
    hm = render(cfg, path)
    t0 = time.perf_counter()
    out = process_frames(hm, cfg, TouchSettings(), fixed=True)
    dt = time.perf_counter() - t0
    print(f"process_frames: {n / dt:.0f} frames/s (2 touches, default sensor, fixed)")
    assert len(out) == n
