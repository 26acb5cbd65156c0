"""Streaming radix-2^2 SDF FFT: the bit-exact twin of ``rtl/fmt_fft_r22sdf.v``.

Algorithm (decimation in frequency, He & Torkelson radix-2^2).  A window of N = 2^L
complex samples flows through L single-path delay-feedback butterfly stages; stage s
has a delay line of D = N / 2^(s+1) samples.  Stages come in pairs working on blocks of
M = N / 4^p samples (p = 0, 1, ...):

  BF2I   (delay M/2)  a = x[n], b = x[n + M/2]:  first half a + b, second half a - b
  BF2II  (delay M/4)  a = y[n], b = y[n + M/4] inside each half; in the second half
                      (the differences) b is first multiplied by -j (swap, negate):
                      first quarter a + b, second quarter a - b
  twiddle             element i of the M-block (quarter q = i div M/4, n = i mod M/4)
                      is multiplied by W_M^(r(q) n), r = (0, 2, 1, 3), W_M = e^(-j 2 pi / M)
                      (skipped when M = 4: all twiddles are 1)

and a last plain radix-2 stage (delay 1) when L is odd.  The output leaves in
bit-reversed order: slot s carries bin bitrev_L(s).

Fixed point (every butterfly grows one bit, so butterflies are exact):
  * input IN_W bits; after stage s the width is IN_W + s + 1 (+ 1 + FRAC_W after the
    first twiddle multiplier).
  * twiddles: TW_W-bit signed, scale 2^(TW_W - 2) (so +1 and -1 are exact), each
    component round(v * 2^(TW_W-2)) with ties away from zero (never a tie in practice).
  * twiddle multiplier: four products, each truncated (floor) by t = k - GUARD bits,
    re = a c - b s, im = a s + b c from the truncated products, then round half up:
    (v + 2^(GUARD-1)) >> GUARD; overall the round-half-up of the exact value / 2^k up to
    +-2^-GUARD LSB.  The FIRST twiddle multiplier keeps FRAC_W more fractional bits
    (k = TW_W - 2 - FRAC_W) and one guard bit; later ones keep the width (k = TW_W - 2).
    The result keeps its low bits (no saturation logic: it cannot overflow) and the
    sticky flag records any element that did not fit.
  * The output is the last stage's full-width value, X * 2^FRAC_W when the last
    twiddle stage had FRAC_W fraction bits, optionally rounded (half up) to OUT_W bits
    and saturated.  SHIFT = full_width - OUT_W - FRAC_W, out = X * 2^-SHIFT.

Why it cannot overflow: after m radix-2 stages an element is a sum of 2^m input
samples times unit-magnitude factors, so |value| <= 2^m sqrt(2) 2^(IN_W-1).  Before the
first twiddle only +-1 and +-j factors occur and the component bound is exactly
2^m 2^(IN_W-1), which IN_W + m bits hold after the one-bit-per-stage growth (each stage
adds a bit, the -j swap only moves a component); after the first twiddle the extra guard
bit leaves a margin of 2 / sqrt(2) over the bound, far above the rounding errors and the
twiddle magnitudes (<= 1 + 2^-(TW_W-2)).  The overflow flag is there anyway
(the twiddle multipliers flag a result that does not fit; the optional output
rounding saturates and flags).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

TW_W = 18          # default twiddle width (DSP48E 18-bit port)
FRAC_W = 3         # default extra fractional bits kept from the first twiddle on
GUARD = 3          # product bits kept below the twiddle output's LSB (fmt_fft_twiddle GUARD)
RTL = Path(__file__).resolve().parents[2] / "rtl"

# Register stages of the RTL (must match rtl/fmt_fft_r22sdf.v and its sub-modules).
IN_REGS = 1        # input register of fmt_fft_r22sdf
BF_REGS = 1        # output register of each fmt_fft_bf stage
TW_REGS = 4        # fmt_fft_twiddle: twiddle/data register, products, sum, rounded output


# ---- structure -----------------------------------------------------------------------
def bitrev(v, bits: int):
    """Bit reversal of integer(s) v over ``bits`` bits."""
    v = np.asarray(v, dtype=np.int64)
    r = np.zeros_like(v)
    for b in range(bits):
        r |= ((v >> b) & 1) << (bits - 1 - b)
    return r


def output_slot_order(log2_n: int) -> np.ndarray:
    """bins[s] = natural bin index carried by output slot s (bit reversal)."""
    return bitrev(np.arange(1 << log2_n), log2_n)


def twiddle_blocks(log2_n: int) -> list[int]:
    """Block sizes M of the stage pairs that are followed by a non-trivial twiddle."""
    out = []
    m = 1 << log2_n
    while m >= 8:      # M = 4: all twiddles are 1;  M = 2: last radix-2 stage, none
        out.append(m)
        m //= 4
    return out


def n_twiddle_mults(log2_n: int) -> int:
    return len(twiddle_blocks(log2_n))


def stage_widths(log2_n: int, in_w: int, frac_w: int = FRAC_W) -> list[int]:
    """Output width of every butterfly stage (index s = 0 .. L-1)."""
    w = in_w
    out = []
    for s in range(log2_n):
        w += 1
        out.append(w)
        if s == 1 and twiddle_blocks(log2_n):
            w += 1 + frac_w          # the first twiddle multiplier's guard + fraction bits
    return out


def full_width(log2_n: int, in_w: int, frac_w: int = FRAC_W) -> int:
    """Width of the last stage (= the default OUT_W): IN_W + L (+ 1 + FRAC_W if any twiddle)."""
    return in_w + log2_n + ((1 + frac_w) if twiddle_blocks(log2_n) else 0)


def frac_bits(log2_n: int, frac_w: int = FRAC_W) -> int:
    """Fraction bits of the last stage's value (FRAC_W when there is a twiddle stage)."""
    return frac_w if twiddle_blocks(log2_n) else 0


