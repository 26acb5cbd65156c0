"""Fixed-point receive back end: the bit-exact twin of ``fmt_pair_split``,
``fmt_magnitude``, ``fmt_accum``, ``fmt_col_pair_rx`` and ``fmt_rx_array``, plus the
floating-point receiver it is measured against.

Chain per column pair (columns 2p, 2p+1; COLS must be even):
  despread  x = adc * (+1/-1 from rx_sign)                   (ADC_BITS + 1 bits)
  FFT       Z = fft_fixed(x_a + j x_b) per window of N samples, Z = X * 2^-SHIFT, OUT_W bits
  split     2A[k] = Z[k] + conj(Z[N-k]),  2B[k] = (Z[k] - conj(Z[N-k])) / j   (exact, OUT_W+1)
  magnitude CORDIC vectoring, ITER = 12, GUARD = 3, gain compensated; fmt_rx_array keeps
            MAG_FRAC = 2 fractional bits (truncated: floor), the reference fmt_col_pair_rx
            none (round half up to an integer)
  accum     sum over M windows (any M = 1..M_MAX; fmt_accum: M = 2^m), D = M * 2^s,
            s = HM_SHIFT + the magnitude's fractional bits, cell = floor((sum +
            floor(D/2)) / D) (round half up), saturated to HM_W bits (sticky flag); for
            M = 2^m exactly (sum + 2^(s'-1)) >> s', s' = m + s.  fmt_rx_array divides by
            an exact reciprocal multiply (recip_divide, below).
With HM_SHIFT = 1 a cell is |A[k]| * 2^-SHIFT (FFT output LSBs), averaged over M.

Rounding (fmt_rx_array): everything is exact except (1) the FFT's own rounding
(``fft_fixed``), (2) the CORDIC (arithmetic right shifts = floor inside the iterations,
the gain-compensated result truncated to MAG_FRAC fractional bits) and (3) the cell's
one round half up of sum / 2M.  The truncation's mean, -2^-(MAG_FRAC+2) cell LSB, and the
half-up rounding's, +2^-(MAG_FRAC+2) / M, cancel at M = 1.  (The reference pair receiver
rounds the magnitude to an integer and then the cell: two roundings, a +0.2 LSB mean
offset against a float receiver; ``test_rx_fixed_vs_float`` measures both.)  Integer
arithmetic is numpy int64 throughout.

Floating-point receiver (``receive``, the chain's float path): despread, FFT per window, comb bins, magnitude, accumulation.

Per column c and window w (samples wN .. wN+N-1 from sample 0):

    y[n]      = adc[n, c] * (+1/-1 from rx_sign[n])                (despread)
    X_w[k]    = sum_j y[wN + j] exp(-2 pi i k j / N)               (numpy rfft)
    cell[r,c] = hm_scale * |X_w[k_r]|, k_r = cfg.bins[r]
    heat map  = mean of the cells over the M windows of a frame    (frames, rows, cols)

Scale (``hm_scale``): 4/N * 2**(HM_W - ADC_BITS): a tone of amplitude A LSB at the ADC
reads A * 2**(HM_W - ADC_BITS + 1) counts (32 A for 16-bit cells and a 12-bit ADC), so a
full-scale ADC tone (2048 LSB) just reaches the 16-bit limit.  This is the scale of the
fixed-point receive chain (``rx_heatmaps_fixed`` above: FFT growth schedule, pair
split, CORDIC, accumulator), so float and fixed heat maps, and the touch thresholds, mean
the same counts (sim/tests/test_rx_array_float.py compares the two: ratio 1 within 0.5 %).  With
the sensor's TONE_LSB = 320 a unit-coupling cell (a fully covered cell) reads
``unit_cell_counts(cfg)`` = 10240 counts, the baseline 320.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import params as _params
from . import sensor as _sensor
from .params import SensorConfig

MAG_ITER = 12        # CORDIC iterations (fmt_magnitude ITER)
MAG_GUARD = 3        # CORDIC guard bits (fmt_magnitude GUARD)
MAG_GAIN_BITS = 20   # fractional bits of the gain-compensation constant
M_LOG2_MAX = 3       # fmt_accum / fmt_col_pair_rx M_LOG2_MAX: M in 1, 2, 4, 8
M_MAX = 255          # fmt_rx_array / fmt_core M_MAX: M = 1 .. 255 (the 8-bit WINDOWS_M)
RECIP_TR = 40        # precision of the reciprocal ROM rtl/fmt_recip.hex (see recip_rom)
RECIP_HEX = "fmt_recip.hex"
HM_SHIFT = 1         # fmt_accum HM_SHIFT: undo the factor 2 of the pair split
MAG_FRAC = 2         # fmt_rx_array MAG_FRAC: fractional bits the magnitudes keep (floor)


def cordic_gain(iters: int = MAG_ITER) -> float:
    """CORDIC vectoring gain K = prod sqrt(1 + 2^-2i), i = 0..iters-1."""
    return float(np.prod([math.sqrt(1.0 + 2.0 ** (-2 * i)) for i in range(iters)]))


def cordic_gain_const(iters: int = MAG_ITER, gain_bits: int = MAG_GAIN_BITS) -> int:
    """fmt_magnitude GAIN_C = round(2^gain_bits / K)."""
    return int(round(2 ** gain_bits / cordic_gain(iters)))


# ---- magnitude -----------------------------------------------------------------------
def magnitude_float(re, im) -> np.ndarray:
    return np.hypot(np.asarray(re, dtype=float), np.asarray(im, dtype=float))


def magnitude_fixed(re, im, iters: int = MAG_ITER, guard: int = MAG_GUARD,
                    gain_bits: int = MAG_GAIN_BITS, frac: int = 0) -> np.ndarray:
    """Bit-exact twin of fmt_magnitude (any input width: the RTL sizes itself).

    frac = 0: |z| rounded half up to an integer; frac > 0 (FRAC): |z| * 2^frac truncated
    (floor), the fraction left for the one rounding downstream."""
    if not 0 <= frac < gain_bits + guard:
        raise ValueError(f"magnitude frac {frac} outside 0 .. {gain_bits + guard - 1}")
    x = np.abs(np.asarray(re, dtype=np.int64)) << guard
    y = np.asarray(im, dtype=np.int64) << guard
    for i in range(iters):
        neg = y < 0
        dx = y >> i
        dy = x >> i
        x, y = np.where(neg, x - dx, x + dx), np.where(neg, y + dy, y - dy)
    gc = cordic_gain_const(iters, gain_bits)
    sh = gain_bits + guard - frac
    return (x * gc + ((1 << (sh - 1)) if frac == 0 else 0)) >> sh


# ---- pair split ----------------------------------------------------------------------
def comb_bins(cfg) -> np.ndarray:
    return np.asarray(cfg.bins, dtype=np.int64)


def pair_split_fixed(z_re, z_im, cfg):
    """(2A, 2B) per comb bin from natural-order FFT bins z (..., N): exact integers.

    Returns a_re, a_im, b_re, b_im of shape (..., rows)."""
    z_re = np.asarray(z_re, dtype=np.int64)
    z_im = np.asarray(z_im, dtype=np.int64)
    k = comb_bins(cfg)
    m = cfg.n_fft - k
    a_re = z_re[..., k] + z_re[..., m]
    a_im = z_im[..., k] - z_im[..., m]
    b_re = z_im[..., k] + z_im[..., m]
    b_im = z_re[..., m] - z_re[..., k]
    return a_re, a_im, b_re, b_im


def pair_split_float(z):
    """A, B spectra (complex, natural order, full length) of z = a + j b."""
    z = np.asarray(z, dtype=complex)
    n = z.shape[-1]
    zm = np.conj(z[..., (-np.arange(n)) % n])
    return (z + zm) / 2, (z - zm) / 2j


def bitrev(i: int, bits: int) -> int:
    return int(f"{i:0{bits}b}"[::-1], 2) if bits else 0


def completion_slots(cfg) -> np.ndarray:
    """Bit-reversed output slot at which row r's pair (k, N-k) is complete."""
    b = cfg.log2_n
    return np.array([max(bitrev(k, b), bitrev(cfg.n_fft - k, b)) for k in cfg.bins])


