"""Fine touches: Von Neumann and Moore paraboloid fits, ellipse, bias correction.

Twin of ``rtl/fmt_interp.v``.  ``interp_float`` is the accuracy reference (float
arithmetic, the same decision rules); ``interp_fixed`` is bit-exact with the RTL.

Input: a candidate (``row``, ``col``, ``z3`` (3x3 ints, ``z3[dy+1][dx+1]``, 0 outside
the sensor) and ``missing`` (9-bit mask, bit k = (dy+1)*3 + (dx+1))), as made by
``fmt.localmax``.

Fits (paper Eq. 3-7), in integers (z = z3, x = dx = column offset, y = dy = row offset):

* Von Neumann, per axis: num = z[0][+1] - z[0][-1], den = 2 (2 z00 - z[0][+1] - z[0][-1]),
  offset = num / den (= -D / 2A).
* Moore least squares (Eq. 6 scaled): with column sums cs(dx) and row sums rs(dy),
  a = cs(-1) + cs(+1) - 2 cs(0)  (A = a/6),   c = rs(-1) + rs(+1) - 2 rs(0)  (C = c/6),
  b = z[+1][+1] + z[-1][-1] - z[-1][+1] - z[+1][-1]  (B = b/4),
  d = cs(+1) - cs(-1)  (D = d/6),   e = rs(+1) - rs(-1)  (E = e/6),
  f = 20 z00 + 8 (edge cells) - 4 (corner cells)  (F = f/36).
  x_f = (BE - 2CD)/(4AC - B^2) = (6be - 8cd) / dm,  y_f = (6bd - 8ae) / dm,
  dm = 16ac - 9b^2  (= 144 (4AC - B^2)).

Decision rules (identical in float, fixed and RTL):

* edge = any neighbour missing (flag bit 2).  Moore fit only when no neighbour is
  missing; an axis with both neighbours present gets its Von Neumann fit; an axis with
  ONE neighbour missing gets the one-sided estimate: q = floor(z_nb * 512 / z00) (the
  same divider; ratio of the present neighbour to the centre), offset = EDGE[q >> 1]
  (255 when q overflows, ratio >= 1) towards the present neighbour, from a 256-entry
  table made from the 8 mm disk profile (a contact whose ratio is below that of a
  centred contact -- i.e. one sitting towards the sensor's border -- reads 0, the cell
  centre: a contact within ~1.2 mm of the edge lights one cell only and no fit can
  recover its position).  The bias setting does not apply to it.  z00 = 0 -> offset 0
  and flag bit 0.  Both neighbours missing (a 1-wide sensor) -> 0.
* Moore mode: the Moore fit is used iff a < 0 and dm > 0 (both eigenvalues of M
  negative: a true maximum); otherwise (plateau, saddle, ridge) each axis falls back to
  its Von Neumann fit and flag bit 0 is set.  Flag bit 3 = Moore fit used.
* Von Neumann axis: valid iff den > 0; otherwise offset 0 and flag bit 0.
* Offset magnitude: q = floor(|num| * 512 / den) (9-bit restoring divider,
  overflow when q >= 512), r = (q + 1) >> 1 (round half up, 8 fractional bits),
  then sign(num) * r.  |offset| > 0.5 cell (q >= 257 or overflow) is clamped to
  +-128 (0.5 cell) and sets flag bit 0 (i.e. |offset| >= 257/512 cell; the float model
  uses the same threshold, so both take the same decisions).  For a true local maximum the Von Neumann
  offset is always within +-0.5, so clamping only happens on tilted Moore fits or
  non-maxima.
* Bias correction (optional): |offset| -> LUT[fit][|offset|] (129 entries, Q8 in and
  out, sign restored), fit = 1 for the Moore fit, 0 for Von Neumann.  The table is the
  inverse of the mean fitted-offset curve of an 8 mm disk contact (paper Eq. 2 profile,
  ``fmt.sensor``) on the 5 mm pitch; it is shown on a Gaussian profile too
  (``scripts/interp_accuracy.py``).  ROM ``rtl/fmt_interp_bias.hex`` (1024 x 8 bit,
  address {kind[1:0], index[7:0]}: kind 0 Von Neumann bias, 1 Moore bias (entries
  129..255 repeat entry 128, never addressed), 2 the edge table, 3 unused zeros).
* Position: x = col * 256 + offset, clamped to [0, (COLS-1) * 256] (likewise y):
  16-bit unsigned, cells, 8 fractional bits, from the centre of cell (0, 0).
* Strength: the candidate's centre cell z00 (the peak cell value).
* Flag bit 1: a present cell in the 3x3 equals 2^HM_W - 1 (saturated).

Ellipse (Moore fit used only; otherwise axes = angle = 0).  The coefficients are first
normalised to ~ZN = 10 bits: sh = max(0, bitlen(OR of the 9 cells) - 10), an = a >>> sh
(floor), likewise bn, cn, dn, en, fn.  Then
  dm = 16 an cn - 9 bn^2,  qn = 2 cn dn^2 - 3 bn dn en + 2 an en^2,
  G = fn dm - 12 qn  (F_v = G / (36 dm), the peak height at the vertex),
  p = -2 (an + cn),  s = |(2 (an - cn), 3 bn)|  (eigenvalues lambda = -(p -+ s)/24),
  semi-axis^2 = F_v / (2 |lambda|):  major^2 = G (p + s) / (3 dm^2),
                                     minor^2 = G / (3 dm (p + s)),
  angle = 1/2 atan2(3 bn, 2 (an - cn)) = 1/2 atan2(B, A - C).
  Defined iff dm > 0 and G > 0 (else axes = angle = 0).
* s and the angle: vectoring CORDIC on (u, v) = (2(an - cn), 3 bn) << 4 guard bits,
  pre-rotation by pi when u < 0, 12 iterations (truncating arithmetic shifts), angle
  accumulator in units of 2 pi / 65536 (table ``CORDIC_ATAN``); angle out =
  ((z + 128) >> 8) & 255 (unit pi/256 of the half angle, 0..255 = 0..pi).
  pp = p * KQ + (u_N << 8), KQ = round(K_12 * 4096)  (pp ~ (p + s) K 4096).
* Logarithms: lg(x) = (bitlen(x) - 1) * 4096 + LOG_ROM[8 mantissa bits after the
  leading one] (LOG_ROM = round(4096 log2(1 + (i + 0.5)/256)), 12 fractional bits).
  L_maj = lg G + lg pp - 2 lg dm - LC_MAJ,  L_min = lg G - lg dm - lg pp + LC_MIN
  (log2 of the squared semi-axis, 12 fractional bits), t = (L >>> 1) + 8 * 4096,
  k = t >>> 12, j = (t >> 4) & 255, axis = round(EXP_ROM[j] * 2^(k - 15)) (round half up;
  EXP_ROM = round(32768 * 2^((j + 0.5)/256))), 0 for k < 0, saturated to 0xFFFF:
  Q8.8 cells.

Error bound fixed vs float (derived, checked in ``sim/tests/test_interp.py``):
position: 1/2 LSB (1/512 cell) of rounding, +1/512 from the truncating divider =
<= 1/256 cell before the bias table; the table is piecewise constant on a 1/256 grid and
its slope is <= ~1.6, so <= 2.5/256 cell after it.  Axes: each lg is within
0.5/256 * log2(e) = 0.0028 of log2 (+ 1/8192 rounding), 4 lg terms + exp -> log2 error
<= 0.0075 -> 0.52 %; the 10-bit normalisation (each coefficient truncated by < 1 LSB
of ~2^10) and the CORDIC (12 iterations: |s| to ~2^-11) add ~1-2 % for well
conditioned fits; bound used: 3 % + 2/256 cell.  Angle: CORDIC residual atan(2^-11)
plus the output quantisation (1/2 LSB = pi/512) -> <= 1.5 LSB (pi/256 units) where the
normalised coefficients are large; looser when |A - C| and B are a few LSB only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

FRAC = 8                     # fractional bits of positions and axes
DIV_QW = 9                   # quotient bits of the offset divider (q = |num| * 512 / den)
ZN = 10                      # normalised width of the ellipse coefficients' source cells
CORDIC_N = 12                # CORDIC iterations
CORDIC_GB = 4                # CORDIC guard bits
LF = 12                      # fractional bits of the logarithms
LOG_IDX = 8                  # mantissa bits addressing the log ROM
EXP_IDX = 8                  # fractional bits addressing the exp ROM
BIAS_N = 129                 # bias table entries (|offset| 0..128)
CLAMP_AT = 257 / 512         # |offset| >= this is clamped to 0.5 cell (flag bit 0)

RTL = Path(__file__).resolve().parents[2] / "rtl"
BIAS_HEX = RTL / "fmt_interp_bias.hex"
LOG_HEX = RTL / "fmt_interp_log.hex"
EXP_HEX = RTL / "fmt_interp_exp.hex"

FLAG_FALLBACK = 1
FLAG_SAT = 2
FLAG_EDGE = 4
FLAG_MOORE = 8

# ---- constants shared with the RTL ---------------------------------------------------
CORDIC_ATAN = [int(round(math.atan(2.0 ** -i) / (2 * math.pi) * 65536)) for i in range(CORDIC_N)]
CORDIC_K = float(np.prod([math.sqrt(1 + 2.0 ** (-2 * i)) for i in range(CORDIC_N)]))
KQ = int(round(CORDIC_K * 4096))
LOG_ROM = [int(round((1 << LF) * math.log2(1 + (i + 0.5) / (1 << LOG_IDX)))) for i in range(1 << LOG_IDX)]
EXP_ROM = [int(round(32768 * 2 ** ((j + 0.5) / (1 << EXP_IDX)))) for j in range(1 << EXP_IDX)]
# lg(pp) = lg((p + s) K 4096): constants of the squared semi-axes (see module docstring)
LC_MAJ = int(round((1 << LF) * math.log2(3 * CORDIC_K * 4096)))
LC_MIN = int(round((1 << LF) * math.log2(CORDIC_K * 4096 / 3)))


@dataclass
class TouchPoint:
    """One fine touch.  Fixed: ints (x, y, axes Q8.8; angle 0..255 in pi/256).  Float:
    x, y, axes in cells, angle in rad [0, pi)."""
    frame: int
    x: float
    y: float
    strength: int
    axis_major: float
    axis_minor: float
    angle: float
    flags: int

    def as_tuple(self):
        return (self.x, self.y, self.strength, self.axis_major, self.axis_minor, self.angle, self.flags)


# ---- candidate access --------------------------------------------------------------
def _cand_parts(cand):
    z = np.asarray(cand.z3).reshape(3, 3)
    if z.dtype.kind not in "iu":
        z = z.astype(np.float64)              # float maps: accuracy reference only
    m = cand.missing
    if not isinstance(m, (int, np.integer)):
        mm = np.asarray(m, dtype=bool).reshape(3, 3)
        m = int(sum(1 << k for k in range(9) if mm.flat[k]))
    miss = np.array([(int(m) >> k) & 1 for k in range(9)], dtype=bool).reshape(3, 3)
    z = np.where(miss, 0, z)
    conv = int if z.dtype.kind in "iu" else float
    return int(cand.row), int(cand.col), [[conv(v) for v in r] for r in z], miss


def coeffs(z):
    """Integer Moore coefficients (a, b, c, d, e, f) of a 3x3 list z[dy+1][dx+1]."""
    cs = [z[0][i] + z[1][i] + z[2][i] for i in range(3)]
    rs = [sum(z[i]) for i in range(3)]
    a = cs[0] + cs[2] - 2 * cs[1]
    c = rs[0] + rs[2] - 2 * rs[1]
    b = z[2][2] + z[0][0] - z[0][2] - z[2][0]
    d = cs[2] - cs[0]
    e = rs[2] - rs[0]
    f = 20 * z[1][1] + 8 * (z[0][1] + z[1][0] + z[1][2] + z[2][1]) - 4 * (z[0][0] + z[0][2] + z[2][0] + z[2][2])
    return a, b, c, d, e, f


def moore_lstsq_coeffs(z):
    """Float (A, B, C, D, E, F) of Eq. 5 from Eq. 6 (for tests against lstsq)."""
    a, b, c, d, e, f = coeffs(z)
    return a / 6, b / 4, c / 6, d / 6, e / 6, f / 36


def _axis_terms(z, miss):
    """(num, den, lo missing, hi missing, lo value, hi value) of the Von Neumann fits,
    x then y."""
    nvx = z[1][2] - z[1][0]
    dvx = 2 * (2 * z[1][1] - z[1][2] - z[1][0])
    nvy = z[2][1] - z[0][1]
    dvy = 2 * (2 * z[1][1] - z[2][1] - z[0][1])
    return ((nvx, dvx, bool(miss[1][0]), bool(miss[1][2]), z[1][0], z[1][2]),
            (nvy, dvy, bool(miss[0][1]), bool(miss[2][1]), z[0][1], z[2][1]))


def _select(z, miss, moore):
    """Per-axis (num, den, kind) with kind 'moore', 'vn', 'edge' or 'zero', plus flags.
    'edge': one neighbour missing: num = +-(present neighbour) (sign = its side),
    den = z00 (the one-sided ratio estimate)."""
    a, b, c, d, e, f = coeffs(z)
    edge = bool(miss.any())
    fb = False
    dm = 16 * a * c - 9 * b * b
    moore_ok = moore and not edge and a < 0 and dm > 0
    if moore and not edge and not moore_ok:
        fb = True
    out = []
    if moore_ok:
        out = [(6 * b * e - 8 * c * d, dm, "moore"), (6 * b * d - 8 * a * e, dm, "moore")]
    else:
        for num, den, mlo, mhi, zlo, zhi in _axis_terms(z, miss):
            if mlo and mhi:
                out.append((0, 1, "zero"))
            elif mlo or mhi:
                if z[1][1] > 0:
                    out.append((zhi if mlo else -zlo, z[1][1], "edge"))
                else:
                    fb = True
                    out.append((0, 1, "zero"))
            elif den > 0:
                out.append((num, den, "vn"))
            else:
                fb = True
                out.append((0, 1, "zero"))
    return out, moore_ok, fb, edge, (a, b, c, d, e, f)


# ---- bias table ------------------------------------------------------------------------
_BIAS_CACHE = {}


def bias_curves(profile: str = "disk", diameter_mm: float = 8.0, n_t: int = 257, n_s: int = 9):
    """Mean fitted |offset| (float fits) against the true offset t in [0, 0.5] cell, for
    the Von Neumann and the Moore fit: returns (t, u_vn, u_moore).  Mean over the other
    axis' offset in [-0.5, 0.5]; both axes (x sweep and y sweep) pooled."""
    from . import params, sensor
    cfg = params.MEDIUM
    p = cfg.pitch_mm
    r0, c0 = cfg.rows // 2, cfg.cols // 2
    t = np.linspace(0.0, 0.5, n_t)
    s = np.linspace(-0.5, 0.5, n_s)
    T, S = np.meshgrid(t, s, indexing="ij")
    us = {"vn": np.zeros(n_t), "moore": np.zeros(n_t)}
    for axis in (0, 1):
        dx, dy = (T, S) if axis == 0 else (S, T)
        ct = np.stack([(c0 + dx.ravel()) * p, (r0 + dy.ravel()) * p,
                       np.full(dx.size, diameter_mm), np.ones(dx.size)], axis=1)
        maps = sensor.contact_maps(cfg, ct, profile=profile)
        z3 = maps[:, r0 - 1:r0 + 2, c0 - 1:c0 + 2]
        for kind in ("vn", "moore"):
            u = _float_offsets_batch(z3, kind)[:, axis]
            us[kind] += np.abs(u).reshape(n_t, n_s).mean(axis=1) / 2
    return t, us["vn"], us["moore"]


