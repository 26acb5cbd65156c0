"""cocotb testbench of rtl/fmt_despread.v against sim/fmt/dds_bank.py despread_fixed.

Checks, under both simulators (ADC_BITS 12; ADC_BITS 7 under Icarus, Verilator too
with FMT_DDS_FULL=1): the extreme -2^(B-1) x -1 =
+2^(B-1) (no overflow in B + 1 bits), the full-scale corners, random samples and signs
with a random ce pattern (the output holds when ce = 0, latency 1 sample), and reset.
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
from fmt.dds_bank import despread_fixed
from fmt_dds_bank.dds_driver import skip_extra_verilator_build


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.bits = env_int("ADC_BITS", 12)
        dut.ce.value = 1
        dut.adc_i.value = 0
        dut.sign_i.value = 0

    async def drive(self, xs, signs, ces):
        """Apply one (x, sign, ce) per cycle from a writable phase; returns y_o after
        every edge."""
        out = []
        for i, (x, s, c) in enumerate(zip(xs, signs, ces)):
            if i:
                await self.writable()
            self.dut.adc_i.value = int(x) & ((1 << self.bits) - 1)
            self.dut.sign_i.value = int(s)
            self.dut.ce.value = int(c)
            await RisingEdge(self.clk)
            await ReadOnly()
            out.append(self.dut.y_o.value.to_signed())
        await self.writable()
        return np.array(out, dtype=np.int64)


def expected(xs, signs, ces, y0=0):
    """y after each edge: the despread input of the last edge with ce = 1."""
    d = despread_fixed(xs, signs)
    out, y = [], y0
    for v, c in zip(d, ces):
        if c:
            y = int(v)
        out.append(y)
    return np.array(out, dtype=np.int64)


@cocotb.test()
async def extremes(dut):
    tb = TB(dut)
    await tb.reset()
    lo, hi = -(1 << (tb.bits - 1)), (1 << (tb.bits - 1)) - 1
    xs = [lo, lo, hi, hi, 0, -1, 1]
    ss = [1, 0, 1, 0, 1, 1, 1]
    y = await tb.drive(xs, ss, [1] * len(xs))
    assert y[0] == 1 << (tb.bits - 1), f"-2^(B-1) x -1 gave {y[0]}"
    assert y.tolist() == [1 << (tb.bits - 1), lo, -hi, hi, 0, 1, -1]


@cocotb.test()
async def random_with_ce(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 3))
    await tb.reset()
    n = 400
    lo, hi = -(1 << (tb.bits - 1)), (1 << (tb.bits - 1)) - 1
    xs = [rng.choice([lo, hi, rng.randint(lo, hi)]) for _ in range(n)]
    ss = [rng.getrandbits(1) for _ in range(n)]
    cs = [int(rng.random() < 0.6) for _ in range(n)]
    y = await tb.drive(xs, ss, cs)
    assert np.array_equal(y, expected(xs, ss, cs)), "despread mismatch"
    assert sum(cs) < n and len(set(y.tolist())) > 10
    # reset clears the output whatever ce is
    await tb.writable()
    dut.ce.value = 0
    await tb.reset(cycles=2)
    await ReadOnly()
    assert dut.y_o.value.to_signed() == 0


@pytest.mark.parametrize("adc_bits", [params.DEFAULT.adc_bits, 7])
def test_fmt_despread(sim, adc_bits):
    skip_extra_verilator_build(sim, adc_bits != params.DEFAULT.adc_bits)
    run_cocotb(
        sim=sim,
        toplevel="fmt_despread",
        sources=sources("fmt_despread"),
        test_module="test_fmt_despread",
        test_dir=Path(__file__).parent,
        parameters={"ADC_BITS": adc_bits},
        extra_env={"ADC_BITS": adc_bits},
        build_args=["-CFLAGS", "-O0"] if sim == "verilator" else [],   # compile time dominates
    )
