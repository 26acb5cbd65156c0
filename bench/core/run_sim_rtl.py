"""``make sim`` through the RTL: a scene through ``fmt_core`` under Verilator, the
fixed-point model in lockstep as the reference.

    python -m bench.core.run_sim_rtl --scene sim/scenes/default.json [--out build/sim]
        [--frames F] [--cps 3] [--engine cpp|cocotb] [--sim verilator|icarus]
        [--cal scene|noiseless] [--no-plot] [--quiet] [--serve PORT [--serve-seconds S] [--serve-once]]

(from the repository root with the repository, ``sim`` and ``tb`` on PYTHONPATH:
``source scripts/env.sh``; ``make sim`` sets them).  The files of the bench are in
``bench/core/`` (README.md there); the RTL comes from ``rtl/filelists/fmt_core.f``.

The simulation top ``bench/core/fmt_core_sim_top.v`` is fmt_core + the simulation-only
channel (DAC words through the channel delay x coupling matrix + counter-based noise,
DC, interferers, display and charger noise -> clip -> ENOB -> ADC words) + a coupling-update player + loggers;
nothing in Python is on the per-sample path:

0. :func:`check_scene`: every effect of the scene is applied by the RTL path
   (``fmt.channel.fixed_effects``: noise, DC offset, ENOB, channel delay, interferers
   (sweeping, bursty), display noise, charger noise (weights in the coupling plan);
   PN in the core's registers; coupling effects in the plan) or the run stops before
   anything is built: ``main`` prints ONE line naming the effect and returns 2
   (``tone_phases`` other than "zero": the DDS has no phase register; a delay over 63
   samples, more than 64 oscillators, a PN setting outside its register).
1. The scene becomes a coupling plan (:func:`coupling_plan`): the channel matrix G (16
   fraction bits, ADC LSB per DAC LSB) at sample 0 and stamped updates -- at every window
   boundary where the coupling changed (moving contacts: the map at the window's first
   sample, held for the window) and at every sample where a contact's touch starts or
   ends inside a window (the exact onset sample).  Updates too close together to be
   loaded in time by the Verilog player (one pending-matrix write per clk) are merged
   into the later one; the model uses the same list, so this costs no exactness.  The
   effects go to ``chan.hex`` with the shared tables ``gauss.hex`` / ``sine.hex``
   (:func:`write_channel_files`); the noise is f(seed, sample, column) (a splitmix64
   counter and an inverse-CDF table, ``fmt.channel.FixedEffects``): it never repeats.
2. The model reference (:func:`model_reference`): the PN signs as the core makes them
   (:func:`pn_rtl`: the chip length reaches the generator a few samples after the
   reset) -> ``dds_bank_fixed`` -> 3-sample DAC delay -> :func:`channel_fixed` (int64
   twin of ``channel_sim_fixed``, with the effects) -> 1-sample ADC register ->
   ``rx_heatmaps_fixed`` (PN receive delay 4 samples + the scene's rx_delay) ->
   ``touch.process_frames(fixed=True)`` with the scene's calibration: by default the real
   procedure (:func:`calibration_fixed`: 16 untouched and 16 calibration-sheet frames with
   the scene's noise and additive effects through this fixed-point chain, averaged);
   ``--cal noiseless``: the old noiseless render (always perfect).
3. The RTL run.  Engine ``cpp`` (default): the standalone Verilator harness
   ``bench/core/sim_main.cpp`` (:func:`run_harness`; built once per sensor size and
   CLK_PER_SAMPLE under ``build/sim_cpp/`` with -O3 and rebuilt only when a source
   changes) clocks ``fmt_core_sim_top`` with EXT_CHANNEL = 1 and computes the channel
   in C++, bit-exact with ``fmt_channel_sim``; it replays the phases of the cocotb test
   cycle for cycle.  Engine ``cocotb``: the cocotb test ``run_scene`` in
   ``bench/core/core_cocotb.py`` (Verilator or Icarus, the Verilog channel and
   player; ~40x slower).  Both program the registers (calibration, settings,
   REPORT_PERIOD 0) through the core's local bus, run the clock and read the status;
   the loggers write every heat-map beat, every event and every receiver frame end
   with its clk cycle.
4. :func:`analyse` compares heat maps and events bit for bit (events sorted by ID per
   frame, time stamps excepted), measures latency and accuracy and writes
   ``<out>/<scene>/report.json``, ``heatmap.png`` and ``latency_hist.png``.
   ``sim_frames_per_s`` = frames / wall time of the clocked run (the build, the model,
   loading the files and the analysis excluded); the C++ engine also reports the CPU
   time of that run (``sim_frames_per_cpu_s``, ``sim_clk_per_s``).

Serve mode (``--serve PORT``, engine cpp): after the scene's frames the harness keeps
clocking the core and bridges ``socket://127.0.0.1:PORT`` to the core's UART (8N1,
UART_DIV = 4 clk per bit), so ``scripts/fmtctl --port socket://127.0.0.1:PORT ...``
drives the running simulation as it drives the board.  It prints ``serving the RTL UART
on socket://127.0.0.1:PORT`` when listening (PORT 0: any free port, the line names it)
and serves one client at a time, any number of clients in turn, until Ctrl-C (SIGINT /
SIGTERM: a clean end), ``--serve-seconds`` of wall time (default 600, 0 = none) or, with
``--serve-once``, the first client's disconnect.  The loggers stay on for the first
``--serve-log-frames`` frames of serving (default 2000, -1 = all).  The coupling of the
scene's last frame holds while serving (the noise generator runs on); only the scene's
frames are compared with the model (the logs are cut at the cycle where serving
started); ``serve.log`` in the job folder lists every UART byte with its cycle.

Cycle conventions: cycle 0 = the first clk edge with rst low; channel sample k is formed
at cycle k * CPS (the ce edges); the receiver takes ADC sample j (= channel sample j - 1)
at cycle j * CPS; a frame ends at the receiver's last sample of its last window.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from common.sources import INCLUDE_DIRS, rom_define, sources
from fmt import channel as _channel
from fmt import dds_bank as _dds
from fmt import pn_gen as _pn
from fmt import rx_array as _rx
from fmt import scene as _scene
from fmt import sensor as _sensor
from fmt import settings as _settings
from fmt.settings import TouchSettings
from fmt.tracker import TrackParams

ROOT = Path(__file__).resolve().parents[2]
BENCH = Path(__file__).resolve().parent
COUP_BITS, COUP_FRAC = 16, 16
NOISE_FRAC = 4           # fraction bits of test noise-file words (channel_fixed noise=)
DAC_DELAY = 3            # channel sample k multiplies DDS sample k - 3 (fmt_tx + channel input)
ADC_DELAY = 1            # receiver sample j = channel sample j - 1 (channel output register)
PN_RX_DELAY = DAC_DELAY + ADC_DELAY   # PN_RX_DELAY register value that aligns the despreaders
LOAD_MARGIN = 6          # clk cycles of slack per update load
TYPE_NAMES = {0: "new", 1: "move", 2: "lift", 3: "blob"}


def upd_len(cfg) -> int:
    """Capacity of the coupling-update record memory of the simulation top."""
    return 1 << 20 if cfg.rows * cfg.cols >= 400 else 1 << 15


def job_dir(cfg, cps: int, tag: str = "") -> Path:
    """Fixed folder per build (the file names are Verilog parameters: a fixed path keeps
    the Verilator build reusable between scenes); ``tag`` separates concurrent users."""
    return ROOT / "build" / "sim_rtl" / f"{cfg.name}_c{cps}{'_' + tag if tag else ''}"


def dac_peak(cfg) -> int:
    """Peak DDS word of a full-amplitude row (the DAC LSB per unit tone)."""
    d = _dds.dds_bank_fixed(cfg.n_fft, cfg=cfg)
    return int(np.abs(d).max())


def coupling_scale(cfg) -> float:
    """Coupling units -> channel G integer: TONE_LSB ADC LSB per unit coupling at the
    DDS peak word, COUP_FRAC fraction bits."""
    return _sensor.TONE_LSB / dac_peak(cfg) * (1 << COUP_FRAC)


def quantise_g(g: np.ndarray, scale: float) -> np.ndarray:
    return np.clip(np.rint(g * scale), 0, (1 << COUP_BITS) - 1).astype(np.int64)


def coupling_plan(scene: _scene.Scene, n_samples: int, cps: int):
    """(g0, updates): the integer matrix in effect from sample 0 and the list of
    (stamp, G) updates, spaced so that the simulation top's player loads each one (one
    write per changed cell, then the commit) before its stamp.  With charger noise in
    the scene every matrix has a row ROWS more: the charger weight of each column
    (``channel.charger_column_weights`` of the same coupling, CHG_W_FRAC fraction bits),
    loaded by kind-3 records, so it changes exactly when the coupling does."""
    cfg = scene.cfg
    n = cfg.n_fft
    nw = -(-n_samples // n)
    wc = _channel.window_coupling(scene, 0, nw)
    scale = coupling_scale(cfg)
    chg = any(o.charger for o in _channel.oscillators(scene))
    if chg:                          # charger weights from the coupling above the baseline
        wq = lambda g, base: np.clip(np.rint(_channel.charger_column_weights(cfg, g - base)
                                       * (1 << _channel.CHG_W_FRAC)), 0, (1 << COUP_BITS) - 1).astype(np.int64)
    by_w = {}
    for w, mask, m0, _m1 in wc.partial:
        by_w.setdefault(w, []).append((mask, m0))
    raw = []
    for w in range(nw):
        parts = by_w.get(w, [])
        cuts = {0}
        for mask, _ in parts:
            ch = np.nonzero(np.diff(mask.astype(np.int8)))[0] + 1
            cuts.update(int(c) for c in ch)
        for s in sorted(cuts):
            g = wc.g0[w].copy()
            for mask, m0 in parts:
                if mask[s]:
                    g += m0
            q = quantise_g(g, scale)
            raw.append((w * n + s, np.vstack([q, wq(g, wc.b0[w])[None, :]]) if chg else q))
    g0 = raw[0][1]
    kept = [(0, g0)]
    for stamp, g in raw[1:]:
        if np.array_equal(g, kept[-1][1]):
            continue
        while True:
            prev_stamp, prev_g = kept[-1]
            writes = int(np.count_nonzero(g != prev_g))
            if len(kept) == 1 or prev_stamp * cps + writes + LOAD_MARGIN < stamp * cps:
                break
            kept.pop()            # too close: the later update replaces it
        if len(kept) == 1 and kept[0][0] * cps + int(np.count_nonzero(g != kept[0][1])) + LOAD_MARGIN >= stamp * cps:
            continue              # cannot load before the stamp right after reset: skip
        if not np.array_equal(g, kept[-1][1]):
            kept.append((stamp, g))
    return g0, kept[1:]


def plan_records(cfg, g0, updates) -> list[int]:
    """64-bit player records (see fmt_core_sim_top.v): kind 1 coupling writes, kind 3
    charger-weight writes (the matrix's row ROWS), kind 2 commits, 0 the end."""
    rec = []
    prev = np.zeros_like(g0)
    for stamp, g in [(0, g0)] + list(updates):
        rr, cc = np.nonzero(g != prev)
        for r, c in zip(rr.tolist(), cc.tolist()):
            kind = 3 if r == cfg.rows else 1         # row ROWS: a charger weight
            rec.append((kind << 60) | (r << 52) | (c << 44) | int(g[r, c]))
        rec.append((2 << 60) | int(stamp))
        prev = g
    rec.append(0)
    return rec


def write_records(path, rec) -> None:
    Path(path).write_text("".join(f"{v:016x}\n" for v in rec))


def check_scene(scene: _scene.Scene) -> _channel.FixedEffects:
    """The scene's channel effects in fixed point, or :class:`fmt.channel.UnsupportedEffect`
    (one line naming the effect) when the RTL path cannot apply one: tone phases other
    than "zero" (the DDS has no phase register), a PN setting outside its register, and
    the ranges of ``channel.fixed_effects``."""
    eff = _channel.fixed_effects(scene, adc_delay=ADC_DELAY)
    enable, chip_len, _d, rx_delay = _channel.pn_settings(scene)
    if not 1 <= chip_len <= 1023:
        raise _channel.UnsupportedEffect(f"effect pn: chip_len {chip_len} outside the register (1..1023)")
    if not 0 <= PN_RX_DELAY + rx_delay <= 63:
        raise _channel.UnsupportedEffect(
            f"effect pn: rx_delay {rx_delay} (register PN_RX_DELAY = {PN_RX_DELAY} + rx_delay) outside 0..63")
    return eff


def write_channel_files(d: Path, eff: _channel.FixedEffects) -> None:
    """chan.hex (parameter words), gauss.hex and sine.hex (the shared tables) in the job folder."""
    write_records(d / "chan.hex", eff.param_words())
    _channel.write_table_hex(d / "gauss.hex", _channel.gauss_table(), 16)
    _channel.write_table_hex(d / "sine.hex", _channel.if_sine_table(), 16)


def channel_fixed(dac, g0, updates, eff: _channel.FixedEffects | None = None, adc_bits: int = 12,
                  noise=None):
    """int64 twin of ``fmt_channel_sim`` / ``channel.channel_sim_fixed`` (same formula:
    round half up of sum_r dac[k - delay]*G + additive effects, >> 16, clip, ENOB mask);
    int64 is exact here (|dac| < 2^11, G < 2^16, ROWS <= 64, additive < 2^40; charger
    sum < 2^38 times W < 2^16).  Matrices with ROWS + 1 rows carry the charger weights.
    ``noise``: file words as channel_sim_fixed's (tests).  Returns (adc, clipped samples)."""
    dac = np.asarray(dac, dtype=np.int64)
    n = dac.shape[0]
    if eff is not None and eff.delay:
        dd = np.zeros_like(dac)
        dd[eff.delay:] = dac[:max(n - eff.delay, 0)]
        dac = dd
    rows = dac.shape[1]
    out = np.empty((n, g0.shape[1]), dtype=np.int64)
    stamps = [0] + [int(s) for s, _ in updates] + [n]
    mats = [g0] + [g for _, g in updates]
    chg = eff.charger(0, n) if eff is not None and eff.has_charger else None
    for i, g in enumerate(mats):
        a, b = min(stamps[i], n), min(stamps[i + 1], n)
        if b > a:
            out[a:b] = dac[a:b] @ g[:rows]
            if chg is not None and g.shape[0] > rows:    # charger weights in row ROWS
                out[a:b] += (chg[a:b, None] * g[rows][None, :]) >> _channel.CHG_W_FRAC
    if noise is not None:
        out += noise[np.arange(n) % noise.shape[0]] << (COUP_FRAC - NOISE_FRAC)
    if eff is not None:
        for k0 in range(0, n, 1 << 16):           # in blocks: the generator's temporaries stay small
            k1 = min(n, k0 + (1 << 16))
            out[k0:k1] += eff.additive(k0, k1 - k0, out.shape[1])
    y = (out + (1 << (COUP_FRAC - 1))) >> COUP_FRAC
    lo, hi = -(1 << (adc_bits - 1)), (1 << (adc_bits - 1)) - 1
    clip = int(np.count_nonzero(((y < lo) | (y > hi)).any(axis=1)))
    y = np.clip(y, lo, hi)
    if eff is not None and eff.enob_clear:
        y &= ~np.int64((1 << eff.enob_clear) - 1)
    return y, clip


@dataclass
class Reference:
    heatmaps: np.ndarray     # (frames, rows, cols)
    events: list             # per frame, fmt.touch events
    clipped: int


def pn_of(scene):
    """(enable, chip_len, PN_RX_DELAY register): the bench's 4 samples of DAC and ADC
    registers plus the scene's receive delay (default: its channel delay, matched)."""
    enable, chip_len, _d, rx = _channel.pn_settings(scene)
    return enable, chip_len, PN_RX_DELAY + rx


REG_LAT = 2             # a register written at clk cycle w reaches fmt_pn_gen from cycle w + 2


def pn_rtl(n: int, enable: bool, chip_len: int, rx_delay: int, bits: int, first: int = 0):
    """(tx, rx) PN signs of samples 0..n-1 as fmt_core's generator makes them in this
    bench.  The registers are written after the reset, so the first ``first`` samples
    (ce edges before PN_CHIP_LEN reaches the generator, :func:`pn_chip_first`) step the
    chip counter with the reset chip length 1: tx[t] = chips[t] for t < first, then
    chips[first + (t - first) // chip_len] -- the model's ``pn_signs`` sequence advanced
    by first * (chip_len - 1) samples from sample ``first`` on (all the same for
    chip_len 1).  rx[t] = tx[t - rx_delay], 0 before.  The late PN_ENABLE and
    PN_RX_DELAY writes change nothing: the LFSR (seed 1) gives chip 0 for its first 14
    chips, so every sign before they arrive is 0 either way."""
    chip_len = max(1, int(chip_len))
    t = np.arange(n, dtype=np.int64)
    idx = np.where(t < first, t, first + (t - first) // chip_len)
    tx = np.zeros(n, dtype=np.uint8)
    if enable and n:
        per = _channel._pn_period(bits, _pn.DEFAULT_SEED)        # one LFSR period, cached
        tx = per[idx % per.size].astype(np.uint8)
    rx = np.zeros_like(tx)
    if rx_delay < n:
        rx[rx_delay:] = tx[:n - rx_delay]
    return tx, rx


def pn_chip_first(scene: _scene.Scene, cps: int) -> int:
    """Samples (ce edges at clk 0, cps, 2 cps, ...) taken before the PN_CHIP_LEN write
    (the i-th register write, at clk i) reaches the generator at clk i + REG_LAT."""
    names = [nm for nm, _v in register_writes(scene, TouchSettings())]
    return -(-(names.index("PN_CHIP_LEN") + REG_LAT) // cps)


def model_reference(scene: _scene.Scene, g0, updates, eff, frames: int, settings, cal,
                    cps: int = 3, m_frames=None) -> Reference:
    """The model's heat maps and events of the run; ``m_frames``: M of each frame when
    WINDOWS_M changes during the run (default: the scene's M throughout)."""
    from fmt import touch as _touch
    hm, clipped = model_heatmaps(scene, g0, updates, eff, frames, cps, m_frames)
    evs = _touch.process_frames(hm, scene.cfg, settings, fixed=True, flatten_cal=cal,
                                frame_period_s=scene.frame_period_s)
    return Reference(hm, evs, clipped)


CAL_SKIP = 1            # calibration captures: start-up frames dropped before the average


def calibration_fixed(scene: _scene.Scene, cps: int = 3, sheet: float = 0.25, frames: int | None = None):
    """(offset, gain) by the real procedure through the bench's fixed-point chain (the
    heat maps the core itself would measure): the captures of
    ``fmt.run_sim.calibration_scenes`` (untouched, uniform sheet; the scene's noise and
    additive effects, no charger noise) through the coupling plan, the fixed-point channel
    and ``rx_heatmaps_fixed``; the first CAL_SKIP frames (the chain's start-up: no DAC word
    in the first samples) dropped, the next ``frames`` averaged by ``flatten.calibrate``."""
    from fmt import flatten as _flatten
    from fmt import run_sim as _run_sim
    frames = _run_sim.CAL_FRAMES if frames is None else frames
    hms = []
    for sc in _run_sim.calibration_scenes(scene, sheet, frames + CAL_SKIP):
        n = sc.frames * sc.samples_per_frame
        g0, ups = coupling_plan(sc, n, cps)
        hm, _clip = model_heatmaps(sc, g0, ups, check_scene(sc), sc.frames, cps)
        hms.append(hm[CAL_SKIP:])
    off, gain = _flatten.calibrate(hms[0], hms[1], None, scene.cfg)
    return np.asarray(off, dtype=np.int64), np.asarray(gain, dtype=np.int64)


def model_heatmaps(scene: _scene.Scene, g0, updates, eff, frames: int, cps: int = 3, m_frames=None):
    """(heat maps (frames, rows, cols), clipped samples) of the bench's fixed-point chain:
    PN as the core makes it, DDS, DAC delay, channel, ADC register, fixed receiver."""
    cfg = scene.cfg
    spf = scene.samples_per_frame
    n = frames * spf
    enable, chip_len, rx_delay = pn_of(scene)
    tx, rx = pn_rtl(n, enable, chip_len, rx_delay, cfg.pn_bits, pn_chip_first(scene, cps))
    dds = _dds.dds_bank_fixed(n, tx_sign=np.concatenate([[0], tx[:-1]]).astype(np.int64), cfg=cfg)
    dac = np.zeros_like(dds)
    dac[DAC_DELAY:] = dds[:n - DAC_DELAY]
    # the initial matrix is committed at the first clk edge after the reset and copied at
    # the next ce edge: channel sample 0 still sees G = 0, W = 0 (no DAC word is there yet
    # either, DAC_DELAY; only a charger weight would show it)
    adc_ch, clipped = channel_fixed(dac, np.zeros_like(g0), [(1, g0)] + list(updates), eff, cfg.adc_bits)
    adc = np.zeros_like(adc_ch)
    adc[ADC_DELAY:] = adc_ch[:n - ADC_DELAY]
    rx_in = np.concatenate([[0], rx[:-1]]).astype(np.int64)
    hm, _order, _flags = _rx.rx_heatmaps_fixed(adc, rx_in, cfg,
                                               m=scene.m if m_frames is None else m_frames)
    return hm, clipped


def register_writes(scene: _scene.Scene, settings: TouchSettings) -> list:
    """(name, value) register writes of a run: PN, M, touch settings, every frame
    reported, no extra delay."""
    cfg = scene.cfg
    enable, chip_len, rx_delay = pn_of(scene)
    tp = TrackParams.from_settings(cfg, settings, scene.frame_period_s)
    return [
        ("PN_RX_DELAY", rx_delay), ("PN_ENABLE", int(enable)), ("PN_CHIP_LEN", chip_len),
        ("WINDOWS_M", scene.m),
        ("TOUCH_THRESHOLD", settings.threshold),
        ("TOUCH_MODE", int(settings.neighbourhood == "moore") | (2 if settings.bias_correction else 0)
         | (4 if settings.blobs else 0)),
        ("CONTACT_LIMIT", settings.max_touches if settings.max_touches is not None else cfg.max_touches),
        ("TRACK_MAX_JUMP", tp.max_jump_q), ("TRACK_GATE_STEP", tp.gate_step_q),
        ("TRACK_HOLD_OFF", tp.hold_off_frames), ("TRACK_VEL_SHIFT", tp.vel_shift),
        ("TRACK_MAX_SPEED", tp.max_speed_v),
        ("TOUCH_ON_THRESHOLD", tp.on_threshold), ("TRACK_CONFIRM", tp.confirm_frames),
        ("BLOB_THRESHOLD", settings.blob_threshold), ("BLOB_MIN_CELLS", settings.blob_min_cells),
        ("LATENCY_DIAL", 0), ("REPORT_PERIOD", 0),
    ]


def cal_writes(cfg, cal) -> list:
    """(name, value) writes loading the calibration (offset, gain) through the windows."""
    out = []
    if cal is None:
        return out
    off, gain = cal
    for r in range(cfg.rows):
        out.append(("CAL_ROW", r))
        for c in range(cfg.cols):
            out += [("CAL_COL", c), ("CAL_OFFSET", int(off[r, c])), ("CAL_GAIN", int(gain[r, c]))]
    return out


# ---- logs ------------------------------------------------------------------------------
def parse_logs(d: Path, cfg, max_cycle: int | None = None):
    """Heat-map rows, ends of frame, events and receiver frame ends of the logs;
    max_cycle: only lines logged before that cycle (serve mode: the scene's part)."""
    hm_rows, eof, evs, fend = {}, [], [], {}
    keep = (lambda cyc: True) if max_cycle is None else (lambda cyc: cyc < max_cycle)
    w = cfg.hm_width
    mask = (1 << w) - 1
    for line in (d / "hm.log").read_text().splitlines():
        p = line.split()
        if not keep(int(p[1])):
            continue
        if p[0] == "R":
            word = int(p[4], 16)
            hm_rows.setdefault(int(p[3]), {})[int(p[2])] = (
                int(p[1]), [(word >> (c * w)) & mask for c in range(cfg.cols)])
        elif p[0] == "E":
            eof.append((int(p[1]), int(p[2])))
    for line in (d / "ev.log").read_text().splitlines():
        p = line.split()
        if p[0] == "V" and keep(int(p[1])):
            v = [int(x) for x in p[1:]]
            evs.append({"cycle": v[0], "frame": v[1], "id": v[2], "type_code": v[3], "x_q": v[4],
                        "y_q": v[5], "strength": v[6], "axis_major_q": v[7], "axis_minor_q": v[8],
                        "angle": v[9], "flags": v[10], "last": v[11], "time": v[12],
                        "type": TYPE_NAMES[v[3]]})
    for line in (d / "fe.log").read_text().splitlines():
        p = line.split()
        if p[0] == "F" and keep(int(p[1])):
            fend[int(p[2])] = int(p[1])
    return hm_rows, eof, evs, fend


def _key(e) -> tuple:
    g = (lambda k: e[k]) if isinstance(e, dict) else (lambda k: getattr(e, k))
    return (g("frame") & 0xFFFF, g("id"), g("type_code"), g("x_q"), g("y_q"), g("strength"),
            g("axis_major_q"), g("axis_minor_q"), g("angle"), g("flags"))


def _stats(v) -> dict:
    if not v:
        return {"n": 0, "min": None, "median": None, "max": None}
    a = np.asarray(v, dtype=np.float64)
    return {"n": int(a.size), "min": float(a.min()), "median": float(np.median(a)), "max": float(a.max())}


def analyse(scene: _scene.Scene, ref: Reference, d: Path, cps: int, status: dict, frames: int,
            wall_s: float, out_dir: Path | None, plot: bool, cal, max_cycle: int | None = None,
            confirm_frames: int = 1) -> dict:
    from fmt import run_sim as _run_sim
    cfg = scene.cfg
    clk_hz = cfg.fs_hz * cps
    hm_rows, eof, evs, fend = parse_logs(d, cfg, max_cycle)
    # heat maps, frame by frame
    n_rtl = len(eof)
    mism = {"heatmap_frames": 0, "event_frames": 0, "first": None}
    rtl_hm = np.zeros((n_rtl, cfg.rows, cfg.cols), dtype=np.int64)
    dropped = 0
    for f in range(frames):
        rows = hm_rows.get(f & 0xFFFF)
        if f >= n_rtl or rows is None or len(rows) != cfg.rows:
            dropped += 1
            continue
        for r, (_c, cells) in rows.items():
            rtl_hm[f, r] = cells
        if not np.array_equal(rtl_hm[f], ref.heatmaps[f]):
            mism["heatmap_frames"] += 1
            if mism["first"] is None:
                mism["first"] = f"heat map of frame {f}"
    # events, per frame sorted by ID
    per = {}
    for e in evs:
        per.setdefault(e["frame"], []).append(e)
    for f in range(min(frames, n_rtl)):
        got = sorted((_key(e) for e in per.get(f & 0xFFFF, [])), key=lambda t: t[1])
        exp = sorted((_key(e) for e in ref.events[f]), key=lambda t: t[1])
        if got != exp:
            mism["event_frames"] += 1
            if mism["first"] is None:
                mism["first"] = f"events of frame {f}: RTL {got} model {exp}"
    # latency: frame end -> first / last event of the frame
    first_lat, last_lat = [], []
    for f, es in per.items():
        if f in fend and es:
            first_lat.append((min(e["cycle"] for e in es) - fend[f]) / clk_hz * 1e6)
            last_lat.append((max(e["cycle"] for e in es) - fend[f]) / clk_hz * 1e6)
    # onset -> first new event of that contact after the onset (true onset sample)
    onset_lat = []
    fs = cfg.fs_hz
    new_evs = [e for e in evs if e["type"] == "new"]
    for c in scene.contacts:
        if c.active is None:
            continue
        for on, off in c.intervals_samples(fs):
            on_cyc = int(on) * cps
            if on_cyc <= 0 or int(on) >= frames * scene.samples_per_frame:
                continue
            x, y = c.position(on / fs)
            for e in new_evs:
                if e["cycle"] > on_cyc and math.hypot(e["x_q"] / 256 * cfg.pitch_mm - x,
                                                      e["y_q"] / 256 * cfg.pitch_mm - y) <= _run_sim.MATCH_MM:
                    onset_lat.append((e["cycle"] - on_cyc) / clk_hz * 1e6)
                    break
    # accuracy from the RTL events
    frame_events = [per.get(f & 0xFFFF, []) for f in range(min(frames, n_rtl))]
    det = _run_sim.detections(frame_events, cfg)
    acc = _run_sim.evaluate(scene.replace(frames=len(det)), det, confirm_frames)
    rate = None
    if len(eof) > 1:
        rate = (len(eof) - 1) / ((eof[-1][0] - eof[0][0]) / clk_hz)
    rep = {
        "scene": scene.name, "sensor": cfg.name, "path": "rtl", "clk_per_sample": cps,
        "frames": n_rtl, "frames_requested": frames,
        "frames_dropped": dropped + int(status.get("EV_DROP_COUNT", 0)),
        "ev_drop_count": int(status.get("EV_DROP_COUNT", 0)),
        "heatmap_rate_hz": rate,
        "events": len(evs),
        "latency_us": {"window_end_to_event": _stats(first_lat),
                       "window_end_to_last_event": _stats(last_lat),
                       "onset_to_event": _stats(onset_lat)},
        "latency_fs_cycles": {"window_end_to_event_max": (max(first_lat) * fs / 1e6) if first_lat else None,
                              "window_end_to_last_event_max": (max(last_lat) * fs / 1e6) if last_lat else None},
        "position_error_mm": acc["position_error_mm"],
        "jitter_mm": acc["jitter_mm"],
        "missed": acc["missed"], "false": acc["false"],
        "tracking": acc["tracking"],
        "golden_mismatches": mism["heatmap_frames"] + mism["event_frames"],
        "golden_detail": mism,
        "sim_frames_per_s": n_rtl / max(wall_s, 1e-9),
        "sim_wall_s": wall_s,
        "clipped_samples_model": ref.clipped,
        "status": status,
    }
    if out_dir is not None:
        od = Path(out_dir) / scene.name
        od.mkdir(parents=True, exist_ok=True)
        if plot and n_rtl:
            try:
                from fmt import flatten as _flatten
                from fmt import plots as _plots
                flat = _flatten.flatten_float(rtl_hm, cal[0], cal[1], cfg) if cal is not None else rtl_hm
                _plots.heatmap_with_tracks(flat, scene.replace(frames=n_rtl),
                                           _run_sim.tracks(frame_events, cfg), od / "heatmap.png")
                rep["png"] = str(od / "heatmap.png")
                latency_histogram(first_lat, last_lat, onset_lat, od / "latency_hist.png")
                rep["latency_png"] = str(od / "latency_hist.png")
                if os.environ.get("FMT_GIF"):        # the animated view, on request (imageio)
                    step = max(1, int(os.environ.get("FMT_GIF_STEP", "1")))
                    _plots.animation_gif(flat, frame_events, cfg, od / "heatmap.gif", step=step)
                    rep["gif"] = str(od / "heatmap.gif")
            except Exception as exc:          # plots are a convenience, never fatal
                rep["plot_error"] = repr(exc)
        _run_sim.write_events(od / "events.jsonl", frame_events)    # the compared frames
        rep["events_file"] = str(od / "events.jsonl")
        rep["events_in_file"] = int(sum(len(e) for e in frame_events))
        (od / "report.json").write_text(json.dumps(rep, indent=1) + "\n")
        rep["report"] = str(od / "report.json")
    return rep


def latency_histogram(first, last, onset, path) -> None:
    """The latency plot: one panel per population, each on its own range (fmt.plots)."""
    from fmt import plots as _plots
    _plots.latency_panels(first, last, onset, path)


# ---- the run ---------------------------------------------------------------------------
def sim_parameters(cfg, cps: int, d: Path) -> dict:
    return {"ROWS": cfg.rows, "COLS": cfg.cols, "LOG2_N": cfg.log2_n, "BIN_LO": cfg.bin_lo,
            "HM_W": cfg.hm_width, "MAX_TOUCHES": cfg.max_touches, "CLK_PER_SAMPLE": cps,
            "EV_DEPTH": 2048, "UART_DIV": 4,
            "CHAN_FILE": f'"{d / "chan.hex"}"', "GAUSS_FILE": f'"{d / "gauss.hex"}"',
            "SINE_FILE": f'"{d / "sine.hex"}"',
            "UPD_LEN": upd_len(cfg), "UPD_FILE": f'"{d / "upd.hex"}"',
            "HM_LOG": f'"{d / "hm.log"}"', "EV_LOG": f'"{d / "ev.log"}"', "FE_LOG": f'"{d / "fe.log"}"'}


def sim_sources() -> list:
    """fmt_core's list (rtl/filelists/fmt_core.f) and the bench's Verilog."""
    return sources("fmt_core") + [BENCH / "fmt_channel_sim.v", BENCH / "fmt_core_sim_top.v"]


def build_args(sim: str, fast_sim: bool = True) -> list:
    """Build options; fast_sim: optimise the model (long runs) rather than the build (tests)."""
    args = [rom_define()]
    if sim == "verilator":
        args += ["-O3", "--x-assign", "fast", "--x-initial", "fast"] if fast_sim else ["-CFLAGS", "-O0"]
    return args


# ---- the standalone C++ harness (bench/core/sim_main.cpp) ---------------------------------
HARNESS_SRC = BENCH / "sim_main.cpp"
HARNESS_CFLAGS = "-O3 -march=native"
STATUS_REGS = ("FRAME_COUNT", "STATUS", "EV_DROP_COUNT", "EV_SKIP_COUNT", "FLAT_SAT_COUNT",
               "LM_DROP_COUNT", "LAT_FIRST_MIN", "LAT_FIRST_MAX", "LAT_FIRST_COUNT",
               "LAT_LAST_MIN", "LAT_LAST_MAX", "LAT_LAST_COUNT")


def harness_dir(cfg, cps: int, tag: str = "") -> Path:
    return ROOT / "build" / "sim_cpp" / f"{cfg.name}_c{cps}{'_' + tag if tag else ''}"


def harness_args(cfg, cps: int, d: Path, bdir: Path, cflags: str = HARNESS_CFLAGS,
                 verilog_channel: bool = False) -> list:
    """Verilator command line of the harness build: fast model (-O3, x fast, no
    assertions, no tracing, one thread), fmt_core_sim_top with EXT_CHANNEL = 1 (the
    channel in C++), the log files of the job folder ``d`` (Verilog parameters).
    verilog_channel: EXT_CHANNEL = 0 instead (fmt_channel_sim + the Verilog player; the
    harness then leaves the channel to the model: a cross-check and a speed comparison)."""
    p = sim_parameters(cfg, cps, d)
    if not verilog_channel:
        for k in ("CHAN_FILE", "GAUSS_FILE", "SINE_FILE", "UPD_FILE"):
            p.pop(k)                               # the C++ channel reads them (job file)
        p["UPD_LEN"] = 1
    p["EXT_CHANNEL"] = 0 if verilog_channel else 1
    args = ["--cc", "--exe", "--build", "-O3", "--x-assign", "fast", "--x-initial", "fast",
            "--noassert", "-Wno-fatal", "-Wno-lint", "-Wno-style", "--output-split", "0",
            "--top-module", "fmt_core_sim_top", "-Mdir", str(bdir), "-o", "Vfmt_core_sim_top",
            *[f"-I{d}" for d in INCLUDE_DIRS], rom_define(),
            "-CFLAGS", cflags, "-MAKEFLAGS", "--no-print-directory",
            # verilated.mk compiles the harness and the runtime with OPT_GLOBAL (-Os) after
            # CFLAGS: the same optimisation everywhere
            "-MAKEFLAGS", f"OPT_FAST={cflags.split()[0]}", "-MAKEFLAGS", f"OPT_GLOBAL={cflags.split()[0]}"]
    args += [f"-G{k}={v}" for k, v in p.items()]
    return args + [str(s) for s in sim_sources()] + [str(HARNESS_SRC)]


def harness_build(cfg, cps: int, d: Path, tag: str = "", cflags: str = HARNESS_CFLAGS,
                  quiet: bool = False, verilog_channel: bool = False) -> tuple[Path, float]:
    """Build (or reuse) the harness executable; rebuilt only when a source file, the
    command line or the Verilator version changed.  Returns (executable, build seconds)."""
    import hashlib
    import shutil
    import subprocess
    bdir = harness_dir(cfg, cps, tag + ("_vch" if verilog_channel and not tag.endswith("_vch") else ""))
    exe = bdir / "Vfmt_core_sim_top"
    args = harness_args(cfg, cps, d, bdir, cflags, verilog_channel)
    verilator = shutil.which("verilator")
    if verilator is None:
        raise RuntimeError("verilator not on PATH (source scripts/env.sh)")
    h = hashlib.sha1(json.dumps(args).encode())
    h.update(subprocess.run([verilator, "--version"], capture_output=True, text=True).stdout.encode())
    for s in sim_sources() + [HARNESS_SRC, BENCH / "channel_fx.h", ROOT / "rtl" / "fmt_defaults.vh"]:
        h.update(Path(s).read_bytes())
    for s in sorted((ROOT / "rtl").glob("*.vh")) + sorted((ROOT / "rtl").glob("*.hex")):
        h.update(s.name.encode() + Path(s).read_bytes())
    key = h.hexdigest()
    stamp = bdir / "build.key"
    if exe.exists() and stamp.exists() and stamp.read_text() == key:
        return exe, 0.0
    if bdir.exists():
        shutil.rmtree(bdir)
    bdir.mkdir(parents=True)
    env = dict(os.environ)
    if "OBJCACHE" not in env and shutil.which("ccache"):
        env["OBJCACHE"] = "ccache"
    if not quiet:
        print(f"building the Verilator harness in {bdir} (full size: minutes) ...", file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    r = subprocess.run([verilator] + args, cwd=bdir, env=env, capture_output=True, text=True)
    (bdir / "build.log").write_text(r.stdout + r.stderr)
    if r.returncode != 0 or not exe.exists():
        raise RuntimeError(f"harness build failed, see {bdir / 'build.log'}:\n{r.stderr[-3000:]}")
    stamp.write_text(key)
    return exe, time.perf_counter() - t0


def write_cpp_job(path: Path, cfg, cps: int, job: dict, d: Path, progress: int,
                  verilog_channel: bool = False, serve: dict | None = None,
                  pre: dict | None = None) -> None:
    """The job of the C++ harness: the same phases as the cocotb run_scene; serve:
    {"port", "seconds", "cycles", "once", "log_clk"} for serve mode (see the module doc;
    log_clk: clk of serving with the loggers on, -1 = all)."""
    from fmt import regmap as _regmap
    addr = lambda n: _regmap.lookup(n).addr
    lines = [f"rows {cfg.rows}", f"cols {cfg.cols}", f"cps {cps}", f"frames {job['frames']}",
             f"progress {int(progress)}",        # 0 off, 1 terminal (\\r), 2 whole lines
             f"ext_channel {0 if verilog_channel else 1}",
             f"chan_file {d / 'chan.hex'}", f"gauss_file {d / 'gauss.hex'}",
             f"sine_file {d / 'sine.hex'}", f"upd_file {d / 'upd.hex'}",
             f"reset_cycles {job['reset_cycles']}", f"run_cycles {job['run_cycles']}",
             f"out {d / 'result.json'}"]
    for key in ("cal", "regs"):
        lines.append(f"{key} {len(job[key])}")
        lines += [f"{addr(n)} {int(v) & 0xFFFFFFFF}" for n, v in job[key]]
    if pre is not None:      # a busy core before the reset under test (sim_main.cpp header)
        lines += [f"pre_cycles {int(pre['cycles'])}", f"pre_seed {int(pre['seed'])}",
                  f"pre_regs {len(pre['regs'])}"]
        lines += [f"{addr(n)} {int(v) & 0xFFFFFFFF}" for n, v in pre["regs"]]
    lines.append(f"status {len(STATUS_REGS)}")
    lines += [f"{n} {addr(n)}" for n in STATUS_REGS]
    if serve is not None:
        lines += [f"serve_port {int(serve['port'])}", f"serve_div {sim_parameters(cfg, cps, d)['UART_DIV']}",
                  f"serve_seconds {float(serve.get('seconds', 600.0))}",
                  f"serve_cycles {int(serve.get('cycles', 0))}", f"serve_once {int(bool(serve.get('once')))}",
                  f"serve_log_clk {int(serve.get('log_clk', -1))}", f"serve_log {d / 'serve.log'}"]
    Path(path).write_text("\n".join(lines) + "\n")


def run_harness(scene: _scene.Scene, frames: int, cps: int, settings=None, cal="scene",
                tag: str = "cpp", quiet: bool = False, cflags: str = HARNESS_CFLAGS,
                verilog_channel: bool = False, serve: dict | None = None, pre: dict | None = None):
    """Build (cached) and run the C++ harness on a prepared job folder; returns
    (job folder, reference, calibration, number of updates, result dict, build seconds).
    serve: serve mode (write_cpp_job); the harness's stdout (the "serving ..." line) is
    this process's, and Ctrl-C ends the serving, not this wait."""
    import subprocess
    if verilog_channel:
        tag += "_vch"
    d, ref, cal, n_upd = prepare(scene, frames, cps, settings, cal=cal, tag=tag)
    exe, build_s = harness_build(scene.cfg, cps, d, tag=tag, cflags=cflags, quiet=quiet,
                                 verilog_channel=verilog_channel)
    job = json.loads((d / "job.json").read_text())
    from fmt.progress import is_tty
    write_cpp_job(d / "job_cpp.txt", scene.cfg, cps, job, d,
                  progress=0 if quiet else (1 if is_tty(sys.stderr) else 2),
                  verilog_channel=verilog_channel, serve=serve, pre=pre)
    (d / "serve.log").unlink(missing_ok=True)
    t0 = time.perf_counter()
    sys.stdout.flush()
    proc = subprocess.Popen([str(exe), str(d / "job_cpp.txt")], cwd=d,
                            stderr=None if not quiet else subprocess.PIPE)
    while True:
        try:
            _out, err = proc.communicate()
            break
        except KeyboardInterrupt:
            if serve is None:           # a normal run: Ctrl-C stops it
                proc.kill()
                raise
            # serve mode: the harness got the SIGINT too and ends its serving cleanly
    proc_s = time.perf_counter() - t0
    if serve is not None and proc.returncode == -2:      # SIGINT before the serving began
        raise KeyboardInterrupt
    if proc.returncode != 0:
        raise RuntimeError(f"harness failed ({proc.returncode}): {err.decode()[-2000:] if err else ''}")
    res = json.loads((d / "result.json").read_text())
    res["process_s"] = proc_s
    return d, ref, cal, n_upd, res, build_s


def prepare(scene: _scene.Scene, frames: int, cps: int, settings=None, cal="scene", tag: str = ""):
    """Write the job folder (records, noise, job.json) and compute the reference.  ``cal``:
    "scene" (the real procedure, :func:`calibration_fixed`), "noiseless" (the old
    noiseless render), None (none loaded) or an (offset, gain) pair."""
    from fmt import run_sim as _run_sim
    cfg = scene.cfg
    eff = check_scene(scene)
    settings = settings or scene.touch_settings()
    d = job_dir(cfg, cps, tag)
    d.mkdir(parents=True, exist_ok=True)
    n = frames * scene.samples_per_frame
    g0, updates = coupling_plan(scene, n, cps)
    rec = plan_records(cfg, g0, updates)
    if len(rec) > upd_len(cfg):
        raise ValueError(f"{len(rec)} update records > capacity {upd_len(cfg)}: fewer frames")
    write_records(d / "upd.hex", rec)
    write_channel_files(d, eff)
    if cal == "scene":              # the real procedure on noisy frames, fixed point
        cal = calibration_fixed(scene, cps)
    elif cal == "noiseless":        # the old, always perfect one (noiseless renders)
        cal = _run_sim.calibration(scene, mode="noiseless")
        cal = (np.asarray(cal[0], dtype=np.int64), np.asarray(cal[1], dtype=np.int64))
    ref = model_reference(scene, g0, updates, eff, frames, settings, cal, cps)
    # cycles: all frames end, plus the post-processing tail
    run_cycles = (n + 4) * cps + 2 * scene.samples_per_frame * cps + 1000
    job = {"frames": frames, "cps": cps, "run_cycles": run_cycles,
           "reset_cycles": int(np.count_nonzero(g0)) + 16,
           "cal": cal_writes(cfg, cal), "regs": register_writes(scene, settings),
           "out": str(d / "result.json"), "n_updates": len(updates)}
    for f in ("hm.log", "ev.log", "fe.log", "result.json"):
        (d / f).unlink(missing_ok=True)
    (d / "job.json").write_text(json.dumps(job))
    return d, ref, cal, len(updates)


def run(scene: _scene.Scene, out_dir=None, frames: int | None = None, cps: int = 3,
        sim: str = "verilator", plot: bool = True, quiet: bool = False, settings=None,
        engine: str = "cpp", serve: dict | None = None, tag: str = "cpp",
        cflags: str = HARNESS_CFLAGS, pre: dict | None = None, cal="scene") -> dict:
    """engine "cpp": the standalone C++ harness (Verilator only, the default of
    ``make sim``); "cocotb": the cocotb test run_scene (Verilator or Icarus).
    serve (engine cpp only): serve the UART after the scene (write_cpp_job); tag and
    cflags: the harness's job folder / build (tests use their own, at -O0)."""
    if serve is not None and not (engine == "cpp" and sim == "verilator"):
        raise ValueError("--serve needs the C++ harness (engine cpp, Verilator)")
    settings = settings or scene.touch_settings()
    if pre is not None and not (engine == "cpp" and sim == "verilator"):
        raise ValueError("a busy core before the reset (pre) needs the C++ harness (engine cpp, Verilator)")
    frames = frames or scene.frames
    scene = scene.replace(frames=frames)
    check_scene(scene)                 # refuse an effect the RTL cannot apply, before any build
    if engine == "cpp" and sim == "verilator":
        t0 = time.perf_counter()
        d, ref, cal, n_upd, res, build_s = run_harness(scene, frames, cps, settings, cal=cal, quiet=quiet,
                                                      tag=tag, cflags=cflags, serve=serve, pre=pre)
        rep = analyse(scene, ref, d, cps, res.get("status", {}), frames, res["wall_s"], out_dir, plot, cal,
                      max_cycle=res.get("serve_start_cycle"), confirm_frames=settings.confirm_frames)
        if "serve" in res:
            rep["serve"] = dict(res["serve"], start_cycle=res["serve_start_cycle"])
        rep.update({"engine": "cpp", "build_s": build_s, "sim_clk_per_s": res["clk_per_s"],
                    "sim_cpu_s": res["cpu_s"],
                    "sim_frames_per_cpu_s": rep["frames"] / max(res["cpu_s"], 1e-9),
                    "sim_run_clk": res["run_clk"], "coupling_updates": n_upd,
                    "upd_late": res.get("upd_late"), "upd_done": res.get("upd_done"),
                    "total_s": time.perf_counter() - t0})
        if out_dir is not None:
            Path(rep["report"]).write_text(json.dumps({k: v for k, v in rep.items() if k != "report"},
                                                      indent=1) + "\n")
        return rep
    from common.runner import run_cocotb
    t0 = time.perf_counter()
    # the job folder: one per simulator, and per tag when a caller gives one (tests that
    # run at the same time under pytest-xdist must not share job.json and the logs)
    jtag = ("" if sim == "verilator" else sim) + ("" if tag == "cpp" else f"_{tag}")
    d, ref, cal, n_upd = prepare(scene, frames, cps, settings, cal=cal, tag=jtag.lstrip("_"))
    t1 = time.perf_counter()
    env = {"FMT_CORE_JOB": str(d / "job.json"), "FMT_QUIET": int(quiet)}
    run_cocotb(sim=sim, toplevel="fmt_core_sim_top", sources=sim_sources(),
               test_module="core_cocotb", test_dir=BENCH,
               testcase="run_scene", parameters=sim_parameters(scene.cfg, cps, d),
               extra_env=env, build_args=build_args(sim), tag="run_sim_rtl")
    res = json.loads((d / "result.json").read_text())
    rep = analyse(scene, ref, d, cps, res.get("status", {}), frames, res["wall_s"], out_dir, plot, cal,
                  confirm_frames=settings.confirm_frames)
    rep["model_s"] = t1 - t0
    rep["coupling_updates"] = n_upd
    rep["upd_late"] = res.get("upd_late")
    if out_dir is not None:
        Path(rep["report"]).write_text(json.dumps({k: v for k, v in rep.items() if k != "report"},
                                                  indent=1) + "\n")
    return rep


def _summary(rep: dict) -> str:
    f = lambda v: "n/a" if v is None else f"{v:.3f}"
    lat = rep["latency_us"]
    pe = rep["position_error_mm"]
    return (f"{rep['scene']} (RTL, {rep['sensor']}, {rep['clk_per_sample']} clk/sample): "
            f"{rep['frames']} frames, dropped {rep['frames_dropped']}, "
            f"golden mismatches {rep['golden_mismatches']}, "
            f"window end -> event max {f(lat['window_end_to_event']['max'])} us "
            f"(last {f(lat['window_end_to_last_event']['max'])} us), onset -> event median "
            f"{f(lat['onset_to_event']['median'])} us, position rms {f(pe['rms'])} mm, "
            f"edge rms {f(pe['rms_edge'])} mm, jitter {f(rep['jitter_mm']['max'])} mm, "
            f"{rep['sim_frames_per_s']:.1f} frames/s simulated"
            + (f" ({rep['sim_clk_per_s']:.0f} clk/s; {rep['sim_frames_per_cpu_s']:.1f} frames per CPU second)"
               if "sim_frames_per_cpu_s" in rep else ""))


def verdict(rep: dict) -> tuple[int, str]:
    """(exit status, one line) of a run: 1 when no frame arrived, frames were dropped or
    the golden model disagrees, else 0."""
    want = rep.get("frames_requested", rep["frames"])
    if rep["frames"] == 0:
        return 1, f"run_sim_rtl: FAIL: no frame arrived (0 of {want} requested)"
    if rep["frames_dropped"]:
        return 1, (f"run_sim_rtl: FAIL: {rep['frames_dropped']} frames dropped "
                   f"({rep['frames']} of {want} arrived, event FIFO drops {rep.get('ev_drop_count', 0)})")
    if rep["golden_mismatches"]:
        first = " ".join(str((rep.get("golden_detail") or {}).get("first") or "").split())[:200]
        return 1, (f"run_sim_rtl: FAIL: {rep['golden_mismatches']} golden mismatches"
                   + (f", first: {first}" if first else ""))
    return 0, ""


def positive_int(text: str) -> int:
    v = int(text)
    if v < 1:
        raise ValueError(text)
    return v


def main(argv=None) -> int:
    from fmt.inputs import InputError, OneLineParser
    ap = OneLineParser(description="Run a scene through the RTL (fmt_core) under Verilator.")
    ap.add_argument("--scene", default=str(ROOT / "sim" / "scenes" / "default.json"))
    ap.add_argument("--out", default=str(ROOT / "build" / "sim"))
    ap.add_argument("--frames", type=positive_int, default=None)
    ap.add_argument("--cps", type=positive_int, default=3,
                    help="clk cycles per sample (CLK_PER_SAMPLE)")
    ap.add_argument("--sim", default="verilator", choices=("verilator", "icarus"))
    ap.add_argument("--engine", default="cpp", choices=("cpp", "cocotb"),
                    help="cpp: the standalone C++ Verilator harness (default, Verilator only); "
                         "cocotb: the cocotb test run_scene (Verilator or Icarus, ~40x slower)")
    ap.add_argument("--settings", default=None,
                    help="touch settings file (JSON, TouchSettings fields); default the scene's")
    ap.add_argument("--cal", default="scene", choices=("scene", "noiseless"),
                    help="calibration: scene (the real procedure on noisy untouched / sheet frames "
                         "through the fixed-point chain, default) or noiseless (the old perfect one)")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--quiet", action="store_true")
    ap.add_argument("--serve", type=int, default=None, metavar="PORT",
                    help="after the scene, keep the simulation running and serve the core's UART on "
                         "socket://127.0.0.1:PORT for scripts/fmtctl (0: any free port); Ctrl-C ends it")
    ap.add_argument("--serve-seconds", type=float, default=600.0,
                    help="end serving after this wall time (default 600 s, 0 = no limit)")
    ap.add_argument("--serve-once", action="store_true",
                    help="end serving when the first client disconnects")
    ap.add_argument("--serve-log-frames", type=int, default=2000,
                    help="keep the heat-map/event loggers on for this many frames of serving "
                         "(default 2000; -1 = all: the logs of a long full-size session grow by MB/s)")
    ap.add_argument("--tag", default="cpp", help="job folder / build tag of the C++ harness")
    ap.add_argument("--cflags", default=HARNESS_CFLAGS,
                    help=f"C++ flags of the harness build (default '{HARNESS_CFLAGS}'; tests: -O0)")
    a = ap.parse_args(argv)
    try:
        sc = _scene.load(a.scene)
        st = _settings.load(a.settings) if a.settings else sc.touch_settings()
    except InputError as exc:
        print(f"run_sim_rtl: {exc}", file=sys.stderr)
        return 2
    if a.serve is not None and not (a.engine == "cpp" and a.sim == "verilator"):
        print("run_sim_rtl: --serve needs the C++ harness (--engine cpp, --sim verilator)", file=sys.stderr)
        return 2
    try:
        check_scene(sc)
    except _channel.UnsupportedEffect as exc:
        print(f"run_sim_rtl: scene '{sc.name}' refused: {exc}", file=sys.stderr)
        return 2
    serve = None
    if a.serve is not None:
        spf_clk = sc.samples_per_frame * a.cps
        serve = {"port": a.serve, "seconds": a.serve_seconds, "once": a.serve_once,
                 "log_clk": -1 if a.serve_log_frames < 0 else a.serve_log_frames * spf_clk}
    try:
        rep = run(sc, a.out, frames=a.frames, cps=a.cps, sim=a.sim, plot=not a.no_plot, quiet=a.quiet,
                  settings=st, engine=a.engine, serve=serve, tag=a.tag, cflags=a.cflags, cal=a.cal)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    print(_summary(rep))
    if "serve" in rep:
        s = rep["serve"]
        print(f"served the UART for {s['clk']} clk ({s['wall_s']:.1f} s, {s['clients']} clients, "
              f"{s['bytes_in']} bytes in, {s['bytes_out']} out), end: {s['end']}")
    print(f"report: {rep['report']}")
    code, line = verdict(rep)
    if code:
        sys.stdout.flush()
        print(line, file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())
