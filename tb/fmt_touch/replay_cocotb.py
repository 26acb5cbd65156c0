"""cocotb side of scripts/replay_touch.py: heat maps from a .npy file through
rtl/fmt_touch.v, events to JSON lines.

Environment: CFG (sensor config), REPLAY_IN (.npy, frames x rows x cols), REPLAY_OUT
(.jsonl), REPLAY_SETTINGS (optional JSON of fmt.settings.TouchSettings fields),
REPLAY_FRAME_PERIOD_S (default: one window).  Rows go
in the order the RTL receive chain emits them (rx_array.row_order), one frame per window
at 3 x fs (3 N clocks), identity calibration.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import RisingEdge

from fmt import flatten, rx_array
from fmt.settings import TouchSettings
from fmt_touch.touch_driver import TB, group

TYPES = {0: "new", 1: "move", 2: "lift", 3: "blob"}
FIELDS = ("frame", "id", "type", "x_q", "y_q", "strength", "axis_major_q", "axis_minor_q",
          "angle", "flags")


class _FftOrder:
    """Stands in for the rng of TB.send: rows in the receive chain's order."""

    def __init__(self, cfg):
        self.order = [int(r) for r in rx_array.row_order(cfg)]

    def shuffle(self, rows):
        rows[:] = self.order


def replay_settings() -> TouchSettings:
    p = os.environ.get("REPLAY_SETTINGS", "")
    return TouchSettings(**json.loads(Path(p).read_text())) if p else TouchSettings()


@cocotb.test()
async def replay(dut):
    tb = TB(dut)
    cfg = tb.cfg
    maps = np.load(os.environ["REPLAY_IN"])
    if maps.ndim != 3 or maps.shape[1:] != (cfg.rows, cfg.cols):
        raise ValueError(f"{os.environ['REPLAY_IN']}: shape {maps.shape}, expected "
                         f"(frames, {cfg.rows}, {cfg.cols}) for the '{cfg.name}' sensor")
    st = replay_settings()
    # tracking settings converted with the real frame period (one window at M = 1)
    tb.settings(st, float(os.environ.get("REPLAY_FRAME_PERIOD_S", cfg.window_s)))
    dut.blob_en_i.value = 0
    await tb.reset()
    await tb.calibrate(*flatten.identity(cfg))
    tb.events.clear()
    await tb.send(maps, _FftOrder(cfg), 3 * cfg.n_fft)
    for _ in range(400):
        await RisingEdge(tb.clk)
    with open(os.environ["REPLAY_OUT"], "w") as f:
        for fr in group(tb.events):
            for cyc, e in fr:
                rec = dict(zip(FIELDS, e))
                rec["type"] = TYPES[rec["type"]]
                rec["cycle"] = cyc
                f.write(json.dumps(rec) + "\n")