def out_shift(log2_n: int, in_w: int, out_w: int | None = None, frac_w: int = FRAC_W) -> int:
    """SHIFT of the output: out = X * 2^-SHIFT (negative = fraction bits kept)."""
    fw = full_width(log2_n, in_w, frac_w)
    out_w = fw if out_w is None else out_w
    return (fw - out_w) - frac_bits(log2_n, frac_w)


def latency0(log2_n: int, in_w: int | None = None, out_w: int | None = None,
             frac_w: int = FRAC_W) -> int:
    """ce cycles from a window's last input sample to its slot 0 output.

    The input sample presented on ce cycle t (registered at that cycle's edge) and the
    output carried (out_valid = 1) on ce cycle t + latency0 + s for slot s of the window
    whose last sample is at t.  The delay lines add up to N - 1, which the window's own
    length absorbs, so latency0 is just the number of register stages (one more when
    OUT_W < FULL_W: the output rounding register).
    """
    extra = 0
    if out_w is not None and in_w is not None and out_w < full_width(log2_n, in_w, frac_w):
        extra = 1
    return IN_REGS + BF_REGS * log2_n + TW_REGS * n_twiddle_mults(log2_n) + extra


# ---- twiddles ------------------------------------------------------------------------
def _round_away(v: np.ndarray) -> np.ndarray:
    return np.sign(v) * np.floor(np.abs(v) + 0.5)


def twiddle_exponents(m: int) -> np.ndarray:
    """Exponent e(i) of W_M for element i = 0..M-1 of an M-block (after BF2II)."""
    i = np.arange(m)
    q, n = i // (m // 4), i % (m // 4)
    r = np.array([0, 2, 1, 3])[q]
    return r * n


def twiddle_table(m: int, tw_w: int = TW_W) -> tuple[np.ndarray, np.ndarray]:
    """(cos, -sin) of W_M^e(i), quantized to tw_w bits, scale 2^(tw_w-2)."""
    e = twiddle_exponents(m)
    ang = 2.0 * np.pi * e / m
    sc = float(1 << (tw_w - 2))
    c = _round_away(np.cos(ang) * sc).astype(np.int64)
    s = _round_away(-np.sin(ang) * sc).astype(np.int64)
    return c, s


def twiddle_hex_name(m: int, tw_w: int = TW_W) -> str:
    return f"fmt_fft_tw{m:04d}.hex" if tw_w == TW_W else f"fmt_fft_tw{m:04d}_w{tw_w}.hex"


