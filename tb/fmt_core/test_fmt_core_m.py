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
from common.runner import long_run, run_cocotb
from fmt import scene as _scene
from fmt.settings import TouchSettings

M = 3


def _run_job(sim, cfg, cps, d) -> dict:
    """The job folder d (rsr.prepare) through the cocotb engine; its result.json."""
    run_cocotb(sim=sim, toplevel="fmt_core_sim_top", sources=rsr.sim_sources(),
               test_module="core_cocotb", test_dir=rsr.BENCH, testcase="run_scene",
               parameters=rsr.sim_parameters(cfg, cps, d),
               extra_env={"FMT_CORE_JOB": str(d / "job.json"), "FMT_CORE_UART": 0,
                          "FMT_CORE_CFG": cfg.name, "FMT_QUIET": 1},
               build_args=rsr.build_args(sim, fast_sim=False), tag=f"c{cps}")
    return json.loads((d / "result.json").read_text())


def test_fmt_core_m3(sim):
    if sim == "verilator" and not long_run():
        pytest.skip("the Verilator build runs in make test-long (FMT_LONG=1); Icarus here")
    frames, cps = 5, 3
    scene = _scene.small_scene().replace(frames=frames, m=M)
    cfg = scene.cfg
    assert scene.samples_per_frame == M * cfg.n_fft
    st = TouchSettings(hold_off_us=5.0, position_noise_mm=2.8)
    d, ref, cal, _n_upd = rsr.prepare(scene, frames, cps, st, cal=None, tag=f"tbm{M}_{sim}")
    assert ref.heatmaps.shape[0] == frames
    res = _run_job(sim, cfg, cps, d)
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


def test_fmt_core_m_written_during_run(sim):
    """Issue #15 item 5: WINDOWS_M written at random cycles, in the middle of frames.
    Each frame must take the value present at the ce edge that takes the last sample of
    its first window (the core's rule, fmt_core m_act_q), seen here from the frame ends
    (fe.log: M = the spacing / N / clk per sample) against the write cycles; then the heat
    maps and events must be bit-exact with the model given that M for each frame."""
    import numpy as np
    if sim == "verilator" and not long_run():
        pytest.skip("the Verilator build runs in make test-long (FMT_LONG=1); Icarus here")
    rng = np.random.default_rng(5)
    frames, cps, m0 = 12, 3, 3
    scene = _scene.small_scene().replace(frames=frames, m=m0)
    cfg = scene.cfg
    st = TouchSettings(hold_off_us=5.0, position_noise_mm=2.8)
    d, _ref, cal, _n = rsr.prepare(scene, frames, cps, st, cal=None, tag=f"tbmw_{sim}")
    job = json.loads((d / "job.json").read_text())
    total, vals, cur = job["run_cycles"], [], m0
    # about one write per window: many land between a frame's latch and the moment the
    # receivers' FFTs output that window (where a receiver reading WINDOWS_M live would
    # disagree with the frame counter)
    times = sorted(rng.integers(int(0.1 * total), int(0.8 * total), size=40).tolist())
    for t in times:
        cur = int(rng.choice([v for v in (1, 2, 3) if v != cur]))
        vals.append([int(t), "WINDOWS_M", cur])
    job["mid_regs"] = vals
    (d / "job.json").write_text(json.dumps(job))
    res = _run_job(sim, cfg, cps, d)
    writes = [(c, v) for c, _n, v in res["mid_regs"]]
    assert len(writes) == len(vals)
    hm_rows, _eof, evs, fend = rsr.parse_logs(d, cfg)
    win = cfg.n_fft * cps
    m_frames, ambiguous = [m0], 0
    for f in range(1, max(fend) + 1):
        gap = fend[f] - fend[f - 1]
        assert gap % win == 0 and 1 <= gap // win <= 3, (f, gap)
        m_f = gap // win
        latch = fend[f] - (m_f - 1) * win          # the first window's last sample
        want = m0
        for c, v in writes:
            if c <= latch:
                want = v
        near = [v for c, v in writes if abs(c - latch) <= 2]
        if near:
            ambiguous += 1
        else:
            assert m_f == want, f"frame {f}: M {m_f}, WINDOWS_M at its first window {want}"
        m_frames.append(m_f)
    assert len(set(m_frames)) == 3 and ambiguous <= 4, (m_frames, ambiguous)
    # bit-exact with the model at those M
    eff = rsr.check_scene(scene)
    g0, updates = rsr.coupling_plan(scene, frames * scene.samples_per_frame, cps)
    ref = rsr.model_reference(scene, g0, updates, eff, frames, st, cal, cps, m_frames=m_frames)
    n_cmp = min(len(m_frames), ref.heatmaps.shape[0]) - 1
    assert n_cmp >= 8, (len(m_frames), ref.heatmaps.shape)
    for f in range(n_cmp):
        rows = hm_rows.get(f, {})
        got = np.array([rows[r][1] for r in range(cfg.rows)]) if len(rows) == cfg.rows else None
        assert got is not None and np.array_equal(got, ref.heatmaps[f]), f"heat map {f}"
    by_f = {}
    for e in evs:
        by_f.setdefault(e["frame"], []).append(rsr._key(e))
    for f in range(n_cmp - 1):
        assert by_f.get(f, []) == [rsr._key(e) for e in ref.events[f]], f"events of frame {f}"
    assert sum(len(e) for e in ref.events[:n_cmp - 1]) > 0, "the scene must give events"
    print(f"fmt_core {cfg.name}: M per frame {m_frames}, {n_cmp} heat maps and their events "
          f"bit-exact, {len(writes)} writes")


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
