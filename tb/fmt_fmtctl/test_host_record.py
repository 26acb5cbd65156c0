"""fmtctl record: the .npz recording of a known source, read back bit for bit, replayed
through the model (every recorded event again) and, under Verilator, through the RTL
post-processing (scripts/replay_touch.py --in the recording --check: the RTL equals the
model on the recorded sequence)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fmt import params
from fmt.host import events as E
from fmt.host import recording as R

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
FMTCTL = ROOT / "scripts" / "fmtctl"
sys.path.insert(0, str(HERE))

from fake_core import FakeCore  # noqa: E402
import known_scene  # noqa: E402


def small_heatmaps(frames: int = 16) -> np.ndarray:
    """The small 4 x 6 sensor: one finger dragging from (1.2, 1.4) to (3.8, 1.9)."""
    cfg = params.SMALL
    yy, xx = np.mgrid[0:cfg.rows, 0:cfg.cols].astype(float)
    out = np.full((frames, cfg.rows, cfg.cols), 100.0)
    for f in range(frames):
        x, y = 1.2 + 2.6 * f / (frames - 1), 1.4 + 0.5 * f / (frames - 1)
        out[f] += 9000 * np.exp(-((xx - x) ** 2 + (yy - y) ** 2) / (2 * 0.7 ** 2))
    return np.rint(out).astype(np.int64)


def record(cfg, hm, recs, path, *extra):
    core = FakeCore(cfg, heatmaps=hm, records=recs, pace_s=0.0005)
    try:
        r = subprocess.run([sys.executable, str(FMTCTL), "--port", core.url, "record", "--out", str(path),
                            "--snapshots", str(len(hm)), "--events", str(len(recs)), *extra],
                           capture_output=True, text=True, timeout=300)
    finally:
        core.close()
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert f"recorded {len(hm)} heat maps and {len(recs)} events" in r.stdout, r.stdout
    return R.load(path)


def without_time(recs):
    return [{k: v for k, v in r.items() if k != "time"} for r in recs]


def test_record_and_model_replay(tmp_path):
    cfg = params.DEFAULT
    hm = known_scene.heatmaps(cfg)
    recs = known_scene.records(hm, cfg)
    rec = record(cfg, hm, recs, tmp_path / "run.npz")
    # the file: documented arrays, metadata
    z = np.load(tmp_path / "run.npz", allow_pickle=False)
    assert {"meta", "heatmaps", "heatmap_frame", "heatmap_host_s", "events", "event_host_s"} <= set(z.files)
    assert z["heatmaps"].dtype == np.uint32 and z["events"].shape == (len(recs), len(E.FIELDS))
    m = rec.meta
    assert m["format"] == "fmt-recording" and m["version"] == 1 and m["config"] == "default"
    assert m["info"]["rows"] == 30 and m["registers"]["TOUCH_THRESHOLD"] == 2000
    assert m["settings_exact"] is True and rec.settings().threshold == 2000
    # bit for bit: heat maps, frame numbers, events (every field, time stamps included)
    assert np.array_equal(rec.heatmaps, hm)
    assert list(rec.heatmap_frame) == list(range(len(hm)))
    assert rec.events == recs
    assert np.all(np.diff(rec.heatmap_host_s) >= 0) and len(rec.event_host_s) == len(recs)
    # the model on the recorded heat maps gives the recorded events again
    again = E.from_model(rec.model_events(), period_clk=3 * cfg.n_fft)
    assert without_time(again) == without_time(recs)


def test_record_errors(tmp_path):
    r = subprocess.run([sys.executable, str(FMTCTL), "--port", "socket://127.0.0.1:1", "record",
                        "--out", str(tmp_path / "x.npz")], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "refused" in r.stderr.lower()
    bad = tmp_path / "bad.npz"
    np.savez(bad, x=np.zeros(3))
    with pytest.raises(ValueError, match="not an fmt recording"):
        R.load(bad)


@pytest.mark.verilator_only
def test_record_replay_rtl(sim, tmp_path):
    """Record the small sensor's scene from the fake port, then scripts/replay_touch.py
    --in the recording --check: the RTL fmt_touch equals the model on it, and both give
    the recorded events (Verilator build of fmt_touch, small config)."""
    assert sim == "verilator"
    cfg = params.SMALL
    hm = small_heatmaps()
    recs = E.from_model(known_scene.process_frames(hm, cfg, fixed=True, frame_period_s=cfg.window_s),
                        period_clk=3 * cfg.n_fft)
    assert {r["type"] for r in recs} >= {"new", "move"}
    rec = record(cfg, hm, recs, tmp_path / "small.npz")
    assert rec.meta["config"] == "small"
    out = tmp_path / "replay.jsonl"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), str(ROOT / "sim"), str(ROOT / "tb"),
                                                        os.environ.get("PYTHONPATH", "")]))
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "replay_touch.py"), "--in", str(tmp_path / "small.npz"),
                        "--out", str(out), "--check"], capture_output=True, text=True, timeout=1800, cwd=ROOT, env=env)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "bit-exact with fmt.touch.process_frames" in r.stdout
    got = [json.loads(x) for x in out.read_text().splitlines() if x.strip()]
    key = lambda e: (e["frame"], e["id"], e["type"], e["x_q"], e["y_q"], e["strength"])
    assert [key(e) for e in got] == [key(e) for e in recs]