def row_order(cfg) -> np.ndarray:
    """Rows in the order the heat-map stream emits them (order of completion)."""
    return np.argsort(completion_slots(cfg), kind="stable")


# ---- accumulation --------------------------------------------------------------------
def _windows(m_log2, m):
    """M from either the old m_log2 keyword or M itself (m wins when given)."""
    if m is None:
        return 1 << int(m_log2)
    m = int(m)
    if m < 1:
        raise ValueError(f"M = {m}: at least one window per frame")
    return m


def accum_fixed(mags, m_log2: int = 0, hm_w: int = 16, hm_shift: int = HM_SHIFT, m=None):
    """mags (windows, ...) unsigned ints -> (cells (frames, ...), saturated flag).

    M = m windows per frame (or 2^m_log2 when m is None; a sequence: M of each frame in
    turn, as when WINDOWS_M is written during a run).  Frames are consecutive groups
    of M windows from window 0; a trailing partial frame is dropped (the RTL never emits
    it).  cell = floor((sum + floor(D/2)) / D), D = M * 2^hm_shift (round half up; for
    M = 2^m bit-identical with (sum + 2^(s-1)) >> s, s = m + hm_shift), then min(cell,
    2^hm_w - 1) with the flag set when that clips.  fmt_rx_array computes the same
    quotient by recip_divide (proved and tested equal)."""
    mags = np.asarray(mags, dtype=np.int64)
    if m is not None and not np.isscalar(m):
        # one M per frame (WINDOWS_M changed during a run): frames of m[0], m[1], ...
        # windows from window 0; frames beyond the windows given are dropped
        cells, sat, w0 = [], False, 0
        for mf in m:
            mf = _windows(0, mf)
            if w0 + mf > mags.shape[0]:
                break
            c, s_ = accum_fixed(mags[w0:w0 + mf], hm_w=hm_w, hm_shift=hm_shift, m=mf)
            cells.append(c[0])
            sat, w0 = sat or s_, w0 + mf
        return np.array(cells, dtype=np.int64).reshape((len(cells),) + mags.shape[1:]), sat
    mm = _windows(m_log2, m)
    frames = mags.shape[0] // mm
    s = mags[:frames * mm].reshape((frames, mm) + mags.shape[1:]).sum(axis=1)
    d = mm << hm_shift
    cell = (s + (d >> 1)) // d
    top = (1 << hm_w) - 1
    sat = bool((cell > top).any())
    return np.minimum(cell, top), sat


