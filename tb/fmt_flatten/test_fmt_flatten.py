"""cocotb testbench of rtl/fmt_flatten.v against sim/fmt/flatten.py flatten_fixed().

Checks: power-on identity (offset 0, gain 1.0), bit-exact output for random offsets
and gains loaded through the calibration port, random row orders, beats on consecutive
cycles and with gaps, back-to-back frames, the fixed latency of 5 cycles for every
beat and end-of-frame marker, per-cell saturation bits, the sticky flag and the
saturated-cell counter (and its clear), reset in the middle of a frame, and directed
exact halves and saturation boundaries of the rounding against a rule written out
independently of the model (exact_halves_and_boundaries: random gains almost never give
an exact half, so a round-half-down mutation passed the random tests).
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import long_run, run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params
from fmt.flatten import GAIN_MAX, GAIN_ONE, flatten_fixed, identity

LATENCY = 5


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("FMT_CFG", "small"))
        self.w = self.cfg.hm_width
        self.rows, self.cols = self.cfg.rows, self.cfg.cols
        self.offset, self.gain = identity(self.cfg)
        for s in ("hm_valid_i", "hm_row_i", "hm_frame_i", "hm_data_i", "hm_eof_i",
                  "cal_we_i", "cal_sel_i", "cal_row_i", "cal_col_i", "cal_data_i", "cal_re_i",
                  "sat_clr_i"):
            getattr(dut, s).value = 0

    def pack(self, row) -> int:
        v = 0
        for c, x in enumerate(row):
            v |= int(x) << (c * self.w)
        return v

    def unpack(self, v: int):
        m = (1 << self.w) - 1
        return [(v >> (c * self.w)) & m for c in range(self.cols)]

    async def load(self, offset, gain):
        """Write every cell's offset and gain through the calibration port."""
        d = self.dut
        for sel, arr in ((0, offset), (1, gain)):
            for r in range(self.rows):
                for c in range(self.cols):
                    await self.writable()
                    d.cal_we_i.value = 1
                    d.cal_sel_i.value = sel
                    d.cal_row_i.value = r
                    d.cal_col_i.value = c
                    d.cal_data_i.value = int(arr[r, c])
        await self.writable()
        d.cal_we_i.value = 0
        self.offset, self.gain = np.array(offset), np.array(gain)

    async def run(self, schedule, tail: int = LATENCY + 3, writes=None):
        """Drive ``schedule`` (per cycle: None, ('row', r, frame, values) or ('eof', frame))
        and return the outputs per cycle: list of (valid, row, frame, data, sat, eof).
        ``writes``: {cycle index: (sel, row, col, value)} calibration writes driven in
        those cycles of the schedule."""
        d = self.dut
        out = []
        for t, item in enumerate(list(schedule) + [None] * tail):
            await self.writable()
            d.hm_valid_i.value = 0
            d.hm_eof_i.value = 0
            if writes is not None:
                w = writes.get(t)
                d.cal_we_i.value = int(w is not None)
                if w is not None:
                    d.cal_sel_i.value, d.cal_row_i.value, d.cal_col_i.value, d.cal_data_i.value = w
            if item is not None and item[0] == "row":
                _, r, f, vals = item
                d.hm_valid_i.value = 1
                d.hm_row_i.value = r
                d.hm_frame_i.value = f
                d.hm_data_i.value = self.pack(vals)
            elif item is not None:
                d.hm_eof_i.value = 1
                d.hm_frame_i.value = item[1]
            await RisingEdge(self.clk)
            await ReadOnly()
            out.append((int(d.hm_valid_o.value), int(d.hm_row_o.value), int(d.hm_frame_o.value),
                        int(d.hm_data_o.value), int(d.hm_sat_o.value), int(d.hm_eof_o.value)))
        return out

    def frames_schedule(self, rng, hms, first_frame=0, gap_p=0.3):
        sched = []
        for i, hm in enumerate(hms):
            order = list(range(self.rows))
            rng.shuffle(order)
            for r in order:
                while rng.random() < gap_p:
                    sched.append(None)
                sched.append(("row", r, first_frame + i, hm[r]))
            sched.append(("eof", first_frame + i))
            if rng.random() < 0.5:
                sched.append(None)
        return sched

    def check(self, sched, out):
        """Every output cycle equals the model applied to the input LATENCY cycles before
        (idle in, idle out).  Returns the number of saturated cells seen."""
        nsat = 0
        for t, item in enumerate(sched):
            v, r, f, data, sat, eof = out[t + LATENCY - 1]
            if item is None:
                assert v == 0 and eof == 0, f"spurious output at cycle {t + LATENCY}"
            elif item[0] == "eof":
                assert eof == 1 and v == 0 and f == item[1]
            else:
                _, rr, ff, vals = item
                q, s = flatten_fixed(np.array(vals), self.offset[rr], self.gain[rr], self.cfg)
                assert v == 1 and eof == 0 and r == rr and f == ff
                assert self.unpack(data) == q.tolist(), f"row {rr} frame {ff}"
                assert sat == sum(1 << c for c in range(self.cols) if s[c])
                nsat += int(s.sum())
        return nsat


