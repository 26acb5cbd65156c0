"""cocotb testbench of rtl/fmt_interp.v against its twin fmt.interp.interp_fixed.

Random candidates (peaked bumps from the sensor model with noise, fully random 3x3s
with invalid fits, plateaus, saddles, single-cell spikes, saturated cells, edges and
corners with garbage in the missing cells, full-scale values), both modes and bias
correction on/off chosen per candidate, back-to-back candidates and gaps, frames with
0 and 16 candidates: every touch field bit-exact, the order, the fixed latency, and the
end-of-frame pulse with its count.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import rom_define, run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import interp, params, sensor
from fmt.localmax import Candidate

LAT = 24


def random_z(rng: random.Random, cfg, kind: str):
    full = (1 << cfg.hm_width) - 1
    z = np.zeros((3, 3), dtype=np.int64)
    if kind == "bump":
        p = cfg.pitch_mm
        d = rng.uniform(6, 14)
        ct = [(2 * p + rng.uniform(-0.5, 0.5) * p, 2 * p + rng.uniform(-0.5, 0.5) * p, d,
               rng.uniform(0.05, 1.0), d * rng.uniform(0.5, 1.0), rng.uniform(0, np.pi))]
        small = params.SensorConfig(name="t", rows=5, cols=5, n_fft=64, bin_lo=9, hm_width=cfg.hm_width)
        m = sensor.contact_map(small, ct, profile=rng.choice(sensor.PROFILES))
        m = m + np.array([[rng.gauss(0, 0.01) for _ in range(5)] for _ in range(5)])
        scale = rng.choice([300, 4096, 30000, 60000])
        z = np.clip(np.round(m[1:4, 1:4] * scale), 0, full).astype(np.int64)
    elif kind == "random":
        z = np.array([[rng.randrange(full + 1) for _ in range(3)] for _ in range(3)])
    elif kind == "peak":
        top = rng.randrange(1, full + 1)
        z = np.array([[rng.randrange(top) for _ in range(3)] for _ in range(3)])
        z[1, 1] = top
    elif kind == "plateau":
        z[:, :] = rng.randrange(full + 1)
    elif kind == "saddle":
        c, h = rng.randrange(1000, full // 2), rng.randrange(1, 1000)
        z = np.array([[c, c - h, c], [c + h, c, c + h], [c, c - h, c]])
        if rng.random() < 0.5:
            z = z.T.copy()
    elif kind == "spike":
        z[1, 1] = rng.randrange(1, full + 1)
    elif kind == "full":
        z = np.array([[rng.randrange(full - 3000, full + 1) for _ in range(3)] for _ in range(3)])
        z[1, 1] = full
    return z


def random_cand(rng: random.Random, cfg):
    kind = rng.choice(["bump", "bump", "bump", "random", "peak", "peak", "plateau",
                       "saddle", "spike", "full"])
    z = random_z(rng, cfg, kind)
    if rng.random() < 0.1:
        z[rng.randrange(3), rng.randrange(3)] = (1 << cfg.hm_width) - 1
    # position: interior or on an edge / corner
    row = rng.choice([0, cfg.rows - 1] + [rng.randrange(1, cfg.rows - 1)] * 4)
    col = rng.choice([0, cfg.cols - 1] + [rng.randrange(1, cfg.cols - 1)] * 4)
    missing = 0
    for k in range(9):
        r, c = row + k // 3 - 1, col + k % 3 - 1
        if not (0 <= r < cfg.rows and 0 <= c < cfg.cols):
            missing |= 1 << k
            z[k // 3, k % 3] = rng.randrange(1 << cfg.hm_width)   # garbage: must be ignored
    return Candidate(row, col, z, missing)


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.idle()
        self.out = []          # (cycle, kind, payload)
        self.cycle = 0
        cocotb.start_soon(self.monitor())

    def idle(self):
        d = self.dut
        d.cand_valid_i.value = 0
        d.cand_eof_i.value = 0
        d.cand_frame_i.value = 0
        d.cand_row_i.value = 0
        d.cand_col_i.value = 0
        d.cand_z_i.value = 0
        d.cand_missing_i.value = 0
        d.cand_count_i.value = 0
        d.cand_overflow_i.value = 0
        d.moore_i.value = 1
        d.bias_en_i.value = 1

    async def monitor(self):
        d = self.dut
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            self.cycle += 1
            if not (d.tp_valid_o.value.is_resolvable and d.tp_eof_o.value.is_resolvable):
                continue            # before the reset
            if int(d.tp_valid_o.value):
                self.out.append((self.cycle, "tp", (
                    int(d.tp_frame_o.value), int(d.tp_x_o.value), int(d.tp_y_o.value),
                    int(d.tp_strength_o.value), int(d.tp_axis_major_o.value),
                    int(d.tp_axis_minor_o.value), int(d.tp_angle_o.value), int(d.tp_flags_o.value))))
            if int(d.tp_eof_o.value):
                self.out.append((self.cycle, "eof", (int(d.tp_frame_o.value), int(d.tp_count_o.value),
                                                     int(d.tp_overflow_o.value))))

    async def drive(self, beats):
        """beats: list of None (idle), ('c', cand, frame, moore, bias) or ('e', frame, count, ovf).
        Returns the expected output list (cycle of the input beat, kind, payload)."""
        d = self.dut
        exp = []
        for b in beats:
            await self.writable()
            self.idle()
            if b is not None and b[0] == "c":
                _, c, frame, moore, bias = b
                d.cand_valid_i.value = 1
                d.cand_frame_i.value = frame
                d.cand_row_i.value = c.row
                d.cand_col_i.value = c.col
                d.cand_z_i.value = c.packed_z(self.cfg.hm_width)
                d.cand_missing_i.value = c.missing
                d.moore_i.value = int(moore)
                d.bias_en_i.value = int(bias)
                tp = interp.interp_fixed(c, self.cfg, moore=moore, bias=bias, frame=frame)
                exp.append((self.cycle + 1, "tp", (frame, tp.x, tp.y, tp.strength, tp.axis_major,
                                                   tp.axis_minor, tp.angle, tp.flags)))
            elif b is not None and b[0] == "e":
                _, frame, count, ovf = b
                d.cand_eof_i.value = 1
                d.cand_frame_i.value = frame
                d.cand_count_i.value = count
                d.cand_overflow_i.value = ovf
                exp.append((self.cycle + 1, "eof", (frame, count, ovf)))
        await self.writable()
        self.idle()
        return exp


def frames(rng, cfg, n_frames):
    beats = []
    for f in range(n_frames):
        n = rng.choice([0, 1, 3, 16, rng.randrange(0, 17)])
        gap = rng.choice([0, 0, 1, 3])
        for _ in range(n):
            beats.append(("c", random_cand(rng, cfg), f, rng.random() < 0.7, rng.random() < 0.6))
            if gap and rng.random() < 0.5:
                beats += [None] * rng.randrange(1, gap + 1)
        beats.append(("e", f, n, int(n == 16 and rng.random() < 0.5)))
        beats += [None] * rng.choice([0, 0, 2])
    return beats


def compare(tb, exp, got):
    assert len(got) == len(exp), f"{len(got)} outputs, expected {len(exp)}"
    names = ("frame", "x", "y", "strength", "axis_major", "axis_minor", "angle", "flags")
    for i, ((ce, ke, pe), (cg, kg, pg)) in enumerate(zip(exp, got)):
        assert ke == kg, f"output {i}: {kg}, expected {ke}"
        if pe != pg:
            diff = {n: (g, e) for n, g, e in zip(names, pg, pe) if g != e}
            raise AssertionError(f"output {i} ({ke}) mismatch (rtl, model): {diff}")
        # ce: the edge that samples the input; cg: the edge after which the output shows,
        # so the consumer samples it at cg + 1
        assert cg + 1 - ce == LAT, f"output {i}: latency {cg + 1 - ce}, expected {LAT}"


@cocotb.test()
async def bit_exact_random(dut):
    """Random frames of candidates: every field bit-exact, order, latency, eof/count."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    await tb.reset()
    beats = frames(rng, tb.cfg, env_int("N_FRAMES", 24))
    exp = await tb.drive(beats)
    await tb.cycles(LAT + 4)
    compare(tb, exp, tb.out)
    n_tp = sum(1 for e in exp if e[1] == "tp")
    flags = [e[2][7] for e in exp if e[1] == "tp"]
    # the stimulus really reaches every case
    for bit in range(4):
        assert any(f >> bit & 1 for f in flags), f"no touch with flag bit {bit}"
    assert any(e[2][4] for e in exp if e[1] == "tp"), "no ellipse"
    dut._log.info(f"{n_tp} touches bit-exact, latency {LAT}")


