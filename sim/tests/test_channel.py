"""Channel and ADC: orthogonal comb, exact onset sample, clipping, ENOB, DC, PN."""
import math

import numpy as np
import pytest

from fmt import channel as ch
from fmt import params, pn_gen, rx_array
from fmt import scene as S
from fmt.sensor import TONE_LSB


@pytest.mark.parametrize("cfg", [params.DEFAULT, params.SMALL, params.MEDIUM], ids=lambda c: c.name)
@pytest.mark.parametrize("kind,delay", [("zero", 0), ("schroeder", 13)])
def test_comb_orthogonal(cfg, kind, delay):
    T = ch.tone_table(cfg, ch.tone_phases(cfg, kind), delay)
    X = np.abs(np.fft.rfft(T, axis=0))[np.asarray(cfg.bins)]      # (bins, rows)
    own = np.diag(X)
    assert np.allclose(own, cfg.n_fft / 2, rtol=1e-12)
    leak = X - np.diag(own)
    assert 20 * np.log10(leak.max() / own.min()) < -200


def _finger(cfg, **eff):
    r, c = cfg.rows // 2, cfg.cols // 2
    return S.Scene(sensor=cfg.name, frames=4, effects=eff,
                   contacts=[{"path": [[0, c * cfg.pitch_mm, r * cfg.pitch_mm]]}])


def test_onset_on_exact_sample():
    cfg = params.MEDIUM
    n0 = 3 * cfg.n_fft + 77
    tap = S.Scene(sensor="medium", frames=6, contacts=[
        {"path": [[0, 22.0, 17.0]], "active": [[n0, None]], "active_units": "samples"}])
    none = S.Scene(sensor="medium", frames=6, contacts=[])
    g = ch.coupling_per_sample(tap, 6 * cfg.n_fft)
    assert np.allclose(g[:n0], g[0]) and g[n0, 3, 4] > g[n0 - 1, 3, 4] + 0.5
    a = ch.adc_streams(tap).adc.astype(int)
    b = ch.adc_streams(none).adc.astype(int)
    assert np.array_equal(a[:n0], b[:n0])
    assert np.abs(a[n0] - b[n0]).max() > 50    # the coupling is on at sample n0 itself


def test_scale_and_unit_cell():
    cfg = params.MEDIUM
    sc = _finger(cfg)
    hm = rx_array.receive(ch.adc_streams(sc).adc, cfg)
    r, c = cfg.rows // 2, cfg.cols // 2
    expect = rx_array.unit_cell_counts(cfg) * (1 + 1 / 32)
    assert rx_array.unit_cell_counts(cfg) == TONE_LSB * 32
    assert np.abs(hm[:, r, c] - expect).max() < 32      # ADC rounding bound, see test_chain


def test_pn_stream_matches_pn_model():
    for chip, d in ((1, 0), (3, 5), (7, 40)):
        tx, rx = pn_gen.pn_signs(5000, chip_len=chip, rx_delay=d)
        assert np.array_equal(ch.pn_stream(0, 5000, chip, True, 0), tx)
        assert np.array_equal(ch.pn_stream(0, 5000, chip, True, d), rx)
        assert np.array_equal(ch.pn_stream(1000, 5000, chip, True, d), rx[1000:])


def test_pn_on_equals_off_when_matched():
    # matched delay: the despread signal is bit-identical (the sign flip is exact, the
    # rounding symmetric), so the heat maps are identical: bound 0
    cfg = params.MEDIUM
    base = dict(contacts=[{"path": [[0, 12.0, 8.0], [1e-5, 14.0, 9.0]]},
                          {"path": [[0, 30.0, 22.0]], "active": [[300, None]], "active_units": "samples"}],
                sensor="medium", frames=8)
    hm = {}
    for on in (False, True):
        sc = S.Scene(effects={"delay_samples": 9, "pn": {"enable": on, "chip_len": 2}}, **base)
        r = ch.adc_streams(sc)
        hm[on] = rx_array.receive(r.adc, cfg, r.rx_sign)
        assert r.clipped == 0
    assert np.array_equal(hm[True], hm[False])
    # misaligned receive delay (hard case): chip_len 2 and one sample off halves the
    # correlation on average; with chip_len 1 the signal is destroyed
    sc = S.Scene(effects={"delay_samples": 9, "pn": {"enable": True, "chip_len": 1, "rx_delay": 10}}, **base)
    r = ch.adc_streams(sc)
    bad = rx_array.receive(r.adc, cfg, r.rx_sign)
    assert bad[-1].max() < 0.25 * hm[True][-1].max()


