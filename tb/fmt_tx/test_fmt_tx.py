"""cocotb testbench of rtl/fmt_tx.v (fmt_pn_gen + fmt_dds_bank) against
sim/fmt/pn_gen.py + sim/fmt/dds_bank.py.

Checks, under Icarus (Verilator: MEDIUM with R = 3; all variants with FMT_DDS_FULL=1),
for ROWS_PER_ENGINE R = 1 (ce = 1) and R = 3 (ce on clk cycles 0, 3,
6, ... after reset, as fmt_core does; the PN generator steps on ce, chip length and
receive delay in samples): every DAC word bit-exact with the model for random PN
settings (chip length, PN enable toggled at random clk cycles), random DDS settings
written at random clk cycles, and a reset in the middle of a window; and the documented
alignment: with rx_delay_i = 3, rx_sign_o is the PN sign of the words on dac_o at the
same ce edge, constant between ce edges.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import env_int
from fmt import dds_bank, params
from fmt.pn_gen import MAXIMAL_TAPS, lfsr_chips
from fmt_dds_bank.dds_driver import LATENCY, TB as BankTB, build_args, skip_extra_verilator_build

ALIGN_DELAY = 3   # rx_delay_i that lines rx_sign_o up with the words on dac_o


class TB(BankTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.pn_bits = env_int("PN_BITS", self.cfg.pn_bits)
        dut.pn_enable_i.value = 1
        dut.chip_len_i.value = 1
        dut.rx_delay_i.value = ALIGN_DELAY

    async def run_tx(self, n, rng, p_toggle=0.01, p_write=0.05):
        """Clk cycles after reset until n samples (ce edges; ce on cycles 0, R, 2R, ...)
        have passed: random PN-enable toggles and DDS writes on any cycle.  Returns
        settings per sample, PN enables and rx signs per clk cycle, words per ce edge."""
        dut = self.dut
        tws, amps, ens, pen, obs, rxs = [], [], [], [], [], []
        pn_en = 1
        t = 0
        while len(obs) < n:
            if t:
                await self.writable()
            ce = int(t % self.rpe == 0)
            dut.ce.value = ce
            if rng.random() < p_toggle:
                pn_en ^= 1
            dut.pn_enable_i.value = pn_en
            write = rng.random() < p_write
            dut.cfg_we_i.value = int(write)
            if ce:
                tws.append(self.tw.copy())
                amps.append(self.amp.copy())
                ens.append(self.en.copy())
            pen.append(pn_en)
            if write:
                self.random_write(rng)
            await RisingEdge(self.clk)
            await ReadOnly()
            if ce:
                obs.append(self.words())
            rxs.append(int(dut.rx_sign_o.value))
            t += 1
        await self.writable()
        dut.cfg_we_i.value = 0
        dut.ce.value = 1 if self.rpe == 1 else 0
        return (np.array(tws), np.array(amps), np.array(ens), np.array(pen),
                np.array(obs), np.array(rxs))


def pn_tx(n, chip_len, pen, bits):
    """tx_sign_o after edge i: PN enable at edge i AND chip (i // chip_len)."""
    cl = max(1, chip_len)
    chips = lfsr_chips(n // cl + 2, bits, MAXIMAL_TAPS[bits])
    return (chips[np.arange(n) // cl].astype(np.int64) & np.asarray(pen, dtype=np.int64))


@cocotb.test()
async def bit_exact_pn_and_settings(dut):
    tb = TB(dut)
    R = tb.rpe
    rng = random.Random(env_int("SEED", 5))
    err0 = tb.ce_errors()
    for seg in range(3):
        chip_len = [1, rng.randrange(2, 5), 0][seg]        # samples per chip (0 = 1)
        await tb.writable()
        dut.chip_len_i.value = chip_len
        dut.rx_delay_i.value = ALIGN_DELAY
        dut.ce.value = 0 if R > 1 else 1
        await tb.reset()
        tb.defaults()
        n = 2 * tb.cfg.n_fft + 64   # the LFSR (seed 1) shows its first 1 at chip 14
        tw, amp, en, pen, obs, rxs = await tb.run_tx(n, rng, p_toggle=0.02 if seg else 0,
                                                     p_write=0.05 if seg else 0)
        if seg == 0:
            # reset comb, PN on: the transmit twin tx_fixed
            ref = dds_bank.tx_fixed(n, cfg=tb.cfg, pn_enable=True, chip_len=chip_len)
            assert not obs[:LATENCY].any()
            assert np.array_equal(obs[LATENCY:], ref[:n - LATENCY]), "tx_fixed mismatch"
        n_clk = len(pen)
        # the PN generator steps on ce: tx_sign_o after ce edge k (clk edge kR) = PN enable
        # at that edge AND chip (k // chip_len); it holds between ce edges
        tx = pn_tx(n, chip_len, pen[R * np.arange(n)], tb.pn_bits)
        # DDS sample k takes tx_sign_o as it is before its ce edge: sample k-1's sign
        sign = np.concatenate([[0], tx[:n - 1]])
        tb.check(tw, amp, en, sign, obs, what=f"segment {seg} chip_len {chip_len}")
        assert tx.any(), "PN active in this segment"
        assert tb.ce_errors() == err0
        # rx_sign_o (delay 3 samples) after ce edge k = tx sign of PN sample k-3 = the sign
        # of dac word k; after any clk edge t it is that of the last ce edge t // R
        rx_s = np.concatenate([np.zeros(ALIGN_DELAY, dtype=np.int64), tx[:-ALIGN_DELAY]])
        assert np.array_equal(rxs, rx_s[np.arange(n_clk) // R]), "rx_sign_o"
        assert np.array_equal(rx_s[LATENCY:], sign[:n - LATENCY]), "rx sign aligned with dac words"
        # a reset in the middle of the next window comes with the next segment
        await tb.cycles(rng.randrange(1, tb.cfg.n_fft))


@pytest.mark.parametrize("rpe", [1, 3], ids=lambda r: f"r{r}")
@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM], ids=lambda c: c.name)
def test_fmt_tx(sim, cfg, rpe):
    """Under Verilator only MEDIUM with R = 3 (the core's build) unless FMT_DDS_FULL=1:
    R = 1 under Verilator is covered by tb/fmt_dds_bank (the same bank RTL)."""
    skip_extra_verilator_build(sim, cfg is params.SMALL or rpe == 1)
    p = cfg.verilog_params()
    parameters = {k: p[k] for k in ("ROWS", "LOG2_N", "BIN_LO", "BIN_STEP", "PHASE_BITS",
                                    "AMP_BITS", "SINE_BITS", "DAC_BITS", "PN_BITS")}
    parameters.update(TAPS=MAXIMAL_TAPS[cfg.pn_bits], TABLE_ADDR=dds_bank.TABLE_ADDR,
                      ROWS_PER_ENGINE=rpe)
    run_cocotb(
        sim=sim,
        toplevel="fmt_tx",
        sources=sources("fmt_tx"),
        test_module="test_fmt_tx",
        test_dir=Path(__file__).parent,
        parameters=parameters,
        extra_env={"CFG": cfg.name, "PN_BITS": cfg.pn_bits, "RPE": rpe},
        build_args=build_args(sim),
    )
