"""cocotb testbench of rtl/fmt_interp_div.v (pipelined non-restoring fraction divider)
against fmt.interp.div_fixed(mag << QW, den): random operands on every cycle (quotients
across the whole range, overflow mag >= den, den = 0, den = 1, mag = 0, full-width
operands) and the latency QW + 1."""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import env_int
from fmt.interp import div_fixed


def operands(rng, mw, dw, qw):
    den = rng.choice([0, 1, (1 << dw) - 1, rng.randrange(1, 1 << dw),
                      min(rng.randrange(1, 256), (1 << dw) - 1)])
    kind = rng.random()
    if kind < 0.6 and den:
        # a quotient in range: mag < den, floor(mag 2^qw / den) = q
        q = rng.randrange(1 << qw)
        mag = min(((q << qw) * den) >> (2 * qw) if den >> qw else rng.randrange(den), den - 1)
        mag = min(rng.randrange(den), (1 << mw) - 1) if rng.random() < 0.5 else mag
    elif kind < 0.8:
        mag = rng.randrange(1 << mw)
    else:
        mag = rng.choice([0, (1 << mw) - 1, min(den, (1 << mw) - 1), max(den - 1, 0)])
    return mag, den


@cocotb.test()
async def random_stream(dut):
    mw, dw, qw = env_int("MAG_W", 42), env_int("DEN_W", 42), env_int("QW", 9)
    cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
    dut.mag_i.value = 0
    dut.den_i.value = 0
    rng = random.Random(env_int("SEED", 1))
    ins = [operands(rng, mw, dw, qw) for _ in range(800)]
    got = []

    async def mon():
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            q, o = dut.quot_o.value, dut.ovf_o.value       # X until the pipeline fills
            got.append((int(q), int(o)) if q.is_resolvable and o.is_resolvable else None)
    await FallingEdge(dut.clk)
    cocotb.start_soon(mon())
    for op in ins:                      # operand i is sampled by the monitor's edge i + 1
        dut.mag_i.value, dut.den_i.value = op
        await FallingEdge(dut.clk)
    for _ in range(qw + 4):
        await FallingEdge(dut.clk)
    n_ovf = 0
    for i, (mag, den) in enumerate(ins):
        q, ovf = div_fixed(mag << qw, den, qw) if den else ((1 << qw) - 1, True)
        # its result is there after edge i + 1 + qw (latency qw + 1)
        assert got[i + qw] == (q, int(ovf)), f"operand {i} ({mag}, {den}): {got[i + qw]}, expected {(q, int(ovf))}"
        n_ovf += int(ovf)
    assert 0 < n_ovf < len(ins)


@pytest.mark.parametrize("widths", [(42, 42, 9), (16, 12, 4)], ids=lambda w: "x".join(map(str, w)))
def test_fmt_interp_div(sim, widths):
    mw, dw, qw = widths
    run_cocotb(sim, "fmt_interp_div", sources("fmt_interp_div"), "test_fmt_interp_div",
               parameters={"MAG_W": mw, "DEN_W": dw, "QW": qw},
               extra_env={"MAG_W": mw, "DEN_W": dw, "QW": qw},
               test_dir=Path(__file__).parent,
               build_args=["--output-split", "0", "-CFLAGS", "-O0"] if sim == "verilator" else [])
