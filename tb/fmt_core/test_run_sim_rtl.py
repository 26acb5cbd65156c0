"""Tests of bench/core/run_sim_rtl.py (``make sim`` through the RTL).

Model side: the int64 channel twin equals ``channel.channel_sim_fixed`` (the bit-exact twin
of fmt_channel_sim) on a stream with stamped updates and noise; the coupling plan
leaves every update enough clk cycles to load; the player records encode the plan.
RTL smoke (short version for ``make test``): a few frames of the small scene through
fmt_core under Icarus (Verilator is the ``make sim`` path, its build takes longer), the
report has its keys and golden_mismatches == 0.
"""
from __future__ import annotations

import shutil

import numpy as np
import pytest

from bench.core import run_sim_rtl as rsr
from fmt import channel, params
from fmt import scene as _scene


def test_channel_fixed_equals_channel_sim_fixed():
    cfg = params.SMALL
    rng = np.random.default_rng(5)
    n = 300
    dac = rng.integers(-2048, 2048, size=(n, cfg.rows))
    g0 = rng.integers(0, 1 << 16, size=(cfg.rows, cfg.cols))
    ups = [(37, rng.integers(0, 1 << 16, size=(cfg.rows, cfg.cols))),
           (200, rng.integers(0, 1 << 16, size=(cfg.rows, cfg.cols)))]
    noise = rng.integers(-3000, 3000, size=(64, cfg.cols))
    a, clip_a = channel.channel_sim_fixed(dac, g0, ups, noise, adc_bits=12)
    b, clip_b = rsr.channel_fixed(dac, g0, ups, None, 12, noise=noise)
    assert np.array_equal(a, b)
    assert int(clip_a.sum()) == clip_b and clip_b > 0


@pytest.mark.parametrize("cps", [1, 3])
def test_coupling_plan_spacing(cps):
    sc = _scene.default_scene().replace(frames=30)
    n = sc.frames * sc.samples_per_frame
    g0, ups = rsr.coupling_plan(sc, n, cps)
    assert g0.shape == (sc.cfg.rows, sc.cfg.cols) and g0.min() > 0    # baseline everywhere
    prev_s, prev_g = 0, g0
    for s, g in ups:
        writes = int(np.count_nonzero(g != prev_g))
        assert 0 < writes and prev_s * cps + writes + rsr.LOAD_MARGIN < s * cps
        prev_s, prev_g = s, g
    # taps: an update lands exactly on every onset sample inside the run
    taps = [c for c in sc.contacts if c.name == "taps"][0]
    stamps = {s for s, _ in ups}
    for on, _off in taps.intervals_samples(sc.cfg.fs_hz):
        if on < n:
            assert int(on) in stamps


def test_plan_records():
    cfg = params.SMALL
    g0 = np.arange(1, cfg.rows * cfg.cols + 1).reshape(cfg.rows, cfg.cols)
    g1 = g0.copy()
    g1[2, 3] = 999
    rec = rsr.plan_records(cfg, g0, [(77, g1)])
    assert len(rec) == cfg.rows * cfg.cols + 1 + 1 + 1 + 1
    assert rec[-1] == 0 and rec[-2] == (2 << 60) | 77
    assert rec[-3] == (1 << 60) | (2 << 52) | (3 << 44) | 999
    assert rec[cfg.rows * cfg.cols] == (2 << 60)


@pytest.mark.skipif(shutil.which("iverilog") is None, reason="Icarus not installed")
def test_run_sim_rtl_smoke(tmp_path):
    sc = _scene.small_scene()
    rep = rsr.run(sc, tmp_path, frames=6, cps=3, sim="icarus", plot=False, quiet=True)
    for k in ("frames", "frames_dropped", "heatmap_rate_hz", "latency_us", "position_error_mm",
              "jitter_mm", "golden_mismatches", "sim_frames_per_s"):
        assert k in rep, k
    for k in ("window_end_to_event", "onset_to_event"):
        assert set(rep["latency_us"][k]) >= {"min", "median", "max"}
    assert rep["frames"] >= 6 and rep["frames_dropped"] == 0
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    assert rep["latency_us"]["window_end_to_event"]["n"] > 0


def test_calibration_fixed_is_the_default():
    """run_sim_rtl calibrates by the real procedure through its fixed-point chain: noise
    free it matches the noiseless render within the rounding; with noise (the scene's) the
    offsets scatter; prepare(cal="scene") loads exactly that, cal="noiseless" the old one."""
    from fmt import run_sim
    sc = _scene.small_scene()
    clean = sc.replace(contacts=[], effects={"pn": {"enable": True, "chip_len": 1}})
    o0, g0 = run_sim.calibration(clean, mode="noiseless")
    o1, g1 = rsr.calibration_fixed(clean, 3)
    assert np.abs(o1 - o0).max() <= 6 and np.abs(g1 / g0 - 1).max() < 0.02      # 10 LSB tones: ADC rounding
    o2, _g2 = rsr.calibration_fixed(sc, 3)
    assert np.sqrt(np.mean((o2 - o0) ** 2.0)) > 5
    _d, _ref, cal, _n = rsr.prepare(sc.replace(frames=2), 2, 3, None, cal="scene", tag="cal_fixed")
    assert np.array_equal(cal[0], o2) and np.array_equal(cal[1], _g2)
    _d, _ref, cal, _n = rsr.prepare(sc.replace(frames=2), 2, 3, None, cal="noiseless", tag="cal_fixed")
    assert np.array_equal(cal[0], o0) and np.array_equal(cal[1], g0)
