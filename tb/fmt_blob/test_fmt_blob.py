"""cocotb testbench of rtl/fmt_blob.v against sim/fmt/blob.py (blob_stream_fixed).

Every frame's blob stream (area, Q8.8 centroid, bounding box, peak and peak cell, in
the model's order: area descending, ties by the raster index of the first cell) and its
end-of-frame record (count, found, overflow, frame number) must equal the model's.
Covered: random bitmaps of several densities (many small regions, more blobs than
MAX_BLOBS), U / spiral / comb / checkerboard shapes (label merging, every label slot
live), regions on edges and corners, the whole sensor on, palm scenes rendered by
fmt.sensor.contact_map with fingers next to the palm, frames without blobs, rows in
random orders with and without gaps, back-to-back frames, a reset in the middle of a
frame (that frame comes out as incomplete).  The latency from the last row beat (and
from hm_eof) to blob_eof is measured and bounded.

The membership mask (blob_mask_fixed) is checked through the cell query port
(mask_q_row_i, mask_q_col_i -> mask_q_data_o two cycles later), one query per cycle
after mask_ready_o: every cell of the frame when the sensor has at most QMAX cells or
the frame is run alone (test full_masks: every cell, in random order), else QMAX cells
(on-cells first, then random cells) -- frames back to back leave the mask readable only
until the next frame's membership pass starts.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.hm_stream import drive_hm_schedule, frame_schedule, pack_row
from common.runner import long_run, run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params
from fmt.blob import blob_mask_fixed, blob_stream_fixed, label_regions

MAX_BLOBS = 8
QMAX = 40                     # mask queries per frame when frames come back to back


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("FMT_CFG", "small"))
        self.w = self.cfg.hm_width
        self.rows, self.cols = self.cfg.rows, self.cfg.cols
        self.mb = env_int("MAX_BLOBS", MAX_BLOBS)
        # fmt_div latency: QW + 1, QW = max index width + 8
        self.div_lat = max((self.rows - 1).bit_length(), (self.cols - 1).bit_length()) + 9
        self.cycle = 0
        self.frames = []
        self.masks = []            # (frame, mask, cycle of mask_ready) per frame
        self.plans = {}            # frame -> cells to query (default: every cell)
        self.cur = []
        self.set(1000, 3)
        for s in ("hm_valid_i", "hm_row_i", "hm_frame_i", "hm_data_i", "hm_eof_i",
                  "mask_q_row_i", "mask_q_col_i"):
            getattr(dut, s).value = 0
        self.mon = None
        # an internal net (public to Verilator by a metacomment in the RTL): a NEW that
        # waits for a free label slot (the NL bound of the RTL says it never does).  A
        # missing net fails the test: the check never switches itself off.
        self.new_wait = dut.new_wait
        self.new_waits = 0

    async def reset(self, cycles: int = 4):
        await super().reset(cycles)
        if self.mon is None:
            self.mon = cocotb.start_soon(self.monitor())
            cocotb.start_soon(self.mask_reader())

    def set(self, threshold, min_cells):
        self.thr, self.minc = threshold, min_cells
        self.dut.blob_threshold_i.value = threshold
        self.dut.blob_min_cells_i.value = min_cells

    async def monitor(self):
        d = self.dut
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            self.cycle += 1
            if int(d.rst.value):
                self.cur = []
                continue
            self.new_waits += int(self.new_wait.value)
            if int(d.blob_valid_o.value):
                self.cur.append((int(d.blob_area_o.value), int(d.blob_cx_o.value),
                                 int(d.blob_cy_o.value), int(d.blob_rmin_o.value),
                                 int(d.blob_cmin_o.value), int(d.blob_rmax_o.value),
                                 int(d.blob_cmax_o.value), int(d.blob_peak_o.value),
                                 int(d.blob_peak_row_o.value), int(d.blob_peak_col_o.value),
                                 int(d.blob_frame_o.value), self.cycle))
            if int(d.blob_eof_o.value):
                self.frames.append(dict(blobs=self.cur, frame=int(d.blob_frame_o.value),
                                        count=int(d.blob_count_o.value),
                                        found=int(d.blob_found_o.value),
                                        overflow=int(d.blob_overflow_o.value),
                                        incomplete=int(d.blob_incomplete_o.value),
                                        cycle=self.cycle))
                self.cur = []

    async def mask_reader(self):
        """On mask_ready_o query the frame's planned cells (every cell by default)
        through the query port, one per cycle (data two cycles after the address).
        The mask records 1 / 0 for a queried cell, -1 for a cell not queried."""
        d = self.dut
        every = [(r, c) for r in range(self.rows) for c in range(self.cols)]
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if int(d.rst.value) or not int(d.mask_ready_o.value):
                continue
            frame, cyc = int(d.mask_frame_o.value), self.cycle
            cells = self.plans.pop(frame, None) or every
            m = np.full((self.rows, self.cols), -1, dtype=np.int8)
            hit_reset = False
            for k in range(len(cells) + 1):
                await self.writable()
                if k < len(cells):
                    d.mask_q_row_i.value, d.mask_q_col_i.value = cells[k]
                await RisingEdge(self.clk)
                await ReadOnly()
                if int(d.rst.value):
                    hit_reset = True          # a read cut by a reset is not a record
                    break
                if k >= 1:                    # address at edge k-1, data after edge k
                    m[cells[k - 1]] = int(d.mask_q_data_o.value)
            if not hit_reset:
                self.masks.append((frame, m, cyc))

    def plan(self, rng, hm, full=False):
        """Cells to query for a frame: every cell (random order) when full or the
        sensor is small, else QMAX cells: on-cells (shuffled) first, then random cells."""
        every = [(r, c) for r in range(self.rows) for c in range(self.cols)]
        if full or len(every) <= QMAX:
            rng.shuffle(every)
            return every
        on = [(r, c) for r, c in every if hm[r][c] >= self.thr]
        rng.shuffle(on)
        cells = on[:QMAX - 8]
        rest = sorted(set(every) - set(cells))
        return cells + rng.sample(rest, QMAX - len(cells))

    def pack(self, row) -> int:
        return pack_row(row, self.w)

    def work(self, hm) -> int:
        """Cycles the RTL needs for a frame, generously: one per row, two per run (a run
        and at most one merge), closes, divider and list."""
        on = np.asarray(hm) >= self.thr
        runs = int((on[:, 1:] & ~on[:, :-1]).sum() + on[:, 0].sum())
        return 2 * self.rows + 2 * runs + 2 * self.mb + self.div_lat + 40

    def schedule(self, rng, hms, first_frame=0, gap_p=0.0, order=None):
        """Rows of each frame (random order unless given), random gaps, eof right after
        the last row.  A frame must be finished before the next frame's hm_eof
        (overrun_o), so short test frames are stretched to the processing time of the
        previous frame by idle cycles before their last row."""
        prev = [0] + [self.work(hm) for hm in hms[:-1]]
        return frame_schedule(rng, hms, self.rows, prev, first_frame, gap_p, order)

    async def drive(self, sched):
        """Drive the schedule (tb/common/hm_stream.py); returns (last row beat, hm_eof)
        monitor cycles per frame."""
        return await drive_hm_schedule(self, sched)

    async def drain(self, n_frames, timeout=20000):
        for _ in range(timeout):
            if len(self.frames) >= n_frames:
                return
            await RisingEdge(self.clk)
        raise AssertionError(f"only {len(self.frames)} of {n_frames} frames came out")

    async def drain_masks(self, n_masks, timeout=20000):
        for _ in range(timeout):
            if len(self.masks) >= n_masks:
                return
            await RisingEdge(self.clk)
        raise AssertionError(f"only {len(self.masks)} of {n_masks} masks came out")

    def expect(self, rec, hm, frame):
        want, found, over = blob_stream_fixed(hm, self.thr, self.minc, self.mb)
        got = [x[:10] for x in rec["blobs"]]
        assert got == want, (f"frame {frame} (thr {self.thr}, min {self.minc}): "
                             f"got {got[:3]}.. want {want[:3]}..")
        assert all(x[10] == frame for x in rec["blobs"]) and rec["frame"] == frame
        assert rec["count"] == len(want) and rec["found"] == found
        assert rec["overflow"] == int(over) and rec["incomplete"] == 0
        assert int(self.dut.overrun_o.value) == 0
        assert self.new_waits == 0, "a NEW waited for a free label slot"
        cyc = [x[11] for x in rec["blobs"]]
        assert cyc == list(range(cyc[0], cyc[0] + len(cyc))) if cyc else True, "one per cycle"
        assert rec["cycle"] == (cyc[-1] + 1 if cyc else rec["cycle"])
        return found

    async def run_frames(self, rng, hms, first_frame=0, gap_p=0.0, order=None, full=False):
        """Drive, check the blob streams and the membership masks (queried cells, see
        plan); returns per frame (last row -> blob_eof, hm_eof -> blob_eof, blobs found,
        last row -> mask_ready)."""
        n0, m0 = len(self.frames), len(self.masks)
        for i, hm in enumerate(hms):
            self.plans[(first_frame + i) & 0xFFFF] = self.plan(rng, hm, full)
        marks = await self.drive(self.schedule(rng, hms, first_frame, gap_p, order))
        await self.drain(n0 + len(hms))
        await self.drain_masks(m0 + len(hms))
        out = []
        for i, hm in enumerate(hms):
            rec = self.frames[n0 + i]
            frame = (first_frame + i) & 0xFFFF
            found = self.expect(rec, hm, frame)
            mframe, mask, mcyc = self.masks[m0 + i]
            want = blob_mask_fixed(hm, self.thr, self.minc)
            assert mframe == frame
            asked = mask >= 0
            assert asked.sum() == min(len(mask.flat), QMAX) or asked.all()
            assert np.array_equal(mask[asked] == 1, want[asked]), \
                f"frame {frame}: mask (-1 not queried)\n{mask.astype(int)}\nwant\n{want.astype(int)}"
            out.append((rec["cycle"] - marks[i][0], rec["cycle"] - marks[i][1], found,
                        mcyc - marks[i][0]))
        return out


# ---- heat maps ------------------------------------------------------------------------
TOP = (1 << 16) - 1


def bitmap_hm(nrng, on, thr):
    """Cells on get random values >= thr (many ties: a few levels, and saturated
    cells), cells off random values < thr."""
    hi = nrng.choice([thr, thr + 1, thr + 500, 20000, TOP], size=on.shape)
    lo = nrng.integers(0, thr, size=on.shape)
    return np.where(on, hi, lo).astype(np.int64)


def random_on(nrng, rows, cols, density):
    return nrng.random((rows, cols)) < density


def shape_maps(rows, cols):
    """Hand-made bitmaps: U (merge at the bottom), spiral, comb (many merges), checker
    (every label live), corners and edges, whole sensor, empty."""
    out = {}
    u = np.zeros((rows, cols), bool)
    u[0:rows - 1, 0] = True
    u[0:rows - 1, cols - 1] = True
    u[rows - 1, :] = True
    out["U"] = u
    inv_u = u[::-1].copy()                       # merge at the top, no merge needed
    out["n"] = inv_u
    sp = np.zeros((rows, cols), bool)           # square spiral inwards, walls 1 apart
    r = c = d = 0
    dirs = ((0, 1), (1, 0), (0, -1), (-1, 0))
    sp[0, 0] = True
    inside = lambda y, x: 0 <= y < rows and 0 <= x < cols
    for _ in range(rows * cols):
        for turn in range(2):
            dr, dc = dirs[(d + turn) % 4]
            nr, nc = r + dr, c + dc
            if inside(nr, nc) and not sp[nr, nc] and not (inside(nr + dr, nc + dc) and sp[nr + dr, nc + dc]):
                d = (d + turn) % 4
                r, c = nr, nc
                sp[r, c] = True
                break
        else:
            break
    out["spiral"] = sp
    comb = np.zeros((rows, cols), bool)
    comb[:, ::2] = True
    comb[rows - 1, :] = True                    # teeth joined at the bottom: many merges
    out["comb"] = comb
    comb2 = np.zeros((rows, cols), bool)
    comb2[1::2, :] = True
    comb2[::2, ::2] = True                      # rows alternate full / teeth
    out["comb2"] = comb2
    chk = (np.add.outer(np.arange(rows), np.arange(cols)) % 2) == 0
    out["checker"] = chk
    ed = np.zeros((rows, cols), bool)
    ed[0, 0] = ed[0, cols - 1] = ed[rows - 1, 0] = ed[rows - 1, cols - 1] = True
    ed[0, 2:cols - 2] = True
    ed[2:rows - 2, cols - 1] = True
    out["edges"] = ed
    out["full"] = np.ones((rows, cols), bool)
    out["empty"] = np.zeros((rows, cols), bool)
    stairs = np.zeros((rows, cols), bool)        # W staircase: merges late, from the right
    for r in range(rows):
        for c in range(cols):
            stairs[r, c] = ((c + r) % 4 == 0) or (r == rows - 1)
    out["stairs"] = stairs
    weave = np.zeros((rows, cols), bool)         # even cells, odd cells (all new labels),
    weave[0::3, 0::2] = True                     # a full row (merges them all): the most
    weave[1::3, 1::2] = True                     # merges with the most runs
    weave[2::3, :] = True
    out["weave"] = weave
    return out


def palm_scene(cfg, nrng):
    """A palm (large ellipse) and two fingers next to it, rendered by the sensor model."""
    sensor = __import__("fmt.sensor", fromlist=["contact_map"])
    w, h = cfg.cols * cfg.pitch_mm, cfg.rows * cfg.pitch_mm
    px, py = nrng.uniform(0.3, 0.5) * w, nrng.uniform(0.35, 0.65) * h
    major, minor = 0.55 * h, 0.4 * w
    contacts = [(px, py, major, 1.0, minor, float(nrng.uniform(0, np.pi)))]
    for _ in range(2):
        contacts.append((nrng.uniform(0.72, 0.95) * w, nrng.uniform(0.1, 0.9) * h,
                         8.0, float(nrng.uniform(0.6, 1.0))))
    cmap = sensor.contact_map(cfg, contacts)
    z = cmap * 12000 + nrng.normal(200, 60, cmap.shape)
    return np.clip(np.rint(z), 0, TOP).astype(np.int64)


# ---- tests ----------------------------------------------------------------------------
@cocotb.test()
async def random_bitmaps(dut):
    """Random bitmaps of several densities (sparse: many small regions and overflow of
    the blob list; dense: large merged regions), several min-cells, random row orders,
    back to back and with gaps."""
    tb = TB(dut)
    await tb.reset()
    seed = env_int("SEED", 1)
    rng, nrng = random.Random(seed), np.random.default_rng(seed)
    frame = 0xFFFE                                     # frame numbers wrap
    n_over = 0
    for density in (0.15, 0.4, 0.55, 0.7):
        for minc in (1, 3, 8):
            thr = rng.choice([1, 1000, 30000])
            tb.set(thr, minc)
            hms = [bitmap_hm(nrng, random_on(nrng, tb.rows, tb.cols, density), thr)
                   for _ in range(2)]
            res = await tb.run_frames(rng, hms, frame, gap_p=rng.choice([0.0, 0.3]))
            n_over += sum(found > tb.mb for _, _, found, _ in res)
            frame += 2
    if tb.rows * tb.cols >= 80:                        # too few cells on SMALL
        assert n_over > 0, "no frame exceeded MAX_BLOBS"


@cocotb.test()
async def shapes(dut):
    """U, spiral, combs, checkerboard, stairs, edges and corners, the whole sensor,
    an empty frame; min-cells 1 and 4."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(3), np.random.default_rng(3)
    maps = shape_maps(tb.rows, tb.cols)
    frame = 10
    for minc in (1, 4):
        tb.set(1000, minc)
        hms = [bitmap_hm(nrng, m, 1000) for m in maps.values()]
        # the labelling must merge: the U is one region
        assert label_regions(hms[0], 1000)[1] == 1
        res = await tb.run_frames(rng, hms, frame)
        if minc == 1:                                # the checkerboard overflows the list
            assert max(found for _, _, found, _ in res) > tb.mb
        frame += len(hms)
    # min-cells exactly at a region's area, and one above
    z = bitmap_hm(nrng, maps["U"], 1000)
    area = int((z >= 1000).sum())
    for minc in (area, area + 1, 0, 65535):          # 0 acts as 1; 65535: no blob
        tb.set(1000, minc)
        await tb.run_frames(rng, [z], frame)
        frame += 1


