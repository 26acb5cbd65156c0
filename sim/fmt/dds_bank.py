"""DDS bank with PN bi-phase modulation, and the column despreader: twins of
``rtl/fmt_dds_bank.v`` (+ ``fmt_dds_chan``, ``fmt_dds_rom2``), ``rtl/fmt_tx.v`` and
``rtl/fmt_despread.v``.

Transmit word of row r at sample k (all integers, bit-exact with the RTL):

    phase[0]   = 0,  phase[k+1] = (phase[k] + tw[k]) mod 2**P           (P = phase_bits)
    addr[k]    = phase[k] >> (P - A)                                      (A = table_addr)
    s[k]       = TABLE[addr[k]],  TABLE[i] = round((2**(S-1) - 1) * sin(2 pi i / 2**A))
    p[k]       = s[k] * amp[k]                       (S-bit signed x AMP_BITS unsigned)
    r[k]       = (p[k] + 2**(SH-1)) >> SH            SH = S + AMP_BITS - DAC_BITS,
                                                     round half up (arithmetic shift)
    dac[k]     = 0 if not enable[k] else (-r[k] if tx_sign[k] else r[k])

The table is symmetric (never -2**(S-1)) and amp <= 2**AMP_BITS - 1, so |r| <=
2**(DAC_BITS-1) - 1 whenever 2**(SH-1) < 2**(S-1) + 2**AMP_BITS - 1 (always true for
DAC_BITS > AMP_BITS): the negation by the PN sign can never overflow and no saturation
is needed (checked by :func:`check_widths`).  The sign is applied after rounding, so
the +1 and -1 words are exact negatives of each other.

The RTL bank time-multiplexes its channel engines (``ROWS_PER_ENGINE`` = R rows per
engine, ce every R clk cycles); R changes the schedule, not the arithmetic: the words
above are those of every R (tb/fmt_dds_bank checks R = 1 and 3 against
:func:`dds_bank_fixed`).

Exact-bin tones: bin k has tuning word k << (P - log2 N); with 2**A >= N entries the
address has no truncated phase bits, so every N-sample window of a row is identical.

The float twin :func:`dds_bank_float` gives the ideal word (same scaling, no table or
output rounding); the fixed words differ from it by at most
0.5 + 0.5 (2**AMP_BITS - 1) / 2**SH LSB (output rounding + table rounding) plus, for
tuning words with non-zero low bits, the phase-truncation term
peak * 2 pi / 2**A (see :func:`error_bound`).

``python -m fmt.generate`` writes the committed sine tables (:func:`render_hex`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .params import DEFAULT, SensorConfig

RTL = Path(__file__).resolve().parents[2] / "rtl"

TABLE_ADDR = 10                 # default table: 2**10 entries (>= N for every N <= 1024)
# Tables committed in rtl/ (table_addr, sine_bits): the default and the purity sweep.
HEX_TABLES = [(10, 10), (10, 12), (10, 14), (10, 16)]


# ---- sine table ------------------------------------------------------------------
def sine_table(table_addr: int = TABLE_ADDR, sine_bits: int = 16) -> np.ndarray:
    """Full-wave table: 2**table_addr signed sine_bits words, the nearest integer to
    (2**(S-1) - 1) sin(2 pi i / 2**A).  No ties occur (sin(2 pi i / 2**A) is 0, +-1 or
    irrational), so the rounding rule does not matter; the table is odd-symmetric and
    never holds -2**(S-1)."""
    n = 1 << table_addr
    peak = (1 << (sine_bits - 1)) - 1
    i = np.arange(n)
    return np.rint(peak * np.sin(2 * np.pi * i / n)).astype(np.int64)


def hex_name(table_addr: int, sine_bits: int) -> str:
    return f"fmt_sine_rom_a{table_addr:02d}_s{sine_bits:02d}.hex"


def render_hex(table_addr: int, sine_bits: int) -> str:
    t = sine_table(table_addr, sine_bits)
    digits = (sine_bits + 3) // 4
    mask = (1 << sine_bits) - 1
    return "".join(f"{int(v) & mask:0{digits}x}\n" for v in t)


# ---- widths ----------------------------------------------------------------------
def out_shift(sine_bits: int, amp_bits: int, dac_bits: int) -> int:
    return sine_bits + amp_bits - dac_bits


def check_widths(sine_bits: int, amp_bits: int, dac_bits: int) -> None:
    """Raise unless the rounded product always fits in +-(2**(DAC_BITS-1) - 1)."""
    sh = out_shift(sine_bits, amp_bits, dac_bits)
    if sh < 0:
        raise ValueError("DAC_BITS must be <= SINE_BITS + AMP_BITS")
    half = (1 << (sh - 1)) if sh > 0 else 0
    if not half < (1 << (sine_bits - 1)) + (1 << amp_bits) - 1:
        raise ValueError("DAC_BITS too small for AMP_BITS: the rounded peak would reach "
                         "-2**(DAC_BITS-1) (use DAC_BITS > AMP_BITS)")


def default_settings(cfg: SensorConfig):
    """Reset values of the bank: the comb's tuning words, full amplitude, enabled."""
    tw = np.array([cfg.tuning_word(k) for k in cfg.bins], dtype=np.int64)
    amp = np.full(cfg.rows, (1 << cfg.amp_bits) - 1, dtype=np.int64)
    en = np.ones(cfg.rows, dtype=np.int64)
    return tw, amp, en


