"""Board-level numbers of the XC5VSX95T build (fpga/xc5vsx95t): the AD9834-class DDS
chips' tone plan and the word sequence fpga/common/rtl/fmt_dds_prog.v sends them.

Tone plan: the chips' MCLK is derived from the ADC's sample clock, MCLK = fs * 2^r
(r = ``mclk_log2``; r = 0: MCLK = fs = 41.667 MHz, inside the AD9834's 75 MHz).  The
chip's output frequency is FREQ * MCLK / 2^28, so row r's word
FREQ = bin << (28 - log2 N - r) gives exactly bin * fs / N: on the comb, no leakage.
"""
from __future__ import annotations

FREQ_BITS = 28            # AD9834 frequency register width
PHASE_BITS = 12           # AD9834 phase register width
CTRL_LOAD = 0x2100        # B28 = 1, RESET bit = 1, PIN/SW = 0
CTRL_RUN = 0x2200         # B28 = 1, PIN/SW = 1 (FSELECT / PSELECT / RESET from the pins)
PHASE_180 = 1 << (PHASE_BITS - 1)
# PSELECT -> DAC output pipeline of the AD9834 in MCLK cycles, as recalled from its data
# sheet ("7 or 8 MCLK cycles"): NOT checked against the data sheet here.
DDS_PIPELINE_MCLK = (7, 8)


def bins(cfg) -> list[int]:
    return [cfg.bin_lo + r * cfg.bin_step for r in range(cfg.rows)]


def dds_freq_words(cfg, mclk_log2: int = 0) -> list[int]:
    """Row r's 28-bit FREQ0 word (twin of fmt_dds_prog's plan)."""
    shift = FREQ_BITS - cfg.log2_n - mclk_log2
    if shift < 0:
        raise ValueError("MCLK too fast for the FFT size: fs * 2^r / N below one LSB")
    words = [b << shift for b in bins(cfg)]
    if max(words) >= 1 << FREQ_BITS:
        raise ValueError("a tone above MCLK")
    return words


def dds_freq_hz(cfg, mclk_log2: int = 0) -> list[float]:
    mclk = cfg.fs_hz * 2 ** mclk_log2
    return [w * mclk / 2 ** FREQ_BITS for w in dds_freq_words(cfg, mclk_log2)]


def dds_spi_words(cfg, mclk_log2: int = 0) -> list[list[int]]:
    """The 16-bit words each chip receives, in order (one list per row)."""
    out = []
    for fw in dds_freq_words(cfg, mclk_log2):
        out.append([CTRL_LOAD, 0x4000 | (fw & 0x3FFF), 0x4000 | (fw >> 14),
                    0xC000, 0xE000 | PHASE_180, CTRL_RUN])
    return out
