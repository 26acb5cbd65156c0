"""The model chain: scene -> ADC streams -> heat maps -> touch events (floating point).

* :func:`heatmaps_float` -- the full path: ``channel.adc_streams`` (tones, coupling,
  PN, delay, effects, 12-bit ADC) then ``rx_array.receive`` (despread, FFT, comb bins,
  magnitude, mean over M), chunked over frames so memory stays bounded.
* :func:`render_heatmaps` -- the scene straight to heat maps WITHOUT signal synthesis, for
  post-processing tests:  cell = |S + n| averaged over the frame's M windows, where S is
  the EXACT comb-bin DFT of the unquantised noiseless column signal, computed from the
  coupling at the window boundaries with precomputed (bins x rows) DFT matrices (so a
  tap's onset inside a window, with the leakage of the gated tones into the neighbouring
  rows' bins, and the motion inside a window are exact), and n is complex Gaussian with
  sigma * sqrt(N/2) * hm_scale per quadrature (sigma^2 = ADC noise^2 + 1/12 quantisation
  (+ ENOB step^2 / 12)): the statistics of a DFT bin of white noise (bins and windows
  independent).  Not modelled by the render: clipping, interferers and the other
  oscillators (display and charger noise), DC (it never reaches a comb bin anyway), PN
  misalignment (a drift and a contact's size_path are: they are coupling).  Noiseless, it differs from the ADC path only by the
  ADC rounding: |error| <= 0.5 LSB * N * hm_scale = 2**(HM_W - ADC_BITS + 1) counts (32)
  per cell, RMS sqrt(N/24) * hm_scale (0.82 counts at N = 256); sim/tests/test_chain.py.
* :func:`events` -- heat maps through ``fmt.touch.process_frames(hm, cfg, settings,
  fixed=False)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import channel as _ch
from . import rx_array as _rx
from . import sensor as _sensor
from .scene import Scene


@dataclass
class ChainResult:
    heatmaps: np.ndarray     # (frames, rows, cols) float64 counts
    clipped: int             # clipped ADC samples
    samples: int             # ADC samples simulated
    noise_sigma: float       # LSB


def heatmaps_float(scene: Scene, cfg=None, frames: int | None = None, chunk_frames: int | None = None,
                   progress=None) -> ChainResult:
    """Scene through the ADC and the float receiver -> heat maps (frames, rows, cols).

    The noise generator is drawn sequentially, so the result does not depend on the
    chunking.  ``progress(done, total)`` is called after every chunk."""
    scene = scene.with_cfg(cfg)
    cfg = scene.cfg
    frames = scene.frames if frames is None else frames
    spf = scene.samples_per_frame
    if chunk_frames is None:
        chunk_frames = max(1, 256 // scene.m)
    enable = _ch.pn_settings(scene)[0]
    # one generator for the whole stream; the chunks are consecutive pieces of it
    sigma = _ch.scene_noise_sigma(scene)
    rng = np.random.default_rng(scene.seed) if sigma > 0 else None
    total = frames * spf
    out = np.empty((frames, cfg.rows, cfg.cols))
    clipped = 0
    for f0 in range(0, frames, chunk_frames):
        f1 = min(frames, f0 + chunk_frames)
        r = _ch.adc_streams(scene, n_samples=(f1 - f0) * spf, rng=rng, start=f0 * spf)
        clipped += r.clipped
        out[f0:f1] = _rx.receive(r.adc, cfg, r.rx_sign if enable else None, scene.m)
        if progress is not None:
            progress(f1, frames)
    return ChainResult(out, clipped, total, sigma)


def frame_coupling(scene: Scene, cfg=None, frames: int | None = None) -> np.ndarray:
    """Mean coupling of each window, (windows, rows, cols), attenuation included: the
    exact sample average of the channel's G[n] over each window."""
    scene = scene.with_cfg(cfg)
    cfg = scene.cfg
    n = cfg.n_fft
    nw = (scene.frames if frames is None else frames) * scene.m
    wc = _ch.window_coupling(scene, 0, nw)
    fbar = (n - 1) / (2.0 * n)                 # mean of j/N over j = 0..N-1
    g = (1 - fbar) * wc.g0 + fbar * wc.g1
    j = np.arange(n) / n
    for w, mask, m0, m1 in wc.partial:
        a = mask.mean()
        b = (mask * j).mean()
        g[w] += (a - b) * m0 + b * m1
    return g


