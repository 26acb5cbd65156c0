"""cocotb testbench of rtl/ref/fmt_accum.v against accum_fixed (sim/fmt/rx_array.py).

Windows of per-row magnitudes (rows in a shuffled order, as the pair split emits them)
for M = 1, 2, 4, 8: the emitted cells are bit-exact (round half up, HM_SHIFT), only on
the last window of each frame, latency 2 ce cycles; large inputs saturate to 2^HM_W - 1
and raise the sticky flag, which small inputs never do; random ce.
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

LANES = 2


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.rows = env_int("ROWS", 4)
        self.d_w = env_int("D_W", 19)
        self.hm_w = env_int("HM_W", 16)
        self.hm_shift = env_int("HM_SHIFT", 1)
        for s in ("ce", "in_valid_i", "in_row_i", "in_data_i", "in_first_i", "in_last_i", "in_shift_i"):
            getattr(dut, s).value = 0

    async def run(self, mags, m_log2, order, ce_prob=1.0, rng=None):
        """mags (windows, rows, LANES); each window: rows in ``order`` then two idle
        beats.  Returns [(row, cells tuple, ce index)] and the input ce index per beat."""
        dut = self.dut
        rng = rng or random.Random(3)
        m = 1 << m_log2
        beats = []
        for w in range(mags.shape[0]):
            for r in order:
                beats.append((w, r))
            beats += [None, None]
        beats += [None] * 4
        outs, in_at, i, cei = [], {}, 0, 0
        while i < len(beats):
            await self.writable()
            ce = 1 if rng.random() < ce_prob else 0
            dut.ce.value = ce
            b = beats[i]
            if b is None:
                dut.in_valid_i.value = 0
            else:
                w, r = b
                dut.in_valid_i.value = 1
                dut.in_row_i.value = r
                dut.in_data_i.value = sum(int(mags[w, r, l]) << (l * self.d_w) for l in range(LANES))
                dut.in_first_i.value = int(w % m == 0)
                dut.in_last_i.value = int(w % m == m - 1)
                dut.in_shift_i.value = m_log2
            await RisingEdge(self.clk)
            await ReadOnly()
            if ce:
                if b is not None:
                    in_at[b] = cei
                cei += 1
                i += 1
                if int(dut.out_valid_o.value):
                    v = int(dut.out_data_o.value)
                    cells = tuple((v >> (l * self.hm_w)) & ((1 << self.hm_w) - 1) for l in range(LANES))
                    outs.append((int(dut.out_row_o.value), cells, cei))
        return outs, in_at


def model(mags, m_log2, hm_w, hm_shift):
    from fmt.rx_array import accum_fixed
    return accum_fixed(mags, m_log2, hm_w, hm_shift)


async def one_case(tb, m_log2, frames, big, ce_prob, seed):
    rng = np.random.default_rng(seed)
    m = 1 << m_log2
    hi = (1 << tb.d_w) if big else (1 << (tb.hm_w - 2))
    mags = rng.integers(0, hi, (frames * m, tb.rows, LANES))
    mags[0, 0, :] = (1 << tb.d_w) - 1 if big else 0
    order = list(range(tb.rows))
    random.Random(seed).shuffle(order)
    outs, in_at = await tb.run(mags, m_log2, order, ce_prob)
    exp, sat = model(mags, m_log2, tb.hm_w, tb.hm_shift)
    assert len(outs) == frames * tb.rows, f"{len(outs)} cells rows out, expected {frames * tb.rows}"
    for j, (r, cells, at) in enumerate(outs):
        f, pos = divmod(j, tb.rows)
        assert r == order[pos]
        assert cells == tuple(int(c) for c in exp[f, r]), f"frame {f} row {r}: {cells} vs {exp[f, r]}"
        assert at - in_at[(f * m + m - 1, r)] == 2, "latency 2 ce cycles"
    assert int(tb.dut.sat_o.value) == int(sat), f"sticky saturation flag {int(tb.dut.sat_o.value)} model {sat}"
    return sat


@cocotb.test()
async def m_sweep_exact(dut):
    tb = TB(dut)
    for m_log2 in range(0, env_int("M_LOG2_MAX", 3) + 1):
        await tb.reset()
        sat = await one_case(tb, m_log2, 3, False, 1.0, 10 + m_log2)
        assert not sat


@cocotb.test()
async def saturation_sticky(dut):
    tb = TB(dut)
    await tb.reset()
    sat = await one_case(tb, 1, 2, True, 1.0, 77)
    can_clip = tb.d_w - tb.hm_shift > tb.hm_w
    assert sat == can_clip, "full-scale inputs saturate exactly when D_W - HM_SHIFT > HM_W"
    await tb.cycles(20)                       # sticky: stays as it was
    assert int(dut.sat_o.value) == int(can_clip)
    await tb.reset()
    assert int(dut.sat_o.value) == 0


@cocotb.test()
async def random_ce(dut):
    tb = TB(dut)
    await tb.reset()
    await one_case(tb, 2, 2, False, 0.4, 5)


@pytest.mark.parametrize("rows,d_w", [(4, 19), (8, 14)])
def test_fmt_accum(sim, rows, d_w):
    p = {"ROWS": rows, "LANES": LANES, "D_W": d_w, "M_LOG2_MAX": 3, "HM_W": 16, "HM_SHIFT": 1}
    run_cocotb(
        sim=sim,
        toplevel="fmt_accum",
        sources=sources("fmt_accum"),
        test_module="test_fmt_accum",
        test_dir=Path(__file__).parent,
        parameters=p,
        extra_env={k: v for k, v in p.items() if k != "LANES"},
        build_args=["-CFLAGS", "-O0"] if sim == "verilator" else None,   # compile time dominates
    )