def _float_offsets_batch(z3, kind):
    """Unclamped float fit offsets (K, 2) of a batch of 3x3 maps (no fallbacks)."""
    z = z3
    if kind == "vn":
        ox = (z[:, 1, 2] - z[:, 1, 0]) / (2 * (2 * z[:, 1, 1] - z[:, 1, 2] - z[:, 1, 0]))
        oy = (z[:, 2, 1] - z[:, 0, 1]) / (2 * (2 * z[:, 1, 1] - z[:, 2, 1] - z[:, 0, 1]))
        return np.stack([ox, oy], axis=1)
    cs = z.sum(axis=1)
    rs = z.sum(axis=2)
    a = cs[:, 0] + cs[:, 2] - 2 * cs[:, 1]
    c = rs[:, 0] + rs[:, 2] - 2 * rs[:, 1]
    b = z[:, 2, 2] + z[:, 0, 0] - z[:, 0, 2] - z[:, 2, 0]
    d = cs[:, 2] - cs[:, 0]
    e = rs[:, 2] - rs[:, 0]
    dm = 16 * a * c - 9 * b * b
    return np.stack([(6 * b * e - 8 * c * d) / dm, (6 * b * d - 8 * a * e) / dm], axis=1)


def bias_table(profile: str = "disk", diameter_mm: float = 8.0):
    """(2, 129) int table: row 0 Von Neumann, row 1 Moore; entry i = round(256 t) where
    the mean fitted offset of a contact at true offset t is i/256 (monotone inverse,
    clamped to 0..128, entry 0 = 0; a curve that passes 0.5 is cut there)."""
    key = (profile, diameter_mm)
    if key not in _BIAS_CACHE:
        t, uv, um = bias_curves(profile, diameter_mm)
        tab = np.zeros((2, BIAS_N), dtype=np.int64)
        for k, u in enumerate((uv, um)):
            u = np.maximum.accumulate(u)          # monotone (it is, up to rounding)
            n = int(np.searchsorted(u, 0.5))      # first point with mean |u| >= 0.5
            if n < len(u):                        # cut the curve where it reaches 0.5
                t_end = float(np.interp(0.5, u[n - 1:n + 1], t[n - 1:n + 1]))
                uu, tt = np.append(u[:n], 0.5), np.append(t[:n], t_end)
            else:
                uu, tt = u, t
            q = np.arange(BIAS_N) / 256.0
            tab[k] = np.clip(np.round(np.interp(q, uu, tt) * 256), 0, 128).astype(np.int64)
            tab[k, 0] = 0
        _BIAS_CACHE[key] = tab
    return _BIAS_CACHE[key]


