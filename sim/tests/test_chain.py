"""render_heatmaps (no signal synthesis) against the ADC -> FFT float path."""
import math

import numpy as np
import pytest

from fmt import chain, channel, params, rx_array
from fmt import scene as S


def _bound(cfg):
    # ADC rounding: |e| <= 1/2 LSB per sample, so |dX| <= N/2 and a cell moves by at most
    # N/2 * hm_scale = 2**(HM_W - ADC_BITS + 1) counts; statistically sqrt(N/24) * hm_scale RMS
    return cfg.n_fft / 2 * rx_array.hm_scale(cfg), math.sqrt(cfg.n_fft / 24) * rx_array.hm_scale(cfg)


def test_render_matches_adc_path_default_scene():
    sc = chain.noiseless(S.load(S.SCENES_DIR / "default.json")).replace(frames=120)
    a = chain.heatmaps_float(sc)
    assert a.clipped == 0
    b = chain.render_heatmaps(sc)
    hard, rms = _bound(sc.cfg)
    d = a.heatmaps - b
    assert np.abs(d).max() <= hard
    # (stationary contacts repeat the same rounding errors window after window, so the
    # statistical figure is only indicative: measured 1.1 counts RMS, max 4.0 on 360 frames)
    assert d.std() < 2 * rms
    # a tap's onset window (partial coupling + leakage of the gated tones) is included
    on = [o for o in S.default_scene().onset_samples()["taps"] if o // sc.samples_per_frame < 120]
    assert any(o % sc.samples_per_frame for o in on)


def test_render_matches_adc_path_effects():
    # attenuation, Schroeder phases, channel delay with matched PN, an elliptical gaussian,
    # a fringe, a fast drag, M = 2
    sc = S.Scene(sensor="medium", frames=10, m=2, effects={
        "row_db_per_cell": 0.3, "col_db_per_cell": 0.2, "tone_phases": "schroeder",
        "delay_samples": 11, "pn": {"enable": True, "chip_len": 3}, "fringe_mm": 1.0},
        contacts=[{"path": [[0, 10.0, 10.0], [2e-4, 30.0, 20.0]]},
                  {"profile": "gaussian", "diameter_mm": 12, "minor_diameter_mm": 7, "angle_deg": 25,
                   "path": [[0, 35.0, 12.0]], "active": [[700, 2000]], "active_units": "samples"}])
    a = chain.heatmaps_float(sc)
    b = chain.render_heatmaps(sc)
    hard, rms = _bound(sc.cfg)
    assert a.clipped == 0
    assert np.abs(a.heatmaps - b).max() <= hard
    assert (a.heatmaps - b).std() < 2 * rms


def test_frame_coupling_is_the_sample_mean():
    sc = S.Scene(sensor="small", frames=6, contacts=[
        {"path": [[0, 5.0, 5.0], [1e-5, 15.0, 9.0]]},
        {"path": [[0, 20.0, 3.0]], "active": [[100, 250]], "active_units": "samples"}])
    g = channel.coupling_per_sample(sc, sc.n_samples)
    fc = chain.frame_coupling(sc)
    n = sc.cfg.n_fft
    assert np.allclose(fc, g.reshape(-1, n, sc.cfg.rows, sc.cfg.cols).mean(axis=1), atol=1e-12)


def test_render_noise_statistics():
    # the rendered noise gives the default physics' 30 dB at M = 1 and 33 dB at M = 2
    cfg = params.DEFAULT
    r, c = cfg.rows // 2, cfg.cols // 2
    clean = rx_array.unit_cell_counts(cfg) * channel.finger_peak_coupling(cfg)
    cells = [(r, c), (r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)]
    for m, want, frames in ((1, 30.0, 1200), (2, 33.0, 800)):
        sc = S.Scene(sensor="default", frames=frames, m=m, seed=3, effects={"noise": {"snr_db": 30.0}},
                     contacts=[{"path": [[0, c * cfg.pitch_mm, r * cfg.pitch_mm]]}])
        hm = chain.render_heatmaps(sc)
        noise = np.concatenate([hm[:, i, j] - hm[:, i, j].mean() for i, j in cells])
        snr = 20 * np.log10(clean / noise.std())
        assert abs(snr - want) < 0.3
        assert hm[:, r, c].mean() == pytest.approx(clean, rel=2e-3)
