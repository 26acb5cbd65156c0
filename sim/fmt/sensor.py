"""Sensor physics: contacts -> coupling of every row/column intersection.

Coordinates (docs/ARCHITECTURE.md): x = column, y = row, in mm, cell (r, c) centred at
(x, y) = (c * pitch, r * pitch); cell (r, c) covers [c - 1/2, c + 1/2] x [r - 1/2, r + 1/2]
pitches.  The sensor spans -pitch/2 .. cols * pitch - pitch/2 in x (rows likewise in y).

Contacts are given as an array of rows ``(x_mm, y_mm, diameter_mm, strength)`` (a round
contact) or ``(x_mm, y_mm, major_diameter_mm, strength, minor_diameter_mm, angle_rad)``
(an elliptical contact; ``angle`` is the major axis direction measured from +x towards +y,
i.e. towards growing row index).

Profiles (``contact_maps(..., profile=...)``), all in "coupling units" where 1.0 is a cell
completely covered by a contact of strength 1:

* ``"disk"`` -- paper Eq. 2: the received level is proportional to the touched area.
  coupling[r, c] = strength * area(contact ellipse ∩ cell square) / pitch**2, computed
  EXACTLY in closed form: the ellipse is mapped to the unit circle by an affine map, the
  cell square becomes a parallelogram, and the area of circle ∩ convex polygon is the sum
  over the polygon's edges of the signed area of circle ∩ triangle(centre, edge) (chord
  triangles and circular sectors; ``_circle_polygon_area``).  Positions therefore move
  the map smoothly, with no sampling noise.
* ``"disk"`` with ``fringe_mm = s > 0`` -- the touched area convolved with a Gaussian of
  standard deviation s (field fringing).  The cell integral of (disk * g) equals the
  integral over the disk of P_cell(p) = the probability that p + N(0, s^2 I) falls in the
  cell, an exact erf product.  The integral over the disk is done with a polar rule
  (Gauss-Legendre in r, trapezoid in theta, n_r = clip(6 a / s, 24, 160) and 2 n_r angles,
  mapped through the ellipse's affine map).  The integrand is smooth on the scale s, so
  the rule converges fast: measured max error per cell of an 8 mm finger against a
  640-point rule ~1e-13 for s = 0.1 .. 2 mm (sim/tests/test_sensor.py checks convergence,
  conservation of the total and the limit s -> 0).  Cells farther than the semi-axis +
  8 s from the centre are set to 0 (their value is < 1e-15).
* ``"gaussian"`` -- a 2-D Gaussian bump with unit density at its centre whose half-height
  contour is the contact ellipse (sigma = diameter / (2 sqrt(2 ln 2)) per axis),
  integrated over the cell / pitch**2.  Same convention as the disk: the density is 1
  where the contact "fully covers" the sensor (a disk has density 1 inside, 0 outside), so
  a cell deep inside a very large contact is 1.0 x strength for both profiles.  The total
  is pi d^2 / (4 ln 2) / pitch^2 (1.44 x the disk's).  Axis-aligned: erf product.  Rotated:
  erf along one cell axis (conditional normal), 24-point Gauss-Legendre along the other
  (agrees with the erf product at angle -> 0 to 1e-8, sim/tests/test_sensor.py); cells
  beyond 8 sigma are left at 0.

Coupling model (the default physics; ``channel.py`` applies it):

    amplitude at the ADC of row r's tone on column c (LSB)
        = TONE_LSB * (baseline[r, c] + contact_map[r, c]) * attenuation[r, c]

* ``TONE_LSB = 320``: a fully covered cell puts a 320-LSB tone into the 12-bit ADC
  (half scale 2048).  A default 8 mm finger centred on a cell couples 1.0 of its own row
  and 0.244 of each neighbouring row into the centre column (0.008 on the diagonals).
  Measured noiseless ADC peaks (30 x 40 sensor, DDS phases: every tone starts at phase
  0, so the baseline comb peaks at 270 LSB): one finger 710 LSB (35 % of full scale), two
  fingers on one column 1106 LSB, three 1573 LSB; with the default 30 dB SNR noise
  (sigma = 118 LSB) none of them clips in 200 frames.  Headroom is kept on purpose:
  fingers sharing a column is ordinary use, not a hard case.
* Hard cases: "all rows touched on one column" is 30 x 320 LSB of tone amplitude on one
  ADC and a palm (~40 mm) couples ~8 rows fully: both drive the ADC far into clipping
  (strength can be raised further per contact).
* ``BASELINE = 1/32`` coupling (16 LSB per tone): the untouched mutual coupling, what
  field flattening removes.  Optional per-row/column attenuation (``attenuation``) models
  resistive electrodes: rows are driven from the x = 0 side, columns are read at the
  y = 0 side.
"""
from __future__ import annotations

