"""cocotb testbench of rtl/fmt_latency.v against its twin sim/fmt/latency.py.

Random but causal traffic: frame ends every P cycles, each frame's 0..4 events leave
the port after a random delay longer than a frame period (frames overlap, as they do
at M = 1), external triggers, a statistics clear, and a reset in the middle.  Every
output is compared with the model on every cycle, the histograms at the end.  A
directed test checks absolute numbers worked out by hand.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt.latency import LatencyCounters

OUTS = ["first_last", "first_min", "first_max", "first_count", "last_last", "last_min",
        "last_max", "last_count", "trig_last", "trig_min", "trig_max", "trig_count",
        "trig_armed", "sat"]
INS = ["clear", "frame_end", "frame_end_slot", "ev_fire", "ev_slot", "ev_last", "ev_new", "trig"]


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.model = LatencyCounters(cnt_w=env_int("CNT_W", 16), num_w=env_int("NUM_W", 32),
                                     hist_shift=env_int("HIST_SHIFT", 5))
        for n in INS:
            getattr(dut, f"{n}_i").value = 0
        dut.hist_sel_i.value = 0
        dut.hist_addr_i.value = 0

    async def run(self, stim: list[dict]):
        """Drive one dict of inputs per cycle; compare outputs after each edge."""
        for cyc, s in enumerate(stim):
            await self.writable()
            for n in INS:
                getattr(self.dut, f"{n}_i").value = s.get(n, 0)
            await RisingEdge(self.clk)
            exp = self.model.step(**{n: s.get(n, 0) for n in INS})
            await ReadOnly()
            for n in OUTS:
                got = int(getattr(self.dut, f"{n}_o").value)
                assert got == exp[n], f"cycle {cyc}: {n} = {got}, model {exp[n]}"

    async def hist(self, sel: int, addr: int) -> int:
        await self.writable()
        self.dut.hist_sel_i.value = sel
        self.dut.hist_addr_i.value = addr
        await RisingEdge(self.clk)
        self.model.step()          # the clock edge also advances the model
        await ReadOnly()
        return int(self.dut.hist_data_o.value)


def traffic(rng: random.Random, n_frames: int, period: int, lat_lo: int, lat_hi: int):
    """Per-cycle stimulus: frame ends every `period` cycles, events later."""
    n = n_frames * period + lat_hi + 20
    stim = [dict() for _ in range(n)]
    busy = set()
    for f in range(n_frames):
        t_end = 5 + f * period
        stim[t_end].update(frame_end=1, frame_end_slot=f & 3)
        k = rng.randrange(0, 5)
        t = t_end + rng.randrange(lat_lo, lat_hi)
        for e in range(k):
            while t in busy:
                t += 1
            busy.add(t)
            stim[t].update(ev_fire=1, ev_slot=f & 3, ev_last=int(e == k - 1), ev_new=rng.randrange(2))
            t += rng.randrange(1, 4)
    for _ in range(n_frames // 2):
        t = rng.randrange(0, n - 10)
        for j in range(rng.randrange(1, 6)):
            stim[t + j]["trig"] = 1
    return stim


@cocotb.test()
async def random_traffic_matches_model(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 7))
    await tb.reset()
    tb.model.reset()
    stim = traffic(rng, 60, 48, 30, 90)
    stim[len(stim) // 2]["clear"] = 1
    await tb.run(stim)
    await check_hists(tb, "random traffic")
    assert tb.model.out["first_count"] > 5 and tb.model.out["trig_count"] > 0, "traffic too thin"
    # reset in the middle of traffic: model and RTL restart together
    await tb.reset()
    tb.model.reset()
    await tb.run(traffic(rng, 20, 48, 30, 90))


@cocotb.test()
async def directed_numbers(dut):
    """Frame end at cycle 0; events at +100 (first), +103, +110 (last): first = 100,
    last = 110; a trigger 50 cycles before a new-contact event reads 50."""
    tb = TB(dut)
    await tb.reset()
    tb.model.reset()
    stim = [dict() for _ in range(200)]
    stim[0].update(frame_end=1, frame_end_slot=1)
    stim[100].update(ev_fire=1, ev_slot=1, ev_new=0)
    stim[103].update(ev_fire=1, ev_slot=1)
    stim[110].update(ev_fire=1, ev_slot=1, ev_last=1)
    stim[140].update(trig=1)
    stim[141].update(trig=1)
    stim[190].update(ev_fire=1, ev_slot=1, ev_new=1, ev_last=1)
    await tb.run(stim)
    d = tb.dut
    assert int(d.first_last_o.value) == 100
    assert int(d.last_min_o.value) == 110 and int(d.last_max_o.value) == 190
    assert int(d.first_count_o.value) == 1 and int(d.last_count_o.value) == 2
    assert int(d.trig_last_o.value) == 50 and int(d.trig_count_o.value) == 1
    assert int(d.sat_o.value) == 0


async def check_hists(tb, what: str):
    for sel, name in ((0, "first"), (1, "last")):
        for a in range(16):
            exp = tb.model.hist[name][a]
            got = await tb.hist(sel, a)
            assert got == exp, f"{what}: hist {name}[{a}] = {got}, model {exp}"


@cocotb.test()
async def histogram_back_to_back_and_clear(dut):
    """The histograms are RAMs with a pipelined read-modify-write (forwarding): first/last
    events of four frames on four consecutive cycles into the same bin (and the next cycle into
    another bin) must all count; a clear makes every bin read 0 at once (read right
    after the clear cycle), and bins count from 0 again afterwards.  The frame-end
    time stamps (also a RAM) read 0 after a reset until their slot's frame end."""
    tb = TB(dut)
    await tb.reset()
    tb.model.reset()
    # an event before any frame end since the reset: its slot's stamp reads 0 (the RAM
    # still holds stamps of the previous test).  Absolute time matters here: tb.reset()
    # returns at a falling edge and run() waits for the next one, so the RTL sees one
    # rising edge with rst low and idle inputs before the first stimulus cycle.
    tb.model.step()
    await tb.run([dict(ev_fire=1, ev_slot=2, ev_last=1) if t == 20 else dict() for t in range(24)])
    assert tb.model.hist["last"][0] == 1 and tb.model.out["last_count"] == 1
    stim = [dict() for _ in range(400)]
    for f in range(4):
        stim[f].update(frame_end=1, frame_end_slot=f)
    for f in range(4):                                   # latency 100 each: one bin
        stim[100 + f].update(ev_fire=1, ev_slot=f, ev_last=1)
    for f in range(4):
        stim[200 + f].update(frame_end=1, frame_end_slot=f)
    stim[200 + 100].update(ev_fire=1, ev_slot=0, ev_last=0)     # first of slot 0: 100
    stim[200 + 101].update(ev_fire=1, ev_slot=1, ev_last=1)     # first+last of slot 1
    stim[200 + 102].update(ev_fire=1, ev_slot=0, ev_last=1)     # last of slot 0: 102
    stim[200 + 140].update(ev_fire=1, ev_slot=2, ev_last=1)     # 3rd bin, other latency
    await tb.run(stim)
    assert tb.model.hist["first"][3] == 6 and tb.model.hist["last"][3] == 6   # stimulus sanity
    await check_hists(tb, "before clear")
    await tb.run([dict(clear=1)])
    assert sum(tb.model.hist["first"]) == 0
    await check_hists(tb, "after clear")
    stim = [dict() for _ in range(150)]
    stim[0].update(frame_end=1, frame_end_slot=3)
    stim[120].update(ev_fire=1, ev_slot=3, ev_last=1)
    await tb.run(stim)
    assert tb.model.hist["last"][120 >> 5] == 1
    await check_hists(tb, "after clear and one event")


