"""cocotb testbench of rtl/fmt_touch.v (flatten -> localmax -> interp -> tracker ->
event port) against sim/fmt/touch.py process_frames(fixed=True).

Heat maps: random (noise plus random bumps: many maxima, the contact limit) and
rendered from moving finger contacts (fmt.sensor, disk profile), rows in random order,
a random calibration (offset / gain) loaded through the calibration port.  Every
frame's events (all fields, in order, ev_last) must equal the model's.  The latency
from the frame's last row beat to its last event on the output (dial 0, consumer
ready) is measured per frame and checked against the budget (140 processing-clock
cycles, BUDGET below); the numbers are logged (pytest -s, or the cocotb log).

Blobs (blob_en_i = 1, test ``blobs``): palm scenes (a large ellipse and fingers next to
it, some fingers landing on the palm) and random maps, bit-exact with
process_frames(blobs=True) (finger removal by the blob mask, type-3 blob events after
the tracker's); the latency last row -> last event with blobs on is logged and
checked against BLOB_BUDGET.  The other tests run with blob_en_i = 0.
"""
from __future__ import annotations

import os
import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge

from common.runner import long_run, run_cocotb, sources
from common.tb_util import env_int
from fmt import flatten, params, sensor
from fmt.settings import TouchSettings
from fmt.blob import blob_stream_fixed
from fmt.touch import MAX_BLOBS, process_frames
from fmt_touch.touch_driver import FRAME_PERIOD_S, TB, build_args, group, scene_maps

# last row -> last event, blobs off: the 30 x 40 sensor with 16 fingers (the contact
# limit) measured 128 (2026-11-28, test-long; 100 before the 125 MHz redesigns of the
# local maxima and the tracker); 140 with the receive chain's 820 clk stays inside the
# 8 us budget (1,000 clk at 125 MHz) with 40 clk to spare
BUDGET = 140
BLOB_BUDGET = 200              # blobs on: + the wait for the blob mask and the replay


def random_maps(cfg, rng, n, top):
    out = np.zeros((n, cfg.rows, cfg.cols), dtype=np.int64)
    for k in range(n):
        z = rng.integers(0, 3000, size=(cfg.rows, cfg.cols))
        for _ in range(rng.integers(0, 6)):
            r, c = rng.integers(0, cfg.rows), rng.integers(0, cfg.cols)
            z[r, c] += int(rng.integers(2000, 40000))
        if rng.random() < 0.2:
            z = rng.integers(0, top + 1, size=(cfg.rows, cfg.cols))   # many maxima, saturation
        out[k] = np.clip(z, 0, top)
    return out


async def run_case(tb, maps, st, cal, rng, period, blobs=False):
    cfg = tb.cfg
    tb.settings(st)
    tb.dut.blob_en_i.value = int(blobs)
    await tb.reset()
    # the calibration RAM is not cleared by reset: always load one
    await tb.calibrate(*(cal if cal is not None else flatten.identity(cfg)))
    tb.events.clear()
    tb.row_cycles.clear()
    await tb.send(maps, rng, period)
    for _ in range(200):
        await RisingEdge(tb.clk)
    exp = process_frames(maps, cfg, st, fixed=True, flatten_cal=cal, frame_period_s=FRAME_PERIOD_S,
                         blobs=blobs)
    got = {fr[0][1][0]: fr for fr in group(tb.events)}
    lat = []
    for k, evs in enumerate(exp):
        e = [(x.frame, x.id, x.type_code, x.x_q, x.y_q, x.strength, x.axis_major_q,
              x.axis_minor_q, x.angle, x.flags) for x in evs]
        g = [x[1] for x in got.get(k, [])]
        assert g == e, f"frame {k}:\nRTL   {g}\nmodel {e}"
        if evs:
            # last row taken at edge R -> last event handshake seen after edge L
            # in cycles: last row beat in cycle c -> last event valid in cycle c + lat
            lat.append((len(evs), got[k][-1][0] - tb.row_cycles[k] + 1))
    assert len(got) == sum(1 for x in exp if x)
    d = tb.dut
    assert int(d.lm_overrun_o.value) == 0 and int(d.trk_overrun_o.value) == 0
    assert int(d.ev_overflow_o.value) == 0
    return lat