def edge_curve(profile: str = "disk", diameter_mm: float = 8.0, n_t: int = 257, n_s: int = 9):
    """Mean ratio r = z(neighbour) / z(centre) against the true offset t in [0, 0.5] cell
    towards that neighbour (mean over the other axis' offset in [-0.5, 0.5])."""
    from . import params, sensor
    cfg = params.MEDIUM
    p = cfg.pitch_mm
    r0, c0 = cfg.rows // 2, cfg.cols // 2
    t = np.linspace(0.0, 0.5, n_t)
    sv = np.linspace(-0.5, 0.5, n_s)
    T, S = np.meshgrid(t, sv, indexing="ij")
    ct = np.stack([(c0 + T.ravel()) * p, (r0 + S.ravel()) * p,
                   np.full(T.size, diameter_mm), np.ones(T.size)], axis=1)
    maps = sensor.contact_maps(cfg, ct, profile=profile)
    r = (maps[:, r0, c0 + 1] / maps[:, r0, c0]).reshape(n_t, n_s).mean(axis=1)
    return t, r


def edge_table(profile: str = "disk", diameter_mm: float = 8.0):
    """(256,) int table of the one-sided edge estimate: entry i = round(256 t) where the
    mean ratio neighbour / centre of a contact at offset t towards the neighbour is
    (i + 0.5) / 256; 0 below the ratio of a centred contact, 128 at ratio 1."""
    key = ("edge", profile, diameter_mm)
    if key not in _BIAS_CACHE:
        t, r = edge_curve(profile, diameter_mm)
        r = np.maximum.accumulate(r)
        q = (np.arange(256) + 0.5) / 256.0
        _BIAS_CACHE[key] = np.clip(np.round(np.interp(q, r, t, left=0.0, right=0.5) * 256),
                                   0, 128).astype(np.int64)
    return _BIAS_CACHE[key]