@cocotb.test()
async def palms(dut):
    """Palm scenes from the sensor model (one big blob, fingers as separate small
    regions) and frames without any blob."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(5), np.random.default_rng(5)
    tb.set(1500, 6)
    hms = [palm_scene(tb.cfg, nrng) for _ in range(3)]
    hms.append(np.full((tb.rows, tb.cols), 300, dtype=np.int64))       # nothing on
    res = await tb.run_frames(rng, hms, 40, gap_p=0.2)
    if tb.rows * tb.cols >= 80:
        assert all(found >= 1 for _, _, found, _ in res[:3]), "the palm is a blob"
    assert res[3][2] == 0


@cocotb.test()
async def full_masks(dut):
    """Frames one at a time, every cell of the mask queried (random order): random
    bitmaps, comb, stairs, checkerboard, a palm scene; min-cells 1 and 5."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(17), np.random.default_rng(17)
    maps = shape_maps(tb.rows, tb.cols)
    frame = 500
    for minc in (1, 5):
        tb.set(1000, minc)
        hms = [bitmap_hm(nrng, random_on(nrng, tb.rows, tb.cols, d), 1000) for d in (0.45, 0.6)]
        hms += [bitmap_hm(nrng, maps[k], 1000) for k in ("comb", "stairs", "checker")]
        hms.append(palm_scene(tb.cfg, nrng))
        for hm in hms:
            await tb.run_frames(rng, [hm], frame, full=True)
            frame += 1


