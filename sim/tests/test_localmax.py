"""Coarse-touch model: tie rule on plateaus, edges, threshold, contact limit, order."""
import itertools

import numpy as np
import pytest

from fmt import params
from fmt.localmax import LocalMaxima, local_maxima_fixed, maxima_mask, near_mask, offsets


def brute_force(z, thr, nb):
    """Cell-by-cell statement of the rule (independent of the vectorized model)."""
    rows, cols = z.shape
    out = np.zeros_like(z, dtype=bool)
    for r in range(rows):
        for c in range(cols):
            ok = z[r, c] >= thr
            for dy, dx in offsets(nb):
                rr, cc = r + dy, c + dx
                if 0 <= rr < rows and 0 <= cc < cols:
                    if rr * cols + cc < r * cols + c:
                        ok &= z[r, c] > z[rr, cc]
                    else:
                        ok &= z[r, c] >= z[rr, cc]
            out[r, c] = ok
    return out


@pytest.mark.parametrize("nb", ["moore", "vn"])
def test_vectorized_equals_cell_rule(nb):
    rng = np.random.default_rng(3)
    for _ in range(200):
        z = rng.integers(0, 6, size=(rng.integers(1, 7), rng.integers(1, 8)))   # many ties
        thr = int(rng.integers(0, 5))
        assert np.array_equal(maxima_mask(z, thr, nb), brute_force(z, thr, nb))


def _connected(cells, nb):
    cells = set(cells)
    start = next(iter(cells))
    seen, stack = {start}, [start]
    while stack:
        r, c = stack.pop()
        for dy, dx in offsets(nb):
            q = (r + dy, c + dx)
            if q in cells and q not in seen:
                seen.add(q)
                stack.append(q)
    return seen == cells


@pytest.mark.parametrize("nb", ["moore", "vn"])
def test_every_plateau_in_3x3_box(nb):
    """Every connected plateau shape inside a 3x3 box, placed in a 7x7 map with lower
    surroundings: never zero touches; exactly one unless the shape has a cell (other
    than the first) with no plateau neighbour earlier in raster order, and then the
    touches are exactly those cells plus the first."""
    box = [(r, c) for r in range(3) for c in range(3)]
    n_shapes = n_one = 0
    for k in range(1, 10):
        for shape in itertools.combinations(box, k):
            if not _connected(shape, nb):
                continue
            z = np.full((7, 7), 10)
            for r, c in shape:
                z[r + 2, c + 2] = 50
            m = maxima_mask(z, 20, nb)
            found = {(int(r) - 2, int(c) - 2) for r, c in zip(*np.nonzero(m))}
            heads = {p for p in shape
                     if not any((p[0] + dy, p[1] + dx) in shape
                                for dy, dx in offsets(nb) if dy < 0 or (dy == 0 and dx < 0))}
            assert found == heads and len(found) >= 1
            n_shapes += 1
            n_one += len(found) == 1
    # rectangles and pairs always give one
    for h, w in [(1, 2), (2, 1), (2, 2), (1, 3), (3, 1), (3, 3), (2, 3)]:
        z = np.full((7, 7), 10)
        z[2:2 + h, 2:2 + w] = 50
        assert maxima_mask(z, 20, nb).sum() == 1
    if nb == "moore":
        for a, b in [((3, 3), (4, 4)), ((3, 4), (4, 3))]:   # diagonal pairs
            z = np.full((7, 7), 10)
            z[a], z[b] = 50, 50
            assert maxima_mask(z, 20, nb).sum() == 1
    assert 0 < n_one < n_shapes      # both kinds exist (see the model's docstring)


