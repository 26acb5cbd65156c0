"""The scene effects of the ``make sim`` channel (issue #12 item 1).

The channel of the RTL bench applies every additive effect of a scene -- counter-based
Gaussian noise, DC offset, interferers, ENOB, channel delay (with the PN receive delay
that matches it) -- bit-exact in numpy (``fmt.channel.FixedEffects``,
``channel_sim_fixed``, ``run_sim_rtl.channel_fixed``), C++ (bench/core/channel_fx.h,
sim_main.cpp) and Verilog (bench/core/fmt_channel_sim.v); a scene effect the RTL path
cannot apply stops the run with one line naming it.

* the noise / interferer words of numpy, C++ (g++ on channel_fx.h) and Verilog (Icarus,
  fmt_channel_sim's functions) agree word for word, also across the 32-bit sample wrap;
* the noise variance equals sigma_q^2 within the stated tolerance, and it does not repeat;
* fmt_channel_sim (Icarus) equals ``channel_sim_fixed`` with every effect on (random row
  words, clipping, ENOB, delay) and the int64 twin ``channel_fixed`` equals it too;
* every effect through the whole core on the small sensor (cocotb engine, Icarus): heat
  maps and events bit-exact with the model, and the effect changes the model's heat maps;
* all effects at once through the C++ harness (Verilator), C++ and Verilog channel;
* tone_phases "schroeder" (no DDS phase register) and out-of-range settings are refused
  before anything is built, with one line naming the effect.
"""
from __future__ import annotations

import inspect
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from bench.core import run_sim_rtl as rsr
from common.runner import long_run
from fmt import channel as ch
from fmt import params
from fmt import scene as _scene

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench" / "core"
HAS_IVERILOG = shutil.which("iverilog") is not None


def fx_all(cfg=params.SMALL, seed: int = 9) -> ch.FixedEffects:
    """Every additive effect on: noise, DC, interferers (a row bin; a fractional frequency
    with a phase; a rising and a falling sweep, one of them in bursts that started before
    sample 0), display harmonics, charger noise (a square wave and a harmonic), ENOB 10,
    delay 5."""
    fs = cfg.fs_hz
    sc = _scene.Scene(name="fx", sensor=cfg.name, frames=1, seed=seed, contacts=[],
                      effects={"noise": {"rms_lsb": 37.7}, "dc_lsb": -13.3, "enob": 10,
                               "delay_samples": 5,
                               "interferer": [{"bin": cfg.bins[1], "amp_lsb": 150.0},
                                              {"freq_hz": 1.234e6, "amp_lsb": 77.7, "phase_rad": 1.0},
                                              {"freq_hz": 3.0e6, "amp_lsb": 60.0, "sweep_hz_per_s": 2.5e11},
                                              {"freq_hz": 9.0e6, "amp_lsb": 55.0, "sweep_hz_per_s": -4.0e11,
                                               "burst": {"period_s": 97 / fs, "on_s": 40 / fs,
                                                         "start_s": -13 / fs}}],
                               "display": {"line_hz": 61.5e3, "harmonics": [[83, 20.0], [90, 11.0, 0.3]]},
                               "charger": {"freq_hz": 97e3, "level": 0.7}})
    e = ch.fixed_effects(sc)
    sc2 = sc.replace(effects={"charger": {"freq_hz": 123e3, "level": 1.5, "harmonics": [[41, 0.4]]}})
    return ch.FixedEffects(**{**e.__dict__, "interferers": e.interferers + ch.fixed_effects(sc2).interferers})


