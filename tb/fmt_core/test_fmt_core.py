"""Tests of rtl/fmt_core.v through the simulation top of the ``make sim`` bench
(bench/core/fmt_core_sim_top.v: fmt_core + fmt_channel_sim + coupling-update player +
loggers) against the fixed-point models (bench/core/run_sim_rtl.py: tx_fixed ->
channel twin -> rx_heatmaps_fixed -> touch.process_frames(fixed=True)).

The cocotb side is the bench's engine ``run_scene`` (bench/core/core_cocotb.py: the
calibration through the local register bus, a reset, the settings, the clocked run,
the status registers and, with FMT_CORE_UART=1, register access, counters and a
heat-map snapshot over the UART).

pytest: the small sensor (4 x 6, N = 64) with a finger, a drag that starts mid-window and
a tap (touch down and lift inside windows), CLK_PER_SAMPLE 1 and 3, both simulators:
heat maps and events bit-exact with the model, register access over the UART, latency
counters equal to the cycles measured from the logs, the snapshot equal to the logged
frame, the calibration windows read back.  FMT_CORE_DEFAULT=1 adds the default 30 x 40 sensor under Verilator (latency at
full size; the build takes minutes).
"""
from __future__ import annotations

import hashlib
import json
import os

import numpy as np
import pytest

from bench.core import run_sim_rtl as rsr
from common.runner import long_run, run_cocotb
from fmt import protocol
from fmt import scene as _scene
from fmt.settings import TouchSettings


# ---- pytest entry ------------------------------------------------------------------------
def small_tap_scene(frames: int) -> _scene.Scene:
    """The small scene plus a tap that lands and lifts inside windows."""
    sc = _scene.small_scene()
    cfg = sc.cfg
    n, fs = cfg.n_fft, cfg.fs_hz
    tap = _scene.Contact(name="tap", path=[[0.0, 25.5, 15.5]],
                         active=[[3 * n / fs + 23 / fs, 7 * n / fs + 41 / fs]])
    return sc.replace(frames=frames, contacts=list(sc.contacts) + [tap])


def _run(sim, scene, cps, uart, settings, model_settings=None, extra_params=None, tag=""):
    """Run the scene on the sim top; the reference uses model_settings (default: the
    settings the registers are written with)."""
    cfg = scene.cfg
    # a job folder per test (pytest-xdist runs tests of one simulator and cps side by side:
    # a shared folder let one test read the other's logs)
    node = os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" (", 1)[0]
    jtag = f"tb_{sim}{tag}_{hashlib.sha1(node.encode()).hexdigest()[:8]}"
    if model_settings is not None:     # the same scene, noise and plan: only the settings differ
        _d, ref_m, _cal, _n = rsr.prepare(scene, scene.frames, cps, model_settings, cal=None, tag=jtag)
    d, ref, cal, n_upd = rsr.prepare(scene, scene.frames, cps, settings, cal=None, tag=jtag)
    if model_settings is not None:
        ref = ref_m
    # slack after the last frame for the UART phase
    run_cocotb(sim=sim, toplevel="fmt_core_sim_top", sources=rsr.sim_sources(),
               test_module="core_cocotb", test_dir=rsr.BENCH, testcase="run_scene",
               parameters={**rsr.sim_parameters(cfg, cps, d), **(extra_params or {})},
               extra_env={"FMT_CORE_JOB": str(d / "job.json"), "FMT_CORE_UART": int(uart),
                          "FMT_CORE_CFG": cfg.name, "FMT_QUIET": 1},
               build_args=rsr.build_args(sim, fast_sim=cfg.name == "default"),
               tag=f"c{cps}{tag}")
    res = json.loads((d / "result.json").read_text())
    rep = rsr.analyse(scene, ref, d, cps, res["status"], scene.frames, res["wall_s"], None, False, cal)
    return d, ref, res, rep


@pytest.mark.parametrize("cps", [1, 3])
def test_fmt_core(sim, cps):
    if not long_run() and (sim, cps) in (("icarus", 3), ("verilator", 1)):
        pytest.skip("make test: cps 1 under Icarus, cps 3 (with the UART) under Verilator; "
                    "the other two in make test-long")
    frames = 14
    # lifts within the run (small frames are 1.536 us); a gate below the tap-drag distance
    # (sqrt 2 x (2.8 mm + 2 x 3 m/s x 1.536 us) = 3.97 mm)
    st = TouchSettings(hold_off_us=5.0, position_noise_mm=2.8)
    scene = small_tap_scene(frames)
    cfg = scene.cfg
    uart = cps == 3                              # the UART phase once per simulator (test time)
    d, ref, res, rep = _run(sim, scene, cps, uart, st)
    assert res["upd_late"] == 0 and res["upd_done"] == 1
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_detail"]["first"] is None, rep["golden_detail"]
    assert rep["golden_mismatches"] == 0
    n_ev = sum(len(e) for e in ref.events)
    types = {e.type_code for evs in ref.events for e in evs}
    assert n_ev > 0 and {0, 1, 2} <= types, f"scene must give new, move and lift events: {types}"
    # latency counters against the cycles measured from the logs (frame end -> events)
    hm_rows, eof, evs, fend = rsr.parse_logs(d, cfg)
    per = {}
    for e in evs:
        per.setdefault(e["frame"], []).append(e["cycle"])
    for f in per:
        per[f] = [c for c in per[f] if c < res["status_cycle"]]
    first = [min(c) - fend[f] for f, c in per.items() if f in fend and c]
    last = [max(c) - fend[f] for f, c in per.items() if f in fend and c]
    stt = res["status"]
    assert stt["LAT_FIRST_COUNT"] == len(first) and stt["LAT_LAST_COUNT"] == len(last)
    assert (stt["LAT_FIRST_MIN"], stt["LAT_FIRST_MAX"]) == (min(first), max(first)), (stt, first)
    assert (stt["LAT_LAST_MIN"], stt["LAT_LAST_MAX"]) == (min(last), max(last)), (stt, last)
    # FRAME_COUNT is read between the two samples of the frame counter of the sim top
    assert res["frames_before_status"] <= stt["FRAME_COUNT"] <= res["frames_at_status"]
    assert res["cal_rb"] == [0x123, 16384], res["cal_rb"]     # written offset, identity gain
    print(f"fmt_core {cfg.name} cps={cps}: {rep['frames']} frames, {len(evs)} events, "
          f"window end -> first event {min(first)}..{max(first)} clk, last {min(last)}..{max(last)} clk")
    if not uart:
        return
    # UART: registers, counters, histogram, snapshot (the event consumer stayed stopped)
    u = res["uart"]
    assert u["scratch"] == 0x5A5AC3C3 and u["id"] == protocol.INFO_MAGIC
    assert u["LAT_FIRST_COUNT"] == len(first) and u["LAT_FIRST_MIN"] == min(first)
    assert u["LAT_LAST_MAX"] == max(last)
    h_first = u["hist"]
    exp_hist = np.bincount(np.minimum(np.asarray(first) >> 5, 15), minlength=16).tolist()
    assert h_first == exp_hist, (h_first, exp_hist)
    assert u["snap_status"] >> 31 == 1
    snap_frame = u["snap_status"] & 0xFFFF
    rows = hm_rows[snap_frame]
    exp = [cell for r in range(cfg.rows) for cell in rows[r][1]]
    assert u["snap"] == exp


