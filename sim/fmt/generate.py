"""Every generated file of the repository, from one entry point.

    python -m fmt.generate            write every generated file (`make generate`)
    python -m fmt.generate --check    exit 1, one line per stale or missing file (`make lint`)
    python -m fmt.generate --list     the generated files

The files and their generators:

* ``rtl/fmt_defaults.vh``  -- default parameters of every RTL module (:mod:`fmt.params`)
* ``rtl/fmt_regmap.vh``, ``rtl/fmt_regfile.v``, ``docs/REGISTERS.md`` -- the register
  map (:mod:`fmt.regmap`)
* ``rtl/fmt_fft_twMMMM.hex`` -- FFT twiddle ROMs (:mod:`fmt.fft_r22sdf`)
* ``rtl/fmt_sine_rom_aAA_sSS.hex`` -- DDS sine ROMs (:mod:`fmt.dds_bank`)
* ``rtl/fmt_interp_log.hex``, ``fmt_interp_exp.hex``, ``fmt_interp_bias.hex`` -- the
  interpolator's ROMs (:mod:`fmt.interp`)
* ``rtl/fmt_recip.hex`` -- the receive's 1/M ROM (:mod:`fmt.rx_array`)

``--check`` renders every file in memory and compares it with the file on disk; nothing
is written.
"""
from __future__ import annotations

import argparse
import sys
from functools import partial
from pathlib import Path
from typing import Callable

from . import dds_bank, fft_r22sdf, interp, params, regmap, rx_array

ROOT = Path(__file__).resolve().parents[2]
COMMAND = "python -m fmt.generate"


def generated() -> dict[Path, Callable[[], str]]:
    """Generated file -> function returning its text."""
    out: dict[Path, Callable[[], str]] = {params.VH_PATH: params.render_vh}
    out.update(regmap.GENERATED)
    for m in fft_r22sdf.ALL_TWIDDLE_BLOCKS:
        out[fft_r22sdf.RTL / fft_r22sdf.twiddle_hex_name(m)] = partial(fft_r22sdf.twiddle_hex_text, m)
    for a, s in dds_bank.HEX_TABLES:
        out[dds_bank.RTL / dds_bank.hex_name(a, s)] = partial(dds_bank.render_hex, a, s)
    out[interp.LOG_HEX] = interp.render_log_hex
    out[interp.EXP_HEX] = interp.render_exp_hex
    out[interp.BIAS_HEX] = interp.render_bias_hex
    out[rx_array.RTL / rx_array.RECIP_HEX] = rx_array.render_recip_hex
    return out


def stale() -> list[Path]:
    """Generated files that are missing or differ from their generator's text."""
    return [p for p, f in generated().items() if not p.exists() or p.read_text() != f()]


def write() -> list[Path]:
    """Write every generated file whose text changed; returns the files written."""
    out = []
    for p, f in generated().items():
        text = f()
        if not p.exists() or p.read_text() != text:
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_text(text)
            out.append(p)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Write (or check) every generated file.")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--check", action="store_true", help="exit 1 when a generated file is stale")
    g.add_argument("--list", action="store_true", help="print the generated files")
    a = ap.parse_args(argv)
    rel = lambda p: p.relative_to(ROOT) if p.is_relative_to(ROOT) else p
    if a.list:
        for p in generated():
            print(rel(p))
        return 0
    if a.check:
        st = stale()
        for p in st:
            print(f"stale: {rel(p)} (run {COMMAND})")
        return 1 if st else 0
    written = write()
    for p in written:
        print(f"wrote {rel(p)}")
    print(f"{len(generated())} generated files, {len(written)} rewritten")
    return 0


if __name__ == "__main__":
    sys.exit(main())
