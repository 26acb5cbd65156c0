"""``make sim``: a scene through the floating-point model, with an accuracy report.

    python -m fmt.run_sim --scene sim/scenes/default.json [--out build/sim] [--frames F]
                          [--render] [--cal noisy|noiseless] [--cal-frames K] [--no-plot] [--quiet]

1. Calibration of the field flattening (``calibration``, ``fmt.flatten.calibrate``): the
   real procedure on CAL_FRAMES (16) untouched frames and 16 frames with a uniform
   calibration sheet (coupling 0.25 on every cell), each through the ADC and the float
   receiver with the scene's noise and additive effects (not the charger noise: no finger
   touches) and averaged; ``--cal noiseless`` renders one noiseless frame of each instead
   (the old, always perfect calibration).
2. ADC streams -> float receiver -> heat maps (``fmt.chain.heatmaps_float``), or the
   render without signal synthesis with ``--render``.
3. Post-processing: ``fmt.touch.process_frames(heatmaps, cfg, settings, fixed=False)``
   (with the calibration and the frame period when it accepts them).
4. ``<out>/<scene>/report.json`` and ``<out>/<scene>/heatmap.png``.

Report fields: ``frames``; ``touches`` (detected contacts per frame: min/mean/max, and
the true count's mean); ``position_error_mm`` against the scene's truth at each frame's
centre time (detections matched to true contacts, nearest first, within
``MATCH_MM``): ``rms`` and ``max`` over contacts more than 3.5 mm from every edge,
``rms_edge`` / ``max_edge`` over contacts centred 1.5 - 3.5 mm from an edge, the counts;
frames whose windows hold a contact's onset or lift (partial coupling), and the first
``confirm_frames - 1`` whole frames of a touch (the tracker's confirmation, whose cost
the tap latency shows), are left out of the errors, and a detection of such a contact
there counts neither as false nor missed;
``missed`` (true contacts touching the whole frame without a detection) / ``false``
(detections matching no contact); ``jitter_mm`` (RMS distance about the mean position
of each stationary, always-touching contact; the worst one and per contact);
``jitter_mm.largest_deviation`` (the largest distance from that mean); ``tracking``:
``id_swaps`` / ``ids_lost`` (a contact touching without a break changes its ID to one
that another contact had / to a new one; ``id_changes`` lists them with their frames),
``ghosts`` (detections matching no contact, with their IDs and frames),
``contacts_minus_truth`` (frames by detected minus true contacts);
``tap_latency_us`` (tap onset sample -> end of the first frame that reports the contact,
i.e. the model's window-alignment latency, without the RTL's processing time);
``model_frames_per_s`` (the signal chain alone, wall clock; ``model_frames_per_cpu_s``
per CPU second, which does not depend on the machine's load) and ``total_frames_per_s``;
``clipped_samples``; ``noise_sigma_lsb``.
"""
from __future__ import annotations

import argparse
import inspect
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from . import chain as _chain
from . import scene as _scene
from .progress import Progress
from . import settings as _settings
from .settings import TouchSettings

MATCH_MM = 10.0          # a detection farther than this from every true contact is false
EDGE_LO_MM, EDGE_HI_MM = 1.5, 3.5
ROOT = Path(__file__).resolve().parents[2]


CAL_FRAMES = 16          # frames averaged per calibration capture (untouched, sheet)
CAL_SEED = 7919          # the captures' noise seeds: scene.seed + CAL_SEED (+ 1 for the sheet)
CAL_MODES = ("noisy", "noiseless")


def calibration_scenes(scene: _scene.Scene, sheet: float = 0.25, frames: int = CAL_FRAMES):
    """(untouched, sheet) capture scenes of the calibration: the scene's sensor and effects
    (noise, interferers, display noise, DC, drift, ...; charger noise left out, as no
    finger touches), no contacts / a uniform sheet of coupling ``sheet`` covering every
    cell, ``frames`` frames of M = 1 from t = 0, noise seeds of their own."""
    cfg = scene.cfg
    eff = {k: v for k, v in scene.effects.items() if k != "charger"}
    base = scene.replace(contacts=[], effects=eff, frames=frames, m=1, seed=scene.seed + CAL_SEED)
    # a disk far larger than the sensor covers every cell: coupling = strength exactly
    big = 4.0 * math.hypot(cfg.width_mm, cfg.height_mm)
    sheet_sc = scene.replace(contacts=[{"name": "sheet", "diameter_mm": big, "strength": sheet,
                                        "path": [[0.0, cfg.width_mm / 2, cfg.height_mm / 2]]}],
                             effects=eff, frames=frames, m=1, seed=scene.seed + CAL_SEED + 1)
    return base, sheet_sc