import math

import numpy as np

from .params import SensorConfig

TONE_LSB = 320.0          # ADC tone amplitude (LSB) of a unit-coupling cell
BASELINE = 1.0 / 32.0     # untouched mutual coupling (coupling units)
FRINGE_NR = 24            # minimum radial Gauss-Legendre points of the fringe quadrature
FRINGE_PER_SIGMA = 6.0    # radial points per (semi-axis / fringe sigma)
FRINGE_MAX = 160          # cap of the radial points (angular points = 2 x radial)
FWHM_TO_SIGMA = 1.0 / (2.0 * math.sqrt(2.0 * math.log(2.0)))

PROFILES = ("disk", "gaussian")


# ---- contacts -------------------------------------------------------------------
def as_contacts(contacts) -> np.ndarray:
    """Normalise contacts to a float64 (K, 6) array (x, y, a, strength, b, angle) where
    a, b are the semi-axes in mm (a = b for round contacts)."""
    if isinstance(contacts, (list, tuple)) and contacts and \
            len({len(r) if hasattr(r, "__len__") else 0 for r in contacts}) > 1:
        # mixed round (4) and elliptical (6) rows: pad the round ones
        contacts = [tuple(r) + (r[2], 0.0) if len(r) == 4 else tuple(r) for r in contacts]
    c = np.asarray(contacts, dtype=np.float64)
    if c.size == 0:
        return np.zeros((0, 6))
    if c.ndim == 1:
        c = c[None, :]
    if c.shape[1] not in (4, 6):
        raise ValueError("contacts must be rows of (x, y, diameter, strength) or "
                         "(x, y, major_diameter, strength, minor_diameter, angle)")
    out = np.zeros((c.shape[0], 6))
    out[:, 0:2] = c[:, 0:2]
    out[:, 2] = c[:, 2] / 2.0
    out[:, 3] = c[:, 3]
    if c.shape[1] == 6:
        out[:, 4] = c[:, 4] / 2.0
        out[:, 5] = c[:, 5]
    else:
        out[:, 4] = out[:, 2]
    if np.any(out[:, 2] <= 0) or np.any(out[:, 4] <= 0):
        raise ValueError("contact diameters must be > 0")
    return out


def _cell_edges(cfg: SensorConfig):
    p = cfg.pitch_mm
    x0 = (np.arange(cfg.cols) - 0.5) * p
    y0 = (np.arange(cfg.rows) - 0.5) * p
    return x0, x0 + p, y0, y0 + p