def small_palm_scene(frames: int) -> _scene.Scene:
    """The small scene's still finger plus a 14 mm palm that lands inside window 4."""
    sc = _scene.small_scene()
    cfg = sc.cfg
    n, fs = cfg.n_fft, cfg.fs_hz
    palm = _scene.Contact(name="palm", diameter_mm=14.0, path=[[0.0, 22.0, 12.0]],
                          active=[[4 * n / fs + 30 / fs, None]])
    return sc.replace(frames=frames, contacts=[sc.contacts[0], palm])


def test_fmt_core_blobs(sim):
    """TOUCH_MODE bit 2 (blobs on) through the register file: the palm's maximum is
    dropped and blob events follow the tracker's, bit-exact with process_frames(blobs)."""
    if sim == "icarus" and not long_run():
        pytest.skip("make test: under Verilator (the core's Icarus run is test_fmt_core[icarus-1]); "
                    "both simulators in make test-long (FMT_LONG=1), for make test's time")
    frames = 12
    # threshold and size between the finger (3 cells above 3500) and the palm (8 cells)
    st = TouchSettings(hold_off_us=5.0, position_noise_mm=2.8, blobs=True,
                       blob_threshold=3500, blob_min_cells=5)
    scene = small_palm_scene(frames)
    d, ref, res, rep = _run(sim, scene, 3, False, st)
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    per_frame = [sorted(e.type for e in evs) for evs in ref.events]
    n_blob = sum(t.count("blob") for t in per_frame)
    assert n_blob >= frames - 6, f"the palm must be a blob in the later frames: {per_frame}"
    assert all(t.count("blob") <= 1 for t in per_frame), per_frame
    # in a frame with a blob, the palm's maximum is not a finger: only the still finger
    # (the first ID) moves or is new there (the palm may be a finger while it lands)
    still = next(e.id for evs in ref.events for e in evs if e.type == "new")   # the first contact
    for evs in ref.events:
        if any(e.type == "blob" for e in evs):
            assert {e.id for e in evs if e.type in ("new", "move")} == {still}, evs
    assert res["status"]["STATUS"] >> 7 & 1 == 0          # no blob overflow/overrun


def test_fmt_core_no_blob_build(sim):
    """fmt_core built with BLOBS = 0: the detector is left out, so TOUCH_MODE bit 2 (written
    here) has no effect: the palm scene's events are those of the model with blobs off."""
    frames = 8
    st_on = TouchSettings(hold_off_us=5.0, position_noise_mm=2.8, blobs=True,
                          blob_threshold=3500, blob_min_cells=5)
    scene = small_palm_scene(frames)
    d, ref, res, rep = _run(sim, scene, 3, False, st_on, model_settings=st_on.replace(blobs=False),
                            extra_params={"BLOBS": 0}, tag="_nb")
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    types = {e.type for evs in ref.events for e in evs}
    assert "blob" not in types and len({e.id for evs in ref.events for e in evs}) == 2, types
    assert res["status"]["STATUS"] >> 7 & 1 == 0


@pytest.mark.verilator_only
@pytest.mark.skipif(not os.environ.get("FMT_CORE_DEFAULT"), reason="FMT_CORE_DEFAULT=1 runs it")
def test_fmt_core_default(sim):
    """Default 30 x 40 sensor, CLK_PER_SAMPLE 3: bit-exact and the latency against 8 us."""
    frames = int(os.environ.get("FMT_CORE_FRAMES", "60"))
    scene = _scene.default_scene().replace(frames=frames)
    d, ref, res, rep = _run(sim, scene, 3, False, TouchSettings())
    lat = rep["latency_us"]
    print(json.dumps({k: rep[k] for k in ("frames", "frames_dropped", "golden_mismatches",
                                          "latency_us", "latency_fs_cycles")}, indent=1))
    assert rep["golden_mismatches"] == 0 and rep["frames_dropped"] == 0
    assert lat["window_end_to_last_event"]["max"] <= 8.0