def ceil_log2(m: int) -> int:
    """l = ceil(log2 m), m >= 1 (fmt_rx_array: the reciprocal's shift)."""
    return (int(m) - 1).bit_length()


def recip(m: int, t_bits: int) -> int:
    """R = ceil(2^(T + l) / m), l = ceil(log2 m): for every integer 0 <= t < 2^T,
    floor(t R / 2^(T + l)) = floor(t / m) (Granlund-Montgomery): with e = R m - 2^(T+l),
    0 <= e < m <= 2^l, t R / 2^(T+l) = t/m + t e / (m 2^(T+l)) and t e < 2^T 2^l, so the
    error term is < 1/m, too small to reach the next multiple of 1/m above t/m.
    2^T <= R <= 2^(T+1) (T + 1 bits)."""
    l = ceil_log2(m)
    return ((1 << (t_bits + l)) + m - 1) // m


@functools.lru_cache(maxsize=None)
def recip_rom(m_max: int = 255, tr: int = RECIP_TR) -> tuple:
    """Contents of rtl/fmt_recip.hex: entry m = recip(m, tr) for m = 1 .. 255 (entry 0 =
    entry 1: M = 0 is taken as 1).  The RTL derives its T-bit reciprocal as
    ceil(entry / 2^(tr - T)) = recip(m, T) (ceil(ceil(x) / n) = ceil(x / n) for integer
    n), so one file serves every width T <= tr."""
    return tuple(recip(max(1, m), tr) for m in range(m_max + 1))