@cocotb.test()
async def reset_mid_frame(dut):
    """A reset in the middle of a frame: the rest of that frame comes out as an
    incomplete frame without blobs, the following frames are exact."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(7), np.random.default_rng(7)
    tb.set(1000, 2)
    hm = bitmap_hm(nrng, random_on(nrng, tb.rows, tb.cols, 0.5), 1000)
    sched = tb.schedule(rng, [hm], 3)
    half = len(sched) // 2
    await tb.drive(sched[:half])
    await tb.reset(2)
    n0 = len(tb.frames)
    await tb.drive(sched[half:])                    # the rest of the frame, and its eof
    await tb.drain(n0 + 1)
    rec = tb.frames[n0]
    assert rec["incomplete"] == 1 and rec["count"] == 0 and rec["blobs"] == []
    await tb.drain_masks(1)
    assert tb.masks[-1][0] == 3 and (tb.masks[-1][1] == 0).all()
    hms = [bitmap_hm(nrng, random_on(nrng, tb.rows, tb.cols, 0.5), 1000) for _ in range(2)]
    await tb.run_frames(rng, hms, 4)


@cocotb.test()
async def reset_random_points(dut):
    """Resets at random points of a busy frame (rows arriving, labelling, closing,
    emission, the membership pass), each followed by new settings and frames that must
    be exact: nothing of the interrupted frame survives the reset."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(11), np.random.default_rng(11)
    frame = 100
    for _k in range(6):
        tb.set(rng.choice([1, 500, 1000]), rng.choice([1, 2, 3]))
        hm = (nrng.integers(0, 3000, (tb.rows, tb.cols)) * (nrng.random((tb.rows, tb.cols)) < 0.6)
              ).astype(np.int64)
        sched = tb.schedule(rng, [hm], frame)
        cut = rng.randrange(len(sched) + 1)
        await tb.drive(sched[:cut])
        for _ in range(rng.randrange(tb.work(hm) + 2 * tb.rows + 60)):
            await RisingEdge(tb.clk)
        await tb.reset(rng.choice([1, 2]))
        frame += 1
        tb.set(rng.choice([700, 1500]), rng.choice([2, 4]))
        hms = [bitmap_hm(nrng, random_on(nrng, tb.rows, tb.cols, 0.5), tb.thr) for _ in range(2)]
        await tb.run_frames(rng, hms, frame)
        frame += 2