# ---- the generator: numpy == C++ == Verilog ------------------------------------------
def _dump_cpp(tmp: Path, k0: int, n: int, cols: int) -> np.ndarray:
    src = tmp / "dump.cpp"
    src.write_text(
        '#include "channel_fx.h"\n#include <cstdlib>\n'
        "int main(int, char** argv) {\n  Effects fx;\n"
        "  const std::string e = fx.load(argv[1], argv[2], argv[3]);\n"
        '  if (!e.empty()) { std::fprintf(stderr, "%s\\n", e.c_str()); return 2; }\n'
        "  const unsigned long long k0 = std::strtoull(argv[4], nullptr, 10);\n"
        "  const long n = std::atol(argv[5]); const int cols = std::atoi(argv[6]);\n"
        "  for (long i = 0; i < n; ++i) {\n"
        "    const uint32_t k = static_cast<uint32_t>(k0 + i);\n"
        '    for (int c = 0; c < cols; ++c) std::printf("%lld ", static_cast<long long>(fx.noise(k, c)));\n'
        '    std::printf("%lld %lld\\n", static_cast<long long>(fx.common(k)), static_cast<long long>(fx.charger(k)));\n'
        "  }\n  return 0;\n}\n")
    exe = tmp / "dump"
    subprocess.run(["g++", "-O1", "-std=c++17", f"-I{BENCH}", str(src), "-o", str(exe)], check=True)
    out = subprocess.run([str(exe), str(tmp / "chan.hex"), str(tmp / "gauss.hex"), str(tmp / "sine.hex"),
                          str(k0), str(n), str(cols)], check=True, capture_output=True, text=True).stdout
    return np.array([[int(v) for v in line.split()] for line in out.splitlines()], dtype=np.int64)


def _dump_verilog(tmp: Path, k0: int, n: int, cols: int) -> np.ndarray:
    tb = tmp / "tb_fx.v"
    tb.write_text(f"""`timescale 1ns/1ps
module tb_fx;
  wire [{cols}*12-1:0] adc; wire cl, cs; wire [31:0] so;
  fmt_channel_sim #(.ROWS(1), .COLS({cols}), .DAC_BITS(12), .ADC_BITS(12),
    .CHAN_FILE("{tmp / 'chan.hex'}"), .GAUSS_FILE("{tmp / 'gauss.hex'}"), .SINE_FILE("{tmp / 'sine.hex'}"))
  u_ch (.clk(1'b0), .rst(1'b1), .ce(1'b0), .dac_i(12'd0), .upd_we_i(1'b0), .upd_chg_i(1'b0), .upd_row_i(1'b0),
    .upd_col_i({{$clog2({cols}){{1'b0}}}}), .upd_data_i(16'd0), .upd_commit_i(1'b0), .upd_stamp_i(32'd0),
    .adc_o(adc), .clip_o(cl), .clip_sticky_o(cs), .sample_o(so));
  integer i, c, fh;
  reg [31:0] k;
  initial begin
    #1;
    fh = $fopen("{tmp / 'v.txt'}", "w");
    for (i = 0; i < {n}; i = i + 1) begin
      k = 32'd{k0 & 0xFFFFFFFF} + i;
      for (c = 0; c < {cols}; c = c + 1) $fwrite(fh, "%0d ", u_ch.fx_noise(k, c[7:0]));
      $fwrite(fh, "%0d %0d\\n", u_ch.fx_common(k), u_ch.fx_osc(k, 1'b1));
    end
    $fclose(fh);
    $finish;
  end
endmodule
""")
    vvp = tmp / "tb_fx.vvp"
    subprocess.run(["iverilog", "-g2005", f"-I{ROOT / 'rtl'}", "-o", str(vvp), str(tb),
                    str(BENCH / "fmt_channel_sim.v")], check=True)
    subprocess.run(["vvp", "-n", str(vvp)], check=True, capture_output=True)
    return np.array([[int(v) for v in line.split()] for line in (tmp / "v.txt").read_text().splitlines()],
                    dtype=np.int64)


