"""The touch-processing pipeline: heat maps -> touch events (twin of ``rtl/fmt_touch.v``).

    flatten (fmt.flatten) -> 3x3 local maxima above the threshold (fmt.localmax)
    [-> blobs (fmt.blob), off by default] -> paraboloid fits (fmt.interp)
    -> frame matching (fmt.tracker)

``fixed=True`` runs the bit-exact twins of the RTL blocks (integer heat maps); the
events then equal the RTL's event stream (without time stamps).  ``fixed=False`` runs
the floating-point references (flatten without rounding, float fits); the fine touches
are then quantised to the event format (Q8.8 round half up, angle to pi/256) only to
enter the tracker, whose arithmetic is integer anyway.
"""
from __future__ import annotations

import math

import numpy as np

from . import flatten as _flatten
from . import interp as _interp
from . import localmax as _localmax
from .params import SensorConfig
from .settings import TouchSettings
from .tracker import Touch, TouchEvent, Tracker, TrackParams

MAX_BLOBS = 8          # blob events per frame (rtl/fmt_touch.v: fmt_blob MAX_BLOBS)


def _touch_from_fixed(tp) -> Touch:
    return Touch(int(tp.x), int(tp.y), int(tp.strength), int(tp.axis_major),
                 int(tp.axis_minor), int(tp.angle), int(tp.flags))


def _touch_from_float(tp) -> Touch:
    q = 256.0
    rq = lambda v: int(math.floor(v * q + 0.5))
    ang = int(math.floor(tp.angle / math.pi * 256 + 0.5)) & 255
    return Touch(rq(tp.x), rq(tp.y), int(round(tp.strength)), rq(tp.axis_major),
                 rq(tp.axis_minor), ang, int(tp.flags))


def _float3x3(z, r: int, c: int) -> np.ndarray:
    """3x3 float neighbourhood (0 outside the sensor)."""
    rows, cols = z.shape
    z3 = np.zeros((3, 3))
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            if 0 <= r + dy < rows and 0 <= c + dx < cols:
                z3[dy + 1, dx + 1] = z[r + dy, c + dx]
    return z3