# ---- exact area: unit circle ∩ convex polygon -----------------------------------
def _circle_polygon_area(px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """Signed area of (unit circle at the origin) ∩ polygon, vertices along the last axis
    (counter-clockwise gives a positive area).  Exact closed form, vectorized.

    For each edge P->Q the signed area of circle ∩ triangle(O, P, Q) is: the part of the
    segment inside the circle (parameters t1..t2 of |P + t(Q-P)| = 1, clipped to [0, 1])
    contributes the triangle cross(A, B)/2, the parts outside contribute circular sectors
    angle(P, A)/2 and angle(B, Q)/2 (unit radius).
    """
    qx = np.roll(px, -1, axis=-1)
    qy = np.roll(py, -1, axis=-1)
    dx, dy = qx - px, qy - py
    a = dx * dx + dy * dy
    b = 2.0 * (px * dx + py * dy)
    c = px * px + py * py - 1.0
    disc = b * b - 4.0 * a * c
    hit = (disc > 0) & (a > 0)
    sq = np.sqrt(np.where(hit, disc, 0.0))
    a_safe = np.where(a > 0, a, 1.0)
    t1 = np.clip((-b - sq) / (2.0 * a_safe), 0.0, 1.0)
    t2 = np.clip((-b + sq) / (2.0 * a_safe), 0.0, 1.0)
    t1 = np.where(hit, t1, 1.0)
    t2 = np.where(hit, t2, 1.0)
    ax, ay = px + t1 * dx, py + t1 * dy
    bx, by = px + t2 * dx, py + t2 * dy

    def sector(ux, uy, vx, vy):
        return 0.5 * np.arctan2(ux * vy - uy * vx, ux * vx + uy * vy)

    area = sector(px, py, ax, ay) + 0.5 * (ax * by - ay * bx) + sector(bx, by, qx, qy)
    return area.sum(axis=-1)


def _to_unit(ct: np.ndarray, x, y):
    """Map points (x, y) (broadcast against contacts on axis 0) into the unit-circle
    frame of each contact's ellipse."""
    cx, cy, a, _, b, th = (ct[:, i] for i in range(6))
    sh = (-1,) + (1,) * (np.ndim(x) - 1)
    cx, cy, a, b = cx.reshape(sh), cy.reshape(sh), a.reshape(sh), b.reshape(sh)
    cs, sn = np.cos(th).reshape(sh), np.sin(th).reshape(sh)
    ux, uy = x - cx, y - cy
    return (cs * ux + sn * uy) / a, (-sn * ux + cs * uy) / b


def _disk_maps(cfg: SensorConfig, ct: np.ndarray) -> np.ndarray:
    """Exact touched areas.  Only the cells of each contact's bounding box are evaluated
    (a box of the largest contact's size, positioned per contact; cells outside the
    ellipse's bounding circle are exactly 0)."""
    p = cfg.pitch_mm
    k = ct.shape[0]
    rad = np.maximum(ct[:, 2], ct[:, 4])
    c_lo = np.clip(np.floor((ct[:, 0] - rad) / p + 0.5).astype(np.int64), 0, cfg.cols - 1)
    c_hi = np.clip(np.floor((ct[:, 0] + rad) / p + 0.5).astype(np.int64), 0, cfg.cols - 1)
    r_lo = np.clip(np.floor((ct[:, 1] - rad) / p + 0.5).astype(np.int64), 0, cfg.rows - 1)
    r_hi = np.clip(np.floor((ct[:, 1] + rad) / p + 0.5).astype(np.int64), 0, cfg.rows - 1)
    sc = int((c_hi - c_lo).max()) + 1
    sr = int((r_hi - r_lo).max()) + 1
    ci = c_lo[:, None] + np.arange(sc)[None, :]            # (K, sc) column indices
    ri = r_lo[:, None] + np.arange(sr)[None, :]            # (K, sr)
    ok = (ci[:, None, :] < cfg.cols) & (ri[:, :, None] < cfg.rows)   # (K, sr, sc)
    x0 = ((ci - 0.5) * p)[:, None, :, None]
    x1 = x0 + p
    y0 = ((ri - 0.5) * p)[:, :, None, None]
    y1 = y0 + p
    shp = (k, sr, sc, 1)
    X = np.concatenate([np.broadcast_to(v, shp) for v in (x0, x1, x1, x0)], axis=-1)
    Y = np.concatenate([np.broadcast_to(v, shp) for v in (y0, y0, y1, y1)], axis=-1)
    ux, uy = _to_unit(ct, X, Y)
    area = np.abs(_circle_polygon_area(ux, uy)) * (ct[:, 2] * ct[:, 4])[:, None, None]
    out = np.zeros((k, cfg.rows, cfg.cols))
    kk = np.broadcast_to(np.arange(k)[:, None, None], ok.shape)
    rr = np.broadcast_to(ri[:, :, None], ok.shape)
    cc = np.broadcast_to(ci[:, None, :], ok.shape)
    out[kk[ok], rr[ok], cc[ok]] = area[ok]
    return out / p ** 2


try:                                   # scipy is optional (not in requirements.txt)
    from scipy.special import erf as _scipy_erf  # type: ignore
except Exception:                      # pragma: no cover - depends on the environment
    _scipy_erf = None
_ERF = np.frompyfunc(math.erf, 1, 1)


def erf(x) -> np.ndarray:
    """Vectorized error function (double precision: math.erf, or scipy when present)."""
    x = np.asarray(x, dtype=np.float64)
    if _scipy_erf is not None:
        return _scipy_erf(x)
    return np.asarray(_ERF(x), dtype=np.float64)


def _interval_prob(lo, hi, mu, sigma):
    s = math.sqrt(2.0) * sigma
    return 0.5 * (erf((hi - mu) / s) - erf((lo - mu) / s))


def _fringe_maps(cfg: SensorConfig, ct: np.ndarray, fringe_mm: float) -> np.ndarray:
    x0, x1, y0, y1 = _cell_edges(cfg)
    # polar Gauss-Legendre rule on the unit disk: r in [0, 1] with weight r dr, theta uniform
    out = np.zeros((ct.shape[0], cfg.rows, cfg.cols))
    for k in range(ct.shape[0]):
        cx, cy, a, _, b, ang = ct[k]
        # the integrand varies on the scale of the fringe: points ~ semi-axis / sigma
        nr = int(min(FRINGE_MAX, max(FRINGE_NR, math.ceil(FRINGE_PER_SIGMA * max(a, b) / fringe_mm))))
        nt = 2 * nr
        g, w = np.polynomial.legendre.leggauss(nr)
        r = 0.5 * (g + 1.0)
        wr = 0.5 * w * r
        th = 2.0 * np.pi * (np.arange(nt) + 0.5) / nt
        ux = (r[:, None] * np.cos(th)[None, :]).ravel()
        uy = (r[:, None] * np.sin(th)[None, :]).ravel()
        wq = (wr[:, None] * np.full(nt, 2.0 * np.pi / nt)[None, :]).ravel()
        cs, sn = math.cos(ang), math.sin(ang)
        px = cx + cs * a * ux - sn * b * uy        # quadrature points in mm
        py = cy + sn * a * ux + cs * b * uy
        jac = a * b                                # area element of the affine map
        # only cells within max(a, b) + 8 sigma of the centre receive anything (< 1e-15)
        reach = max(a, b) + 8.0 * fringe_mm
        cs_ = (x1 > cx - reach) & (x0 < cx + reach)
        rs_ = (y1 > cy - reach) & (y0 < cy + reach)
        if not cs_.any() or not rs_.any():
            continue
        Px = _interval_prob(x0[None, cs_], x1[None, cs_], px[:, None], fringe_mm)  # (Q, C')
        Py = _interval_prob(y0[None, rs_], y1[None, rs_], py[:, None], fringe_mm)  # (Q, R')
        out[k][np.ix_(rs_, cs_)] = np.einsum("q,qr,qc->rc", wq * jac, Py, Px)
    return out / cfg.pitch_mm ** 2


_GL24 = np.polynomial.legendre.leggauss(24)


def _gauss_maps(cfg: SensorConfig, ct: np.ndarray) -> np.ndarray:
    x0, x1, y0, y1 = _cell_edges(cfg)
    out = np.zeros((ct.shape[0], cfg.rows, cfg.cols))
    for k in range(ct.shape[0]):
        cx, cy, a, _, b, ang = ct[k]
        sa, sb = 2 * a * FWHM_TO_SIGMA, 2 * b * FWHM_TO_SIGMA   # sigmas along the axes
        # unit-peak density integrates to 2 pi sa sb; a normal pdf integrates to 1
        norm = 2.0 * np.pi * sa * sb
        cs, sn = math.cos(ang), math.sin(ang)
        if abs(sn) < 1e-15 or abs(sa - sb) < 1e-15 * max(sa, sb):
            sx, sy = (sa, sb) if abs(sn) < 1e-15 else (sa, sa)
            Px = _interval_prob(x0, x1, cx, sx)
            Py = _interval_prob(y0, y1, cy, sy)
            out[k] = norm * Py[:, None] * Px[None, :]
            continue
        # covariance of the rotated Gaussian
        cxx = cs * cs * sa * sa + sn * sn * sb * sb
        cyy = sn * sn * sa * sa + cs * cs * sb * sb
        cxy = cs * sn * (sa * sa - sb * sb)
        sx = math.sqrt(cxx)
        sy_c = math.sqrt(cyy - cxy * cxy / cxx)     # std of y given x
        g, w = _GL24
        # cells beyond 8 sigma (density < 1e-14) are left at 0
        reach = 8.0 * max(sa, sb)
        cs_ = (x1 > cx - reach) & (x0 < cx + reach)
        rs_ = (y1 > cy - reach) & (y0 < cy + reach)
        if not cs_.any() or not rs_.any():
            continue
        # x integral over each column by Gauss-Legendre, y analytic (conditional normal)
        xs = (0.5 * (x0[cs_, None] + x1[cs_, None]) + 0.5 * cfg.pitch_mm * g[None, :])  # (C', 24)
        wx = 0.5 * cfg.pitch_mm * w
        fx = np.exp(-0.5 * ((xs - cx) / sx) ** 2) / (math.sqrt(2 * np.pi) * sx)    # (C', 24)
        mu_y = cy + cxy / cxx * (xs - cx)                                          # (C', 24)
        Py = _interval_prob(y0[rs_, None, None], y1[rs_, None, None], mu_y[None], sy_c)
        out[k][np.ix_(rs_, cs_)] = norm * np.einsum("rcq,cq,q->rc", Py, fx, wx)
    return out / cfg.pitch_mm ** 2


def contact_maps(cfg: SensorConfig, contacts, profile: str = "disk",
                 fringe_mm: float = 0.0) -> np.ndarray:
    """Per-contact coupling maps, shape (K, rows, cols), including each contact's
    strength.  See the module docstring for the profiles and their normalisation."""
    ct = as_contacts(contacts)
    if ct.shape[0] == 0:
        return np.zeros((0, cfg.rows, cfg.cols))
    if profile == "disk":
        m = _fringe_maps(cfg, ct, fringe_mm) if fringe_mm > 0 else _disk_maps(cfg, ct)
    elif profile == "gaussian":
        m = _gauss_maps(cfg, ct)
    else:
        raise ValueError(f"unknown contact profile '{profile}' (known: {PROFILES})")
    return m * ct[:, 3][:, None, None]


def contact_map(cfg: SensorConfig, contacts, profile: str = "disk",
                fringe_mm: float = 0.0) -> np.ndarray:
    """Coupling of each row/column intersection, (rows, cols) float64: the sum over the
    contacts of ``contact_maps`` (1.0 = a cell fully covered by a strength-1 contact)."""
    return contact_maps(cfg, contacts, profile, fringe_mm).sum(axis=0)


# ---- untouched coupling and attenuation -----------------------------------------
def attenuation(cfg: SensorConfig, row_db_per_cell: float = 0.0,
                col_db_per_cell: float = 0.0) -> np.ndarray:
    """Amplitude factor (rows, cols) of resistive electrodes: a row's tone is driven at
    the x = 0 end and loses ``row_db_per_cell`` dB per cell along x; a column is read at
    its y = 0 end and loses ``col_db_per_cell`` dB per cell along y."""
    c = np.arange(cfg.cols)[None, :]
    r = np.arange(cfg.rows)[:, None]
    return 10.0 ** (-(row_db_per_cell * c + col_db_per_cell * r) / 20.0)


def baseline(cfg: SensorConfig, level: float = BASELINE, row_db_per_cell: float = 0.0,
             col_db_per_cell: float = 0.0) -> np.ndarray:
    """Untouched mutual coupling per intersection (coupling units), attenuation included."""
    return level * attenuation(cfg, row_db_per_cell, col_db_per_cell)


def coupling(cfg: SensorConfig, contacts=(), profile: str = "disk", fringe_mm: float = 0.0,
             level: float = BASELINE, row_db_per_cell: float = 0.0,
             col_db_per_cell: float = 0.0) -> np.ndarray:
    """Total coupling (rows, cols) = (baseline + contact_map) * attenuation; multiply by
    ``TONE_LSB`` for the tone amplitude at the ADC in LSB."""
    att = attenuation(cfg, row_db_per_cell, col_db_per_cell)
    return (level + contact_map(cfg, contacts, profile, fringe_mm)) * att
