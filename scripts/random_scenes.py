#!/usr/bin/env python3
"""`make random-scenes`: random scenes through the fixed-point model, checked by invariants.

Each scene is drawn from its own seed (``--seed`` and its index): 0-5 contacts of random
size (3-26 mm: fingers to palms), shape (disk / gaussian, round / elliptical), strength,
path (stationary, drags and fast flicks, partly or wholly off the sensor) and activity
(always, random intervals, tap trains); random channel effects (noise by SNR or RMS,
ENOB, DC offset, up to two interferers, electrode attenuation, channel delay, PN on/off
and chip length); random M and touch settings (threshold, neighbourhood, contact limit,
bias correction, gates, hold-off, blobs).  Every scene runs the bit-exact twin of the
RTL path (``bench/core/run_sim_rtl.model_reference``: DDS -> fixed-point channel ->
receive array -> touch chain, calibrated as ``make sim`` calibrates).

Invariants checked on every frame (a violation prints the scene's seed and index and
the script exits 1; the scene and its settings are written to ``--fail-dir``, whose
earlier ``random_*.json`` files are removed at the start):
  * nothing raises;
  * heat-map cells within 0 .. 2^HM_W - 1;
  * events carry their frame's number, in order: the tracker's events, then blob events;
  * a contact ID is born by 'new' (never while alive), then only 'move' until 'lift'
    (which ends it); one event per ID per frame; at most the contact limit seen (new or
    move) per frame, at most the tracker's slots alive;
  * positions inside the sensor (0 .. (cols-1) x 256, 0 .. (rows-1) x 256, Q8.8 cells);
    new / move strengths at or above the threshold; flags, axes and angle in their
    fields' ranges;
  * blob events only with blobs on, at most MAX_BLOBS per frame, id 0xFF, centroids inside.

With ``--rtl K`` the first K scenes that fit the simulation bench (its coupling-update
memory; the others are counted as skipped) also run through the RTL of the small builds
(the C++ Verilator harness of ``make sim``, one build per sensor, clk = 3 x fs) with
their random settings written to the registers: heat maps and events must equal the
model's bit for bit, no frame dropped or missing (``run_sim_rtl.verdict``).

With ``--reset`` each of those RTL runs first keeps the core busy for a random number of
cycles (up to three frames: random ADC words on every column, random register settings
with a low threshold, the event consumer stalling at random), so the reset before the
scene lands at a random point of a frame with the pipeline, the FIFOs and the tracker
full of state; the scene after it must still be bit-exact (issue #15 item 3).

    python scripts/random_scenes.py [--count N] [--seed S] [--sensor small|medium|mixed]
                                    [--rtl K] [--reset] [--fail-dir DIR] [--quiet]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "sim")]

from bench.core import run_sim_rtl as rsr          # noqa: E402
from fmt import params as _params                  # noqa: E402
from fmt import run_sim as _run_sim                # noqa: E402
from fmt import scene as _scene                    # noqa: E402
from fmt.settings import TouchSettings             # noqa: E402

MAX_BLOBS = 8


def _f(rng, lo, hi):
    return float(rng.uniform(lo, hi))


def random_contact(rng, cfg, T: float, i: int) -> dict:
    p = cfg.pitch_mm
    w, h = (cfg.cols - 1) * p, (cfg.rows - 1) * p
    m = 6.0                                   # up to 6 mm beyond the outer electrodes
    pt = lambda: [_f(rng, -m, w + m), _f(rng, -m, h + m)]
    kind = rng.choice(["still", "drag", "flick", "multi"])
    if kind == "still":
        path = [[0.0] + pt()]
    elif kind == "drag":
        path = [[_f(rng, 0, T / 2)] + pt(), [_f(rng, T / 2, T)] + pt()]
    elif kind == "flick":                     # a fast move inside one or two frames
        t0 = _f(rng, 0, T)
        path = [[t0] + pt(), [t0 + _f(rng, 1e-6, 4 * T / 10)] + pt()]
    else:
        ts = np.sort(rng.uniform(0, T, 4))
        path = [[float(t)] + pt() for t in ts]
    c = {"name": f"c{i}", "path": path,
         "diameter_mm": _f(rng, 3, 26) if rng.random() < 0.3 else _f(rng, 5, 12),
         "strength": _f(rng, 0.2, 1.5), "profile": str(rng.choice(["disk", "gaussian"]))}
    if rng.random() < 0.25:
        c["minor_diameter_mm"] = _f(rng, 3, c["diameter_mm"])
        c["angle_deg"] = _f(rng, -90, 90)
    a = rng.random()
    if a < 0.35:
        ivs, t = [], _f(rng, -T / 4, T / 2)
        for _ in range(int(rng.integers(1, 4))):
            on = t
            off = on + _f(rng, T / 50, T / 2)
            ivs.append([max(on, 0.0), off if rng.random() < 0.8 else None])
            if ivs[-1][1] is None:
                break
            t = off + _f(rng, T / 100, T / 4)
        c["active"] = ivs
    elif a < 0.5:
        c["active"] = {"repeat": {"first_s": _f(rng, 0, T / 4), "period_s": _f(rng, T / 12, T / 3),
                                  "on_s": _f(rng, T / 40, T / 12), "count": int(rng.integers(2, 7)),
                                  "step_samples": int(rng.integers(0, 40))}}
    return c


def random_effects(rng, cfg) -> dict:
    e = {}
    if rng.random() < 0.8:
        e["noise"] = ({"snr_db": _f(rng, 12, 50)} if rng.random() < 0.8
                      else {"rms_lsb": _f(rng, 0, 40)})
    if rng.random() < 0.15:
        e["enob"] = int(rng.integers(6, cfg.adc_bits + 1))
    if rng.random() < 0.2:
        e["dc_lsb"] = _f(rng, -300, 300)
    if rng.random() < 0.25:
        k = int(rng.integers(1, 3))
        hi = cfg.n_fft / 2 - 1
        e["interferer"] = [{"bin": _f(rng, 1, hi), "amp_lsb": _f(rng, 0, 400),
                            "phase_rad": _f(rng, 0, 6.28)} for _ in range(k)]
    if rng.random() < 0.2:
        e["row_db_per_cell"] = _f(rng, 0, 0.3)
        e["col_db_per_cell"] = _f(rng, 0, 0.3)
    if rng.random() < 0.2:
        e["delay_samples"] = int(rng.integers(0, 6))
    e["pn"] = {"enable": bool(rng.random() < 0.7), "chip_len": int(rng.integers(1, 5))}
    return e


def random_settings(rng, cfg) -> TouchSettings:
    return TouchSettings(
        threshold=int(rng.integers(100, 6000)),
        neighbourhood=str(rng.choice(["moore", "vn"])),
        max_touches=int(rng.integers(1, cfg.max_touches + 1)) if rng.random() < 0.5 else None,
        bias_correction=bool(rng.random() < 0.7),
        position_noise_mm=_f(rng, 0, 10), hold_off_us=_f(rng, 0, 400),
        velocity_window_us=_f(rng, 0, 4000), max_speed_mm_s=_f(rng, 0, 6000),
        blobs=bool(rng.random() < 0.4), blob_threshold=int(rng.integers(1, 4000)),
        blob_min_cells=int(rng.integers(1, 16)),
        on_threshold=int(rng.integers(0, 8000)), confirm_frames=int(rng.integers(1, 4)))


def random_scene(seed: int, index: int, sensor: str):
    rng = np.random.default_rng([seed, index])
    name = sensor if sensor != "mixed" else str(rng.choice(["small", "small", "medium"]))
    cfg = _params.get(name)
    m = int(rng.choice([1, 1, 1, 2, 3]))
    frames = int(rng.integers(6, 25))
    T = frames * m * cfg.n_fft / cfg.fs_hz
    contacts = [random_contact(rng, cfg, T, i) for i in range(int(rng.integers(0, 6)))]
    sc = _scene.Scene(name=f"random_{seed}_{index}", sensor=name, frames=frames, m=m,
                      seed=int(rng.integers(1, 1 << 30)), contacts=contacts,
                      effects=random_effects(rng, cfg))
    return sc, random_settings(rng, cfg)


def busy_before_reset(seed: int, index: int, sc: _scene.Scene, cps: int = 3) -> dict:
    """The busy phase before the reset under test (bench/core/sim_main.cpp pre_cycles):
    random cycles (up to three frames of the scene), random settings with a low threshold
    and blobs on, a random M and PN setting."""
    rng = np.random.default_rng([seed, index, 1])
    cfg = sc.cfg
    pre_sc = sc.replace(m=int(rng.integers(1, 4)),
                        effects=dict(sc.effects, pn={"enable": bool(rng.random() < 0.5),
                                                     "chip_len": int(rng.integers(1, 5))}))
    st = random_settings(rng, cfg).replace(threshold=int(rng.integers(1, 400)), blobs=True)
    return {"cycles": int(rng.integers(1, 3 * pre_sc.samples_per_frame * cps)),
            "seed": int(rng.integers(1, 1 << 62)), "regs": rsr.register_writes(pre_sc, st)}


def run_model(sc: _scene.Scene, st: TouchSettings, cps: int = 3):
    eff = rsr.check_scene(sc)
    n = sc.frames * sc.samples_per_frame
    g0, updates = rsr.coupling_plan(sc, n, cps)
    cal = _run_sim.calibration(sc)
    cal = (np.asarray(cal[0], dtype=np.int64), np.asarray(cal[1], dtype=np.int64))
    return rsr.model_reference(sc, g0, updates, eff, sc.frames, st, cal, cps)


def check(sc: _scene.Scene, st: TouchSettings, ref) -> list[str]:
    """Invariant violations of one run (empty when it is clean)."""
    cfg = sc.cfg
    bad = []
    hm = np.asarray(ref.heatmaps)
    if hm.shape != (sc.frames, cfg.rows, cfg.cols):
        bad.append(f"heat maps of shape {hm.shape}, expected {(sc.frames, cfg.rows, cfg.cols)}")
    if hm.size and (hm.min() < 0 or hm.max() > (1 << cfg.hm_width) - 1):
        bad.append(f"heat-map cell outside 0..2^{cfg.hm_width}-1: {hm.min()}..{hm.max()}")
    if len(ref.events) != sc.frames:
        bad.append(f"{len(ref.events)} event frames for {sc.frames} frames")
    limit = st.max_touches if st.max_touches is not None else cfg.max_touches
    xmax, ymax = (cfg.cols - 1) * 256, (cfg.rows - 1) * 256
    alive = set()
    for f, evs in enumerate(ref.events):
        seen, blob_seen = set(), 0
        for e in evs:
            where = f"frame {f}, {e}"
            if e.frame != f % (1 << 16):
                bad.append(f"{where}: frame number {e.frame}")
            if not (0 <= e.x_q <= xmax and 0 <= e.y_q <= ymax):
                bad.append(f"{where}: position outside the sensor (0..{xmax}, 0..{ymax})")
            if e.type == "blob":
                blob_seen += 1
                if not st.blobs or e.id != 0xFF:
                    bad.append(f"{where}: blob event with blobs {st.blobs}, id {e.id}")
                continue
            if blob_seen:
                bad.append(f"{where}: tracker event after a blob event")
            if e.id in seen:
                bad.append(f"{where}: second event of ID {e.id} in one frame")
            seen.add(e.id)
            if e.type == "new":
                if e.id in alive:
                    bad.append(f"{where}: 'new' for the live ID {e.id}")
                alive.add(e.id)
            elif e.type in ("move", "lift"):
                if e.id not in alive:
                    bad.append(f"{where}: '{e.type}' for ID {e.id}, which is not alive")
                if e.type == "lift":
                    alive.discard(e.id)
            else:
                bad.append(f"{where}: unknown type")
            if e.type in ("new", "move") and e.strength < st.threshold:
                bad.append(f"{where}: strength below the threshold {st.threshold}")
            if not (0 <= e.axis_major_q < 1 << 16 and 0 <= e.axis_minor_q < 1 << 16
                    and 0 <= e.angle < 1 << 8 and 0 <= e.flags < 1 << 8):
                bad.append(f"{where}: a field outside its width")
        if blob_seen > MAX_BLOBS:
            bad.append(f"frame {f}: {blob_seen} blob events > {MAX_BLOBS}")
        # the contact limit caps the contacts seen in a frame; IDs held through a
        # hold-off stay alive in the tracker's slots (MAX_TOUCHES of the build)
        seen_now = sum(1 for e in evs if e.type in ("new", "move"))
        if seen_now > limit:
            bad.append(f"frame {f}: {seen_now} contacts reported > the limit {limit}")
        if len(alive) > cfg.max_touches:
            bad.append(f"frame {f}: {len(alive)} live IDs > the tracker's {cfg.max_touches} slots")
    return bad


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--start", type=int, default=0, help="first scene index")
    ap.add_argument("--sensor", choices=["small", "medium", "mixed"], default="mixed")
    ap.add_argument("--fail-dir", default=str(ROOT / "build" / "random_scenes"))
    ap.add_argument("--rtl", type=int, default=0, help="also run the first K scenes through the RTL")
    ap.add_argument("--reset", action="store_true",
                    help="RTL runs start with a busy core reset at a random cycle")
    ap.add_argument("--quiet", action="store_true")
    a = ap.parse_args(argv)
    if a.count < 1 or a.rtl < 0 or a.start < 0:
        print("random_scenes: --count must be >= 1, --rtl and --start >= 0", file=sys.stderr)
        return 2
    # failing scenes of an earlier run must not look like this run's
    for old in Path(a.fail_dir).glob("random_*.json"):
        old.unlink()
    t0 = time.time()
    fails, frames, events = 0, 0, 0
    rtl_done, rtl_skipped = 0, 0
    for i in range(a.start, a.start + a.count):
        sc, st = random_scene(a.seed, i, a.sensor)
        try:
            ref = run_model(sc, st)
            bad = check(sc, st, ref)
            frames += sc.frames
            events += sum(len(e) for e in ref.events)
        except Exception:                       # a crash is a failure, reported with its scene
            bad = ["raised: " + traceback.format_exc().strip().splitlines()[-1]]
        if not bad and rtl_done < a.rtl:
            try:
                rep = rsr.run(sc, cps=3, sim="verilator", plot=False, quiet=True, settings=st,
                              tag="random", pre=busy_before_reset(a.seed, i, sc) if a.reset else None)
                rc, line = rsr.verdict(rep)
                rtl_done += 1
                if rc:
                    bad = ["RTL: " + line]
            except ValueError as e:
                if "update records" in str(e):
                    rtl_skipped += 1            # more coupling updates than the bench holds
                else:
                    bad = [f"RTL raised: {type(e).__name__}: {e}"]
            except Exception as e:              # a harness failure is a failure of the scene
                bad = [f"RTL raised: {type(e).__name__}: " + " ".join(str(e).split())[:300]]
        if bad:
            fails += 1
            d = Path(a.fail_dir)
            d.mkdir(parents=True, exist_ok=True)
            sc.save(d / f"{sc.name}.json")
            (d / f"{sc.name}.settings.json").write_text(json.dumps(st.as_dict(), indent=1) + "\n")
            print(f"random_scenes: FAIL seed {a.seed} index {i} ({sc.sensor}, {sc.frames} frames): "
                  f"{bad[0]}" + (f" (+{len(bad) - 1} more)" if len(bad) > 1 else "")
                  + f"; scene in {d / sc.name}.json", file=sys.stderr)
        elif not a.quiet and (i - a.start + 1) % 100 == 0:
            print(f"random_scenes: {i - a.start + 1} / {a.count} scenes, {fails} failed, "
                  f"{time.time() - t0:.0f} s", flush=True)
    print(f"random_scenes: {a.count} scenes (seed {a.seed}, indices {a.start}..{a.start + a.count - 1}), "
          f"{frames} frames, {events} events, {fails} failed"
          + (f"; through the RTL{' after a busy core was reset' if a.reset else ''}: "
             f"{rtl_done} (bit-exact unless failed above), "
             f"{rtl_skipped} skipped (bench update memory)" if a.rtl else "")
          + f", {time.time() - t0:.0f} s")
    if a.rtl and rtl_done < a.rtl:
        print(f"random_scenes: FAIL only {rtl_done} of {a.rtl} scenes ran through the RTL "
              f"(raise --count)", file=sys.stderr)
        return 1
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