def render_bias_hex(tab=None, etab=None) -> str:
    """1024 x 8 bit: rows {fit}: 0 Von Neumann bias, 1 Moore bias (129 entries, padded with
    entry 128), 2 the edge table (256 entries), 3 zeros (unused)."""
    tab = bias_table() if tab is None else tab
    etab = edge_table() if etab is None else etab
    words = []
    for k in range(2):
        row = list(tab[k]) + [int(tab[k][-1])] * (256 - BIAS_N)
        words += [f"{int(v):02x}" for v in row]
    words += [f"{int(v):02x}" for v in etab]
    words += ["00"] * 256
    return "\n".join(words) + "\n"


def render_log_hex() -> str:
    return "\n".join(f"{v:03x}" for v in LOG_ROM) + "\n"


def render_exp_hex() -> str:
    return "\n".join(f"{v:04x}" for v in EXP_ROM) + "\n"


# ---- fixed point ------------------------------------------------------------------------
def div_fixed(num: int, den: int, qw: int = DIV_QW):
    """The RTL divider fmt_div: (floor(num / den), overflow = num >= den << qw); the
    quotient is the low qw bits of the restoring division when there is no overflow."""
    if num >= (den << qw):
        return (1 << qw) - 1, True
    return num // den, False


def offset_fixed(num: int, den: int):
    """Signed Q8 offset and clamp flag (see module docstring)."""
    m = abs(num)
    q, ovf = div_fixed(m << 9, den)
    if ovf or q >= 257:
        r, clamp = 128, True
    else:
        r, clamp = (q + 1) >> 1, False
    return (-r if num < 0 else r), clamp