@cocotb.test()
async def saturation_is_flagged(dut):
    """A latency beyond 2^CNT_W - 1 reads as the maximum and sets the sticky flag
    (the model's saturation is checked in sim/tests/test_latency.py)."""
    tb = TB(dut)
    await tb.reset()
    cmax = (1 << env_int("CNT_W", 16)) - 1
    await tb.writable()
    dut.frame_end_i.value = 1
    await tb.writable()
    dut.frame_end_i.value = 0
    await ClockCycles(tb.clk, cmax + 5)
    await tb.writable()
    dut.ev_fire_i.value = 1
    dut.ev_last_i.value = 1
    await tb.writable()
    dut.ev_fire_i.value = 0
    await RisingEdge(tb.clk)       # the statistics take the event one cycle after it
    await ReadOnly()
    assert int(dut.first_last_o.value) == cmax and int(dut.last_last_o.value) == cmax
    assert int(dut.sat_o.value) == 1


# num_w = 3: event counters and histogram bins saturate at 7 (sticky flag, no wrap)
@pytest.mark.parametrize("cnt_w, num_w", [(8, 32), (16, 32), (8, 3)])
def test_fmt_latency(sim, cnt_w, num_w):
    run_cocotb(sim=sim, toplevel="fmt_latency", sources=sources("fmt_latency"),
               test_module="test_fmt_latency", test_dir=Path(__file__).parent,
               parameters={"CNT_W": cnt_w, "NUM_W": num_w},
               extra_env={"CNT_W": cnt_w, "NUM_W": num_w})
