"""The host tools against the simulated core (Verilator only): ``python -m bench.core.run_sim_rtl
--serve`` at the small sensor (sim/scenes/small.json: a still finger and a drag, events
every frame; the serve test's Server of tb/fmt_core, its own build tag), three clients in
turn, then Ctrl-C:

* fmtctl tuio (--hold-frames 0) sends 6 reports to a python-osc receiver in the test;
  every received bundle's session IDs and positions are the core's own events of that
  frame (ev.log of the bench's loggers: new/move events, normalised to the sensor), and
  every bundle holds both fingers (the UART sends whole reports: fmt_report_fifo).
* fmtctl view --png-dir --frames 3: three PNG frames, a red finger disc where the core's
  event of the snapshot's frame puts the still finger.
* fmtctl record --snapshots 8 --events 10: every snapshot equals the logged heat map of
  the frame SNAP_STATUS names, every event the logged event; then scripts/replay_touch.py
  --in the recording --check: the RTL fmt_touch equals the model on the recorded
  sequence (a session recorded and replayed through the RTL post-processing)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bench.core import run_sim_rtl as rsr
from fmt import params
from fmt.host import events as E
from fmt_core.test_fmt_core_serve import CPS, Server

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
FMTCTL = ROOT / "scripts" / "fmtctl"
sys.path.insert(0, str(HERE))

from test_host_tuio import Receiver  # noqa: E402

TAG = "tb_tuio"


@pytest.mark.verilator_only
@pytest.mark.long_only       # tuio / view / record against the model server run in make test
def test_host_tools_on_the_simulated_core(sim, tmp_path):
    assert sim == "verilator"
    cfg = params.SMALL
    srv = Server(tmp_path, "--serve-seconds", "600", "--tag", TAG)
    rx = Receiver()
    run = lambda *args: subprocess.run([sys.executable, str(FMTCTL), "--port", port, *args],
                                       capture_output=True, text=True, timeout=300)
    try:
        port = srv.wait_serving(wall_s=900)
        r = run("tuio", "--port", str(rx.port), "--count", "6", "--hold-frames", "0", "--event-timeout", "60")
        rv = run("view", "--png-dir", str(tmp_path / "png"), "--frames", "3")
        rr = run("record", "--out", str(tmp_path / "rec.npz"), "--snapshots", "8", "--events", "10")
        srv.interrupt()
        rc, text = srv.finish()
    finally:
        srv.kill()
        rx.close()
    assert r.returncode == 0 and "6 bundles" in r.stdout, r.stderr
    assert rv.returncode == 0 and "view: 3 frames" in rv.stdout, rv.stderr
    assert rr.returncode == 0 and "recorded 8 heat maps" in rr.stdout, rr.stderr
    assert rc == 0 and "golden mismatches 0" in text, text
    hm_rows, _eof, evs, _fend = rsr.parse_logs(rsr.job_dir(cfg, CPS, TAG), cfg)
    s = E.Sensor(cfg.rows, cfg.cols)
    logged = {}
    for e in evs:
        if e["type"] in ("new", "move"):
            logged.setdefault(e["frame"], {})[e["id"]] = s.norm(e["x_q"], e["y_q"])

    # ---- tuio
    got, cur, alive = {}, {}, []
    for addr, args in rx.msgs:
        if addr != "/tuio/2Dcur":
            continue
        if args[0] == "alive":
            alive, cur = args[1:], {}
        elif args[0] == "set":
            cur[args[1]] = tuple(args[2:4])
        elif args[0] == "fseq":
            assert sorted(cur) == sorted(alive)
            got[args[1]] = cur
    assert len(got) == 6, got
    # the UART sends whole reports (fmt_report_fifo; a frame that does not fit is dropped
    # whole): every bundle holds all its frame's fingers, each exactly as the core made it
    for f, d in got.items():
        assert f in logged and set(d) == set(logged[f]), (f, d, logged.get(f))
        for i, xy in d.items():
            assert xy == pytest.approx(logged[f][i], abs=1e-6), (f, i)
    assert all(len(d) == 2 for d in got.values()), got   # both fingers, in every bundle

    # ---- view: red finger discs where the core's events put the fingers (both are near
    # still while serving: a disc within 6 px of an ID's mean position)
    from PIL import Image
    from fmt.host import view as V
    pngs = sorted((tmp_path / "png").glob("frame_*.png"))
    assert len(pngs) == 3
    ren = V.Renderer(s)
    img = np.asarray(Image.open(pngs[-1]))[:, :, :3].astype(int)
    red = np.argwhere((img[:, :, 0] == 255) & (img[:, :, 1] == 0) & (img[:, :, 2] == 0))
    assert len(red), "no finger disc"
    pos = {}
    for e in evs:
        if e["type"] in ("new", "move"):
            pos.setdefault(e["id"], []).append((e["x_q"] / 256, e["y_q"] / 256))
    near = [i for i, p in pos.items()
            if np.min(np.hypot(*(red - np.array(ren.pixel_of(*np.mean(p, axis=0)))).T)) <= 6]
    assert near, (pos.keys(), red[:5])

    # ---- record: snapshots and events bit for bit with the logs, then the RTL replay
    from fmt.host import recording as R
    rec = R.load(tmp_path / "rec.npz")
    assert rec.meta["config"] == "small" and len(rec.heatmaps) == 8 and len(rec.events) >= 10
    for k, fr in enumerate(rec.heatmap_frame):
        rows = hm_rows[int(fr) & 0xFFFF]
        assert np.array_equal(rec.heatmaps[k], np.array([rows[r][1] for r in range(cfg.rows)])), fr
    by_key = {(e["frame"], e["id"]): e for e in evs}
    for e in rec.events:
        le = by_key[(e["frame"], e["id"])]
        assert (e["type"], e["x_q"], e["y_q"], e["strength"], e["time"]) == \
            (le["type"], le["x_q"], le["y_q"], le["strength"], le["time"]), (e, le)
    out = tmp_path / "replay.jsonl"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), str(ROOT / "sim"), str(ROOT / "tb"),
                                                        os.environ.get("PYTHONPATH", "")]))
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "replay_touch.py"), "--in", str(tmp_path / "rec.npz"),
                        "--out", str(out), "--check"], capture_output=True, text=True, timeout=1800, cwd=ROOT, env=env)
    assert r.returncode == 0 and "bit-exact with fmt.touch.process_frames" in r.stdout, r.stdout[-2000:] + r.stderr[-2000:]
