"""cocotb testbench of rtl/fmt_rx_array.v (the whole receive back end: COLS/2 column-pair
receivers) against rx_heatmaps_fixed (sim/fmt/rx_array.py).

Checks: heat maps bit-exact for touch-like stirred tones with random PN settings (on/off,
chip length, delay) and M = 1, 2, 3, 5 windows per frame (any M: the exact reciprocal
divider; M_LIST); the heat-map stream protocol (each row once per
frame in rx_fixed.row_order, frame numbers from 0, hm_eof_o one cycle after the last row
and never with a row); accuracy against a floating-point receiver (numpy FFT, exact
split and magnitude, mean over M) within 2 LSB; the hard cases (palm = saturated column,
DC offset, impulse, tone between bins, all rows in phase, full-scale random, full-scale
tone: sticky saturation flag exactly when the model saturates); a reset in the middle of
a window (the stream restarts cleanly with the next full frame); ce = 1 in 3
(CLK_PER_SAMPLE = 3); every row's beat time (the schedule of the shared magnitude units,
rx_fixed.rx_row_beats) and the LATENCY from a window's last ADC sample to its last row and
to hm_eof_o, written to build/rx_latency_<cfg>_postclk<p>_cps<c>.txt; the sticky queue
overrun (overrun_o, apart from the saturation and FFT flags) when ce comes faster than the
units were sized for.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

import cocotb
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common.runner import ROOT, run_cocotb, sources      # noqa: E402
from common.tb_util import env_int, env_str               # noqa: E402
from fmt import fft_r22sdf, params                         # noqa: E402
from fmt import rx_array as R                             # noqa: E402
from fmt_rx_array.rx_driver import TB, build_args         # noqa: E402
import rx_stim                                            # noqa: E402

FLOAT_BOUND_LSB = 2.0


def check_exact(tb, adc, rx_sign, m, beats, eofs, float_check=True):
    """m = windows per frame (any M)."""
    cfg = tb.cfg
    exp, order, flags = R.rx_heatmaps_fixed(adc, rx_sign, cfg, m=m)
    got = tb.frames_from(beats, eofs, exp.shape[0])
    for f in range(exp.shape[0]):
        if not np.array_equal(got[f], exp[f]):
            bad = np.argwhere(got[f] != exp[f])
            r, c = bad[0]
            raise AssertionError(f"frame {f}: {len(bad)} cells differ, first ({r},{c}) rtl {got[f, r, c]} model {exp[f, r, c]}; "
                                 f"all {[(int(a), int(b), int(got[f, a, b] - exp[f, a, b])) for a, b in bad[:12]]}")
    assert int(tb.dut.sat_o.value) == int(flags.sat), "sticky saturation flag"
    assert int(tb.dut.fft_ovf_o.value) == int(flags.fft_ovf), "sticky FFT overflow flag"
    assert not int(tb.dut.overrun_o.value), "sticky overrun flag"
    if float_check:
        ref = R.rx_heatmaps_float(adc, rx_sign, cfg, m=m)
        ok = exp < (1 << cfg.hm_width) - 1            # saturated cells are clipped, not errors
        err = np.abs(exp - ref)[ok]
        assert err.max() <= FLOAT_BOUND_LSB, f"fixed vs float {err.max():.2f} LSB"
        return float(err.max())
    return None


@cocotb.test()
async def exact_random_pn_and_m(dut):
    """Touch-like stirred tones, random PN settings, M = 1, 2, 3, 5 (M_LIST, windows per
    frame): bit-exact + float bound."""
    tb = TB(dut)
    cfg = tb.cfg
    rng = np.random.default_rng(env_int("SEED", 11))
    worst = 0.0
    for m in [int(x) for x in env_str("M_LIST", "1,2,3,5").split(",")]:
        wins = env_int("FRAMES", 2) * m
        s = wins * cfg.n_fft
        tx, rx, _ = rx_stim.pn(cfg, s, rng)
        adc = rx_stim.tones(cfg, s, rng, tx=tx)
        await tb.reset()
        beats, eofs, _ = await tb.run(adc, rx, m)
        worst = max(worst, check_exact(tb, adc, rx, m, beats, eofs))
    dut._log.info(f"max |fixed - float| = {worst:.3f} LSB")


@cocotb.test()
async def hard_cases(dut):
    """Palm, DC, impulse, tone between bins, growth, random, full-scale tone (M = 1)."""
    tb = TB(dut)
    cfg = tb.cfg
    adc, names = rx_stim.hard_cases(cfg, np.random.default_rng(3))
    rx = np.zeros(len(adc), dtype=np.uint8)
    await tb.reset()
    beats, eofs, _ = await tb.run(adc, rx, 1)
    check_exact(tb, adc, rx, 1, beats, eofs)
    exp, _, flags = R.rx_heatmaps_fixed(adc, rx, cfg, m=1)
    # the hard cases do what they should: palm column saturates nothing in the FFT,
    # the full-scale tone reaches the top of the cell range
    assert not flags.fft_ovf
    assert exp[names.index("fullscale")].max() >= (1 << cfg.hm_width) - 64


@cocotb.test()
async def reset_mid_window(dut):
    """Reset 1.5 windows into a run: the stream restarts with frame 0 of the samples
    after the reset, bit-exact, nothing half-made comes out."""
    tb = TB(dut)
    cfg = tb.cfg
    n = cfg.n_fft
    rng = np.random.default_rng(5)
    pre = rx_stim.uniform_random(cfg, 3 * n, rng)
    await tb.reset()
    beats0, eofs0, _ = await tb.run(pre, np.zeros(len(pre), np.uint8), 1, tail=0, stop_at=3 * n // 2)
    # window 0's early rows may be out already (a cut frame, never with hm_eof_o): the
    # touch processing is reset with the receiver
    assert len(beats0) < cfg.rows and not eofs0 and all(b[2] == 0 for b in beats0)
    await tb.reset(cycles=1)
    tx, rx, _ = rx_stim.pn(cfg, 2 * n, rng, enable=True)
    adc = rx_stim.tones(cfg, 2 * n, rng, tx=tx)
    beats, eofs, _ = await tb.run(adc, rx, 1)
    check_exact(tb, adc, rx, 1, beats, eofs)


def row_beats_formula(cfg, every=1, post_clk=1, cps=None, fft_ch=None):
    """clk cycles from the ce edge that takes a window's last ADC sample to the edge that
    puts each row on the heat-map stream (M = 1), dict row -> clk: the pair split takes
    slot s on the ce edge latency0 + s + 1 ce cycles later (latency0 counts from the FFT
    input register, which the despread register feeds); then the shared units' queue and
    engine (rx_fixed.rx_row_beats: queued 1 step later, loaded >= 1 step after that, P
    unit input steps, MAG_ITER + 3 magnitude stages, accumulator read, sum, round, row
    register; a step is a clk with POST_CLK = 1, a ce period with POST_CLK = 0)."""
    lat0 = fft_r22sdf.latency0(cfg.log2_n, cfg.adc_bits + 1, R.fft_out_w(cfg))
    return R.rx_row_beats(cfg, lat0, every, post_clk, cps, fft_ch=fft_ch)


@cocotb.test()
async def latency_and_slow_ce(dut):
    """Latency at ce = 1 and at ce = 1 in 3 (3 x fs processing clock), M = 1: every row's
    beat time against the schedule of the shared units."""
    tb = TB(dut)
    cfg = tb.cfg
    n = cfg.n_fft
    rng = np.random.default_rng(8)
    post_clk = env_int("POST_CLK", 1)
    cps = env_int("CPS", 3 if post_clk else 1)
    res = {}
    fch = tb.fft_ch
    # a time-multiplexed engine (FFT_CH > 1) needs ce every >= FFT_CH clk: its exact rate
    # and one clk more (engine idle one clk per sample)
    every_default = "1,3" if fch == 1 else f"{fch},{fch + 1}"
    for every in [int(x) for x in env_str("EVERY_LIST", every_default).split(",")]:
        tx, rx, _ = rx_stim.pn(cfg, n, rng)
        adc = rx_stim.tones(cfg, n, rng, tx=tx)
        await tb.reset()
        beats, eofs, taken = await tb.run(adc, rx, 1, ce_every=every)
        check_exact(tb, adc, rx, 1, beats, eofs, float_check=False)
        last_in = taken[n - 1]                      # clk of the window's last sample
        exp = row_beats_formula(cfg, every, post_clk, cps, fch)
        got = {b[1]: b[0] - last_in for b in beats[:cfg.rows]}
        assert got == exp, f"ce every {every}: row beats (row: clk) {got}, schedule {exp}"
        lat_row = beats[cfg.rows - 1][0] - last_in  # clk cycles to the last row beat
        lat_eof = eofs[0][0] - last_in
        assert lat_row == max(exp.values())
        assert lat_eof == lat_row + (1 if post_clk else every), f"eof {lat_eof} clk after the last sample"
        assert not int(dut.overrun_o.value), "queue overrun flag"
        res[every] = (lat_row, lat_eof)
    lines = [f"{cfg.name} (CLK_PER_SAMPLE {cps}, POST_CLK {post_clk}, MAG_UNITS "
             f"{R.rx_mag_units_default(cfg, cps if post_clk else 1)}, FFT_CH {fch}): "
             f"last ADC sample of a window -> last heat-map row / hm_eof:"]
    budget = int(8e-6 * cfg.fs_hz)
    for every, (row, eof) in res.items():
        lines.append(f"  clk = {every} x fs: {row} / {eof} clk = {row / every:.2f} / {eof / every:.2f} fs cycles "
                     f"({row / every / (cfg.fs_hz / 1e6):.3f} us to the last row); 8 us budget = {budget} fs "
                     f"cycles, left for touch processing: {budget - eof / every:.2f} fs cycles = "
                     f"{every * budget - eof} clk")
    text = "\n".join(lines) + "\n"
    out = ROOT / "build" / f"rx_latency_{cfg.name}_postclk{post_clk}_cps{cps}.txt"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    dut._log.info(text)


@cocotb.test(skip=os.environ.get("OVERRUN", "0") in ("", "0"))
async def overrun_flag(dut):
    """Only with OVERRUN=1 (a build whose MAG_UNITS is too few for ce = 1): the sticky
    overrun is clear at ce = 1 in 3 (exact heat maps) and set in overrun_o at ce = 1 (no
    saturation or FFT flag: the three flags are separate)."""
    tb = TB(dut)
    cfg = tb.cfg
    rng = np.random.default_rng(9)
    adc = rx_stim.tones(cfg, 3 * cfg.n_fft, rng)
    rx = np.zeros(len(adc), np.uint8)
    await tb.reset()
    beats, eofs, _ = await tb.run(adc, rx, 1, ce_every=3)
    check_exact(tb, adc, rx, 1, beats, eofs, float_check=False)
    assert not int(dut.overrun_o.value), "overrun flagged at the rate the units are sized for"
    await tb.reset()
    await tb.run(adc, rx, 1, ce_every=1)
    assert int(dut.overrun_o.value) == 1, "queue overrun not flagged"
    assert not int(dut.sat_o.value) and not int(dut.fft_ovf_o.value)


def _run(sim, cfg_name, extra=None, testcase=None, post_clk=1, cps=None, params_extra=None):
    p = params.get(cfg_name).verilog_params()
    cps = (3 if post_clk else 1) if cps is None else cps
    fft_ch = (params_extra or {}).get("FFT_CH", R.rx_fft_ch_default(post_clk, cps))
    env = {"CFG": cfg_name, "POST_CLK": post_clk, "CPS": cps, "FFT_CH": fft_ch}
    env.update(extra or {})
    run_cocotb(
        sim=sim,
        toplevel="fmt_rx_array",
        sources=sources("fmt_rx_array"),
        test_module="test_fmt_rx_array",
        test_dir=Path(__file__).parent,
        parameters={**{k: p[k] for k in ("ROWS", "COLS", "LOG2_N", "BIN_LO", "BIN_STEP", "ADC_BITS", "HM_W")},
                    "POST_CLK": post_clk, "CLK_PER_SAMPLE": cps, **(params_extra or {})},
        extra_env=env,
        testcase=testcase,
        build_args=build_args(sim),
    )


@pytest.mark.parametrize("cfg_name,cps", [("small", 3), ("medium", 1)])
def test_fmt_rx_array(sim, cfg_name, cps):
    """All tests at ce = 1 (the latency test also at 1 in 3).  small: the default
    CLK_PER_SAMPLE = 3 (MAG_UNITS 1, enough for ce = 1 too at 6 columns); medium:
    CLK_PER_SAMPLE = 1 (MAG_UNITS 3)."""
    _run(sim, cfg_name, cps=cps)


def test_fmt_rx_array_medium_cps3(sim):
    """medium at CLK_PER_SAMPLE = 3 (MAG_UNITS 1): every row's beat at 3 x fs."""
    if sim == "verilator" and not env_int("FMT_RX_FULL", 0):
        pytest.skip("Icarus covers this variant (test time); FMT_RX_FULL=1 adds Verilator")
    _run(sim, "medium", {"EVERY_LIST": "3"}, testcase="latency_and_slow_ce")


