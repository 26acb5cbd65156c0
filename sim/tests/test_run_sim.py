"""make sim (fmt.run_sim) on the small scene: report keys and plausibility.

The post-processing is another block's model (fmt.touch).  So that this file tests
run_sim's own part independently of it, it also runs with a minimal processor written
here (3x3 local maximum above a threshold + Von Neumann parabola fit, paper Eq. 3-4,
one event per maximum, IDs by order)."""
import json
import math

import numpy as np
import pytest

from fmt import run_sim
from fmt import scene as S
from fmt.settings import TouchSettings


def _local_processor(heatmaps, scene, settings, cal):
    offset, gain = cal
    z = (heatmaps - offset) * (gain / 16384.0)
    cfg = scene.cfg
    q = 1 << cfg.frac_bits
    out = []
    for f, h in enumerate(z):
        p = np.pad(h, 1, constant_values=0.0)
        evs = []
        for r in range(cfg.rows):
            for c in range(cfg.cols):
                v = p[r + 1, c + 1]
                nb = p[r:r + 3, c:c + 3].copy()
                nb[1, 1] = -np.inf
                if v < settings.threshold or v <= nb.max():
                    continue
                def vertex(a, b):   # parabola through (-1, a), (0, v), (1, b)
                    den = a - 2 * v + b
                    return 0.0 if den >= 0 else 0.5 * (a - b) / den
                x = c + vertex(p[r + 1, c], p[r + 1, c + 2])
                y = r + vertex(p[r, c + 1], p[r + 2, c + 1])
                evs.append({"frame": f, "id": len(evs), "type": "move",
                            "x_q": int(round(x * q)), "y_q": int(round(y * q)), "strength": int(v)})
        out.append(evs)
    return out


KEYS = {"frames", "touches", "position_error_mm", "jitter_mm", "model_frames_per_s",
        "missed", "false", "tap_latency_us", "clipped_samples"}


def _check(rep, sc):
    assert KEYS <= set(rep)
    assert rep["frames"] == sc.frames
    t = rep["touches"]
    assert 0 <= t["min"] <= t["mean"] <= t["max"] <= 4
    assert abs(t["mean"] - t["truth_mean"]) < 0.3
    pe = rep["position_error_mm"]
    assert pe["n"] > 0 and 0 <= pe["rms"] <= pe["max"] < 2.5
    assert rep["jitter_mm"]["max"] is not None and 0 < rep["jitter_mm"]["max"] < 1.0
    assert rep["model_frames_per_s"] > 0 and rep["clipped_samples"] == 0
    assert rep["tap_latency_us"]["n"] == 1
    assert 0 < rep["tap_latency_us"]["mean"] <= 2 * sc.frame_period_s * 1e6


def test_run_sim_small_local_processor(tmp_path):
    sc = S.load(S.SCENES_DIR / "small.json")
    rep = run_sim.run(sc, tmp_path, settings=TouchSettings(threshold=1500),
                      processor=_local_processor, quiet=True)
    _check(rep, sc)
    on_disk = json.loads((tmp_path / "small" / "report.json").read_text())
    assert on_disk["frames"] == rep["frames"]
    assert (tmp_path / "small" / "heatmap.png").stat().st_size > 10000
    # the same through the render path
    rep2 = run_sim.run(sc, None, settings=TouchSettings(threshold=1500),
                       processor=_local_processor, render=True)
    _check(rep2, sc)


def test_run_sim_small_with_touch_pipeline(tmp_path):
    pytest.importorskip("fmt.touch")
    sc = S.load(S.SCENES_DIR / "small.json")
    rep = run_sim.run(sc, tmp_path, plot=False, quiet=True)
    _check(rep, sc)


def test_evaluate_counts_misses_and_false():
    sc = S.Scene(sensor="small", frames=3, contacts=[{"name": "a", "path": [[0, 5.0, 5.0]]}])
    det = [[(0, 5.3, 5.4)], [], [(0, 5.0, 5.0), (1, 20.0, 14.0)]]
    ev = run_sim.evaluate(sc, det)
    assert ev["missed"] == 1 and ev["false"] == 1
    assert ev["position_error_mm"]["max"] == pytest.approx(0.5)
    assert ev["position_error_mm"]["rms"] == pytest.approx(math.sqrt(0.25 / 2))


def test_cli(tmp_path, capsys):
    pytest.importorskip("fmt.touch")
    assert run_sim.main(["--scene", str(S.SCENES_DIR / "small.json"), "--out", str(tmp_path),
                         "--no-plot", "--quiet"]) == 0
    assert "position error" in capsys.readouterr().out
    assert (tmp_path / "small" / "report.json").exists()