RTL = Path(__file__).resolve().parents[2] / "rtl"


def render_recip_hex() -> str:
    digits = (RECIP_TR + 1 + 3) // 4
    return "".join(f"{v:0{digits}x}\n" for v in recip_rom())


def recip_from_rom(m: int, t_bits: int, tr: int = RECIP_TR) -> int:
    """The RTL's T-bit reciprocal from the ROM entry: (entry + 2^(tr-T) - 1) >> (tr - T)."""
    e = recip_rom()[m]
    return (e + (1 << (tr - t_bits)) - 1) >> (tr - t_bits)


def recip_divide(t, m: int, t_bits: int):
    """fmt_rx_array's divider: floor(t / m) = (t * R) >> (T + l) for 0 <= t < 2^T."""
    t = np.asarray(t, dtype=object)
    r = recip_from_rom(m, t_bits)
    return (t * r) >> (t_bits + ceil_log2(m))


def rx_sum_width(cfg, m_max: int = M_MAX, mag_frac: int = MAG_FRAC) -> int:
    """SUM_W of fmt_rx_array: magnitude width MW + MAG_FRAC + width of M, exact for M_MAX
    windows."""
    return (fft_out_w(cfg) + 1) + mag_frac + int(m_max).bit_length()


def rx_div_t_bits(cfg, m_max: int = M_MAX, mag_frac: int = MAG_FRAC) -> int:
    """T of fmt_rx_array's divider: SUM_W + 1 (the sum plus the rounding half M 2^MAG_FRAC)."""
    return rx_sum_width(cfg, m_max, mag_frac) + 1


# ---- the whole receive path ----------------------------------------------------------
@dataclass(frozen=True)
class RxFlags:
    fft_ovf: bool
    sat: bool

    @property
    def any(self) -> bool:
        return self.fft_ovf or self.sat


def despread_fixed(adc, rx_sign) -> np.ndarray:
    """adc (samples, cols) x (+1/-1): rx_sign 1 = invert.  ADC_BITS + 1 bits."""
    adc = np.asarray(adc, dtype=np.int64)
    s = 1 - 2 * np.asarray(rx_sign, dtype=np.int64)
    return adc * s[:, None]


def fft_shift(cfg) -> int:
    """S of fmt_col_pair_rx: the FFT output is X * 2^-S, S = max(0, ADC_BITS + LOG2_N - 2
    - HM_W), so that a full-scale tone's |X| = 2^(ADC_BITS + LOG2_N - 2) maps to 2^HM_W."""
    return max(0, cfg.adc_bits + cfg.log2_n - 2 - cfg.hm_width)


def fft_out_w(cfg) -> int:
    """FFT_OUT_W of fmt_col_pair_rx (integer bins, S bits rounded off)."""
    return cfg.adc_bits + cfg.log2_n + 2 - fft_shift(cfg)


def fft_windows_fixed(x_re, x_im, cfg, fft_kw=None):
    """Natural-order fixed-point FFT (fmt_fft_r22sdf twin) of (windows, N) int arrays at
    the receiver's output width -> (re, im, ovf)."""
    from . import fft_r22sdf as f     # twin of fmt_fft_r22sdf
    kw = {"out_w": fft_out_w(cfg)}
    kw.update(fft_kw or {})
    return f.fft_fixed(x_re, x_im, cfg.log2_n, cfg.adc_bits + 1, **kw)