def twiddle_hex_text(m: int, tw_w: int = TW_W) -> str:
    """One line per element: {cos, -sin} as 2*tw_w bits, cos in the upper half."""
    c, s = twiddle_table(m, tw_w)
    mask = (1 << tw_w) - 1
    nd = (2 * tw_w + 3) // 4
    lines = [f"// fmt_fft_tw{m:04d}: twiddles W_{m}^e(i) of fmt_fft_twiddle, {{cos, -sin}}, "
             f"{tw_w}-bit each, scale 2^{tw_w - 2}.  GENERATED by python -m fmt.generate"]
    for ci, si in zip(c.tolist(), s.tolist()):
        lines.append(f"{(((ci & mask) << tw_w) | (si & mask)):0{nd}x}")
    return "\n".join(lines) + "\n"


ALL_TWIDDLE_BLOCKS = (8, 16, 32, 64, 128, 256, 512, 1024)


# ---- fixed-point arithmetic ----------------------------------------------------------
def _sat(v: np.ndarray, w: int) -> tuple[np.ndarray, bool]:
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    ovf = bool(np.any(v < lo) or np.any(v > hi))
    return np.clip(v, lo, hi), ovf


def _wrap(v: np.ndarray, w: int) -> tuple[np.ndarray, bool]:
    """Two's complement wrap to w bits, and whether anything did not fit."""
    lo, hi = -(1 << (w - 1)), (1 << (w - 1)) - 1
    ovf = bool(np.any(v < lo) or np.any(v > hi))
    return ((v - lo) & ((1 << w) - 1)) + lo, ovf


def _twiddle_mul(re, im, c, s, k: int, w: int, guard: int = GUARD):
    """fmt_fft_twiddle: (a + jb)(c + js) / 2^k, round half up after truncating each
    product by t = k - guard bits (floor); the low w bits are kept (ovf if it did not
    fit: the RTL does not saturate there, the flag says so)."""
    t = max(k - guard, 0)
    g = k - t
    pr = ((re * c) >> t) - ((im * s) >> t)
    pi = ((re * s) >> t) + ((im * c) >> t)
    if g > 0:
        pr = (pr + (1 << (g - 1))) >> g
        pi = (pi + (1 << (g - 1))) >> g
    pr, o1 = _wrap(pr, w)
    pi, o2 = _wrap(pi, w)
    return pr, pi, o1 or o2