def _dft_mats(cfg, T: np.ndarray, weight=None):
    """(D0, D1): comb-bin DFT of weight(j) * T[j, r] and of weight(j) * j/N * T[j, r],
    shapes (bins, rows) complex: X_w = D0 @ g0 + D1 @ (g1 - g0) for a coupling that
    moves linearly from g0 to g1 over the window."""
    n = cfg.n_fft
    j = np.arange(n)
    ph = 2.0 * np.pi * (np.outer(np.asarray(cfg.bins), j) % n) / n       # (bins, N)
    c, s = np.cos(ph), -np.sin(ph)
    Tw = T if weight is None else T * weight[:, None]
    Tj = Tw * (j / n)[:, None]
    # real matmuls (a complex @ real product is not a BLAS call in numpy)
    return c @ Tw + 1j * (s @ Tw), c @ Tj + 1j * (s @ Tj)


def render_spectra(scene: Scene, cfg=None, frames: int | None = None) -> np.ndarray:
    """Noiseless comb-bin spectra (windows, rows, cols) complex of the unquantised, despread
    column signals, in heat-map units (|value| = the cell): EXACT for the coupling model
    (matched PN cancels), computed from the coupling at the window boundaries with
    precomputed DFT matrices instead of synthesising samples."""
    scene = scene.with_cfg(cfg)
    cfg = scene.cfg
    nw = (scene.frames if frames is None else frames) * scene.m
    eff = scene.effects
    T = _ch.tone_table(cfg, _ch.tone_phases(cfg, eff.get("tone_phases", "zero")),
                       int(eff.get("delay_samples", 0)))
    D0, D1 = _dft_mats(cfg, T)
    wc = _ch.window_coupling(scene, 0, nw)
    dg = wc.g1 - wc.g0
    X = _ch.left_mul(D0.real, wc.g0) + 1j * _ch.left_mul(D0.imag, wc.g0)
    if dg.any():
        X += _ch.left_mul(D1.real, dg) + 1j * _ch.left_mul(D1.imag, dg)
    for w, mask, m0, m1 in wc.partial:
        P0, P1 = _dft_mats(cfg, T, mask.astype(np.float64))
        X[w] += P0 @ m0 + P1 @ (m1 - m0)
    return X * (_sensor.TONE_LSB * _rx.hm_scale(cfg))


def render_heatmaps(scene: Scene, cfg=None, frames: int | None = None, noise: bool = True,
                    rng: np.random.Generator | None = None) -> np.ndarray:
    """Scene -> heat maps (frames, rows, cols) float64 without signal synthesis (see the
    module docstring for what it models)."""
    scene = scene.with_cfg(cfg)
    cfg = scene.cfg
    X = render_spectra(scene, None, frames)
    sigma = _ch.scene_noise_sigma(scene) if noise else 0.0
    if sigma > 0:
        var = sigma * sigma + 1.0 / 12.0
        enob = scene.effects.get("enob")
        if enob is not None and enob < cfg.adc_bits:
            var += (2.0 ** (cfg.adc_bits - enob)) ** 2 / 12.0
        sq = np.sqrt(var * cfg.n_fft / 2.0) * _rx.hm_scale(cfg)
        rng = np.random.default_rng(scene.seed + 7919) if rng is None else rng
        X = X + sq * (rng.standard_normal(X.shape) + 1j * rng.standard_normal(X.shape))
    return _rx.accum_float(np.abs(X), scene.m)


def noiseless(scene: Scene) -> Scene:
    """A copy of the scene without the noise effect."""
    eff = {k: v for k, v in scene.effects.items() if k != "noise"}
    return scene.replace(effects=eff)


def events(heatmaps: np.ndarray, scene: Scene, settings=None, fixed: bool = False):
    """Post-processing of heat maps: ``fmt.touch.process_frames`` (imported lazily: it is
    another block's model)."""
    from . import touch as _touch          # noqa: WPS433 (optional dependency)
    from .settings import TouchSettings
    settings = TouchSettings() if settings is None else settings
    return _touch.process_frames(heatmaps, scene.cfg, settings, fixed=fixed)