@pytest.mark.skipif(not HAS_IVERILOG or shutil.which("g++") is None, reason="needs iverilog and g++")
@pytest.mark.parametrize("k0", [0, (1 << 32) - 700], ids=["k0", "wrap"])
def test_generator_numpy_cpp_verilog_word_for_word(tmp_path, k0):
    eff = fx_all()
    rsr.write_channel_files(tmp_path, eff)
    n, cols = 1500, 6                                      # 9000 noise words, 1500 common terms
    py = np.column_stack([eff.noise(k0, n, cols), eff.additive(k0, n, 1)[:, 0] - eff.noise(k0, n, 1)[:, 0],
                          eff.charger(k0, n)])
    assert np.count_nonzero(py[:, :cols]) > 0.99 * n * cols and np.unique(py[:, cols]).size > 100
    assert np.unique(py[:, cols + 1]).size > 100
    cpp = _dump_cpp(tmp_path, k0, n, cols)
    assert np.array_equal(cpp, py), f"C++ differs at {np.argwhere(cpp != py)[:3].tolist()}"
    ver = _dump_verilog(tmp_path, k0, n, cols)
    assert np.array_equal(ver, py), f"Verilog differs at {np.argwhere(ver != py)[:3].tolist()}"


def test_noise_variance_and_no_repeat():
    """Sample variance of 400k words = (sigma_q / 2^8)^2 within 1 % (the statistical
    sigma of the estimate is 0.22 %); the table itself has unit variance within 1e-5;
    sigma_q is sigma rounded to 2^-8 LSB; windows 512 apart (the old file's period) differ."""
    t = ch.gauss_table().astype(np.float64) / (1 << ch.GAUSS_FRAC)
    assert abs(np.mean(t * t) - 1.0) < 1e-5 and t.mean() == 0.0 and abs(t).max() < 4.4
    for sigma in (3.0, 59.03, 118.06):
        sc = _scene.Scene(name="n", sensor="small", frames=1, seed=3, contacts=[],
                          effects={"noise": {"rms_lsb": sigma}})
        eff = ch.fixed_effects(sc)
        assert abs(eff.sigma_q / 256 - sigma) <= 1 / 512
        w = eff.noise(0, 100_000, 4).astype(np.float64) / (1 << ch.ADD_FRAC)
        assert abs(w.var() / (eff.sigma_q / 256) ** 2 - 1.0) < 0.01, (sigma, w.var())
        assert abs(w.mean()) < 4 * sigma / np.sqrt(w.size)
    eff = fx_all()
    n = params.SMALL.n_fft
    a = eff.noise(0, n, 6)
    for per in (512, 4096):
        b = eff.noise(per * n, n, 6)
        assert not np.array_equal(a, b)
        assert abs(np.corrcoef(a.ravel(), b.ravel())[0, 1]) < 0.15
    # neighbouring columns and samples are uncorrelated
    w = eff.noise(0, 50_000, 2).astype(np.float64)
    assert abs(np.corrcoef(w[:, 0], w[:, 1])[0, 1]) < 0.02
    assert abs(np.corrcoef(w[1:, 0], w[:-1, 0])[0, 1]) < 0.02


def test_channel_fixed_equals_channel_sim_fixed_with_effects():
    cfg = params.SMALL
    rng = np.random.default_rng(3)
    n = 400
    dac = rng.integers(-2047, 2048, size=(n, cfg.rows))
    g0 = rng.integers(0, 1 << 15, size=(cfg.rows, cfg.cols))
    ups = [(150, rng.integers(0, 1 << 16, size=(cfg.rows, cfg.cols)))]
    eff = fx_all(cfg)
    a, clip_a = ch.channel_sim_fixed(dac, g0, ups, None, adc_bits=12, effects=eff)
    b, clip_b = rsr.channel_fixed(dac, g0, ups, eff, 12)
    assert np.array_equal(a, b) and int(clip_a.sum()) == clip_b > 0
    assert not (a & 3).any()                                     # ENOB 10: 2 low bits clear
    # the delay: the first 5 samples see no row words (the delay line starts at 0)
    e0 = ch.FixedEffects(delay=5)
    c, _ = ch.channel_sim_fixed(dac, g0, (), None, effects=e0)
    d, _ = ch.channel_sim_fixed(np.vstack([np.zeros((5, cfg.rows), np.int64), dac[:-5]]), g0, ())
    assert np.array_equal(c, d) and not c[:5].any()


