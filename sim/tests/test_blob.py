"""Blob model: a palm is one blob, its maxima are removed, fingers next to it stay."""
import numpy as np
import pytest

from fmt import params
from fmt.blob import find_blobs, label_regions, split_touches
from fmt.localmax import local_maxima_fixed


def ellipse_map(cfg, cx, cy, a, b, peak, rng=None):
    """Cells inside an axis-aligned ellipse (cells) get peak * (1 - 0.3 r^2) (a domed
    palm), others 0; optional noise makes several local maxima inside the palm."""
    r, c = np.mgrid[0:cfg.rows, 0:cfg.cols]
    d2 = ((c - cx) / a) ** 2 + ((r - cy) / b) ** 2
    z = np.where(d2 <= 1, peak * (1 - 0.3 * d2), 0.0)
    if rng is not None:
        z = z + np.where(d2 <= 1, rng.normal(0, 0.05 * peak, z.shape), 0)
    return np.clip(np.rint(z), 0, 65535).astype(np.int64)


def finger(cfg, row, col, peak):
    r, c = np.mgrid[0:cfg.rows, 0:cfg.cols]
    return np.rint(peak * np.exp(-((r - row) ** 2 + (c - col) ** 2) / 0.8)).astype(np.int64)


def test_labelling_is_4_connected():
    z = np.zeros((4, 4), dtype=np.int64)
    z[0, 0] = z[1, 1] = 5            # diagonal only: two regions
    z[3, 1:4] = 5
    lab, n = label_regions(z, 5)
    assert n == 3 and lab[0, 0] != lab[1, 1] and len(set(lab[3, 1:4])) == 1


def test_palm_is_one_blob_and_fingers_survive():
    cfg = params.DEFAULT
    rng = np.random.default_rng(5)
    palm = ellipse_map(cfg, cx=12.0, cy=15.0, a=7.0, b=9.0, peak=8000, rng=rng)
    fingers = [(4, 30), (25, 33), (15, 24)]          # (15, 24): 5 cells from the palm's edge
    z = palm.copy()
    for r, c in fingers:
        z = np.maximum(z, finger(cfg, r, c, 6000))
    cands, n, _ = local_maxima_fixed(z, 2000, "moore", 64)
    assert n > len(fingers) + 1                      # the noisy palm gives a swarm of maxima
    kept, blobs = split_touches(z, cands, blob_threshold=1000, blob_min_cells=12)
    assert len(blobs) == 1
    b = blobs[0]
    assert abs(b.cx - 12.0) < 0.3 and abs(b.cy - 15.0) < 0.3
    assert abs(b.cx_q - b.cx * 256) <= 0.5 and abs(b.cy_q - b.cy * 256) <= 0.5
    assert b.area == int((palm >= 1000).sum())
    assert b.bbox[0] >= 6 and b.bbox[2] <= 24 and b.bbox[1] >= 5 and b.bbox[3] <= 19
    assert b.peak == int(z[b.mask].max())
    assert sorted((c.row, c.col) for c in kept) == sorted(fingers)


def test_sensor_rendered_palm():
    sensor = pytest.importorskip("fmt.sensor")
    cfg = params.DEFAULT
    # a 50 x 70 mm palm and a finger 15 mm to its right
    cmap = (sensor.contact_map(cfg, [(60.0, 70.0, 70.0, 1.0, 50.0, 0.3)])
            + sensor.contact_map(cfg, [(120.0, 70.0, 8.0, 1.0)]))
    z = np.rint(cmap * 10000).astype(np.int64)
    cands, n, _ = local_maxima_fixed(z, 2000, "moore", 64)
    kept, blobs = split_touches(z, cands, 1000, 12)
    assert len(blobs) == 1 and blobs[0].area >= 100
    assert abs(blobs[0].cx * 5 - 60.0) < 2.5 and abs(blobs[0].cy * 5 - 70.0) < 2.5
    assert [(c.row, c.col) for c in kept] == [(14, 24)]


def test_small_region_is_not_a_blob():
    cfg = params.SMALL
    z = np.zeros((cfg.rows, cfg.cols), dtype=np.int64)
    z[1:3, 1:4] = 5000                               # 6 cells
    assert find_blobs(z, 1000, 12) == []
    assert len(find_blobs(z, 1000, 6)) == 1


def test_blob_stream_fixed_order_limit_and_bounds():
    """The RTL twin: largest first, ties by the first cell's raster index, the first
    max_blobs kept, overflow when more; centroid within 0.5 LSB of the float value."""
    from fmt.blob import blob_stream_fixed
    rng = np.random.default_rng(9)
    z = np.zeros((8, 10), dtype=np.int64)
    z[0, 0] = 7                                  # 1 cell, first in raster order
    z[0, 8:10] = 9                               # 2 cells
    z[3:5, 3:5] = [[5, 9], [9, 2]]               # 4 cells, peak 9 twice: first (3, 4)
    z[7, 9] = 3                                  # 1 cell, last
    recs, found, over = blob_stream_fixed(z, 1, 1, 8)
    assert found == 4 and not over
    assert [r[0] for r in recs] == [4, 2, 1, 1]
    assert (recs[2][3], recs[2][4]) == (0, 0) and (recs[3][3], recs[3][4]) == (7, 9)
    assert recs[0][7:] == (9, 3, 4) and recs[0][3:7] == (3, 3, 4, 4)
    # cx = (5*3 + 9*4 + 9*3 + 2*4) * 256 / 25, round half up
    assert recs[0][1] == (86 * 256 + 12) // 25
    recs2, found2, over2 = blob_stream_fixed(z, 1, 1, 3)
    assert recs2 == recs[:3] and found2 == 4 and over2
    assert blob_stream_fixed(z, 1, 2, 8)[1] == 2
    with pytest.raises(ValueError):
        blob_stream_fixed(z, 0, 1, 8)
    for _ in range(20):
        hm = np.where(rng.random((30, 40)) < 0.5, rng.integers(1, 65536, (30, 40)), 0)
        recs, found, _ = blob_stream_fixed(hm, 1, 1, 1000)
        for r, b in zip(recs, find_blobs(hm, 1, 1)):
            assert abs(r[1] - b.cx * 256) <= 0.5 and abs(r[2] - b.cy * 256) <= 0.5


def test_blob_mask_fixed_is_union_of_blob_masks():
    from fmt.blob import blob_mask_fixed
    z = np.zeros((6, 8), dtype=np.int64)
    z[0, 0:3] = 10                 # 3 cells
    z[2:5, 5] = 10                 # 3 cells
    z[5, 0] = 10                   # 1 cell
    m = blob_mask_fixed(z, 5, 3)
    assert m.sum() == 6 and m[0, 0] and m[4, 5] and not m[5, 0]
    assert not blob_mask_fixed(z, 5, 4).any()
