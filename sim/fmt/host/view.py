"""Heat map + contacts renderer of ``fmtctl view`` (matplotlib, blitted).

:class:`Renderer` draws one frame: the raw heat map (image), every finger as a filled red
disc with its ID, its ellipse (white outline, the event's semi-axes and angle) and its
track (the last ``track_len`` positions, one colour per ID), palms (blob events) as
magenta squares.  The axes, ticks and labels are drawn once; every frame restores that
background, writes the colour-mapped heat map straight into the canvas pixels (one
table lookup and two index gathers, no image resampling) and draws only the changing
artists (blitting, artists reused from pools), so a frame costs that, a few markers and
the PNG encoding: the test asks >= 30 frames/s headless on the default 30 x 40 map
(about 70 here).  Coordinates are cells
(x = column, y = row, cell centres on integers), y pointing down as on the sensor.

:func:`frames_of_recording` turns a recording into the (heat map, update) sequence the
viewer shows: one frame per report, the heat map of the latest snapshot taken before it
(or one per snapshot when there are no events).
"""
from __future__ import annotations

from collections import deque
from pathlib import Path

import numpy as np

from .events import Contacts, Sensor, Update, group

FINGER_RGB = (1.0, 0.0, 0.0)
PALM_RGB = (1.0, 0.0, 1.0)
# track colours: tab10 without its red (C3), so a track never looks like a finger
TRACK_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                 "#bcbd22", "#17becf"]
POOL = 32


def track_colour(key: int) -> str:
    return TRACK_COLOURS[key % len(TRACK_COLOURS)]