def edge_offset_fixed(num: int, den: int, etab=None) -> int:
    """One-sided edge estimate: q = floor(|num| * 512 / den) (the same divider),
    index = q >> 1 (255 on overflow, i.e. ratio >= 1), offset = +-EDGE[index]."""
    etab = edge_table() if etab is None else etab
    q, ovf = div_fixed(abs(num) << 9, den)
    r = int(etab[255 if ovf else q >> 1])
    return -r if num < 0 else r


def lg_fixed(x: int) -> int:
    """log2(x) with LF fractional bits via the log ROM (x > 0)."""
    n = x.bit_length() - 1
    i = (x >> (n - LOG_IDX)) if n >= LOG_IDX else (x << (LOG_IDX - n))
    return n * (1 << LF) + LOG_ROM[i & ((1 << LOG_IDX) - 1)]


def exp_axis_fixed(L: int) -> int:
    """Semi-axis Q8.8 from L = log2(axis^2) with LF fractional bits."""
    t = (L >> 1) + (FRAC << LF)
    k = t >> LF
    j = (t >> (LF - EXP_IDX)) & ((1 << EXP_IDX) - 1)
    m = EXP_ROM[j]
    if k < 0:
        return 0
    if k >= 15:
        v = m << (k - 15)
    else:
        v = (m + (1 << (14 - k))) >> (15 - k)
    return min(v, 0xFFFF)


