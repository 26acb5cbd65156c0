"""Channel and ADC: orthogonal comb, exact onset sample, clipping, ENOB, DC, PN."""
import json
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
    assert e.interferers == ((inc0, inc0, 51200, 0, 0, 0, 0, 0),
                             (inc1, (inc1 + (1 << 30)) & 0xFFFFFFFF, 384, 0, 0, 0, 0, 0))
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


# ---- issue #12 item 2: sweeping and bursty interferers, display and charger noise --------
def _osc_scene(cfg=params.SMALL, contacts=(), frames=2, **eff):
    return S.Scene(name="o", sensor=cfg.name, frames=frames, seed=3, contacts=list(contacts), effects=eff)


def test_sweep_words_hand_values():
    """A sweep of fs^2 / 2^32 Hz/s is dinc = 2^32: the top 32 phase bits are then ph0 +
    k inc + k (k - 1) / 2 (the increment grows by one every sample); a falling sweep is the
    two's complement."""
    cfg = params.SMALL
    fs = cfg.fs_hz
    sc = _osc_scene(interferer=[{"bin": 10, "amp_lsb": 100.0, "sweep_hz_per_s": fs * fs / 2 ** 32},
                                {"bin": 10, "amp_lsb": 100.0, "sweep_hz_per_s": -fs * fs / 2 ** 32}])
    e = ch.fixed_effects(sc, adc_delay=0)
    (inc, ph0, amp, dinc, bper, bon, bst, fl), o2 = e.interferers
    assert dinc == 1 << 32 and o2[3] == (1 << 64) - (1 << 32)
    # inc = 10 bins (10 * 2^32 / 64) plus half a step of the sweep (0.5 in 2^-32 units: rounds to even)
    assert inc in (10 << 26, (10 << 26) + 1) and ph0 == 0 and (amp, bper, fl) == (25600, 0, 0)
    k = np.arange(3000)
    top = (ph0 + k * inc + k * (k - 1) // 2) % (1 << 32)
    want = (100 * 256 * ch.if_sine_table()[top >> 20]) >> 7
    assert np.array_equal(e.interference(0, 3000) - ch.FixedEffects(interferers=(o2,)).interference(0, 3000), want)


def test_sweep_and_burst_follow_the_float_model():
    """The fixed-point chirp and burst gate follow the float model's (Osc.wave) to the
    sine table's phase truncation (< 0.4 LSB at 150 LSB), across 20k samples (the
    frequency moves 0.8 MHz), with the ADC delay's time shift."""
    cfg = params.SMALL
    fs = cfg.fs_hz
    it = {"freq_hz": 5.0e6, "amp_lsb": 150.0, "phase_rad": 0.4, "sweep_hz_per_s": 1.7e12,
          "burst": {"period_s": 1000 / fs, "on_s": 300 / fs, "start_s": 250 / fs}}
    sc = _osc_scene(interferer=[it])
    (o,) = ch.oscillators(sc)
    e = ch.fixed_effects(sc, adc_delay=1)
    k = np.arange(20000)
    fix = e.interference(0, k.size) / 65536.0
    flt = o.wave(k + 1, fs)
    assert np.abs(fix - flt).max() < 0.4
    # gate by hand: ADC samples n = k + 1 in [250 + 1000 j, 550 + 1000 j)
    n = k + 1
    on = (n >= 250) & ((n - 250) % 1000 < 300)
    assert not fix[~on].any() and np.abs(fix[on]).max() > 140


def test_display_harmonics_and_limits():
    cfg = params.DEFAULT
    sc = _osc_scene(cfg, display={"line_hz": 62.5e3, "harmonics": [[90, 30.0], [100, 20.0, 1.0]]})
    osc = ch.oscillators(sc)
    assert [(o.freq_hz, o.amp_lsb, o.phase_rad, o.charger) for o in osc] == [
        (5.625e6, 30.0, 0.0, False), (6.25e6, 20.0, 1.0, False)]
    e = ch.fixed_effects(sc, adc_delay=0)
    # 6.25 MHz = fs * 3 / 20: inc = round(2^32 * 0.15); every column gets the same sum
    assert e.interferers[1][0] == round(0.15 * 2 ** 32)
    r = ch.adc_streams(sc, n_samples=512)
    assert (r.adc == r.adc[:, :1]).all() and np.abs(r.adc).max() >= 40


@pytest.mark.parametrize("eff,word", [
    ({"interferer": [{"bin": 10, "amp_lsb": 1.0, "sweep_hz_per_s": "fast"}]}, "sweep_hz_per_s"),
    ({"interferer": [{"bin": 40, "amp_lsb": 1.0}]}, "bin"),
    ({"interferer": [{"freq_hz": 3e7, "amp_lsb": 1.0}]}, "freq_hz"),
    ({"interferer": [{"bin": 10, "amp_lsb": -1.0}]}, "amp_lsb"),
    ({"interferer": [{"bin": 10, "amp_lsb": 1.0, "burst": {"period_s": -1e-6, "on_s": 0}}]}, "burst"),
    ({"interferer": [{"bin": 10, "amp_lsb": 1.0, "burst": {"period_s": 1e-6, "on_s": 2e-6}}]}, "burst"),
    ({"display": {"line_hz": 6e4, "harmonics": [[400, 1.0]]}}, "above Nyquist"),
    ({"display": {"line_hz": 6e4, "harmonics": [[2.5, 1.0]]}}, "harmonics[0]"),
    ({"charger": {"freq_hz": 1e5, "level": -1}}, "level"),
    ({"charger": {"freq_hz": 1e5, "level": 1, "harmonics": "triangle"}}, "harmonics"),
    ({"charger": {"freq_hz": 1e5, "level": 1, "harmonics": [[300, 0.5]]}}, "above Nyquist"),
])
def test_noise_effects_bad_values_one_line(tmp_path, eff, word):
    from fmt.inputs import InputError
    p = tmp_path / "s.json"
    p.write_text(json.dumps({"name": "bad", "sensor": "small", "frames": 1, "effects": eff, "contacts": []}))
    with pytest.raises(InputError) as ei:
        S.load(p)
    msg = str(ei.value)
    assert "\n" not in msg and word in msg and "effect" in msg, msg


def _finger_at(cfg, col, row, **kw):
    return {"name": "f", "path": [[0.0, col * cfg.pitch_mm, row * cfg.pitch_mm]], **kw}


def test_charger_only_through_touching_fingers():
    """Noise-free: with no contact the charger changes nothing; a finger centred on
    column 5 gets the square wave of peak level x a finger's tone on column 5 (weight 1,
    within the ADC rounding), less on the neighbours, nothing 4 columns away; a tap
    gets it from its onset sample on."""
    cfg = params.MEDIUM
    chg = {"charger": {"freq_hz": 1.0e5, "level": 0.5}}
    none0 = ch.adc_streams(_osc_scene(cfg, frames=3)).adc.astype(int)
    none1 = ch.adc_streams(_osc_scene(cfg, frames=3, **chg)).adc.astype(int)
    assert np.array_equal(none0, none1)
    fing = [_finger_at(cfg, 5, cfg.rows // 2)]
    a = ch.adc_streams(_osc_scene(cfg, fing, frames=3)).adc.astype(int)
    b = ch.adc_streams(_osc_scene(cfg, fing, frames=3, **chg)).adc.astype(int)
    d = b - a
    peak = 0.5 * ch.finger_tone_lsb(cfg)
    assert abs(np.abs(d[:, 5]).max() - peak) <= 1.0
    assert np.abs(d[:, 4]).max() < 0.9 * peak and np.abs(d[:, 6]).max() < 0.9 * peak
    assert np.abs(d[:, 4]).max() > 0.05 * peak
    assert not d[:, 9:].any() and not d[:, :1].any()
    # the square wave: + on the first half period of 100 kHz (fs / 1e5 = 416.7 samples)
    assert (d[5:200, 5] > 0.9 * peak).all() and (d[215:400, 5] < -0.9 * peak).all()
    n0 = cfg.n_fft + 77
    tap = [_finger_at(cfg, 5, cfg.rows // 2, active=[[n0, None]], active_units="samples")]
    a = ch.adc_streams(_osc_scene(cfg, tap, frames=3)).adc.astype(int)
    b = ch.adc_streams(_osc_scene(cfg, tap, frames=3, **chg)).adc.astype(int)
    assert not (b - a)[:n0].any() and np.abs((b - a)[n0:n0 + 300, 5]).min() > 0.9 * peak


def test_charger_weights_in_the_coupling_plan():
    """The RTL plan carries the charger weights as a row ROWS more (kind-3 records): 0
    before the tap lands, the float model's weights (to 2^-12) after; none without a charger."""
    from bench.core import run_sim_rtl as rsr
    cfg = params.SMALL
    n0 = 3 * cfg.n_fft + 11
    tap = [_finger_at(cfg, 2, 1, active=[[n0, None]], active_units="samples")]
    sc = _osc_scene(cfg, tap, frames=6, charger={"freq_hz": 1.0e5, "level": 1.0})
    g0, ups = rsr.coupling_plan(sc, 6 * cfg.n_fft, 3)
    assert g0.shape == (cfg.rows + 1, cfg.cols) and not g0[cfg.rows].any()
    (stamp, g1), = ups
    w = g1[cfg.rows] / 4096.0
    assert stamp == n0 and w.argmax() == 2 and abs(w[2] - 1.0) < 0.05 and w[5] == 0
    rec = rsr.plan_records(cfg, g0, ups)
    assert sum(1 for r in rec if r >> 60 == 3) == np.count_nonzero(g1[cfg.rows])
    g0n, upsn = rsr.coupling_plan(sc.replace(effects={}), 6 * cfg.n_fft, 3)
    assert g0n.shape == (cfg.rows, cfg.cols) and np.array_equal(upsn[0][1], g1[:cfg.rows])


# ---- contacts whose strength and size change (issue #12 item 2, part 4) -------------------
def test_size_path_landing_finger():
    """A finger landing (strength 0.1 -> 1, 4 -> 8 mm over frames 2..6): noise-free ADC
    words equal those of the constant first size before the first point and of the
    constant last size after the last (held), and the peak cell grows in between."""
    cfg = params.MEDIUM
    win = cfg.n_fft / cfg.fs_hz
    xy = [[0.0, 5 * cfg.pitch_mm, 4 * cfg.pitch_mm]]
    land = S.Scene(name="land", sensor="medium", frames=9, contacts=[
        {"path": xy, "size_path": [[2 * win, 0.1, 4.0], [6 * win, 1.0, 8.0]]}])
    small = land.replace(contacts=[{"path": xy, "strength": 0.1, "diameter_mm": 4.0}])
    full = land.replace(contacts=[{"path": xy}])
    a, s0, s1 = (ch.adc_streams(x).adc for x in (land, small, full))
    n = cfg.n_fft
    assert np.array_equal(a[:2 * n], s0[:2 * n]) and np.array_equal(a[6 * n:], s1[6 * n:])
    hm = rx_array.receive(a, cfg)[:, 4, 5]
    assert (np.diff(hm[1:7]) > 0.05 * hm[6]).all()
    assert not land.contacts[0].fixed and land.contacts[0].stationary
    assert land.truth(7 * win)[0]["diameter_mm"] == 8.0 and land.truth(4 * win)[0]["diameter_mm"] == 6.0


def test_size_path_reaches_the_rtl_plan():
    """The RTL coupling plan holds each window's map: an update at every window boundary
    while the size changes, each equal to the float model's coupling at that boundary
    (quantised), none after the last size point."""
    from bench.core import run_sim_rtl as rsr
    cfg = params.SMALL
    win = cfg.n_fft / cfg.fs_hz
    sc = S.Scene(name="grow", sensor="small", frames=8, contacts=[
        {"path": [[0.0, 8.0, 6.0]], "diameter_mm": 12.0, "size_path": [[0.0, 0.2, 6.0], [4 * win, 1.0, 12.0]]}])
    g0, ups = rsr.coupling_plan(sc, 8 * cfg.n_fft, 3)
    assert [s for s, _ in ups] == [w * cfg.n_fft for w in range(1, 5)]
    wc = ch.window_coupling(sc, 0, 8)
    scale = rsr.coupling_scale(cfg)
    for w, (s, g) in enumerate([(0, g0)] + ups):
        assert np.array_equal(g, rsr.quantise_g(wc.g0[w], scale))
    assert (ups[-1][1] > g0).sum() >= 4


@pytest.mark.parametrize("sp,word", [([[0, 1.0]], "size_path"), ([[0, -1, 8]], "strength >= 0"),
                                     ([[0, 1, 0]], "diameter_mm > 0"), ("big", "size_path")])
def test_size_path_bad_values_one_line(tmp_path, sp, word):
    from fmt.inputs import InputError
    p = tmp_path / "s.json"
    p.write_text(json.dumps({"name": "bad", "sensor": "small", "frames": 1, "effects": {},
                             "contacts": [{"path": [[0, 1, 1]], "size_path": sp}]}))
    with pytest.raises(InputError) as ei:
        S.load(p)
    assert "\n" not in str(ei.value) and word in str(ei.value) and "contacts[0]" in str(ei.value)


# ---- a baseline that drifts (issue #12 item 2, part 5) ---------------------------------
def test_drift_rates_and_coupling():
    """Per-cell rates within +-g and +-o (fractions per second), fixed by the seed; the
    window-boundary coupling of an untouched sensor is base (1 + a t) + base b t."""
    cfg = params.SMALL
    sc = S.Scene(name="d", sensor="small", frames=4, seed=11, contacts=[],
                 effects={"drift": {"gain_pct_per_s": 5.0, "offset_pct_per_s": 2.0}})
    a, b = ch.drift_rates(sc)
    assert np.abs(a).max() <= 0.05 and np.abs(b).max() <= 0.02 and np.abs(a).max() > 0.03
    a2, _ = ch.drift_rates(sc.replace(seed=11))
    a3, _ = ch.drift_rates(sc.replace(seed=12))
    assert np.array_equal(a, a2) and not np.array_equal(a, a3)
    assert ch.drift_rates(sc.replace(effects={})) is None
    wc = ch.window_coupling(sc, 0, 4)
    base = 1.0 / 32
    for w in range(4):
        t0, t1 = w * cfg.n_fft / cfg.fs_hz, (w + 1) * cfg.n_fft / cfg.fs_hz
        assert np.allclose(wc.g0[w], base * (1 + a * t0) + base * b * t0, rtol=1e-12, atol=0)
        assert np.allclose(wc.g1[w], base * (1 + a * t1) + base * b * t1, rtol=1e-12, atol=0)
        assert np.array_equal(wc.g0[w], wc.b0[w])


def test_drift_moves_the_untouched_heat_map():
    """Noise-free, untouched, 1e5 %/s (+-25 % over the run): each cell's heat map moves by (a + b) (t1 - t0)
    relative to its first frame (the ADC rounds a 10 LSB baseline tone: cells scatter by
    ~1 %, the fit over 80 cells within 3 %); no drift = no change."""
    cfg = params.MEDIUM
    sc = S.Scene(name="d", sensor="medium", frames=60, seed=4, contacts=[],
                 effects={"drift": {"gain_pct_per_s": 1e5, "offset_pct_per_s": 5e4}})
    hm = rx_array.receive(ch.adc_streams(sc).adc, cfg)
    a, b = ch.drift_rates(sc)
    win = cfg.n_fft / cfg.fs_hz
    want = (1 + (a + b) * 59.5 * win) / (1 + (a + b) * 0.5 * win) - 1.0
    rel = hm[-1] / hm[0] - 1.0
    slope = float((rel * want).sum() / (want * want).sum())
    assert abs(slope - 1.0) < 0.03 and np.abs(rel - want).max() < 0.03 and np.abs(want).max() > 0.08
    h0 = rx_array.receive(ch.adc_streams(sc.replace(effects={})).adc, cfg)
    assert np.array_equal(h0[-1], h0[0])


def test_drift_bad_values_one_line(tmp_path):
    from fmt.inputs import InputError
    for eff, word in (({"gain_pct_per_s": -1}, "gain_pct_per_s"), ({"rate": 1}, "effect drift"),
                      ({"offset_pct_per_s": "x"}, "offset_pct_per_s")):
        p = tmp_path / "s.json"
        p.write_text(json.dumps({"name": "bad", "sensor": "small", "frames": 1, "effects": {"drift": eff},
                                 "contacts": []}))
        with pytest.raises(InputError) as ei:
            S.load(p)
        assert "\n" not in str(ei.value) and word in str(ei.value)


def test_charger_wave_float_and_fixed():
    """The charger's square wave and harmonics: the fixed-point sum (at weight 1) follows
    the float model's at the ADC-delayed time base: the square wave to its amplitude's
    1/256 LSB (+ the >> 7 floor), except samples whose edge falls between the two phases
    (< 0.5 % of them); the harmonics (330 LSB in all) to the sine table's phase truncation
    (330 * 2 pi / 4096 = 0.51 LSB)."""
    cfg = params.DEFAULT
    for harm in ("square", [[45, 0.7], [47, 0.3]]):
        sc = _osc_scene(cfg, charger={"freq_hz": 1.13e5, "level": 1.0, "harmonics": harm})
        osc = ch.oscillators(sc)
        assert all(o.charger for o in osc)
        e = ch.fixed_effects(sc, adc_delay=1)
        assert e.has_charger and not e.interference(0, 100).any()
        k = np.arange(40000)
        fix = e.charger(0, k.size) / 65536.0
        flt = sum(o.wave(k + 1, cfg.fs_hz) for o in osc)
        err = np.abs(fix - flt)
        if harm == "square":
            bad = err > 0.02
            assert bad.mean() < 0.005 and set(np.round(flt[bad] / np.abs(flt).max()).tolist()) <= {-1.0, 1.0}
        else:
            assert err.max() < 0.52
        assert np.abs(flt).max() > 0.9 * ch.finger_tone_lsb(cfg)
