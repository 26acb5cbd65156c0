"""cocotb testbench of the simulation-only channel bench/core/fmt_channel_sim.v
against its twin sim/fmt/channel.py channel_sim_fixed.

Random row words and a random ce pattern; the coupling matrix is loaded through the
update port and replaced twice during the run by updates stamped with the sample at
which they apply (the second with large couplings, to force clipping); noise words
come from a $readmemh file written by the model.  Every ADC word, the per-sample clip
flag, the sticky flag and the sample index equal the model's.  MEDIUM under both
simulators, SMALL under Icarus (Verilator too with FMT_DDS_FULL=1).
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import BUILD, run_cocotb
from common.tb_util import ClockedTB, env_int, env_str
from fmt import channel, params
from fmt_dds_bank.dds_driver import skip_extra_verilator_build

ROOT = Path(__file__).resolve().parents[2]
COUP_BITS, COUP_FRAC, NOISE_BITS, NOISE_FRAC, NOISE_LEN = 16, 16, 16, 4, 64


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.rows, self.cols = self.cfg.rows, self.cfg.cols
        self.noise = np.load(env_str("NOISE_NPY", ""))
        for s in ("ce", "upd_we_i", "upd_chg_i", "upd_row_i", "upd_col_i", "upd_data_i", "upd_commit_i",
                  "upd_stamp_i", "dac_i"):
            getattr(dut, s).value = 0

    def adc(self):
        v = int(self.dut.adc_o.value)
        b = self.cfg.adc_bits
        w = np.array([(v >> (c * b)) & ((1 << b) - 1) for c in range(self.cols)], dtype=np.int64)
        return np.where(w >= 1 << (b - 1), w - (1 << b), w)


@cocotb.test()
async def bit_exact_with_stamped_updates(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 7))
    cfg = tb.cfg
    await tb.reset()
    mats = []

    async def load(g, stamp):
        for r in range(tb.rows):
            for c in range(tb.cols):
                dut.upd_we_i.value = 1
                dut.upd_row_i.value = r
                dut.upd_col_i.value = c
                dut.upd_data_i.value = int(g[r, c])
                await RisingEdge(tb.clk)
                await tb.writable()
                dut.upd_we_i.value = 0
                await step()
        dut.upd_commit_i.value = 1
        dut.upd_stamp_i.value = stamp
        await RisingEdge(tb.clk)
        await tb.writable()
        dut.upd_commit_i.value = 0
        await step()

    dacs, obs, clips, stick, idx = [], [], [], [], []
    state = {"ce_on": False, "k": 0}
    dmax = (1 << (cfg.dac_bits - 1)) - 1

    async def step():
        """One more cycle of the sample stream (only once the stream is running)."""
        if not state["ce_on"]:
            return
        ce = int(rng.random() < 0.8)
        words = [rng.randint(-dmax, dmax) for _ in range(tb.rows)]
        dut.ce.value = ce
        dut.dac_i.value = sum((w & ((1 << cfg.dac_bits) - 1)) << (r * cfg.dac_bits)
                              for r, w in enumerate(words))
        await RisingEdge(tb.clk)
        await ReadOnly()
        if ce:
            dacs.append(words)
            obs.append(tb.adc())
            clips.append(int(dut.clip_o.value))
            stick.append(int(dut.clip_sticky_o.value))
            idx.append(int(dut.sample_o.value))
            state["k"] += 1
        await tb.writable()
        dut.ce.value = 0

    g0 = np.array([[rng.randrange(0, 1 << 14) for _ in range(tb.cols)] for _ in range(tb.rows)])
    await load(g0, 0)                         # before the stream: in effect from sample 0
    state["ce_on"] = True
    updates = []
    for big in (False, True):
        for _ in range(rng.randrange(20, 60)):
            await step()
        hi = (1 << COUP_BITS) - 1 if big else 1 << 14
        g = np.array([[rng.randrange(0, hi) for _ in range(tb.cols)] for _ in range(tb.rows)])
        # the stamp lies beyond the cycles the load itself takes
        stamp = state["k"] + tb.rows * tb.cols + rng.randrange(1, 20)
        await load(g, stamp)
        updates.append((stamp, g))
        while state["k"] <= stamp + 5:
            await step()
    for _ in range(30):
        await step()

    adc, clip = channel.channel_sim_fixed(np.array(dacs), g0, updates, tb.noise, adc_bits=cfg.adc_bits,
                                      coup_frac=COUP_FRAC, noise_frac=NOISE_FRAC)
    obs = np.array(obs)
    assert idx == list(range(len(idx))), "sample index"
    bad = np.argwhere(obs != adc)
    assert bad.size == 0, f"{len(bad)} ADC mismatches, first at sample {bad[0][0]}"
    assert np.array_equal(np.array(clips, dtype=bool), clip), "clip flag"
    assert np.array_equal(np.array(stick, dtype=bool), np.maximum.accumulate(clip)), "sticky clip"
    assert clip.any() and not clip[:updates[1][0]].any(), "clipping starts with the big update"


@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM], ids=lambda c: c.name)
def test_fmt_channel_sim(sim, cfg):
    skip_extra_verilator_build(sim, cfg is params.SMALL)
    out = BUILD / "channel_noise"
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(11)
    noise = np.clip(np.rint(rng.normal(0, 3 * (1 << NOISE_FRAC), size=(NOISE_LEN, cfg.cols))),
                    -(1 << (NOISE_BITS - 1)), (1 << (NOISE_BITS - 1)) - 1).astype(np.int64)
    hexf, npyf = out / f"{cfg.name}.hex", out / f"{cfg.name}.npy"
    channel.write_noise_hex(hexf, noise, NOISE_BITS)
    np.save(npyf, noise)
    p = cfg.verilog_params()
    run_cocotb(
        sim=sim,
        toplevel="fmt_channel_sim",
        sources=[ROOT / "bench" / "core" / "fmt_channel_sim.v"],
        test_module="test_fmt_channel_sim",
        test_dir=Path(__file__).parent,
        parameters={**{k: p[k] for k in ("ROWS", "COLS", "DAC_BITS", "ADC_BITS")},
                    "COUP_BITS": COUP_BITS, "COUP_FRAC": COUP_FRAC,
                    "NOISE_BITS": NOISE_BITS, "NOISE_FRAC": NOISE_FRAC, "NOISE_LEN": NOISE_LEN,
                    "NOISE_FILE": f'"{hexf}"'},
        extra_env={"CFG": cfg.name, "NOISE_NPY": npyf},
        build_args=["-CFLAGS", "-O0"] if sim == "verilator" else [],
    )
