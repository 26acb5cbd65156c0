"""cocotb testbench of rtl/fmt_event_port.v against its cycle twin sim/fmt/event_port.py.

Every handshake (cycle, all fields, ev_time, ev_last) and the final drop / skip
counters must equal the model's, for: dial delays 0, 1, 37, large and the loss-free
maximum (exact c + 5 + delay checked), report-rate decimation, random and long
consumer stalls with whole-frame drops, and a reset in the middle of a frame.  While
ev_valid is high and ev_ready low the output must hold.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import FallingEdge, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt import params
from fmt.event_port import FIXED_LATENCY, PortParams, frames_to_beats, run_port
from fmt.tracker import EV_TYPES, TouchEvent

FIELDS = ("ev_frame_o", "ev_time_o", "ev_id_o", "ev_type_o", "ev_x_o", "ev_y_o",
          "ev_strength_o", "ev_axis_major_o", "ev_axis_minor_o", "ev_angle_o",
          "ev_flags_o", "ev_last_o")


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.p = PortParams(depth=env_int("DEPTH", 64), max_ev=env_int("MAX_EV", 8))
        self.hm_w = env_int("HM_W", 16)
        d = dut
        d.in_valid_i.value = 0
        d.ev_ready_i.value = 1
        d.delay_i.value = 0
        d.report_period_i.value = 0
        for n in ("in_frame_i", "in_id_i", "in_type_i", "in_x_i", "in_y_i", "in_strength_i",
                  "in_axis_major_i", "in_axis_minor_i", "in_angle_i", "in_flags_i", "in_last_i"):
            getattr(d, n).value = 0

    async def run(self, beats, n, ready=None, delay=0, period=0, reset_at=()):
        """Drive n cycles from cycle 0 = the first cycle after reset; return handshakes
        as (cycle, field tuple)."""
        d = self.dut
        d.delay_i.value = delay
        d.report_period_i.value = period
        await self.reset()
        got = []
        prev = None
        resets = set(reset_at)
        for c in range(n):
            # we are at the falling edge inside cycle c: outputs are cycle c's
            v = int(d.ev_valid_o.value)
            cur = tuple(int(getattr(d, f).value) for f in FIELDS)
            if prev is not None and prev[0] and not prev[1] and c - 1 not in resets:
                assert v and cur == prev[2], f"output changed while stalled, cycle {c}"
            r = 1 if ready is None else int(ready[c])
            d.ev_ready_i.value = r
            d.rst.value = 1 if c in resets else 0
            b = beats.get(c)
            d.in_valid_i.value = 1 if b is not None and c not in resets else 0
            if b is not None:
                e, last = b
                d.in_frame_i.value = e.frame
                d.in_id_i.value = e.id
                d.in_type_i.value = e.type_code
                d.in_x_i.value = e.x_q
                d.in_y_i.value = e.y_q
                d.in_strength_i.value = e.strength
                d.in_axis_major_i.value = e.axis_major_q
                d.in_axis_minor_i.value = e.axis_minor_q
                d.in_angle_i.value = e.angle
                d.in_flags_i.value = e.flags
                d.in_last_i.value = int(last)
            if v and r and c not in resets:
                got.append((c, cur))
            prev = (v, r, cur)
            await RisingEdge(self.clk)
            await FallingEdge(self.clk)
        d.rst.value = 0
        d.in_valid_i.value = 0
        return got


def expected(outs):
    return [(o.cycle, (o.event.frame, o.time, o.event.id, o.event.type_code, o.event.x_q,
                       o.event.y_q, o.event.strength, o.event.axis_major_q,
                       o.event.axis_minor_q, o.event.angle, o.event.flags, int(o.last)))
            for o in outs]


def rand_frames(rng, n, max_ev, hm_w):
    out = []
    for f in range(n):
        k = rng.randrange(0, max_ev + 1)
        out.append([TouchEvent(f & 0xFFFF, rng.randrange(256), EV_TYPES[rng.randrange(4)],
                               rng.randrange(1 << 16), rng.randrange(1 << 16),
                               rng.randrange(1 << hm_w), rng.randrange(1 << 16),
                               rng.randrange(1 << 16), rng.randrange(256), rng.randrange(256))
                    for _ in range(k)])
    return out


async def check(tb, beats, n, ready=None, delay=0, period=0, reset_at=()):
    got = await tb.run(beats, n, ready, delay, period, reset_at)
    outs, port = run_port(beats, n, ready, delay, period, tb.p, reset_at)
    exp = expected(outs)
    assert got == exp, f"first difference at {next((i for i, (a, b) in enumerate(zip(got, exp)) if a != b), min(len(got), len(exp)))}"
    assert int(tb.dut.drop_count_o.value) == port.drop_count
    assert int(tb.dut.skip_count_o.value) == port.skip_count
    assert int(tb.dut.overflow_o.value) == int(port.overflow)
    return got, port


@cocotb.test()
async def exact_delays(dut):
    """Dial 0, 1, 37 and large: bit-exact, and every event leaves at c + 5 + delay
    (c + FIXED_LATENCY + delay)."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    frames = rand_frames(rng, 30, tb.p.max_ev, tb.hm_w)
    beats = frames_to_beats(frames, start=3, gap=4)
    inv = {id(b[0]): c for c, b in beats.items()}
    span = max(beats) + 1
    for delay in (0, 1, 37, tb.p.depth - 2 * tb.p.max_ev - 3):    # last: ~FIFO-sized
        got, port = await check(tb, beats, span + delay + 10, delay=delay)
        assert len(got) == len(beats) and port.drop_count == 0
        outs, _ = run_port(beats, span + delay + 10, None, delay, 0, tb.p)
        assert all(o.cycle == inv[id(o.event)] + FIXED_LATENCY + delay for o in outs)