def _per_sample(x, n: int, rows: int) -> np.ndarray:
    a = np.asarray(x, dtype=np.int64)
    if a.ndim == 0:
        a = np.full(rows, int(a), dtype=np.int64)
    if a.ndim == 1:
        a = np.broadcast_to(a, (n, rows))
    if a.shape != (n, rows):
        raise ValueError(f"expected shape ({n}, {rows}) or ({rows},), got {a.shape}")
    return a


def _phases(n: int, tuning: np.ndarray, phase_bits: int) -> np.ndarray:
    """phase[k] = sum_{j<k} tw[j] mod 2**P, per row (int64, exact for P <= 32)."""
    mod = 1 << phase_bits
    tw = tuning % mod
    ph = np.zeros_like(tw)
    # partial sums stay < n * 2**32 < 2**63 for n < 2**31
    ph[1:] = np.cumsum(tw[:-1], axis=0) % mod
    return ph


def _sign_enable(r, enable, tx_sign, n):
    sg = np.asarray(tx_sign, dtype=np.int64)
    sg = np.full((n, 1), int(sg)) if sg.ndim == 0 else sg.reshape(n, 1)
    out = np.where(sg != 0, -r, r)
    return np.where(enable != 0, out, 0)


# ---- the bank ---------------------------------------------------------------------
def dds_bank_fixed(n_samples: int, tuning=None, amp=None, enable=None, tx_sign=0,
                   cfg: SensorConfig = DEFAULT, table_addr: int = TABLE_ADDR,
                   sine_bits: int | None = None, dac_bits: int | None = None,
                   amp_bits: int | None = None) -> np.ndarray:
    """DAC words (int64, shape (n_samples, rows)) of samples 0..n-1 after reset,
    bit-exact with ``fmt_dds_bank``.

    ``tuning``, ``amp``, ``enable``: per row (shape (rows,)) or per sample and row
    (shape (n, rows)): the register values in effect when sample k is computed
    (None = the reset defaults).  ``tx_sign``: scalar or shape (n,), 1 = multiply by
    -1 (shared by all rows).  Widths default to the config's.
    """
    s_bits = cfg.sine_bits if sine_bits is None else sine_bits
    d_bits = cfg.dac_bits if dac_bits is None else dac_bits
    a_bits = cfg.amp_bits if amp_bits is None else amp_bits
    check_widths(s_bits, a_bits, d_bits)
    if (1 << table_addr) < cfg.n_fft:
        raise ValueError("sine table must have >= N entries")
    n, rows = n_samples, cfg.rows
    dtw, damp, den = default_settings(cfg)
    damp = np.full(rows, (1 << a_bits) - 1, dtype=np.int64)
    tw = _per_sample(dtw if tuning is None else tuning, n, rows)
    am = _per_sample(damp if amp is None else amp, n, rows)
    en = _per_sample(den if enable is None else enable, n, rows)
    if np.any(am < 0) or np.any(am >= (1 << a_bits)):
        raise ValueError("amplitude out of range")
    ph = _phases(n, tw, cfg.phase_bits)
    addr = ph >> (cfg.phase_bits - table_addr)
    s = sine_table(table_addr, s_bits)[addr]
    p = s * am
    sh = out_shift(s_bits, a_bits, d_bits)
    r = (p + ((1 << (sh - 1)) if sh > 0 else 0)) >> sh
    return _sign_enable(r, en, tx_sign, n)


