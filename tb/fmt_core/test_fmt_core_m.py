"""fmt_core with a frame of M = 3 windows (WINDOWS_M = 3: not a power of two), small
sensor, CLK_PER_SAMPLE 3, both simulators: heat maps and events bit-exact with the
fixed-point model at M = 3 (rx_fixed.rx_heatmaps_fixed(m=3): the receive array's exact
reciprocal divider), the core's own frame-end counter (fmt_latency) one frame = 3
windows apart, the latency counters equal to the cycles measured from the logs.

The cocotb side is ``run_scene`` of bench/core/core_cocotb.py (the job-file engine of
``python -m bench.core.run_sim_rtl``); the reference is computed by run_sim_rtl.prepare, which
passes the scene's M to rx_heatmaps_fixed.
"""
from __future__ import annotations

import json
import sys

import pytest

from bench.core import run_sim_rtl as rsr
from common.runner import run_cocotb
from fmt import scene as _scene
from fmt.settings import TouchSettings

M = 3


def test_fmt_core_m3(sim):
    frames, cps = 5, 3
    scene = _scene.small_scene().replace(frames=frames, m=M)
    cfg = scene.cfg
    assert scene.samples_per_frame == M * cfg.n_fft
    st = TouchSettings(hold_off_us=5.0, max_jump_mm=4.0)
    d, ref, cal, _n_upd = rsr.prepare(scene, frames, cps, st, cal=None, tag=f"tbm{M}_{sim}")
    assert ref.heatmaps.shape[0] == frames
    run_cocotb(sim=sim, toplevel="fmt_core_sim_top", sources=rsr.sim_sources(),
               test_module="core_cocotb", test_dir=rsr.BENCH, testcase="run_scene",
               parameters=rsr.sim_parameters(cfg, cps, d),
               extra_env={"FMT_CORE_JOB": str(d / "job.json"), "FMT_CORE_UART": 0,
                          "FMT_CORE_CFG": cfg.name, "FMT_QUIET": 1},
               build_args=rsr.build_args(sim, fast_sim=False), tag=f"c{cps}")
    res = json.loads((d / "result.json").read_text())
    rep = rsr.analyse(scene, ref, d, cps, res["status"], frames, res["wall_s"], None, False, cal)
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    assert sum(len(e) for e in ref.events) > 0, "the scene must give events"
    hm_rows, eof, evs, fend = rsr.parse_logs(d, cfg)
    # the core's frame ends (fmt_latency) are M windows apart
    ends = [fend[f] for f in sorted(fend)]
    assert len(ends) >= frames - 1
    period = M * cfg.n_fft * cps
    assert all(b - a == period for a, b in zip(ends, ends[1:])), ends
    # each frame's heat map leaves after its frame end, before the next one
    for f, c in enumerate(eof[:len(ends)]):
        c_eof = c if isinstance(c, int) else c[0]
        assert ends[f] < c_eof < ends[f] + period, (f, ends[f], c)
    # latency counters against the logs
    per = {}
    for e in evs:
        if e["cycle"] < res["status_cycle"]:
            per.setdefault(e["frame"], []).append(e["cycle"])
    first = [min(c) - fend[f] for f, c in per.items() if f in fend and c]
    stt = res["status"]
    assert first and stt["LAT_FIRST_COUNT"] == len(first)
    assert (stt["LAT_FIRST_MIN"], stt["LAT_FIRST_MAX"]) == (min(first), max(first)), (stt, first)
    print(f"fmt_core {cfg.name} M={M} cps={cps}: {rep['frames']} frames, {len(evs)} events, "
          f"frame end -> first event {min(first)}..{max(first)} clk")


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
