"""Transmit, channel and ADC (floating-point physics, integer ADC words out).

Column c at ADC sample n (before quantisation, in LSB):

    v[n, c] = TONE_LSB * sum_r G[n, r, c] * p(n - d) * sin(2 pi k_r (n - d) / N + phi_r)
              + oscillators(n) + charger(n) * w_c(n) + dc + noise[n, c]
    G[n]    = (baseline + sum_k touching_k(n) * map_k(n)) * attenuation      (sensor.py)
              (* (1 + a t) + baseline * b t with a ``drift``)
    adc     = enob_mask(clip(round_half_even(v), -2**(B-1), 2**(B-1) - 1))

* Row tones: exact FFT bins k_r = cfg.bins[r], equal amplitude, phase phi_r = 0 (the DDS
  starts every row at phase 0 and sends a sine) or Schroeder phases ("tone_phases").
  Every window of N samples of a tone is identical (exact bins).
* PN: p = +1/-1 from ``fmt.pn_gen.pn_signs`` (tx sign 1 = invert), common to all rows; the
  channel delays the modulated row signals by d = ``delay_samples``; before the first
  sample the delayed sign is +1 (the convention of the receiver's delay line, which also
  outputs 0 = +1 before its first sample), so a matched receive delay despreads exactly.
* Coupling changes at ANY sample: contact k touches on the exact samples of its intervals
  (``touching_k(n)``).  Moving contacts: the contact map is evaluated exactly at every
  window boundary and linearly interpolated in between (a contact moves 6 um per window
  at 1 m/s; the interpolation error is second order in that, < 1e-6 of a cell).
* Oscillators (:func:`oscillators`): interferers (fixed, sweeping, in bursts) and display
  harmonics on every column; charger harmonics or a square wave on column c weighted by
  w_c(n) = the touching contacts' coupling to the column over a default finger's
  (:func:`charger_column_weights`, from G - baseline: 0 when nothing touches).
* ADC: round half to even (numpy rint), clip to the B-bit range (counted: ``clipped``),
  ENOB = clear the low B - enob bits (floor), DC offset and noise before quantisation.
  Noise: white Gaussian, sigma from ``noise_sigma_for_snr`` (the default physics).

The RTL bench (``make sim``) applies the same effects in integers (``FixedEffects``,
``channel_sim_fixed`` below; bit-exact with bench/core's C++ and Verilog channels): a
counter-based noise generator instead of numpy's, oscillators from a 64-bit phase
accumulator and a 4096-word sine table, the charger weights held per coupling update,
round half up, row words before the channel delay are 0 (docs/simulation.md lists the
differences).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import pn_gen as _pn
from . import sensor as _sensor
from .params import SensorConfig
from .scene import DEFAULT_SNR_DB, FINGER_MM, Scene


# ---- tones ------------------------------------------------------------------------------
def tone_phases(cfg: SensorConfig, kind: str = "zero") -> np.ndarray:
    """Start phase of every row's sine: "zero" (the DDS) or "schroeder"
    (phi_r = -pi r^2 / R, low crest factor)."""
    r = np.arange(cfg.rows)
    if kind == "zero":
        return np.zeros(cfg.rows)
    if kind == "schroeder":
        return -np.pi * r * r / cfg.rows
    raise ValueError(f"unknown tone_phases '{kind}'")


def tone_table(cfg: SensorConfig, phases=None, delay: int = 0, dtype=np.float64) -> np.ndarray:
    """(N, rows) one window of every row tone at the ADC, unit amplitude:
    sin(2 pi k_r (j - delay) / N + phi_r), j = 0..N-1 (exactly periodic in N)."""
    n = cfg.n_fft
    ph = np.zeros(cfg.rows) if phases is None else np.asarray(phases, dtype=np.float64)
    k = np.asarray(cfg.bins, dtype=np.int64)
    j = (np.arange(n, dtype=np.int64)[:, None] - delay) * k[None, :] % n   # exact phase index
    return np.sin(2.0 * np.pi * j / n + ph[None, :]).astype(dtype)


# ---- noise calibration ------------------------------------------------------------------
def finger_peak_coupling(cfg: SensorConfig, level: float = _sensor.BASELINE) -> float:
    """Coupling of the peak cell under a default finger centred on a cell (model value)."""
    r, c = cfg.rows // 2, cfg.cols // 2
    m = _sensor.coupling(cfg, [(c * cfg.pitch_mm, r * cfg.pitch_mm, FINGER_MM, 1.0)], level=level)
    return float(m[r, c])


def noise_sigma_for_snr(cfg: SensorConfig, snr_db: float = DEFAULT_SNR_DB,
                        level: float = _sensor.BASELINE) -> float:
    """ADC noise sigma (LSB) giving ``snr_db`` at M = 1 for a default finger centred on a
    cell.  The peak cell's tone amplitude A = TONE_LSB * coupling comes from the sensor
    model; white noise of sigma per sample puts sigma * sqrt(N/2) on each quadrature of a
    DFT bin whose tone is A * N / 2, so the cell's magnitude has RMS noise sigma *
    sqrt(N/2) (high SNR: the in-phase component) and SNR = A sqrt(N/2) / sigma.  The ADC's
    own quantisation noise (1/12 LSB^2) is subtracted from the budget."""
    a = _sensor.TONE_LSB * finger_peak_coupling(cfg, level)
    total = a * math.sqrt(cfg.n_fft / 2.0) / 10.0 ** (snr_db / 20.0)
    return math.sqrt(max(total * total - 1.0 / 12.0, 0.0))


def scene_noise_sigma(scene: Scene) -> float:
    """Noise sigma (LSB) the scene asks for (0 without a noise effect)."""
    nz = scene.effects.get("noise")
    if not nz:
        return 0.0
    if "rms_lsb" in nz:
        return float(nz["rms_lsb"])
    level = scene.effects.get("baseline", _sensor.BASELINE)
    return noise_sigma_for_snr(scene.cfg, float(nz.get("snr_db", DEFAULT_SNR_DB)), level)


# ---- coupling over time -----------------------------------------------------------------
@dataclass
class WindowCoupling:
    """Coupling of windows w0 .. w1-1 (coupling units, attenuation included).

    ``g0[w]``, ``g1[w]``: the always-touching part at the window's first sample and at the
    next window's first sample (linear in between).  ``partial``: a list of
    (window, mask (N,), map0, map1) for contacts that touch only part of the window.
    ``b0[w]``, ``b1[w]``: the untouched baseline at the same two instants (it moves only
    with a ``drift`` effect); g - b is the touching contacts' part (charger weights)."""

    g0: np.ndarray
    g1: np.ndarray
    partial: list
    b0: np.ndarray | None = None
    b1: np.ndarray | None = None


