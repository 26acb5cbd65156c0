"""cocotb testbench of rtl/fmt_dds_bank.v against its twin sim/fmt/dds.py.

Checks, under both simulators, for ROWS_PER_ENGINE R = 1 (one engine per row, a random
ce pattern) and R = 3 (time-multiplexed engines, ce every third clk at a random phase):
- bit-exact against ``dds_bank_fixed`` with random tuning words (exact bins and
  arbitrary 32-bit words), amplitudes and enables written at random clk cycles (also
  between ce strobes), random PN signs changing on every clk (only the value at a ce
  edge counts), writes that must be ignored (sel 3, rows >= ROWS) and a reset at a
  random point of the sample period (with writes pending just before it); dac_o
  changes at ce edges only; R > 1: the simulation-time ce check stays silent
  (SMALL and MEDIUM sizes; SMALL under Icarus only unless FMT_DDS_FULL=1, to keep the
  Verilator builds few);
- phase continuity: a row disabled and enabled again continues its phase;
- R > 1: the ce check counts a strobe that comes early and one that is missing;
- exact comb: with the reset (exact-bin) tuning words every N-sample window of every
  row is identical, and the float twin is within the stated error bound;
- spectral purity measured from the RTL output (one window per row, FFT, worst spur in
  dBc) for SINE_BITS 10, 12, 16 (Icarus; Verilator too with FMT_DDS_FULL=1) with
  DAC_BITS = SINE_BITS + AMP_BITS (the table's own purity): worst spur <= -6 * SINE_BITS
  dBc per row; sum of all rows: worst non-comb bin <= -6 * SINE_BITS + 10 log10(ROWS)
  dBc relative to the weakest tone;
- the full 30-row bank at the default widths with R = 3 (Verilator only): bit-exact
  random run and the comb.
"""
from __future__ import annotations

import json
import math
import os
import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import RTL, rtl_sources, run_cocotb
from common.tb_util import ClockedTB, env_int, env_str
from fmt import dds, params