class Renderer:
    def __init__(self, sensor: Sensor, vmax: float = 12000.0, size=(6.4, 4.8), dpi: int = 100,
                 track_len: int = 400, cmap: str = "gray", figure=None):
        from matplotlib.figure import Figure
        from matplotlib.patches import Ellipse
        self.sensor = sensor
        self.track_len = track_len
        if figure is None:
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            self.fig = Figure(figsize=size, dpi=dpi)
            FigureCanvasAgg(self.fig)
        else:
            self.fig = figure
        self.canvas = self.fig.canvas
        ax = self.ax = self.fig.add_axes((0.08, 0.1, 0.88, 0.82))
        r, c = sensor.rows, sensor.cols
        # the image artist gives the axes their colour map and extent; every frame writes
        # its pixels straight into the canvas (see _paint_heatmap), not through it
        self.im = ax.imshow(np.zeros((r, c)), cmap=cmap, vmin=0, vmax=vmax, interpolation="nearest",
                            extent=(-0.5, c - 0.5, r - 0.5, -0.5), animated=True)
        self.vmax = float(vmax)
        lut = (self.im.cmap(np.arange(256)) * 255 + 0.5).astype(np.uint8)         # (256, 4)
        self.lut32 = np.ascontiguousarray(lut).view(np.uint32)[:, 0]   # one RGBA word each
        ax.set_xlim(-0.5, c - 0.5)
        ax.set_ylim(r - 0.5, -0.5)
        ax.set_xlabel("x (column)")
        ax.set_ylabel("y (row)")
        self.title = ax.set_title(" ", fontsize=9, animated=True)
        kw = dict(animated=True, linestyle="none")
        self.fingers, = ax.plot([], [], "o", ms=9, mfc=FINGER_RGB, mec="white", mew=1.0, **kw)
        self.palms, = ax.plot([], [], "s", ms=12, mfc=PALM_RGB, mec="white", mew=1.0, **kw)
        self.ellipses = [Ellipse((0, 0), 1, 1, fill=False, ec="white", lw=1.0, animated=True,
                                 visible=False) for _ in range(POOL)]
        for e in self.ellipses:
            ax.add_patch(e)
        self.labels = [ax.text(0, 0, "", color="white", fontsize=8, animated=True, visible=False)
                       for _ in range(POOL)]
        self.lines = [ax.plot([], [], "-", lw=1.5, animated=True, visible=False)[0] for _ in range(POOL)]
        self.tracks: dict[int, deque] = {}
        self.last: Update | None = None
        self.hm = None                          # the heat map on show (kept when draw gets None)
        self._layout()

    def _layout(self) -> None:
        """Draw the static parts, keep them as the background, map the axes' pixels to
        cells; again whenever the canvas changed size (a resized window)."""
        self.canvas.draw()
        self.bg = self.canvas.copy_from_bbox(self.fig.bbox)
        self._size = tuple(self.fig.bbox.size)
        self._pixel_map()

    def _pixel_map(self) -> None:
        """The canvas pixels inside the axes and the cell each one shows (nearest)."""
        h = int(round(self.fig.bbox.height))
        (x0, y0), (x1, y1) = self.ax.bbox.get_points()
        cols = np.arange(int(np.ceil(x0 - 0.5)), int(np.floor(x1 - 0.5)) + 1)   # pixel centres inside
        rows_up = np.arange(int(np.ceil(y0 - 0.5)), int(np.floor(y1 - 0.5)) + 1)
        inv = self.ax.transData.inverted()
        dx = inv.transform(np.column_stack([cols + 0.5, np.full(cols.size, y0)]))[:, 0]
        dy = inv.transform(np.column_stack([np.full(rows_up.size, x0), rows_up + 0.5]))[:, 1]
        r, c = self.sensor.rows, self.sensor.cols
        self.px_cols = cols
        self.px_rows = h - 1 - rows_up                      # buffer rows: y pointing down
        self.cell_col = np.clip(np.floor(dx + 0.5).astype(int), 0, c - 1)
        self.cell_row = np.clip(np.floor(dy + 0.5).astype(int), 0, r - 1)
        self.px_r0, self.px_r1 = int(self.px_rows.min()), int(self.px_rows.max()) + 1
        self.px_c0, self.px_c1 = int(cols.min()), int(cols.max()) + 1
        order = np.argsort(self.px_rows)
        self.cell_row_sorted = self.cell_row[order]

    def _paint_heatmap(self, buf: np.ndarray, heatmap) -> None:
        """Colour-map the heat map (vmin 0, vmax) and write it, nearest-neighbour, into
        the canvas pixels of the axes: one table lookup and one fancy index per frame."""
        hm = np.asarray(heatmap, dtype=float)
        idx = np.clip((hm * (256.0 / self.vmax)).astype(np.int64), 0, 255)
        px = self.lut32[idx]                                        # (rows, cols), RGBA words
        px = px.take(self.cell_col, axis=1).take(self.cell_row_sorted, axis=0)
        buf.view(np.uint32)[self.px_r0:self.px_r1, self.px_c0:self.px_c1, 0] = px

    def update_tracks(self, upd: Update) -> None:
        """A new report: its contacts extend the tracks (drawn until the contact ends)."""
        self.last = upd
        for k in upd.removed:
            self.tracks.pop(k, None)
        for k, c in upd.alive.items():
            if not c.palm:
                self.tracks.setdefault(k, deque(maxlen=self.track_len)).append((c.x_q / 256, c.y_q / 256))

    def draw(self, heatmap, upd: Update | None = None, title: str = "") -> np.ndarray:
        """Render one frame (upd None: the contacts of the last update_tracks); the RGBA
        pixels (height, width, 4), a view of the canvas."""
        upd = upd if upd is not None else self.last
        if tuple(self.fig.bbox.size) != self._size:
            self._layout()
        self.canvas.restore_region(self.bg)
        ax = self.ax
        if heatmap is not None:
            self.hm = heatmap
        if self.hm is not None:
            self._paint_heatmap(np.asarray(self.canvas.buffer_rgba()), self.hm)
        alive = upd.alive if upd is not None else {}
        fingers = [c for c in alive.values() if not c.palm][:POOL]
        palms = [c for c in alive.values() if c.palm]
        for i, line in enumerate(self.lines):
            line.set_visible(False)
        for i, (k, pts) in enumerate(list(self.tracks.items())[:POOL]):
            line = self.lines[i]
            p = np.asarray(pts)
            line.set_data(p[:, 0], p[:, 1])
            line.set_color(track_colour(k))
            line.set_visible(True)
            ax.draw_artist(line)
        for i, e in enumerate(self.ellipses):
            if i < len(fingers):
                c = fingers[i]
                e.set_center((c.x_q / 256, c.y_q / 256))
                e.set_width(2 * c.axis_major_q / 256)
                e.set_height(2 * c.axis_minor_q / 256)
                # angle against +x with y down: matplotlib's angle is counter-clockwise
                # with y up, and the axes are flipped, so the same number of degrees
                e.set_angle(c.angle * 180.0 / 256)
                e.set_visible(True)
                ax.draw_artist(e)
        self.fingers.set_data([c.x_q / 256 for c in fingers], [c.y_q / 256 for c in fingers])
        self.palms.set_data([c.x_q / 256 for c in palms], [c.y_q / 256 for c in palms])
        ax.draw_artist(self.palms)
        ax.draw_artist(self.fingers)
        for i, t in enumerate(self.labels):
            if i < len(fingers):
                c = fingers[i]
                t.set_position((c.x_q / 256 + 0.45, c.y_q / 256 - 0.45))
                t.set_text(str(c.key))
                t.set_visible(True)
                ax.draw_artist(t)
        self.title.set_text(title)
        ax.draw_artist(self.title)
        return np.asarray(self.canvas.buffer_rgba())

    def pixel_of(self, x: float, y: float) -> tuple[int, int]:
        """(row, column) of the image pixel at data coordinates (x, y) (cells)."""
        dx, dy = self.ax.transData.transform((x, y))
        h = int(self.fig.bbox.height)
        return int(round(h - dy - 0.5)), int(round(dx - 0.5))


