"""Plots of model runs (matplotlib, Agg backend: no display needed)."""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def pick_frame(scene) -> int:
    """The middle one of the frames with the most true contacts."""
    counts = [len(t) for t in scene.truth_frames()]
    if not counts:
        return 0
    best = [i for i, c in enumerate(counts) if c == max(counts)]
    return best[len(best) // 2]


def heatmap_with_tracks(heatmaps: np.ndarray, scene, tracks: dict, path, frame: int | None = None):
    """One (flattened) heat map with the true positions (white x), the detected positions
    of that frame (circles) and every track over the whole run (lines), in cells."""
    plt = _plt()
    f = pick_frame(scene) if frame is None else frame
    f = min(f, heatmaps.shape[0] - 1)
    cfg = scene.cfg
    fig, ax = plt.subplots(figsize=(8, 6.5), dpi=110)
    im = ax.imshow(heatmaps[f], origin="upper", cmap="viridis", interpolation="nearest",
                   extent=(-0.5, cfg.cols - 0.5, cfg.rows - 0.5, -0.5))
    fig.colorbar(im, ax=ax, shrink=0.8, label="flattened heat map (counts)")
    for k, (tid, pts) in enumerate(sorted(tracks.items())):
        p = np.asarray(pts)
        ax.plot(p[:, 1], p[:, 2], "-", lw=1.2, color=f"C{k % 10}", label=f"track {tid}")
        now = p[p[:, 0] == f]
        if now.size:
            ax.plot(now[:, 1], now[:, 2], "o", mfc="none", mec="red", ms=12, mew=1.5)
    for t in scene.truth((f + 0.5) * scene.frame_period_s):
        ax.plot(t["x_cells"], t["y_cells"], "x", color="white", ms=10, mew=2)
    ax.set_xlabel("x (columns, cells)")
    ax.set_ylabel("y (rows, cells)")
    ax.set_title(f"{scene.name}: frame {f}  (x truth, o detected, lines tracks)")
    if tracks:
        ax.legend(loc="upper right", fontsize=7, framealpha=0.6)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path