def test_edges_corners_spike_saturation_threshold():
    cfg = params.MEDIUM
    z = np.zeros((cfg.rows, cfg.cols), dtype=np.int64)
    corners = [(0, 0), (0, cfg.cols - 1), (cfg.rows - 1, 0), (cfg.rows - 1, cfg.cols - 1)]
    for i, p in enumerate(corners):
        z[p] = 1000 + i
    z[3, 0] = 65535                 # saturated edge cell
    z[4, 5] = 999                   # exactly at the threshold below
    cands, n, ov = local_maxima_fixed(z, 999, "moore", 16)
    got = [(c.row, c.col) for c in cands]
    assert got == [(3, 0), (7, 9), (7, 0), (0, 9), (0, 0), (4, 5)]
    assert n == 6 and not ov
    c = cands[0]
    assert c.missing == 0b001001001 and c.z3[1, 1] == 65535 and c.z3[:, 0].tolist() == [0, 0, 0]
    c00 = [c for c in cands if (c.row, c.col) == (0, 0)][0]
    assert c00.missing == 0b001001111
    assert local_maxima_fixed(z, 1000, "moore", 16)[1] == 5        # 999 is below threshold 1000
    # a spike next to a 2-cell plateau on the other neighbourhood
    z2 = np.zeros((5, 5), dtype=np.int64)
    z2[1, 1] = z2[1, 2] = 300
    z2[3, 3] = 301
    cands, n, _ = local_maxima_fixed(z2, 1, "vn", 16)
    assert [(c.row, c.col) for c in cands] == [(3, 3), (1, 1)]


def test_contact_limit_17_of_16():
    cfg = params.DEFAULT
    z = np.zeros((cfg.rows, cfg.cols), dtype=np.int64)
    pos = [(r, c) for r in range(2, 28, 6) for c in range(2, 38, 8)][:17]
    vals = [500 + 10 * i for i in range(17)]
    vals[5] = vals[6] = 700            # a tie in strength: raster order decides
    for p, v in zip(pos, vals):
        z[p] = v
    cands, n, ov = local_maxima_fixed(z, 100, "moore", 16)
    assert n == 17 and ov and len(cands) == 16
    weakest = pos[int(np.argmin(vals))]
    assert weakest not in [(c.row, c.col) for c in cands]
    zs = [c.z for c in cands]
    assert zs == sorted(zs, reverse=True)
    i5 = [(c.row, c.col) for c in cands].index(pos[5])
    assert [(c.row, c.col) for c in cands][i5 + 1] == pos[6]
    cands, n, ov = local_maxima_fixed(z, 100, "moore", 17)
    assert n == 17 and not ov and len(cands) == 17
    assert local_maxima_fixed(z, 100, "moore", 0)[0] == []


def test_packed_z():
    z = np.arange(1, 10).reshape(3, 3)
    cands, _, _ = local_maxima_fixed(z, 0, "moore", 4)
    c = cands[0]
    assert (c.row, c.col) == (2, 2)
    w = c.packed_z(16)
    assert [(w >> (16 * k)) & 0xFFFF for k in range(9)] == [5, 6, 0, 8, 9, 0, 0, 0, 0]
    assert c.missing == 0b111100100


def test_continuing_maxima_rank_first():
    """Hysteresis on the ranking: a maximum within one cell of a candidate of the frame
    before ranks ahead of every new one, whatever its strength; two cells away it is new."""
    z = np.zeros((9, 12), dtype=np.int64)
    pos = [(1, 1), (1, 5), (1, 9), (5, 1), (5, 5)]
    for p, v in zip(pos, (900, 800, 700, 600, 500)):
        z[p] = v
    lm = LocalMaxima()
    cands, n, ov = lm.frame(z, 100, "moore", 4)
    assert n == 5 and ov and [(c.row, c.col) for c in cands] == pos[:4]
    z2 = np.zeros_like(z)                      # every maximum one cell down-right; the
    for p, v in zip(pos, (900, 800, 700, 300, 5000)):   # dropped one now the strongest
        z2[p[0] + 1, p[1] + 1] = v
    cands, _, _ = lm.frame(z2, 100, "moore", 4)
    assert [(c.row, c.col) for c in cands] == [(2, 2), (2, 6), (2, 10), (6, 2)]
    assert [c.z for c in cands] == [900, 800, 700, 300]     # continuing, then by strength
    far = [(c.row, c.col) for c in local_maxima_fixed(z2, 100, "moore", 4, prev=[(0, 0)])[0]]
    assert far[0] == (6, 6)                    # (0, 0) is two cells from (2, 2): all new
    lm.reset()
    assert lm.frame(z2, 100, "moore", 4)[0][0].z == 5000
    assert near_mask((3, 3), [(0, 0)]).sum() == 4 and near_mask((3, 3), [(1, 1)]).all()
