"""cocotb side of scripts/replay_rx.py: feeds an ADC capture (samples x columns, int)
through fmt_rx_array and writes the heat maps it streams out.

Environment: REPLAY_IN (.npy adc), REPLAY_SIGN (.npy rx sign, optional: PN off),
REPLAY_OUT (.npy heat maps, frames x rows x cols), CFG, M (windows per frame, any) or
M_LOG2 (M = 2^M_LOG2).
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import cocotb
import numpy as np

from fmt_rx_array.rx_driver import TB


@cocotb.test()
async def replay(dut):
    tb = TB(dut)
    cfg = tb.cfg
    adc = np.load(os.environ["REPLAY_IN"]).astype(np.int64)
    if adc.ndim != 2 or adc.shape[1] != cfg.cols:
        raise ValueError(f"capture must be (samples, {cfg.cols}), got {adc.shape}")
    lo, hi = -(1 << (cfg.adc_bits - 1)), (1 << (cfg.adc_bits - 1)) - 1
    if adc.min() < lo or adc.max() > hi:
        raise ValueError(f"capture outside the {cfg.adc_bits}-bit ADC range")
    sp = os.environ.get("REPLAY_SIGN", "")
    rx = np.load(sp).astype(np.uint8) if sp else np.zeros(len(adc), dtype=np.uint8)
    # windows per frame: M (any), else 2^M_LOG2 (scripts/replay_rx.py)
    m = int(os.environ.get("M", "0")) or (1 << int(os.environ.get("M_LOG2", "0")))
    frames = (len(adc) // cfg.n_fft) // m
    await tb.reset()
    beats, eofs, _ = await tb.run(adc, rx, m)
    hm = tb.frames_from(beats, eofs, frames)
    np.save(os.environ["REPLAY_OUT"], hm.astype(np.uint32))
    info = {"frames": int(frames), "sat": int(dut.sat_o.value), "fft_ovf": int(dut.fft_ovf_o.value),
            "overrun": int(dut.overrun_o.value)}
    Path(os.environ["REPLAY_OUT"] + ".json").write_text(json.dumps(info) + "\n")
    dut._log.info(f"replay: {info}")
