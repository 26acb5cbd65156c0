"""cocotb testbench of rtl/fmt_magnitude.v against magnitude_fixed (sim/fmt/rx_array.py).

Bit-exact magnitudes for random full-scale inputs, the extremes (-2^(W-1) on both axes,
axes, zero), the tag and valid path, ce gating (random ce pattern: the pipeline only
advances on ce) and the latency ITER + 3 ce cycles; the model test bounds the error
against the exact sqrt.
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
from fmt import rx_array as R


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.w = env_int("IN_W", 19)
        self.iters = env_int("ITER", 12)
        dut.ce.value = 0
        dut.in_valid_i.value = 0
        dut.in_re_i.value = 0
        dut.in_im_i.value = 0
        dut.in_tag_i.value = 0

    async def stream(self, re_, im_, ce_prob=1.0, rng=None):
        """Drive samples (one per ce), return [(ce_index_of_output, mag, tag)] and the
        ce index of each input."""
        dut = self.dut
        rng = rng or random.Random(1)
        outs, ce_idx, i, n = [], 0, 0, len(re_)
        lat = self.iters + 3
        in_at = []
        while i < n or ce_idx < (in_at[-1] if in_at else 0) + lat + 2:
            await self.writable()
            ce = 1 if rng.random() < ce_prob else 0
            dut.ce.value = ce
            if i < n:
                dut.in_valid_i.value = 1
                dut.in_re_i.value = int(re_[i])
                dut.in_im_i.value = int(im_[i])
                dut.in_tag_i.value = i & 0xFF
            else:
                dut.in_valid_i.value = 0
            await RisingEdge(self.clk)
            await ReadOnly()
            if ce:
                if i < n:
                    in_at.append(ce_idx)
                    i += 1
                ce_idx += 1
                if int(dut.out_valid_o.value):
                    outs.append((ce_idx, int(dut.out_mag_o.value), int(dut.out_tag_o.value)))
        return outs, in_at


async def run_vectors(tb, re_, im_, ce_prob):
    outs, in_at = await tb.stream(re_, im_, ce_prob)
    exp = R.magnitude_fixed(np.array(re_), np.array(im_), iters=tb.iters)
    assert len(outs) == len(re_), f"{len(outs)} outputs for {len(re_)} inputs"
    for j, (at, mag, tag) in enumerate(outs):
        assert mag == int(exp[j]), f"sample {j}: ({re_[j]}, {im_[j]}) rtl {mag} model {exp[j]}"
        assert tag == (j & 0xFF)
        assert at - in_at[j] == tb.iters + 3, f"latency {at - in_at[j]} ce cycles"


@cocotb.test()
async def random_and_extremes(dut):
    tb = TB(dut)
    await tb.reset()
    rng = np.random.default_rng(env_int("SEED", 5))
    w = tb.w
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    re_ = [lo, lo, hi, hi, 0, 0, lo, 1, -1, 0, 3, -3] + rng.integers(lo, hi + 1, 300).tolist()
    im_ = [lo, hi, lo, hi, lo, hi, 0, 0, 0, 0, -4, 4] + rng.integers(lo, hi + 1, 300).tolist()
    # small values (weak cells)
    re_ += rng.integers(-50, 51, 100).tolist()
    im_ += rng.integers(-50, 51, 100).tolist()
    await run_vectors(tb, re_, im_, 1.0)


@cocotb.test()
async def ce_gating(dut):
    """Random ce (1 in 3 on average, as at 3 x fs): same results, latency in ce cycles."""
    tb = TB(dut)
    await tb.reset()
    rng = np.random.default_rng(7)
    w = tb.w
    re_ = rng.integers(-(1 << (w - 1)), 1 << (w - 1), 60).tolist()
    im_ = rng.integers(-(1 << (w - 1)), 1 << (w - 1), 60).tolist()
    await run_vectors(tb, re_, im_, 0.35)


@cocotb.test()
async def reset_clears_valid(dut):
    tb = TB(dut)
    await tb.reset()
    await tb.writable()
    dut.ce.value = 1
    dut.in_valid_i.value = 1
    await tb.cycles(5)
    await tb.reset(cycles=1)
    dut.in_valid_i.value = 0
    dut.ce.value = 1
    seen = 0
    for _ in range(tb.iters + 6):
        await RisingEdge(tb.clk)
        await ReadOnly()
        seen += int(dut.out_valid_o.value)
    assert seen == 0, "samples in flight at reset must not come out"


@pytest.mark.parametrize("in_w", [13, 19])
def test_fmt_magnitude(sim, in_w):
    run_cocotb(
        sim=sim,
        toplevel="fmt_magnitude",
        sources=sources("fmt_magnitude"),
        test_module="test_fmt_magnitude",
        test_dir=Path(__file__).parent,
        parameters={"IN_W": in_w, "ITER": R.MAG_ITER, "GUARD": R.MAG_GUARD,
                    "GAIN_BITS": R.MAG_GAIN_BITS, "GAIN_C": R.cordic_gain_const(), "TAG_W": 8},
        extra_env={"IN_W": in_w, "ITER": R.MAG_ITER},
        build_args=["-CFLAGS", "-O0"] if sim == "verilator" else None,   # compile time dominates
    )
