"""Reusable parts of the fmt_dds_bank testbench: the bench class (:class:`TB`), the
build arguments and :func:`run`, which builds the bank and runs the cocotb tests of
test_fmt_dds_bank.py.  Used by tb/fmt_dds_bank, tb/fmt_tx, tb/fmt_despread,
tb/fmt_channel_sim and scripts/dds_purity.py (nothing imports a test module).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import rom_define, run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import dds_bank, params

LATENCY = 2     # the word of sample k is on dac_o after ce edge k + LATENCY


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.sine_bits = env_int("SINE_BITS", self.cfg.sine_bits)
        self.dac_bits = env_int("DAC_BITS", self.cfg.dac_bits)
        self.table_addr = env_int("TABLE_ADDR", dds_bank.TABLE_ADDR)
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
        tw, amp, en = dds_bank.default_settings(self.cfg)
        self.tw, self.amp, self.en = tw.copy(), amp.copy(), en.copy()

    def words(self) -> np.ndarray:
        v = int(self.dut.dac_o.value)
        d = self.dac_bits
        w = np.array([(v >> (r * d)) & ((1 << d) - 1) for r in range(self.rows)], dtype=np.int64)
        return np.where(w >= 1 << (d - 1), w - (1 << d), w)

    def model(self, n, tw, amp, en, sign):
        return dds_bank.dds_bank_fixed(n, tuning=tw, amp=amp, enable=en, tx_sign=sign, cfg=self.cfg,
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
    args = [rom_define()]
    if sim == "verilator":
        args += ["-CFLAGS", "-O0"]
    return args


def run(sim, cfg, sine_bits=None, dac_bits=None, testcase=None, rpe=1):
    """Build fmt_dds_bank at ``cfg``'s sizes (SINE_BITS, DAC_BITS, ROWS_PER_ENGINE as
    given) and run the cocotb tests of test_fmt_dds_bank.py (``testcase``: some of them)."""
    sine_bits = cfg.sine_bits if sine_bits is None else sine_bits
    dac_bits = cfg.dac_bits if dac_bits is None else dac_bits
    p = cfg.verilog_params()
    parameters = {k: p[k] for k in ("ROWS", "LOG2_N", "BIN_LO", "BIN_STEP", "PHASE_BITS", "AMP_BITS")}
    parameters.update(SINE_BITS=sine_bits, DAC_BITS=dac_bits, TABLE_ADDR=dds_bank.TABLE_ADDR,
                      ROWS_PER_ENGINE=rpe)
    run_cocotb(
        sim=sim,
        toplevel="fmt_dds_bank",
        sources=sources("fmt_dds_bank"),
        test_module="test_fmt_dds_bank",
        test_dir=Path(__file__).parent,
        parameters=parameters,
        extra_env={"CFG": cfg.name, "SINE_BITS": sine_bits, "DAC_BITS": dac_bits,
                   "TABLE_ADDR": dds_bank.TABLE_ADDR, "RPE": rpe},
        build_args=build_args(sim),
        testcase=testcase,
    )
