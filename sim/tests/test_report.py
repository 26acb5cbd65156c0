"""make report (fmt.report): the smoke sweep writes its files with plausible numbers, and the
cheap path it measures on (render_heatmaps + the receive chain's quantisation) has the
noise statistics of the full path (ADC -> rx_array.rx_heatmaps_fixed)."""
import json
import math

import numpy as np
import pytest

from fmt.settings import TouchSettings
from fmt import channel, params, report, rx_array, sensor
from fmt import scene as S


def _fingers(cfg, n=8):
    """n stationary default fingers, well apart, at different sub-cell offsets."""
    out = []
    for i in range(n):
        x = (5 + 9 * (i % 4) + 0.13 * i) * cfg.pitch_mm
        y = (6 + 12 * (i // 4) + 0.29 * (i % 3)) * cfg.pitch_mm
        out.append(S.Contact(name=f"f{i}", path=[[0.0, x, y]]))
    return out


def test_render_path_noise_matches_adc_path():
    """DEFAULT sensor, 8 fingers, 30 dB per window, PN on, M = 2, 128 frames: the heat
    maps of report's path (render per window, magnitude word floor(8 x cell), accum_fixed)
    against ADC -> rx_fixed (the RTL's twin), different noise draws.

    Tolerances (n = samples): baseline cells (1145 cells x 128 frames = 147k samples):
    the standard error of a mean or std is ~0.3 % of it, the FFT's rounding and the
    CORDIC (~1 count) are < 0.1 % of the 181-count noise: mean and std within 1.5 %.
    Touched cells (coupling > 0.5, 11 cells): per-cell means differ by noise only,
    SE = std * sqrt(2 / frames) (~30 counts): each within 4 SE + 0.2 % (the fixed
    chain's scale error, < 0.2 %); pooled mean within 0.5 %; pooled std (1400 degrees
    of freedom per path, relative SE 2 %) within 10 %."""
    cfg = params.DEFAULT
    cts = _fingers(cfg)
    frames, m = 128, 2
    sc = S.Scene(name="noise_check", sensor="default", frames=frames, m=m, seed=11, contacts=cts,
                 effects={"noise": {"snr_db": 30.0}, "pn": {"enable": True, "chip_len": 1}})
    a = channel.adc_streams(sc)
    assert a.clipped == 0
    hm_a, _, flags = rx_array.rx_heatmaps_fixed(a.adc, a.rx_sign, cfg, 1)
    assert not flags.any
    hm_r, sat = report.quantise(report.window_cells(sc), m, cfg.hm_width)
    assert not sat
    assert hm_a.shape == hm_r.shape == (frames, cfg.rows, cfg.cols)
    cp = sensor.coupling(cfg, [tuple(c.position(0.0)) + c.shape_row() for c in cts])
    base = cp <= sensor.BASELINE + 1e-9
    touched = cp > 0.5
    assert base.sum() > 1000 and touched.sum() >= 8
    ba, br = hm_a[:, base].astype(float), hm_r[:, base].astype(float)
    assert abs(br.mean() / ba.mean() - 1) < 0.015
    sa = math.sqrt(ba.var(axis=0, ddof=1).mean())
    sr = math.sqrt(br.var(axis=0, ddof=1).mean())
    assert abs(sr / sa - 1) < 0.015, (sa, sr)
    ta, tr = hm_a[:, touched].astype(float), hm_r[:, touched].astype(float)
    std = np.sqrt(0.5 * (ta.var(axis=0, ddof=1) + tr.var(axis=0, ddof=1)))
    se = std * math.sqrt(2.0 / frames)
    d = np.abs(ta.mean(axis=0) - tr.mean(axis=0))
    assert np.all(d < 4 * se + 0.002 * ta.mean(axis=0)), (d, se)
    assert abs(tr.mean() / ta.mean() - 1) < 0.005
    sta = math.sqrt(ta.var(axis=0, ddof=1).mean())
    str_ = math.sqrt(tr.var(axis=0, ddof=1).mean())
    assert abs(str_ / sta - 1) < 0.10, (sta, str_)


def test_width_scaling_is_exact():
    """render_heatmaps at HM_W = 12 is the 16-bit render x 2^-4 with the same noise draws,
    which is why the report quantises one render at every width."""
    cfg = params.DEFAULT
    sc = S.Scene(name="w", sensor="default", frames=6, m=1, seed=3, contacts=_fingers(cfg, 2),
                 effects={"noise": {"snr_db": 30.0}})
    c16 = report.window_cells(sc)
    c12 = report.window_cells(sc.with_cfg(cfg.replace(hm_width=12)))
    np.testing.assert_allclose(c12, c16 * 2.0 ** -4, rtol=1e-12, atol=1e-9)
    h12, _ = report.quantise(c16, 2, 12)
    top = (1 << 12) - 1
    assert h12.max() <= top and h12.min() >= 0


def test_quantise_divider_agrees_with_accum():
    """report.quantise uses fmt_rx_array's divider (accum_fixed with any M): the magnitude
    words floor(2 x cell x 4) (two fractional bits), then round half up of sum / 8M for
    M = 2^k and for M = 40 (the mean of the magnitude words / 8)."""
    rng = np.random.default_rng(4)
    cells = rng.uniform(0, 9000, size=(80, 3, 5))
    assert report._rx.MAG_FRAC == 2
    mags = np.floor(8 * cells).astype(np.int64)
    for m in (1, 2, 4, 8, 16):
        hm, _ = report.quantise(cells, m, 16)
        s = mags.reshape(80 // m, m, 3, 5).sum(axis=1)
        assert np.array_equal(hm, (s + 4 * m) // (8 * m))
    hm40, sat = report.quantise(cells, 40, 16)
    exact = mags.reshape(2, 40, 3, 5).sum(axis=1) / 320.0
    assert not sat and np.array_equal(hm40, np.floor(exact + 0.5).astype(np.int64))
    big, sat = report.quantise(np.full((4, 1, 1), 70000.0), 4, 16)
    assert sat and big.max() == (1 << 16) - 1


def test_pooled_statistics():
    rms, ci, n = report.pooled_rms([1.0, 2.0, None], [10, 30, 0])
    assert n == 40 and rms == pytest.approx(math.sqrt((10 * 1 + 30 * 4) / 40))
    assert ci > 0
    j, jci, k = report.pooled_jitter([0.3, 0.4], frames=5)
    assert k == 2 and j == pytest.approx(math.sqrt((0.09 + 0.16) / 2 * 5 / 4))


def test_latency_figures():
    """The receive-chain figure is tb/fmt_rx_array's schedule (810 clk at 3 x fs with the
    shared magnitude units: 6.48 us); it must fit the 8 us budget and exceed the FFT's
    output time."""
    cfg = params.DEFAULT
    rx = report.rx_latency_clk(cfg)
    us = rx["rx_clk"] / report.CLK_PER_SAMPLE / cfg.fs_hz * 1e6
    assert cfg.window_s * 1e6 < us < 8.0
    assert report.latency_us(cfg, 1, 874, 120) == pytest.approx((874 + 120) / 3 / cfg.fs_hz * 1e6)
    assert report.latency_us(cfg, 40, 874, 120) - report.latency_us(cfg, 1, 874, 120) == \
        pytest.approx(39 * cfg.window_s * 1e6)


def test_smoke_sweep(tmp_path):
    """--smoke: two points (M = 1, 8 at 30 dB, Moore + bias correction), files written,
    numbers plausible: jitter falls about as 1/sqrt(M), the position error falls too,
    every contact is found, the default physics meets the Windows limits."""
    assert report.main(["--smoke", "--quiet", "--out", str(tmp_path)]) == 0
    res = json.loads((tmp_path / "report.json").read_text())
    md = (tmp_path / "REPORT.md").read_text()
    assert "| M |" in md and "![error_vs_rate.png](error_vs_rate.png)" in md
    for name in ("error_vs_rate.png", "jitter_vs_rate.png", "error_vs_latency.png",
                 "jitter_vs_latency.png", "rate_vs_latency.png"):
        assert (tmp_path / name).stat().st_size > 5000
    pts = {p["m"]: p for p in res["points"]}
    assert set(pts) == {1, 8}
    p1, p8 = pts[1], pts[8]
    assert p1["frame_rate_hz"] == pytest.approx(params.DEFAULT.fs_hz / 256)
    assert p1["latency_us"] < 8.0 < p8["latency_us"]
    for p in (p1, p8):
        assert p["missed"] == 0 and p["false"] == 0
        assert 0 < p["pos_rms_mm"] < 1.0 and 0 < p["jitter_rms_mm"] < 0.5
        assert p["edge_rms_mm"] is not None and p["edge_rms_mm"] < 2.0
        # every frame of every finger but the confirmation frames (its first
        # confirm_frames - 1: not reported yet, counted neither as missed nor in the errors)
        nf = 8 - (TouchSettings().confirm_frames - 1)
        assert p["pos_n"] == 3 * 12 * nf and p["edge_n"] == 3 * 4 * nf
    # jitter ~ 1/sqrt(M): sqrt(8) = 2.8 (sampling spread of the smoke sizes: ~15 %)
    assert 2.0 < p1["jitter_rms_mm"] / p8["jitter_rms_mm"] < 4.0
    assert p8["pos_rms_mm"] < p1["pos_rms_mm"]
    # 30 dB per window at M = 1: the noise moves a finger by a fraction of a cell
    assert 0.05 < p1["jitter_rms_mm"] < 0.5
