"""The recording format of ``fmtctl record``: one ``.npz`` file (numpy, no pickles).

Arrays::

    meta            0-d unicode string: the JSON metadata below
    heatmaps        uint32 (K, rows, cols)  raw heat-map snapshots (HEATMAP window,
                                            before field flattening), in capture order
    heatmap_frame   int64 (K,)              the core's 16-bit frame number of each
                                            snapshot (SNAP_STATUS), -1 when unknown
    heatmap_host_s  float64 (K,)            host time of each snapshot, s from the start
    events          int64 (N, 12)           event records, columns = meta event_fields
                                            (type as its code 0 new, 1 move, 2 lift,
                                            3 blob; last 0 / 1)
    event_host_s    float64 (N,)            host time each event was read
    cal_offset, cal_gain  int64 (rows, cols) only with ``--with-cal``: the core's
                                            field-flattening calibration

Metadata (JSON): ``format`` "fmt-recording", ``version`` 1, ``created`` (UTC ISO 8601),
``source`` (the port, or what made it), ``info`` (the INFO reply), ``config`` (the
fmt.params sensor config of that size, or null), ``registers`` (name -> value of every
read-write register at the start), ``settings`` (fmt.settings.TouchSettings fields as
the registers give them), ``settings_exact`` (false when the tracking registers differ
from what those settings convert to: the model then needs the registers), ``report``
(snapshots, events, seconds), ``event_fields``, ``event_types``.

A UART recording is decimated (REPORT_PERIOD; snapshots are whole frames taken when
asked): it is not the board's own event stream.  Its heat maps are a sequence the model
(:meth:`Recording.model_events`) and the RTL (scripts/replay_touch.py --in FILE.npz)
process bit-exactly alike.
"""
from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .events import FIELDS, TYPE_CODES

FORMAT = "fmt-recording"
VERSION = 1
TYPE_NAMES = {v: k for k, v in TYPE_CODES.items()}


def config_for(info: dict):
    """The fmt.params sensor config with INFO's sizes, or None."""
    from fmt import params
    for name in ("default", "small", "medium"):
        cfg = params.get(name)
        if (cfg.rows, cfg.cols, cfg.n_fft) == (int(info["rows"]), int(info["cols"]), int(info["n_fft"])):
            return cfg
    return None


def settings_from_registers(regs: dict, cfg) -> tuple[dict, bool]:
    """(TouchSettings fields, exact) of a register dump (name -> value)."""
    from fmt.settings import TouchSettings
    from fmt.tracker import TrackParams
    mode = int(regs.get("TOUCH_MODE", 3))
    st = TouchSettings(threshold=int(regs.get("TOUCH_THRESHOLD", TouchSettings.threshold)),
                       neighbourhood="moore" if mode & 1 else "vn", bias_correction=bool(mode & 2),
                       blobs=bool(mode & 4),
                       max_touches=int(regs["CONTACT_LIMIT"]) if "CONTACT_LIMIT" in regs else None,
                       blob_threshold=int(regs.get("BLOB_THRESHOLD", TouchSettings.blob_threshold)),
                       blob_min_cells=int(regs.get("BLOB_MIN_CELLS", TouchSettings.blob_min_cells)),
                       on_threshold=int(regs.get("TOUCH_ON_THRESHOLD", TouchSettings.on_threshold)),
                       confirm_frames=min(7, max(1, int(regs.get("TRACK_CONFIRM",
                                                                 TouchSettings.confirm_frames)))))
    exact = False
    if cfg is not None:
        m = max(1, int(regs.get("WINDOWS_M", 1)))
        tp = TrackParams.from_settings(cfg, st, cfg.window_s * m)
        want = {"TRACK_MAX_JUMP": tp.max_jump_q, "TRACK_GATE_STEP": tp.gate_step_q,
                "TRACK_HOLD_OFF": tp.hold_off_frames, "TRACK_VEL_SHIFT": tp.vel_shift,
                "TRACK_MAX_SPEED": tp.max_speed_v}
        exact = all(int(regs.get(k, v)) == v for k, v in want.items())
    return st.as_dict(), exact


