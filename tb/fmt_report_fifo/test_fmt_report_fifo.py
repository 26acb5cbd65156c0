"""cocotb testbench of rtl/fmt_report_fifo.v against its cycle twin sim/fmt/report_fifo.py.

Random streams of frames (1..2^AW + 2 events each, gaps of 0..3 cycles, so frames that
cannot fit, frames that start while a report still waits and frames admitted into an
empty FIFO all occur), a consumer that
takes events at random (slow and fast phases, like a UART that is busy for a while), the
stream switched off and on in the middle of frames.  Every output is compared with the
model on every cycle.  On top of the model comparison the test checks what the block
promises by itself: the consumer receives only whole frames (each run of events ends with
a 'last' one and carries one frame number), in order, and every frame offered while on is
either received whole or counted as a drop.  (That a frame is admitted only into an empty
FIFO, the freshness rule, is the model's; the formal proof checks the rest.)
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt.report_fifo import ReportFifo

W = 40          # payload: frame number (16) << 24 | index (8) << 16 | random (16)


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.aw = env_int("AW", 3)
        self.model = ReportFifo(self.aw)
        for n in ("en_i", "in_valid_i", "in_data_i", "in_last_i", "out_ready_i"):
            getattr(dut, n).value = 0

    async def run(self, stim: list[dict]) -> list[int]:
        """One dict of inputs per cycle; compare every output; return the taken payloads."""
        taken = []
        for cyc, s in enumerate(stim):
            await self.writable()
            d = self.dut
            d.en_i.value = s["en"]
            d.in_valid_i.value = s["v"]
            d.in_data_i.value = s["data"]
            d.in_last_i.value = s["last"]
            d.out_ready_i.value = s["ready"]
            await ReadOnly()
            ov, od, drop, cnt = self.model.step(bool(s["en"]), bool(s["v"]), s["data"], bool(s["last"]),
                                                bool(s["ready"]))
            got = (int(d.out_valid_o.value), int(d.drop_o.value), int(d.drop_count_o.value))
            assert got == (int(ov), int(drop), cnt), f"cycle {cyc}: (valid, drop, count) {got}, model {(ov, drop, cnt)}"
            if ov:
                assert int(d.out_data_o.value) == od, f"cycle {cyc}: out_data"
                if s["ready"]:
                    taken.append(od)
            await RisingEdge(self.clk)
        return taken


def stream(rng: random.Random, n_frames: int, depth: int, toggles: bool):
    """Per-cycle stimulus and the frames offered: {frame: [payloads]}."""
    stim, frames = [], {}
    ready_p = 0.5
    en = 1
    for f in range(n_frames):
        k = rng.choice([1, 2, 3, depth // 2, depth - 1, depth, depth + 1, depth + 2])
        frames[f] = []
        for i in range(k):
            data = (f << 24) | (i << 16) | rng.randrange(1 << 16)
            frames[f].append(data)
            if rng.random() < 0.02:
                ready_p = rng.choice([0.02, 0.1, 0.5, 1.0])
            if toggles and rng.random() < 0.02:
                en ^= 1
            stim.append(dict(en=en, v=1, data=data, last=int(i == k - 1), ready=int(rng.random() < ready_p)))
            for _ in range(rng.randrange(0, 3) if i < k - 1 else rng.randrange(0, 8)):
                stim.append(dict(en=en, v=0, data=rng.randrange(1 << W), last=rng.randrange(2),
                                 ready=int(rng.random() < ready_p)))
    for _ in range(4 * depth + 10):
        stim.append(dict(en=en, v=0, data=0, last=0, ready=1))
    return stim, frames


def whole_frames(taken: list[int], frames: dict, cut_ok: bool = False) -> list[int]:
    """Split the taken payloads into frames; each must be a complete offered frame
    (``cut_ok``: or its beginning, when the stream was switched off while it was read)."""
    out, cur = [], []
    for p in taken:
        f = p >> 24
        if cur and cur[0] >> 24 != f:
            assert cut_ok, f"frame {cur[0] >> 24}: {len(cur)} of {len(frames[cur[0] >> 24])} events, then frame {f}"
            cur = []
        cur.append(p)
        assert cur == frames[f][:len(cur)], f"frame {f}: events differ from the offered ones"
        if len(cur) == len(frames[f]):
            out.append(f)
            cur = []
    assert cut_ok or not cur, "stream ended inside a frame"
    assert out == sorted(out) and len(set(out)) == len(out), "frames out of order"
    return out


@cocotb.test()
async def random_frames_match_model(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 11))
    depth = 1 << tb.aw
    await tb.reset()
    tb.model.reset()
    stim, frames = stream(rng, 300, depth, toggles=False)
    taken = await tb.run(stim)
    got = whole_frames(taken, frames)
    drops = tb.model.drop_count
    assert len(got) + drops == len(frames), f"{len(got)} received + {drops} dropped != {len(frames)} offered"
    big = [f for f, ev in frames.items() if len(ev) > depth]
    assert big and not set(big) & set(got), "frames longer than the FIFO are never admitted"
    assert drops > len(big) and len(got) >= 40, f"stimulus too easy or too hard: {len(got)} received, {drops} dropped"


@cocotb.test()
async def stream_on_off(dut):
    """en_i toggles in the middle of frames: the FIFO empties while off, and after it
    comes back the frame in progress is skipped (frames arrive whole, except one being
    read when the stream goes off)."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 11) + 1)
    await tb.reset()
    tb.model.reset()
    stim, frames = stream(rng, 300, 1 << tb.aw, toggles=True)
    assert any(s["en"] == 0 for s in stim)
    taken = await tb.run(stim)
    got = whole_frames(taken, frames, cut_ok=True)
    assert len(got) > 20


@pytest.mark.parametrize("aw", [1, 3, 5])
def test_fmt_report_fifo(sim, aw):
    run_cocotb(sim=sim, toplevel="fmt_report_fifo", sources=sources("fmt_report_fifo"),
               test_module="test_fmt_report_fifo", test_dir=Path(__file__).parent,
               parameters={"W": W, "AW": aw}, extra_env={"AW": aw})
