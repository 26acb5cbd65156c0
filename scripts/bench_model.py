#!/usr/bin/env python3
"""Speed of the floating-point model on ONE core: frames/s of the full float chain
(ADC synthesis + receive) on the default 30 x 40 sensor, and of render_heatmaps.

    python scripts/bench_model.py [--scene sim/scenes/default.json] [--frames 2000] [--repeat 3]

BLAS/OpenMP threads are pinned to 1 before numpy is imported.  Both wall-clock and
process CPU time are reported (the machine is shared: CPU time is the figure that does
not depend on the load of other processes); the best of ``--repeat`` runs is kept.
"""
from __future__ import annotations

import os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "sim"))

from fmt import chain  # noqa: E402
from fmt import scene as _scene  # noqa: E402


def _time(fn, repeat):
    best_wall, best_cpu = float("inf"), float("inf")
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        best_wall = min(best_wall, time.perf_counter() - w0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return best_wall, best_cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=str(ROOT / "sim" / "scenes" / "default.json"))
    ap.add_argument("--frames", type=int, default=2000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", action="store_true", help="print the result as JSON")
    a = ap.parse_args(argv)
    if a.frames < 1 or a.repeat < 1:
        print("bench_model: --frames and --repeat must be >= 1", file=sys.stderr)
        return 2
    try:
        sc = _scene.load(a.scene).replace(frames=a.frames)
    except ValueError as e:                       # fmt.inputs.InputError: one line
        print(f"bench_model: {e}", file=sys.stderr)
        return 2
    chain.heatmaps_float(sc, frames=8)            # warm up (imports, caches)
    res = {"scene": sc.name, "sensor": sc.cfg.name, "frames": a.frames, "m": sc.m}
    for label, fn in (("adc_chain", lambda: chain.heatmaps_float(sc)),
                      ("render", lambda: chain.render_heatmaps(sc))):
        wall, cpu = _time(fn, a.repeat)
        res[label] = {"wall_s": wall, "cpu_s": cpu, "frames_per_s_wall": a.frames / wall,
                      "frames_per_s_cpu": a.frames / cpu}
    if a.json:
        print(json.dumps(res, indent=1))
    else:
        for label in ("adc_chain", "render"):
            r = res[label]
            print(f"{label:10s} {a.frames} frames of '{sc.name}' ({sc.cfg.rows}x{sc.cfg.cols}, "
                  f"N={sc.cfg.n_fft}, M={sc.m}): {r['frames_per_s_cpu']:8.0f} frames/s per CPU "
                  f"second ({r['frames_per_s_wall']:.0f} frames/s wall)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