@cocotb.test()
async def power_on_identity(dut):
    """Without any calibration write the block passes the heat map unchanged and reads
    back offset 0 / gain 1.0."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(env_int("SEED", 1))
    hms = [np.array([[rng.randrange(1 << tb.w) for _ in range(tb.cols)] for _ in range(tb.rows)])]
    sched = tb.frames_schedule(rng, hms, gap_p=0.0)
    out = await tb.run(sched)
    assert tb.check(sched, out) == 0
    assert int(dut.sat_flag_o.value) == 0 and int(dut.sat_count_o.value) == 0
    assert [tb.unpack(o[3]) for o in out if o[0]] == [list(hms[0][item[1]]) for item in sched
                                                      if item and item[0] == "row"]
    # power-on contents (INIT_IDENTITY) read back: offset 0, gain 1.0 (this test runs first)
    await readback_trials(tb, rng, np.zeros((tb.rows, tb.cols), dtype=int),
                          np.full((tb.rows, tb.cols), 1 << 14), 8)


@cocotb.test()
async def random_calibration_bit_exact(dut):
    """Random offsets/gains and random heat maps, back-to-back frames with and without
    gaps; saturation bits, flag and counter equal the model's."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(env_int("SEED", 1) + 1)
    nrng = np.random.default_rng(env_int("SEED", 1))
    top = (1 << tb.w) - 1
    off = nrng.integers(0, top // 4, size=(tb.rows, tb.cols))
    gain = nrng.integers(0, GAIN_MAX + 1, size=(tb.rows, tb.cols))
    gain[0, 0], gain[-1, -1] = GAIN_MAX, 0
    await tb.load(off, gain)
    hms = [nrng.integers(0, top + 1, size=(tb.rows, tb.cols)) for _ in range(3)]
    hms[1][0, 0], hms[1][-1, -1] = top, top           # full-scale cell at max gain, one at gain 0
    sched = tb.frames_schedule(rng, hms, first_frame=0xFFFE, gap_p=0.0)      # frame wraps
    sched += tb.frames_schedule(rng, [nrng.integers(0, top + 1, size=(tb.rows, tb.cols))],
                                first_frame=3, gap_p=0.5)
    sched = [(it[0], it[1] & 0xFFFF, *it[2:]) if it and it[0] == "eof" else
             (it[0], it[1], it[2] & 0xFFFF, it[3]) if it else None for it in sched]
    out = await tb.run(sched)
    nsat = tb.check(sched, out)
    assert nsat > 0
    await RisingEdge(tb.clk)
    await ReadOnly()
    assert int(dut.sat_flag_o.value) == 1
    assert int(dut.sat_count_o.value) == nsat
    await tb.writable()
    dut.sat_clr_i.value = 1
    await RisingEdge(tb.clk)
    await tb.writable()
    dut.sat_clr_i.value = 0
    await ReadOnly()
    assert int(dut.sat_flag_o.value) == 0 and int(dut.sat_count_o.value) == 0


CAL_Q = 8                      # the builds' calibration queue depth (parameter CAL_Q)


def frame_rows(sched, out):
    """{frame: {row: (input values, output cells)}} of a run."""
    fr = {}
    for t, item in enumerate(sched):
        if item is not None and item[0] == "row":
            fr.setdefault(item[2], {})[item[1]] = (np.array(item[3]), out[t + LATENCY - 1][3])
    return fr


def tables_after(off, gain, writes):
    """The calibration after each prefix of ``writes`` (k = 0 .. len)."""
    o, g = np.array(off), np.array(gain)
    tabs = [(o.copy(), g.copy())]
    for sel, r, c, v in writes:
        (g if sel else o)[r, c] = v
        tabs.append((o.copy(), g.copy()))
    return tabs


def explaining(tb, rows, tabs):
    """The prefixes k whose table gives every row of the frame."""
    ks = []
    for k, (o, g) in enumerate(tabs):
        if all(tb.unpack(data) == flatten_fixed(vals, o[r], g[r], tb.cfg)[0].tolist()
               for r, (vals, data) in rows.items()):
            ks.append(k)
    return ks


@cocotb.test()
async def calibration_frame_boundaries(dut):
    """Calibration writes at random cycles, in the middle of frames too: every frame is
    flattened with ONE calibration, the table after the first k writes with k never
    decreasing from frame to frame; after an idle gap every write has landed; cal_late_o
    stays 0.  Then CAL_Q + 3 writes inside one frame: cal_late_o is set, no write is lost."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(env_int("SEED", 1) + 7)
    nrng = np.random.default_rng(env_int("SEED", 1) + 7)
    top = (1 << tb.w) - 1
    shape = (tb.rows, tb.cols)
    off0 = nrng.integers(0, top // 8, size=shape)
    gain0 = nrng.integers(GAIN_ONE // 2, 3 * GAIN_ONE // 2, size=shape)
    await tb.load(off0, gain0)

    def new_write():
        sel, r, c = rng.randrange(2), rng.randrange(tb.rows), rng.randrange(tb.cols)
        v = rng.randrange(GAIN_ONE // 2, 3 * GAIN_ONE // 2) if sel else rng.randrange(top // 8)
        return (sel, r, c, v)

    hms = [nrng.integers(top // 4, top // 2, size=shape) for _ in range(10)]
    # two writes per frame on average, three idle cycles between frames: the queue
    # (drained one word per cycle from the hm_eof cycle on) never fills here
    sched = []
    for f in range(len(hms) - 1):
        sched += tb.frames_schedule(rng, hms[f:f + 1], first_frame=f, gap_p=0.25) + [None] * 3
    cyc = sorted(rng.sample(range(len(sched)), k=2 * (len(hms) - 1)))
    sched += [None] * (len(cyc) + 2)                    # idle: the queue drains
    sched += tb.frames_schedule(rng, hms[-1:], first_frame=len(hms) - 1, gap_p=0.0)
    wl = [new_write() for _ in cyc]
    out = await tb.run(sched, writes=dict(zip(cyc, wl)))
    tabs = tables_after(off0, gain0, wl)
    fr = frame_rows(sched, out)
    k_prev, mid = 0, 0
    for f in sorted(fr):
        ks = [k for k in explaining(tb, fr[f], tabs) if k >= k_prev]
        assert ks, f"frame {f}: no single calibration (after >= {k_prev} writes) gives its rows"
        k_prev = ks[0]
        first = min(t for t, it in enumerate(sched) if it and it[0] == "row" and it[2] == f)
        last = max(t for t, it in enumerate(sched) if it and it[0] == "eof" and it[1] == f)
        mid += sum(first < t <= last for t in cyc)
    assert len(wl) in explaining(tb, fr[len(hms) - 1], tabs), "a write did not land"
    assert mid >= len(hms) // 2, f"only {mid} writes inside frames"
    assert int(dut.cal_late_o.value) == 0            # (run() ends in the read-only phase)

    # more than CAL_Q writes inside one frame: the oldest go in at once, flagged, none lost
    await tb.writable()
    wl2 = [new_write() for _ in range(CAL_Q + 3)]
    hm = nrng.integers(top // 4, top // 2, size=shape)
    sched2 = [("row", 0, 20, hm[0])] + [None] * (CAL_Q + 3)
    sched2 += [("row", r, 20, hm[r]) for r in range(1, tb.rows)] + [("eof", 20)]
    sched2 += [None] * (CAL_Q + 4)
    sched2 += [("row", r, 21, hm[r]) for r in range(tb.rows)] + [("eof", 21)]
    out2 = await tb.run(sched2, writes={1 + i: w for i, w in enumerate(wl2)})
    assert int(dut.cal_late_o.value) == 1
    tabs2 = tables_after(*tabs[-1], wl2)
    assert len(wl2) in explaining(tb, frame_rows(sched2, out2)[21], tabs2), "a write was lost"


def round_half_up_ref(z: int, off: int, g: int, w: int) -> tuple[int, bool]:
    """The rule of fmt_flatten written out independently of fmt.flatten (exact rationals):
    q = floor(max(z - off, 0) * g / 2^14 + 1/2), saturated at 2^w - 1."""
    from fractions import Fraction
    top = (1 << w) - 1
    q = int(Fraction(max(z - off, 0) * g, 1 << 14) + Fraction(1, 2))   # int() floors a positive
    return min(q, top), q > top


def directed_cases(w: int) -> list:
    """(z, offset, gain) cells: exact halves (which a round-half-down or round-to-even
    mutation gets wrong), one LSB either side of a half, the offset clamp, gain 0 and
    full scale, and products just either side of the saturation threshold."""
    top = (1 << w) - 1
    cases = []
    for g, zs in ((8192, (1, 3, 5, 7, 2 * 1234 + 1, top, top - 2)),      # x.5 with gain 0.5
                  (4096, (2, 6, 10, top - 1)),                              # gain 0.25
                  (2048, (4, 12, 20)), (24576, (1, 3, 5)),                  # gain 0.125, 1.5
                  (40960, (1, 3)), (57344, (1, 3)), (1, (1 << 13,)),      # gain 2.5, 3.5, 2^-14
                  (8191, (1, 3)), (8193, (1, 3)), (16383, (1, 2)), (16385, (1, top))):
        cases += [(z, 0, g) for z in zs]
    cases += [(11, 10, 8192), (1010, 1000, 8192 + 4096), (7, 7, 9999), (6, 7, 9999), (0, top, 16384),
              (top, 0, 0), (top, 0, 16384), (top, 0, (1 << 16) - 1), (top, 1, 16385), (top - 1, 0, 16385)]
    # products around the saturation threshold (top + 1/2) * 2^14
    thr = top * (1 << 14) + (1 << 13)
    near = []
    for d in range(top, top - 3000, -1):
        g = thr // d
        for gg in (g - 1, g, g + 1):
            if 0 <= gg < (1 << 16) and abs(d * gg - thr) <= 2 * d:
                near.append((d, 0, gg))
        if len(near) >= 12:
            break
    return cases + near


@cocotb.test()
async def exact_halves_and_boundaries(dut):
    """Directed roundings: every exact half rounds up, every saturation boundary holds
    (against round_half_up_ref, written independently of the model, and the model)."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(env_int("SEED", 1) + 4)
    cases = directed_cases(tb.w)
    n = tb.rows * tb.cols
    halves = sum(1 for z, o, g in cases if (max(z - o, 0) * g) % (1 << 14) == 1 << 13)
    assert halves >= 20, halves
    sat_seen = 0
    for i in range(0, len(cases), n):
        chunk = cases[i:i + n] + [(0, 0, GAIN_ONE)] * (n - len(cases[i:i + n]))
        z = np.array([c[0] for c in chunk]).reshape(tb.rows, tb.cols)
        off = np.array([c[1] for c in chunk]).reshape(tb.rows, tb.cols)
        gain = np.array([c[2] for c in chunk]).reshape(tb.rows, tb.cols)
        await tb.load(off, gain)
        sched = tb.frames_schedule(rng, [z], first_frame=i, gap_p=0.2)
        out = await tb.run(sched)
        tb.check(sched, out)                         # the model, as the other tests
        for t, item in enumerate(sched):
            if item is None or item[0] != "row":
                continue
            r = item[1]
            got = tb.unpack(out[t + LATENCY - 1][3])
            satbits = out[t + LATENCY - 1][4]
            for c in range(tb.cols):
                want, wsat = round_half_up_ref(int(z[r, c]), int(off[r, c]), int(gain[r, c]), tb.w)
                assert got[c] == want, (f"cell z={z[r, c]} offset={off[r, c]} gain={gain[r, c]}: "
                                        f"RTL {got[c]}, round half up gives {want}")
                assert bool(satbits >> c & 1) == wsat, f"saturation of z={z[r, c]} gain={gain[r, c]}"
                sat_seen += wsat
    assert sat_seen >= 3


@cocotb.test()
async def reset_mid_frame(dut):
    """A reset in the middle of a frame drops the beats in flight; the next frame is exact."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(env_int("SEED", 1) + 2)
    nrng = np.random.default_rng(env_int("SEED", 1) + 2)
    off = nrng.integers(0, 1000, size=(tb.rows, tb.cols))
    gain = nrng.integers(GAIN_ONE // 2, 2 * GAIN_ONE, size=(tb.rows, tb.cols))
    await tb.load(off, gain)
    hm = nrng.integers(0, 1 << tb.w, size=(tb.rows, tb.cols))
    sched = tb.frames_schedule(rng, [hm], gap_p=0.0)
    await tb.run(sched[: max(2, tb.rows // 2)], tail=0)
    await tb.writable()
    dut.hm_valid_i.value = 0          # the beats already accepted are in flight
    await tb.reset(cycles=1)
    out = await tb.run([None] * LATENCY, tail=0)
    assert not any(o[0] or o[5] for o in out), "beats in flight must be dropped by reset"
    sched = tb.frames_schedule(rng, [hm], first_frame=7)
    out = await tb.run(sched)
    tb.check(sched, out)


@cocotb.test()
async def calibration_readback(dut):
    """Read back offsets and gains, also while heat-map beats occupy the read port
    (the request waits for a free cycle)."""
    tb = TB(dut)
    await tb.reset()
    rng = random.Random(env_int("SEED", 1) + 3)
    nrng = np.random.default_rng(env_int("SEED", 1) + 3)
    off = nrng.integers(0, 1 << tb.w, size=(tb.rows, tb.cols))
    gain = nrng.integers(0, GAIN_MAX + 1, size=(tb.rows, tb.cols))
    await tb.load(off, gain)
    await readback_trials(tb, rng, off, gain, 24)


async def readback_trials(tb, rng, off, gain, n):
    dut = tb.dut
    for trial in range(n):
        r, c, sel = rng.randrange(tb.rows), rng.randrange(tb.cols), rng.randrange(2)
        busy = rng.randrange(0, 4) if trial % 2 else 0      # beats occupying the read port
        await tb.writable()
        dut.cal_re_i.value = 1
        dut.cal_row_i.value = r
        dut.cal_col_i.value = c
        dut.cal_sel_i.value = sel
        dut.hm_valid_i.value = int(busy > 0)
        dut.hm_row_i.value = rng.randrange(tb.rows)
        await RisingEdge(tb.clk)
        await tb.writable()
        dut.cal_re_i.value = 0
        waited = 0
        for i in range(busy + 4):
            dut.hm_valid_i.value = int(i + 1 < busy)
            await RisingEdge(tb.clk)
            await ReadOnly()
            waited += 1
            if int(dut.cal_rvalid_o.value):
                break
            await tb.writable()
        assert int(dut.cal_rvalid_o.value) == 1, "no read-back answer"
        want = int(gain[r, c] if sel else off[r, c])
        assert int(dut.cal_rdata_o.value) == want, f"cell ({r},{c}) sel {sel}"
        assert waited == max(busy, 1) + 1, f"answer after {waited} cycles, {busy} busy"
        await tb.writable()
        dut.hm_valid_i.value = 0
    await tb.cycles(LATENCY + 2)


# ---- pytest entry ------------------------------------------------------------------
def sensor_params(cfg) -> dict:
    """The sensor parameters of fmt_flatten from ``cfg`` (SensorConfig.verilog_params)."""
    p = cfg.verilog_params()
    return {k: p[k] for k in ("ROWS", "COLS", "HM_W")}


# CAL_BRAM = 0: the LUT-RAM variant of the column memories (same behaviour)
@pytest.mark.parametrize("cfg, cal_bram", [(params.SMALL, 1), (params.MEDIUM, 1), (params.SMALL, 0)],
                         ids=["SMALL", "MEDIUM", "SMALL-lutram"])
def test_fmt_flatten(sim, cfg, cal_bram):
    run_cocotb(sim=sim, toplevel="fmt_flatten", sources=sources("fmt_flatten"),
               test_module="test_fmt_flatten", test_dir=Path(__file__).parent,
               parameters={**sensor_params(cfg), "CAL_BRAM": cal_bram, "CAL_Q": CAL_Q},
               extra_env={"FMT_CFG": cfg.name, "SEED": 1})


@pytest.mark.verilator_only
@pytest.mark.skipif(not long_run(),
                    reason="full-size build: set FMT_LONG=1 (the datapath is per column, "
                           "SMALL and MEDIUM cover it)")
def test_fmt_flatten_default(sim):
    cfg = params.DEFAULT
    run_cocotb(sim=sim, toplevel="fmt_flatten", sources=sources("fmt_flatten"),
               test_module="test_fmt_flatten", test_dir=Path(__file__).parent,
               parameters={**sensor_params(cfg), "CAL_Q": CAL_Q},
               extra_env={"FMT_CFG": cfg.name, "SEED": 2})