def drift_rates(scene: Scene):
    """(gain, offset) drift rates per cell, (rows, cols) each, in fractions per second, or
    None without a ``drift`` effect: each cell's gain drifts at a rate drawn uniformly from
    +-gain_pct_per_s %/s and its offset at +-offset_pct_per_s % of its untouched coupling
    per second, from a generator seeded by the scene's seed (the same cells drift the same
    way in every run of the scene)."""
    d = scene.effects.get("drift")
    if not d:
        return None
    cfg = scene.cfg
    rng = np.random.default_rng([int(scene.seed), 0xD21F7])
    ga = float(d.get("gain_pct_per_s", 0.0)) / 100.0 * rng.uniform(-1.0, 1.0, (cfg.rows, cfg.cols))
    of = float(d.get("offset_pct_per_s", 0.0)) / 100.0 * rng.uniform(-1.0, 1.0, (cfg.rows, cfg.cols))
    return ga, of


def window_coupling(scene: Scene, w0: int, w1: int) -> WindowCoupling:
    cfg = scene.cfg
    n, fs = cfg.n_fft, cfg.fs_hz
    eff = scene.effects
    att = _sensor.attenuation(cfg, eff.get("row_db_per_cell", 0.0), eff.get("col_db_per_cell", 0.0))
    level = eff.get("baseline", _sensor.BASELINE)
    fringe = eff.get("fringe_mm", 0.0)
    nw = w1 - w0
    g0 = np.broadcast_to(level * att, (nw, cfg.rows, cfg.cols)).copy()
    g1 = g0.copy()
    partial = []
    edges = np.arange(w0, w1 + 1, dtype=np.int64) * n
    t = edges / fs
    for c in scene.contacts:
        frac = c.active_fraction(edges, fs)
        if not frac.any():
            continue
        use = np.nonzero(frac > 0)[0]
        if c.fixed:          # one map for every boundary
            m = _sensor.contact_maps(cfg, [tuple(c.position(0.0)) + c.shape_row()],
                                     c.profile, fringe)[0] * att
            full = use[frac[use] == 1.0]
            g0[full] += m
            g1[full] += m
            at = lambda b, m=m: m
        else:
            bidx = np.unique(np.concatenate([use, use + 1]))
            pos = c.position(t[bidx])
            rows = np.column_stack([pos, c.shape_rows(t[bidx])])
            maps = _sensor.contact_maps(cfg, rows, c.profile, fringe) * att
            lut = np.full(nw + 1, -1, dtype=np.int64)
            lut[bidx] = np.arange(bidx.size)
            full = use[frac[use] == 1.0]
            g0[full] += maps[lut[full]]
            g1[full] += maps[lut[full + 1]]
            at = lambda b, maps=maps, lut=lut: maps[lut[b]]
        for w in use[frac[use] < 1.0]:
            mask = c.active_mask(int(edges[w]), int(edges[w + 1]), fs)
            partial.append((int(w), mask, at(w), at(w + 1)))   # w: index within w0..w1-1
    base = level * att
    dr = drift_rates(scene)
    if dr is None:
        b = np.broadcast_to(base, g0.shape)
        return WindowCoupling(g0, g1, partial, b, b)
    # drift: G(t) = G_0(t) (1 + gain t) + base offset t at every window boundary t
    ga, of = dr
    tb = (edges / fs)[:, None, None]
    fac = 1.0 + ga[None] * tb                         # (nw + 1, R, C)
    off = base[None] * of[None] * tb
    g0 = g0 * fac[:-1] + off[:-1]
    g1 = g1 * fac[1:] + off[1:]
    partial = [(w, mask, m0 * fac[w], m1 * fac[w + 1]) for w, mask, m0, m1 in partial]
    bb = base[None] * fac + off
    return WindowCoupling(g0, g1, partial, bb[:-1], bb[1:])


