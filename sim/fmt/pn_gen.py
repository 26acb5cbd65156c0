"""PN chip generator: the bit-exact twin of ``rtl/fmt_pn_gen.v``.

Fibonacci LFSR of ``bits`` bits: feedback = parity(state & taps), shifted in at bit 0;
the chip sign is the top bit.  The LFSR is loaded with ``seed`` at reset and steps
once every ``chip_len`` samples.  Sign 1 means multiply by -1.
"""
from __future__ import annotations

import numpy as np

# Maximal-length taps masks (Fibonacci form, bit i = x^(i+1) term) for a few lengths.
MAXIMAL_TAPS = {
    5: 0x14,      # x^5 + x^3 + 1
    7: 0x60,      # x^7 + x^6 + 1
    9: 0x110,     # x^9 + x^5 + 1
    10: 0x240,    # x^10 + x^7 + 1
    11: 0x500,    # x^11 + x^9 + 1
    15: 0x6000,   # x^15 + x^14 + 1 (the default)
    17: 0x12000,  # x^17 + x^14 + 1
}
DEFAULT_SEED = 1


def lfsr_chips(n_chips: int, bits: int = 15, taps: int | None = None, seed: int = DEFAULT_SEED) -> np.ndarray:
    """Chip signs (0/1, uint8) of the first ``n_chips`` chips after reset."""
    if taps is None:
        taps = MAXIMAL_TAPS[bits]
    mask = (1 << bits) - 1
    state = seed & mask
    if state == 0:
        raise ValueError("LFSR seed must be non-zero")
    out = np.empty(n_chips, dtype=np.uint8)
    for i in range(n_chips):
        out[i] = (state >> (bits - 1)) & 1
        fb = bin(state & taps).count("1") & 1
        state = ((state << 1) | fb) & mask
    return out


def pn_signs(n_samples: int, chip_len: int = 1, enable: bool = True, rx_delay: int = 0,
             bits: int = 15, taps: int | None = None, seed: int = DEFAULT_SEED,
             start: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(tx_sign, rx_sign) for samples ``start .. start + n_samples - 1`` after reset.

    ``chip_len`` 0 is taken as 1, as in the RTL.  ``rx_sign[t] = tx_sign[t - rx_delay]``
    and 0 before the first sample.
    """
    chip_len = max(1, int(chip_len))
    first = max(0, start - rx_delay)
    last = start + n_samples
    n_chips = (last + chip_len - 1) // chip_len + 1
    chips = lfsr_chips(n_chips, bits, taps, seed)
    t = np.arange(first, last)
    s = chips[t // chip_len] if enable else np.zeros(t.size, dtype=np.uint8)
    full = np.zeros(last, dtype=np.uint8)
    full[first:last] = s
    tx = full[start:last]
    rx = np.zeros(n_samples, dtype=np.uint8)
    idx = np.arange(start, last) - rx_delay
    ok = idx >= 0
    rx[ok] = full[idx[ok]]
    return tx, rx


def sign_to_pm1(s: np.ndarray) -> np.ndarray:
    """0/1 sign bits to +1/-1 multipliers."""
    return 1 - 2 * s.astype(np.int64)
