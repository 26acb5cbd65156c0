"""Sensor coupling model: touched areas checked against geometry known independently of
the code (areas of disks, squares, symmetric placements)."""
import math

import numpy as np
import pytest

from fmt import params
from fmt.sensor import (BASELINE, TONE_LSB, attenuation, baseline, contact_map,
                        contact_maps, coupling)

CFG = params.DEFAULT
P = CFG.pitch_mm


def test_disk_inside_one_cell():
    # 4 mm disk at the centre of cell (10, 20): area pi*2^2 inside a 5x5 square
    m = contact_map(CFG, [(20 * P, 10 * P, 4.0, 1.0)])
    assert m[10, 20] == pytest.approx(math.pi * 4 / 25, abs=1e-13)
    m[10, 20] = 0
    assert np.abs(m).max() < 1e-13


def test_disk_covering_cell_is_one():
    # 8 mm disk centred on a cell: corner distance 3.54 mm < 4 mm -> fully covered
    m = contact_map(CFG, [(20 * P, 10 * P, 8.0, 1.0)])
    assert m[10, 20] == pytest.approx(1.0, abs=1e-13)
    # strength scales linearly
    m2 = contact_map(CFG, [(20 * P, 10 * P, 8.0, 0.25)])
    assert np.allclose(m2, 0.25 * m, atol=1e-15)


def test_disk_on_corner_four_equal_cells():
    x, y = 20.5 * P, 10.5 * P      # the corner shared by cells (10,20),(10,21),(11,20),(11,21)
    for d in (3.0, 6.0, 9.0):
        m = contact_map(CFG, [(x, y, d, 1.0)])
        quad = [m[10, 20], m[10, 21], m[11, 20], m[11, 21]]
        assert np.ptp(quad) < 1e-13
        if d <= P * 2:   # disk inside the 2x2 block: each cell holds a quarter
            assert quad[0] == pytest.approx(math.pi * d * d / 16 / 25, abs=1e-13)


@pytest.mark.parametrize("d", [2.0, 8.0, 13.7, 20.0])
def test_total_area_conserved(d):
    rng = np.random.default_rng(1)
    for _ in range(5):
        x, y = rng.uniform(40, 150), rng.uniform(40, 100)
        m = contact_map(CFG, [(x, y, d, 1.0)])
        assert m.sum() * P * P == pytest.approx(math.pi * d * d / 4, rel=1e-12)


def test_half_disk_on_sensor_edge():
    # centre on the left sensor edge x = -P/2: exactly half the disk is on the sensor
    m = contact_map(CFG, [(-P / 2, 50.0, 6.0, 1.0)])
    assert m.sum() * P * P == pytest.approx(math.pi * 9 / 2, rel=1e-12)


def test_ellipse_area_and_rotation_symmetry():
    a, b = 12.0, 6.0
    for ang in (0.0, 0.3, math.pi / 2, 1.1):
        m = contact_map(CFG, [(100.0, 70.0, a, 1.0, b, ang)])
        assert m.sum() * P * P == pytest.approx(math.pi * a * b / 4, rel=1e-12)
    # an ellipse along x on a cell centre is mirror symmetric and elongated along x
    m = contact_map(CFG, [(20 * P, 10 * P, 14.0, 1.0, 6.0, 0.0)])
    assert m[10, 19] == pytest.approx(m[10, 21], abs=1e-13)
    assert m[9, 20] == pytest.approx(m[11, 20], abs=1e-13)
    assert m[10, 21] > m[11, 20]
    # rotating by pi/2 swaps the roles of rows and columns
    m90 = contact_map(CFG, [(20 * P, 10 * P, 14.0, 1.0, 6.0, math.pi / 2)])
    assert m90[11, 20] == pytest.approx(m[10, 21], abs=1e-12)


def test_moves_smoothly():
    xs = 100.0 + np.linspace(0, 0.05, 11)
    vals = np.array([contact_map(CFG, [(x, 50.0, 8.0, 1.0)])[10, 21] for x in xs])
    d = np.diff(vals)
    assert np.all(d > 0) and np.ptp(d) < 1e-3 * d.mean()   # monotone, locally linear