@dataclass
class Recording:
    meta: dict
    heatmaps: np.ndarray                    # (K, rows, cols)
    heatmap_frame: np.ndarray               # (K,)
    heatmap_host_s: np.ndarray              # (K,)
    events: list = field(default_factory=list)          # event records (dicts)
    event_host_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    cal: tuple | None = None                # (offset, gain) or None

    @property
    def rows(self) -> int:
        return int(self.meta["info"]["rows"])

    @property
    def cols(self) -> int:
        return int(self.meta["info"]["cols"])

    def config(self):
        from fmt import params
        return params.get(self.meta["config"]) if self.meta.get("config") else config_for(self.meta["info"])

    def settings(self):
        from fmt.settings import TouchSettings
        return TouchSettings(**self.meta["settings"])

    def model_events(self, flatten_cal=None):
        """The bit-exact model (fmt.touch.process_frames) on the recorded heat maps, one
        frame per window (M = WINDOWS_M of the registers): per snapshot a list of
        TouchEvent.  ``flatten_cal`` default: identity (what scripts/replay_touch.py does)."""
        from fmt.touch import process_frames
        cfg = self.config()
        if cfg is None:
            raise ValueError(f"no sensor config of {self.rows} x {self.cols} in fmt.params")
        m = max(1, int(self.meta.get("registers", {}).get("WINDOWS_M", 1)))
        return process_frames(self.heatmaps.astype(np.int64), cfg, self.settings(), fixed=True,
                              flatten_cal=flatten_cal, frame_period_s=cfg.window_s * m)

    def save(self, path) -> Path:
        path = Path(path)
        ev = np.array([[r[f] if f != "type" else TYPE_CODES[r[f]] for f in FIELDS] for r in self.events],
                      dtype=np.int64).reshape(-1, len(FIELDS))
        arrays = {"meta": np.array(json.dumps(self.meta, sort_keys=True)),
                  "heatmaps": np.asarray(self.heatmaps, dtype=np.uint32).reshape(-1, self.rows, self.cols),
                  "heatmap_frame": np.asarray(self.heatmap_frame, dtype=np.int64),
                  "heatmap_host_s": np.asarray(self.heatmap_host_s, dtype=np.float64),
                  "events": ev, "event_host_s": np.asarray(self.event_host_s, dtype=np.float64)}
        if self.cal is not None:
            arrays["cal_offset"] = np.asarray(self.cal[0], dtype=np.int64)
            arrays["cal_gain"] = np.asarray(self.cal[1], dtype=np.int64)
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "wb") as f:            # (np.savez would append .npz to another suffix)
            np.savez_compressed(f, **arrays)
        return path


def new_meta(info: dict, source: str, registers: dict) -> dict:
    cfg = config_for(info)
    settings, exact = settings_from_registers(registers, cfg)
    return {"format": FORMAT, "version": VERSION, "source": source,
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "info": info, "config": cfg.name if cfg is not None else None,
            "registers": registers, "settings": settings, "settings_exact": exact,
            "event_fields": list(FIELDS), "event_types": TYPE_NAMES}


def load(path) -> Recording:
    """Read a recording; ValueError with one line for anything else."""
    try:
        z = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: not a readable .npz file ({e})") from None
    with z:
        if "meta" not in z.files:
            raise ValueError(f"{path}: not an fmt recording (no 'meta' array)")
        meta = json.loads(str(z["meta"]))
        if meta.get("format") != FORMAT or int(meta.get("version", 0)) > VERSION:
            raise ValueError(f"{path}: format {meta.get('format')!r} version {meta.get('version')}, "
                             f"expected {FORMAT!r} <= {VERSION}")
        fields = meta["event_fields"]
        evs = []
        for row in z["events"]:
            r = dict(zip(fields, (int(v) for v in row)))
            r["type"] = TYPE_NAMES[r["type"]]
            r["last"] = bool(r["last"])
            evs.append(r)
        cal = (z["cal_offset"], z["cal_gain"]) if "cal_offset" in z.files else None
        return Recording(meta, z["heatmaps"].astype(np.int64), z["heatmap_frame"], z["heatmap_host_s"],
                         evs, z["event_host_s"], cal)
