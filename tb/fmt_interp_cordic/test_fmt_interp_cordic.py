"""cocotb testbench of rtl/fmt_interp_cordic.v (vectoring CORDIC) against
fmt.interp.cordic_fixed, bit for bit, on random vectors in all four quadrants, the axes,
zero and the extreme input values; and the model against atan2 / hypot (angle within
atan(2^-11) + table rounding + N / |(u, v)| of truncation, magnitude / K within 2^-10 relative + 4 LSB)."""
from __future__ import annotations

import math
import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt.interp import CORDIC_K, cordic_fixed

N = 12


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.iw = env_int("IW", 21)
        dut.valid_i.value = 0
        dut.u_i.value = 0
        dut.v_i.value = 0


def vectors(rng, iw, n):
    lo, hi = -(1 << (iw - 1)), (1 << (iw - 1)) - 1
    out = [(0, 0), (hi, 0), (lo, 0), (0, hi), (0, lo), (lo, lo), (hi, hi), (lo, hi), (hi, lo),
           (-1, 0), (-1, -1), (1, -1)]
    while len(out) < n:
        s = rng.choice([4, 8, 12, iw - 1])
        out.append((rng.randrange(-(1 << s), 1 << s) if s < iw - 1 else rng.randrange(lo, hi + 1),
                    rng.randrange(-(1 << s), 1 << s) if s < iw - 1 else rng.randrange(lo, hi + 1)))
    return out


@cocotb.test()
async def bit_exact_stream(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    await tb.reset()
    vec = vectors(rng, tb.iw, 500)
    got = []

    async def mon():
        while True:
            await RisingEdge(tb.clk)
            await ReadOnly()
            if int(dut.valid_o.value):
                got.append((int(dut.mag_o.value), int(dut.ang_o.value)))
    cocotb.start_soon(mon())
    for u, v in vec:
        await tb.writable()
        dut.valid_i.value = 1
        dut.u_i.value = u
        dut.v_i.value = v
    await tb.writable()
    dut.valid_i.value = 0
    await tb.cycles(N + 4)
    assert len(got) == len(vec)
    for (u, v), g in zip(vec, got):
        assert g == cordic_fixed(u, v), f"({u}, {v}): rtl {g}, model {cordic_fixed(u, v)}"
    # the model against exact atan2 / hypot on vectors that are not tiny
    for u, v in vec:
        r = math.hypot(u, v)
        if r < 1000:
            continue
        # residual of the last iteration + table rounding + ~1 LSB truncation per step
        tol = math.atan(2.0 ** -(N - 1)) + N * math.pi / 65536 + N / r
        mag, ang = cordic_fixed(u, v)
        d = (ang * 2 * math.pi / 65536 - math.atan2(v, u) + math.pi) % (2 * math.pi) - math.pi
        assert abs(d) <= tol, f"angle error {d} at ({u}, {v})"
        assert abs(mag / CORDIC_K - r) <= r * 2 ** -10 + 4, f"magnitude {mag / CORDIC_K} vs {r}"


@pytest.mark.parametrize("iw", [21])
def test_fmt_interp_cordic(sim, iw):
    run_cocotb(sim, "fmt_interp_cordic", sources("fmt_interp_cordic"), "test_fmt_interp_cordic",
               parameters={"IW": iw, "N": N}, extra_env={"IW": iw},
               test_dir=Path(__file__).parent,
               build_args=["--output-split", "0", "-CFLAGS", "-O0"] if sim == "verilator" else [])