def cordic_fixed(u: int, v: int):
    """Vectoring CORDIC: (u_N ~ K |(u, v)|, z angle in 2 pi / 65536 units, 16 bit)."""
    zacc = 0
    if u < 0:
        u, v, zacc = -u, -v, 32768
    for i in range(CORDIC_N):
        if v >= 0:
            u, v, zacc = u + (v >> i), v - (u >> i), zacc + CORDIC_ATAN[i]
        else:
            u, v, zacc = u - (v >> i), v + (u >> i), zacc - CORDIC_ATAN[i]
    return u, zacc & 0xFFFF


def ellipse_fixed(z, co):
    """(major Q8.8, minor Q8.8, angle 0..255, defined) of a Moore fit."""
    orv = 0
    for r in z:
        for v in r:
            orv |= v
    sh = max(0, orv.bit_length() - ZN)
    an, bn, cn, dn, en, fn = (v >> sh for v in co)
    dm = 16 * an * cn - 9 * bn * bn
    qn = 2 * cn * dn * dn - 3 * bn * dn * en + 2 * an * en * en
    G = fn * dm - 12 * qn
    p = -2 * (an + cn)
    uN, zang = cordic_fixed((2 * (an - cn)) << CORDIC_GB, (3 * bn) << CORDIC_GB)
    pp = p * KQ + (uN << (12 - CORDIC_GB))
    if not (dm > 0 and G > 0 and pp > 0):
        return 0, 0, 0, False
    lG, ldm, lpp = lg_fixed(G), lg_fixed(dm), lg_fixed(pp)
    maj = exp_axis_fixed(lG + lpp - 2 * ldm - LC_MAJ)
    mnr = exp_axis_fixed(lG - ldm - lpp + LC_MIN)
    ang = ((zang + 128) >> 8) & 255
    return maj, mnr, ang, True


