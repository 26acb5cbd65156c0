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


# tab10 without its red (the detected positions are red circles)
TRACK_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
                 "#bcbd22", "#7f7f7f"]


def heatmap_tracks_figure(heatmaps: np.ndarray, scene, tracks: dict, frame: int | None = None):
    """(fig, ax, frame) of :func:`heatmap_with_tracks` (tests map cells to pixels with
    ax.transData; the figure is saved without tight bounding boxes)."""
    plt = _plt()
    from matplotlib import patheffects as pe
    f = pick_frame(scene) if frame is None else frame
    f = min(f, heatmaps.shape[0] - 1)
    cfg = scene.cfg
    fig, ax = plt.subplots(figsize=(8, 6.5), dpi=110)
    im = ax.imshow(heatmaps[f], origin="upper", cmap="viridis", interpolation="nearest",
                   extent=(-0.5, cfg.cols - 0.5, cfg.rows - 0.5, -0.5))
    fig.colorbar(im, ax=ax, shrink=0.8, label="flattened heat map (counts)")
    outline = [pe.Stroke(linewidth=4.5, foreground="white"), pe.Normal()]
    for k, (tid, pts) in enumerate(sorted(tracks.items())):
        p = np.asarray(pts)
        col = TRACK_COLOURS[k % len(TRACK_COLOURS)]
        # the whole run: a thick line with a white outline (visible on any heat map),
        # a dot where the track starts, a square where it ends
        ax.plot(p[:, 1], p[:, 2], "-", lw=2.5, color=col, label=f"track {tid}", path_effects=outline,
                solid_capstyle="round", zorder=3)
        ax.plot(p[:1, 1], p[:1, 2], "o", ms=6, color=col, mec="white", mew=1.2, zorder=4)
        if len(p) > 1:
            ax.plot(p[-1:, 1], p[-1:, 2], "s", ms=6, color=col, mec="white", mew=1.2, zorder=4)
        now = p[p[:, 0] == f]
        if now.size:
            ax.plot(now[:, 1], now[:, 2], "o", mfc="none", mec="red", ms=12, mew=1.5, zorder=5)
    for t in scene.truth((f + 0.5) * scene.frame_period_s):
        ax.plot(t["x_cells"], t["y_cells"], "x", color="white", ms=10, mew=2, zorder=6)
    ax.set_xlim(-0.5, cfg.cols - 0.5)
    ax.set_ylim(cfg.rows - 0.5, -0.5)
    ax.set_xlabel("x (columns, cells)")
    ax.set_ylabel("y (rows, cells)")
    ax.set_title(f"{scene.name}: frame {f}  (x truth, o detected, lines: tracks over the whole run)")
    if tracks:
        ax.legend(loc="upper right", fontsize=7, framealpha=0.6)
    fig.tight_layout()
    return fig, ax, f


def heatmap_with_tracks(heatmaps: np.ndarray, scene, tracks: dict, path, frame: int | None = None):
    """One (flattened) heat map with the true positions (white x), the detected positions
    of that frame (red circles) and every track over the whole run (thick lines with a
    white outline, a dot at the start, a square at the end), in cells."""
    plt = _plt()
    fig, _ax, _f = heatmap_tracks_figure(heatmaps, scene, tracks, frame)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path


LATENCY_POPULATIONS = (("window end -> first event", "C0"), ("window end -> last event", "C1"),
                       ("onset -> new-contact event", "C2"))


def latency_figure(first, last, onset, budget_us: float = 8.0):
    """(fig, axes, bins): one panel per population, each with its own range and bins,
    so none hides another (the onset latencies are fewer and farther right)."""
    plt = _plt()
    fig, axes = plt.subplots(3, 1, figsize=(6.5, 6.5))
    bins_all = []
    for ax, v, (lab, col) in zip(axes, (first, last, onset), LATENCY_POPULATIONS):
        v = np.asarray(list(v), dtype=float)
        if v.size == 0:
            ax.text(0.5, 0.5, f"{lab}: no data", ha="center", va="center", transform=ax.transAxes)
            ax.set_yticks([])
            bins_all.append(None)
            continue
        lo, hi = float(v.min()), float(v.max())
        pad = max(0.05, 0.05 * (hi - lo))
        bins = np.linspace(lo - pad, hi + pad, 41)
        ax.hist(v, bins=bins, color=col, label=lab)
        if lo - pad <= budget_us <= hi + pad:
            ax.axvline(budget_us, color="k", ls="--", lw=1, label=f"{budget_us:g} us budget")
        ax.set_title(f"{lab}: n {v.size}, median {np.median(v):.2f} us, max {hi:.2f} us", fontsize=9)
        ax.set_ylabel("count")
        ax.legend(fontsize=7, loc="upper right")
        bins_all.append(bins)
    axes[-1].set_xlabel("latency (us)")
    fig.tight_layout()
    return fig, axes, bins_all


def latency_panels(first, last, onset, path, budget_us: float = 8.0):
    """The latency plot of a run: a panel per population (window end -> first / last
    event, onset -> new-contact event)."""
    plt = _plt()
    fig, _axes, _bins = latency_figure(first, last, onset, budget_us)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def animation_frames(heatmaps, frame_events, cfg, step: int = 1, max_frames: int = 300,
                     vmax: float | None = None):
    """RGB frames (fmt.host.view.Renderer: heat map, fingers, IDs, ellipses, tracks) of a
    run: every ``step``-th frame, at most ``max_frames``."""
    from fmt.host import events as E
    from fmt.host import view as V
    hm = np.asarray(heatmaps)
    n = min(len(hm), len(frame_events))
    ren = V.Renderer(E.Sensor(cfg.rows, cfg.cols, cfg.pitch_mm),
                     vmax=float(vmax if vmax is not None else max(1.0, float(np.max(hm[:n])))),
                     cmap="viridis")
    contacts = E.Contacts(hold_frames=0)
    get = lambda e, k: e[k] if isinstance(e, dict) else getattr(e, k)
    keys = ("id", "type", "x_q", "y_q", "strength", "axis_major_q", "axis_minor_q", "angle", "flags")
    out = []
    for f in range(n):
        recs = [dict({k: get(e, k) for k in keys}, frame=f & 0xFFFF, time=0, last=False)
                for e in frame_events[f]]
        upd = contacts.update(recs, frame=f & 0xFFFF)
        ren.update_tracks(upd)
        if f % step == 0:
            out.append(ren.draw(hm[f], upd, f"frame {f}")[:, :, :3].copy())
            if len(out) >= max_frames:
                break
    return out, ren


def animation_gif(heatmaps, frame_events, cfg, path, step: int = 1, max_frames: int = 300,
                  fps: float = 20.0, vmax: float | None = None):
    """An animated GIF of a run (imageio): the heat map with contacts, IDs, ellipses and
    tracks, every ``step``-th frame."""
    try:
        import imageio.v3 as iio
    except ImportError:
        raise ImportError("the animated view needs imageio (pip install imageio)") from None
    frames, _ren = animation_frames(heatmaps, frame_events, cfg, step, max_frames, vmax)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, np.stack(frames), duration=1000.0 / fps, loop=0)
    return path