def clamp_boundary_cands(cfg):
    """Interior candidates whose x quotient q (|offset| in 1/512 cell, before the clamp
    and the rounding) is exactly 255..258, for the Moore and the Von Neumann fit: q = 257
    is the first clamped value (0.5 cell, flag bit 0), q = 256 the last one rounded.
    Found by scanning the right neighbour of a fixed 3 x 3 patch (q moves by less than
    one per LSB there) and reading q from the model's own quotient."""
    found = {}
    miss = np.zeros((3, 3), dtype=bool)
    row, col = cfg.rows // 2, cfg.cols // 2
    for moore, base, span in ((True, [[3000, 5200, 3100], [5000, 9000, 0], [2900, 5100, 3000]],
                               range(12500, 13800)),
                              (False, [[0, 5200, 0], [5000, 9000, 0], [0, 5100, 0]],
                               range(8500, 9300))):
        for right in span:
            z = np.array(base, dtype=np.int64)
            z[1][2] = right
            sel, moore_ok, _, _, _ = interp._select(z.tolist(), miss, moore)
            num, den, kind = sel[0]
            if kind != ("moore" if moore else "vn") or moore_ok != moore:
                continue
            q, ovf = interp.div_fixed(abs(num) << 9, den)
            if not ovf and 255 <= q <= 258 and (moore, q) not in found:
                found[(moore, q)] = Candidate(row, col, z, 0)
    return found


