"""Behavioural models for the XC5VSX95T board core's testbench (tb/fpga_xc5v).

Every model here is behavioural and labelled as such: the ADS5272-class ADC's serial
output (one lane per channel, ADC_BITS bits per sample MSB first, a frame-clock lane per
chip, test patterns chosen over its serial control port), the board top's IODELAY (one
tap per step, reset to 0) and ISERDES (SER_W bits per clk, the earliest at the top), and
the AD9834-class DDS chip's SPI port and phase select.  Register words of the ADC are the
board's placeholders (fpga_core TP_*), not the data sheet's register map.
"""
from __future__ import annotations

import numpy as np

SYNC_WORD = 0xFC0          # sync pattern and frame-clock shape (first bit at the MSB)
DESKEW_WORD = 0x555        # 0101... (first bit 0)


class SpiSlave:
    """Write-only SPI receiver: SDATA latched on SCLK falling edges while CS is low; a
    word is complete when CS rises.  ``step`` is called once per clk with the pins."""

    def __init__(self, lanes: int = 1, word_bits: int = 16):
        self.lanes, self.word_bits = lanes, word_bits
        self.sclk_prev = 1
        self.bits = [[] for _ in range(lanes)]
        self.words: list[list[int]] = [[] for _ in range(lanes)]
        self.cs_prev = 1
        self.errors: list[str] = []

    def step(self, sclk: int, sdata: list[int], cs_n: int) -> list[int] | None:
        done = None
        if cs_n == 0 and self.sclk_prev == 1 and sclk == 0:
            for l in range(self.lanes):
                self.bits[l].append(sdata[l])
        if self.cs_prev == 0 and cs_n == 1:
            done = []
            for l in range(self.lanes):
                b = self.bits[l]
                if len(b) != self.word_bits:
                    self.errors.append(f"lane {l}: {len(b)} bits in a transfer")
                w = 0
                for x in b:
                    w = (w << 1) | x
                self.words[l].append(w)
                done.append(w)
                self.bits[l] = []
        self.sclk_prev, self.cs_prev = sclk, cs_n
        return done


