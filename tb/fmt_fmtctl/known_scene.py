"""A known touch scene for the host-tool tests: heat maps made directly (Gaussian
bumps on a flat baseline, no physics) and the bit-exact model's events of them."""
from __future__ import annotations

import numpy as np

from fmt import params
from fmt.host import events as E
from fmt.touch import process_frames  # (also used by the tests)

PEAK = 9000


def heatmaps(cfg=params.DEFAULT, frames: int = 24) -> np.ndarray:
    """Finger A still at (x 10.3, y 7.6) cells; finger B drags from (25.0, 20.0) to
    (31.0, 22.0) and lifts after frame 15; finger C lands at frame 6 at (4.5, 24.2)."""
    yy, xx = np.mgrid[0:cfg.rows, 0:cfg.cols].astype(float)
    out = np.full((frames, cfg.rows, cfg.cols), 100.0)
    for f in range(frames):
        fingers = [(10.3, 7.6)]
        if f <= 15:
            fingers.append((25.0 + 6.0 * f / 15, 20.0 + 2.0 * f / 15))
        if f >= 6:
            fingers.append((4.5, 24.2))
        for x, y in fingers:
            out[f] += PEAK * np.exp(-((xx - x) ** 2 + (yy - y) ** 2) / (2 * 0.7 ** 2))
    return np.rint(out).astype(np.int64)


def model_events(hm, cfg=params.DEFAULT):
    return process_frames(hm, cfg, fixed=True, frame_period_s=cfg.window_s)


def records(hm, cfg=params.DEFAULT) -> list[dict]:
    return E.from_model(model_events(hm, cfg), period_clk=3 * cfg.n_fft)