@pytest.mark.skipif(not HAS_IVERILOG, reason="Icarus not installed")
def test_fmt_channel_sim_effects_icarus(tmp_path):
    """fmt_channel_sim with CHAN_FILE (every effect on) against channel_sim_fixed: random
    row words on a ce every other clk, G and the charger weights W loaded before the
    stream, a second matrix (and W) that clips; every ADC word and clip flag."""
    cfg = params.SMALL
    rows, cols, n = cfg.rows, cfg.cols, 600
    rng = np.random.default_rng(8)
    dac = rng.integers(-2047, 2048, size=(n, rows))
    g0 = rng.integers(0, 1 << 14, size=(rows + 1, cols))        # row ROWS: charger weights
    g1 = rng.integers(0, 1 << 16, size=(rows + 1, cols))
    g0[rows] = rng.integers(1 << 10, 1 << 12, size=cols)         # weights 0.25 .. 1
    g0[rows, 2] = 0                                               # no charger on column 2
    stamp = 300
    eff = fx_all(cfg, seed=21)
    rsr.write_channel_files(tmp_path, eff)
    (tmp_path / "dac.hex").write_text("".join(
        "".join(f"{int(v) & 0xFFF:03x}" for v in row[::-1]) + "\n" for row in dac))
    loads = []
    for g, st in ((g0, 0), (g1, stamp)):
        for r in range(rows + 1):
            for c in range(cols):
                loads.append(f"ld({r % rows}, {c}, {int(g[r, c])}, {int(r == rows)});")
        loads.append(f"cm({st});")
    tb = tmp_path / "tb_ch.v"
    tb.write_text(f"""`timescale 1ns/1ps
module tb_ch;
  reg clk = 1'b0, rst = 1'b1, ce = 1'b0, we = 1'b0, wc = 1'b0, cmt = 1'b0;
  reg [{rows * 12 - 1}:0] dac_i = 0;
  reg [1:0] row = 0; reg [2:0] col = 0; reg [15:0] data = 0; reg [31:0] st = 0;
  wire [{cols * 12 - 1}:0] adc; wire cl, cs; wire [31:0] so;
  reg [{rows * 12 - 1}:0] mem [0:{n - 1}];
  fmt_channel_sim #(.ROWS({rows}), .COLS({cols}), .DAC_BITS(12), .ADC_BITS(12),
    .CHAN_FILE("{tmp_path / 'chan.hex'}"), .GAUSS_FILE("{tmp_path / 'gauss.hex'}"),
    .SINE_FILE("{tmp_path / 'sine.hex'}"))
  u_ch (.clk(clk), .rst(rst), .ce(ce), .dac_i(dac_i), .upd_we_i(we), .upd_chg_i(wc), .upd_row_i(row),
    .upd_col_i(col), .upd_data_i(data), .upd_commit_i(cmt), .upd_stamp_i(st),
    .adc_o(adc), .clip_o(cl), .clip_sticky_o(cs), .sample_o(so));
  always #5 clk = ~clk;
  integer i, fh;
  task ld(input integer r, input integer c, input integer v, input integer w);
    begin @(negedge clk); we = 1; wc = w; row = r; col = c; data = v; @(negedge clk); we = 0; wc = 0; end
  endtask
  task cm(input integer s);
    begin @(negedge clk); cmt = 1; st = s; @(negedge clk); cmt = 0; end
  endtask
  initial begin
    $readmemh("{tmp_path / 'dac.hex'}", mem);
    fh = $fopen("{tmp_path / 'adc.txt'}", "w");
    repeat (3) @(negedge clk);
    rst = 0;
    {" ".join(loads[:(rows + 1) * cols + 1])}
    @(negedge clk); @(negedge clk);
    for (i = 0; i < {n}; i = i + 1) begin
      @(negedge clk); ce = 1; dac_i = mem[i];
      @(posedge clk); #1 $fwrite(fh, "%0d %0d %h\\n", so, cl, adc);
      @(negedge clk); ce = 0;
      if (i == 100) begin {" ".join(loads[(rows + 1) * cols + 1:])} end
    end
    $fclose(fh);
    $finish;
  end
endmodule
""")
    vvp = tmp_path / "tb_ch.vvp"
    subprocess.run(["iverilog", "-g2005", f"-I{ROOT / 'rtl'}", "-o", str(vvp), str(tb),
                    str(BENCH / "fmt_channel_sim.v")], check=True)
    subprocess.run(["vvp", "-n", str(vvp)], check=True, capture_output=True)
    lines = (tmp_path / "adc.txt").read_text().split("\n")[:-1]
    got = np.zeros((n, cols), dtype=np.int64)
    clips = np.zeros(n, dtype=bool)
    for line in lines:
        s, cl, hx = line.split()
        v = int(hx, 16)
        w = np.array([(v >> (12 * c)) & 0xFFF for c in range(cols)])
        got[int(s)] = np.where(w >= 2048, w - 4096, w)
        clips[int(s)] = cl == "1"
    assert len(lines) == n
    # the second load takes ~2 * (rows * cols + 1) samples from sample 100: in effect at the stamp
    exp, clip = ch.channel_sim_fixed(dac, g0, [(stamp, g1)], None, adc_bits=12, effects=eff)
    bad = np.argwhere(got != exp)
    assert bad.size == 0, f"{len(bad)} ADC mismatches, first at {bad[0].tolist()}: {got[bad[0][0]]} vs {exp[bad[0][0]]}"
    assert np.array_equal(clips, clip) and clip.any() and not clip[:stamp].any()
    # the charger reaches a column only through its weight: W = 0 on column 2 before the stamp
    noc, _ = ch.channel_sim_fixed(dac, g0[:rows], [(stamp, g1[:rows])], None, adc_bits=12, effects=eff)
    diff = (noc != exp)[:stamp]
    assert not diff[:, 2].any() and diff[:, [0, 1, 3, 4, 5]].mean() > 0.5