class AdcSerialModel:
    """ADS5272-class chips: ``cols`` data lanes, one frame lane per chip (lane index
    cols + k), serial words of ``bits`` bits at 12 bits per 3 clk (SER_W = 4 per clk).

    Per chip a bit slip (0 .. bits-1: where the words start in the bit stream); per lane
    a skew in IODELAY taps (whole bits and a sub-bit part, ``tpb`` taps per bit) on top
    of the lane's IODELAY tap.  A lane sampled within ``edge`` taps of a bit transition
    reads random bits.  Modes (set by the control words): 'normal' (samples), 'deskew',
    'sync'; the frame lanes always carry SYNC_WORD.  Words are two's complement."""

    def __init__(self, cols, samples, words, ser_w=4, bits=12, ch_per_chip=8, tpb=26,
                 edge=4, taps=64, skew=None, slip=None, seed=1):
        self.cols, self.bits, self.ser_w = cols, bits, ser_w
        self.chips = (cols + ch_per_chip - 1) // ch_per_chip
        self.cpc = ch_per_chip
        self.nl = cols + self.chips
        self.rng = np.random.default_rng(seed)
        self.tpb, self.edge, self.taps = tpb, edge, taps
        self.skew = list(skew) if skew is not None else [int(x) for x in self.rng.integers(0, 60, self.nl)]
        self.slip = list(slip) if slip is not None else [int(x) for x in self.rng.integers(0, bits, self.chips)]
        self.tap = [0] * self.nl
        self.samples = np.asarray(samples, dtype=np.int64)  # (n, cols)
        self.mode_of = {words["deskew"]: "deskew", words["sync"]: "sync", words["normal"]: "normal"}
        self.mode = "normal"          # power-up: data (the training must switch it)
        self.w_norm = 0               # first word of the current normal stretch
        self.cache: dict = {}
        self.t = 0                    # clk cycles so far
        self.spi = SpiSlave(1, 16)
        self.unknown_words: list[int] = []
        self.sent_first: dict = {}    # sample index -> first bit time (global bit index)

    def chip(self, lane):
        return (lane - self.cols) if lane >= self.cols else lane // self.cpc

    def word(self, lane, w):
        key = (lane, w)
        v = self.cache.get(key)
        if v is None:
            if lane >= self.cols:
                v = SYNC_WORD
            elif self.mode == "deskew":
                v = DESKEW_WORD
            elif self.mode == "sync":
                v = SYNC_WORD
            else:
                i = w - self.w_norm
                v = int(self.samples[i, lane]) & ((1 << self.bits) - 1) if 0 <= i < len(self.samples) else 0
            self.cache[key] = v
        return v

    def control(self, sclk, sdata, cs_n):
        done = self.spi.step(sclk, [sdata], cs_n)
        if done:
            w = done[0]
            m = self.mode_of.get(w)
            if m is None:
                self.unknown_words.append(w)
            elif m != self.mode:
                self.mode = m
                # words not yet started take the new mode (slip 0 reference is enough here)
                self.w_norm = (self.t * self.ser_w) // self.bits + 2
                self.cache = {k: v for k, v in self.cache.items() if k[1] < self.w_norm}

    def iodelay(self, rst, ce_mask, inc):
        if rst:
            self.tap = [0] * self.nl
        else:
            for l in range(self.nl):
                if (ce_mask >> l) & 1:
                    self.tap[l] = (self.tap[l] + (1 if inc else -1)) % self.taps

    def lane_bits(self, lane):
        """The SER_W bits the lane's ISERDES gives in this clk, earliest at the top."""
        d = self.skew[lane] + self.tap[lane]
        k, frac = divmod(d, self.tpb)
        bad = frac < self.edge or frac >= self.tpb - self.edge
        slip = self.slip[self.chip(lane)]
        out = 0
        for j in range(self.ser_w):
            n = self.t * self.ser_w + j - k - slip       # source bit index
            if bad:
                b = int(self.rng.integers(0, 2))
            elif n < 0:
                b = 0
            else:
                w, p = divmod(n, self.bits)
                b = (self.word(lane, w) >> (self.bits - 1 - p)) & 1
            out = (out << 1) | b
        return out

    def step(self):
        """All lanes' bits of this clk: (data bits int, frame bits int), lane l at
        [l*SER_W +: SER_W]."""
        data = 0
        for l in range(self.cols):
            data |= self.lane_bits(l) << (l * self.ser_w)
        frame = 0
        for k in range(self.chips):
            frame |= self.lane_bits(self.cols + k) << (k * self.ser_w)
        self.t += 1
        return data, frame

    def centred(self, lane) -> int:
        """Distance (taps) of the lane's sampling point from its eye centre."""
        frac = (self.skew[lane] + self.tap[lane]) % self.tpb
        return abs(frac - self.tpb // 2)


class Ad9834Model:
    """AD9834-class chip (behavioural): 16-bit SPI words (B28 two-word frequency writes,
    phase registers, control), PIN/SW, PSELECT sampled each MCLK (= one ce here), the
    output's phase register chosen ``pipeline`` MCLK cycles after PSELECT."""

    def __init__(self, pipeline: int = 7):
        self.ctrl = 0
        self.freq = [0, 0]
        self.phase = [0, 0]
        self.b28_half = None      # pending LSB half of a B28 write
        self.words: list[int] = []
        self.pipe: list[int] = []
        self.pipeline = pipeline
        self.out_sel: list[int] = []   # phase register in use at each MCLK (after reset release)

    def write(self, w: int):
        self.words.append(w)
        top2 = w >> 14
        if top2 == 0:
            self.ctrl = w
            self.b28_half = None
        elif top2 in (1, 2):
            r = top2 - 1
            if self.ctrl & 0x2000:                       # B28: LSB 14 bits, then MSB 14 bits
                if self.b28_half is None:
                    self.b28_half = w & 0x3FFF
                else:
                    self.freq[r] = ((w & 0x3FFF) << 14) | self.b28_half
                    self.b28_half = None
            else:
                raise AssertionError("B28 = 0 writes are not used by fmt_dds_prog")
        else:
            self.phase[(w >> 13) & 1] = w & 0xFFF

    def mclk(self, psel_pin: int, reset_pin: int):
        pin_sw = bool(self.ctrl & 0x0200)
        in_reset = reset_pin if pin_sw else bool(self.ctrl & 0x0100)
        sel = psel_pin if pin_sw else bool(self.ctrl & 0x0400)
        self.pipe.append(int(sel))
        if len(self.pipe) > self.pipeline + 1:       # output at MCLK m: PSELECT of MCLK m - pipeline
            self.pipe.pop(0)
        if not in_reset:
            self.out_sel.append(self.pipe[0] if len(self.pipe) == self.pipeline + 1 else 0)