@cocotb.test()
async def max_delay_full_rate(dut):
    """Frames of MAX_EV events every F cycles: delay (DEPTH/MAX_EV - 1) frames loses
    nothing, two frames more drop whole frames (counted)."""
    tb = TB(dut)
    rng = random.Random(2)
    p = tb.p
    F = p.max_ev + 4
    frames = [rand_frames(rng, 1, p.max_ev, tb.hm_w)[0] or [TouchEvent(f, 1, "move", 1, 1)]
              for f in range(3 * p.depth // p.max_ev)]
    frames = [[TouchEvent(f, i, "move", i, f) for i in range(p.max_ev)] for f in range(len(frames))]
    beats = frames_to_beats(frames, period=F)
    dmax = (p.depth // p.max_ev - 1) * F - p.max_ev
    n = len(frames) * F + dmax + 3 * F
    got, port = await check(tb, beats, n, delay=dmax)
    assert port.drop_count == 0 and len(got) == len(beats)
    got, port = await check(tb, beats, n, delay=dmax + 2 * F)
    assert port.drop_count > 0


@cocotb.test()
async def decimation(dut):
    tb = TB(dut)
    rng = random.Random(3)
    frames = rand_frames(rng, 40, tb.p.max_ev, tb.hm_w)
    F = tb.p.max_ev + 6
    beats = frames_to_beats(frames, period=F)
    n = max(beats) + 40
    for period in (1, 2 * F - 1, 5 * F + 3):
        got, port = await check(tb, beats, n, delay=5, period=period)
        assert port.skip_count > 0 or period == 1


@cocotb.test()
async def stalls_and_drops(dut):
    """Random short stalls and long stalls: whole frames dropped and counted."""
    tb = TB(dut)
    rng = random.Random(4)
    frames = rand_frames(rng, 120, tb.p.max_ev, tb.hm_w)
    beats = frames_to_beats(frames, period=tb.p.max_ev + 2)
    n = max(beats) + 200
    ready = [1 if (c // 150) % 3 else 0 for c in range(n)]
    ready = [r if rng.random() < 0.6 else 0 for r in ready]
    got, port = await check(tb, beats, n, ready=ready, delay=3)
    assert port.drop_count > 0
    ready = [1 if rng.random() < 0.8 else 0 for _ in range(n)]
    await check(tb, beats, n, ready=ready, delay=0, period=30)


@cocotb.test()
async def reset_mid_frame(dut):
    tb = TB(dut)
    frames = [[TouchEvent(f, i, "move", i, f) for i in range(5)] for f in range(20)]
    beats = frames_to_beats(frames, period=20)
    beats = {c: b for c, b in beats.items() if not 203 < c < 220}   # the tracker is reset too
    await check(tb, beats, 450, delay=30, reset_at=[203])


# ---- pytest entry ------------------------------------------------------------------
@pytest.mark.parametrize("cfg_name,depth,max_ev", [("small", 64, 8), ("medium", 128, 20)])
def test_fmt_event_port(sim, cfg_name, depth, max_ev):
    cfg = params.get(cfg_name)
    run_cocotb(
        sim=sim,
        toplevel="fmt_event_port",
        sources=sources("fmt_event_port"),
        test_module="test_fmt_event_port",
        test_dir=Path(__file__).parent,
        parameters={"DEPTH": depth, "MAX_EV": max_ev, "HM_W": cfg.hm_width},
        extra_env={"DEPTH": depth, "MAX_EV": max_ev, "HM_W": cfg.hm_width, "SEED": 1},
    )