def save_png(rgba: np.ndarray, path, compress_level: int = 1) -> None:
    from PIL import Image
    a = np.ascontiguousarray(rgba, dtype=np.uint8)
    if a.ndim != 3 or a.shape[2] != 4:
        raise ValueError(f"save_png: an RGBA image (height, width, 4) expected, got shape {a.shape}")
    img = Image.frombuffer("RGBA", (a.shape[1], a.shape[0]), a, "raw", "RGBA", 0, 1)
    img.convert("RGB").save(path, format="PNG", compress_level=compress_level)


def frames_of_recording(rec, hold_frames: int = 40):
    """Yield (heat map, update, title) of a recording (fmt.host.recording.Recording)."""
    reports = group(rec.events)
    hm = rec.heatmaps
    if not reports:
        for k in range(len(hm)):
            yield hm[k], None, f"snapshot {k} (frame {int(rec.heatmap_frame[k])})"
        return
    # the host time of each report: that of its last event
    t_ev = np.asarray(rec.event_host_s, dtype=float)
    ends = np.cumsum([len(r) for r in reports]) - 1
    t_rep = t_ev[ends] if t_ev.size == len(rec.events) else np.zeros(len(reports))
    t_hm = np.asarray(rec.heatmap_host_s, dtype=float)
    contacts = Contacts(hold_frames)
    for r, t in zip(reports, t_rep):
        k = int(np.searchsorted(t_hm, t, side="right")) - 1
        upd = contacts.update(r)
        yield (hm[max(k, 0)] if len(hm) else None), upd, f"frame {upd.frame}: {len(upd.alive)} contacts"


def frames_of_device(dev, a):
    """Yield (heat map, update or None, title) live: a heat-map snapshot per frame, the
    reports that arrived meanwhile (the stream is on; the caller switches it)."""
    from .events import Reports, from_payload
    from fmt import protocol as P
    grouper, contacts = Reports(), Contacts(a.hold_frames)
    while True:
        hm = dev.heatmap()
        upd = None
        while dev.pending:
            fr = dev.pending.pop(0)
            if fr.cmd == P.CMD_EVENT:
                for rep in grouper.feed(from_payload(fr.payload)):
                    upd = contacts.update(rep)
        frame = dev.snap_frame
        n = len(contacts.alive)
        yield hm, upd, f"snapshot of frame {frame}: {n} contacts"


def render_to_pngs(frames, sensor: Sensor, out_dir, limit: int | None = None, vmax: float | None = None,
                   **kw) -> int:
    """Write frame_00000.png ... of (heat map, update, title) items; returns the count."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    ren = None
    n = 0
    for hm, upd, title in frames:
        if ren is None:
            v = vmax if vmax is not None else (float(np.max(hm)) if hm is not None else 12000.0)
            ren = Renderer(sensor, vmax=max(v, 1.0), **kw)
        if upd is not None:
            ren.update_tracks(upd)
        save_png(ren.draw(hm, upd, title), out / f"frame_{n:05d}.png")
        n += 1
        if limit and n >= limit:
            break
    return n


def show_live(frames, sensor: Sensor, limit: int | None = None, vmax: float | None = None) -> int:
    """The frames in a window (an interactive matplotlib backend); returns the count.
    RuntimeError when matplotlib has no interactive backend (no display)."""
    import matplotlib
    import matplotlib.pyplot as plt
    backend = matplotlib.get_backend().lower()
    if backend in ("agg", "pdf", "ps", "svg", "cairo", "template") or backend.startswith("module://"):
        raise RuntimeError(f"no interactive matplotlib backend ({backend}; no display?): "
                           f"use --png-dir DIR for PNG frames")
    ren = None
    n = 0
    for hm, upd, title in frames:
        if ren is None:
            fig = plt.figure(figsize=(6.4, 4.8))
            v = vmax if vmax is not None else (float(np.max(hm)) if hm is not None else 12000.0)
            plt.show(block=False)
            ren = Renderer(sensor, vmax=max(v, 1.0), figure=fig)
        if not plt.fignum_exists(ren.fig.number):
            break                               # window closed
        if upd is not None:
            ren.update_tracks(upd)
        ren.draw(hm, upd, title)
        ren.canvas.blit(ren.fig.bbox)
        ren.canvas.flush_events()
        n += 1
        if limit and n >= limit:
            break
    return n