class TouchPipeline:
    """Stateful pipeline (the tracker keeps contacts across calls)."""

    def __init__(self, cfg: SensorConfig, settings: TouchSettings | None = None,
                 fixed: bool = True, flatten_cal=None, frame_period_s: float | None = None,
                 track_params: TrackParams | None = None, blobs: bool | None = None):
        self.cfg = cfg
        self.fixed = fixed
        self.frame_period_s = frame_period_s
        self.offset, self.gain = flatten_cal if flatten_cal is not None else _flatten.identity(cfg)
        self.tp = track_params or TrackParams.from_settings(cfg, settings or TouchSettings(),
                                                            frame_period_s)
        self.tracker = Tracker(self.tp)
        self.localmax = _localmax.LocalMaxima()      # the ranking's previous frame
        self._use(settings or TouchSettings(), blobs)

    def _use(self, settings: TouchSettings, blobs: bool | None = None) -> None:
        """Settings of the next frames (the stage settings and the tracker's)."""
        self.s = settings
        self.blobs = settings.blobs if blobs is None else blobs
        self.max_touches = (settings.max_touches if settings.max_touches is not None
                            else self.cfg.max_touches)
        self.moore = settings.neighbourhood == "moore"

    def set_frame_settings(self, settings: TouchSettings) -> None:
        """Change every setting from the next frame on, as rtl/fmt_touch.v does for a
        register write before the frame's first row: the stages and the tracker (its
        parameters converted with this pipeline's frame period; contacts kept)."""
        self._use(settings)
        self.tp = TrackParams.from_settings(self.cfg, settings, self.frame_period_s)
        self.tracker.p = self.tp

    def touches(self, hm_flat, frame: int) -> tuple[list, list]:
        """Fine touches (tracker input) and blobs of one flattened heat map."""
        s = self.s
        zi = np.rint(hm_flat).astype(np.int64) if not self.fixed else hm_flat
        cands, _, _ = self.localmax.frame(zi, s.threshold, s.neighbourhood, self.max_touches)
        blobs = []
        if self.blobs:
            from . import blob as _blobs
            # finger removal after the contact limit, by every blob (also those beyond
            # the MAX_BLOBS reported); events for the first MAX_BLOBS blobs only
            cands, blobs = _blobs.split_touches(zi, cands, s.blob_threshold, s.blob_min_cells)
            blobs = blobs[:MAX_BLOBS]
        if self.fixed:
            tps = _interp.interp_frame_fixed(cands, self.cfg, self.moore, s.bias_correction, frame)
            return [_touch_from_fixed(t) for t in tps], blobs
        fc = []
        for c in cands:
            fc.append(_localmax.Candidate(c.row, c.col, _float3x3(hm_flat, c.row, c.col),
                                          c.missing))
        tps = _interp.interp_frame_float(fc, self.cfg, self.moore, s.bias_correction, frame)
        return [_touch_from_float(t) for t in tps], blobs

    def flatten(self, heatmaps):
        if self.fixed:
            out, _ = _flatten.flatten_fixed(np.asarray(heatmaps, dtype=np.int64), self.offset,
                                            self.gain, self.cfg)
            return out
        return _flatten.flatten_float(heatmaps, self.offset, self.gain, self.cfg)

    def run(self, heatmaps, first_frame: int = 0,
            frame_settings=None) -> list[list[TouchEvent]]:
        """``frame_settings``: one TouchSettings per frame (or None: keep the current)."""
        flat = self.flatten(heatmaps)          # vectorised over the frames
        if frame_settings is not None and len(frame_settings) != flat.shape[0]:
            raise ValueError(f"frame_settings: {len(frame_settings)} entries for "
                             f"{flat.shape[0]} frames")
        out = []
        for k in range(flat.shape[0]):
            fr = (first_frame + k) & 0xFFFF
            if frame_settings is not None and frame_settings[k] is not None:
                self.set_frame_settings(frame_settings[k])
            ts, blobs = self.touches(flat[k], fr)
            evs = self.tracker.step(fr, ts)
            for b in blobs:                    # one 'blob' event per reported blob
                evs.append(TouchEvent(fr, 0xFF, "blob", b.cx_q, b.cy_q, b.peak))
            out.append(evs)
        return out


def process_frames(heatmaps, cfg: SensorConfig, settings: TouchSettings | None = None,
                   fixed: bool = True, flatten_cal=None, frame_period_s: float | None = None,
                   first_frame: int = 0, blobs: bool | None = None,
                   frame_settings=None) -> list[list[TouchEvent]]:
    """Heat maps (frames, rows, cols) -> list (per frame) of TouchEvent lists.

    ``flatten_cal`` = (offset, gain) arrays (default: identity).  ``frame_period_s``
    converts the tracking settings (default one window, M = 1).  ``blobs=True`` (default:
    ``settings.blobs``) adds the blob stage: maxima (after the contact limit) inside any blob are not fingers, and
    the first MAX_BLOBS = 8 blobs (largest first, ``blobs.blob_stream_fixed`` order)
    give 'blob' events (type 3, id 0xFF, x/y = centroid Q8.8, strength = peak, other
    fields 0) after the tracker's events.  With ``fixed=True`` the events are
    bit-exact with ``rtl/fmt_touch.v`` (per frame, in the RTL's order; blob_en_i =
    blobs, blob_threshold >= 1).

    ``frame_settings``: settings that change during the run, one TouchSettings per frame
    (each with its own ``blobs``; ``blobs`` must then be None): the RTL gives every frame
    the settings present when its first heat-map row enters fmt_touch."""
    hm = np.asarray(heatmaps)
    if hm.ndim == 2:
        hm = hm[None]
    if frame_settings is not None and blobs is not None:
        raise ValueError("process_frames: blobs comes from frame_settings; pass blobs=None")
    p = TouchPipeline(cfg, settings, fixed, flatten_cal, frame_period_s, blobs=blobs)
    return p.run(hm, first_frame, frame_settings)