def fft_fixed_slots(x_re, x_im, log2_n: int, in_w: int, tw_w: int = TW_W,
                    frac_w: int = FRAC_W, out_w: int | None = None, guard: int = GUARD):
    """As :func:`fft_fixed` but in output-slot (bit-reversed) order."""
    n = 1 << log2_n
    xr = np.asarray(x_re, dtype=np.int64)
    xi = np.asarray(x_im, dtype=np.int64)
    if xr.shape != xi.shape or xr.shape[-1] != n:
        raise ValueError(f"inputs must be (..., {n}) and of equal shape")
    lo, hi = -(1 << (in_w - 1)), (1 << (in_w - 1)) - 1
    if np.any(xr < lo) or np.any(xr > hi) or np.any(xi < lo) or np.any(xi > hi):
        raise ValueError(f"input outside the {in_w}-bit range")
    lead = xr.shape[:-1]
    xr = xr.reshape(-1, n).copy()
    xi = xi.reshape(-1, n).copy()
    ovf = False
    blocks = twiddle_blocks(log2_n)
    w = in_w
    first_tw = True
    for s in range(log2_n):
        d = n >> (s + 1)                      # delay of this stage
        r = xr.reshape(-1, n // (2 * d), 2, d)
        i = xi.reshape(-1, n // (2 * d), 2, d)
        ar, ai, br, bi = r[:, :, 0], i[:, :, 0], r[:, :, 1], i[:, :, 1]
        if s % 2 == 1:
            # BF2II: b times -j in the second half (the differences) of each 4d block;
            # the parity of the 2d-block index says which half
            odd = (np.arange(n // (2 * d)) % 2 == 1)[None, :, None]
            br, bi = np.where(odd, bi, br), np.where(odd, -br, bi)
        sr, si = ar + br, ai + bi
        dr, di = ar - br, ai - bi
        xr = np.stack([sr, dr], axis=2).reshape(-1, n)
        xi = np.stack([si, di], axis=2).reshape(-1, n)
        w += 1
        if s % 2 == 1:
            m = 4 * d
            if m in blocks:
                c, sn = twiddle_table(m, tw_w)
                k = tw_w - 2 - (frac_w if first_tw else 0)
                wo = w + (1 + frac_w if first_tw else 0)
                rr = xr.reshape(-1, n // m, m)
                ii = xi.reshape(-1, n // m, m)
                pr, pi, o = _twiddle_mul(rr, ii, c[None, None, :], sn[None, None, :], k, wo, guard)
                xr, xi = pr.reshape(-1, n), pi.reshape(-1, n)
                ovf = ovf or o
                w = wo
                first_tw = False
    if out_w is not None and out_w != w:
        if out_w > w:
            raise ValueError(f"out_w {out_w} > full width {w}")
        k = w - out_w
        xr = (xr + (1 << (k - 1))) >> k
        xi = (xi + (1 << (k - 1))) >> k
        xr, o1 = _sat(xr, out_w)
        xi, o2 = _sat(xi, out_w)
        ovf = ovf or o1 or o2
    return xr.reshape(lead + (n,)), xi.reshape(lead + (n,)), ovf


def fft_fixed(x_re, x_im, log2_n: int, in_w: int, tw_w: int = TW_W, frac_w: int = FRAC_W,
              out_w: int | None = None, guard: int = GUARD):
    """Bit-exact fixed-point FFT of fmt_fft_r22sdf, natural bin order.

    x_re, x_im: integer arrays (..., N) of IN_W-bit values (windows along the leading
    axes).  Returns (X_re, X_im, ovf): int64 arrays (..., N) with X[k] * 2^-SHIFT (see
    :func:`out_shift`, SHIFT = -FRAC_W at the default full OUT_W) and the overflow flag.
    """
    yr, yi, ovf = fft_fixed_slots(x_re, x_im, log2_n, in_w, tw_w, frac_w, out_w, guard)
    inv = np.empty(1 << log2_n, dtype=np.int64)
    inv[output_slot_order(log2_n)] = np.arange(1 << log2_n)
    return yr[..., inv], yi[..., inv], ovf


def fft_float(x_re, x_im, log2_n: int, in_w: int, frac_w: int = FRAC_W, out_w: int | None = None):
    """Floating-point reference: numpy FFT of the same integer samples, scaled like the
    RTL output (X * 2^-SHIFT), natural bin order."""
    x = np.asarray(x_re, dtype=np.float64) + 1j * np.asarray(x_im, dtype=np.float64)
    return np.fft.fft(x, axis=-1) * 2.0 ** (-out_shift(log2_n, in_w, out_w, frac_w))


def sqnr_db(ref: np.ndarray, got: np.ndarray) -> float:
    """10 log10(sum |ref|^2 / sum |got - ref|^2) (inf when exact)."""
    num = float(np.sum(np.abs(ref) ** 2))
    den = float(np.sum(np.abs(got - ref) ** 2))
    return math.inf if den == 0 else 10.0 * math.log10(num / den)


# ---- test signals shared by the tests and scripts/fft_accuracy.py ----------------------
def comb_input(log2_n: int, bins, in_w: int, windows: int = 1, amp_frac: float = 0.98,
               seed: int = 1, in_phase: bool = False):
    """A near-full-scale comb of real tones on ``bins`` in each of re and im (two
    independent real columns, as the receiver pairs them), quantized to in_w bits."""
    n = 1 << log2_n
    rng = np.random.default_rng(seed)
    t = np.arange(windows * n)
    full = (1 << (in_w - 1)) - 1
    out = []
    for _ in range(2):
        ph = np.zeros(len(bins)) if in_phase else rng.uniform(0, 2 * np.pi, len(bins))
        sig = np.zeros(t.size)
        for k, p in zip(bins, ph):
            sig += np.cos(2 * np.pi * k * t / n + p)
        sig *= amp_frac * full / np.max(np.abs(sig))
        out.append(np.clip(np.floor(sig + 0.5), -full - 1, full).astype(np.int64).reshape(windows, n))
    return out[0], out[1]