def dds_bank_float(n_samples: int, tuning=None, amp=None, enable=None, tx_sign=0,
                   cfg: SensorConfig = DEFAULT, sine_bits: int | None = None,
                   dac_bits: int | None = None, amp_bits: int | None = None) -> np.ndarray:
    """Ideal words (float64, DAC LSB units): (2**(S-1) - 1) amp sin(2 pi phase / 2**P)
    / 2**SH with the exact phase, signed by tx_sign and gated by enable."""
    s_bits = cfg.sine_bits if sine_bits is None else sine_bits
    d_bits = cfg.dac_bits if dac_bits is None else dac_bits
    a_bits = cfg.amp_bits if amp_bits is None else amp_bits
    n, rows = n_samples, cfg.rows
    dtw, _, den = default_settings(cfg)
    damp = np.full(rows, (1 << a_bits) - 1, dtype=np.int64)
    tw = _per_sample(dtw if tuning is None else tuning, n, rows)
    am = _per_sample(damp if amp is None else amp, n, rows)
    en = _per_sample(den if enable is None else enable, n, rows)
    ph = _phases(n, tw, cfg.phase_bits)
    sh = out_shift(s_bits, a_bits, d_bits)
    v = ((1 << (s_bits - 1)) - 1) * am * np.sin(2 * np.pi * ph / float(1 << cfg.phase_bits)) / 2.0 ** sh
    return _sign_enable(v, en, tx_sign, n).astype(np.float64)


def error_bound(cfg: SensorConfig = DEFAULT, table_addr: int = TABLE_ADDR, exact_bins: bool = True,
                sine_bits: int | None = None, dac_bits: int | None = None,
                amp_bits: int | None = None) -> float:
    """Max |fixed - float| in DAC LSB: output rounding 0.5 LSB (0 when SH = 0), table
    rounding 0.5 table LSB scaled by amp / 2**SH, and for non-exact tuning words the
    phase truncation (|d sin| <= 2 pi 2**-A times the peak)."""
    s_bits = cfg.sine_bits if sine_bits is None else sine_bits
    d_bits = cfg.dac_bits if dac_bits is None else dac_bits
    a_bits = cfg.amp_bits if amp_bits is None else amp_bits
    sh = out_shift(s_bits, a_bits, d_bits)
    amax = (1 << a_bits) - 1
    b = (0.5 if sh > 0 else 0.0) + 0.5 * amax / 2.0 ** sh
    if not exact_bins:
        peak = ((1 << (s_bits - 1)) - 1) * amax / 2.0 ** sh
        b += peak * 2 * np.pi / (1 << table_addr)
    return b


def tx_fixed(n_samples: int, cfg: SensorConfig = DEFAULT, pn_enable: bool = True,
                 chip_len: int = 1, **kw) -> np.ndarray:
    """Words of ``fmt_tx`` (fmt_pn_gen + fmt_dds_bank), samples 0..n-1 after reset:
    DDS sample k carries the PN sign of PN sample k-1 (the generator's registered
    output; +1 for k = 0)."""
    from .pn_gen import pn_signs
    tx, _ = pn_signs(max(n_samples - 1, 0), chip_len=chip_len, enable=pn_enable, bits=cfg.pn_bits)
    sign = np.concatenate([[0], tx]).astype(np.int64)[:n_samples]
    return dds_bank_fixed(n_samples, tx_sign=sign, cfg=cfg, **kw)


# ---- despreader ------------------------------------------------------------------
def despread_fixed(x, sign) -> np.ndarray:
    """ADC word times the receive PN sign (1 = multiply by -1), exact in ADC_BITS + 1
    bits (-(-2**(ADC_BITS-1)) = +2**(ADC_BITS-1) fits)."""
    x = np.asarray(x, dtype=np.int64)
    return np.where(np.asarray(sign) != 0, -x, x)


def despread_float(x, sign) -> np.ndarray:
    """Float twin (the operation is exact: identical to the fixed one)."""
    x = np.asarray(x, dtype=np.float64)
    return np.where(np.asarray(sign) != 0, -x, x)


# ---- spectral purity -------------------------------------------------------------
def worst_spur_dbc(x: np.ndarray, tone_bins) -> tuple[float, int]:
    """Worst non-tone bin (excluding DC) relative to the weakest tone bin of one
    window ``x`` (length N, rectangular window: exact-bin tones do not leak), in dBc,
    and the bin where it is (a spur-free window reports -300 dBc)."""
    X = np.abs(np.fft.rfft(np.asarray(x, dtype=np.float64)))
    tone = min(X[k] for k in tone_bins)
    mask = np.ones(X.size, dtype=bool)
    mask[0] = False
    mask[list(tone_bins)] = False
    k = int(np.flatnonzero(mask)[np.argmax(X[mask])])
    spur = max(X[k], tone * 1e-15)
    return 20 * np.log10(spur / tone), k