LATENCY = 2     # the word of sample k is on dac_o after ce edge k + LATENCY


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.sine_bits = env_int("SINE_BITS", self.cfg.sine_bits)
        self.dac_bits = env_int("DAC_BITS", self.cfg.dac_bits)
        self.table_addr = env_int("TABLE_ADDR", dds.TABLE_ADDR)
        self.rows = self.cfg.rows
        self.rpe = env_int("RPE", 1)       # ROWS_PER_ENGINE
        self.row_w = max(1, (self.rows - 1).bit_length())
        dut.ce.value = 1
        dut.cfg_we_i.value = 0
        dut.cfg_row_i.value = 0
        dut.cfg_sel_i.value = 0
        dut.cfg_data_i.value = 0
        if hasattr(dut, "tx_sign_i"):      # fmt_tx drives it from its PN generator
            dut.tx_sign_i.value = 0
        self.defaults()

    def defaults(self):
        tw, amp, en = dds.default_settings(self.cfg)
        self.tw, self.amp, self.en = tw.copy(), amp.copy(), en.copy()

    def words(self) -> np.ndarray:
        v = int(self.dut.dac_o.value)
        d = self.dac_bits
        w = np.array([(v >> (r * d)) & ((1 << d) - 1) for r in range(self.rows)], dtype=np.int64)
        return np.where(w >= 1 << (d - 1), w - (1 << d), w)

    def model(self, n, tw, amp, en, sign):
        return dds.dds_bank_fixed(n, tuning=tw, amp=amp, enable=en, tx_sign=sign, cfg=self.cfg,
                                  table_addr=self.table_addr, sine_bits=self.sine_bits,
                                  dac_bits=self.dac_bits)

    def ce_pattern(self, rng=None, p_ce=1.0):
        """ce per clk cycle t: R = 1: random with probability p_ce (rng) or always 1;
        R > 1: every R-th cycle from a random phase."""
        if self.rpe == 1:
            return lambda t: 1 if (rng is None or rng.random() < p_ce) else 0
        off = rng.randrange(self.rpe) if rng is not None else 0
        return lambda t: 1 if t >= off and (t - off) % self.rpe == 0 else 0

    async def run(self, n_samples, rng=None, p_ce=1.0, p_write=0.0, sign_fn=None, write_fn=None):
        """Drive clk cycles until n_samples ce edges have passed, starting in a writable
        phase (right after reset()); returns (settings per sample, observed words per ce
        edge).  Settings recorded for a ce edge are the register values before it.
        Writes: random (p_write per clk cycle) or write_fn(sample index, ce) ->
        (row, sel, data) or None.  Fails if dac_o changes at an edge without ce."""
        tws, amps, ens, signs, obs = [], [], [], [], []
        dut = self.dut
        ce_fn = self.ce_pattern(rng, p_ce)
        prev = self.words()
        self.since_ce = 0
        t = 0
        while len(obs) < n_samples:
            if t:
                await self.writable()
            ce = ce_fn(t)
            sign = sign_fn(t) if sign_fn else 0
            dut.ce.value = ce
            dut.tx_sign_i.value = sign
            w = write_fn(len(obs), ce) if write_fn else None
            write = w is not None or (rng is not None and rng.random() < p_write)
            dut.cfg_we_i.value = int(write)
            if ce:
                tws.append(self.tw.copy())
                amps.append(self.amp.copy())
                ens.append(self.en.copy())
                signs.append(sign)
            if w is not None:
                self.apply_write(*w)
            elif write:
                self.random_write(rng)
            await RisingEdge(self.clk)
            await ReadOnly()
            now = self.words()
            if ce:
                obs.append(now)
                self.since_ce = 0
            else:
                self.since_ce += 1
                assert np.array_equal(now, prev), f"dac_o changed at clk cycle {t} without ce"
            prev = now
            t += 1
            assert t < 4 * self.rpe * n_samples + 100, "too few ce strobes"
        await self.writable()
        dut.cfg_we_i.value = 0
        dut.ce.value = 1 if self.rpe == 1 else 0    # R > 1: ce stops (idle_ce continues it)
        return (np.array(tws), np.array(amps), np.array(ens), np.array(signs, dtype=np.int64),
                np.array(obs))

    async def idle_ce(self, n_cycles, rng):
        """n_cycles more clk cycles right after run(), ce continuing its pattern (the
        words are not checked), random writes; the last cycle writes, so that writes
        are pending in the bank when a reset follows."""
        dut = self.dut
        for t in range(n_cycles):
            if t:       # run() left us in the writable phase of the next cycle
                await self.writable()
            dut.ce.value = 1 if self.rpe == 1 else int((self.since_ce + 1 + t) % self.rpe == 0)
            dut.cfg_we_i.value = int(t == n_cycles - 1 or rng.random() < 0.3)
            self.random_write(rng)
            await RisingEdge(self.clk)
        await self.writable()
        dut.cfg_we_i.value = 0
        dut.ce.value = 1 if self.rpe == 1 else 0    # R > 1: ce stops until the reset

    def ce_errors(self) -> int:
        """The bank's simulation-time ce check (R > 1): errors counted so far."""
        bank = self.dut.u_dds if hasattr(self.dut, "u_dds") else self.dut   # fmt_tx wraps the bank
        return int(bank.ce_errors.value)

    def random_write(self, rng):
        dut = self.dut
        row = rng.randrange(0, 1 << self.row_w)
        sel = rng.choice([0, 0, 1, 1, 2, 2, 2, 3])
        if sel == 0:
            data = (self.cfg.tuning_word(rng.randrange(1, self.cfg.n_fft // 2)) if rng.random() < 0.5
                    else rng.getrandbits(self.cfg.phase_bits))
        elif sel == 1:
            data = rng.choice([0, 1, (1 << self.cfg.amp_bits) - 1, rng.getrandbits(self.cfg.amp_bits)])
        else:
            data = rng.getrandbits(self.cfg.phase_bits)   # enable takes bit 0 only
        self.apply_write(row, sel, data)

    def apply_write(self, row, sel, data):
        """Drive one settings write (cfg_we_i set by the caller) and track its effect."""
        dut = self.dut
        dut.cfg_row_i.value = row
        dut.cfg_sel_i.value = sel
        dut.cfg_data_i.value = data
        if row < self.rows:
            if sel == 0:
                self.tw[row] = data
            elif sel == 1:
                self.amp[row] = data
            elif sel == 2:
                self.en[row] = data & 1

    def check(self, tw, amp, en, sign, obs, what):
        n = len(obs)
        ref = self.model(n, tw, amp, en, sign)
        assert not obs[:LATENCY].any(), f"{what}: dac_o not 0 right after reset"
        got = obs[LATENCY:]
        exp = ref[:n - LATENCY]
        bad = np.argwhere(got != exp)
        assert bad.size == 0, (f"{what}: {len(bad)} mismatches, first at sample {bad[0][0]} row "
                               f"{bad[0][1]}: rtl {got[tuple(bad[0])]} model {exp[tuple(bad[0])]}")
        return ref


@cocotb.test()
async def bit_exact_random(dut):
    """Random settings written at random clk cycles, random PN signs, the ce pattern of
    R, resets at random points with writes pending: every word equals the fixed model's."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    err0 = tb.ce_errors()
    for seg in range(3):
        await tb.reset(cycles=[4, 1, 2][seg])
        tb.defaults()
        n = int(1.5 * tb.cfg.n_fft) + 3 * LATENCY
        res = await tb.run(n, rng=rng, p_ce=0.75, p_write=0.08,
                           sign_fn=lambda t: rng.getrandbits(1))
        tb.check(*res, what=f"segment {seg}")
        assert res[4].any(), "some output must be non-zero"
        assert tb.ce_errors() == err0, "the ce check fired on a regular ce"
        # a reset somewhere in the next sample period, writes pending in the bank
        await tb.idle_ce(rng.randrange(1, 3 * tb.rpe + 2), rng)


@cocotb.test()
async def enable_keeps_phase(dut):
    """A row turned off and on again continues its phase: its words after re-enable
    equal those of an undisturbed run (the accumulator kept running)."""
    tb = TB(dut)
    await tb.reset()
    tb.defaults()
    n = 3 * tb.cfg.n_fft // 2
    q, h = tb.cfg.n_fft // 4, tb.cfg.n_fft // 2

    def write_fn(k, ce):
        # in the clk cycle of ce edge q (resp. h): in effect from sample q + 1 (h + 1)
        if ce and k in (q, h):
            return (1, 2, 0 if k == q else 1)
        return None

    tw, amp, en, sign, obs = await tb.run(n, write_fn=write_fn)
    assert en[q + 1, 1] == 0 and en[h + 1, 1] == 1 and en[q, 1] == 1
    tb.check(tw, amp, en, sign, obs, what="enable toggles")
    got = obs[LATENCY:]
    ref = tb.model(n, None, None, None, 0)       # undisturbed: always enabled
    exp = ref[:n - LATENCY]
    assert not got[q + 1:h + 1, 1].any(), "disabled row must output 0"
    assert got[h + 1:, 1].any()
    assert np.array_equal(got[h + 1:, 1], exp[h + 1:, 1]), "phase continuity after re-enable"
    assert np.array_equal(got[:q + 1, 1], exp[:q + 1, 1])
    assert np.array_equal(np.delete(got, 1, axis=1), np.delete(exp, 1, axis=1)), "other rows"


@cocotb.test()
async def ce_check_fires(dut):
    """R > 1: the simulation-time check counts a ce that comes one cycle early and one
    that comes one cycle late (R = 1: nothing to check, any ce pattern is allowed)."""
    tb = TB(dut)
    if tb.rpe == 1:
        assert tb.ce_errors() == 0
        return
    await tb.reset()
    e0 = tb.ce_errors()
    R = tb.rpe
    pattern = [1] + [0] * (R - 1) + [1] + [0] * (R - 2) + [1] + [0] * R + [1] + [0] * (R - 1) + [1]
    counts = []
    for i, ce in enumerate(pattern):
        if i:       # reset() returns in the writable phase of the first cycle
            await tb.writable()
        dut.ce.value = ce
        await RisingEdge(tb.clk)
        await ReadOnly()
        counts.append(tb.ce_errors() - e0)
    await tb.writable()
    dut.ce.value = 0
    await RisingEdge(tb.clk)
    await ReadOnly()
    assert tb.ce_errors() - e0 == 2, f"expected 2 ce errors (early, late), counted {counts}"


@cocotb.test()
async def exact_comb_and_purity(dut):
    """Reset settings, PN off: every window of a row is identical (no leakage), equal
    to the fixed model, within the float bound; worst spur per row and of the comb."""
    tb = TB(dut)
    await tb.reset()
    tb.defaults()
    N = tb.cfg.n_fft
    n_win = 3
    res = await tb.run(n_win * N + LATENCY)
    ref = tb.check(*res, what="comb")
    words = res[4][LATENCY:LATENCY + n_win * N]
    for w in range(1, n_win):
        assert np.array_equal(words[w * N:(w + 1) * N], words[:N]), f"window {w} differs from window 0"
    flt = dds.dds_bank_float(n_win * N, cfg=tb.cfg, sine_bits=tb.sine_bits, dac_bits=tb.dac_bits)
    err = np.abs(words - flt).max()
    bound = dds.error_bound(tb.cfg, tb.table_addr, True, tb.sine_bits, tb.dac_bits)
    assert err <= bound, f"|rtl - float| = {err} > {bound}"
    # purity of the RTL words
    B = min(tb.sine_bits, tb.dac_bits)
    row_spur = max(dds.worst_spur_dbc(words[:N, r], [tb.cfg.bins[r]])[0] for r in range(tb.rows))
    comb_spur, k = dds.worst_spur_dbc(words[:N].sum(axis=1), tb.cfg.bins)
    row_bound = -6.0 * B
    comb_bound = row_bound + 10 * math.log10(tb.rows)
    dut._log.info("rows %d SINE_BITS %d DAC_BITS %d: worst row spur %.1f dBc (bound %.1f), "
                  "comb worst non-comb bin %.1f dBc at bin %d (bound %.1f), |rtl-float| %.3f LSB",
                  tb.rows, tb.sine_bits, tb.dac_bits, row_spur, row_bound, comb_spur, k, comb_bound, err)
    out = os.environ.get("DDS_PURITY_OUT")
    if out:     # scripts/dds_purity.py collects the measured numbers
        Path(out).write_text(json.dumps({
            "rows": tb.rows, "n_fft": N, "sine_bits": tb.sine_bits, "dac_bits": tb.dac_bits,
            "row_spur_dbc": row_spur, "row_bound_dbc": row_bound, "comb_spur_dbc": comb_spur,
            "comb_spur_bin": k, "comb_bound_dbc": comb_bound, "max_err_lsb": float(err),
            "err_bound_lsb": bound}))
    assert row_spur <= row_bound, f"row spur {row_spur:.1f} dBc > {row_bound}"
    assert comb_spur <= comb_bound, f"comb spur {comb_spur:.1f} dBc > {comb_bound:.1f}"


# ---- pytest entry ------------------------------------------------------------------
def skip_extra_verilator_build(sim: str, extra: bool) -> None:
    """Test-time budget: each Verilator build costs ~10 s of CPU.  Variants marked
    extra (the SMALL size, the SINE_BITS sweep, the second ADC width...) run under Icarus
    only, unless FMT_DDS_FULL=1; bit-exactness under Verilator is covered by the MEDIUM
    and DEFAULT builds of the same RTL."""
    if sim == "verilator" and extra and not os.environ.get("FMT_DDS_FULL"):
        pytest.skip("variant runs under Icarus; FMT_DDS_FULL=1 adds Verilator")


def build_args(sim: str) -> list[str]:
    """The sine tables' folder for $readmemh (simulators resolve paths from their
    working directory); for Verilator -O0: these runs are short, the C++ compile
    dominates their time."""
    args = [f'-DFMT_ROM_DIR="{RTL}/"']
    if sim == "verilator":
        args += ["-CFLAGS", "-O0"]
    return args


def _run(sim, cfg, sine_bits=None, dac_bits=None, testcase=None, rpe=1):
    sine_bits = cfg.sine_bits if sine_bits is None else sine_bits
    dac_bits = cfg.dac_bits if dac_bits is None else dac_bits
    p = cfg.verilog_params()
    parameters = {k: p[k] for k in ("ROWS", "LOG2_N", "BIN_LO", "BIN_STEP", "PHASE_BITS", "AMP_BITS")}
    parameters.update(SINE_BITS=sine_bits, DAC_BITS=dac_bits, TABLE_ADDR=dds.TABLE_ADDR,
                      ROWS_PER_ENGINE=rpe)
    run_cocotb(
        sim=sim,
        toplevel="fmt_dds_bank",
        sources=rtl_sources("fmt_dds_bank", "fmt_dds_chan", "fmt_dds_rom2"),
        test_module="test_fmt_dds_bank",
        test_dir=Path(__file__).parent,
        parameters=parameters,
        extra_env={"CFG": cfg.name, "SINE_BITS": sine_bits, "DAC_BITS": dac_bits,
                   "TABLE_ADDR": dds.TABLE_ADDR, "RPE": rpe},
        build_args=build_args(sim),
        testcase=testcase,
    )


@pytest.mark.parametrize("rpe", [1, 3], ids=lambda r: f"r{r}")
@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM], ids=lambda c: c.name)
def test_fmt_dds_bank(sim, cfg, rpe):
    """R = 1 and R = 3 (ROWS_PER_ENGINE); SMALL (4 rows: with R = 3 the second engine
    has one idle slot) under Icarus only unless FMT_DDS_FULL=1."""
    skip_extra_verilator_build(sim, cfg is params.SMALL)
    _run(sim, cfg, rpe=rpe)


@pytest.mark.parametrize("sine_bits", [10, 12, 16])
def test_fmt_dds_bank_purity(sim, sine_bits):
    """Table-width sweep (R = 1; the words do not depend on R).  Under Verilator only
    with FMT_DDS_FULL=1: three more C++ builds of the same RTL (bit-exactness under
    Verilator is covered above)."""
    skip_extra_verilator_build(sim, True)
    cfg = params.SMALL
    _run(sim, cfg, sine_bits=sine_bits, dac_bits=sine_bits + cfg.amp_bits,
         testcase="exact_comb_and_purity")


@pytest.mark.verilator_only
def test_fmt_dds_bank_default(sim):
    """The full 30-row bank as the core builds it (R = 3): random run and comb."""
    _run(sim, params.DEFAULT, rpe=3, testcase="bit_exact_random,exact_comb_and_purity")
