"""Blobs: extended contacts (palm, flat hand, cheek).  The paper left this as future
work; this module defines it.  RTL twin: ``rtl/fmt_blob.v`` (``blob_stream_fixed``).

Definition:

* a **region** is a 4-connected set of cells with ``z >= blob_threshold`` (the same
  ">=" convention as the coarse-touch threshold);
* a region of at least ``blob_min_cells`` cells is a **blob**, reported once as
  :class:`Blob`: area (cells), centroid, bounding box, peak value and peak cell;
* the coarse touches (local maxima) that lie inside a blob are removed from the finger
  touches (``split_touches``); maxima outside every blob stay fingers.

Centroid: z-weighted mean of the cell centres, in cells with ``FRAC`` = 8 fractional
bits (Q8.8, same coordinates as the touch events: from the centre of cell (0, 0)).
Fixed point: ``cx = (sum(z*c) * 256 + sum(z) // 2) // sum(z)`` (round half up on exact
integers); the float model returns the unrounded value, ``|fixed - float*256| <= 0.5``.
Blobs are ordered by area (largest first), ties by the raster index of their first cell.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FRAC = 8


@dataclass
class Blob:
    area: int                 # cells
    cx_q: int                 # centroid x (column), Q8.8
    cy_q: int                 # centroid y (row), Q8.8
    cx: float                 # float centroid (reference)
    cy: float
    bbox: tuple               # (row_min, col_min, row_max, col_max), inclusive
    peak: int                 # largest z in the blob
    peak_rc: tuple            # (row, col) of the first cell in raster order holding the peak
    mask: np.ndarray          # bool (rows, cols)


def label_regions(hm, threshold: int) -> tuple[np.ndarray, int]:
    """4-connected labelling of ``z >= threshold``: (labels, n); 0 = background, regions
    numbered 1..n in raster order of their first cell."""
    z = np.asarray(hm, dtype=np.int64)
    rows, cols = z.shape
    on = z >= threshold
    lab = np.zeros((rows, cols), dtype=np.int64)
    n = 0
    for r0 in range(rows):
        for c0 in range(cols):
            if on[r0, c0] and lab[r0, c0] == 0:
                n += 1
                lab[r0, c0] = n
                stack = [(r0, c0)]
                while stack:
                    r, c = stack.pop()
                    for rr, cc in ((r - 1, c), (r + 1, c), (r, c - 1), (r, c + 1)):
                        if 0 <= rr < rows and 0 <= cc < cols and on[rr, cc] and lab[rr, cc] == 0:
                            lab[rr, cc] = n
                            stack.append((rr, cc))
    return lab, n


def find_blobs(hm, blob_threshold: int, blob_min_cells: int) -> list[Blob]:
    z = np.asarray(hm, dtype=np.int64)
    lab, n = label_regions(z, blob_threshold)
    blobs = []
    for k in range(1, n + 1):
        m = lab == k
        area = int(m.sum())
        if area < blob_min_cells:
            continue
        rr, cc = np.nonzero(m)
        w = z[rr, cc]
        sw = int(w.sum())
        if sw == 0:                       # threshold 0 and an all-zero region
            w = np.ones_like(w)
            sw = int(w.sum())
        sx, sy = int((w * cc).sum()), int((w * rr).sum())
        cx_q = (sx * (1 << FRAC) + sw // 2) // sw
        cy_q = (sy * (1 << FRAC) + sw // 2) // sw
        i = int(np.argmax(z[rr, cc]))     # first in raster order among equal peaks
        blobs.append(Blob(area=area, cx_q=cx_q, cy_q=cy_q, cx=sx / sw, cy=sy / sw,
                          bbox=(int(rr.min()), int(cc.min()), int(rr.max()), int(cc.max())),
                          peak=int(z[rr[i], cc[i]]), peak_rc=(int(rr[i]), int(cc[i])), mask=m))
    blobs.sort(key=lambda b: (-b.area, int(np.flatnonzero(b.mask.ravel())[0])))
    return blobs


def split_touches(hm, candidates, blob_threshold: int, blob_min_cells: int):
    """``(fingers, blobs)``: the candidates (objects with ``row``/``col``) outside every
    blob, and the blobs."""
    blobs = find_blobs(hm, blob_threshold, blob_min_cells)
    if not blobs:
        return list(candidates), blobs
    inside = np.zeros_like(blobs[0].mask)
    for b in blobs:
        inside |= b.mask
    return [c for c in candidates if not inside[c.row, c.col]], blobs


def blob_stream_fixed(hm, blob_threshold: int, blob_min_cells: int, max_blobs: int):
    """Twin of ``rtl/fmt_blob.v``: ``(records, found, overflow)``.

    ``records`` are the first ``max_blobs`` blobs of ``find_blobs`` (largest first, ties
    by the raster index of the first cell), each a tuple ``(area, cx_q, cy_q, rmin,
    cmin, rmax, cmax, peak, peak_row, peak_col)`` in the order of the RTL's blob stream;
    ``found`` is the number of blobs in the frame, ``overflow = found > max_blobs``
    (the smaller blobs beyond the limit are dropped: the rule is "keep the max_blobs
    first in the blob order").  The RTL needs ``blob_threshold >= 1`` (the centroid
    divides by sum(z) > 0); the unit-weight fallback of ``find_blobs`` for an all-zero
    region (threshold 0) has no RTL counterpart.
    """
    if blob_threshold < 1:
        raise ValueError("the RTL twin needs blob_threshold >= 1")
    blobs = find_blobs(hm, blob_threshold, blob_min_cells)
    recs = [(b.area, b.cx_q, b.cy_q, b.bbox[0], b.bbox[1], b.bbox[2], b.bbox[3], b.peak,
             b.peak_rc[0], b.peak_rc[1]) for b in blobs[:max_blobs]]
    return recs, len(blobs), len(blobs) > max_blobs


def blob_mask_fixed(hm, blob_threshold: int, blob_min_cells: int) -> np.ndarray:
    """Twin of the membership mask of ``rtl/fmt_blob.v`` (``mask_rd_data_o``): bool
    (rows, cols), True for the cells of every blob (also those beyond the RTL's
    MAX_BLOBS list); the same cells ``split_touches`` removes fingers from."""
    z = np.asarray(hm, dtype=np.int64)
    inside = np.zeros(z.shape, dtype=bool)
    for b in find_blobs(z, blob_threshold, blob_min_cells):
        inside |= b.mask
    return inside