@cocotb.test()
async def random_heatmaps(dut):
    tb = TB(dut)
    cfg = tb.cfg
    top = (1 << cfg.hm_width) - 1
    rng = np.random.default_rng(env_int("SEED", 1))
    prng = random.Random(env_int("SEED", 1))
    maps = random_maps(cfg, rng, 25, top)
    off = rng.integers(0, 400, size=(cfg.rows, cfg.cols))
    gain = rng.integers(12000, 24000, size=(cfg.rows, cfg.cols))
    st = TouchSettings(threshold=2500, hold_off_us=3000)
    period = 3 * cfg.n_fft          # the real frame period: N samples at 3 x fs
    lat = await run_case(tb, maps, st, (off, gain), prng, period)
    st2 = TouchSettings(threshold=1500, neighbourhood="vn", bias_correction=False,
                        max_touches=3, hold_off_us=1000)
    lat += await run_case(tb, maps[:12], st2, None, prng, period)
    worst = max(l for _, l in lat)
    dut._log.info(f"latency last row -> last event (events, cycles): worst {worst}, "
                  f"all {sorted(set(lat))}")
    # no budget check here: noise maps with ~100 maxima above the threshold cost the
    # local-maxima stage one cycle per maximum (see fmt_localmax); the scene test checks


@cocotb.test()
async def scene_heatmaps(dut):
    tb = TB(dut)
    cfg = tb.cfg
    top = (1 << cfg.hm_width) - 1
    rng = np.random.default_rng(5)
    maps = scene_maps(cfg, 40, top, rng)
    st = TouchSettings(threshold=3000, hold_off_us=3000, max_speed_mm_s=1000)
    lat = await run_case(tb, maps, st, None, random.Random(5), 3 * cfg.n_fft)
    by_n = {}
    for n, l in lat:
        by_n[n] = max(by_n.get(n, 0), l)
    dut._log.info(f"latency last row -> last event, worst per event count: {by_n}")
    assert max(by_n.values()) <= BUDGET


