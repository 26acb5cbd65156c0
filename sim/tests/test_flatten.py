"""Field flattening model: fixed vs float bound, saturation, rounding, calibration."""
import numpy as np
import pytest

from fmt import params
from fmt.flatten import GAIN_ONE, GAIN_MAX, calibrate, flatten_float, flatten_fixed, identity


@pytest.mark.parametrize("cfg", [params.SMALL, params.DEFAULT], ids=lambda c: c.name)
def test_fixed_vs_float_bound(cfg):
    rng = np.random.default_rng(1)
    top = (1 << cfg.hm_width) - 1
    hm = rng.integers(0, top + 1, size=(20, cfg.rows, cfg.cols))
    off = rng.integers(0, 4000, size=(cfg.rows, cfg.cols))
    gain = rng.integers(0, GAIN_MAX + 1, size=(cfg.rows, cfg.cols))
    q, sat = flatten_fixed(hm, off, gain, cfg)
    f = flatten_float(hm, off, gain, cfg)
    assert q.min() >= 0 and q.max() <= top
    ok = ~sat
    assert np.abs(q[ok] - f[ok]).max() <= 0.5          # round half up: at most 1/2 LSB
    # saturation flagged exactly where the exact product exceeds full scale (+1/2 rounding)
    exact = np.maximum(hm - off, 0) * gain / GAIN_ONE
    assert np.array_equal(sat, exact + 0.5 >= top + 1)
    assert sat.any() and (~sat).any()
    assert np.all(q[sat] == top)


def test_identity_is_transparent_and_rounding():
    cfg = params.SMALL
    off, gain = identity(cfg)
    hm = np.arange(cfg.rows * cfg.cols).reshape(cfg.rows, cfg.cols) * 997 % 65536
    q, sat = flatten_fixed(hm, off, gain, cfg)
    assert np.array_equal(q, hm) and not sat.any()
    # round half up: d * gain = 1.5 LSB and 2.5 LSB -> 2 and 3; 0.5 LSB -> 1
    z = np.array([[3, 5, 1]])
    c1 = params.SMALL.replace(rows=1, cols=3)
    q, _ = flatten_fixed(z, np.zeros_like(z), np.full_like(z, GAIN_ONE // 2), c1)
    assert q.tolist() == [[2, 3, 1]]
    # below the offset: clamp to 0, not saturation
    q, sat = flatten_fixed(np.array([[10, 0, 65535]]), np.array([[11, 5, 0]]),
                           np.array([[GAIN_MAX, GAIN_MAX, GAIN_ONE]]), c1)
    assert q.tolist() == [[0, 0, 65535]] and not sat.any()
    with pytest.raises(ValueError):
        flatten_fixed(np.array([[65536, 0, 0]]), np.zeros((1, 3), int), np.zeros((1, 3), int), c1)


def test_calibration_recovers_offset_and_gain():
    """Each cell has its own baseline and sensitivity; after calibration a uniform
    object reads the same everywhere (to quantization) and a non-uniform known
    calibration map is reproduced."""
    cfg = params.DEFAULT
    rng = np.random.default_rng(7)
    base = rng.uniform(200, 800, size=(cfg.rows, cfg.cols))
    sens = rng.uniform(0.6, 1.6, size=(cfg.rows, cfg.cols))
    noise = lambda n: rng.normal(0, 2.0, size=(n, cfg.rows, cfg.cols))
    untouched = np.rint(base + noise(64))
    sheet = np.rint(base + 20000 * sens + noise(64))
    off, gain = calibrate(untouched, sheet, None, cfg)
    assert np.abs(off - base).max() < 2.0
    assert gain.min() >= 0 and gain.max() <= GAIN_MAX
    assert abs(np.median(gain) - GAIN_ONE) <= 1
    q, sat = flatten_fixed(np.rint(base + 20000 * sens).astype(np.int64), off, gain, cfg)
    assert not sat.any()
    med = np.median(q)
    assert np.abs(q - med).max() / med < 2e-3            # flat to 0.2 %
    # a finger at 30 % of the sheet reads 30 % on every cell
    qf, _ = flatten_fixed(np.rint(base + 6000 * sens).astype(np.int64), off, gain, cfg)
    assert np.abs(qf / med - 0.3).max() < 3e-3
    # known non-uniform calibration object (e.g. a puck covering part of the sensor)
    truth = np.zeros((cfg.rows, cfg.cols))
    truth[5:25, 10:30] = np.linspace(0.5, 1.0, 20)[None, :]
    cal = np.rint(base + 20000 * sens * truth + noise(64))
    off2, gain2 = calibrate(untouched, cal, truth, cfg)
    assert np.all(gain2[truth == 0] == GAIN_ONE)          # unknown cells keep gain 1.0
    q2, _ = flatten_fixed(np.rint(base + 20000 * sens).astype(np.int64), off2, gain2, cfg)
    inner = q2[5:25, 10:30]
    assert np.abs(inner / np.median(inner) - 1).max() < 5e-3