def pn_rejection_db(cfg, chip_len, frames=64, bin_offset=0.0):
    """Mean heat-map value of an interferer on a comb bin with PN on over PN off, dB."""
    k = cfg.bins[cfg.rows // 2] + bin_offset
    out = {}
    for on in (False, True):
        sc = S.Scene(sensor=cfg.name, frames=frames, contacts=[],
                     effects={"baseline": 0.0, "interferer": {"bin": k, "amp_lsb": 300.0},
                              "pn": {"enable": on, "chip_len": chip_len}})
        r = ch.adc_streams(sc)
        out[on] = rx_array.receive(r.adc, cfg, r.rx_sign)[:, cfg.rows // 2, :].mean()
    return 20 * np.log10(out[True] / out[False])


def test_interferer_spread_by_pn():
    # white spreading (chip_len 1): the despread interferer is white noise of power A^2/2,
    # a bin's magnitude is Rayleigh with mean sqrt(pi)/2 * sqrt(N/2) * A against A * N/2
    # unspread: sqrt(pi/(2N)) = -22.1 dB at N = 256 (measured -22.1 dB over 256 windows)
    rej = pn_rejection_db(params.DEFAULT, 1)
    assert -23.5 < rej < -20.5
    # longer chips spread less (chip_len 8: about fs/8 wide): less rejection
    assert pn_rejection_db(params.DEFAULT, 8) > rej + 3


def test_clipping_reported():
    cfg = params.DEFAULT
    finger = ch.adc_streams(_finger(cfg))
    assert finger.clipped == 0
    assert np.abs(finger.adc.astype(int)).max() < 0.75 * 2048      # headroom for the noise
    # every row touched on one column: a 6 mm wide strip along column 20
    strip = S.Scene(sensor="default", frames=2, contacts=[
        {"diameter_mm": 400.0, "minor_diameter_mm": 6.0, "angle_deg": 90.0, "path": [[0, 100.0, 72.5]]}])
    r = ch.adc_streams(strip)
    assert r.clipped > 0 and r.adc.max() == 2047 and r.adc.min() == -2048
    palm = S.Scene(sensor="default", frames=2, contacts=[{"diameter_mm": 40.0, "path": [[0, 100.0, 70.0]]}])
    assert ch.adc_streams(palm).clipped > 0


def test_enob_and_dc():
    cfg = params.SMALL
    sc = _finger(cfg)
    a = ch.adc_streams(sc).adc
    e = ch.adc_streams(_finger(cfg, enob=8)).adc
    assert np.all(e % 16 == 0) and np.abs(e.astype(int) - a).max() <= 16
    d = ch.adc_streams(_finger(cfg, dc_lsb=100.0)).adc
    assert np.array_equal(d.astype(int) - a, np.full(a.shape, 100))
    # DC never reaches a comb bin
    assert np.allclose(rx_array.receive(d, cfg), rx_array.receive(a, cfg), atol=1e-9)


def test_chunking_does_not_change_the_stream():
    sc = S.load(S.SCENES_DIR / "small.json")
    a = ch.adc_streams(sc, chunk_windows=7).adc
    b = ch.adc_streams(sc, chunk_windows=1000).adc
    assert np.array_equal(a, b)


def _snr_db(cfg, m, frames):
    r, c = cfg.rows // 2, cfg.cols // 2
    sc = S.Scene(sensor=cfg.name, frames=frames, m=m, seed=5, effects={"noise": {"snr_db": 30.0}},
                 contacts=[{"path": [[0, c * cfg.pitch_mm, r * cfg.pitch_mm]]}])
    hm = rx_array.receive(ch.adc_streams(sc).adc, cfg, m=m)
    clean = rx_array.unit_cell_counts(cfg) * ch.finger_peak_coupling(cfg)
    # the peak cell and its 4 neighbours (all >> noise): the same in-phase noise RMS
    cells = [(r, c), (r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)]
    noise = np.concatenate([hm[:, i, j] - hm[:, i, j].mean() for i, j in cells])
    return 20 * np.log10(clean / noise.std())


def test_snr_calibration_default_physics():
    cfg = params.DEFAULT
    assert ch.noise_sigma_for_snr(cfg) == pytest.approx(118.06, abs=0.01)
    s1 = _snr_db(cfg, 1, 600)
    s2 = _snr_db(cfg, 2, 400)
    assert abs(s1 - 30.0) < 0.5
    assert abs(s2 - 33.0) < 0.5


def test_returned_coupling_and_adc_consistent():
    # noiseless, no PN, no delay: the ADC word is the rounded sum of the returned coupling
    # times the tone table
    sc = S.Scene(sensor="small", frames=5, contacts=[
        {"path": [[0, 5.0, 5.0], [1e-5, 15.0, 9.0]]},
        {"path": [[0, 20.0, 3.0]], "active": [[100, 250]], "active_units": "samples"}])
    cfg = sc.cfg
    r = ch.adc_streams(sc, return_coupling=True, chunk_windows=2)
    assert np.allclose(r.coupling, ch.coupling_per_sample(sc, sc.n_samples), atol=1e-13)
    T = ch.tone_table(cfg)
    n = np.arange(sc.n_samples) % cfg.n_fft
    v = TONE_LSB * np.einsum("nr,nrc->nc", T[n], r.coupling)
    assert np.array_equal(r.adc.astype(int), np.rint(v).astype(int))


def test_other_sensor_build():
    # a scene runs on another build of its sensor (here a 14-bit ADC): same physics in LSB
    sc = _finger(params.SMALL)
    cfg14 = params.SMALL.replace(adc_bits=14)
    a = ch.adc_streams(sc).adc
    b = ch.adc_streams(sc, cfg14).adc
    assert np.array_equal(a, b)                     # nothing clips: identical words
    strip = S.Scene(sensor="small", frames=1, contacts=[{"diameter_mm": 300.0, "strength": 3.0,
                                                          "path": [[0, 12.0, 7.0]]}])
    assert ch.adc_streams(strip).adc.max() == 2047
    assert ch.adc_streams(strip, cfg14).adc.max() > 2047
    assert strip.with_cfg(cfg14).replace(frames=2).cfg is cfg14



def test_channel_sim_fixed_hand_values():
    # 2 rows, 1 column; G = 0.5 and 0.25 (16 fractional bits); noise 0.5 LSB (4 frac bits)
    dac = np.array([[3, 2], [3, 2], [2047, 2047], [-5, 1]])
    g0 = np.array([[1 << 15], [1 << 14]])
    g1 = np.array([[(1 << 16) - 1], [(1 << 16) - 1]])
    noise = np.array([[8], [-8]])
    adc, clip = ch.channel_sim_fixed(dac, g0, [(2, g1)], noise, adc_bits=12)
    # s0: 1.5 + 0.5 + 0.5 = 2.5 -> 3 (half up); s1: 2.0 - 0.5 = 1.5 -> 2
    # s2: ~4094 -> clipped to 2047; s3: (-5 + 1)*(1 - 2^-16) - 0.5 = -4.49994 -> -4
    assert adc[:, 0].tolist() == [3, 2, 2047, -4]
    assert clip.tolist() == [False, False, True, False]


def test_fixed_effects_words():
    """The scene's effects in fixed point (bench/core's channel): exact bin increments,
    the ADC-delay phase offset, DC, ENOB, delay; tone_phases "schroeder" refused."""
    cfg = params.DEFAULT
    sc = S.Scene(name="x", sensor="default", frames=1, seed=5, contacts=[],
                 effects={"dc_lsb": 2.5, "enob": 9, "delay_samples": 4, "noise": {"rms_lsb": 10.0},
                          "interferer": [{"bin": 43, "amp_lsb": 200.0},
                                         {"bin": 53.5, "amp_lsb": 1.5, "phase_rad": math.pi / 2}]})
    e = ch.fixed_effects(sc, adc_delay=1)
    assert (e.key, e.sigma_q, e.dc_q, e.enob_clear, e.delay) == (1005, 2560, 5 << 15, 3, 4)
    inc0, inc1 = 43 << 24, int(53.5 * (1 << 24))
    assert e.interferers == ((inc0, inc0, 51200), (inc1, (inc1 + (1 << 30)) & 0xFFFFFFFF, 384))
    assert e.param_words()[:6] == [1005, 2560, 5 << 15, 7, 4, 2]
    # the interferer sum follows the float sine within the table's phase truncation
    k = np.arange(2000)
    v = e.interference(0, 2000) / 65536.0
    f = 200 * np.sin(2 * np.pi * 43 * (k + 1) / 256) + 1.5 * np.sin(2 * np.pi * 53.5 * (k + 1) / 256 + np.pi / 2)
    assert np.abs(v - f).max() < 0.35
    with pytest.raises(ch.UnsupportedEffect, match="tone_phases"):
        ch.fixed_effects(sc.replace(effects={"tone_phases": "schroeder"}))


def test_channel_sim_fixed_effects_hand_values():
    # 1 row, 1 column, G = 1.0 - 2^-16; delay 2, DC 0.5 LSB, ENOB 10 (2 low bits cleared)
    dac = np.array([[100], [-7], [13], [2047], [-2048]])
    g0 = np.array([[(1 << 16) - 1]])
    e = ch.FixedEffects(dc_q=1 << 15, delay=2, enob_clear=2)
    adc, clip = ch.channel_sim_fixed(dac, g0, (), None, adc_bits=12, effects=e)
    # samples 0, 1: no row words yet, 0.5 -> 1 (half up) -> 0 after ENOB;
    # 2: 100 (1 - 2^-16) + 0.5 = 100.4985 -> 100; 3: -6.4999 -> -6 -> -8; 4: 13.4998 -> 13 -> 12
    assert adc[:, 0].tolist() == [0, 0, 100, -8, 12] and not clip.any()
