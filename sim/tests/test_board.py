"""sim/fmt/board.py: the AD9834-class tone words are exactly on the FFT comb (MCLK = fs and
MCLK = 2 fs), the default plan's figures, and the SPI word sequence."""
from fractions import Fraction

import pytest

from fmt import board, params


@pytest.mark.parametrize("name", ["small", "medium", "default"])
@pytest.mark.parametrize("r", [0, 1])
def test_words_on_comb(name, r):
    cfg = params.get(name)
    fs = Fraction(125_000_000, 3)
    for b, w in zip(board.bins(cfg), board.dds_freq_words(cfg, r)):
        assert 0 < w < 1 << 28
        assert Fraction(w) * fs * 2 ** r / 2 ** 28 == b * fs / cfg.n_fft   # exact, no leakage


def test_default_plan():
    cfg = params.DEFAULT
    w = board.dds_freq_words(cfg)
    assert (w[0], w[-1]) == (33 << 20, 62 << 20) == (0x2100000, 0x3E00000)
    f = board.dds_freq_hz(cfg)
    assert abs(f[0] - 5.371e6) < 1e3 and abs(f[-1] - 10.091e6) < 1e3
    seq = board.dds_spi_words(cfg)[0]
    assert seq == [0x2100, 0x4000, 0x4000 | (0x2100000 >> 14), 0xC000, 0xE800, 0x2200]
