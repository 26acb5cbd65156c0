"""Float receiver: scale, despreading, accumulation over M windows."""
import numpy as np
import pytest

from fmt import params, rx_array


@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM, params.DEFAULT], ids=lambda c: c.name)
def test_tone_amplitude_scale(cfg):
    # a tone of amplitude A LSB on bin k_r reads A * 2**(HM_W - ADC_BITS + 1) on row r, every column
    n = np.arange(3 * cfg.n_fft)
    r = cfg.rows - 1
    A = np.array([100.0, 333.0])
    x = A[None, :] * np.cos(2 * np.pi * cfg.bins[r] * n / cfg.n_fft + 0.3)[:, None]
    hm = rx_array.receive(x, cfg)
    assert hm.shape == (3, cfg.rows, 2)
    assert np.allclose(hm[:, r, :], A * 32, rtol=1e-12)
    hm[:, r, :] = 0
    assert hm.max() < 1e-9


def test_despread_and_accumulate():
    cfg = params.SMALL
    rng = np.random.default_rng(0)
    x = rng.normal(size=(8 * cfg.n_fft + 5, 6))
    sign = rng.integers(0, 2, size=x.shape[0]).astype(np.uint8)
    y = rx_array.despread_float(x, sign)
    assert np.array_equal(y, x * (1 - 2 * sign[:, None].astype(float)))
    cells = rx_array.window_cells(x, cfg, sign)
    assert cells.shape == (8, cfg.rows, 6)               # trailing partial window dropped
    hm = rx_array.receive(x, cfg, sign, m=3)
    assert hm.shape == (2, cfg.rows, 6)                  # trailing partial frame dropped
    assert np.allclose(hm[1], cells[3:6].mean(axis=0))
    # cells are scale * |DFT| of the despread window
    X = np.fft.fft(y[cfg.n_fft:2 * cfg.n_fft], axis=0)[np.asarray(cfg.bins)]
    assert np.allclose(cells[1], rx_array.hm_scale(cfg) * np.abs(X))


@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM], ids=lambda c: c.name)
def test_scale_matches_fixed_receive_chain(cfg):
    # the float heat map has the fixed-point chain's scale (other block's twin, rx_fixed)
    R = pytest.importorskip("fmt.rx_array")
    pytest.importorskip("fmt.fft_r22sdf")
    from fmt import channel, scene
    sc = scene.Scene(sensor=cfg.name, frames=2, effects={"pn": {"enable": True}}, contacts=[
        {"path": [[0, 7.0, 6.0]]}, {"path": [[0, 21.0, 12.0]], "strength": 0.5}])
    a = channel.adc_streams(sc)
    hf = rx_array.receive(a.adc, cfg, a.rx_sign)
    hx = R.rx_heatmaps_fixed(a.adc, a.rx_sign, cfg)[0]
    big = hf > 1000
    assert big.sum() >= 4
    ratio = hx[big] / hf[big]
    assert np.abs(ratio - 1).max() < 5e-3
