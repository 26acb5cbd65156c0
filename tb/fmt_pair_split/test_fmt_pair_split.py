"""cocotb testbench of rtl/fmt_pair_split.v against pair_split_fixed (sim/fmt/rx_array.py).

Random FFT outputs (full W-bit range, extremes included) stream in bit-reversed bin order
as fmt_fft_r22sdf emits them, one bin per ce: every row's (2A, 2B) is bit-exact, comes
exactly once per window, at the completion slot of its pair (+LAT = 2 ce cycles), rows in the
order of rx_fixed.row_order; natural order input works too (the block is order
independent); random ce; a reset in the middle of a window drops the half-held pairs.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params
from fmt import rx_array as R

LAT = R.split_lat(env_int("CH", 1))   # ce cycles from the second bin of a pair to its (2A, 2B):
#       2 (decode, LUT-RAM held memory + sums), 4 with CH >= 3 (decode, block-RAM read
#       latch and output register, sums)


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.w = env_int("W", 18)
        for s in ("ce", "in_valid_i", "in_bin_i", "in_re_i", "in_im_i", "in_tag_i", "in_ch_i"):
            getattr(dut, s).value = 0

    async def run(self, order, z_re, z_im, ce_prob=1.0, rng=None, gaps=False):
        """Stream windows (rows of z_*) with bins in ``order``; returns outputs as a list
        of (window, row, a_re, a_im, b_re, b_im, slot_of_output)."""
        dut, n = self.dut, self.cfg.n_fft
        rng = rng or random.Random(2)
        items = [(w, s) for w in range(z_re.shape[0]) for s in range(n)]
        outs, i, tail, fed = [], 0, 0, []
        while i < len(items) or tail < 4:
            await self.writable()
            ce = 1 if rng.random() < ce_prob else 0
            dut.ce.value = ce
            if i < len(items):
                w, s = items[i]
                b = order[s]
                dut.in_valid_i.value = 1
                dut.in_bin_i.value = int(b)
                dut.in_re_i.value = int(z_re[w, b])
                dut.in_im_i.value = int(z_im[w, b])
                dut.in_tag_i.value = w & 0xF
            else:
                dut.in_valid_i.value = 0
            await RisingEdge(self.clk)
            await ReadOnly()
            if ce:
                fed.append(items[i] if i < len(items) else None)
                if int(dut.out_valid_o.value):
                    assert len(fed) >= LAT and fed[-LAT] is not None, "output without a bin in"
                    ow, os_ = fed[-LAT]
                    outs.append((int(dut.out_tag_o.value), int(dut.out_row_o.value),
                                 dut.a_re_o.value.to_signed(), dut.a_im_o.value.to_signed(),
                                 dut.b_re_o.value.to_signed(), dut.b_im_o.value.to_signed(), os_))
                if i < len(items):
                    i += 1
                else:
                    tail += 1
        return outs


def bitrev_order(cfg):
    return [R.bitrev(s, cfg.log2_n) for s in range(cfg.n_fft)]


def check(tb, outs, z_re, z_im, order_name="bitrev"):
    cfg = tb.cfg
    ar, ai, br, bi = R.pair_split_fixed(z_re, z_im, cfg)
    wins = z_re.shape[0]
    assert len(outs) == wins * cfg.rows, f"{len(outs)} outputs, expected {wins * cfg.rows}"
    if order_name == "bitrev":
        slots = R.completion_slots(cfg)
        order = R.row_order(cfg)
    else:
        slots = np.array([cfg.n_fft - k for k in cfg.bins])     # the mirror comes last
        order = np.argsort(slots)
    for j, (w, r, a0, a1, b0, b1, slot) in enumerate(outs):
        win, pos = divmod(j, cfg.rows)
        assert w == (win & 0xF), f"output {j}: window tag {w}, expected {win & 0xF}"
        assert r == order[pos], f"output {j}: row {r}, expected {order[pos]}"
        assert slot == slots[r], f"row {r} left after slot {slot}, pair completes at {slots[r]}"
        assert (a0, a1, b0, b1) == (ar[win, r], ai[win, r], br[win, r], bi[win, r]), \
            f"window {win} row {r}: rtl {(a0, a1, b0, b1)} model {(ar[win, r], ai[win, r], br[win, r], bi[win, r])}"


def rand_spectra(tb, wins, seed):
    rng = np.random.default_rng(seed)
    lo, hi = -(1 << (tb.w - 1)), (1 << (tb.w - 1))
    z_re = rng.integers(lo, hi, (wins, tb.cfg.n_fft))
    z_im = rng.integers(lo, hi, (wins, tb.cfg.n_fft))
    z_re[0, :4], z_im[0, :4] = lo, lo       # extremes (bins 0..3 are not comb bins)
    k = tb.cfg.bins[0]
    z_re[1, k], z_im[1, k], z_re[1, -k], z_im[1, -k] = lo, hi - 1, lo, lo
    return z_re, z_im


@cocotb.test()
async def bitrev_stream_exact(dut):
    tb = TB(dut)
    await tb.reset()
    z_re, z_im = rand_spectra(tb, 3, env_int("SEED", 1))
    outs = await tb.run(bitrev_order(tb.cfg), z_re, z_im)
    check(tb, outs, z_re, z_im)


@cocotb.test()
async def natural_order_and_random_ce(dut):
    tb = TB(dut)
    await tb.reset()
    z_re, z_im = rand_spectra(tb, 2, 9)
    outs = await tb.run(list(range(tb.cfg.n_fft)), z_re, z_im, ce_prob=0.4)
    check(tb, outs, z_re, z_im, "natural")


@cocotb.test()
async def reset_mid_window(dut):
    """Half a window, reset, then full windows: only the full windows' rows come out,
    bit-exact (nothing held from before the reset pairs with the new window)."""
    tb = TB(dut)
    await tb.reset()
    z_re, z_im = rand_spectra(tb, 2, 4)
    cfg = tb.cfg
    # stream the first 3/4 of a bit-reversed window: many pairs are half held
    part = await tb.run(bitrev_order(cfg)[: 3 * cfg.n_fft // 4] + [0] * (cfg.n_fft // 4),
                        z_re[:1] * 0 + 5, z_im[:1] * 0 - 7)
    await tb.reset(cycles=1)
    outs = await tb.run(bitrev_order(cfg), z_re, z_im)
    check(tb, outs, z_re, z_im)
    assert len(part) < cfg.rows


async def run_ch(tb, order, zs_re, zs_im, ch, ce_prob=1.0, rng=None):
    """CH interleaved channels in lockstep: bin order[s] of window w for channel 0, 1, ..
    CH-1 in turn.  Returns outputs (channel, tag, row, a_re, a_im, b_re, b_im, slot)."""
    dut, n = tb.dut, tb.cfg.n_fft
    rng = rng or random.Random(3)
    items = [(w, s, c) for w in range(zs_re.shape[1]) for s in range(n) for c in range(ch)]
    outs, i, tail, fed = [], 0, 0, []
    while i < len(items) or tail < 4:
        await tb.writable()
        ce = 1 if rng.random() < ce_prob else 0
        dut.ce.value = ce
        if i < len(items):
            w, s, c = items[i]
            b = order[s]
            dut.in_valid_i.value = 1
            dut.in_bin_i.value = int(b)
            dut.in_ch_i.value = c
            dut.in_re_i.value = int(zs_re[c, w, b])
            dut.in_im_i.value = int(zs_im[c, w, b])
            dut.in_tag_i.value = w & 0xF
        else:
            dut.in_valid_i.value = 0
        await RisingEdge(tb.clk)
        await ReadOnly()
        if ce:
            fed.append(items[i] if i < len(items) else None)
            if int(dut.out_valid_o.value):
                assert len(fed) >= LAT and fed[-LAT] is not None, "output without a bin in"
                _, os_, oc = fed[-LAT]
                assert int(dut.out_ch_o.value) == oc, f"out_ch_o {int(dut.out_ch_o.value)}, input channel {oc}"
                outs.append((oc, int(dut.out_tag_o.value), int(dut.out_row_o.value),
                             dut.a_re_o.value.to_signed(), dut.a_im_o.value.to_signed(),
                             dut.b_re_o.value.to_signed(), dut.b_im_o.value.to_signed(), os_))
            if i < len(items):
                i += 1
            else:
                tail += 1
    return outs


@cocotb.test(skip=env_int("CH", 1) < 2)
async def channels_lockstep(dut):
    """CH channels interleaved in lockstep (bit-reversed order, then random ce): every
    channel's rows bit-exact, in row order, at their completion slot; a reset in the
    middle of a window drops every channel's half-held pairs."""
    tb = TB(dut)
    ch = env_int("CH", 1)
    for ce_prob, seed in ((1.0, 21), (0.5, 22)):
        await tb.reset()
        zs = [rand_spectra(tb, 2, seed + 10 * c) for c in range(ch)]
        zr, zi = np.stack([z[0] for z in zs]), np.stack([z[1] for z in zs])
        if ce_prob == 0.5:
            # a reset in the middle of a window first: nothing pairs across it
            n = tb.cfg.n_fft
            part = await run_ch(tb, bitrev_order(tb.cfg)[: 3 * n // 4] + [0] * (n // 4),
                                zr[:, :1] * 0 + 3, zi[:, :1] * 0 - 5, ch)
            assert len(part) < tb.cfg.rows * ch
            await tb.reset(cycles=1)
        outs = await run_ch(tb, bitrev_order(tb.cfg), zr, zi, ch, ce_prob=ce_prob)
        for c in range(ch):
            check(tb, [o[1:] for o in outs if o[0] == c], zr[c], zi[c])


@pytest.mark.parametrize("cfg_name", ["small", "medium"])
def test_fmt_pair_split(sim, cfg_name, ch=1):
    p = params.get(cfg_name).verilog_params()
    w = 18
    run_cocotb(
        sim=sim,
        toplevel="fmt_pair_split",
        sources=sources("fmt_pair_split"),
        test_module="test_fmt_pair_split",
        test_dir=Path(__file__).parent,
        parameters={**{k: p[k] for k in ("LOG2_N", "ROWS", "BIN_LO", "BIN_STEP")},
                    "W": w, "TAG_W": 4, "CH": ch},
        extra_env={"CFG": cfg_name, "W": w, "CH": ch},
        testcase="channels_lockstep" if ch > 1 else None,
        build_args=["-CFLAGS", "-O0"] if sim == "verilator" else None,   # compile time dominates
    )


def test_fmt_pair_split_ch3(sim):
    """CH = 3: the split shared by a time-multiplexed engine's three column pairs."""
    test_fmt_pair_split(sim, "medium", ch=3)