@cocotb.test()
async def many_fingers(dut):
    """Up to MAX_TOUCHES fingers on a 3-cell grid, jittering, a few lifting and
    landing each frame: the worst realistic tail (all moves + news + lifts)."""
    tb = TB(dut)
    cfg = tb.cfg
    top = (1 << cfg.hm_width) - 1
    rng = np.random.default_rng(9)
    P = cfg.pitch_mm
    grid = [(1.5 * P + 3 * P * i, 1.5 * P + 3 * P * j)
            for j in range(max(1, (cfg.rows - 1) // 3)) for i in range(max(1, (cfg.cols - 1) // 3))]
    grid = grid[:cfg.max_touches]
    on = np.ones(len(grid), dtype=bool)
    maps = np.zeros((30, cfg.rows, cfg.cols), dtype=np.int64)
    for k in range(30):
        if k > 5:
            flip = rng.random(len(grid)) < 0.1
            on ^= flip
        cts = [(x + rng.normal(0, 0.3), y + rng.normal(0, 0.3), 8.0, 1.0)
               for (x, y), o in zip(grid, on) if o]
        m = sensor.contact_map(cfg, cts) * 25000 if cts else np.zeros((cfg.rows, cfg.cols))
        maps[k] = np.clip(np.rint(m + rng.normal(0, 30, m.shape) + 200), 0, top)
    st = TouchSettings(threshold=3000, hold_off_us=2000)
    lat = await run_case(tb, maps, st, None, random.Random(9), 3 * cfg.n_fft)
    worst = max(l for _, l in lat)
    dut._log.info(f"{len(grid)} fingers: latency last row -> last event (events, cycles): "
                  f"worst {worst}, all {sorted(set(lat))}")
    assert worst <= BUDGET


def palm_maps(cfg, n, top, rng):
    """A palm (large ellipse, drifting) with fingers next to it; every 4th frame one
    finger sits on the palm's edge (removed as part of the blob), some frames without
    the palm (fingers only), some with two small blobs."""
    out = np.zeros((n, cfg.rows, cfg.cols), dtype=np.int64)
    w, h = cfg.width_mm, cfg.height_mm
    for k in range(n):
        px, py = (0.35 + 0.01 * k) * w, (0.45 + 0.005 * k) * h
        cts = []
        if k % 7 != 6:
            cts.append((px, py, 0.5 * h, 1.0, 0.35 * w, 0.3 + 0.05 * k))
        cts.append((0.85 * w, (0.2 + 0.01 * k) * h, 8.0, 1.0, 8.0, 0.0))
        cts.append((0.88 * w, 0.8 * h, 7.0, 0.8, 7.0, 0.0))
        if k % 4 == 3:
            cts.append((px + 0.3 * w, py, 7.0, 1.0, 7.0, 0.0))
        if k % 5 == 4:
            cts.append((0.1 * w, 0.1 * h, 9.0, 1.0, 9.0, 0.0))
        m = sensor.contact_map(cfg, cts) * 25000 + rng.normal(200, 40, (cfg.rows, cfg.cols))
        out[k] = np.clip(np.rint(m), 0, top)
    return out


@cocotb.test()
async def blobs(dut):
    """blob_en_i = 1: palm scenes and random maps (many small regions: more than 8
    blobs, fingers removed by blobs beyond the reported 8), bit-exact with
    process_frames(blobs=True); latency with blobs on."""
    tb = TB(dut)
    cfg = tb.cfg
    top = (1 << cfg.hm_width) - 1
    rng = np.random.default_rng(11)
    period = 3 * cfg.n_fft
    maps = palm_maps(cfg, 24, top, rng)
    st = TouchSettings(threshold=3000, hold_off_us=3000, max_speed_mm_s=1000,
                       blob_threshold=4000, blob_min_cells=6)
    lat = await run_case(tb, maps, st, None, random.Random(11), period, blobs=True)
    exp = process_frames(maps, cfg, st, fixed=True, frame_period_s=FRAME_PERIOD_S, blobs=True)
    assert sum(e.type == "blob" for f in exp for e in f) >= 12, "palm scenes give blobs"
    worst = max(l for _, l in lat)
    dut._log.info(f"blobs on, palm scenes: latency last row -> last event (events, cycles): "
                  f"worst {worst}, all {sorted(set(lat))}")
    assert worst <= BLOB_BUDGET
    rmaps = random_maps(cfg, rng, 16, top)
    st2 = TouchSettings(threshold=2500, hold_off_us=3000, blob_threshold=2000,
                        blob_min_cells=1)
    exp = process_frames(rmaps, cfg, st2, fixed=True, frame_period_s=FRAME_PERIOD_S, blobs=True)
    # single cells count: frames with more than 8 blobs (the list is full)
    assert max(sum(e.type == "blob" for e in f) for f in exp) == 8
    lat2 = await run_case(tb, rmaps, st2, None, random.Random(12), period, blobs=True)
    dut._log.info(f"blobs on, random maps: latency (events, cycles): worst "
                  f"{max(l for _, l in lat2)}")


def random_settings(cfg, rng) -> TouchSettings:
    """Settings drawn over their useful ranges (every field that fmt_touch takes)."""
    return TouchSettings(
        threshold=int(rng.integers(1500, 4000)),
        neighbourhood=str(rng.choice(["moore", "vn"])),
        max_touches=int(rng.integers(1, cfg.max_touches + 1)) if rng.random() < 0.5 else None,
        bias_correction=bool(rng.random() < 0.5),
        position_noise_mm=float(rng.uniform(0.0, 10.0)),
        hold_off_us=float(rng.choice([1000.0, 2000.0, 5000.0])),
        velocity_window_us=float(rng.choice([1000.0, 4000.0, 16000.0])),
        max_speed_mm_s=float(rng.uniform(200.0, 5000.0)),
        blobs=bool(rng.random() < 0.5),
        blob_threshold=int(rng.integers(1500, 5000)),
        blob_min_cells=int(rng.integers(1, 16)),
        on_threshold=int(rng.integers(0, 6000)),
        confirm_frames=int(rng.integers(1, 4)))


@cocotb.test()
async def settings_midframe(dut):
    """Issue #15 item 5: every setting (blob_en_i included) rewritten at random cycles,
    in the middle of frames as well as between them.  Each frame must be processed
    with the settings present when its first row entered (process_frames with one
    settings entry per frame): every event bit-exact, no overrun, no frame lost."""
    tb = TB(dut)
    cfg = tb.cfg
    top = (1 << cfg.hm_width) - 1
    rng = np.random.default_rng(env_int("SEED", 1) + 20)
    n = 40
    # palms (blob sizes around min-cells) and random maps (cells on both sides of every
    # threshold, Moore and Von Neumann maxima differ), in each half
    q = n // 4
    maps = np.concatenate([palm_maps(cfg, q, top, rng), random_maps(cfg, rng, q, top),
                           random_maps(cfg, rng, q, top), palm_maps(cfg, q, top, rng)])
    cur = {"st": random_settings(cfg, rng)}
    per_frame = [None] * n

    def apply(st):
        cur["st"] = st
        tb.settings(st)
        tb.dut.blob_en_i.value = int(st.blobs)

    def hook(k, i):
        # about three changes per frame, anywhere (rows, the eof cycle, the idle cycles)
        if rng.random() < 3.0 / (3 * cfg.n_fft):
            apply(random_settings(cfg, rng))
        if i == 0:
            per_frame[k] = cur["st"]        # driven with the frame's first row

    apply(cur["st"])
    await tb.reset()
    await tb.calibrate(*flatten.identity(cfg))
    tb.events.clear()
    # the first half in bursts, the second with the rows spread over the frame period
    # (the next frame arrives while the previous one is finished, as in the core)
    await tb.send(maps[:n // 2], random.Random(21), 3 * cfg.n_fft, hook=hook)
    await tb.send(maps[n // 2:], random.Random(22), 3 * cfg.n_fft, spread=True,
                  hook=hook, first_frame=n // 2)
    for _ in range(300):
        await RisingEdge(tb.clk)
    exp = process_frames(maps, cfg, per_frame[0], fixed=True, frame_period_s=FRAME_PERIOD_S,
                         frame_settings=per_frame)
    got = {fr[0][1][0]: fr for fr in group(tb.events)}
    changed = sum(a != b for a, b in zip(per_frame, per_frame[1:]))
    assert changed >= n // 3, f"only {changed} frames with new settings"
    assert sum(bool(e) for e in exp) >= n // 2, "the scenes give events"
    for k, evs in enumerate(exp):
        e = [(x.frame, x.id, x.type_code, x.x_q, x.y_q, x.strength, x.axis_major_q,
              x.axis_minor_q, x.angle, x.flags) for x in evs]
        g = [x[1] for x in got.get(k, [])]
        assert g == e, f"frame {k} ({per_frame[k]}):\nRTL   {g}\nmodel {e}"
    assert len(got) == sum(1 for x in exp if x)
    d = tb.dut
    assert int(d.lm_overrun_o.value) == 0 and int(d.trk_overrun_o.value) == 0
    assert int(d.ev_overflow_o.value) == 0
    # the blob flag (sticky): set exactly when a frame with blobs on had more blobs than
    # the list holds (random maps at full size do), never by an overrun
    flat, _ = flatten.flatten_fixed(maps, *flatten.identity(cfg), cfg)
    blob_ovf = [k for k in range(n) if per_frame[k].blobs and blob_stream_fixed(
        flat[k], per_frame[k].blob_threshold, per_frame[k].blob_min_cells, MAX_BLOBS)[2]]
    assert int(d.blob_flag_o.value) == int(bool(blob_ovf)), f"blob overflow in frames {blob_ovf}"
    dut._log.info(f"settings changed before {changed} of {n} frames; "
                  f"{sum(len(e) for e in exp)} events bit-exact; blob overflow in frames {blob_ovf}")


# ---- pytest entry ------------------------------------------------------------------
# medium by default (the Verilator build of the whole chain takes ~1 min per size);
# FMT_TOUCH_ALL=1 adds the small sensor.
SIZES = ["small", "medium"] if os.environ.get("FMT_TOUCH_ALL") else ["medium"]


@pytest.mark.parametrize("cfg_name", SIZES)
def test_fmt_touch(sim, cfg_name):
    _run_touch(sim, cfg_name)


# cocotb tests of this module.  make test (for its time) runs them under Verilator only
# (Icarus sees the touch top inside fmt_core's Icarus runs); make test-long (FMT_LONG=1)
# runs every test under both.
COCOTB_TESTS = ["random_heatmaps", "scene_heatmaps", "many_fingers", "blobs", "settings_midframe"]


def test_cocotb_test_list():
    """COCOTB_TESTS names every cocotb test of this module (a new one is never left out)."""
    names = [n for n, v in globals().items() if type(v).__module__.startswith("cocotb._decorators")]
    assert sorted(names) == sorted(COCOTB_TESTS), names


def _run_touch(sim, cfg_name):
    p = params.get(cfg_name).verilog_params()
    tests = COCOTB_TESTS
    if sim == "icarus" and not long_run():
        pytest.skip("Verilator runs every test of the touch top in make test; Icarus in "
                    "make test-long (FMT_LONG=1) and inside fmt_core's Icarus runs")
    run_cocotb(
        sim=sim,
        toplevel="fmt_touch",
        sources=sources("fmt_touch"),
        test_module="test_fmt_touch",
        test_dir=Path(__file__).parent,
        parameters={**{k: p[k] for k in ("ROWS", "COLS", "HM_W", "MAX_TOUCHES")}, "EV_DEPTH": 256},
        extra_env={"CFG": cfg_name, "SEED": 1},
        build_args=build_args(sim, "-O1"), tag=cfg_name, testcase=tests,
    )


@pytest.mark.verilator_only
@pytest.mark.skipif(not os.environ.get("FMT_TOUCH_DEFAULT"), reason="FMT_TOUCH_DEFAULT=1 runs it")
def test_fmt_touch_default(sim):
    """The default 30 x 40 sensor (latency against the budget at full size)."""
    _run_touch(sim, "default")
