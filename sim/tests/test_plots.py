"""The pictures of a run (fmt.plots), checked by pixels at known coordinates: the tracks
over the whole run on the heat map, every latency population in its own panel, and the
animated view (GIF through imageio) with the contacts where the events put them."""
from __future__ import annotations

import numpy as np
import pytest

from fmt import params, plots
from fmt import scene as _scene
from fmt.settings import TouchSettings
from fmt.touch import process_frames


def hexrgb(h: str):
    return tuple(int(h[i:i + 2], 16) for i in (1, 3, 5))


def pixel(fig, ax, x, y):
    dx, dy = ax.transData.transform((x, y))
    return int(round(fig.bbox.height - dy - 0.5)), int(round(dx - 0.5))


def canvas_rgb(fig):
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[:, :, :3].astype(int)


def close(p, want, tol=12):
    return max(abs(int(a) - int(b)) for a, b in zip(p, want)) <= tol


def empty_scene(frames=20):
    return _scene.Scene.from_dict({"name": "t", "sensor": "default", "frames": frames, "m": 1,
                                   "seed": 1, "contacts": []})


def test_tracks_on_the_heat_map(tmp_path):
    sc = empty_scene()
    hm = np.zeros((20, 30, 40))
    hm[:, 0, 0] = 1000.0                       # colour scale 0..1000: zero is viridis(0)
    tracks = {3: [(f, 5 + 1.0 * f, 10.0) for f in range(20)],          # a drag along y = 10
              7: [(f, 30.0, 4 + 1.0 * f) for f in range(20)]}          # and one along x = 30
    fig, ax, _f = plots.heatmap_tracks_figure(hm, sc, tracks, frame=10)
    img = canvas_rgb(fig)
    c0, c1 = hexrgb(plots.TRACK_COLOURS[0]), hexrgb(plots.TRACK_COLOURS[1])
    for x in (7.5, 12.5, 20.5):                # the line over the whole run, between samples
        assert close(img[pixel(fig, ax, x, 10.0)], c0), x
    for y in (6.5, 17.5):
        assert close(img[pixel(fig, ax, 30.0, y)], c1), y
    # the white outline just beside the line, the heat map (viridis of 0) farther away
    r, c = pixel(fig, ax, 12.5, 10.0)
    assert any(min(img[r + d, c]) >= 200 for d in range(2, 5))
    far = img[pixel(fig, ax, 12.5, 14.0)]
    assert close(far, (68, 1, 84), 3)          # viridis(0)
    path = plots.heatmap_with_tracks(hm, sc, tracks, tmp_path / "hm.png", frame=10)
    from PIL import Image
    saved = np.asarray(Image.open(path))[:, :, :3].astype(int)
    assert saved.shape[:2] == img.shape[:2] and close(saved[pixel(fig, ax, 7.5, 10.0)], c0)


def test_latency_panels_show_every_population(tmp_path):
    rng = np.random.default_rng(1)
    first = rng.normal(6.9, 0.01, 1000)
    last = rng.normal(6.95, 0.01, 1000)
    onset = rng.uniform(9.0, 12.0, 12)          # few, far right: hidden on shared bins before
    fig, axes, bins = plots.latency_figure(first, last, onset)
    img = canvas_rgb(fig)
    for ax, v, b, (_lab, col) in zip(axes, (first, last, onset), bins, plots.LATENCY_POPULATIONS):
        from matplotlib.colors import to_rgb
        want = tuple(int(round(255 * c)) for c in to_rgb(col))
        k = int(np.searchsorted(b, v[0], side="right")) - 1      # the bin of a sample: >= 1 count
        x = 0.5 * (b[k] + b[k + 1])
        h = np.histogram(v, b)[0][k]
        assert close(img[pixel(fig, ax, x, 0.5 * h)], want, 3), col     # inside that bar
    assert plots.latency_panels(first, last, [], tmp_path / "lat.png").exists()


def test_animated_gif(tmp_path):
    iio = pytest.importorskip("imageio.v3", reason="imageio is not installed")
    cfg = params.DEFAULT
    yy, xx = np.mgrid[0:cfg.rows, 0:cfg.cols].astype(float)
    hm = np.full((8, cfg.rows, cfg.cols), 100.0)
    for f in range(8):
        hm[f] += 9000 * np.exp(-((xx - (8 + f)) ** 2 + (yy - 12.3) ** 2) / (2 * 0.7 ** 2))
    hm = np.rint(hm).astype(np.int64)
    # new contacts reported at once (no confirmation frame): frame 0 has the finger; it
    # moves a cell (5 mm) a frame, which a finger can at frames of 64 windows (0.39 ms:
    # the tracker's gate is 7.6 mm there, 3.6 mm at one window)
    evs = process_frames(hm, cfg, TouchSettings(confirm_frames=1), fixed=True,
                         frame_period_s=64 * cfg.window_s)
    path = plots.animation_gif(hm, evs, cfg, tmp_path / "run.gif", fps=10)
    frames = iio.imread(path)
    assert frames.shape[0] == 8
    _fr, ren = plots.animation_frames(hm, evs, cfg)             # the same geometry
    for f in (0, 7):
        (e,) = [e for e in evs[f] if e.type in ("new", "move")]
        p = frames[f][ren.pixel_of(e.x_q / 256, e.y_q / 256)][:3].astype(int)
        assert p[0] >= 200 and p[1] <= 60 and p[2] <= 60, (f, p)     # the red finger disc
    # the last frame's track: the finger's start (under its disc in frame 0) is now on
    # the track line, in the track colour of its ID
    from fmt.host import view as V
    e0 = [e for e in evs[0] if e.type == "new"][0]
    want = hexrgb(V.track_colour(e0.id))
    p = frames[7][ren.pixel_of(e0.x_q / 256 + 0.5, e0.y_q / 256)][:3].astype(int)
    assert close(p, want, 40), (p, want)
