#!/usr/bin/env python3
"""Replay ADC captures through the RTL receive back end (fmt_rx_array under Verilator,
fed from Python through cocotb) and write the heat maps.

    source scripts/env.sh
    python scripts/replay_rx.py --in captures.npy --out heatmaps.npy [--config default|small|medium]
                                [--m 1] [--sign rx_sign.npy] [--cps 1|3] [--check]

captures.npy: (samples, COLS) integers in the ADC range, sample 0 = the first sample
after reset.  --sign: (samples,) 0/1 receive PN signs (default: PN off).  --m: windows
per frame (1, 2, 4, 8).  Writes heatmaps.npy (frames, ROWS, COLS) uint32 and
heatmaps.npy.json (frames, sticky flags), both renamed from a temporary name only when
the simulation passed.  Bad input (dtype other than integer, wrong shape, a value outside
the ADC range, fewer samples than a frame) gives one line and exit 2 before any build; a
failed simulation one line and exit 1, the old --out untouched.  --check compares with the bit-exact model
sim/fmt/rx_array.py and exits 1 on a difference.  --cps: the build's CLK_PER_SAMPLE:
1 (default, fastest: a sample every clk, one FFT engine per column pair) or 2..4 (the
core's structure: CLK_PER_SAMPLE column pairs per time-multiplexed FFT engine, a
sample every CLK_PER_SAMPLE clk).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "sim"), str(ROOT / "tb")]
os.environ["PYTHONPATH"] = os.pathsep.join(
    [str(ROOT / "sim"), str(ROOT / "tb")] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])

import numpy as np  # noqa: E402


def windows_m(text: str) -> int:
    """--m: windows per frame, 1..255."""
    v = int(text)
    if not 1 <= v <= 255:
        raise ValueError(text)
    return v


def main(argv=None) -> int:
    from fmt.inputs import InputError, OneLineParser
    ap = OneLineParser(description=__doc__.splitlines()[0])
    ap.add_argument("--in", dest="inp", required=True, help="ADC capture .npy (samples x columns)")
    ap.add_argument("--out", required=True, help="heat maps .npy (frames x rows x cols)")
    ap.add_argument("--config", default="default", choices=["default", "small", "medium"])
    ap.add_argument("--m", type=windows_m, default=1, metavar="M",
                    help="windows per frame, 1..255")
    ap.add_argument("--sign", default="", help="receive PN signs .npy (samples,), default PN off")
    ap.add_argument("--cps", type=int, default=1, choices=[1, 2, 3, 4],
                    help="CLK_PER_SAMPLE of the build (clk per sample of the replay)")
    ap.add_argument("--check", action="store_true", help="compare with rx_fixed (bit-exact)")
    a = ap.parse_args(argv)
    try:
        return run(a)
    except InputError as e:
        print(f"replay_rx: {e}", file=sys.stderr)
        return 2


def check_inputs(a, cfg):
    """The capture (and signs) as int64 arrays; InputError (one line) on a bad file."""
    from fmt.inputs import InputError, load_int_array
    lo, hi = -(1 << (cfg.adc_bits - 1)), (1 << (cfg.adc_bits - 1)) - 1
    adc = load_int_array(a.inp, "capture", (None, cfg.cols), lo, hi)
    if len(adc) < cfg.n_fft * a.m:
        raise InputError(f"capture {a.inp}: {len(adc)} samples, less than one frame "
                         f"({cfg.n_fft} x M = {a.m} samples)")
    sign = (load_int_array(a.sign, "--sign", (len(adc),), 0, 1) if a.sign
            else np.zeros(len(adc), dtype=np.int64))
    out = Path(a.out)
    if out.suffix != ".npy":
        raise InputError(f"--out {out}: must end in .npy")
    if not out.resolve().parent.is_dir():
        raise InputError(f"--out {out}: no such directory {out.resolve().parent}")
    return adc, sign


def run(a) -> int:
    from common.runner import SimulationFailed, run_cocotb, sources
    from fmt import inputs, params, rx_array
    from fmt_rx_array.rx_driver import build_args

    cfg = params.get(a.config)
    adc, sign = check_inputs(a, cfg)
    inp, out = Path(a.inp).resolve(), Path(a.out).resolve()
    out_json = Path(str(out) + ".json")
    # the simulation writes under a temporary name; renamed only when it passed
    tmp = inputs.temp_output(out, ".npy")
    tmp_json = Path(str(tmp) + ".json")
    inputs.remove_quietly(tmp, tmp_json)
    fft_ch = rx_array.rx_fft_ch_default(1, a.cps)
    env = {"CFG": a.config, "M": a.m, "REPLAY_IN": inp, "REPLAY_OUT": tmp,
           "REPLAY_SIGN": Path(a.sign).resolve() if a.sign else "",
           "FFT_CH": fft_ch, "CE_EVERY": a.cps}
    try:
        run_cocotb(
            sim="verilator",
            toplevel="fmt_rx_array",
            sources=sources("fmt_rx_array"),
            test_module="replay_cocotb",
            test_dir=ROOT / "tb" / "fmt_rx_array",
            parameters={"ROWS": cfg.rows, "COLS": cfg.cols, "LOG2_N": cfg.log2_n,
                        "BIN_LO": cfg.bin_lo, "BIN_STEP": cfg.bin_step, "ADC_BITS": cfg.adc_bits,
                        "HM_W": cfg.hm_width,
                        # a sample every cps clk; FFT_CH defaults to CLK_PER_SAMPLE (POST_CLK 1)
                        "POST_CLK": 1, "CLK_PER_SAMPLE": a.cps},
            extra_env=env,
            build_args=build_args("verilator"),
        )
        hm = np.load(tmp)
        info = json.loads(tmp_json.read_text())
    except (SimulationFailed, RuntimeError, OSError, ValueError, SystemExit) as e:
        inputs.remove_quietly(tmp, tmp_json)
        sys.stdout.flush()
        print(f"replay_rx: the simulation failed ({inputs.one_line(e)}); {out} not written",
              file=sys.stderr)
        return 1
    inputs.commit_output(tmp, out)
    inputs.commit_output(tmp_json, out_json)
    print(f"{out}: {hm.shape[0]} frames of {cfg.rows} x {cfg.cols}, flags {info}")
    if a.check:
        try:
            exp, _, _ = rx_array.rx_heatmaps_fixed(adc, sign.astype(np.uint8), cfg, m=a.m)
        except Exception as e:  # noqa: BLE001 -- a model error is a failed check, one line
            print(f"replay_rx: the model failed ({inputs.one_line(e)})", file=sys.stderr)
            return 1
        if not np.array_equal(hm, exp):
            print(f"replay_rx: MISMATCH: {int(np.sum(hm != exp))} cells differ from rx_fixed",
                  file=sys.stderr)
            return 1
        print("bit-exact with rx_fixed")
    return 0

if __name__ == "__main__":
    sys.exit(main())
