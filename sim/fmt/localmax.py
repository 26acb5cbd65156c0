"""Coarse touches: 3x3 local maxima above a threshold, the twin of ``rtl/fmt_localmax.v``.

Rule (the RTL follows it bit for bit; integer heat maps, so the float and fixed
models are the same function):

* cell p = (r, c) with value z[p] is a **coarse touch** iff ``z[p] >= threshold`` (a cell
  exactly at the threshold counts) and, for every neighbour q of p that exists on the
  sensor (Moore: 8 neighbours, Von Neumann "vn": 4):

  - ``z[p] >  z[q]`` if q **precedes** p in raster order (row above, or same row and
    column to the left),
  - ``z[p] >= z[q]`` if q **follows** p (same row to the right, or row below).

  A neighbour outside the sensor does not disqualify p (edges and corners).

* Tie rule: for two equal neighbouring cells exactly one of the two comparisons is
  strict, so exactly one of them can be the maximum: the one first in raster order.
  More generally, in a plateau (a connected set of equal cells with lower cells around
  it) a cell is a maximum iff none of its plateau neighbours precedes it.  The first
  plateau cell in raster order always qualifies, so a plateau never yields zero touches;
  it yields exactly one whenever every other plateau cell has a plateau neighbour
  earlier in raster order -- true for every rectangle (2x1, 2x2, 3x1, ...), every
  diagonal pair, and every plateau that is convex along rows.  Only concave
  ("V"/"U"-shaped) plateaus whose arms open upward, e.g. (0,0),(1,1),(0,2) under Moore,
  give one touch per arm; ``sim/tests/test_localmax.py`` checks these statements
  exhaustively over all plateau shapes in a 3x3 box.

* Contact limit, with hysteresis on the ranking (issue #11 item 3): a maximum is
  *continuing* when it lies within one cell (|row - r| <= 1 and |col - c| <= 1, for
  either neighbourhood) of a candidate the previous frame emitted (none after a reset
  or an incomplete frame).  When more maxima than ``max_touches`` exist, the first in
  this order are kept: continuing before new, then z descending, then raster index
  (row * COLS + col) ascending; the others are dropped, ``overflow`` is set and
  ``n_found - max_touches`` is the drop count.  The candidates come out in that order.
  So N + 1 fingers under a limit of N give the same N every frame (the strongest N of
  the frame they landed in), and a finger landing among a full set waits for a free
  place instead of taking it from a weaker continuing one.  A finger moves far less
  than a cell per frame (3 m/s is 18 um a frame at 162.76 kHz, the cells are mm), so
  its maximum stays within one cell of the last frame's.  :class:`LocalMaxima` keeps
  the previous frame's candidates; :func:`local_maxima_fixed` takes them as ``prev``.

Each candidate carries its 3x3 neighbourhood ``z3[dy+1][dx+1]`` (a neighbour outside
the sensor reads 0) and ``missing`` (9-bit mask, bit k = (dy+1)*3 + (dx+1) set when that
neighbour is outside the sensor), the same packing as the RTL's ``cand_z`` /
``cand_missing``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NEIGHBOURHOODS = ("moore", "vn")
MOORE_OFFSETS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]
VN_OFFSETS = [(-1, 0), (0, -1), (0, 1), (1, 0)]


@dataclass
class Candidate:
    row: int
    col: int
    z3: np.ndarray      # (3, 3) int64, z3[dy+1, dx+1]; 0 outside the sensor
    missing: int        # bit (dy+1)*3 + (dx+1) = 1 when that neighbour is outside

    @property
    def z(self) -> int:
        return int(self.z3[1, 1])

    def packed_z(self, hm_w: int) -> int:
        """The RTL's ``cand_z`` word: neighbour k at bits [k*hm_w +: hm_w]."""
        v = 0
        for k in range(9):
            v |= int(self.z3[k // 3, k % 3]) << (k * hm_w)
        return v


def offsets(neighbourhood: str):
    if neighbourhood == "moore":
        return MOORE_OFFSETS
    if neighbourhood == "vn":
        return VN_OFFSETS
    raise ValueError(f"neighbourhood must be one of {NEIGHBOURHOODS}, got {neighbourhood!r}")


def maxima_mask(hm, threshold: int, neighbourhood: str = "moore") -> np.ndarray:
    """Boolean map of the coarse touches (before the contact limit). Vectorized."""
    z = np.asarray(hm, dtype=np.int64)
    rows, cols = z.shape
    pad = np.full((rows + 2, cols + 2), -1, dtype=np.int64)   # -1: never disqualifies
    pad[1:-1, 1:-1] = z
    ok = z >= threshold
    for dy, dx in offsets(neighbourhood):
        q = pad[1 + dy:1 + dy + rows, 1 + dx:1 + dx + cols]
        precedes = dy < 0 or (dy == 0 and dx < 0)
        ok &= (z > q) if precedes else (z >= q)
    return ok


def neighbourhood3x3(hm, r: int, c: int) -> tuple[np.ndarray, int]:
    z = np.asarray(hm, dtype=np.int64)
    rows, cols = z.shape
    z3 = np.zeros((3, 3), dtype=np.int64)
    missing = 0
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            rr, cc = r + dy, c + dx
            if 0 <= rr < rows and 0 <= cc < cols:
                z3[dy + 1, dx + 1] = z[rr, cc]
            else:
                missing |= 1 << ((dy + 1) * 3 + dx + 1)
    return z3, missing


def near_mask(shape, prev) -> np.ndarray:
    """Cells within one cell (Chebyshev) of any (row, col) in ``prev``."""
    rows, cols = shape
    m = np.zeros((rows, cols), dtype=bool)
    for r, c in prev:
        m[max(0, r - 1):r + 2, max(0, c - 1):c + 2] = True
    return m


def local_maxima_fixed(hm, threshold: int, neighbourhood: str = "moore", max_touches: int = 16,
                       prev=()):
    """Coarse touches of one heat map: ``(candidates, n_found, overflow)``.

    ``candidates``: at most ``max_touches`` :class:`Candidate`, continuing ones first
    (within one cell of a (row, col) in ``prev``, the previous frame's candidates), then
    strongest first, ties by raster order; ``n_found``: number of maxima before the
    limit; ``overflow``: ``n_found > max_touches``.
    """
    z = np.asarray(hm, dtype=np.int64)
    m = maxima_mask(z, threshold, neighbourhood)
    rr, cc = np.nonzero(m)                      # raster order
    vals = z[rr, cc]
    near = near_mask(z.shape, prev)[rr, cc].astype(np.int64)
    order = np.lexsort((rr * z.shape[1] + cc, -vals, -near))
    n_found = int(len(order))
    keep = order[:max(0, int(max_touches))]
    cands = []
    for i in keep:
        z3, missing = neighbourhood3x3(z, int(rr[i]), int(cc[i]))
        cands.append(Candidate(int(rr[i]), int(cc[i]), z3, missing))
    return cands, n_found, n_found > max_touches


class LocalMaxima:
    """The stateful twin of ``rtl/fmt_localmax.v``: :func:`local_maxima_fixed` frame after
    frame, each ranked against the candidates the frame before emitted."""

    def __init__(self):
        self.prev: list[tuple[int, int]] = []

    def reset(self) -> None:
        """After a reset (or a frame that came out incomplete): no continuing maxima."""
        self.prev = []

    def frame(self, hm, threshold: int, neighbourhood: str = "moore", max_touches: int = 16):
        out = local_maxima_fixed(hm, threshold, neighbourhood, max_touches, self.prev)
        self.prev = [(c.row, c.col) for c in out[0]]
        return out
