"""Reusable parts of the fmt_touch testbench: the bench class (:class:`TB`: settings,
calibration, heat-map rows in, events out), the rendered-scene heat maps, the grouping
of events per frame and the build arguments.  Used by test_fmt_touch.py,
test_replay_touch.py and replay_cocotb.py (scripts/replay_touch.py); nothing imports a
test module.
"""
from __future__ import annotations

import cocotb
import numpy as np
from cocotb.triggers import ReadOnly, RisingEdge

from common.sources import rom_define
from common.tb_util import ClockedTB, env_str
from fmt import params, sensor
from fmt.settings import TouchSettings
from fmt.tracker import TrackParams

FRAME_PERIOD_S = 1e-3          # scaled timeline for the tracking settings


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.cycle = 0
        self.events = []
        self.row_cycles = {}
        d = dut
        d.hm_valid_i.value = 0
        d.hm_eof_i.value = 0
        d.hm_row_i.value = 0
        d.hm_frame_i.value = 0
        d.hm_data_i.value = 0
        d.cal_we_i.value = 0
        d.cal_sel_i.value = 0
        d.cal_row_i.value = 0
        d.cal_col_i.value = 0
        d.cal_data_i.value = 0
        d.cal_re_i.value = 0
        d.sat_clr_i.value = 0
        d.ev_ready_i.value = 1
        d.delay_i.value = 0
        d.report_period_i.value = 0
        d.blob_en_i.value = 0
        d.blob_threshold_i.value = 1
        d.blob_min_cells_i.value = 0
        cocotb.start_soon(self._monitor())

    def settings(self, st: TouchSettings, frame_period_s: float = FRAME_PERIOD_S):
        """Drive the settings inputs; the tracking settings are converted with
        ``frame_period_s`` (default: the tests' scaled timeline)."""
        cfg, d = self.cfg, self.dut
        tp = TrackParams.from_settings(cfg, st, frame_period_s)
        d.threshold_i.value = st.threshold
        d.moore_i.value = int(st.neighbourhood == "moore")
        d.limit_i.value = st.max_touches if st.max_touches is not None else cfg.max_touches
        d.bias_en_i.value = int(st.bias_correction)
        d.max_jump_i.value = tp.max_jump_q
        d.gate_step_i.value = tp.gate_step_q
        d.hold_off_i.value = tp.hold_off_frames
        d.vel_shift_i.value = tp.vel_shift
        d.max_speed_i.value = tp.max_speed_v
        d.on_thr_i.value = tp.on_threshold
        d.confirm_i.value = tp.confirm_frames
        d.blob_threshold_i.value = st.blob_threshold
        d.blob_min_cells_i.value = st.blob_min_cells

    async def _monitor(self):
        d = self.dut
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            self.cycle += 1
            v, r = d.ev_valid_o.value, d.rst.value
            if not (v.is_resolvable and r.is_resolvable) or int(r):
                continue
            if int(v) and int(d.ev_ready_i.value):
                self.events.append((self.cycle, tuple(int(getattr(d, f).value) for f in (
                    "ev_frame_o", "ev_id_o", "ev_type_o", "ev_x_o", "ev_y_o", "ev_strength_o",
                    "ev_axis_major_o", "ev_axis_minor_o", "ev_angle_o", "ev_flags_o")),
                    int(d.ev_last_o.value)))

    async def calibrate(self, off, gain):
        d, cfg = self.dut, self.cfg
        await self.writable()
        for sel, arr in ((0, off), (1, gain)):
            for r in range(cfg.rows):
                for c in range(cfg.cols):
                    d.cal_we_i.value = 1
                    d.cal_sel_i.value = sel
                    d.cal_row_i.value = r
                    d.cal_col_i.value = c
                    d.cal_data_i.value = int(arr[r, c])
                    await RisingEdge(self.clk)
                    await self.writable()
        d.cal_we_i.value = 0

    async def send(self, frames, rng, period, hook=None, spread=False, first_frame=0):
        """Heat maps one row per cycle in random order, hm_eof on the next cycle, one
        frame every `period` cycles, numbered from ``first_frame``.  Records the edge that
        takes each last row.
        ``hook(k, i)``, if given, runs before every cycle is driven (frame k; i = the
        beat's index in the frame: rows 0..rows-1, then rows for hm_eof and rows + 1 for
        the idle cycles): it may change the settings in any cycle.  ``spread``: the
        rows spread over the period as the receive array sends them (idle cycles after
        each row, the next frame's first row soon after hm_eof), so that a frame is
        still being finished while the next one arrives."""
        d, cfg = self.dut, self.cfg
        w = cfg.hm_width
        gap = max(0, (period - cfg.rows - 1) // max(1, cfg.rows - 1)) if spread else 0
        await self.writable()
        for k, hm in enumerate(frames, start=first_frame):
            order = list(range(cfg.rows))
            rng.shuffle(order)
            t0 = self.cycle
            for i, r in enumerate(order):
                if hook is not None:
                    hook(k, i)
                word = 0
                for c in range(cfg.cols):
                    word |= int(hm[r, c]) << (c * w)
                d.hm_valid_i.value = 1
                d.hm_row_i.value = r
                d.hm_frame_i.value = k
                d.hm_data_i.value = word
                await RisingEdge(self.clk)
                await self.writable()
                if gap and r != order[-1]:
                    d.hm_valid_i.value = 0
                    for _ in range(gap):
                        if hook is not None:
                            hook(k, cfg.rows + 1)
                        await RisingEdge(self.clk)
                        await self.writable()
            self.row_cycles[k] = self.cycle          # the edge that took the last row
            if hook is not None:
                hook(k, cfg.rows)
            d.hm_valid_i.value = 0
            d.hm_eof_i.value = 1
            d.hm_frame_i.value = k
            await RisingEdge(self.clk)
            await self.writable()
            d.hm_eof_i.value = 0
            while self.cycle < t0 + period:
                if hook is not None:
                    hook(k, cfg.rows + 1)
                await RisingEdge(self.clk)
                await self.writable()


def scene_maps(cfg, n, top, rng):
    """Two fingers moving 0.4 mm per frame, one tapping, a 3rd crossing."""
    out = np.zeros((n, cfg.rows, cfg.cols), dtype=np.int64)
    W, H = cfg.width_mm, cfg.height_mm
    for k in range(n):
        cts = [(3 + 0.4 * k % (W - 6), 0.3 * H + 0.1 * k, 8.0, 1.0)]
        if (k // 5) % 2 == 0:
            cts.append((0.7 * W, 0.6 * H, 7.0, 0.8))
        cts.append((W - 3 - 0.5 * k % (W - 6), 0.5 * H, 8.0, 1.2))
        m = sensor.contact_map(cfg, cts) * 25000 + rng.normal(0, 30, (cfg.rows, cfg.cols)) + 200
        out[k] = np.clip(np.rint(m), 0, top)
    return out


def group(events):
    fr, cur = [], []
    for c, e, last in events:
        cur.append((c, e))
        if last:
            fr.append(cur)
            cur = []
    assert not cur, "stream ended inside a frame"
    return fr


def build_args(sim: str, opt: str = "-O0") -> list[str]:
    """Verilator: one C++ file at ``opt``: -O0 for the short replays (the compile
    dominates); the cocotb tests of test_fmt_touch.py pass -O1 (their ~1.8 ms of
    simulated time ran 81 s at -O0 and 11 s at -O1, for 11 s more of compile)."""
    args = [rom_define()]
    if sim == "verilator":
        args += ["--output-split", "0", "--output-split-cfuncs", "0", "-CFLAGS", opt]
    return args