# ---- every effect through the whole core --------------------------------------------------
EFFECTS = {
    "interferer": {"interferer": [{"bin": 10, "amp_lsb": 120.0},
                                  {"bin": 11.5, "amp_lsb": 90.0, "phase_rad": 0.7}]},
    "dc_lsb": {"dc_lsb": 250.5},
    "enob": {"enob": 7},
    "delay_samples": {"delay_samples": 7},
    "pn_rx_mismatch": {"delay_samples": 3, "pn": {"enable": True, "chip_len": 2, "rx_delay": 1}},
    "noise_rms": {"noise": {"rms_lsb": 80.0}},
    # a sweep across the comb (row bins 9..12 of the small sensor) in bursts, and a fixed
    # tone in bursts that start in the second window
    "interferer_sweep_burst": {"interferer": [
        {"bin": 8.7, "amp_lsb": 150.0, "sweep_hz_per_s": 3.0e11,
         "burst": {"period_s": 5.0e-6, "on_s": 2.0e-6, "start_s": 1.0e-6}},
        {"bin": 11, "amp_lsb": 120.0, "burst": {"period_s": 3.1e-6, "on_s": 0.9e-6, "start_s": 1.6e-6}}]},
    "display": {"display": {"line_hz": 65.1e3, "harmonics": [[100, 60.0], [150, 40.0, 1.0], [170, 30.0]]}},
    # the small scene's drag lands in window 5: the charger reaches the RTL through the
    # weights of both contacts, changing at that onset sample
    "charger": {"charger": {"freq_hz": 93e3, "level": 1.0}},
    "charger_harmonics": {"charger": {"freq_hz": 130.2e3, "level": 2.0, "harmonics": [[75, 0.5], [80, 0.3]]}},
}


def effect_scene(name: str, frames: int = 6) -> _scene.Scene:
    sc = _scene.small_scene()
    return sc.replace(frames=frames, effects={**sc.effects, **EFFECTS[name]})


# through the core one by one (~15 s each); display noise and charger harmonics run
# through the core in noise_small.json (display) and the harness test (both)
CORE_ONE_BY_ONE = sorted(set(EFFECTS) - {"display", "charger_harmonics"})


# make test runs one by one only the effects that no other core run of make test has:
# these are in test_all_effects_harness (both channels, Verilator) or, the charger, in
# test_coupling_effects_through_core_icarus; make test-long (FMT_LONG=1) runs all
COVERED_IN_MAKE_TEST = {"interferer", "dc_lsb", "enob", "delay_samples", "noise_rms",
                        "interferer_sweep_burst", "charger"}


