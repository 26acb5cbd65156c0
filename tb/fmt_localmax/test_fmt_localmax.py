"""cocotb testbench of rtl/fmt_localmax.v against sim/fmt/localmax.py.

Every frame's candidate stream (row, col, 3x3 neighbourhood, missing mask, order), its
end-of-frame record (count, found, overflow) and frame number must equal the model's
``local_maxima_fixed(hm, threshold, neighbourhood, limit, prev)``, ``prev`` the candidates
of the frame before (none after a reset: continuing maxima rank first).  Covered: random heat maps with
many ties, random row orders, beats on consecutive cycles and with gaps, back-to-back
frames, plateaus (2 cells, 2x2, 3x1), single-cell spikes, saturated cells, edges and
corners, 17 maxima with a limit of 16, continuing maxima kept over stronger new ones
(also moved by one cell, and not when moved by two), a cell exactly at the threshold, both
neighbourhoods, a reset in the middle of a frame, undefined row, data and frame inputs
(X under Icarus, garbage under Verilator) between beats.  The latency from the last row beat
(and from hm_eof) to the last candidate is measured and bounded: 15 + n + m + e for n
candidates, m maxima in the rows completed by the last beat and e their extra stall
cycles: one for a row with a partial mask but no maximum, one more for a row with two
partial-mask cells or more and at most one maximum (rtl/fmt_localmax.v).
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import RisingEdge
from cocotb.types import LogicArray

from common.hm_stream import drive_hm_schedule, frame_schedule, pack_row
from common.runner import run_cocotb, sources
from common.streams import StreamMonitor
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params
from fmt.localmax import local_maxima_fixed, maxima_mask, offsets


# latency bound, last row beat -> last candidate (rtl/fmt_localmax.v header): LAT_C + n + m + e
# for n candidates, m maxima in the rows completed by the last beat and e their extra
# stall cycles: one for a row with a partial mask (every test but the row below) and no
# maximum, one more for a row with two partial-mask cells or more and at most one maximum
LAT_C = 15


def partial_mask(hm, threshold: int, neighbourhood: str) -> np.ndarray:
    """The RTL's partial mask: the maxima test without the row below."""
    z = np.asarray(hm, dtype=np.int64)
    rows, cols = z.shape
    pad = np.full((rows + 2, cols + 2), -1, dtype=np.int64)
    pad[1:-1, 1:-1] = z
    ok = z >= threshold
    for dy, dx in offsets(neighbourhood):
        if dy > 0:
            continue
        q = pad[1 + dy:1 + dy + rows, 1 + dx:1 + dx + cols]
        ok &= (z > q) if (dy < 0 or dx < 0) else (z >= q)
    return ok


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("FMT_CFG", "small"))
        self.w = self.cfg.hm_width
        self.rows, self.cols = self.cfg.rows, self.cfg.cols
        self.k = env_int("MAX_TOUCHES", self.cfg.max_touches)
        self.frames = []           # records from the candidate stream
        self.prev = []             # (row, col) of the last frame's candidates (the ranking's)
        self.set(threshold=1, moore=True, limit=self.k)
        for s in ("hm_valid_i", "hm_eof_i"):
            getattr(dut, s).value = 0
        # between beats the row, data and frame inputs are undefined, as in the core
        # (fmt_flatten's datapath registers have no reset): X under Icarus, garbage under
        # Verilator (no X there)
        self.icarus = cocotb.SIM_NAME.lower().startswith("icarus")
        self.idle_rng = random.Random(99)
        dut.hm_row_i.value, dut.hm_data_i.value, dut.hm_frame_i.value = self.idle()
        self.mon = None

    def idle(self):
        """Values of hm_row_i, hm_data_i, hm_frame_i without a beat: X or garbage."""
        ws = [len(self.dut.hm_row_i), len(self.dut.hm_data_i), len(self.dut.hm_frame_i)]
        if self.icarus:
            return tuple(LogicArray("X" * w) for w in ws)
        return tuple(self.idle_rng.getrandbits(w) for w in ws)

    CAND_FIELDS = ("row", "col", "z", "missing", "frame")
    EOF_FIELDS = ("frame", "count", "found", "overflow", "incomplete")

    async def reset(self, cycles: int = 4):
        await super().reset(cycles)
        self.prev = []
        if self.mon is None:                 # outputs are defined from the first reset on
            # cocotb-bus BusMonitor of the candidate stream (tb/common/streams.py)
            self.mon = StreamMonitor(self.dut, "cand", self.clk, self.CAND_FIELDS, eof="eof",
                                     eof_fields=self.EOF_FIELDS, reset=self.rst,
                                     callback=self._frame)

    @property
    def cycle(self) -> int:
        """Monitor cycle number (edges since the monitor started)."""
        return self.mon.cycle if self.mon is not None else 0

    def set(self, threshold, moore, limit):
        # limits above MAX_TOUCHES act as MAX_TOUCHES (the list length)
        self.thr, self.nb, self.limit = threshold, "moore" if moore else "vn", min(limit, self.k)
        self.dut.threshold_i.value = threshold
        self.dut.moore_i.value = int(moore)
        self.dut.limit_i.value = limit

    def _frame(self, rec):
        self.frames.append(dict(cands=[b.tuple(self.CAND_FIELDS) + (b.cycle,) for b in rec.beats],
                                cycle=rec.cycle, **rec.eof))

    def pack(self, row) -> int:
        return pack_row(row, self.w)

    def schedule(self, rng, hms, first_frame=0, gap_p=0.0, order=None):
        """Rows of each frame (random order unless given), random gaps, eof right after
        the last row and the next frame's first row right after eof.  A frame must be
        finished before the frame after the next one starts (overrun_o): the real frame
        period is N x CLK_PER_SAMPLE = 192..768 cycles, so short test frames are stretched
        to ``min_period`` cycles by idle cycles before their last row (processing takes
        about ROWS + maxima + 2 x count cycles per frame)."""
        # every maximum takes one cycle in the serialiser
        min_period = [2 * self.k + 32 + self.rows + int(maxima_mask(hm, self.thr, self.nb).sum())
                      for hm in hms]
        return frame_schedule(rng, hms, self.rows, min_period, first_frame, gap_p, order)

    async def drive(self, sched):
        """Drive the schedule (tb/common/hm_stream.py); returns (last row beat, hm_eof)
        monitor cycles per frame."""
        return await drive_hm_schedule(self, sched, idle=self.idle)

    async def drain(self, n_frames, timeout=2000):
        for _ in range(timeout):
            if len(self.frames) >= n_frames:
                return
            await RisingEdge(self.clk)
        raise AssertionError(f"only {len(self.frames)} of {n_frames} frames came out")

    def expect(self, rec, hm, frame):
        cands, n_found, overflow = local_maxima_fixed(hm, self.thr, self.nb, self.limit, self.prev)
        self.prev = [(c.row, c.col) for c in cands]
        want = [(c.row, c.col, c.packed_z(self.w), c.missing) for c in cands]
        got = [x[:4] for x in rec["cands"]]
        assert got == want, f"frame {frame}: got {got[:4]}.. want {want[:4]}.. (thr {self.thr} {self.nb})"
        assert all(x[4] == frame for x in rec["cands"]) and rec["frame"] == frame
        assert rec["count"] == len(want) and rec["found"] == n_found
        assert rec["overflow"] == int(overflow) and rec["incomplete"] == 0
        assert int(self.dut.overrun_o.value) == 0
        cyc = [x[5] for x in rec["cands"]]
        assert cyc == list(range(cyc[0], cyc[0] + len(cyc))) if cyc else True, "one per cycle"
        assert rec["cycle"] == (cyc[-1] + 1 if cyc else rec["cycle"])
        return n_found

    async def run_frames(self, rng, hms, first_frame=0, gap_p=0.0, order=None):
        n0 = len(self.frames)
        sched = self.schedule(rng, hms, first_frame, gap_p, order)
        marks = await self.drive(sched)
        await self.drain(n0 + len(hms))
        lat = []
        for i, hm in enumerate(hms):
            rec = self.frames[n0 + i]
            self.expect(rec, hm, (first_frame + i) & 0xFFFF)
            last_c = rec["cands"][-1][5] if rec["cands"] else rec["cycle"]
            lat.append((last_c - marks[i][0], last_c - marks[i][1], len(rec["cands"])))
        return lat


