"""ADC stimulus for the receive back-end testbenches and scripts/replay_rx.py.

Every generator returns (adc (samples, cols) int64 in ADC_BITS range, rx_sign (samples,)
uint8): the row tones (optionally stirred by the PN transmit sign), noise and the hard
cases of the brief, one window at a time.
"""
from __future__ import annotations

import numpy as np

from fmt.pn_gen import pn_signs


def clip_adc(x, cfg):
    lo, hi = -(1 << (cfg.adc_bits - 1)), (1 << (cfg.adc_bits - 1)) - 1
    return np.clip(np.round(x), lo, hi).astype(np.int64)


def pn(cfg, samples, rng, enable=None, chip_len=None, delay=None):
    """(tx, rx) PN signs with random settings (on/off, chip length, delay)."""
    enable = bool(rng.integers(0, 2)) if enable is None else enable
    chip_len = int(rng.choice([1, 2, 3, 7])) if chip_len is None else chip_len
    delay = int(rng.integers(0, 4)) if delay is None else delay
    tx, rx = pn_signs(samples, chip_len=chip_len, enable=enable, rx_delay=delay)
    return tx, rx, dict(enable=enable, chip_len=chip_len, delay=delay)


def tones(cfg, samples, rng, amp=None, noise=4.0, tx=None, phase_same=False, delay=0):
    """Row tones on every column with a random coupling per cell (touch-like), stirred
    by the transmit sign ``tx`` (delayed by ``delay`` samples, the channel), plus noise."""
    n = cfg.n_fft
    t = np.arange(samples)
    full = (1 << (cfg.adc_bits - 1)) - 1
    amp = full / cfg.rows if amp is None else amp
    g = rng.uniform(0.3, 1.0, (cfg.rows, cfg.cols)) * amp
    ph = np.zeros((cfg.rows, cfg.cols)) if phase_same else rng.uniform(0, 2 * np.pi, (cfg.rows, cfg.cols))
    x = np.zeros((samples, cfg.cols))
    for r, k in enumerate(cfg.bins):
        x += g[r][None, :] * np.cos(2 * np.pi * k * t[:, None] / n + ph[r][None, :])
    if tx is not None:
        s = 1.0 - 2.0 * tx.astype(float)
        s = np.concatenate([np.ones(delay), s[:samples - delay]]) if delay else s
        x *= s[:, None]
    x += rng.normal(0, noise, x.shape)
    return clip_adc(x, cfg)


def uniform_random(cfg, samples, rng):
    """Full-range random ADC words (worst-case random growth)."""
    lo, hi = -(1 << (cfg.adc_bits - 1)), (1 << (cfg.adc_bits - 1))
    return rng.integers(lo, hi, (samples, cfg.cols)).astype(np.int64)


def hard_cases(cfg, rng):
    """One window each: palm (column 0 saturated), DC offset, impulse, a tone between
    bins, all rows at full amplitude in phase (growth), full-scale random.  Returns
    (adc, names) with no PN (rx_sign = 0)."""
    n = cfg.n_fft
    full = (1 << (cfg.adc_bits - 1)) - 1
    t = np.arange(n)
    wins, names = [], []
    # palm: heavy coupling on column 0 drives the ADC into both rails
    w = tones(cfg, n, rng)
    w[:, 0] = clip_adc(8 * full * np.cos(2 * np.pi * cfg.bins[0] * t / n) * 1.0, cfg)
    wins.append(w); names.append("palm")
    # DC offset on every column on top of the tones
    w = tones(cfg, n, rng, amp=full / cfg.rows / 2)
    wins.append(clip_adc(w + full // 2, cfg)); names.append("dc")
    # impulse: one full-scale sample on every column
    w = np.zeros((n, cfg.cols), dtype=np.int64)
    w[n // 3, :] = full
    w[n // 3 + 1, 1::2] = -full - 1
    wins.append(w); names.append("impulse")
    # a tone between two comb bins (k + 1/2): leaks into its neighbours
    w = clip_adc(np.repeat((full / 2 * np.cos(2 * np.pi * (cfg.bins[1] + 0.5) * t / n))[:, None], cfg.cols, 1), cfg)
    wins.append(w); names.append("between")
    # growth: every row at full amplitude, in phase, peaks add up to full scale
    w = tones(cfg, n, rng, amp=full / cfg.rows, noise=0.0, phase_same=True)
    wins.append(w); names.append("growth")
    wins.append(uniform_random(cfg, n, rng)); names.append("random")
    # a pure full-scale tone on one bin on every column: the largest cell (saturation edge)
    w = clip_adc(np.repeat((full * np.cos(2 * np.pi * cfg.bins[-1] * t / n))[:, None], cfg.cols, 1), cfg)
    wins.append(w); names.append("fullscale")
    return np.concatenate(wins), names
