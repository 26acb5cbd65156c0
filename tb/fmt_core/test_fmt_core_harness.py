"""The standalone C++ Verilator harness of ``make sim`` (bench/core/sim_main.cpp driving
bench/core/fmt_core_sim_top.v with EXT_CHANNEL = 1; bench/core/run_sim_rtl.py
run_harness) on the small sensor (4 x 6, N = 64): a finger, a drag that starts
mid-window and a tap that lands and lifts inside windows, CLK_PER_SAMPLE 3.

Checks: the harness's channel in C++ feeds the core so that heat maps and events are
bit-exact with the fixed-point model (tx_fixed -> channel twin -> rx_heatmaps_fixed
-> touch.process_frames), every coupling update lands on its stamp (none late, all
applied), no frame dropped, the latency counters read over the bus equal the cycles
measured from the logs, and the scene gives new, move and lift events.  The same scene
under the cocotb path is tb/fmt_core/test_fmt_core.py (Verilog channel + player).

Then, on the same build (in the same test: two tests building one folder at once under
pytest-xdist would collide), the short sample of the random-scene regression: 8 scenes
of scripts/random_scenes.py (random contacts, effects and run-time settings; the first
three start after a busy core, random ADC words and settings, was reset mid-frame) must be
bit-exact with the model (``make random-scenes`` runs 200 on the small and medium builds).

The build is at -O0 (a few frames; `make sim` builds at -O3 / -O2 and caches the build).
Verilator only (there is no Icarus variant of a Verilator C++ harness).
"""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from bench.core import run_sim_rtl as rsr
from fmt import scene as _scene
from fmt.settings import TouchSettings


def small_tap_scene(frames: int) -> _scene.Scene:
    """The small scene plus a tap that lands and lifts inside windows (as test_fmt_core)."""
    sc = _scene.small_scene()
    n, fs = sc.cfg.n_fft, sc.cfg.fs_hz
    tap = _scene.Contact(name="tap", path=[[0.0, 25.5, 15.5]],
                         active=[[3 * n / fs + 23 / fs, 7 * n / fs + 41 / fs]])
    return sc.replace(frames=frames, contacts=list(sc.contacts) + [tap])


@pytest.mark.verilator_only
def test_fmt_core_harness(sim):
    assert sim == "verilator"
    frames = 24
    st = TouchSettings(hold_off_us=5.0, position_noise_mm=2.8)
    scene = small_tap_scene(frames)
    cfg = scene.cfg
    d, ref, cal, n_upd, res, build_s = rsr.run_harness(scene, frames, 3, st, cal="scene",
                                                      tag="tb_cpp", quiet=True, cflags="-O0")
    rep = rsr.analyse(scene, ref, d, 3, res["status"], frames, res["wall_s"], None, False, cal)
    assert n_upd > 3 and res["upd_copies"] == n_upd + 1           # G0 + every update
    assert res["upd_late"] == 0 and res["upd_done"] == 1
    assert rep["frames"] >= frames and rep["frames_dropped"] == 0, rep
    assert rep["golden_detail"]["first"] is None, rep["golden_detail"]
    assert rep["golden_mismatches"] == 0
    types = {e.type_code for evs in ref.events for e in evs}
    assert {0, 1, 2} <= types, f"scene must give new, move and lift events: {types}"
    # latency counters (read by the harness over the bus) against the logged cycles
    _hm, _eof, evs, fend = rsr.parse_logs(d, cfg)
    per = {}
    for e in evs:
        if e["cycle"] < res["status_cycle"]:
            per.setdefault(e["frame"], []).append(e["cycle"])
    first = [min(c) - fend[f] for f, c in per.items() if f in fend]
    last = [max(c) - fend[f] for f, c in per.items() if f in fend]
    stt = res["status"]
    assert stt["LAT_FIRST_COUNT"] == len(first) > 0 and stt["LAT_LAST_COUNT"] == len(last)
    assert (stt["LAT_FIRST_MIN"], stt["LAT_FIRST_MAX"]) == (min(first), max(first)), (stt, first)
    assert (stt["LAT_LAST_MIN"], stt["LAT_LAST_MAX"]) == (min(last), max(last)), (stt, last)
    assert res["frames_before_status"] <= stt["FRAME_COUNT"] <= res["frames_at_status"]
    print(json.dumps({"build_s": round(build_s, 1), "frames": rep["frames"],
                      "events": res["events"], "clk_per_s": res["clk_per_s"]}))
    # the random-scene sample through the same build
    spec = importlib.util.spec_from_file_location(
        "_random_scenes", Path(__file__).resolve().parents[2] / "scripts" / "random_scenes.py")
    rs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(rs)
    ran, i = 0, 0
    while ran < 8:
        sc, st = rs.random_scene(21, i, "small")
        i += 1
        assert i < 100, "too few random scenes fit the bench"
        try:
            # the first three after a busy core was reset at a random cycle (--reset)
            pre = rs.busy_before_reset(21, i - 1, sc) if ran < 3 else None
            rep = rsr.run(sc, cps=3, sim="verilator", plot=False, quiet=True, settings=st,
                          tag="tb_cpp", cflags="-O0", pre=pre)
        except ValueError as e:
            if "update records" in str(e):
                continue
            raise
        rc, line = rsr.verdict(rep)
        assert rc == 0 and rep["frames"] >= sc.frames, (i - 1, line)
        ran += 1