def test_fmt_rx_array_overrun(sim):
    """small rows and N with 30 columns and ONE magnitude unit (P = 30 steps a row: fits
    3 x fs, not ce = 1): the sticky overrun flag."""
    if sim == "verilator" and not env_int("FMT_RX_FULL", 0):
        pytest.skip("Icarus covers this variant (test time); FMT_RX_FULL=1 adds Verilator")
    _run(sim, "small", {"OVERRUN": 1, "COLS": 30}, testcase="overrun_flag",
         params_extra={"COLS": 30, "MAG_UNITS": 1})


def test_fmt_rx_array_post_on_ce(sim):
    """POST_CLK = 0 (the back end advances on ce): exact and its latency, small size."""
    _run(sim, "small", testcase="latency_and_slow_ce", post_clk=0)


@pytest.mark.verilator_only
@pytest.mark.long_only       # make test: small and medium; fmt_core_default also covers 30 x 40
def test_fmt_rx_array_default(sim):
    """Full 30 x 40, N = 256 at the real clocking: ce = 1 in 3, CLK_PER_SAMPLE = 3
    (MAG_UNITS 4): bit-exact (M = 1, 3), latency, hard cases."""
    _run(sim, "default", {"M_LIST": "1,3", "FRAMES": 1, "CE_EVERY": 3, "EVERY_LIST": "3"})