def random_hm(nrng, rows, cols, kind):
    top = (1 << 16) - 1
    if kind == "ties":                      # few levels: plateaus and ties everywhere
        return nrng.integers(0, 4, size=(rows, cols)) * 1000
    if kind == "full":
        return nrng.integers(0, top + 1, size=(rows, cols))
    # fingers: bumps + noise, some saturated
    r, c = np.mgrid[0:rows, 0:cols]
    z = nrng.normal(300, 100, size=(rows, cols))
    for _ in range(nrng.integers(1, 6)):
        y, x = nrng.uniform(-0.5, rows - 0.5), nrng.uniform(-0.5, cols - 0.5)
        z += nrng.uniform(2000, 90000) * np.exp(-((r - y) ** 2 + (c - x) ** 2) / 1.2)
    return np.clip(np.rint(z), 0, top).astype(np.int64)


@cocotb.test()
async def random_frames(dut):
    """Random heat maps in random row orders, back-to-back and with gaps, both
    neighbourhoods, several thresholds and limits."""
    tb = TB(dut)
    await tb.reset()
    seed = env_int("SEED", 1)
    rng, nrng = random.Random(seed), np.random.default_rng(seed)
    frame = 0xFFFD                                     # frame numbers wrap
    for moore in (True, False):
        for kind, thr in (("ties", 1000), ("full", 30000), ("fingers", 1500), ("ties", 0)):
            tb.set(thr, moore, rng.choice([tb.k, tb.k, max(1, tb.k // 2), 0, tb.k + 1]))
            hms = [random_hm(nrng, tb.rows, tb.cols, kind) for _ in range(3)]
            await tb.run_frames(rng, hms, frame, gap_p=rng.choice([0.0, 0.4]))
            frame += 3


@cocotb.test()
async def plateaus_spikes_edges(dut):
    """Hand-made cases: 2-cell plateaus in every direction, 2x2 and 3x1 plateaus, a
    spike, saturated cells, corners and edges, a cell exactly at the threshold."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(3)
    R, C = tb.rows, tb.cols
    hms = []
    top = (1 << tb.w) - 1
    for (a, b) in [((1, 1), (1, 2)), ((1, 1), (2, 1)), ((1, 1), (2, 2)), ((1, 2), (2, 1))]:
        z = np.full((R, C), 100, dtype=np.int64)
        z[a] = z[b] = 5000
        hms.append(z)
    z = np.full((R, C), 100, dtype=np.int64); z[1:3, 1:3] = 7000; hms.append(z)          # 2x2
    z = np.full((R, C), 100, dtype=np.int64); z[0:3, C - 1] = 7000; hms.append(z)        # 3x1 on an edge
    z = np.full((R, C), 100, dtype=np.int64); z[R - 1, 0:3] = 7000; hms.append(z)        # 1x3 bottom edge
    z = np.zeros((R, C), dtype=np.int64)
    z[0, 0], z[0, C - 1], z[R - 1, 0], z[R - 1, C - 1] = top, top - 1, 5, 2000           # corners
    hms.append(z)
    z = np.zeros((R, C), dtype=np.int64); z[R // 2, C // 2] = 2000; hms.append(z)        # spike at threshold
    z = np.full((R, C), top, dtype=np.int64); hms.append(z)                              # all saturated
    z = np.zeros((R, C), dtype=np.int64); hms.append(z)                                  # nothing
    for moore in (True, False):
        tb.set(2000, moore, tb.k)
        await tb.run_frames(rng, hms, 10, gap_p=0.2)
    tb.set(2001, True, tb.k)                                                             # flicker: just above
    lat = await tb.run_frames(rng, hms[-3:-2], 40)
    assert tb.frames[-1]["count"] == 0


@cocotb.test()
async def contact_limit(dut):
    """More maxima than the limit: the strongest are kept (ties by raster order), the
    overflow is flagged and the dropped ones counted (17 of 16 where the sensor holds 17
    separated maxima, else limit = found - 1)."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(5)
    R, C = tb.rows, tb.cols
    z = np.zeros((R, C), dtype=np.int64)
    pos = [(r, c) for r in range(0, R, 2) for c in range(0, C, 2)]
    n = min(len(pos), tb.k + 1)
    vals = [3000 + 7 * i for i in range(n)]
    if n > 3:
        vals[1] = vals[2]                                    # a tie in strength
    for p, v in zip(pos, vals):
        z[p] = v
    limit = tb.k if n == tb.k + 1 else n - 1
    tb.set(100, True, limit)
    await tb.run_frames(rng, [z], 1)
    rec = tb.frames[-1]
    assert rec["found"] == n and rec["count"] == limit and rec["overflow"] == 1
    assert int(dut.overflow_flag_o.value) == 1
    assert int(dut.drop_count_o.value) == n - limit
    z[pos[0]] = 0                                            # the weakest: now n - 1 maxima
    tb.set(100, True, limit + 5)                             # above MAX_TOUCHES: clamped
    await tb.run_frames(rng, [z], 2)
    rec = tb.frames[-1]
    assert rec["found"] == n - 1 and rec["overflow"] == int(n - 1 > tb.k)
    assert int(dut.drop_count_o.value) == n - limit + max(0, n - 1 - tb.k)


@cocotb.test()
async def continuing_first(dut):
    """Hysteresis on the ranking: limit + 1 separated maxima; the weakest of the kept
    ones then becomes the weakest of all and the dropped one the strongest: the kept
    set stays (also when every maximum moves by one cell, in any direction); moved by
    two cells nothing is continuing and the strongest win again."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(13)
    R, C = tb.rows, tb.cols
    pos = [(r, c) for r in range(1, R - 1, 3) for c in range(1, C - 1, 3)]   # no edge reached
    n = min(len(pos), tb.k + 1)
    assert n >= 2, "the configuration holds at least 2 separated maxima"
    limit = n - 1
    tb.set(100, True, limit)

    def frame(vals, dr=0, dc=0):
        z = np.zeros((R, C), dtype=np.int64)
        for (r, c), v in zip(pos[:n], vals):
            z[r + dr, c + dc] = v
        return z

    def kept():
        return {(x[0], x[1]) for x in tb.frames[-1]["cands"]}

    vals = [3000 + 10 * i for i in range(n)]                # pos[0] the weakest: dropped
    await tb.run_frames(rng, [frame(vals)], 1)
    first = kept()
    assert first == set(pos[1:n])
    swapped = list(vals)
    swapped[0], swapped[1] = 9000, 2000                     # the dropped one now the strongest
    for k, (dr, dc) in enumerate(((0, 0), (1, 0), (0, -1), (-1, 0), (0, 1))):   # <= 1 a frame
        await tb.run_frames(rng, [frame(swapped, dr, dc)], 2 + k)
        assert kept() == {(r + dr, c + dc) for r, c in first}, \
            f"moved by ({dr}, {dc}): the kept set changed"
    await tb.run_frames(rng, [frame(swapped, 1, -1)], 9)   # two columns from the last frame's
    got = kept()
    assert (pos[0][0] + 1, pos[0][1] - 1) in got and (pos[1][0] + 1, pos[1][1] - 1) not in got


@cocotb.test()
async def reset_mid_frame(dut):
    """Reset in the middle of a frame: the rest of that frame comes out as an
    incomplete frame without candidates; the next full frame is exact."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(7), np.random.default_rng(7)
    tb.set(1500, True, tb.k)
    hm = random_hm(nrng, tb.rows, tb.cols, "fingers")
    sched = tb.schedule(rng, [hm])
    half = max(1, tb.rows // 2)
    await tb.drive(sched[:half])
    await tb.reset(cycles=1)
    n0 = len(tb.frames)
    await tb.drive(sched[half:])                               # rest of the frame + eof
    await tb.drain(n0 + 1)
    assert tb.frames[-1]["incomplete"] == 1 and tb.frames[-1]["cands"] == []
    await tb.run_frames(rng, [hm, random_hm(nrng, tb.rows, tb.cols, "fingers")], 9)


@cocotb.test()
async def overrun_flagged(dut):
    """Frames arriving faster than they are finished (many maxima, frames of ROWS
    beats back to back) raise the sticky overrun flag; a reset clears it."""
    tb = TB(dut)
    await tb.reset()
    tb.set(0, False, tb.k)
    z = np.zeros((tb.rows, tb.cols), dtype=np.int64)
    z[0::2, 0::2] = 100
    z[1::2, 1::2] = 100                       # Von Neumann checkerboard: ROWS*COLS/2 maxima
    sched = []
    for f in range(3):
        sched += [("row", r, z[r]) for r in range(tb.rows)] + [("eof", f)]
    await tb.drive(sched)
    assert int(dut.overrun_o.value) == 1
    await tb.reset()
    await RisingEdge(tb.clk)
    assert int(dut.overrun_o.value) == 0


@cocotb.test()
async def latency(dut):
    """Rows one per cycle in the FFT's order (bit-reversed bins), eof right after the
    last row, next frame right after eof: cycles from the last row beat and from hm_eof
    to the last candidate."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(11), np.random.default_rng(11)
    cfg = tb.cfg
    bits = cfg.log2_n
    slot = lambda k: int(format(k, f"0{bits}b")[::-1], 2)
    order = sorted(range(tb.rows), key=lambda r: slot(cfg.bins[r]))
    tb.set(1500, True, tb.k)
    lastr = order[-1]

    def late(hm):
        """Maxima in the rows the last beat completes (its row and the rows next to it),
        plus the extra stall cycles of these rows: one for a partial mask and no maximum,
        one more for two partial-mask cells or more and at most one maximum."""
        mm = maxima_mask(hm, tb.thr, tb.nb)[max(0, lastr - 1):lastr + 2]
        pm = partial_mask(hm, tb.thr, tb.nb)[max(0, lastr - 1):lastr + 2]
        km, kp = mm.sum(axis=1), pm.sum(axis=1)
        return int(km.sum()) + int(((kp >= 1) & (km == 0)).sum()) + int(((kp >= 2) & (km <= 1)).sum())

    hms = [random_hm(nrng, tb.rows, tb.cols, "fingers") for _ in range(4)]
    lat = await tb.run_frames(rng, hms, 100, order=order)
    for hm, (from_row, from_eof, n) in zip(hms, lat):
        m = late(hm)
        dut._log.info(f"latency: last row -> last candidate {from_row} cycles, "
                      f"hm_eof -> last candidate {from_eof} cycles, {n} candidates, "
                      f"m + e = {m} (maxima, and the extra stall cycles, in the rows "
                      f"completed by the last beat)")
        assert from_row <= LAT_C + n + m, "latency bound"
    # worst case for the model: all 16 candidates in the last rows
    z = np.zeros((tb.rows, tb.cols), dtype=np.int64)
    for c in range(0, tb.cols, 2):
        z[lastr, c] = 5000 + c
    lat = await tb.run_frames(rng, [z], 200, order=order)
    dut._log.info(f"latency, {lat[0][2]} maxima all in the last row: {lat[0][0]} cycles from "
                  f"the last row, {lat[0][1]} from hm_eof")
    assert lat[0][0] <= LAT_C + lat[0][2] + late(z)


# ---- pytest entry ------------------------------------------------------------------
def _run(sim, cfg, seed):
    run_cocotb(sim=sim, toplevel="fmt_localmax",
               sources=sources("fmt_localmax"),
               test_module="test_fmt_localmax", test_dir=Path(__file__).parent,
               parameters={"ROWS": cfg.rows, "COLS": cfg.cols, "HM_W": cfg.hm_width,
                           "MAX_TOUCHES": cfg.max_touches},
               extra_env={"FMT_CFG": cfg.name, "SEED": seed, "MAX_TOUCHES": cfg.max_touches})


@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM], ids=lambda c: c.name)
def test_fmt_localmax(sim, cfg):
    _run(sim, cfg, 1)


@pytest.mark.verilator_only
def test_fmt_localmax_default(sim):
    _run(sim, params.DEFAULT, 2)
