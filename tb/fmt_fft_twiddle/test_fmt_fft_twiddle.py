"""cocotb testbench of rtl/fmt_fft_twiddle.v (the FFT's twiddle multiplier) alone.

Inside fmt_fft_r22sdf the growth plan makes an overflow impossible, so the overflow
detection and the sticky ovf_o are tested here with an output narrower than the data
needs: bit-exact rotated values (ROM contents, truncated products, round half up, the
kept low bits) against ``fft_fixed._twiddle_mul`` with random ce, the 4-step latency (the ROM address nxt_idx_i one step ahead),
ovf_o staying 0 while every element fits and rising together with the first element
that does not, and reset clearing it.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly

from common.runner import run_cocotb, sources
from common.sources import rom_define
from common.tb_util import ClockedTB, env_int
from fmt import fft_r22sdf as F


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.log2_n = env_int("LOG2_N", 6)
        self.log2_m = env_int("LOG2_M", 6)
        self.dw, self.ow, self.sh = env_int("DW", 15), env_int("OW", 12), env_int("SH", 13)
        dut.ce.value = 0
        dut.in_valid_i.value = 0
        dut.in_idx_i.value = 0
        dut.nxt_idx_i.value = 0
        dut.in_re_i.value = 0
        dut.in_im_i.value = 0

    def model(self, idx, re, im):
        c, s = F.twiddle_table(1 << self.log2_m)
        i = idx % (1 << self.log2_m)
        return F._twiddle_mul(re, im, c[i], s[i], self.sh, self.ow)

    async def run(self, re, im, rng):
        """Feed elements (idx = position mod N); return (out_re, out_im, ovf after each)."""
        dut = self.dut
        n = len(re)
        got, k, cyc = [], 0, 0
        # one invalid step first: it reads element 0's twiddle (the ROM reads one step ahead)
        await self.writable()
        dut.ce.value = 1
        dut.in_valid_i.value = 0
        dut.nxt_idx_i.value = 0
        while len(got) < n:
            await self.writable()
            ce = 1 if rng.random() < 0.7 else 0
            dut.ce.value = ce
            if ce:
                dut.in_valid_i.value = 1 if k < n else 0
                dut.in_idx_i.value = k % (1 << self.log2_n)
                dut.nxt_idx_i.value = (k + 1) % (1 << self.log2_n)   # the ROM reads one step ahead
                dut.in_re_i.value = int(re[k]) if k < n else 0
                dut.in_im_i.value = int(im[k]) if k < n else 0
            await ReadOnly()
            if ce:
                # the output registers now hold the element fed 4 ce steps ago
                assert int(dut.out_valid_o.value) == (1 if 4 <= k < n + 4 else 0), f"valid at {k}"
                if k >= 4:
                    assert int(dut.out_idx_o.value) == (k - 4) % (1 << self.log2_n)
                    got.append((dut.out_re_o.value.to_signed(), dut.out_im_o.value.to_signed(),
                                int(dut.ovf_o.value)))
                k += 1
            cyc += 1
            assert cyc < 10 * n + 100
        g = np.array(got, dtype=np.int64)
        return g[:, 0], g[:, 1], g[:, 2]


@cocotb.test()
async def overflow_and_sticky_flag(dut):
    tb = TB(dut)
    rng = np.random.default_rng(2)
    r = random.Random(3)
    await tb.reset()
    n1, n2 = 3 * (1 << tb.log2_m), 2 * (1 << tb.log2_m)
    # phase 1: small values, |out| <= |in| 2^(16-SH) sqrt(2) stays inside OW bits
    lim = int((1 << (tb.ow - 1)) / (2.0 ** (16 - tb.sh) * 1.5))
    re1 = rng.integers(-lim, lim, n1)
    im1 = rng.integers(-lim, lim, n1)
    # phase 2: full DW-bit range, mostly overflowing
    re2 = rng.integers(-(1 << (tb.dw - 1)), 1 << (tb.dw - 1), n2)
    im2 = rng.integers(-(1 << (tb.dw - 1)), 1 << (tb.dw - 1), n2)
    re2[:5] = 0                               # the first few stay in range
    im2[:5] = 0
    re, im = np.concatenate([re1, re2]), np.concatenate([im1, im2])
    idx = np.arange(re.size)
    ore, oim, ovf = await tb.run(re, im, r)
    sat_any = np.zeros(re.size, dtype=bool)
    for j in range(re.size):
        mr, mi, o = tb.model(idx[j], re[j], im[j])
        assert (ore[j], oim[j]) == (mr, mi), f"element {j}: rtl {ore[j]},{oim[j]} model {mr},{mi}"
        sat_any[j] = o or (j > 0 and sat_any[j - 1])
    assert not sat_any[:n1].any(), "phase 1 should fit (test setup)"
    assert not sat_any[n1:n1 + 5].any() and sat_any[-1], "phase 2 should overflow (test setup)"
    assert np.array_equal(ovf.astype(bool), sat_any), "ovf_o must rise with the first overflow"
    # reset clears the sticky flag
    await tb.reset()
    await ReadOnly()
    assert int(dut.ovf_o.value) == 0


@pytest.mark.parametrize("dw", [15, 21])
def test_fmt_fft_twiddle(sim, dw):
    """DW = 15: one multiplier per product; DW = 21 > MUL_W: split products (g_split)."""
    prm = {"LOG2_N": 6, "LOG2_M": 6, "DW": dw, "OW": 12, "SH": 13, "TW_W": 18}
    run_cocotb(sim=sim, toplevel="fmt_fft_twiddle", sources=sources("fmt_fft_twiddle"),
               test_module="test_fmt_fft_twiddle", test_dir=Path(__file__).parent,
               parameters=prm, extra_env=prm, build_args=[rom_define()])