@pytest.mark.skipif(not HAS_IVERILOG, reason="Icarus not installed")
@pytest.mark.parametrize("name", CORE_ONE_BY_ONE)
def test_effect_through_core_icarus(tmp_path, name):
    if name in COVERED_IN_MAKE_TEST and not long_run():
        pytest.skip(f"{name}: through the core in another run of make test (the harness test "
                    "or the coupling test); one by one in make test-long (FMT_LONG=1)")
    sc = effect_scene(name)
    base = _scene.small_scene().replace(frames=sc.frames)
    n = sc.frames * sc.samples_per_frame
    g0, ups = rsr.coupling_plan(sc, n, 3)
    r0 = rsr.model_reference(base, g0, ups, rsr.check_scene(base), sc.frames, rsr.TouchSettings(), None)
    r1 = rsr.model_reference(sc, g0, ups, rsr.check_scene(sc), sc.frames, rsr.TouchSettings(), None)
    assert not np.array_equal(r0.heatmaps, r1.heatmaps), f"{name} does not change the heat maps"
    rep = rsr.run(sc, tmp_path, frames=sc.frames, cps=3, sim="icarus", engine="cocotb", plot=False, quiet=True,
                  tag=f"fx_{name}")        # its own job folder: the effects run side by side under xdist
    assert rep["frames"] >= sc.frames and rep["frames_dropped"] == 0
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]


@pytest.mark.skipif(not HAS_IVERILOG, reason="Icarus not installed")
def test_coupling_effects_through_core_icarus(tmp_path):
    """A finger landing (strength and diameter over time, ``size_path``), a drifting
    baseline (1e5 %/s: the integer matrices move within a few windows) and charger noise
    through the core: the plan's per-window coupling and charger weights, bit-exact."""
    sc = _scene.small_scene()
    win = sc.cfg.n_fft / sc.cfg.fs_hz
    still = dict(sc.contacts[0].to_dict(), size_path=[[win, 0.2, 4.0], [4 * win, 1.0, 9.0]])
    sc = sc.replace(frames=8, contacts=[still, sc.contacts[1].to_dict()],
                    effects={**sc.effects, **EFFECTS["charger"],
                             "drift": {"gain_pct_per_s": 1e5, "offset_pct_per_s": 5e4}})
    n = sc.frames * sc.samples_per_frame
    g0, ups = rsr.coupling_plan(sc, n, 3)
    assert g0.shape[0] == sc.cfg.rows + 1 and sum(1 for s, _ in ups if s >= 6 * sc.cfg.n_fft) >= 2
    rep = rsr.run(sc, tmp_path, frames=sc.frames, cps=3, sim="icarus", engine="cocotb", plot=False, quiet=True,
                  tag="fx_coupling")
    assert rep["frames"] >= sc.frames and rep["frames_dropped"] == 0
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]


@pytest.mark.skipif(not HAS_IVERILOG, reason="Icarus not installed")
def test_noise_small_scene_through_core_icarus(tmp_path):
    """The shipped sim/scenes/noise_small.json (every noise effect of issue #12 item 2 at
    once: charger, display, sweeping bursty interferer, drift, a landing finger), its first
    10 frames through the core: golden 0."""
    sc = _scene.load(ROOT / "sim" / "scenes" / "noise_small.json")
    rep = rsr.run(sc, tmp_path, frames=10, cps=3, sim="icarus", engine="cocotb", plot=False, quiet=True,
                  tag="fx_noise_small")
    assert rep["frames"] >= 10 and rep["frames_dropped"] == 0
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]