def calibration(scene: _scene.Scene, sheet: float = 0.25, mode: str = "noisy", frames: int = CAL_FRAMES):
    """(offset, gain) of the field flattening by ``fmt.flatten.calibrate``, from heat maps
    of the sensor untouched and covered by a uniform sheet of coupling ``sheet``.

    ``mode`` "noisy" (the real procedure, the default): ``frames`` frames of each capture
    (``calibration_scenes``) through the ADC streams and the float receiver with the
    scene's noise and additive effects, averaged.  "noiseless": one noiseless rendered
    frame of each (always perfect; the behaviour before issue #12, kept for comparison)."""
    from . import flatten as _flatten
    cfg = scene.cfg
    if mode not in CAL_MODES:
        raise ValueError(f"calibration mode {mode!r}: one of {', '.join(CAL_MODES)}")
    if mode == "noiseless":
        base, sheet_sc = calibration_scenes(scene, sheet, 1)
        u = _chain.render_heatmaps(base, noise=False)
        c = _chain.render_heatmaps(sheet_sc, noise=False)
    else:
        base, sheet_sc = calibration_scenes(scene, sheet, frames)
        u = _chain.heatmaps_float(base).heatmaps
        c = _chain.heatmaps_float(sheet_sc).heatmaps
    return _flatten.calibrate(u, c, None, cfg)


def default_processor(heatmaps, scene: _scene.Scene, settings: TouchSettings, flatten_cal):
    """fmt.touch.process_frames (float), given the calibration and frame period when its
    signature takes them."""
    from . import touch as _touch
    fn = _touch.process_frames
    kw = {}
    sig = inspect.signature(fn).parameters
    if "flatten_cal" in sig:
        kw["flatten_cal"] = flatten_cal
    if "frame_period_s" in sig:
        kw["frame_period_s"] = scene.frame_period_s
    return fn(heatmaps, scene.cfg, settings, fixed=False, **kw)


def _ev(e, name, default=None):
    if isinstance(e, dict):
        return e.get(name, default)
    return getattr(e, name, default)


def detections(frame_events, cfg) -> list:
    """Per frame: list of (id, x_mm, y_mm) of the live contacts (events 'new'/'move')."""
    q = float(1 << cfg.frac_bits)
    out = []
    for evs in frame_events:
        d = []
        for e in evs:
            if _ev(e, "type") in ("new", "move"):
                d.append((int(_ev(e, "id")), _ev(e, "x_q") / q * cfg.pitch_mm,
                          _ev(e, "y_q") / q * cfg.pitch_mm))
        out.append(d)
    return out


def _match(truth, det):
    """Greedy nearest matching -> list of (truth index, det index, distance mm)."""
    pairs = []
    for i, t in enumerate(truth):
        for j, d in enumerate(det):
            pairs.append((math.hypot(t["x_mm"] - d[1], t["y_mm"] - d[2]), i, j))
    pairs.sort()
    ti, dj, out = set(), set(), []
    for dist, i, j in pairs:
        if dist > MATCH_MM or i in ti or j in dj:
            continue
        ti.add(i)
        dj.add(j)
        out.append((i, j, dist))
    return out


def _rms(v):
    return float(math.sqrt(np.mean(np.square(v)))) if len(v) else None


def confirming(act_frac, confirm_frames: int) -> np.ndarray:
    """Frames of a contact that count as its onset: partial coupling (0 < fraction < 1),
    and the first ``confirm_frames - 1`` whole frames after each onset, in which the
    tracker's confirmation may still hold the new contact back (its stated latency)."""
    a = np.asarray(act_frac, dtype=float)
    out = (a > 0) & (a < 1)
    run = 0
    for f in range(len(a)):
        run = run + 1 if a[f] >= 1 else 0
        if 0 < run <= confirm_frames - 1:
            out[f] = True
    return out


