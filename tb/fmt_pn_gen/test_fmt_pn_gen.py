"""cocotb testbench of rtl/fmt_pn_gen.v against its twin sim/fmt/pn_gen.py.

Checks, under both simulators and for several LFSR lengths: bit-exact transmit and
receive signs for random chip lengths and delays, the enable switch, the maximal
period 2^L - 1 and the balance of one period (2^(L-1) ones, 2^(L-1) - 1 zeros),
chip length changes at run time, a reset in the middle of a chip, and the sample
strobe: with ce high one clk in C (C = 3, as at 3 x fs) or at random, the signs seen at
the ce edges are the same sequence and nothing changes between ce edges.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt import params
from fmt.pn_gen import MAXIMAL_TAPS, pn_signs


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.bits = env_int("PN_BITS", 15)
        self.chip_w = env_int("CHIP_W", 10)
        self.delay_w = env_int("DELAY_W", 6)
        dut.ce.value = 1
        dut.enable_i.value = 1
        dut.chip_len_i.value = 1
        dut.rx_delay_i.value = 0

    async def capture(self, n: int):
        """tx/rx/chip_start of the next n samples (sample 0 = first edge after reset)."""
        tx = np.zeros(n, dtype=np.uint8)
        rx = np.zeros(n, dtype=np.uint8)
        cs = np.zeros(n, dtype=np.uint8)
        for i in range(n):
            await RisingEdge(self.clk)
            await ReadOnly()
            tx[i] = int(self.dut.tx_sign_o.value)
            rx[i] = int(self.dut.rx_sign_o.value)
            cs[i] = int(self.dut.chip_start_o.value)
        return tx, rx, cs


@cocotb.test()
async def bit_exact_random_settings(dut):
    """Random chip lengths and delays: tx and rx signs equal the model's."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    for trial in range(4):
        chip_len = rng.choice([0, 1, 2, 3, rng.randrange(1, 1 << tb.chip_w)])
        delay = rng.randrange(0, 1 << tb.delay_w)
        await tb.writable()
        dut.chip_len_i.value = chip_len
        dut.rx_delay_i.value = delay
        await tb.reset()
        n = 300
        tx, rx, cs = await tb.capture(n)
        mtx, mrx = pn_signs(n, chip_len=chip_len, rx_delay=delay, bits=tb.bits)
        assert np.array_equal(tx, mtx), f"tx mismatch trial {trial} chip_len={chip_len}"
        assert np.array_equal(rx, mrx), f"rx mismatch trial {trial} delay={delay}"
        cl = max(1, chip_len)
        assert np.array_equal(np.flatnonzero(cs), np.arange(0, n, cl)), "chip_start pulses"


@cocotb.test()
async def enable_off_gives_plus_one(dut):
    """PN off: both signs stay 0 (multiply by +1); back on, the sequence is where a
    free-running LFSR would be (the generator never stops)."""
    tb = TB(dut)
    dut.chip_len_i.value = 2
    dut.rx_delay_i.value = 3
    dut.enable_i.value = 0
    await tb.reset()
    tx, rx, _ = await tb.capture(50)
    assert not tx.any() and not rx.any()
    await tb.writable()
    dut.enable_i.value = 1
    await RisingEdge(tb.clk)          # sample 50 is computed with enable already 1
    tx2, _, _ = await tb.capture(100)
    mtx, _ = pn_signs(151, chip_len=2, bits=tb.bits)
    assert np.array_equal(tx2, mtx[51:151])


@cocotb.test()
async def period_and_balance(dut):
    """Maximal length: the chip sequence repeats after exactly 2^L - 1 chips and one
    period holds 2^(L-1) ones."""
    tb = TB(dut)
    period = (1 << tb.bits) - 1
    dut.chip_len_i.value = 1
    await tb.reset()
    tx, _, _ = await tb.capture(period + 64)
    assert int(tx[:period].sum()) == 1 << (tb.bits - 1), "balance of one period"
    assert np.array_equal(tx[period:], tx[:64]), "sequence repeats after 2^L-1 chips"
    # and not earlier: no shorter period divides 2^L - 1 here
    for p in range(1, period):
        if period % p == 0 and np.array_equal(tx[p:p + 64], tx[:64]):
            assert False, f"shorter period {p}"


@cocotb.test()
async def reset_mid_chip(dut):
    """A reset in the middle of a chip restarts the sequence from the seed."""
    tb = TB(dut)
    dut.chip_len_i.value = 7
    await tb.reset()
    await tb.cycles(17)           # mid-chip
    dut.chip_len_i.value = 7
    await tb.reset(cycles=1)
    tx, _, _ = await tb.capture(80)
    mtx, _ = pn_signs(80, chip_len=7, bits=tb.bits)
    assert np.array_equal(tx, mtx)


@cocotb.test()
async def sample_strobe(dut):
    """ce every 3rd clk, then at random: the outputs after each ce edge follow the model
    sample by sample (chip length and delay in samples) and hold between ce edges."""
    tb = TB(dut)
    rng = random.Random(11)
    for mode in ("every3", "random"):
        chip_len, delay = rng.randrange(1, 6), rng.randrange(0, 1 << tb.delay_w)
        await tb.writable()
        dut.chip_len_i.value = chip_len
        dut.rx_delay_i.value = delay
        dut.ce.value = 0
        await tb.reset()
        n = 240
        tx = np.zeros(n, dtype=np.uint8)
        rx = np.zeros(n, dtype=np.uint8)
        k, t = 0, 0
        held = None
        while k < n:
            ce = (t % 3 == 0) if mode == "every3" else (rng.random() < 0.4)
            await tb.writable()
            dut.ce.value = int(ce)
            await RisingEdge(tb.clk)
            await ReadOnly()
            now = (int(dut.tx_sign_o.value), int(dut.rx_sign_o.value), int(dut.chip_start_o.value))
            if ce:
                tx[k], rx[k] = now[0], now[1]
                k += 1
            elif held is not None:
                assert now == held, f"{mode}: output changed without ce at clk {t}"
            held = now
            t += 1
        mtx, mrx = pn_signs(n, chip_len=chip_len, rx_delay=delay, bits=tb.bits)
        assert np.array_equal(tx, mtx), f"{mode}: tx mismatch chip_len={chip_len}"
        assert np.array_equal(rx, mrx), f"{mode}: rx mismatch delay={delay}"
    await tb.writable()
    dut.ce.value = 1


# ---- pytest entry ------------------------------------------------------------------
@pytest.mark.parametrize("pn_bits", [7, params.DEFAULT.pn_bits])
def test_fmt_pn_gen(sim, pn_bits):
    chip_w, delay_w = 10, 6
    run_cocotb(
        sim=sim,
        toplevel="fmt_pn_gen",
        sources=sources("fmt_pn_gen"),
        test_module="test_fmt_pn_gen",
        test_dir=Path(__file__).parent,
        parameters={"PN_BITS": pn_bits, "TAPS": MAXIMAL_TAPS[pn_bits],
                    "CHIP_W": chip_w, "DELAY_W": delay_w},
        extra_env={"PN_BITS": pn_bits, "CHIP_W": chip_w, "DELAY_W": delay_w},
    )
