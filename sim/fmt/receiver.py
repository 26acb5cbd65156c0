"""Floating-point receiver: despread, FFT per window, comb bins, magnitude, accumulation.

Per column c and window w (samples wN .. wN+N-1 from sample 0):

    y[n]      = adc[n, c] * (+1/-1 from rx_sign[n])                (despread)
    X_w[k]    = sum_j y[wN + j] exp(-2 pi i k j / N)               (numpy rfft)
    cell[r,c] = hm_scale * |X_w[k_r]|, k_r = cfg.bins[r]
    heat map  = mean of the cells over the M windows of a frame    (frames, rows, cols)

Scale (``hm_scale``): 4/N * 2**(HM_W - ADC_BITS): a tone of amplitude A LSB at the ADC
reads A * 2**(HM_W - ADC_BITS + 1) counts (32 A for 16-bit cells and a 12-bit ADC), so a
full-scale ADC tone (2048 LSB) just reaches the 16-bit limit.  This is the scale of the
fixed-point receive chain (``rx_fixed.rx_heatmaps_fixed``: FFT growth schedule, pair
split, CORDIC, accumulator), so float and fixed heat maps, and the touch thresholds, mean
the same counts (sim/tests/test_receiver.py compares the two: ratio 1 within 0.5 %).  With
the sensor's TONE_LSB = 320 a unit-coupling cell (a fully covered cell) reads
``unit_cell_counts(cfg)`` = 10240 counts, the baseline 320.
"""
from __future__ import annotations

import numpy as np

from . import sensor as _sensor
from .params import SensorConfig


def hm_scale(cfg: SensorConfig) -> float:
    """Heat-map counts per unit of |X[k]| (see the module docstring)."""
    return 4.0 / cfg.n_fft * 2.0 ** (cfg.hm_width - cfg.adc_bits)


def unit_cell_counts(cfg: SensorConfig) -> float:
    """Heat-map value of a unit-coupling cell (noiseless, no attenuation)."""
    return _sensor.TONE_LSB * 2.0 ** (cfg.hm_width - cfg.adc_bits + 1)


def despread(adc, rx_sign=None, dtype=np.float64) -> np.ndarray:
    """adc (samples, cols) times +1/-1 (rx_sign 1 = invert; None = PN off)."""
    x = np.asarray(adc).astype(dtype)
    if rx_sign is not None:
        x *= (1.0 - 2.0 * np.asarray(rx_sign, dtype=dtype))[:, None]
    return x


def window_spectra(x: np.ndarray, cfg: SensorConfig) -> np.ndarray:
    """Comb-bin DFT values (windows, rows, cols) complex of despread samples (samples, cols);
    a trailing partial window is dropped."""
    n = cfg.n_fft
    wins = x.shape[0] // n
    xw = x[:wins * n].reshape(wins, n, x.shape[1])
    X = np.fft.rfft(xw, axis=1)
    return X[:, np.asarray(cfg.bins), :]


def window_cells(adc, cfg: SensorConfig, rx_sign=None, scale: float | None = None) -> np.ndarray:
    """Per-window cells (windows, rows, cols) float: scale * |X_w[k_r]|."""
    s = hm_scale(cfg) if scale is None else scale
    return s * np.abs(window_spectra(despread(adc, rx_sign), cfg))


def accumulate(cells: np.ndarray, m: int) -> np.ndarray:
    """Mean over consecutive groups of m windows -> (frames, rows, cols); a trailing
    partial frame is dropped."""
    frames = cells.shape[0] // m
    return cells[:frames * m].reshape((frames, m) + cells.shape[1:]).mean(axis=1)


def receive(adc, cfg: SensorConfig, rx_sign=None, m: int = 1,
            scale: float | None = None) -> np.ndarray:
    """Heat maps (frames, rows, cols) float64 of an ADC stream starting at a window
    boundary (see the module docstring)."""
    return accumulate(window_cells(adc, cfg, rx_sign, scale), m)