def coupling_per_sample(scene: Scene, n_samples: int) -> np.ndarray:
    """True coupling G[n, r, c] of samples 0 .. n_samples-1 (float64; big: for short
    streams and tests)."""
    n = scene.cfg.n_fft
    nw = -(-n_samples // n)
    wc = window_coupling(scene, 0, nw)
    f = (np.arange(n) / n)[None, :, None, None]
    g = (1 - f) * wc.g0[:, None] + f * wc.g1[:, None]
    for w, mask, m0, m1 in wc.partial:
        ff = f[0]
        g[w] += mask[:, None, None] * ((1 - ff) * m0 + ff * m1)
    return g.reshape(nw * n, scene.cfg.rows, scene.cfg.cols)[:n_samples]


def left_mul(a: np.ndarray, g: np.ndarray) -> np.ndarray:
    """a (P, R) @ g[w] (R, C) for every w -> (W, P, C), as ONE matrix product (numpy's
    batched matmul of small matrices is slow)."""
    w, r, c = g.shape
    y = a @ g.transpose(1, 0, 2).reshape(r, w * c)
    return y.reshape(a.shape[0], w, c).transpose(1, 0, 2)


# ---- ADC streams --------------------------------------------------------------------------
@dataclass
class AdcResult:
    adc: np.ndarray          # (samples, cols) int16 ADC words
    tx_sign: np.ndarray      # (samples,) uint8 transmit PN sign (1 = invert), undelayed
    rx_sign: np.ndarray      # (samples,) uint8 receive PN sign (delayed by rx_delay)
    clipped: int             # number of clipped samples
    noise_sigma: float       # LSB
    coupling: np.ndarray | None = None   # (samples, rows, cols) when asked

    @property
    def clip_fraction(self) -> float:
        return self.clipped / max(1, self.adc.size)


def pn_settings(scene: Scene) -> tuple[bool, int, int, int]:
    """(enable, chip_len, channel delay, programmed receive delay)."""
    eff = scene.effects
    d = int(eff.get("delay_samples", 0))
    p = eff.get("pn") or {}
    return bool(p.get("enable", False)), int(p.get("chip_len", 1)), d, int(p.get("rx_delay", d))


@functools.lru_cache(maxsize=8)
def _pn_period(bits: int, seed: int) -> np.ndarray:
    """One full period (2**bits - 1 chips) of the LFSR (``fmt.pn_gen.lfsr_chips``), cached."""
    return _pn.lfsr_chips((1 << bits) - 1, bits, None, seed)


def pn_stream(n0: int, n1: int, chip_len: int = 1, enable: bool = True, delay: int = 0,
              bits: int = 15, seed: int = _pn.DEFAULT_SEED) -> np.ndarray:
    """PN sign bits (uint8, 1 = invert) of samples n0 .. n1-1 delayed by ``delay``:
    chips[(n - delay) // chip_len], 0 for n < delay -- the same values as
    ``fmt.pn_gen.pn_signs`` (checked in the tests) but from a cached LFSR period, so long
    streams cost no Python loop."""
    if not enable:
        return np.zeros(n1 - n0, dtype=np.uint8)
    chip_len = max(1, int(chip_len))
    per = _pn_period(bits, seed)
    t = np.arange(n0, n1, dtype=np.int64) - delay
    out = per[(np.maximum(t, 0) // chip_len) % per.size]
    return np.where(t >= 0, out, 0).astype(np.uint8)


def adc_streams(scene: Scene, cfg: SensorConfig | None = None, n_samples: int | None = None,
                frames: int | None = None, return_coupling: bool = False,
                chunk_windows: int = 128, rng: np.random.Generator | None = None,
                start: int = 0) -> AdcResult:
    """The scene's ADC words, (samples, cols) int16, from sample ``start`` (a multiple of
    N; default 0).

    Length: ``n_samples``, or ``frames`` whole frames, or the whole scene.  Chunked over
    ``chunk_windows`` windows (memory ~ chunk_windows * N * (rows + cols) * 8 bytes); the
    result does not depend on the chunking (the noise generator is drawn sequentially:
    pass the same ``rng`` to consecutive calls to continue a stream).  ``cfg`` (optional)
    runs the scene on another sensor build than its named one (``Scene.with_cfg``)."""
    scene = scene.with_cfg(cfg)
    cfg = scene.cfg
    n = cfg.n_fft
    if start % n:
        raise ValueError("start must be a multiple of N (a window boundary)")
    if n_samples is None:
        n_samples = (scene.frames if frames is None else frames) * scene.samples_per_frame
    eff = scene.effects
    wb = start // n
    nw = -(-n_samples // n)
    total = nw * n
    enable, chip_len, delay, rx_delay = pn_settings(scene)
    tx = pn_stream(start, start + total, chip_len, enable, 0)
    tx_del = pn_stream(start, start + total, chip_len, enable, delay)
    rx = pn_stream(start, start + total, chip_len, enable, rx_delay)
    pm = (1.0 - 2.0 * tx_del.astype(np.float64)) * _sensor.TONE_LSB
    T = tone_table(cfg, tone_phases(cfg, eff.get("tone_phases", "zero")), delay)
    sigma = scene_noise_sigma(scene)
    if sigma > 0 and rng is None:
        rng = np.random.default_rng(scene.seed)
    oscs = oscillators(scene)
    common_osc = [o for o in oscs if not o.charger]
    chg_osc = [o for o in oscs if o.charger]
    dc = float(eff.get("dc_lsb", 0.0))
    bits = cfg.adc_bits
    lo, hi = -(1 << (bits - 1)), (1 << (bits - 1)) - 1
    enob = eff.get("enob")
    out = np.empty((total, cfg.cols), dtype=np.int16)
    coup = np.empty((total, cfg.rows, cfg.cols)) if return_coupling else None
    clipped = 0
    f = (np.arange(n) / n)[:, None]
    for w0 in range(0, nw, chunk_windows):
        w1 = min(nw, w0 + chunk_windows)
        wc = window_coupling(scene, wb + w0, wb + w1)
        # (N, R) @ (R, C) for all windows at once
        y0 = left_mul(T, wc.g0)
        dg = wc.g1 - wc.g0
        v = y0 + f * left_mul(T, dg) if dg.any() else y0
        for w, mask, m0, m1 in wc.partial:
            v[w] += mask[:, None] * ((1.0 - f) * (T @ m0) + f * (T @ m1))
        s0, s1 = w0 * n, w1 * n
        v = v.reshape(-1, cfg.cols) * pm[s0:s1, None]
        if oscs:
            nn = np.arange(start + s0, start + s1, dtype=np.int64)
            for o in common_osc:
                v += o.wave(nn, cfg.fs_hz)[:, None]
            if chg_osc:      # through the touching contacts: weight per column and sample
                cw = lambda g: charger_column_weights(cfg, g)
                wgt = (1.0 - f)[None] * cw(wc.g0 - wc.b0)[:, None, :] + f[None] * cw(wc.g1 - wc.b1)[:, None, :]
                for w, mask, m0, m1 in wc.partial:
                    wgt[w] += mask[:, None] * ((1.0 - f) * cw(m0) + f * cw(m1))
                chg = sum(o.wave(nn, cfg.fs_hz) for o in chg_osc)
                v += chg[:, None] * wgt.reshape(-1, cfg.cols)
        if dc:
            v += dc
        if sigma > 0:
            v += sigma * rng.standard_normal(v.shape)
        q = np.rint(v)
        clipped += int(np.count_nonzero((q[:n_samples - s0] < lo) | (q[:n_samples - s0] > hi)))
        q = np.clip(q, lo, hi).astype(np.int16)
        if enob is not None and enob < bits:
            q &= np.int16(~((1 << (bits - int(enob))) - 1))
        out[s0:s1] = q
        if return_coupling:
            fc = f[None, :, :, None]
            g = (1 - fc) * wc.g0[:, None] + fc * wc.g1[:, None]
            for w, mask, m0, m1 in wc.partial:
                g[w] += mask[:, None, None] * ((1 - f[:, :, None]) * m0 + f[:, :, None] * m1)
            coup[s0:s1] = g.reshape(-1, cfg.rows, cfg.cols)
    return AdcResult(adc=out[:n_samples], tx_sign=tx[:n_samples], rx_sign=rx[:n_samples],
                     clipped=clipped, noise_sigma=sigma,
                     coupling=None if coup is None else coup[:n_samples])


# ---- simulation-only channel (bench/core/fmt_channel_sim.v) ------------------------
def write_noise_hex(path, noise: np.ndarray, noise_bits: int = 16) -> None:
    """Noise words (shape (NOISE_LEN, cols), signed noise_bits) for $readmemh,
    row-major (sample, column)."""
    a = np.asarray(noise, dtype=np.int64)
    lim = 1 << (noise_bits - 1)
    if a.min() < -lim or a.max() >= lim:
        raise ValueError("noise word out of range")
    digits = (noise_bits + 3) // 4
    mask = (1 << noise_bits) - 1
    Path(path).write_text("".join(f"{int(v) & mask:0{digits}x}\n" for v in a.ravel()))


def channel_sim_fixed(dac: np.ndarray, g0: np.ndarray, updates=(), noise=None,
                      adc_bits: int = 12, coup_frac: int = 16, noise_frac: int = 4,
                      effects: "FixedEffects | None" = None):
    """Bit-exact twin of ``fmt_channel_sim``.  ``dac``: (n, rows) row words of samples
    0..n-1; ``g0``: (rows, cols) coupling in effect from sample 0 (unsigned integers,
    coup_frac fractional bits); ``updates``: (stamp, G) pairs in commit order, each in
    effect from sample ``stamp`` on (a later commit must have a later stamp);
    ``noise``: (L, cols) signed file words with noise_frac fractional bits, sample k uses
    row k mod L (the NOISE_FILE of the Verilog; the bench uses ``effects`` instead);
    a matrix with ROWS + 1 rows carries the charger weights W (unsigned, CHG_W_FRAC
    fraction bits) in its last row: column c adds (chg(k) * W_c) >>> CHG_W_FRAC;
    ``effects``: :class:`FixedEffects` (coup_frac must be ADD_FRAC): the row words
    delayed by ``delay`` samples, the counter noise, DC and interferers added, the ENOB
    mask after the clip.  Returns (adc (n, cols) int64, clip (n,) bool): round half up of
    sum_r dac*G + additive terms, then clip to the ADC range (clip: before the ENOB mask)."""
    dac = np.asarray(dac, dtype=np.int64)
    n = dac.shape[0]
    if effects is not None and effects.delay:
        d = effects.delay
        dd = np.zeros_like(dac)
        dd[d:] = dac[:max(n - d, 0)]
        dac = dd
    g_of = np.empty(n, dtype=np.int64)
    mats = [np.asarray(g0, dtype=np.int64)] + [np.asarray(g, dtype=np.int64) for _, g in updates]
    g_of[:] = 0
    for i, (stamp, _) in enumerate(updates):
        g_of[int(stamp):] = i + 1
    rows = dac.shape[1]
    acc = np.zeros((n, mats[0].shape[1]), dtype=object)
    chg = None
    if effects is not None and effects.has_charger:
        chg = effects.charger(0, n).astype(object)
    for i, g in enumerate(mats):
        sel = g_of == i
        if sel.any():
            acc[sel] = (dac[sel].astype(object)) @ g[:rows].astype(object)
            if chg is not None and g.shape[0] > rows:       # row ROWS: the charger weights W
                acc[sel] += (chg[sel][:, None] * g[rows].astype(object)[None, :]) >> CHG_W_FRAC
    if noise is not None:
        nz = np.asarray(noise, dtype=np.int64)
        acc = acc + (nz[np.arange(n) % nz.shape[0]].astype(object) << (coup_frac - noise_frac))
    if effects is not None:
        if coup_frac != ADD_FRAC:
            raise ValueError("effects need coup_frac == ADD_FRAC")
        acc = acc + effects.additive(0, n, acc.shape[1]).astype(object)
    half = (1 << (coup_frac - 1)) if coup_frac > 0 else 0
    y = np.array((acc + half) >> coup_frac, dtype=np.int64)
    lo, hi = -(1 << (adc_bits - 1)), (1 << (adc_bits - 1)) - 1
    clip = ((y < lo) | (y > hi)).any(axis=1)
    y = np.clip(y, lo, hi)
    if effects is not None and effects.enob_clear:
        y &= ~np.int64((1 << effects.enob_clear) - 1)
    return y, clip


# ---- the RTL bench's additive effects, fixed point (bench/core: numpy, C++, Verilog) ------
# Every word below is computed with integer arithmetic only, identically by
# ``channel_sim_fixed`` / ``bench.core.run_sim_rtl.channel_fixed`` (numpy),
# bench/core/sim_main.cpp (C++) and bench/core/fmt_channel_sim.v (Verilog).  Units of the
# additive term: 2^-ADD_FRAC ADC LSB (= the coupling product's fraction bits).
#
# Noise (counter based, no state, no repetition): for channel sample k (32 bits) and
# column c (< 256), z = mix64(key + (((k << 8) | c) + 1) * GAMMA) mod 2^64 -- splitmix64's
# output number ((k << 8) | c) + 1 of a generator seeded with ``key`` -- and the word is
#   noise = (GAUSS[z >> (64 - GAUSS_BITS)] * sigma_q) >>> (GAUSS_FRAC + SIGMA_FRAC - ADD_FRAC)
# GAUSS: the 2^16 midpoint quantiles of the standard normal, scaled so that the table's
# variance is 1, GAUSS_FRAC fraction bits (|word| <= 4.2 sigma); sigma_q = sigma in
# 2^-SIGMA_FRAC LSB.  Sample variance = (sigma_q / 2^8)^2 within 1e-5 + the floor's
# 1/12 * 2^-32 LSB^2.  The float model (adc_streams) draws numpy Gaussians instead.
# Oscillators (interferers, display harmonics, charger harmonics; :func:`oscillators`):
# oscillator i at channel sample k (32 bits) has the 64-bit phase (cycles, 2^-64)
#   ph_i(k) = ((ph0_i + k * inc_i) mod 2^32) << 32  +  dinc_i * T(k)      (mod 2^64),
#   T(k)    = k (k - 1) / 2  (exact in 64 bits: k < 2^32),
# i.e. a phase increment inc_i + dinc_i * k / 2^32 that grows by dinc_i every sample (a
# linear chirp: dinc = round(sweep_hz_per_s / fs^2 * 2^64) mod 2^64, two's complement
# for a falling sweep; dinc 0 = a fixed tone with a 32-bit accumulator).  Its word is a
# sine table of 2^IF_TABLE_BITS words round(32767 sin(2 pi j / 2^IF_TABLE_BITS)) read at
# ph >> (64 - IF_TABLE_BITS) (truncated phase: spurs near -72 dBc), or for a square wave
# +32767 / -32767 when ph's top bit is 0 / 1; amplitude amp_q in 2^-IF_AMP_FRAC LSB:
# term = (amp_q * word) >>> (IF_AMP_FRAC + 15 - ADD_FRAC).  A burst gate (bper > 0)
# keeps the term only on samples k >= bstart with (k - bstart) mod bper < bon (bstart a
# signed 64-bit word; the oscillator runs on while gated off).  Flags: bit 0 square
# wave, bit 1 charger (see below).  inc = round(f / fs * 2^32) (a bin b: round(b * 2^32
# / N), exact for half bins), ph0 = round(phase / 2 pi * 2^32) + adc_delay * inc
# (channel sample k reaches the receiver as ADC sample k + adc_delay, the float model's
# time base; a sweeping oscillator takes inc and ph0 from the float chirp at that
# sample, inc corrected by half a step for the discrete sum).  Oscillators without the
# charger flag are added to every column.  The charger oscillators' sum chg(k) reaches
# column c as (chg(k) * W_c) >>> CHG_W_FRAC, W_c an unsigned 16-bit weight with
# CHG_W_FRAC fraction bits that changes with the coupling updates (the touching
# contacts' coupling to the column, :func:`charger_column_weights`).
ADD_FRAC = 16
GAUSS_BITS, GAUSS_FRAC, SIGMA_FRAC = 16, 12, 8
IF_TABLE_BITS, IF_AMP_FRAC, IF_MAX = 12, 8, 64     # IF_MAX: oscillators at most
OSC_WORDS = 8                  # parameter words per oscillator
CHG_W_FRAC = 12               # fraction bits of the charger column weights
GAMMA = 0x9E3779B97F4A7C15
MIX1, MIX2 = 0xBF58476D1CE4E5B9, 0x94D049BB133111EB
_M64 = (1 << 64) - 1


class UnsupportedEffect(ValueError):
    """A scene effect the fixed-point / RTL channel cannot apply (one line naming it)."""


def mix64(z):
    """splitmix64's finaliser on uint64 numpy arrays (wrapping arithmetic)."""
    z = np.asarray(z, dtype=np.uint64)
    with np.errstate(over="ignore"):
        z = (z ^ (z >> np.uint64(30))) * np.uint64(MIX1)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(MIX2)
    return z ^ (z >> np.uint64(31))


@functools.lru_cache(maxsize=1)
def gauss_table() -> np.ndarray:
    """2^GAUSS_BITS int64 words, GAUSS_FRAC fraction bits: the midpoint quantiles
    Phi^-1((i + 1/2) / 2^GAUSS_BITS) scaled to unit variance (statistics.NormalDist:
    plain double arithmetic), rounded; antisymmetric (T[L-1-i] = -T[i])."""
    from statistics import NormalDist
    size = 1 << GAUSS_BITS
    inv = NormalDist().inv_cdf
    q = np.array([inv((i + 0.5) / size) for i in range(size // 2)], dtype=np.float64)
    q = np.concatenate([q, -q[::-1]])
    q /= math.sqrt(float(np.mean(q * q)))
    return np.rint(q * (1 << GAUSS_FRAC)).astype(np.int64)


@functools.lru_cache(maxsize=1)
def if_sine_table() -> np.ndarray:
    """2^IF_TABLE_BITS int64 words round(32767 sin(2 pi j / 2^IF_TABLE_BITS))."""
    j = np.arange(1 << IF_TABLE_BITS)
    return np.rint(32767.0 * np.sin(2.0 * np.pi * j / (1 << IF_TABLE_BITS))).astype(np.int64)


def write_table_hex(path, words, bits: int = 16) -> None:
    """Signed words for $readmemh / the C++ harness, one per line, two's complement."""
    a = np.asarray(words, dtype=np.int64)
    digits, mask = (bits + 3) // 4, (1 << bits) - 1
    Path(path).write_text("".join(f"{int(v) & mask:0{digits}x}\n" for v in a))


# ---- oscillators: interferers, display noise, charger noise (float spec) ----------------
@dataclass(frozen=True)
class Osc:
    """One oscillator of a scene, in float terms (both the float model and
    :func:`fixed_effects` are built from these): amplitude (LSB; a charger oscillator's
    amplitude is on a column with charger weight 1), frequency at ADC sample 0, start
    phase, sweep rate, burst gate (period, on, start in ADC samples, or None), wave."""

    name: str
    freq_hz: float
    amp_lsb: float
    phase_rad: float = 0.0
    sweep_hz_per_s: float = 0.0
    burst: tuple | None = None       # (period, on, start) samples
    square: bool = False
    charger: bool = False

    def cycles(self, n: np.ndarray, fs: float) -> np.ndarray:
        """Phase in cycles at ADC samples n (float64)."""
        t = np.asarray(n, dtype=np.float64) / fs
        return self.freq_hz * t + self.phase_rad / (2 * math.pi) + 0.5 * self.sweep_hz_per_s * t * t

    def gate(self, n: np.ndarray) -> np.ndarray:
        """bool: the burst gate at ADC samples n (all True without a burst)."""
        n = np.asarray(n, dtype=np.int64)
        if self.burst is None:
            return np.ones(n.shape, dtype=bool)
        per, on, st = self.burst
        return (n >= st) & (np.mod(n - st, per) < on)

    def wave(self, n: np.ndarray, fs: float) -> np.ndarray:
        """The oscillator's value (LSB) at ADC samples n (float model)."""
        cyc = self.cycles(n, fs)
        if self.square:
            w = 1.0 - 2.0 * (np.mod(cyc, 1.0) >= 0.5)
        else:
            w = np.sin(2 * np.pi * np.mod(cyc, 1.0))
        return np.where(self.gate(n), self.amp_lsb * w, 0.0)


def finger_tone_lsb(cfg: SensorConfig, level: float = _sensor.BASELINE) -> float:
    """A finger's tone at the ADC (LSB): TONE_LSB x the coupling of the peak cell under a
    default finger centred on a cell (the signal of ``noise_sigma_for_snr``)."""
    return _sensor.TONE_LSB * finger_peak_coupling(cfg, level)


@functools.lru_cache(maxsize=16)
def _finger_column_sum(cfg: SensorConfig) -> float:
    r, c = cfg.rows // 2, cfg.cols // 2
    m = _sensor.contact_maps(cfg, [(c * cfg.pitch_mm, r * cfg.pitch_mm, FINGER_MM, 1.0)])[0]
    return float(m.sum(axis=0).max())


def charger_column_weights(cfg: SensorConfig, g_minus_base: np.ndarray) -> np.ndarray:
    """Charger weight of every column from the touching contacts' coupling (coupling
    above the untouched baseline, (..., rows, cols)): its sum over the rows divided by
    that of a default finger centred on a cell (1.0 on the finger's column; 0 with no
    contact; a palm more).  Shape (..., cols)."""
    return np.asarray(g_minus_base).sum(axis=-2) / _finger_column_sum(cfg)


def _burst(b, fs: float, where: str):
    if b is None:
        return None
    if not isinstance(b, dict) or not {"period_s", "on_s"} <= set(b) or set(b) - {"period_s", "on_s", "start_s"}:
        raise ValueError(f"{where}: burst must be {{\"period_s\", \"on_s\"[, \"start_s\"]}}, got {b!r}")
    per = round(_num(b["period_s"], f"{where}: burst period_s", 0.0) * fs)
    on = round(_num(b["on_s"], f"{where}: burst on_s", 0.0) * fs)
    st = round(_num(b.get("start_s", 0.0), f"{where}: burst start_s", -1e6, 1e6) * fs)
    if per < 1 or not 0 <= on <= per:
        raise ValueError(f"{where}: burst needs period_s >= 1 sample and 0 <= on_s <= period_s")
    return (int(per), int(on), int(st))


def _num(v, where: str, lo=None, hi=None) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ValueError(f"{where}: must be a finite number, got {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise ValueError(f"{where}: {v} outside {lo} .. {hi}")
    return float(v)


def _harmonics(w: str, harm, f0: float, nyq: float, second: str, phase: bool) -> list:
    """A scene's harmonic list [[h, value(, phase_rad)], ...] of fundamental f0 checked
    (h whole >= 1, h * f0 <= Nyquist, value >= 0; the phase only where ``phase``):
    (h, h * f0, value, phase_rad) each."""
    form = f"[h, {second}(, phase_rad)]" if phase else f"[h, {second}]"
    if not isinstance(harm, list) or not harm:
        raise ValueError(f"{w}: harmonics must be a list of {form}")
    out = []
    for j, h in enumerate(harm):
        if (not isinstance(h, list) or len(h) not in ((2, 3) if phase else (2,))
                or int(_num(h[0], f"{w}: harmonics[{j}]", 1)) != h[0]):
            raise ValueError(f"{w}: harmonics[{j}] must be {form} with h whole >= 1, got {h!r}")
        f = h[0] * f0
        if f > nyq:
            raise ValueError(f"{w}: harmonic {h[0]} at {f:g} Hz above Nyquist ({nyq:g} Hz)")
        out.append((h[0], f, _num(h[1], f"{w}: harmonics[{j}] {second}", 0.0),
                    _num(h[2], f"{w}: harmonics[{j}] phase_rad") if len(h) == 3 else 0.0))
    return out


def oscillators(scene: Scene) -> list:
    """The scene's oscillators (:class:`Osc`): its ``interferer`` entries, the harmonics
    of its ``display`` noise and of its ``charger`` noise (see fmt.scene); raises
    ValueError (one line naming the field) for a bad value.  Empty without them."""
    cfg = scene.cfg
    fs = cfg.fs_hz
    nyq = fs / 2
    eff = scene.effects
    out = []
    interf = eff.get("interferer") or []
    if isinstance(interf, dict):
        interf = [interf]
    for i, it in enumerate(interf):
        w = f"effect interferer[{i}]"
        if not isinstance(it, dict):
            raise ValueError(f"{w}: must be an object")
        if "freq_hz" in it:
            f = _num(it["freq_hz"], f"{w}: freq_hz", 0.0, nyq)
        elif "bin" in it:
            f = _num(it["bin"], f"{w}: bin", 0.0, cfg.n_fft / 2) * cfg.bin_hz
        else:
            raise ValueError(f"{w}: needs freq_hz or bin")
        sw = _num(it.get("sweep_hz_per_s", 0.0), f"{w}: sweep_hz_per_s", -fs * fs / 4, fs * fs / 4)
        out.append(Osc(w, f, _num(it.get("amp_lsb", 0.0), f"{w}: amp_lsb", 0.0),
                       _num(it.get("phase_rad", 0.0), f"{w}: phase_rad"), sw,
                       _burst(it.get("burst"), fs, w)))
    disp = eff.get("display")
    if disp:
        w = "effect display"
        line = _num(disp.get("line_hz", 0.0), f"{w}: line_hz", 0.0, nyq)
        if line <= 0:
            raise ValueError(f"{w}: line_hz must be > 0")
        for h, f, amp, ph in _harmonics(w, disp.get("harmonics"), line, nyq, "amp_lsb", True):
            out.append(Osc(f"{w} harmonic {h}", f, amp, ph))
    chg = eff.get("charger")
    if chg:
        w = "effect charger"
        f0 = _num(chg.get("freq_hz", 0.0), f"{w}: freq_hz", 0.0, nyq)
        if f0 <= 0:
            raise ValueError(f"{w}: freq_hz must be > 0")
        a = _num(chg.get("level", 0.0), f"{w}: level", 0.0, 100.0) * finger_tone_lsb(
            cfg, eff.get("baseline", _sensor.BASELINE))
        harm = chg.get("harmonics", "square")
        if harm == "square":
            out.append(Osc(f"{w} square", f0, a, 0.0, square=True, charger=True))
        elif isinstance(harm, list) and harm:
            for h, f, rel, _ in _harmonics(w, harm, f0, nyq, "relative amplitude", False):
                out.append(Osc(f"{w} harmonic {h}", f, a * rel, charger=True))
        else:
            raise ValueError(f"{w}: harmonics must be \"square\" or a list of [h, relative amplitude]")
    return out


@dataclass(frozen=True)
class FixedEffects:
    """The additive effects of a scene as the fixed-point channel applies them."""

    key: int = 0                 # noise generator seed (64 bits)
    sigma_q: int = 0             # noise sigma, 2^-SIGMA_FRAC LSB (0 = no noise)
    dc_q: int = 0                # DC offset, 2^-ADD_FRAC LSB
    enob_clear: int = 0          # low ADC bits cleared after the clip (ADC_BITS - enob)
    delay: int = 0               # channel delay of the row words, samples
    interferers: tuple = ()      # oscillators: (inc, ph0, amp_q[, dinc, bper, bon, bstart, flags])

    @property
    def oscs(self) -> list:
        """The oscillators as full 8-tuples (short tuples: no sweep, no burst, sine)."""
        return [tuple(it) + (0, 0, 0, 0, 0)[:OSC_WORDS - len(it)] for it in self.interferers]

    @property
    def has_charger(self) -> bool:
        return any(o[7] & 2 for o in self.oscs)

    def noise(self, k0: int, n: int, cols: int) -> np.ndarray:
        """(n, cols) int64 noise words of channel samples k0 .. k0+n-1, 2^-ADD_FRAC LSB."""
        if self.sigma_q == 0 or n <= 0:
            return np.zeros((max(n, 0), cols), dtype=np.int64)
        k = (np.arange(k0, k0 + n, dtype=np.uint64) & np.uint64(0xFFFFFFFF))
        ctr = (k[:, None] << np.uint64(8)) | np.arange(cols, dtype=np.uint64)[None, :]
        with np.errstate(over="ignore"):
            z = mix64(np.uint64(self.key) + (ctr + np.uint64(1)) * np.uint64(GAMMA))
        idx = (z >> np.uint64(64 - GAUSS_BITS)).astype(np.int64)
        return (gauss_table()[idx] * self.sigma_q) >> (GAUSS_FRAC + SIGMA_FRAC - ADD_FRAC)

    def _osc_sum(self, k0: int, n: int, charger: bool) -> np.ndarray:
        out = np.zeros(max(n, 0), dtype=np.int64)
        tab = if_sine_table()
        k = np.arange(k0, k0 + n, dtype=np.uint64) & np.uint64(0xFFFFFFFF)
        tk = None
        for inc, ph0, amp, dinc, bper, bon, bstart, flags in self.oscs:
            if bool(flags & 2) != charger:
                continue
            with np.errstate(over="ignore"):            # mod 2^64
                ph = ((np.uint64(ph0) + k * np.uint64(inc)) & np.uint64(0xFFFFFFFF)) << np.uint64(32)
                if dinc:
                    if tk is None:
                        tk = (k * (k - np.uint64(1))) >> np.uint64(1)
                    ph = ph + np.uint64(dinc) * tk
            if flags & 1:
                wv = np.where((ph >> np.uint64(63)) == 1, -32767, 32767).astype(np.int64)
            else:
                wv = tab[(ph >> np.uint64(64 - IF_TABLE_BITS)).astype(np.int64)]
            term = (amp * wv) >> (IF_AMP_FRAC + 15 - ADD_FRAC)
            if bper:
                d = k.astype(np.int64) - _signed64(bstart)
                term = np.where((d >= 0) & (np.mod(d, bper) < bon), term, 0)
            out += term
        return out

    def interference(self, k0: int, n: int) -> np.ndarray:
        """(n,) int64 sum of the oscillators added to every column (not the charger's) at
        channel samples k0 .. k0+n-1."""
        return self._osc_sum(k0, n, False)

    def charger(self, k0: int, n: int) -> np.ndarray:
        """(n,) int64 sum of the charger oscillators chg(k) (a column adds (chg * W_c)
        >>> CHG_W_FRAC)."""
        return self._osc_sum(k0, n, True)

    def additive(self, k0: int, n: int, cols: int) -> np.ndarray:
        """(n, cols) int64: noise + DC + oscillators (without the charger), 2^-ADD_FRAC LSB."""
        a = self.noise(k0, n, cols)
        if self.dc_q:
            a += self.dc_q
        if self.interferers:
            a += self.interference(k0, n)[:, None]
        return a

    def param_words(self) -> list[int]:
        """The channel parameter file (CHAN_FILE of fmt_channel_sim.v, chan_file of the
        C++ harness), 64-bit words: key, sigma_q, dc_q, mask of the ENOB-cleared bits,
        delay, number of oscillators, then (inc, ph0, amp_q, dinc, bper, bon, bstart,
        flags) per oscillator."""
        mask = (1 << self.enob_clear) - 1
        w = [self.key, self.sigma_q, self.dc_q, mask, self.delay, len(self.interferers)]
        for it in self.oscs:
            w += list(it)
        return [int(v) & _M64 for v in w]


def _signed64(v: int) -> int:
    v = int(v) & _M64
    return v - (1 << 64) if v >> 63 else v


def osc_words(o: Osc, fs: float, adc_delay: int) -> tuple:
    """The fixed-point 8-tuple of an oscillator (see the comment above ADD_FRAC)."""
    if o.sweep_hz_per_s == 0.0:
        inc = int(round(o.freq_hz / fs * (1 << 32))) & 0xFFFFFFFF
        ph0 = int(round(o.phase_rad / (2 * math.pi) * (1 << 32)))
        ph0 = (ph0 + adc_delay * inc) & 0xFFFFFFFF
        dinc = 0
    else:
        r = o.sweep_hz_per_s / (fs * fs)            # cycles per sample^2
        cyc = float(o.cycles(np.array([adc_delay]), fs)[0])
        inc = int(round(((o.freq_hz + o.sweep_hz_per_s * adc_delay / fs) / fs + 0.5 * r) * (1 << 32))) & 0xFFFFFFFF
        ph0 = int(round((cyc % 1.0) * (1 << 32))) & 0xFFFFFFFF
        dinc = int(round(r * (1 << 64))) & _M64
    amp = int(round(o.amp_lsb * (1 << IF_AMP_FRAC)))
    if o.burst is None:
        bper = bon = bstart = 0
    else:
        bper, bon, st = o.burst
        bstart = (st - adc_delay) & _M64
    flags = (1 if o.square else 0) | (2 if o.charger else 0)
    return (inc, ph0, amp, dinc, bper, bon, bstart, flags)


def fixed_effects(scene: Scene, adc_delay: int = 1, key: int | None = None) -> FixedEffects:
    """The scene's additive channel effects in fixed point (see above); raises
    :class:`UnsupportedEffect` (a one-line message naming the effect) for an effect the
    fixed-point channel cannot apply.  ``key``: the noise seed (default scene.seed + 1000)."""
    cfg = scene.cfg
    eff = scene.effects
    ph = eff.get("tone_phases", "zero")
    if ph != "zero":
        raise UnsupportedEffect(f"effect tone_phases '{ph}': the RTL DDS starts every row at phase 0 "
                                "(no phase register); only 'zero' runs through the RTL")
    sigma = scene_noise_sigma(scene)
    sigma_q = int(round(sigma * (1 << SIGMA_FRAC)))
    if not 0 <= sigma_q < (1 << 32):
        raise UnsupportedEffect(f"effect noise: sigma {sigma} LSB outside 0 .. 2^{32 - SIGMA_FRAC}")
    dc = float(eff.get("dc_lsb", 0.0))
    if abs(dc) >= (1 << 20):
        raise UnsupportedEffect(f"effect dc_lsb: {dc} LSB too large (|dc| < 2^20)")
    dc_q = int(round(dc * (1 << ADD_FRAC)))
    enob = eff.get("enob")
    if enob is not None:
        if int(enob) != enob or not 1 <= int(enob):
            raise UnsupportedEffect(f"effect enob: {enob} is not a whole number of bits >= 1")
    clear = 0 if enob is None else max(0, cfg.adc_bits - int(enob))
    d = eff.get("delay_samples", 0)
    if int(d) != d or not 0 <= int(d) <= 63:
        raise UnsupportedEffect(f"effect delay_samples: {d} is not a whole number of samples 0..63")
    try:
        oscs = oscillators(scene)
    except ValueError as e:
        raise UnsupportedEffect(str(e)) from None
    if len(oscs) > IF_MAX:
        kinds = dict.fromkeys(o.name.split("[")[0].split(" harmonic")[0].split(" square")[0] for o in oscs)
        raise UnsupportedEffect(f"effect {'/'.join(k.replace('effect ', '') for k in kinds)}: "
                                f"{len(oscs)} oscillators (interferers + display and charger harmonics) "
                                f"> {IF_MAX}")
    its = []
    for o in oscs:
        if not 0 <= o.amp_lsb < (1 << 16):
            raise UnsupportedEffect(f"{o.name}: amplitude {o.amp_lsb} LSB outside 0 .. 65535")
        if o.burst is not None and not (o.burst[0] < (1 << 32) and abs(o.burst[2]) < (1 << 40)):
            raise UnsupportedEffect(f"{o.name}: burst period or start too long for the 32-bit sample counter")
        its.append(osc_words(o, cfg.fs_hz, adc_delay))
    k = (scene.seed + 1000) if key is None else key
    return FixedEffects(key=int(k) & _M64, sigma_q=sigma_q, dc_q=dc_q, enob_clear=clear, delay=int(d),
                        interferers=tuple(its))
