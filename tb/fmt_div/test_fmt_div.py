"""cocotb testbench of rtl/fmt_div.v (pipelined restoring divider) against
fmt.interp.div_fixed: random operands on every cycle (quotients across the whole range,
overflow, den = 0, den = 1, num = 0, extreme widths), the valid strobe and its latency
QW + 1, checked against Python's exact integer division."""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt.interp import div_fixed


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.nw, self.dw, self.qw = env_int("NUM_W", 32), env_int("DEN_W", 24), env_int("QW", 9)
        dut.valid_i.value = 0
        dut.num_i.value = 0
        dut.den_i.value = 0


def operands(rng, nw, dw, qw):
    den = rng.choice([0, 1, (1 << dw) - 1, rng.randrange(1, 1 << dw), min(rng.randrange(1, 256), (1 << dw) - 1)])
    kind = rng.random()
    if kind < 0.6 and den:
        q = rng.randrange(1 << qw)                          # a quotient in range
        num = min(q * den + rng.randrange(den), (1 << nw) - 1)
    elif kind < 0.8:
        num = rng.randrange(1 << nw)
    else:
        num = rng.choice([0, (1 << nw) - 1, den << qw if den << qw < 1 << nw else 0])
    return num, den


@cocotb.test()
async def random_stream(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    await tb.reset()
    n = 600
    ins = [operands(rng, tb.nw, tb.dw, tb.qw) if rng.random() < 0.85 else None for _ in range(n)]
    got = []

    cyc = [0]

    async def mon():
        while True:
            await RisingEdge(tb.clk)
            await ReadOnly()
            cyc[0] += 1
            if int(dut.valid_o.value):
                got.append((cyc[0], int(dut.quot_o.value), int(dut.ovf_o.value)))
    cocotb.start_soon(mon())
    exp = []
    for op in ins:
        await tb.writable()
        dut.valid_i.value = int(op is not None)
        if op is not None:
            dut.num_i.value, dut.den_i.value = op
            q, ovf = div_fixed(op[0], op[1], tb.qw) if op[1] else ((1 << tb.qw) - 1, True)
            exp.append((cyc[0] + 1, q, int(ovf)))      # the edge that samples it
    await tb.writable()
    dut.valid_i.value = 0
    await tb.cycles(tb.qw + 4)
    assert len(got) == len(exp)
    n_ovf = 0
    for (ce, qe, oe), (cg, qg, og) in zip(exp, got):
        assert (qg, og) == (qe, oe), f"quotient/overflow {qg, og}, expected {qe, oe}"
        assert cg + 1 - ce == tb.qw + 1, f"latency {cg + 1 - ce}"
        n_ovf += oe
    assert 0 < n_ovf < len(exp)


@pytest.mark.parametrize("widths", [(51, 42, 9), (12, 6, 4)], ids=lambda w: "x".join(map(str, w)))
def test_fmt_div(sim, widths):
    nw, dw, qw = widths
    run_cocotb(sim, "fmt_div", sources("fmt_div"), "test_fmt_div",
               parameters={"NUM_W": nw, "DEN_W": dw, "QW": qw},
               extra_env={"NUM_W": nw, "DEN_W": dw, "QW": qw},
               test_dir=Path(__file__).parent,
               build_args=["--output-split", "0", "-CFLAGS", "-O0"] if sim == "verilator" else [])