@cocotb.test()
async def clamp_boundary(dut):
    """The offset clamp starts exactly at 257/512 cell: quotients 255..258 of both fits
    (random stimulus almost never lands on them), bit-exact with the model, and the
    model itself rounds 256 to 128 unflagged and clamps 257 with flag bit 0."""
    tb = TB(dut)
    await tb.reset()
    found = clamp_boundary_cands(tb.cfg)
    assert {(True, 256), (True, 257)} <= set(found), sorted(found)
    beats = []
    for (moore, q), c in sorted(found.items()):
        beats.append(("c", c, 0, moore, False))
    beats.append(("e", 0, len(found), 0))
    assert interp.offset_fixed(256, 512) == (128, False)
    assert interp.offset_fixed(257, 512) == (128, True)
    exp = await tb.drive(beats)
    await tb.cycles(LAT + 4)
    compare(tb, exp, tb.out)
    flags = {(m, q): e[2][7] & 1 for ((m, q), _), e in zip(sorted(found.items()), exp)}
    assert all(f == (q >= 257) for (m, q), f in flags.items()), flags


@cocotb.test()
async def back_to_back_and_reset(dut):
    """64 candidates on consecutive cycles, then a reset in the middle of a stream: no
    stale touch or eof comes out after the reset."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1) + 100)
    await tb.reset()
    beats = [("c", random_cand(rng, tb.cfg), 7, rng.random() < 0.5, rng.random() < 0.5)
             for _ in range(64)] + [("e", 7, 64 % 256, 0)]
    exp = await tb.drive(beats)
    await tb.cycles(LAT + 4)
    compare(tb, exp, tb.out)
    tb.out.clear()
    beats = [("c", random_cand(rng, tb.cfg), 8, True, True) for _ in range(10)] + [("e", 8, 10, 0)]
    await tb.drive(beats)
    await tb.reset(cycles=2)
    await tb.cycles(LAT + 4)
    # only outputs that were already at the end of the pipeline before the reset
    assert all(c <= tb.cycle - LAT for c, _, _ in tb.out) or not tb.out
    n_before = len(tb.out)
    await tb.cycles(LAT)
    assert len(tb.out) == n_before, "outputs after reset"


# ---- pytest entry ------------------------------------------------------------------
def build_args(sim: str) -> list[str]:
    """The ROMs' folder for $readmemh (simulators resolve paths from their working
    directory); Verilator: one C++ file, -O0 (short runs: the compile dominates)."""
    args = [rom_define()]
    if sim == "verilator":
        args += ["--output-split", "0", "-CFLAGS", "-O0"]
    return args


@pytest.mark.parametrize("cfg", ["small", "medium"])
def test_fmt_interp(sim, cfg):
    c = params.get(cfg)
    p = c.verilog_params()
    run_cocotb(
        sim, "fmt_interp", sources("fmt_interp"), "test_fmt_interp",
        parameters={k: p[k] for k in ("ROWS", "COLS", "HM_W")},
        extra_env={"CFG": cfg, "SEED": 1 if cfg == "small" else 2},
        test_dir=Path(__file__).parent, build_args=build_args(sim), tag=cfg)
