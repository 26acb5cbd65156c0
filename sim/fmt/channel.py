"""Transmit, channel and ADC (floating-point physics, integer ADC words out).

Column c at ADC sample n (before quantisation, in LSB):

    v[n, c] = TONE_LSB * sum_r G[n, r, c] * p(n - d) * sin(2 pi k_r (n - d) / N + phi_r)
              + interferer(n) + dc + noise[n, c]
    G[n]    = (baseline + sum_k touching_k(n) * map_k(n)) * attenuation      (sensor.py)
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
* ADC: round half to even (numpy rint), clip to the B-bit range (counted: ``clipped``),
  ENOB = clear the low B - enob bits (floor), DC offset and noise before quantisation.
  Noise: white Gaussian, sigma from ``noise_sigma_for_snr`` (the default physics).

The RTL bench (``make sim``) applies the same effects in integers (``FixedEffects``,
``channel_sim_fixed`` below; bit-exact with bench/core's C++ and Verilog channels): a
counter-based noise generator instead of numpy's, interferers from a 32-bit phase
accumulator and a 4096-word sine table, round half up, row words before the channel
delay are 0 (docs/simulation.md lists the differences).
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
    (window, mask (N,), map0, map1) for contacts that touch only part of the window."""

    g0: np.ndarray
    g1: np.ndarray
    partial: list


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
        if c.stationary:     # one map for every boundary
            m = _sensor.contact_maps(cfg, [tuple(c.position(0.0)) + c.shape_row()],
                                     c.profile, fringe)[0] * att
            full = use[frac[use] == 1.0]
            g0[full] += m
            g1[full] += m
            at = lambda b, m=m: m
        else:
            bidx = np.unique(np.concatenate([use, use + 1]))
            pos = c.position(t[bidx])
            rows = np.column_stack([pos, np.broadcast_to(c.shape_row(), (bidx.size, 4))])
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
    return WindowCoupling(g0, g1, partial)


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
    interf = eff.get("interferer")
    if isinstance(interf, dict):
        interf = [interf]
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
        if interf:
            tt = np.arange(start + s0, start + s1) / cfg.fs_hz
            for it in interf:
                fr = it["freq_hz"] if "freq_hz" in it else it["bin"] * cfg.bin_hz
                v += (it["amp_lsb"] * np.sin(2 * np.pi * fr * tt + it.get("phase_rad", 0.0)))[:, None]
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
    acc = np.zeros((n, mats[0].shape[1]), dtype=object)
    for i, g in enumerate(mats):
        sel = g_of == i
        if sel.any():
            acc[sel] = (dac[sel].astype(object)) @ g.astype(object)
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
# Interferer i: a 32-bit phase accumulator ph_i(k) = ph0_i + k * inc_i (mod 2^32), a sine
# table of 2^IF_TABLE_BITS words round(32767 sin(2 pi j / 2^IF_TABLE_BITS)) read at
# ph >> (32 - IF_TABLE_BITS) (truncated phase: spurs near -72 dBc), amplitude amp_q in
# 2^-IF_AMP_FRAC LSB: term = (amp_q * SINE[...]) >>> (IF_AMP_FRAC + 15 - ADD_FRAC), the
# same in every column.  inc = round(f / fs * 2^32) (a bin b: round(b * 2^32 / N), exact
# for half bins), ph0 = round(phase / 2 pi * 2^32) + adc_delay * inc (channel sample k
# reaches the receiver as ADC sample k + adc_delay, the float model's time base).
# DC: dc_q = round(dc_lsb * 2^ADD_FRAC).  ENOB: the low ADC_BITS - enob bits of the
# clipped word cleared.  Delay: the row words of channel sample k are those of sample
# k - delay (0 before sample ``delay``: a delay line reset to 0; the float model continues
# the periodic tones there instead).
ADD_FRAC = 16
GAUSS_BITS, GAUSS_FRAC, SIGMA_FRAC = 16, 12, 8
IF_TABLE_BITS, IF_AMP_FRAC, IF_MAX = 12, 8, 8
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


@dataclass(frozen=True)
class FixedEffects:
    """The additive effects of a scene as the fixed-point channel applies them."""

    key: int = 0                 # noise generator seed (64 bits)
    sigma_q: int = 0             # noise sigma, 2^-SIGMA_FRAC LSB (0 = no noise)
    dc_q: int = 0                # DC offset, 2^-ADD_FRAC LSB
    enob_clear: int = 0          # low ADC bits cleared after the clip (ADC_BITS - enob)
    delay: int = 0               # channel delay of the row words, samples
    interferers: tuple = ()      # (inc, ph0, amp_q) per interferer

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

    def interference(self, k0: int, n: int) -> np.ndarray:
        """(n,) int64 sum of the interferers at channel samples k0 .. k0+n-1."""
        out = np.zeros(max(n, 0), dtype=np.int64)
        tab = if_sine_table()
        k = np.arange(k0, k0 + n, dtype=np.uint64) & np.uint64(0xFFFFFFFF)
        for inc, ph0, amp in self.interferers:
            with np.errstate(over="ignore"):            # mod 2^64, then mod 2^32
                ph = (np.uint64(ph0) + k * np.uint64(inc)) & np.uint64(0xFFFFFFFF)
            idx = (ph >> np.uint64(32 - IF_TABLE_BITS)).astype(np.int64)
            out += (amp * tab[idx]) >> (IF_AMP_FRAC + 15 - ADD_FRAC)
        return out

    def additive(self, k0: int, n: int, cols: int) -> np.ndarray:
        """(n, cols) int64: noise + DC + interferers, 2^-ADD_FRAC LSB."""
        a = self.noise(k0, n, cols)
        if self.dc_q:
            a += self.dc_q
        if self.interferers:
            a += self.interference(k0, n)[:, None]
        return a

    def param_words(self) -> list[int]:
        """The channel parameter file (CHAN_FILE of fmt_channel_sim.v, chan_file of the
        C++ harness), 64-bit words: key, sigma_q, dc_q, mask of the ENOB-cleared bits,
        delay, number of interferers, then (inc, ph0, amp_q) per interferer."""
        mask = (1 << self.enob_clear) - 1
        w = [self.key, self.sigma_q, self.dc_q, mask, self.delay, len(self.interferers)]
        for it in self.interferers:
            w += list(it)
        return [int(v) & _M64 for v in w]


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
    interf = eff.get("interferer") or []
    if isinstance(interf, dict):
        interf = [interf]
    if len(interf) > IF_MAX:
        raise UnsupportedEffect(f"effect interferer: {len(interf)} interferers > {IF_MAX}")
    its = []
    for it in interf:
        if "freq_hz" in it:
            inc = int(round(float(it["freq_hz"]) / cfg.fs_hz * (1 << 32)))
        else:
            inc = int(round(float(it["bin"]) * (1 << 32) / cfg.n_fft))
        inc &= 0xFFFFFFFF
        amp = float(it.get("amp_lsb", 0.0))
        if not 0 <= amp < (1 << 16):
            raise UnsupportedEffect(f"effect interferer: amp_lsb {amp} outside 0 .. 65535")
        ph0 = int(round(float(it.get("phase_rad", 0.0)) / (2 * math.pi) * (1 << 32)))
        ph0 = (ph0 + adc_delay * inc) & 0xFFFFFFFF
        its.append((inc, ph0, int(round(amp * (1 << IF_AMP_FRAC)))))
    k = (scene.seed + 1000) if key is None else key
    return FixedEffects(key=int(k) & _M64, sigma_q=sigma_q, dc_q=dc_q, enob_clear=clear, delay=int(d),
                        interferers=tuple(its))