def test_fringe_small_sigma_and_conservation():
    c = [(101.3, 52.1, 8.0, 1.0)]
    m0 = contact_map(CFG, c)
    m1 = contact_map(CFG, c, fringe_mm=0.3)
    # convolution keeps the total (far from the edges) and barely changes a small-sigma map
    assert m1.sum() == pytest.approx(m0.sum(), rel=1e-6)
    assert np.abs(m1 - m0).max() < 0.05
    m2 = contact_map(CFG, c, fringe_mm=2.0)
    assert m2.sum() == pytest.approx(m0.sum(), rel=1e-6)
    assert (m2 > 1e-3).sum() > (m0 > 1e-3).sum()      # the fringe spreads


def test_gaussian_profile():
    d = 8.0
    sig = d / (2 * math.sqrt(2 * math.log(2)))
    g = contact_map(CFG, [(100.0, 50.0, d, 1.0)], profile="gaussian")
    # unit-peak density: total volume 2 pi sigma^2
    assert g.sum() * P * P == pytest.approx(2 * math.pi * sig ** 2, rel=1e-9)
    # rotated elliptical Gaussian: same total, and a round one is rotation invariant
    e = contact_map(CFG, [(100.0, 50.0, 12.0, 1.0, 6.0, 0.7)], profile="gaussian")
    s1, s2 = 12 * sig / d, 6 * sig / d
    assert e.sum() * P * P == pytest.approx(2 * math.pi * s1 * s2, rel=1e-9)
    r0 = contact_map(CFG, [(101.0, 52.0, 8.0, 1.0, 8.0, 0.0)], profile="gaussian")
    r1 = contact_map(CFG, [(101.0, 52.0, 8.0, 1.0, 8.0 * (1 + 1e-9), 0.4)], profile="gaussian")
    assert np.abs(r0 - r1).max() < 1e-8
    # half-height: the density at the contour is 1/2 -> a tiny probe cell scaled check
    small = params.SensorConfig(name="t", rows=4, cols=6, n_fft=64, bin_lo=9, pitch_mm=0.01)
    probe = contact_map(small, [(d / 2, 0.0, d, 1.0)], profile="gaussian")
    assert probe[0, 0] == pytest.approx(0.5, rel=1e-4)


def test_gaussian_rotated_matches_axis_aligned_at_zero_angle():
    c = (97.0, 48.0, 12.0, 1.0, 6.0)
    a = contact_map(CFG, [c + (0.0,)], profile="gaussian")
    b = contact_map(CFG, [c + (1e-9,)], profile="gaussian")   # takes the rotated path
    assert np.abs(a - b).max() < 1e-8


def test_contact_maps_per_contact():
    c = [(50.0, 50.0, 8.0, 1.0), (120.0, 60.0, 8.0, 0.5)]
    ms = contact_maps(CFG, c)
    assert ms.shape == (2, CFG.rows, CFG.cols)
    assert np.allclose(ms.sum(0), contact_map(CFG, c))


def test_baseline_and_attenuation():
    att = attenuation(CFG, 0.1, 0.2)
    assert att[0, 0] == 1.0
    assert 20 * math.log10(att[0, 10]) == pytest.approx(-1.0)
    assert 20 * math.log10(att[5, 0]) == pytest.approx(-1.0)
    assert np.allclose(baseline(CFG), BASELINE)
    cp = coupling(CFG, [(100.0, 50.0, 8.0, 1.0)], row_db_per_cell=0.1)
    assert cp[10, 20] == pytest.approx((1 + BASELINE) * 10 ** (-2 / 20))
    assert TONE_LSB * (1 + BASELINE) < 2 ** (CFG.adc_bits - 1)


def test_fringe_quadrature_converged(monkeypatch):
    # doubling the quadrature order changes nothing: the default rule has converged
    from fmt import sensor
    c = [(101.3, 52.1, 8.0, 1.0), (60.0, 30.0, 12.0, 0.7, 6.0, 0.5)]
    for s in (0.5, 1.5):
        m = contact_map(CFG, c, fringe_mm=s)
        monkeypatch.setattr(sensor, "FRINGE_NR", 2 * sensor.FRINGE_NR)
        monkeypatch.setattr(sensor, "FRINGE_PER_SIGMA", 2 * sensor.FRINGE_PER_SIGMA)
        monkeypatch.setattr(sensor, "FRINGE_MAX", 2 * sensor.FRINGE_MAX)
        ref = contact_map(CFG, c, fringe_mm=s)
        monkeypatch.undo()
        assert np.abs(m - ref).max() < 1e-9