@pytest.mark.verilator_only
def test_replay_rx_script(sim):
    """scripts/replay_rx.py on a small generated capture (PN on, M = 2), through the
    core's structure at 3 clk per sample (FFT_CH 3), equals rx_fixed."""
    import importlib.util
    cfg = params.SMALL
    rng = np.random.default_rng(31)
    s = 4 * cfg.n_fft
    tx, rx, _ = rx_stim.pn(cfg, s, rng, enable=True, chip_len=2, delay=0)
    adc = rx_stim.tones(cfg, s, rng, tx=tx)
    d = ROOT / "build" / "replay_test"
    d.mkdir(parents=True, exist_ok=True)
    np.save(d / "cap.npy", adc)
    np.save(d / "sign.npy", rx)
    spec = importlib.util.spec_from_file_location("replay_rx", ROOT / "scripts" / "replay_rx.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rc = mod.main(["--in", str(d / "cap.npy"), "--out", str(d / "hm.npy"), "--config", "small",
                   "--m", "2", "--sign", str(d / "sign.npy"), "--cps", "3", "--check"])
    assert rc == 0
    hm = np.load(d / "hm.npy")
    exp, _, _ = R.rx_heatmaps_fixed(adc, rx, cfg, 1)
    assert hm.shape == (2, cfg.rows, cfg.cols) and np.array_equal(hm, exp)

