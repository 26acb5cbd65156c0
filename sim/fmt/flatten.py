"""Field flattening and its calibration: the twin of ``rtl/fmt_flatten.v``.

    z' = (z - offset[r][c]) * gain[r][c]

Formats (all unsigned):

* ``z``, ``offset``, ``z'``: ``HM_W`` bits (``cfg.hm_width``), counts.
* ``gain``: 16 bits, Q2.14: 1.0 = 16384 (``GAIN_ONE``), range 0 .. 3.99994.

Fixed-point rule (``flatten_fixed``, bit-exact with the RTL):

1. ``d = z - offset`` (HM_W + 1 bit signed).  ``d < 0`` -> ``d = 0``.  A cell below its
   own baseline is ordinary noise on an untouched cell, so this clamp is **not** an
   error and is not flagged (flagging it would keep the sticky flag set forever).
2. ``p = d * gain`` (HM_W + 16 bits).
3. ``q = (p + 2^13) >> 14``: round half up.
4. ``q > 2^HM_W - 1`` -> ``q = 2^HM_W - 1`` and the cell's saturation bit is set (the RTL
   raises a sticky flag and counts saturated cells).

The float model ``flatten_float`` computes ``max(z - offset, 0) * gain / 2^14`` with the same
clamps, no rounding; ``|fixed - float| <= 0.5`` LSB for every non-saturated cell.

Calibration (``calibrate``): the offset of a cell is the (rounded) mean of untouched
frames (baseline).  The gain is set from frames taken with a **calibration object of
known coupling**: by default a flat conductive sheet (or a uniform pressed pad) covering
the whole sensor, ``calib_truth_map`` = all ones; any known contact map (e.g. the scene
model's rendering of a calibration puck) works, cells where the truth is zero keep gain
1.0.  The gain makes ``(calib - offset) * gain`` proportional to the truth map with a
common scale chosen so the median gain is 1.0 (the flattened heat map keeps the raw
counts' scale and the touch threshold keeps its meaning).  Power-on values: offset 0,
gain 1.0 (the block is transparent).
"""
from __future__ import annotations

import numpy as np

from .params import SensorConfig

GAIN_BITS = 16          # unsigned gain word
GAIN_FRAC = 14          # Q2.14
GAIN_ONE = 1 << GAIN_FRAC
GAIN_MAX = (1 << GAIN_BITS) - 1


def identity(cfg: SensorConfig) -> tuple[np.ndarray, np.ndarray]:
    """Power-on calibration: offset 0, gain 1.0 everywhere."""
    return (np.zeros((cfg.rows, cfg.cols), dtype=np.int64),
            np.full((cfg.rows, cfg.cols), GAIN_ONE, dtype=np.int64))


def flatten_fixed(hm, offset, gain, cfg: SensorConfig) -> tuple[np.ndarray, np.ndarray]:
    """Bit-exact twin of ``fmt_flatten``: returns ``(out, sat_mask)``.

    ``hm`` may be one heat map (rows x cols) or a stack (..., rows, cols); ``offset`` and
    ``gain`` broadcast against it.  ``sat_mask`` is True where the result saturated.
    """
    w = cfg.hm_width
    top = (1 << w) - 1
    z = np.asarray(hm, dtype=np.int64)
    off = np.asarray(offset, dtype=np.int64)
    g = np.asarray(gain, dtype=np.int64)
    if (z < 0).any() or (z > top).any() or (off < 0).any() or (off > top).any():
        raise ValueError("heat map and offsets must be unsigned HM_W-bit")
    if (g < 0).any() or (g > GAIN_MAX).any():
        raise ValueError("gain must be unsigned 16-bit (Q2.14)")
    d = np.maximum(z - off, 0)
    q = (d * g + (1 << (GAIN_FRAC - 1))) >> GAIN_FRAC
    sat = q > top
    return np.minimum(q, top), sat


def flatten_float(hm, offset, gain, cfg: SensorConfig) -> np.ndarray:
    """Floating-point reference: ``max(z - offset, 0) * gain / 2^14`` clipped to full scale.
    ``gain`` is the Q2.14 integer word (so the two models see the same gain)."""
    top = float((1 << cfg.hm_width) - 1)
    d = np.maximum(np.asarray(hm, dtype=float) - np.asarray(offset, dtype=float), 0.0)
    return np.minimum(d * np.asarray(gain, dtype=float) / GAIN_ONE, top)


def calibrate(untouched_frames, calib_frames, calib_truth_map=None, cfg: SensorConfig | None = None,
              ) -> tuple[np.ndarray, np.ndarray]:
    """Offsets and Q2.14 gains from calibration captures.

    ``untouched_frames``: stack (n, rows, cols) of raw heat maps with nothing on the sensor.
    ``calib_frames``: stack (m, rows, cols) with the calibration object in place.
    ``calib_truth_map``: the object's known relative coupling per cell (rows x cols);
    ``None`` = uniform (a sheet covering the sensor).  Returns integer ``(offset, gain)``
    quantized to the RTL formats (offset rounded half up and clipped to HM_W bits, gain
    rounded half up and clipped to 0..65535).
    """
    base = np.asarray(untouched_frames, dtype=float)
    if base.ndim == 2:
        base = base[None]
    cal = np.asarray(calib_frames, dtype=float)
    if cal.ndim == 2:
        cal = cal[None]
    rows, cols = base.shape[-2:]
    top = (1 << (cfg.hm_width if cfg else 16)) - 1
    offset = np.clip(np.floor(base.mean(axis=0) + 0.5), 0, top).astype(np.int64)
    truth = np.ones((rows, cols)) if calib_truth_map is None else np.asarray(calib_truth_map, float)
    signal = cal.mean(axis=0) - offset
    use = (truth > 0) & (signal > 0)
    gain = np.full((rows, cols), float(GAIN_ONE))
    if use.any():
        ratio = signal[use] / truth[use]          # counts per unit of coupling
        scale = float(np.median(ratio))           # median gain = 1.0
        gain[use] = GAIN_ONE * scale * truth[use] / signal[use]
    gain = np.clip(np.floor(gain + 0.5), 0, GAIN_MAX).astype(np.int64)
    return offset, gain
