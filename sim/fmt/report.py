"""``make report``: speed against error, a sweep over the fixed-point model.

    python -m fmt.report --full  [--out build/report]     (the whole sweep, ~5-10 min)
    python -m fmt.report --smoke [--out build/report]     (two points, a few seconds)

What one point is
-----------------
A point is (M windows per frame, SNR per window, interpolator = Von Neumann or Moore,
bias correction on / off, heat-map width HM_W).  Frame rate = fs / (N M); latency =
window end -> event (the RTL's figures, see *Latency*) + (M - 1) windows of integration
that an onset at the start of a frame waits for.

How a point is measured (the cheapest faithful path)
----------------------------------------------------
* Scenes on the DEFAULT 30 x 40 sensor, default physics (8 mm disk fingers of strength 1,
  white ADC noise set by ``channel.noise_sigma_for_snr`` so that a finger centred on a
  cell has ``snr_db`` in ONE window; averaging M windows adds 10 log10 M dB by itself).
  Each scene holds 12 stationary interior contacts (a 3 x 4 grid, 45 mm apart, each at a
  random sub-cell offset, uniform over a whole cell) and 4 stationary edge contacts, one
  per edge, centred 1.5 - 3.5 mm from it (uniform) at a random position along it.  The
  SAME scenes (positions) are used at every (M, SNR) point (common random numbers: the
  differences between points are not position sampling noise); the noise differs.
* Heat maps: ``chain.render_heatmaps`` of the scene with M = 1 gives the per-window cells
  hm_scale * |S + n| (S the exact comb-bin DFT of the noiseless column signal, n complex
  Gaussian with the statistics of a DFT bin of the ADC noise plus its quantisation).  They
  are then quantised like the fixed receive chain (``quantise``): the magnitude word of
  ``fmt_magnitude`` is |2A| in FFT-output LSBs = 2 x cell with MAG_FRAC fractional bits,
  truncated, and the M-window accumulation is ``rx_fixed.accum_fixed`` (the twin of
  ``fmt_rx_array``'s accumulator: sum, round half up of sum / 2M, saturate, for any
  M = 1 .. 255).  What this omits: the FFT's own rounding and the CORDIC
  error (both ~1 count, against >= 100 counts of noise at 40 dB), clipping, PN.  The
  agreement with the full path (ADC -> ``rx_fixed.rx_heatmaps_fixed``) is checked in
  ``sim/tests/test_report.py`` (noise statistics within the stated tolerances).
  Every swept M (16 and 40 included) is an RTL mode of the default build: fmt_rx_array
  takes any M = 1 .. M_MAX = 255 and divides exactly (reciprocal multiply, bit-exact with
  accum_fixed; tb/fmt_rx_array checks M = 3 and 5, tb/fmt_core M = 3).
* Other widths HM_W: the rendered cells scale exactly with 2^(HM_W - 16) (hm_scale), so the
  same rendered noise is quantised at HM_W bits (also checked in the test); the touch
  threshold (2000 counts at 16 bits) and the calibration scale with it.  The fit's own
  widths (8 fractional bits, the 9-bit offset quotient ``interp.DIV_QW``) are module
  constants of ``fmt.interp`` and of the RTL, not parameters: they are not swept.
* Touch processing: ``touch.process_frames(hm, cfg, settings, fixed=True)``, the bit-exact
  twin of ``rtl/fmt_touch.v`` (tb/fmt_touch checks the RTL against it bit for bit), with
  the flattening calibration of ``run_sim.calibration`` (noiseless untouched + sheet
  renders) and the tracking settings converted at the point's frame period.
* Scoring: ``run_sim.detections`` + ``run_sim.evaluate`` per scene: position error =
  distance of the detection from the true centre per frame, RMS over (contact, frame)
  for contacts more than 3.5 mm from every edge, and separately for contacts centred
  1.5 - 3.5 mm from an edge; jitter of a stationary contact = RMS distance of its
  positions about their mean over the scene's F frames, here with the F / (F - 1)
  correction (unbiased for the variance), pooled as the RMS over the interior contacts.
  Confidence: 95 % intervals from the spread between scenes (independent positions and
  noise), delta method for the square root.

Latency
-------
window end -> event = receive chain (last ADC sample of the frame's last window -> last
heat-map row beat: ``rx_clk`` processing-clock cycles at 3 x fs, the figure measured and
asserted by tb/fmt_rx_array ``latency_and_slow_ce``; computed here from its formula and
compared with ``build/rx_latency_default_postclk1_cps3.txt`` when that file exists) + touch processing
(last row beat -> last event on the event port: ``--touch-clk``, default 140 cycles = the
bound tb/fmt_touch asserts on scene heat maps and 16 fingers (``BUDGET``); the header of rtl/fmt_touch.v
gives the per-stage figures 4 + (6 + n) + 23 + (events + 5) + 3).  Plus (M - 1) N / fs.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import chain as _chain
from . import fft_r22sdf as _fft
from . import params as _params
from . import run_sim as _run_sim
from . import rx_array as _rx
from . import scene as _scene
from . import touch as _touch
from .progress import Progress
from .settings import TouchSettings

ROOT = Path(__file__).resolve().parents[2]
CLK_PER_SAMPLE = 3                  # processing clock = 3 x fs (docs/ARCHITECTURE.md)
TOUCH_CLK_DEFAULT = 140             # tb/fmt_touch BUDGET (last row beat -> last event)
BASE_THRESHOLD = 2000               # TouchSettings().threshold at HM_W = 16
INTERPS = (("vn", False), ("vn", True), ("moore", False), ("moore", True))
PAPER_RATE_HZ, PAPER_LAT_US = 4000.0, 40.0
WIN_ACC_MM, WIN_EDGE_MM, WIN_JIT_MM = 1.0, 2.0, 0.5          # Windows requirements
TARGET_ACC_MM, TARGET_JIT_MM, TARGET_M = 0.25, 0.05, 40        # project targets at M = 40


@dataclass(frozen=True)
class SweepSpec:
    ms: tuple
    snrs: tuple
    widths: tuple                   # HM_W values; the first one gets every interpolator
    interps: tuple                  # (neighbourhood, bias) at the first width
    width_interps: tuple            # (neighbourhood, bias) at the other widths
    scenes: int                     # independent scenes (position sets) per point
    frames: int                     # frames per scene
    seed: int = 1


FULL = SweepSpec(ms=(1, 2, 4, 8, 16, 40), snrs=(20.0, 30.0, 40.0), widths=(16, 12, 10, 8),
                 interps=INTERPS, width_interps=(("moore", True),), scenes=40, frames=16)
SMOKE = SweepSpec(ms=(1, 8), snrs=(30.0,), widths=(16,), interps=(("moore", True),),
                  width_interps=(), scenes=3, frames=8)


# ---- scenes -------------------------------------------------------------------------------
GRID_ROWS = (5, 14, 23)             # interior anchors (cells): 45 mm apart, >= 27 mm from edges
GRID_COLS = (5, 14, 23, 32)


def layout(cfg, rng) -> list:
    """12 interior + 4 edge stationary 8 mm fingers (names 'in<k>' / 'edge<k>')."""
    p = cfg.pitch_mm
    cts = []
    for r in GRID_ROWS:
        for c in GRID_COLS:
            x = (c + rng.uniform(-0.5, 0.5)) * p
            y = (r + rng.uniform(-0.5, 0.5)) * p
            cts.append(_scene.Contact(name=f"in{len(cts)}", path=[[0.0, float(x), float(y)]]))
    lo_x, hi_x = -p / 2, (cfg.cols - 0.5) * p
    lo_y, hi_y = -p / 2, (cfg.rows - 0.5) * p
    d = rng.uniform(1.5, 3.5, 4)
    along = rng.uniform(-0.5, 0.5, 4) * p
    # anchors along the edges, >= 30 mm from every interior anchor
    edge = [(lo_x + d[0], 9.5 * p + along[0]), (hi_x - d[1], 18.5 * p + along[1]),
            (9.5 * p + along[2], lo_y + d[2]), (18.5 * p + along[3], hi_y - d[3])]
    for k, (x, y) in enumerate(edge):
        cts.append(_scene.Contact(name=f"edge{k}", path=[[0.0, float(x), float(y)]]))
    return cts


def make_scene(contacts, m: int, snr_db: float, frames: int, seed: int) -> _scene.Scene:
    return _scene.Scene(name=f"sweep_m{m}_snr{snr_db:g}", sensor="default", frames=frames, m=m,
                        seed=seed, contacts=contacts, effects={"noise": {"snr_db": snr_db}})


def window_cells(scene: _scene.Scene) -> np.ndarray:
    """Per-window float cells (windows, rows, cols) of the scene (render_heatmaps at M = 1)."""
    per_win = scene.replace(m=1, frames=scene.frames * scene.m)
    return _chain.render_heatmaps(per_win)


# ---- fixed receive chain emulation --------------------------------------------------------
def quantise(cells: np.ndarray, m: int, hm_w: int, cells_w: int = 16):
    """Per-window float cells (at ``cells_w`` bits) -> (heat maps (frames, rows, cols) int64
    at ``hm_w`` bits, saturated flag), as the fixed receive chain: magnitude word
    floor(2 x cell x 2^MAG_FRAC) (|2A| in FFT LSBs with MAG_FRAC fractional bits), then
    ``rx_fixed.accum_fixed`` for any M (fmt_rx_array's exact divider: round half up of
    sum / 2M, the chain's one rounding)."""
    c = np.asarray(cells, dtype=np.float64) * 2.0 ** (hm_w - cells_w)
    mags = np.floor(2.0 * c * 2.0 ** _rx.MAG_FRAC).astype(np.int64)
    return _rx.accum_fixed(mags, m=m, hm_w=hm_w, hm_shift=_rx.HM_SHIFT + _rx.MAG_FRAC)


# ---- latency --------------------------------------------------------------------------------
def rx_latency_clk(cfg) -> dict:
    """Last ADC sample of a window -> last heat-map row beat, processing clocks at 3 x fs
    (the schedule tb/fmt_rx_array asserts row by row: ``rx_fixed.rx_row_beats`` with the
    shared magnitude units of the core's configuration), cross-checked with the figure the
    test writes when it has run."""
    lat0 = _fft.latency0(cfg.log2_n, cfg.adc_bits + 1, _rx.fft_out_w(cfg))
    clk = int(max(_rx.rx_row_beats(cfg, lat0, every=CLK_PER_SAMPLE, post_clk=1).values()))
    out = {"rx_clk": clk, "source": "rx_fixed.rx_row_beats (the schedule tb/fmt_rx_array asserts)"}
    f = ROOT / "build" / f"rx_latency_{cfg.name}_postclk1_cps{CLK_PER_SAMPLE}.txt"
    if f.exists():
        mt = re.search(r"clk = 3 x fs: (\d+) /", f.read_text())
        if mt:
            out["measured_clk"] = int(mt.group(1))
            agree = "agrees" if int(mt.group(1)) == clk else "DIFFERS: stale file or changed RTL"
            out["source"] += f"; measured {mt.group(1)} clk in {f.relative_to(ROOT)} ({agree})"
    return out


def latency_us(cfg, m: int, rx_clk: int, touch_clk: int) -> float:
    fs = cfg.fs_hz
    return ((m - 1) * cfg.n_fft / fs + (rx_clk + touch_clk) / CLK_PER_SAMPLE / fs) * 1e6


# ---- statistics -------------------------------------------------------------------------------
def pooled_rms(rms_list, n_list):
    """Pooled RMS of per-scene (rms, n) and the 95 % half-width from the scene spread."""
    ok = [(r, n) for r, n in zip(rms_list, n_list) if r is not None and n > 0]
    if not ok:
        return None, None, 0
    ms = np.array([r * r for r, _ in ok])
    n = np.array([k for _, k in ok], dtype=float)
    tot = ms @ n / n.sum()
    p = len(ok)
    if p > 1:
        var = np.sum((n * (ms - tot)) ** 2) / n.sum() ** 2 * p / (p - 1)
    else:
        var = float("nan")
    rms = math.sqrt(tot)
    ci = 1.96 * math.sqrt(var) / (2 * rms) if rms > 0 else 0.0
    return rms, ci, int(n.sum())


def pooled_jitter(values, frames: int):
    """RMS over contacts of the Bessel-corrected jitter, and its 95 % half-width."""
    v = np.asarray(values, dtype=float) ** 2 * frames / max(frames - 1, 1)
    if v.size == 0:
        return None, None, 0
    tot = float(v.mean())
    rms = math.sqrt(tot)
    se = float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else float("nan")
    return rms, (1.96 * se / (2 * rms) if rms > 0 else 0.0), int(v.size)


# ---- the sweep ----------------------------------------------------------------------------------
def settings_for(neigh: str, bias: bool, hm_w: int) -> TouchSettings:
    return TouchSettings(neighbourhood=neigh, bias_correction=bias,
                         threshold=int(round(BASE_THRESHOLD * 2.0 ** (hm_w - 16))),
                         on_threshold=int(round(TouchSettings.on_threshold * 2.0 ** (hm_w - 16))))


def calibrations(cfg, widths) -> dict:
    out = {}
    for w in widths:
        cw = cfg.replace(hm_width=w)
        sc = make_scene([], 1, 30.0, 1, 1).with_cfg(cw)
        # the sweep's figures (README, docs/model.md) were measured with the noiseless
        # calibration, one for every SNR of the sweep: kept explicitly (issue #12 made the
        # noisy procedure run_sim's default)
        out[w] = (cw, _run_sim.calibration(sc, mode="noiseless"))
    return out


def run_sweep(spec: SweepSpec, touch_clk: int = TOUCH_CLK_DEFAULT, progress=True) -> dict:
    cfg = _params.DEFAULT
    t_start = time.perf_counter()
    rng = np.random.default_rng(spec.seed)
    layouts = [layout(cfg, rng) for _ in range(spec.scenes)]
    cals = calibrations(cfg, spec.widths)
    rx = rx_latency_clk(cfg)
    combos = [(w, n, b) for w in spec.widths
              for n, b in (spec.interps if w == spec.widths[0] else spec.width_interps)]
    groups = [(m, s) for s in spec.snrs for m in spec.ms]
    # per (m, snr, w, neigh, bias): lists of per-scene results
    acc = {}
    sat_any = {}
    # relative cost of one scene: rendering ~ M windows, touch processing ~ settings
    cost = lambda m: 0.3 * m + len(combos)
    work = sum(cost(m) for m, _ in groups) * spec.scenes
    bar = Progress(work)
    done = 0.0
    for gi, (m, snr) in enumerate(groups):
        for si, cts in enumerate(layouts):
            seed = spec.seed * 1_000_003 + si * 1009 + m * 31 + int(snr * 10)
            sc = make_scene(cts, m, snr, spec.frames, seed)
            cells = window_cells(sc)
            for w, neigh, bias in combos:
                cw, cal = cals[w]
                key = (m, snr, w, neigh, bias)
                hm, sat = quantise(cells, m, w)
                sat_any[key] = sat_any.get(key, False) or sat
                evs = _touch.process_frames(hm, cw, settings_for(neigh, bias, w), fixed=True,
                                            flatten_cal=cal, frame_period_s=sc.frame_period_s)
                ev = _run_sim.evaluate(sc, _run_sim.detections(evs, cw),
                                       settings_for(neigh, bias, w).confirm_frames)
                acc.setdefault(key, []).append(ev)
            done += cost(m)
            if progress:
                el = time.perf_counter() - t_start
                eta = el / done * (work - done)
                bar.update(done, f"  report: group {gi + 1}/{len(groups)} (M={m}, {snr:g} dB) scene "
                                 f"{si + 1}/{spec.scenes}, {el:5.0f} s elapsed, ~{eta:4.0f} s left  ")
    if progress:
        bar.close()
    points = []
    for (m, snr, w, neigh, bias), evl in acc.items():
        pe = [e["position_error_mm"] for e in evl]
        rms, ci, n = pooled_rms([p["rms"] for p in pe], [p["n"] for p in pe])
        erms, eci, en = pooled_rms([p["rms_edge"] for p in pe], [p["n_edge"] for p in pe])
        jv = [v for e in evl for k, v in e["jitter_mm"]["per_contact"].items() if k.startswith("in")]
        jit, jci, jn = pooled_jitter(jv, spec.frames)
        points.append({
            "m": m, "snr_db": snr, "hm_w": w, "neighbourhood": neigh, "bias_correction": bias,
            "setting": f"{'Moore' if neigh == 'moore' else 'VN'} {'+bias' if bias else 'raw'}",
            "frame_rate_hz": cfg.fs_hz / (cfg.n_fft * m),
            "frame_period_us": cfg.n_fft * m / cfg.fs_hz * 1e6,
            "latency_us": latency_us(cfg, m, rx["rx_clk"], touch_clk),
            "snr_frame_db": snr + 10 * math.log10(m),
            "pos_rms_mm": rms, "pos_rms_ci95_mm": ci, "pos_n": n,
            "edge_rms_mm": erms, "edge_rms_ci95_mm": eci, "edge_n": en,
            "jitter_rms_mm": jit, "jitter_rms_ci95_mm": jci, "jitter_contacts": jn,
            "jitter_max_mm": float(max(jv)) * math.sqrt(spec.frames / (spec.frames - 1)) if jv else None,
            "missed": int(sum(e["missed"] for e in evl)),
            "false": int(sum(e["false"] for e in evl)),
            "contact_frames": len(evl) * spec.frames * (len(GRID_ROWS) * len(GRID_COLS) + 4),
            "accum_saturated": bool(sat_any[(m, snr, w, neigh, bias)]),
            "accum_mode": "fmt_rx_array (exact divider, M <= 255)",
        })
    points.sort(key=lambda p: (p["hm_w"] != spec.widths[0], p["hm_w"], p["snr_db"],
                               p["neighbourhood"], p["bias_correction"], p["m"]))
    return {
        "sensor": cfg.name, "rows": cfg.rows, "cols": cfg.cols, "n_fft": cfg.n_fft,
        "fs_hz": cfg.fs_hz, "pitch_mm": cfg.pitch_mm,
        "spec": {"ms": list(spec.ms), "snrs_db": list(spec.snrs), "widths": list(spec.widths),
                 "interps": [list(x) for x in spec.interps],
                 "width_interps": [list(x) for x in spec.width_interps],
                 "scenes": spec.scenes, "frames_per_scene": spec.frames, "seed": spec.seed,
                 "interior_contacts_per_scene": len(GRID_ROWS) * len(GRID_COLS),
                 "edge_contacts_per_scene": 4},
        "latency": {"rx_clk": rx["rx_clk"], "rx_source": rx["source"],
                    "measured_rx_clk": rx.get("measured_clk"), "touch_clk": touch_clk,
                    "touch_source": "tb/fmt_touch BUDGET (asserted bound, last row -> last event)"
                    if touch_clk == TOUCH_CLK_DEFAULT else "--touch-clk",
                    "clk_per_sample": CLK_PER_SAMPLE,
                    "window_end_to_event_us": latency_us(cfg, 1, rx["rx_clk"], touch_clk)},
        "points": points,
        "wall_s": time.perf_counter() - t_start,
    }


# ---- outputs --------------------------------------------------------------------------------------
STYLE = {("vn", False): ("tab:blue", "--", "s"), ("vn", True): ("tab:blue", "-", "o"),
         ("moore", False): ("tab:orange", "--", "s"), ("moore", True): ("tab:orange", "-", "o")}
WIDTH_STYLE = {16: ("black", "-"), 12: ("tab:purple", "--"), 10: ("tab:brown", ":"), 8: ("tab:green", "-.")}


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _sel(points, **kw):
    return [p for p in points if all(p[k] == v for k, v in kw.items())]


def _limit_lines(ax, ykey):
    if ykey == "pos_rms_mm":
        ax.axhline(WIN_ACC_MM, color="red", ls="--", lw=1, label="Windows limit 1 mm")
        ax.axhline(TARGET_ACC_MM, color="green", ls=":", lw=1.2, label="target 0.25 mm at M = 40")
    elif ykey == "jitter_rms_mm":
        ax.axhline(WIN_JIT_MM, color="red", ls="--", lw=1, label="Windows limit 0.5 mm")
        ax.axhline(TARGET_JIT_MM, color="green", ls=":", lw=1.2, label="target 0.05 mm at M = 40")
    elif ykey == "edge_rms_mm":
        ax.axhline(WIN_EDGE_MM, color="red", ls="--", lw=1, label="Windows limit 2 mm (edge)")


def _log_axes(ax):
    from matplotlib.ticker import FormatStrFormatter, FuncFormatter
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    # label the minor ticks 2, 3, 5 x 10^k only (no overlap with the decade labels)
    minor = lambda v, _: f"{v:g}" if f"{v:.0e}"[0] in "235" else ""
    ax.yaxis.set_minor_formatter(FuncFormatter(minor))
    ax.tick_params(axis="y", which="minor", labelsize=7)
    ax.grid(True, which="both", alpha=0.3)


def plot_metric(res, xkey, ykey, path, ylabel):
    """One panel per SNR, one curve per (interpolator, bias) at the main width."""
    plt = _plt()
    pts = _sel(res["points"], hm_w=res["spec"]["widths"][0])
    snrs = res["spec"]["snrs_db"]
    fig, axs = plt.subplots(1, len(snrs), figsize=(5.2 * len(snrs), 4.4), squeeze=False,
                            sharey=True)
    for ax, snr in zip(axs[0], snrs):
        for neigh, bias in res["spec"]["interps"]:
            q = sorted(_sel(pts, snr_db=snr, neighbourhood=neigh, bias_correction=bias),
                       key=lambda p: p[xkey])
            q = [p for p in q if p[ykey] is not None]
            if not q:
                continue
            col, ls, mk = STYLE[(neigh, bias)]
            ci = ykey.replace("_mm", "_ci95_mm")
            ax.errorbar([p[xkey] for p in q], [p[ykey] for p in q],
                        yerr=[p.get(ci) or 0.0 for p in q], color=col, ls=ls, marker=mk, ms=4,
                        capsize=2, label=q[0]["setting"])
            for p in q:
                if neigh == "moore" and bias:
                    ax.annotate(f"M={p['m']}", (p[xkey], p[ykey]), fontsize=7,
                                textcoords="offset points", xytext=(3, 4))
        _limit_lines(ax, ykey)
        if xkey == "frame_rate_hz":
            ax.axvline(PAPER_RATE_HZ, color="grey", ls="-.", lw=1,
                       label="paper: 4 kHz frames (star on the Windows limit: no accuracy given)")
            ax.plot([PAPER_RATE_HZ], [WIN_ACC_MM if ykey != "jitter_rms_mm" else WIN_JIT_MM],
                    marker="*", color="grey", ms=12, ls="none")
            ax.set_xlabel("frame rate (Hz)")
        else:
            ax.axvline(PAPER_LAT_US, color="grey", ls="-.", lw=1,
                       label="paper: 40 us latency (star on the Windows limit: no accuracy given)")
            ax.plot([PAPER_LAT_US], [WIN_ACC_MM if ykey != "jitter_rms_mm" else WIN_JIT_MM],
                    marker="*", color="grey", ms=12, ls="none")
            ax.set_xlabel("latency, window end -> event + (M-1) windows (us)")
        _log_axes(ax)
        ax.set_title(f"{snr:g} dB per window")
    axs[0][0].set_ylabel(ylabel)
    axs[0][-1].legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_rate_latency(res, path):
    plt = _plt()
    pts = _sel(res["points"], hm_w=res["spec"]["widths"][0], snr_db=res["spec"]["snrs_db"][0],
               neighbourhood=res["spec"]["interps"][0][0],
               bias_correction=res["spec"]["interps"][0][1])
    pts = sorted(pts, key=lambda p: p["m"])
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.plot([p["latency_us"] for p in pts], [p["frame_rate_hz"] for p in pts], "o-", color="black",
            label="this design (M windows per frame)")
    for p in pts:
        ax.annotate(f"M={p['m']}", (p["latency_us"], p["frame_rate_hz"]), fontsize=8,
                    textcoords="offset points", xytext=(4, 4))
    ax.plot([PAPER_LAT_US], [PAPER_RATE_HZ], "*", color="red", ms=14, label="paper: 4 kHz frames, 40 us latency\n(40 us integration, then idle)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("latency (us)")
    ax.set_ylabel("frame rate (Hz)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_widths(res, path):
    plt = _plt()
    widths = res["spec"]["widths"]
    snrs = res["spec"]["snrs_db"]
    fig, axs = plt.subplots(2, len(snrs), figsize=(5.2 * len(snrs), 7.5), squeeze=False)
    for j, snr in enumerate(snrs):
        for i, key in enumerate(("pos_rms_mm", "jitter_rms_mm")):
            ax = axs[i][j]
            for w in widths:
                q = sorted(_sel(res["points"], snr_db=snr, hm_w=w, neighbourhood="moore",
                                bias_correction=True), key=lambda p: p["frame_rate_hz"])
                if not q:
                    continue
                col, ls = WIDTH_STYLE.get(w, ("grey", "-"))
                ax.errorbar([p["frame_rate_hz"] for p in q], [p[key] for p in q],
                            yerr=[p[key.replace("_mm", "_ci95_mm")] or 0.0 for p in q],
                            color=col, ls=ls, marker="o", ms=4, capsize=2, label=f"HM_W = {w}")
            _limit_lines(ax, key)
            _log_axes(ax)
            ax.set_title(f"Moore +bias, {snr:g} dB per window")
            ax.set_xlabel("frame rate (Hz)")
            ax.set_ylabel("position RMS (mm)" if i == 0 else "jitter RMS (mm)")
    axs[0][-1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


PLOTS = (("error_vs_rate.png", "frame_rate_hz", "pos_rms_mm", "position RMS error, interior (mm)"),
         ("jitter_vs_rate.png", "frame_rate_hz", "jitter_rms_mm", "stationary jitter RMS (mm)"),
         ("error_vs_latency.png", "latency_us", "pos_rms_mm", "position RMS error, interior (mm)"),
         ("jitter_vs_latency.png", "latency_us", "jitter_rms_mm", "stationary jitter RMS (mm)"),
         ("edge_vs_rate.png", "frame_rate_hz", "edge_rms_mm", "position RMS error, 1.5-3.5 mm from an edge (mm)"))


def write_plots(res, out: Path) -> list:
    names = []
    for name, x, y, lab in PLOTS:
        plot_metric(res, x, y, out / name, lab)
        names.append(name)
    plot_rate_latency(res, out / "rate_vs_latency.png")
    names.append("rate_vs_latency.png")
    if len(res["spec"]["widths"]) > 1:
        plot_widths(res, out / "widths.png")
        names.append("widths.png")
    return names


def _f(v, ci=None, nd=3):
    if v is None:
        return "n/a"
    return f"{v:.{nd}f}" + (f" ± {ci:.{nd}f}" if ci is not None and not math.isnan(ci) else "")


def render_md(res, plots, cmd: str) -> str:
    sp = res["spec"]
    lat = res["latency"]
    w0 = sp["widths"][0]
    settings = [tuple(x) for x in sp["interps"]]
    label = lambda n, b: f"{'Moore' if n == 'moore' else 'VN'} {'+bias' if b else 'raw'}"
    L = [f"# Speed against error: fixed-point sweep ({res['sensor']} {res['rows']} x {res['cols']} sensor)", "",
         f"Command: `{cmd}` ({res['wall_s']:.0f} s wall). Produced by `sim/fmt/report.py`; every point is "
         "also in `report.json`.", "",
         "## Method", "",
         f"* {sp['scenes']} scenes x {sp['frames_per_scene']} frames per point; each scene holds "
         f"{sp['interior_contacts_per_scene']} interior 8 mm fingers (random sub-cell positions, > 27 mm "
         f"from the edges) and {sp['edge_contacts_per_scene']} fingers centred 1.5-3.5 mm from an edge: "
         f"{sp['scenes'] * sp['interior_contacts_per_scene']} interior and "
         f"{sp['scenes'] * sp['edge_contacts_per_scene']} edge positions, the same at every point.",
         "* Heat maps: `chain.render_heatmaps` per window (default physics: SNR per window at a "
         "finger centred on a cell), quantised as the fixed receive chain (magnitude word = floor(2 x "
         "cell) with 2 fractional bits, `rx_fixed.accum_fixed` = the accumulator of `fmt_rx_array`); touch processing `touch.process_frames(fixed=True)` "
         "= bit-exact twin of `rtl/fmt_touch.v` (`tb/fmt_touch` checks the RTL against it event for event on "
         "random and scene heat maps of the MEDIUM sensor: that is the RTL confirmation of this model; the "
         "sweep's own points are not re-run through the RTL); scoring "
         "`run_sim.evaluate`.",
         "* Every M of the sweep (16 and 40 included) is an RTL mode: `fmt_rx_array` takes any "
         "M = 1 .. 255 (WINDOWS_M) and divides exactly (round half up of sum / 2M by a reciprocal "
         "multiply, bit-exact with `rx_fixed.accum_fixed`).",
         "* Position error: RMS over (contact, frame) of the distance to the true centre. Jitter: RMS "
         "distance about the contact's own mean over the scene's frames (x F/(F-1)), RMS over "
         "interior contacts. ± = 95 % confidence half-width from the spread between scenes.",
         f"* Latency = (M - 1) windows + window end -> event: receive chain {lat['rx_clk']} clk "
         f"({lat['rx_source']}) + touch processing {lat['touch_clk']} clk ({lat['touch_source']}), "
         f"at {lat['clk_per_sample']} x fs: {lat['window_end_to_event_us']:.2f} us at M = 1.",
         "* The paper's operating point: 4 kHz frames, each integrated over 40 us and reported 40 us "
         "later, idle for the rest of the 250 us. Here windows follow back to back: 40 us of integration "
         "is M = 6.5 (M = 8: 49 us, 20.3 kHz frames), and 4 kHz frames are M = 40 (246 us of integration, "
         "+8 dB: the better use of the idle time the paper suggests).",
         "* Not swept: the fit's widths (8 fractional bits, 9-bit offset quotient) are constants of "
         "`fmt.interp` and the RTL, not parameters.", "",
         "## Frame rate and latency", "",
         "| M | frame rate (Hz) | frame period (us) | latency (us) | SNR per frame (dB, at the 30 dB point) |",
         "|---|---|---|---|---|"]
    for m in sp["ms"]:
        p = _sel(res["points"], m=m)[0]
        L.append(f"| {m} | {p['frame_rate_hz']:.0f} | {p['frame_period_us']:.2f} | {p['latency_us']:.2f} | "
                 f"{30 + 10 * math.log10(m):.1f} |")
    L.append("")
    for snr in sp["snrs_db"]:
        L += [f"## {snr:g} dB per window (HM_W = {w0})", ""]
        hdr = "| M | " + " | ".join(label(n, b) for n, b in settings) + " |"
        sep = "|---|" + "---|" * len(settings)
        for title, key in (("Position RMS error, interior (mm)", "pos_rms_mm"),
                           ("Stationary jitter RMS (mm)", "jitter_rms_mm"),
                           ("Position RMS error, 1.5-3.5 mm from an edge (mm)", "edge_rms_mm")):
            L += [f"{title}:", "", hdr, sep]
            for m in sp["ms"]:
                row = []
                for n, b in settings:
                    q = _sel(res["points"], m=m, snr_db=snr, hm_w=w0, neighbourhood=n, bias_correction=b)
                    row.append(_f(q[0][key], q[0][key.replace("_mm", "_ci95_mm")]) if q else "")
                L.append(f"| {m} | " + " | ".join(row) + " |")
            L.append("")
        L += ["Missed / false detections (contact-frames) per setting:", "", hdr, sep]
        for m in sp["ms"]:
            row = []
            for n, b in settings:
                q = _sel(res["points"], m=m, snr_db=snr, hm_w=w0, neighbourhood=n, bias_correction=b)
                row.append(f"{q[0]['missed']} / {q[0]['false']} of {q[0]['contact_frames']}" if q else "")
            L.append(f"| {m} | " + " | ".join(row) + " |")
        L.append("")
    if len(sp["widths"]) > 1:
        L += ["## Heat-map width HM_W (Moore +bias)", "",
              "| SNR (dB) | M | " + " | ".join(f"HM_W {w}: position / jitter (mm)" for w in sp["widths"]) + " |",
              "|---|---|" + "---|" * len(sp["widths"])]
        for snr in sp["snrs_db"]:
            for m in sp["ms"]:
                row = []
                for w in sp["widths"]:
                    q = _sel(res["points"], m=m, snr_db=snr, hm_w=w, neighbourhood="moore", bias_correction=True)
                    row.append(f"{_f(q[0]['pos_rms_mm'])} / {_f(q[0]['jitter_rms_mm'])}"
                               + (" (sat)" if q[0]["accum_saturated"] else "") if q else "")
                L.append(f"| {snr:g} | {m} | " + " | ".join(row) + " |")
        L.append("")
    # verdicts
    L += ["## Against the limits", ""]
    for snr in sp["snrs_db"]:
        for n, b in settings:
            q = sorted(_sel(res["points"], snr_db=snr, hm_w=w0, neighbourhood=n, bias_correction=b),
                       key=lambda p: p["m"])
            ok_win = [p["m"] for p in q if p["pos_rms_mm"] is not None and p["pos_rms_mm"] <= WIN_ACC_MM
                      and p["jitter_rms_mm"] is not None and p["jitter_rms_mm"] <= WIN_JIT_MM]
            ok_tgt = [p["m"] for p in q if p["pos_rms_mm"] is not None and p["pos_rms_mm"] <= TARGET_ACC_MM
                      and p["jitter_rms_mm"] is not None and p["jitter_rms_mm"] <= TARGET_JIT_MM]
            L.append(f"* {snr:g} dB, {label(n, b)}: Windows limits (1 mm, 0.5 mm) met at M = "
                     f"{', '.join(map(str, ok_win)) or 'none'}; project targets (0.25 mm, 0.05 mm) met at M = "
                     f"{', '.join(map(str, ok_tgt)) or 'none'}.")
    L.append("")
    L += ["## Plots", ""]
    for name in plots:
        L += [f"![{name}]({name})", ""]
    return "\n".join(L) + "\n"


def write_outputs(res, out: Path, cmd: str, plots: bool = True) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    names = write_plots(res, out) if plots else []
    res = dict(res, plots=names)
    (out / "report.json").write_text(json.dumps(res, indent=1) + "\n")
    (out / "REPORT.md").write_text(render_md(res, names, cmd))
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Speed against error sweep over the fixed-point model "
                                             "(make report).")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--full", action="store_true", help="the whole sweep (default)")
    g.add_argument("--smoke", action="store_true", help="two points, a few seconds (make test)")
    ap.add_argument("--out", default=str(ROOT / "build" / "report"))
    ap.add_argument("--scenes", type=int, default=None, help="override the scene count")
    ap.add_argument("--frames", type=int, default=None, help="override the frames per scene")
    ap.add_argument("--touch-clk", type=int, default=TOUCH_CLK_DEFAULT,
                    help="touch-processing latency, last row beat -> last event (processing clocks)")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--from-json", default=None,
                    help="rewrite REPORT.md and the plots from a report.json (no simulation)")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    spec = SMOKE if a.smoke else FULL
    kw = {}
    if a.scenes:
        kw["scenes"] = a.scenes
    if a.frames:
        kw["frames"] = a.frames
    if kw:
        spec = SweepSpec(**{**spec.__dict__, **kw})
    if a.from_json:
        res = json.loads(Path(a.from_json).read_text())
        res.pop("plots", None)
        cmd = res.get("command", "python -m fmt.report --full")
    else:
        res = run_sweep(spec, a.touch_clk, progress=not a.quiet)
        cmd = "python -m fmt.report " + " ".join(argv if argv is not None else sys.argv[1:])
        res["command"] = cmd.strip()
    res = write_outputs(res, Path(a.out), cmd.strip(), plots=not a.no_plot)
    if not a.quiet:
        print(f"{len(res['points'])} points in {res['wall_s']:.0f} s: {Path(a.out) / 'REPORT.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
