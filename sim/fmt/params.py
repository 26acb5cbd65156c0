"""One source of truth for sensor and datapath parameters.

The golden model, the RTL parameters passed by the testbenches and the generated
Verilog header ``rtl/fmt_defaults.vh`` all read the values defined here.  Nothing
is written twice by hand: ``python -m fmt.generate`` regenerates the header
and ``sim/tests/test_params.py`` fails when the committed header is stale.

Tone plan: row ``r`` transmits FFT bin ``bin_lo + r * bin_step``.  With a phase
accumulator of ``phase_bits`` bits clocked at fs, bin k has the tuning word
``k << (phase_bits - log2(n_fft))`` and is exactly periodic in every window.
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path


class ToneplanError(ValueError):
    """An invalid tone plan or sensor configuration."""


def _is_pow2(n: int) -> bool:
    return n > 0 and (n & (n - 1)) == 0


@dataclass(frozen=True)
class SensorConfig:
    """A sensor build: geometry, tone comb and datapath widths."""

    name: str
    rows: int                 # transmit electrodes (heat-map rows, y)
    cols: int                 # receive electrodes (heat-map columns, x)
    n_fft: int                # samples per window (power of two, 64..1024)
    bin_lo: int               # FFT bin of row 0
    bin_step: int = 1         # bins between adjacent rows (spacing = bin_step * fs / n_fft)
    fs_hz: float = 125e6 / 3  # ADC sample rate (the fs clock)
    adc_bits: int = 12        # ADC word width (two's complement)
    dac_bits: int = 12        # DDS output word width per row
    sine_bits: int = 16       # DDS sine-table word width (signed)
    phase_bits: int = 32      # DDS phase-accumulator width
    amp_bits: int = 8         # DDS per-row amplitude word (unsigned, full scale = 2**amp_bits - 1)
    hm_width: int = 16        # heat-map cell width W (unsigned)
    pitch_mm: float = 5.0     # electrode pitch
    max_touches: int = 16     # contact limit
    pn_bits: int = 15         # LFSR length L (period 2**L - 1)
    frac_bits: int = 8        # fractional bits of a cell in coordinates
    extra: dict = field(default_factory=dict, compare=False, hash=False)

    # ---- derived values -------------------------------------------------------
    @property
    def log2_n(self) -> int:
        return self.n_fft.bit_length() - 1

    @property
    def bins(self) -> list[int]:
        return [self.bin_lo + r * self.bin_step for r in range(self.rows)]

    @property
    def bin_hi(self) -> int:
        return self.bins[-1]

    @property
    def window_s(self) -> float:
        return self.n_fft / self.fs_hz

    @property
    def bin_hz(self) -> float:
        return self.fs_hz / self.n_fft

    @property
    def tone_hz(self) -> list[float]:
        return [k * self.bin_hz for k in self.bins]

    @property
    def width_mm(self) -> float:
        return self.cols * self.pitch_mm

    @property
    def height_mm(self) -> float:
        return self.rows * self.pitch_mm

    def tuning_word(self, k: int) -> int:
        """Phase increment of FFT bin k (exact: low bits are zero)."""
        return k << (self.phase_bits - self.log2_n)

    # ---- validation -----------------------------------------------------------
    def validate(self) -> "SensorConfig":
        errs = []
        if self.rows < 1 or self.cols < 1:
            errs.append(f"rows and cols must be >= 1 (got {self.rows} x {self.cols})")
        if not _is_pow2(self.n_fft) or not 64 <= self.n_fft <= 1024:
            errs.append(f"n_fft must be a power of two in 64..1024 (got {self.n_fft})")
        if self.bin_step < 1:
            errs.append(
                f"tone spacing {self.bin_step} bin(s) is below 1/tau: adjacent rows would not be "
                "orthogonal over one window")
        if self.bin_lo < 1:
            errs.append(f"lowest tone bin must be >= 1 (got {self.bin_lo}); bin 0 is DC")
        if _is_pow2(self.n_fft) and self.rows >= 1:
            if self.bin_hi >= self.n_fft // 2:
                errs.append(
                    f"highest tone bin {self.bin_hi} is outside the FFT's first Nyquist zone "
                    f"(must be < {self.n_fft // 2})")
            if self.bin_hi >= 2 * self.bin_lo:
                errs.append(
                    f"highest tone bin {self.bin_hi} >= 2 x lowest bin {self.bin_lo}: the second "
                    "harmonic of the lowest tone would land on the comb")
        if self.phase_bits < self.log2_n:
            errs.append("phase_bits must be >= log2(n_fft)")
        if self.hm_width < 8 or self.hm_width > 32:
            errs.append(f"hm_width must be 8..32 (got {self.hm_width})")
        if errs:
            raise ToneplanError(f"sensor '{self.name}': " + "; ".join(errs))
        return self

    def replace(self, **kw) -> "SensorConfig":
        return dataclasses.replace(self, **kw).validate()

    # ---- RTL view -------------------------------------------------------------
    def verilog_params(self) -> dict[str, int]:
        """Values every RTL module may take, by the Verilog parameter name."""
        return {
            "ROWS": self.rows,
            "COLS": self.cols,
            "LOG2_N": self.log2_n,
            "BIN_LO": self.bin_lo,
            "BIN_STEP": self.bin_step,
            "ADC_BITS": self.adc_bits,
            "DAC_BITS": self.dac_bits,
            "SINE_BITS": self.sine_bits,
            "PHASE_BITS": self.phase_bits,
            "AMP_BITS": self.amp_bits,
            "HM_W": self.hm_width,
            "MAX_TOUCHES": self.max_touches,
            "PN_BITS": self.pn_bits,
            "FRAC_BITS": self.frac_bits,
        }


# The paper's demonstrator (brief: "The default sensor").
DEFAULT = SensorConfig(name="default", rows=30, cols=40, n_fft=256, bin_lo=33).validate()
# Small build for fast tests: 4 x 6, N = 64, bins 9..12.
SMALL = SensorConfig(name="small", rows=4, cols=6, n_fft=64, bin_lo=9).validate()
# A middle size, to catch size-specific bugs between the two.
MEDIUM = SensorConfig(name="medium", rows=8, cols=10, n_fft=128, bin_lo=17).validate()

CONFIGS = {c.name: c for c in (DEFAULT, SMALL, MEDIUM)}


def get(name: str) -> SensorConfig:
    try:
        return CONFIGS[name]
    except KeyError:
        raise ToneplanError(f"unknown sensor config '{name}' (known: {', '.join(CONFIGS)})") from None


# ---- generated Verilog header -------------------------------------------------
VH_PATH = Path(__file__).resolve().parents[2] / "rtl" / "fmt_defaults.vh"


def render_vh(cfg: SensorConfig = DEFAULT) -> str:
    lines = [
        "// fmt_defaults.vh -- GENERATED by `python -m fmt.generate` from sim/fmt/params.py.",
        "// Do not edit by hand: sim/tests/test_params.py fails when this file is stale.",
        f"// Default parameters of every RTL module: the '{cfg.name}' sensor "
        f"({cfg.rows} x {cfg.cols}, N = {cfg.n_fft}, bins {cfg.bin_lo}..{cfg.bin_hi}).",
        "`ifndef FMT_DEFAULTS_VH",
        "`define FMT_DEFAULTS_VH",
    ]
    for k, v in cfg.verilog_params().items():
        lines.append(f"`define FMT_{k} {v}")
    lines += ["`endif", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--show", default=None, help="print one config")
    a = ap.parse_args(argv)
    if a.show:
        c = get(a.show)
        for f in dataclasses.fields(c):
            print(f"{f.name:12s} {getattr(c, f.name)}")
        print(f"{'bins':12s} {c.bins[0]}..{c.bins[-1]}  ({c.tone_hz[0]/1e6:.3f}..{c.tone_hz[-1]/1e6:.3f} MHz)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