def interp_fixed(cand, cfg, moore: bool = True, bias: bool = True, frame: int = 0,
                 table=None) -> TouchPoint:
    """Bit-exact twin of fmt_interp for one candidate."""
    row, col, z, miss = _cand_parts(cand)
    tab = bias_table() if table is None else table
    sel, moore_ok, fb, edge, co = _select(z, miss, moore)
    offs = []
    for num, den, kind in sel:
        if kind == "edge":
            offs.append(edge_offset_fixed(num, den))
            continue
        o, clamp = offset_fixed(num, den)
        fb = fb or clamp
        if bias:
            o = (-1 if o < 0 else 1) * int(tab[1 if kind == "moore" else 0][abs(o)])
        offs.append(o)
    q = 1 << FRAC
    x = min(max(col * q + offs[0], 0), (cfg.cols - 1) * q)
    y = min(max(row * q + offs[1], 0), (cfg.rows - 1) * q)
    full = (1 << cfg.hm_width) - 1
    sat = any(z[i][j] == full and not miss[i][j] for i in range(3) for j in range(3))
    maj = mnr = ang = 0
    if moore_ok:
        maj, mnr, ang, _ = ellipse_fixed(z, co)
    flags = (FLAG_FALLBACK if fb else 0) | (FLAG_SAT if sat else 0) | (FLAG_EDGE if edge else 0) \
        | (FLAG_MOORE if moore_ok else 0)
    return TouchPoint(frame, x, y, z[1][1], maj, mnr, ang, flags)


# ---- floating point (accuracy reference) ------------------------------------------------
def _bias_float(o: float, kind: str, tab) -> float:
    """Bias correction in float: linear interpolation of the same table."""
    if kind == "zero":
        return o
    row = tab[1 if kind == "moore" else 0] / 256.0
    return math.copysign(float(np.interp(abs(o) * 256.0, np.arange(BIAS_N), row)), o)


def ellipse_float(co):
    """(major, minor semi-axes in cells, angle rad in [0, pi), defined) from the exact
    coefficients (half-height contour of the fitted paraboloid)."""
    A, B, C, D, E, F = (co[0] / 6, co[1] / 4, co[2] / 6, co[3] / 6, co[4] / 6, co[5] / 36)
    M = np.array([[A, B / 2], [B / 2, C]])
    g = np.array([D, E])
    det = A * C - B * B / 4
    if not (A < 0 and det > 0):
        return 0.0, 0.0, 0.0, False
    Fv = F - 0.25 * g @ np.linalg.solve(M, g)
    lam = np.linalg.eigvalsh(M)           # ascending: lam[0] most negative (minor axis)
    if Fv <= 0:
        return 0.0, 0.0, 0.0, False
    minor = math.sqrt(-Fv / (2 * lam[0]))
    major = math.sqrt(-Fv / (2 * lam[1]))
    ang = (0.5 * math.atan2(B, A - C)) % math.pi
    return major, minor, ang, True


def interp_float(cand, cfg, moore: bool = True, bias: bool = True, frame: int = 0,
                 table=None, clamp_xy: bool = True) -> TouchPoint:
    """Float reference: the same rules, exact arithmetic; x, y, axes in cells."""
    row, col, z, miss = _cand_parts(cand)
    tab = bias_table() if table is None else table
    sel, moore_ok, fb, edge, co = _select(z, miss, moore)
    offs = []
    for num, den, kind in sel:
        if kind == "edge":
            r = abs(num) / den * 256 - 0.5
            o = float(np.interp(r, np.arange(256), edge_table())) / 256
            offs.append(-o if num < 0 else o)
            continue
        o = num / den
        if abs(o) >= CLAMP_AT:
            o, fb = math.copysign(0.5, o), True
        if bias:
            o = _bias_float(o, kind, tab)
        offs.append(o)
    x, y = col + offs[0], row + offs[1]
    if clamp_xy:
        x = min(max(x, 0.0), cfg.cols - 1.0)
        y = min(max(y, 0.0), cfg.rows - 1.0)
    full = (1 << cfg.hm_width) - 1
    sat = any(z[i][j] == full and not miss[i][j] for i in range(3) for j in range(3))
    maj = mnr = ang = 0.0
    if moore_ok:
        maj, mnr, ang, _ = ellipse_float(co)
    flags = (FLAG_FALLBACK if fb else 0) | (FLAG_SAT if sat else 0) | (FLAG_EDGE if edge else 0) \
        | (FLAG_MOORE if moore_ok else 0)
    return TouchPoint(frame, x, y, z[1][1], maj, mnr, ang, flags)


def interp_frame_fixed(cands, cfg, moore=True, bias=True, frame=0):
    """Fixed touches of one frame's candidates (same order)."""
    return [interp_fixed(c, cfg, moore, bias, frame) for c in cands]


def interp_frame_float(cands, cfg, moore=True, bias=True, frame=0):
    return [interp_float(c, cfg, moore, bias, frame) for c in cands]
