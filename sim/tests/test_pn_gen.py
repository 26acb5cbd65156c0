"""PN model: maximal taps really are maximal, and the sequence is balanced."""
import numpy as np
import pytest

from fmt.pn_gen import MAXIMAL_TAPS, lfsr_chips, pn_signs


@pytest.mark.parametrize("bits", sorted(b for b in MAXIMAL_TAPS if b <= 15))
def test_maximal_period_and_balance(bits):
    period = (1 << bits) - 1
    c = lfsr_chips(2 * period, bits)
    assert np.array_equal(c[:period], c[period:])
    assert int(c[:period].sum()) == 1 << (bits - 1)
    # no proper divisor of the period is a period
    for p in range(1, period):
        if period % p == 0:
            assert not np.array_equal(c[:period - p], c[p:period])


def test_delay_and_chip_length():
    tx, rx = pn_signs(500, chip_len=5, rx_delay=7)
    assert np.array_equal(rx[7:], tx[:-7]) and not rx[:7].any()
    assert all(len(set(tx[i:i + 5])) == 1 for i in range(0, 500, 5))
