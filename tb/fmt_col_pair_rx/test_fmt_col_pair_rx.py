"""cocotb testbench of rtl/ref/fmt_col_pair_rx.v (one column pair: despread x2, FFT, pair
split, magnitude x2, accumulation) against rx_heatmaps_fixed on two columns
(mag_frac = 0: the reference rounds each magnitude to an integer, fmt_rx_array keeps two
fractional bits).

Bit-exact cells for stirred tones with random PN settings at M = 1, 2, 4 and for
full-range random ADC words, rows in rx_fixed.row_order with out_last_row_o on the last
one only, outputs only in the last window of a frame, ce = 1 in 3 (the pipeline advances
on ce only), the sticky saturation flag with a full-scale tone (cells clip at 2^HM_W - 1
only when the model says so), and M changed at run time taking effect at a frame start.
"""
from __future__ import annotations

import sys
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fmt_rx_array"))

from common.runner import run_cocotb, sources            # noqa: E402
from common.sources import rom_define                     # noqa: E402
from common.tb_util import ClockedTB, env_str             # noqa: E402
from fmt import params                                    # noqa: E402
from fmt import rx_array as R                             # noqa: E402
import rx_stim                                            # noqa: E402



class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        for s in ("ce", "adc_a_i", "adc_b_i", "rx_sign_i", "m_log2_i"):
            getattr(dut, s).value = 0

    async def reset(self, cycles: int = 4):
        await self.writable()
        self.dut.ce.value = 0
        await super().reset(cycles)

    async def run(self, adc, rx_sign, m_sched, ce_every=1):
        """adc (samples, 2); m_sched(i) = m_log2_i while sample i is fed.  Returns
        [(row, cell a, cell b, last_row)] in output order."""
        dut, cfg = self.dut, self.cfg
        total = len(adc) + cfg.n_fft + 60
        outs, i, phase = [], 0, 0
        hw = cfg.hm_width
        while i < total:
            await self.writable()
            ce = 1 if phase == 0 else 0
            phase = (phase + 1) % ce_every
            dut.ce.value = ce
            if ce:
                a, b = (adc[i] if i < len(adc) else (0, 0))
                dut.adc_a_i.value = int(a)
                dut.adc_b_i.value = int(b)
                dut.rx_sign_i.value = int(rx_sign[i]) if i < len(adc) else 0
                dut.m_log2_i.value = m_sched(i)
            await RisingEdge(self.clk)
            await ReadOnly()
            if ce:
                i += 1
            # POST_CLK = 1 (default): out_valid_o is a one-clk pulse, on any clk
            if int(dut.out_valid_o.value):
                v = int(dut.out_hm_o.value)
                outs.append((int(dut.out_row_o.value), v & ((1 << hw) - 1), v >> hw,
                             int(dut.out_last_row_o.value)))
        return outs


def check(tb, outs, exp, tag):
    cfg = tb.cfg
    order = R.row_order(cfg).tolist()
    nfr = exp.shape[0]
    assert len(outs) >= nfr * cfg.rows, f"{tag}: {len(outs)} rows out, expected {nfr * cfg.rows}"
    for f in range(nfr):
        fr = outs[f * cfg.rows:(f + 1) * cfg.rows]
        assert [o[0] for o in fr] == order, f"{tag} frame {f}: row order"
        assert [o[3] for o in fr] == [0] * (cfg.rows - 1) + [1], f"{tag} frame {f}: out_last_row_o"
        for r, a, b, _ in fr:
            assert (a, b) == (exp[f, r, 0], exp[f, r, 1]), \
                f"{tag} frame {f} row {r}: rtl ({a}, {b}) model {tuple(exp[f, r])}"