def rx_heatmaps_fixed(adc, rx_sign, cfg, m_log2: int = 0, hm_shift: int = HM_SHIFT,
                      fft_kw=None, fft_fn=None, m=None, mag_frac: int = MAG_FRAC):
    """Bit-exact twin of fmt_rx_array.

    adc (samples, cols) int (ADC_BITS two's complement values), rx_sign (samples,) 0/1
    (the receive PN sign of each sample, as fmt_pn_gen rx_sign_o).  Windows start at
    sample 0 (the first ce after reset); only complete frames of M windows are returned
    (M = m, any 1 .. M_MAX, or 2^m_log2 when m is None).  Returns (heatmaps (frames, rows, cols) int64, row_order (rows,), RxFlags).
    ``fft_fn(x_re, x_im) -> (Z_re, Z_im, ovf)`` on (windows, N) arrays replaces the
    default fft_fixed (tests of the blocks without the FFT).  ``mag_frac``: the
    magnitudes' fractional bits (MAG_FRAC of fmt_rx_array; 0 = the reference
    fmt_col_pair_rx, which rounds the magnitude to an integer).
    """
    adc = np.asarray(adc, dtype=np.int64)
    n, cols = cfg.n_fft, adc.shape[1]
    if cols % 2:
        raise ValueError("COLS must be even (columns are received in pairs)")
    x = despread_fixed(adc, rx_sign)
    wins = x.shape[0] // n
    x = x[:wins * n].reshape(wins, n, cols)
    mags = np.zeros((wins, cfg.rows, cols), dtype=np.int64)
    ovf = False
    for p in range(cols // 2):
        xr, xi = x[:, :, 2 * p], x[:, :, 2 * p + 1]
        if fft_fn is None:
            zr, zi, o = fft_windows_fixed(xr, xi, cfg, fft_kw)
        else:
            zr, zi, o = fft_fn(xr, xi)
        ovf = ovf or bool(o)
        a_re, a_im, b_re, b_im = pair_split_fixed(zr, zi, cfg)
        mags[:, :, 2 * p] = magnitude_fixed(a_re, a_im, frac=mag_frac)
        mags[:, :, 2 * p + 1] = magnitude_fixed(b_re, b_im, frac=mag_frac)
    hm, sat = accum_fixed(mags, m_log2, cfg.hm_width, hm_shift + mag_frac, m=m)
    return hm, row_order(cfg), RxFlags(fft_ovf=ovf, sat=sat)


def rx_heatmaps_float(adc, rx_sign, cfg, m_log2: int = 0, shift: float | None = None, m=None):
    """Floating-point receiver of the same despread samples: numpy FFT per real column,
    exact magnitude at the comb bins, mean over M windows, in the fixed path's units
    (|X[k]| * 2^-S, S = fft_shift(cfg) unless given)."""
    if shift is None:
        shift = fft_shift(cfg)
    x = despread_fixed(adc, rx_sign).astype(float)
    n = cfg.n_fft
    wins = x.shape[0] // n
    x = x[:wins * n].reshape(wins, n, -1)
    X = np.fft.fft(x, axis=1)[:, comb_bins(cfg), :]          # (wins, rows, cols)
    mag = np.abs(X) * 2.0 ** (-shift)
    mm = _windows(m_log2, m)
    frames = wins // mm
    return mag[:frames * mm].reshape(frames, mm, cfg.rows, -1).mean(axis=1)


def get_cfg(name: str):
    return _params.get(name)


# ---- timing of fmt_rx_array's shared magnitude units (no arithmetic) -----------------
RX_SHARE_BACK = MAG_ITER + 12  # steps from a row's last unit input to its beat, minus P:
#                                P unit input steps, the cell multiplexer register,
#                                MAG_ITER + 3 magnitude stages +
#                                accumulator read and its output register, sum, rounding
#                                add, reciprocal partial products, their middle sum, the
#                                full product, shift + saturate, row register
RX_RES_RD = 2  # FFT_CH > 1: the result memories are block RAM (read latch + output
#                register) between the engine's row / group and the cell multiplexer
#                (FFT_CH = 1: LUT RAM read at once, 0)


def rx_share_schedule(cfg, units: int, step_per_slot: int):
    """Twin of fmt_rx_array's row queue and engine over one window (engine idle at the
    start).  Row r's split output is registered at step a_r = step_per_slot * slot_r (+ a
    constant common to all rows, left out), it is queued at a_r + 1 and loaded at
    L_r = max(a_r + 2, previous load + P).  Returns (P, dict row -> (a_r, L_r),
    keeps_up, no_long_wait): keeps_up = the engine can load the next window's first row
    on time (the elaboration check of the RTL), no_long_wait = also no row waits more than
    P steps (the rule of the default MAG_UNITS)."""
    slots = completion_slots(cfg)
    p = -(-cfg.cols // units)
    f, sched, wait_ok = 0, {}, True
    order = row_order(cfg)
    for r in order:
        a = int(slots[r]) * step_per_slot
        lo = max(a + 2, f)
        wait_ok = wait_ok and (lo - (a + 2) <= p)
        f = lo + p
        sched[int(r)] = (a, lo)
    keeps = f <= (int(slots[order[0]]) + cfg.n_fft) * step_per_slot + 1
    return p, sched, keeps, keeps and wait_ok


def rx_mag_units_default(cfg, step_per_slot: int) -> int:
    """fmt_rx_array's default MAG_UNITS: K = ceil(COLS / (4 C)), C = steps per FFT slot
    (a row in at most 4 C steps: the comb's rows complete at most two in any 8
    consecutive slots; tests check the resulting schedule with rx_share_schedule)."""
    return max(1, -(-cfg.cols // (4 * step_per_slot)))


def rx_mag_units_min(cfg, step_per_slot: int) -> int:
    """The smallest K whose schedule has no row waiting longer than P steps (for
    comparison with the default rule)."""
    for k in range(1, cfg.cols + 1):
        if rx_share_schedule(cfg, k, step_per_slot)[3]:
            return k
    return cfg.cols


def max_completions_in(cfg, slots: int = 8) -> int:
    """Most rows completing in any ``slots`` consecutive FFT slots."""
    s = np.sort(completion_slots(cfg))
    return int(max(np.searchsorted(s, v + slots) - i for i, v in enumerate(s)))


def rx_fft_ch_default(post_clk: int = 1, cps=None) -> int:
    """fmt_rx_array's default FFT_CH: column pairs per time-multiplexed FFT engine,
    CLK_PER_SAMPLE when POST_CLK = 1, else 1 (one engine per pair)."""
    if cps is None:
        cps = 3 if post_clk else 1
    return cps if post_clk else 1


SPLIT_LAT = 2   # fmt_pair_split: steps from a pair's second bin to its output register
#                 (decode register, held memory + sums); its steps are clk cycles when the
#                 split runs on every clk (POST_CLK = 1, FFT_CH > 1), else ce cycles
SPLIT_LAT_BRAM = 4   # the same with its held memory in block RAM (CH >= 3, HELD_BRAM):
#                 decode register, read latch, block-RAM output register, sums


def split_lat(fft_ch: int) -> int:
    """fmt_pair_split's latency in steps for the channels of one engine (FFT_CH = 1:
    fmt_rx_pair_front's split, CH = 1)."""
    return SPLIT_LAT_BRAM if fft_ch >= 3 else SPLIT_LAT


def rx_split_clk(latency0: int, slot: int, every: int, fft_ch: int, ch: int,
                 post_clk: int = 1) -> int:
    """clk cycle (from the ce edge that takes a window's last ADC sample, that edge = 0)
    at whose end the pair split registers its output for slot ``slot`` of pair ``ch`` of
    an engine.  The split takes the FFT output slot (its decode register) on the clk
    edge below, then SPLIT_LAT - 1 split steps later its output register.
    fft_ch = 1 (fmt_rx_pair_front): the despread register, then LATENCY0 + slot ce
    cycles: (latency0 + 1 + slot) * every.  fft_ch = G > 1 (fmt_rx_group_front): channel
    c enters on the clk c + 1 after the ce edge (step j G + c for sample j); slot s leaves
    the FFT on step t_c + latency0 + s G; step j G + q runs on clk j every + 1 + q (the
    engine steps on the G clk cycles after each ce, ce every ``every`` >= G clk)."""
    extra = (split_lat(fft_ch) - 1) * (1 if post_clk else every)
    if fft_ch <= 1:
        return (latency0 + 1 + slot) * every + extra
    if every < fft_ch:
        raise ValueError(f"ce every {every} clk is too fast for {fft_ch} pairs per FFT engine")
    d = ch + latency0 + slot * fft_ch          # steps after the last sample's channel-0 step
    return (d // fft_ch) * every + 1 + d % fft_ch + extra


def rx_row_beats(cfg, latency0: int, every: int = 1, post_clk: int = 1, cps=None,
                 units=None, fft_ch=None):
    """clk cycles from the ce edge that takes a window's last ADC sample to each row's
    heat-map beat (M = 1), dict row -> clk.  every = clk per ce in the run; cps =
    fmt_rx_array CLK_PER_SAMPLE (default: 3 if post_clk else 1); units = MAG_UNITS
    (default: the rule); fft_ch = FFT_CH (default rx_fft_ch_default: the row is queued
    when the engine's last pair, channel FFT_CH - 1, has it).  latency0 =
    fft_fixed.latency0 of the receiver's FFT."""
    if cps is None:
        cps = 3 if post_clk else 1
    if fft_ch is None:
        fft_ch = rx_fft_ch_default(post_clk, cps)
    steps_cfg = cps if post_clk else 1        # what the RTL sizes K for
    if units is None:
        units = rx_mag_units_default(cfg, steps_cfg)
    steps_run = every if post_clk else 1       # steps per FFT slot in this run
    step_clk = 1 if post_clk else every        # clk per step
    p, sched, keeps, _ = rx_share_schedule(cfg, units, steps_run)
    if not keeps:
        raise ValueError(f"{units} magnitude units do not keep up at {steps_run} steps per slot")
    # split of slot 0 (the queue push), clk; the schedule counts from there
    base = rx_split_clk(latency0, 0, every, fft_ch, fft_ch - 1, post_clk)
    back = RX_SHARE_BACK + (RX_RES_RD if fft_ch > 1 else 0)
    return {r: base + (lo + p + back) * step_clk for r, (a, lo) in sched.items()}


# ---- floating-point receiver (the chain's float path, fmt.chain) -------------------
def hm_scale(cfg: SensorConfig) -> float:
    """Heat-map counts per unit of |X[k]| (see the module docstring)."""
    return 4.0 / cfg.n_fft * 2.0 ** (cfg.hm_width - cfg.adc_bits)


def unit_cell_counts(cfg: SensorConfig) -> float:
    """Heat-map value of a unit-coupling cell (noiseless, no attenuation)."""
    return _sensor.TONE_LSB * 2.0 ** (cfg.hm_width - cfg.adc_bits + 1)


def despread_float(adc, rx_sign=None, dtype=np.float64) -> np.ndarray:
    """adc (samples, cols) times +1/-1 (rx_sign 1 = invert; None = PN off)."""
    x = np.asarray(adc).astype(dtype)
    if rx_sign is not None:
        x *= (1.0 - 2.0 * np.asarray(rx_sign, dtype=dtype))[:, None]
    return x


def window_spectra(x: np.ndarray, cfg: SensorConfig) -> np.ndarray:
    """Comb-bin DFT values (windows, rows, cols) complex of despread samples (samples, cols);
    a trailing partial window is dropped."""
    n = cfg.n_fft
    wins = x.shape[0] // n
    xw = x[:wins * n].reshape(wins, n, x.shape[1])
    X = np.fft.rfft(xw, axis=1)
    return X[:, np.asarray(cfg.bins), :]


def window_cells(adc, cfg: SensorConfig, rx_sign=None, scale: float | None = None) -> np.ndarray:
    """Per-window cells (windows, rows, cols) float: scale * |X_w[k_r]|."""
    s = hm_scale(cfg) if scale is None else scale
    return s * np.abs(window_spectra(despread_float(adc, rx_sign), cfg))


def accum_float(cells: np.ndarray, m: int) -> np.ndarray:
    """Mean over consecutive groups of m windows -> (frames, rows, cols); a trailing
    partial frame is dropped."""
    frames = cells.shape[0] // m
    return cells[:frames * m].reshape((frames, m) + cells.shape[1:]).mean(axis=1)


def receive(adc, cfg: SensorConfig, rx_sign=None, m: int = 1,
            scale: float | None = None) -> np.ndarray:
    """Heat maps (frames, rows, cols) float64 of an ADC stream starting at a window
    boundary (see the module docstring)."""
    return accum_float(window_cells(adc, cfg, rx_sign, scale), m)