def evaluate(scene: _scene.Scene, det: list, confirm_frames: int = 1) -> dict:
    """Accuracy, jitter, misses and tap latency of per-frame detections against the truth.
    ``confirm_frames``: the tracker's confirmation (TouchSettings.confirm_frames): the
    first confirm_frames - 1 whole frames of each touch count like its onset frame."""
    cfg = scene.cfg
    fs, spf = cfg.fs_hz, scene.samples_per_frame
    frames = len(det)
    edges = np.arange(frames + 1, dtype=np.int64) * spf
    partial = [confirming(c.active_fraction(edges, fs), confirm_frames) for c in scene.contacts]
    act = [np.asarray(c.active_fraction(edges, fs)) for c in scene.contacts]
    err_in, err_edge, missed, false = [], [], 0, 0
    pos = {i: [] for i in range(len(scene.contacts))}
    truth_count = []
    ids = {i: [] for i in range(len(scene.contacts))}   # (frame, ID) matched to contact i
    ghosts, count_err = [], {}
    for f in range(frames):
        tc = (f + 0.5) * spf / fs
        truth = scene.truth(tc)
        truth_count.append(len(truth))
        # contacts touching for part of this frame's windows may or may not be reported
        have = {t["index"] for t in truth}
        for i, c in enumerate(scene.contacts):
            if partial[i][f] and i not in have:
                x, y = c.position(tc)
                truth.append({"index": i, "name": c.name, "x_mm": float(x), "y_mm": float(y),
                              "edge_mm": float(_scene.edge_distance_mm(cfg, x, y))})
        m = _match(truth, det[f])
        false += len(det[f]) - len(m)
        matched = {truth[i]["index"] for i, _, _ in m}
        missed += sum(1 for t in truth if not partial[t["index"]][f] and t["index"] not in matched)
        mj = {j for _, j, _ in m}
        ghosts += [(f, det[f][j][0]) for j in range(len(det[f])) if j not in mj]
        # contacts per frame against the truth (contacts in onset / lift frames left out)
        n_part = sum(1 for i, _, _ in m if partial[truth[i]["index"]][f])
        k = (len(det[f]) - n_part) - sum(1 for t in truth if not partial[t["index"]][f])
        count_err[k] = count_err.get(k, 0) + 1
        for i, j, dist in m:
            t = truth[i]
            if partial[t["index"]][f]:
                continue
            ids[t["index"]].append((f, det[f][j][0]))
            pos[t["index"]].append((det[f][j][1], det[f][j][2]))
            if t["edge_mm"] > EDGE_HI_MM:
                err_in.append(dist)
            elif t["edge_mm"] >= EDGE_LO_MM:
                err_edge.append(dist)
    jit, dev = {}, {}
    for i, c in enumerate(scene.contacts):
        if c.stationary and c.active is None and len(pos[i]) > 1:
            p = np.asarray(pos[i])
            r = np.sqrt(np.sum((p - p.mean(0)) ** 2, axis=1))
            jit[c.name or str(i)] = float(math.sqrt(np.mean(r ** 2)))
            dev[c.name or str(i)] = float(r.max())
    # ID changes of a contact that touched without a break in between: a swap when the
    # new ID was matched to another contact before, else a lost ID (a new one)
    changes = []
    for i, c in enumerate(scene.contacts):
        seq = ids[i]
        for (f0, a), (f1, b) in zip(seq, seq[1:]):
            if a == b or not (act[i][f0:f1 + 1] > 0).all():
                continue
            other = any(fo < f1 and idv == b for k, s2 in ids.items() if k != i for fo, idv in s2)
            changes.append({"frame": f1, "contact": c.name or str(i), "from": a, "to": b,
                            "kind": "swap" if other else "new_id"})
    # tap latency: onset sample -> end of the first frame with a matched detection
    lat = []
    for i, c in enumerate(scene.contacts):
        if c.active is None:
            continue
        for on, off in c.intervals_samples(fs):
            f0 = int(on // spf)
            for f in range(max(0, f0), min(frames, int(min(off, frames * spf) // spf) + 1)):
                x, y = c.position((f + 0.5) * spf / fs)
                hit = any(math.hypot(x - d[1], y - d[2]) <= MATCH_MM for d in det[f])
                if hit:
                    lat.append(((f + 1) * spf - on) / fs * 1e6)
                    break
    return {
        "position_error_mm": {
            "rms": _rms(err_in), "max": float(max(err_in)) if err_in else None, "n": len(err_in),
            "rms_edge": _rms(err_edge), "max_edge": float(max(err_edge)) if err_edge else None,
            "n_edge": len(err_edge)},
        "missed": missed, "false": false,
        "truth_touches_mean": float(np.mean(truth_count)) if truth_count else 0.0,
        "jitter_mm": {"max": max(jit.values()) if jit else None, "per_contact": jit,
                      "largest_deviation": max(dev.values()) if dev else None,
                      "largest_deviation_per_contact": dev},
        "tracking": {
            "id_swaps": sum(ch["kind"] == "swap" for ch in changes),
            "ids_lost": sum(ch["kind"] == "new_id" for ch in changes),
            "id_changes": changes[:50],
            "ghosts": len(ghosts), "ghost_ids": sorted({g for _, g in ghosts}),
            "ghost_frames": sorted({f for f, _ in ghosts})[:50],
            "contacts_minus_truth": {str(k): v for k, v in sorted(count_err.items())}},
        "tap_latency_us": {"n": len(lat), "mean": float(np.mean(lat)) if lat else None,
                           "max": float(np.max(lat)) if lat else None,
                           "values": [round(v, 3) for v in lat]},
    }


def tracks(frame_events, cfg) -> dict:
    """{id: [(frame, x_cells, y_cells), ...]} from the events."""
    q = float(1 << cfg.frac_bits)
    tr = {}
    for f, evs in enumerate(frame_events):
        for e in evs:
            if _ev(e, "type") in ("new", "move"):
                tr.setdefault(int(_ev(e, "id")), []).append((f, _ev(e, "x_q") / q, _ev(e, "y_q") / q))
    return tr


def run(scene: _scene.Scene, out_dir=None, settings: TouchSettings | None = None,
        processor=None, render: bool = False, plot: bool = True, quiet: bool = False,
        frames: int | None = None, cal: str = "noisy", cal_frames: int = CAL_FRAMES) -> dict:
    """Run a scene; returns the report (and writes it, with the events, under
    ``out_dir/<name>/``).  ``settings``: default the scene's (``settings`` key);
    ``cal``, ``cal_frames``: the calibration's mode and frames (``calibration``)."""
    settings = settings or scene.touch_settings()
    processor = processor or default_processor
    cfg = scene.cfg
    if frames is not None:
        scene = scene.replace(frames=frames)
    t0, c0 = time.perf_counter(), time.process_time()

    bar = Progress(scene.frames)

    def progress(done, total):
        if not quiet and total >= 1000:
            bar.total = total
            bar.update(done, f"  {scene.name}: {done}/{total} frames")

    if render:
        hm = _chain.render_heatmaps(scene)
        res = _chain.ChainResult(hm, 0, scene.n_samples, 0.0)
    else:
        res = _chain.heatmaps_float(scene, progress=progress)
        if not quiet and scene.frames >= 1000:
            bar.close()
    t1, c1 = time.perf_counter(), time.process_time()
    cal_mode = cal
    cal = calibration(scene, mode=cal_mode, frames=cal_frames)
    evs = processor(res.heatmaps, scene, settings, cal)
    t2 = time.perf_counter()
    det = detections(evs, cfg)
    n_det = [len(d) for d in det]
    rep = {
        "scene": scene.name, "sensor": cfg.name, "frames": scene.frames, "m": scene.m,
        "frame_period_us": scene.frame_period_s * 1e6,
        "signal_path": "render" if render else "adc",
        "touches": {"min": int(min(n_det)), "mean": float(np.mean(n_det)), "max": int(max(n_det))},
        "model_frames_per_s": scene.frames / max(t1 - t0, 1e-9),
        "model_frames_per_cpu_s": scene.frames / max(c1 - c0, 1e-9),
        "total_frames_per_s": scene.frames / max(t2 - t0, 1e-9),
        "clipped_samples": int(res.clipped),
        "noise_sigma_lsb": float(res.noise_sigma),
        "events": int(sum(len(e) for e in evs)),
        "calibration": {"mode": cal_mode, "frames": cal_frames if cal_mode == "noisy" else 1},
    }
    rep.update(evaluate(scene, det, settings.confirm_frames))
    rep["touches"]["truth_mean"] = rep.pop("truth_touches_mean")
    if out_dir is not None:
        d = Path(out_dir) / scene.name
        d.mkdir(parents=True, exist_ok=True)
        if plot:
            from . import plots as _plots
            from . import flatten as _flatten
            flat = _flatten.flatten_float(res.heatmaps, cal[0], cal[1], cfg)
            png = d / "heatmap.png"
            _plots.heatmap_with_tracks(flat, scene, tracks(evs, cfg), png)
            rep["png"] = str(png)
        write_events(d / "events.jsonl", evs)
        rep["events_file"] = str(d / "events.jsonl")
        rep["events_in_file"] = int(sum(len(e) for e in evs))
        (d / "report.json").write_text(json.dumps(rep, indent=1) + "\n")
        rep["report"] = str(d / "report.json")
    return rep


EVENT_FIELDS = ("frame", "id", "type", "x_q", "y_q", "strength", "axis_major_q",
                "axis_minor_q", "angle", "flags")


def write_events(path, frame_events) -> None:
    """Every event, one JSON object per line, in frame order (``index`` = the frame's
    position in the run; ``frame`` = its 16-bit number).  Written to a temporary name and
    renamed: a failed run never leaves a half file."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with tmp.open("w") as fh:
        for k, evs in enumerate(frame_events):
            for e in evs:
                rec = {"index": k}
                rec.update({f: (_ev(e, f) if f == "type" else int(_ev(e, f, 0))) for f in EVENT_FIELDS})
                fh.write(json.dumps(rec) + "\n")
    tmp.replace(path)


def _summary(rep: dict) -> str:
    pe = rep["position_error_mm"]
    f = lambda v: "n/a" if v is None else f"{v:.3f}"
    return (f"{rep['scene']}: {rep['frames']} frames ({rep['signal_path']}), "
            f"touches/frame {rep['touches']['mean']:.2f} (truth {rep['touches']['truth_mean']:.2f}), "
            f"position error rms {f(pe['rms'])} mm max {f(pe['max'])} mm, "
            f"edge rms {f(pe['rms_edge'])} mm, jitter {f(rep['jitter_mm']['max'])} mm, "
            f"missed {rep['missed']} false {rep['false']}, tap latency mean "
            f"{f(rep['tap_latency_us']['mean'])} us, model {rep['model_frames_per_s']:.0f} frames/s, "
            f"clipped {rep['clipped_samples']}")


def main(argv=None) -> int:
    from .inputs import InputError, OneLineParser

    def positive(text):
        v = int(text)
        if v < 1:
            raise ValueError(text)
        return v

    ap = OneLineParser(description="Run a scene through the FMT model (make sim).")
    ap.add_argument("--scene", default=str(ROOT / "sim" / "scenes" / "default.json"))
    ap.add_argument("--out", default=str(ROOT / "build" / "sim"))
    ap.add_argument("--frames", type=positive, default=None, help="override the scene's length")
    ap.add_argument("--render", action="store_true",
                    help="heat maps by render_heatmaps (no ADC synthesis)")
    ap.add_argument("--settings", default=None,
                    help="touch settings file (JSON, TouchSettings fields); default the scene's")
    ap.add_argument("--cal", default="noisy", choices=CAL_MODES,
                    help="calibration: noisy (the real procedure on noisy untouched / sheet frames, "
                         "default) or noiseless (one rendered frame each, always perfect)")
    ap.add_argument("--cal-frames", type=positive, default=CAL_FRAMES,
                    help=f"frames averaged per calibration capture (default {CAL_FRAMES})")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    try:
        sc = _scene.load(a.scene)
        st = _settings.load(a.settings) if a.settings else sc.touch_settings()
    except InputError as e:
        print(f"run_sim: {e}", file=sys.stderr)
        return 2
    rep = run(sc, a.out, settings=st, render=a.render, plot=not a.no_plot, quiet=a.quiet,
              frames=a.frames, cal=a.cal, cal_frames=a.cal_frames)
    print(_summary(rep))
    print(f"report: {rep['report']}" + (f", plot: {rep['png']}" if "png" in rep else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