@cocotb.test()
async def overrun(dut):
    """Frames faster than they can be labelled (checkerboards back to back, no idle
    cycles) set the sticky overrun_o; a reset clears it and the next frame is exact."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(13), np.random.default_rng(13)
    tb.set(1000, 1)
    chk = bitmap_hm(nrng, shape_maps(tb.rows, tb.cols)["checker"], 1000)
    sched = []
    for i in range(3):
        sched += [("row", r, chk[r]) for r in range(tb.rows)] + [("eof", i)]
    await tb.drive(sched)
    await tb.cycles(5)
    assert int(dut.overrun_o.value) == 1
    await tb.reset()
    assert int(dut.overrun_o.value) == 0
    await tb.cycles(tb.rows + 4)                 # a mask read cut by the reset ends
    await tb.run_frames(rng, [chk], 9)


@cocotb.test()
async def latency(dut):
    """Rows one per cycle in the FFT's order (bit-reversed bins), eof right after the
    last row: cycles from the last row beat and from hm_eof to blob_eof, for palm
    scenes and for a frame without blobs.  The worst-case frames (checkerboard,
    combs) must fit in the frame period 3N."""
    tb = TB(dut)
    await tb.reset()
    rng, nrng = random.Random(11), np.random.default_rng(11)
    cfg = tb.cfg
    bits = cfg.log2_n
    slot = lambda k: int(format(k, f"0{bits}b")[::-1], 2)
    order = sorted(range(tb.rows), key=lambda r: slot(cfg.bins[r]))
    tb.set(1500, 6)
    hms = [palm_scene(cfg, nrng) for _ in range(2)] + [np.zeros((tb.rows, tb.cols), np.int64)]
    for (from_row, from_eof, n, mlat), hm in zip(await tb.run_frames(rng, hms, 100, order=order), hms):
        on = hm >= tb.thr
        runs = int((on[:, 1:] & ~on[:, :-1]).sum() + on[:, 0].sum())
        dut._log.info(f"latency: last row -> blob_eof {from_row} cycles, hm_eof -> blob_eof "
                      f"{from_eof} cycles, last row -> mask_ready {mlat} cycles, {n} blobs, {runs} runs")
        assert from_row <= tb.rows + 2 * runs + tb.div_lat + 20 + min(n, tb.mb), "latency bound"
        assert mlat <= 2 * tb.rows + 2 * runs + 20, "mask latency bound"
    # worst cases: processing time (rows in order, one per cycle) against 3N cycles
    period = 3 * (1 << bits)
    maps = shape_maps(tb.rows, tb.cols)
    tb.set(1000, 1)
    for name in ("checker", "comb", "comb2", "stairs", "weave"):
        hm = bitmap_hm(nrng, maps[name], 1000)
        (from_row, from_eof, n, mlat), = await tb.run_frames(rng, [hm], 200, order=list(range(tb.rows)))
        total = max(from_row, mlat) + tb.rows
        dut._log.info(f"worst case {name}: last row -> blob_eof {from_row} cycles, -> mask_ready "
                      f"{mlat}, first row -> done {total}, frame period {period}")
        assert total < period, "a frame must be processed within the frame period"


# ---- pytest entry ---------------------------------------------------------------------
def _run(sim, cfg, seed, testcase=None):
    run_cocotb(sim=sim, toplevel="fmt_blob",
               sources=sources("fmt_blob"),
               test_module="test_fmt_blob", test_dir=Path(__file__).parent,
               parameters={"ROWS": cfg.rows, "COLS": cfg.cols, "HM_W": cfg.hm_width,
                           "MAX_BLOBS": MAX_BLOBS},
               extra_env={"FMT_CFG": cfg.name, "SEED": seed, "MAX_BLOBS": MAX_BLOBS},
               testcase=testcase)


@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM], ids=lambda c: c.name)
def test_fmt_blob(sim, cfg):
    if sim == "verilator" and not long_run():
        pytest.skip("small / medium under Icarus, the default size under Verilator in make test; "
                    "both simulators for every size in make test-long (FMT_LONG=1)")
    _run(sim, cfg, 1)


@pytest.mark.verilator_only
def test_fmt_blob_default(sim):
    _run(sim, params.DEFAULT, 2)