@pytest.mark.skipif(not HAS_IVERILOG, reason="Icarus not installed")
@pytest.mark.parametrize("cps,chip_len", [(1, 3), (2, 4)])
def test_pn_chip_len_through_core_icarus(tmp_path, cps, chip_len):
    """chip_len > 1 at other clk per sample: the model's PN signs follow the core's
    (pn_rtl: the first pn_chip_first samples step with the reset chip length 1)."""
    sc = _scene.small_scene()
    sc = sc.replace(frames=4, effects={**sc.effects, "pn": {"enable": True, "chip_len": chip_len}})
    assert rsr.pn_chip_first(sc, cps) == -(-(2 + rsr.REG_LAT) // cps)
    rep = rsr.run(sc, tmp_path, frames=sc.frames, cps=cps, sim="icarus", engine="cocotb", plot=False, quiet=True,
                  tag=f"pn_c{cps}")
    assert rep["frames_dropped"] == 0 and rep["golden_mismatches"] == 0, rep["golden_detail"]


def harness_effects(base: dict) -> dict:
    """The effects of test_all_effects_harness: all of them at once."""
    eff = dict(base)
    for k in ("interferer", "dc_lsb", "enob", "display", "charger_harmonics"):
        eff.update(EFFECTS[k])
    eff["interferer"] = eff["interferer"] + EFFECTS["interferer_sweep_burst"]["interferer"]
    eff.update({"delay_samples": 6, "noise": {"rms_lsb": 70.0}})
    return eff


def test_covered_effects_are_in_other_core_runs():
    """Every effect make test does not run one by one is in the harness run (each of its
    keys; its interferers among the harness's), or is the charger of the coupling run."""
    eff = harness_effects(_scene.small_scene().effects)
    for name in COVERED_IN_MAKE_TEST - {"charger"}:
        for k, v in EFFECTS[name].items():
            assert k in eff, (name, k)
            if k == "interferer":
                assert all(i in eff[k] for i in v), name
    assert 'EFFECTS["charger"]' in inspect.getsource(test_coupling_effects_through_core_icarus)


@pytest.mark.verilator_only
@pytest.mark.parametrize("vch", [False, True], ids=["cpp_channel", "verilog_channel"])
def test_all_effects_harness(sim, vch):
    """Every effect at once through the C++ harness (its C++ channel, and the Verilog
    channel of the top for the cross-check); small sensor, -O0 build."""
    assert sim == "verilator"
    sc = _scene.small_scene().replace(frames=10)
    sc = sc.replace(effects=harness_effects(sc.effects))
    d, ref, cal, n_upd, res, _b = rsr.run_harness(sc, sc.frames, 3, None, cal="scene", tag="tb_fx",
                                                  quiet=True, cflags="-O0", verilog_channel=vch)
    rep = rsr.analyse(sc, ref, d, 3, res["status"], sc.frames, res["wall_s"], None, False, cal)
    assert rep["frames"] >= sc.frames and rep["frames_dropped"] == 0
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    assert res["upd_late"] == 0


# ---- refusals ---------------------------------------------------------------------------
REFUSED = {
    "tone_phases": ({"tone_phases": "schroeder"}, "tone_phases"),
    "delay_samples": ({"delay_samples": 80}, "delay_samples"),
    "pn_rx_delay": ({"pn": {"enable": True, "chip_len": 1, "rx_delay": 70}}, "effect pn"),
    "interferers": ({"interferer": [{"bin": 10, "amp_lsb": 1.0}] * 60,
                     "display": {"line_hz": 1e5, "harmonics": [[h, 1.0] for h in range(1, 6)]}},
                    "interferer/display: 65 oscillators"),
    "enob": ({"enob": 7.5}, "enob"),
}


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_refused_before_build(tmp_path, monkeypatch, capsys, name):
    eff, word = REFUSED[name]
    sc = _scene.small_scene()
    sc = sc.replace(effects={**sc.effects, **eff})
    path = tmp_path / "s.json"
    sc.save(path)

    def no_build(*_a, **_k):
        raise AssertionError("built or prepared a refused scene")
    monkeypatch.setattr(rsr, "harness_build", no_build)
    monkeypatch.setattr(rsr, "prepare", no_build)
    assert rsr.main(["--scene", str(path), "--frames", "2", "--no-plot", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0] and "refused" in err[0], err
    with pytest.raises(ch.UnsupportedEffect):
        rsr.run(sc, None, frames=2)