@cocotb.test()
async def exact_pn_m(dut):
    tb = TB(dut)
    cfg = tb.cfg
    rng = np.random.default_rng(21)
    for m_log2, every in ((0, 1), (1, 3), (2, 1)):
        wins = 2 << m_log2
        s = wins * cfg.n_fft
        tx, rx, _ = rx_stim.pn(cfg, s, rng)
        adc = rx_stim.tones(cfg, s, rng, tx=tx)[:, :2]
        await tb.reset()
        outs = await tb.run(adc, rx, lambda i: m_log2, every)
        exp, _, flags = R.rx_heatmaps_fixed(adc, rx, cfg, m_log2, mag_frac=0)
        check(tb, outs, exp, f"M={1 << m_log2} ce/{every}")
        if m_log2 > 0:
            # the zero tail (N + 60 samples) never completes another frame of M >= 2
            # windows: any extra row would be one emitted outside a frame's last window
            assert len(outs) == exp.shape[0] * cfg.rows, "rows outside the last window of a frame"
        assert int(dut.sat_o.value) == int(flags.sat) and int(dut.fft_ovf_o.value) == 0


@cocotb.test()
async def random_words_and_saturation(dut):
    tb = TB(dut)
    cfg = tb.cfg
    n = cfg.n_fft
    rng = np.random.default_rng(22)
    adc = rx_stim.uniform_random(cfg, 2 * n, rng)[:, :2]
    t = np.arange(n)
    full = (1 << (cfg.adc_bits - 1)) - 1
    adc[n:, 0] = np.round(full * np.cos(2 * np.pi * cfg.bins[2] * t / n))
    # rail-to-rail square wave (palm-like saturated column): its fundamental is 4/pi x
    # full scale, above the largest cell
    adc[n:, 1] = np.where(np.cos(2 * np.pi * cfg.bins[1] * t / n) >= 0, full, -full - 1)
    rx = np.zeros(2 * n, dtype=np.uint8)
    await tb.reset()
    outs = await tb.run(adc, rx, lambda i: 0)
    exp, _, flags = R.rx_heatmaps_fixed(adc, rx, cfg, 0, mag_frac=0)
    check(tb, outs, exp, "random/full-scale")
    assert flags.sat, "the square wave must saturate its cell in the model"
    assert int(dut.sat_o.value) == 1
    assert exp[1, 1, 1] == (1 << cfg.hm_width) - 1


@cocotb.test()
async def m_change_at_frame_start(dut):
    """m_log2_i changes in the middle of a frame: the new M starts with the next frame."""
    tb = TB(dut)
    cfg = tb.cfg
    n = cfg.n_fft
    rng = np.random.default_rng(23)
    adc = rx_stim.tones(cfg, 6 * n, rng)[:, :2]
    rx = np.zeros(6 * n, dtype=np.uint8)
    await tb.reset()
    # frame 0 = windows 0, 1 (M = 2); M = 4 requested during window 1 -> windows 2..5
    outs = await tb.run(adc, rx, lambda i: 1 if i < n + n // 2 else 2)
    e1, _, _ = R.rx_heatmaps_fixed(adc[:2 * n], rx[:2 * n], cfg, 1, mag_frac=0)
    e2, _, _ = R.rx_heatmaps_fixed(adc[2 * n:], rx[2 * n:], cfg, 2, mag_frac=0)
    check(tb, outs, np.concatenate([e1, e2]), "M 2 -> 4")


@pytest.mark.parametrize("cfg_name", ["small", "medium"])
def test_fmt_col_pair_rx(sim, cfg_name):
    p = params.get(cfg_name).verilog_params()
    run_cocotb(
        sim=sim,
        toplevel="fmt_col_pair_rx",
        sources=sources("fmt_col_pair_rx"),
        test_module="test_fmt_col_pair_rx",
        test_dir=Path(__file__).parent,
        parameters={k: p[k] for k in ("LOG2_N", "ROWS", "BIN_LO", "BIN_STEP", "ADC_BITS", "HM_W")},
        extra_env={"CFG": cfg_name},
        build_args=[rom_define()] + (["--output-split", "0", "-CFLAGS", "-O0"] if sim == "verilator" else []),
    )
