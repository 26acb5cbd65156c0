"""Scenes: contacts moving over the sensor, effects of the channel, and the truth.

A scene is a :class:`Scene` object and a JSON (or YAML) file with the same fields::

    {"name": "demo", "sensor": "default", "frames": 300, "m": 1, "seed": 1,
     "effects": {"noise": {"snr_db": 30}, "pn": {"enable": true, "chip_len": 1}},
     "contacts": [
        {"name": "still", "diameter_mm": 8, "path": [[0, 52.3, 41.7]]},
        {"name": "drag", "path": [[0, 20, 20], [0.0018, 24, 22]]},
        {"name": "tap", "path": [[0, 100, 30]], "active": [[1e-4, 3e-4]]},
        {"name": "taps", "path": [[0, 60, 100]],
         "active": {"repeat": {"first_s": 5e-5, "period_s": 2.5e-4, "on_s": 1.2e-4,
                               "count": 6, "step_samples": 37}}},
        {"name": "thumb", "diameter_mm": 14, "minor_diameter_mm": 9, "angle_deg": 30,
         "profile": "gaussian", "strength": 0.8, "path": [[0, 80, 70]]}]}

Time: sample n of the ADC stream is at t = n / fs; frame f is windows f*M .. f*M+M-1,
samples [f*M*N, (f+1)*M*N); its centre time is (f + 1/2) M N / fs.

Contacts
  ``path``: waypoints ``[t_s, x_mm, y_mm]`` (x = column, y = row, mm from the centre of
  cell (0, 0)); the position is linearly interpolated between waypoints and held before
  the first / after the last.  One waypoint = stationary; two = a linear drag; pinches and
  crossings are two contacts with two waypoints each; any path is a list of waypoints.
  ``active``: absent = touching the whole time; a list of ``[onset, lift]`` intervals
  (lift ``null`` = never lifts) in seconds, or in samples with ``"active_units":
  "samples"``; or ``{"repeat": {...}}`` = ``count`` taps, tap i touching from
  ``first + i*period`` (+ ``i*step_samples`` samples, to spread the onsets over the
  window phase) for ``on_s``.  An interval [on, off) in seconds touches samples
  n with round(on * fs) <= n < round(off * fs): the onset falls on that exact sample,
  anywhere inside a window (``onset_samples`` lists them).
  ``diameter_mm`` (8 = the default finger), ``strength`` (1), ``profile`` ("disk" or
  "gaussian"), optional ``minor_diameter_mm`` and ``angle_deg`` (elliptical contact).
  ``size_path``: optional ``[[t_s, strength, diameter_mm], ...]``, strength and diameter
  over time (a finger landing: strength 0.2 -> 1 and 5 -> 8 mm over a few ms; a palm
  growing), linearly interpolated like the path and held before the first / after the
  last point; it replaces ``strength`` and ``diameter_mm`` (an ellipse keeps its minor /
  major ratio).  Only the coupling changes: the float model evaluates the map at every
  window boundary (linear in between), the RTL plan holds it per window.

Effects (every one costs nothing when absent)
  ``noise``: ``{"snr_db": s}`` (white Gaussian ADC noise set from the model so that a
  default finger centred on a cell gives s dB at M = 1; see
  :func:`fmt.channel.noise_sigma_for_snr`) or ``{"rms_lsb": sigma}``.
  ``enob``: effective bits (the low ADC_BITS - enob bits of every sample are cleared).
  ``dc_lsb``: DC offset added before quantisation.  ``interferer``: ``{"freq_hz": f}`` or
  ``{"bin": b}`` (fractional bins allowed; 0 .. Nyquist), ``"amp_lsb"``, ``"phase_rad"``;
  a list of them is allowed.  Optional per interferer: ``"sweep_hz_per_s"`` (a linear
  chirp: the frequency is f + sweep * t, t = n / fs from ADC sample 0; it aliases at the
  ADC like any tone once it leaves 0 .. Nyquist; |sweep| <= fs^2 / 4) and ``"burst":
  {"period_s": P, "on_s": D, "start_s": S}`` (the interferer is present on samples n >=
  round(S fs) with (n - round(S fs)) mod round(P fs) < round(D fs); S defaults to 0; the
  oscillator runs on while gated off, so each burst continues its phase).
  ``display``: display noise on every column, ``{"line_hz": f, "harmonics": [[h, amp_lsb],
  [h, amp_lsb, phase_rad], ...]}``: a sine of amp_lsb at h * f for each listed harmonic h
  (a whole number >= 1; h * f must not exceed Nyquist), e.g. a 60 kHz line rate's
  harmonics inside the tone band.  ``charger``: charger / common-mode noise that couples
  only through touching contacts, ``{"freq_hz": f0, "level": x, "harmonics": "square"}``
  (a square wave of peak amplitude x times a finger's tone, ``channel.finger_tone_lsb``,
  with all its odd harmonics, aliased above Nyquist) or ``"harmonics": [[h, a], ...]``
  (sines of x * a finger tones at h * f0, each below Nyquist); column c receives it
  multiplied by ``channel.charger_column_weights``: the touching contacts' coupling summed
  over the column's rows relative to a default finger centred on a cell (1 on that
  finger's column, 0 when nothing touches; it follows contacts as they move, land and
  lift).  Interferers, display and charger harmonics together: at most
  ``channel.IF_MAX`` (64) for the RTL path.
  ``drift``: a baseline that drifts, ``{"gain_pct_per_s": g, "offset_pct_per_s": o}``:
  each cell's coupling becomes G(t) (1 + a t) + G_untouched b t, with per-cell rates a
  uniform in +-g %/s and b uniform in +-o %/s, drawn once from the scene's seed
  (``channel.drift_rates``); applied at every window boundary (linear in between), so it
  reaches the RTL through the coupling plan (whose integer matrices change once the drift
  is larger than their quantum, about 0.3 % of the untouched coupling).
  ``row_db_per_cell``, ``col_db_per_cell``: electrode attenuation.
  ``baseline``: untouched coupling (default ``sensor.BASELINE``).  ``fringe_mm``: the
  disk profile's Gaussian fringe.  ``delay_samples``: channel delay.  ``pn``:
  ``{"enable": bool, "chip_len": L, "rx_delay": d}`` (rx_delay defaults to the channel
  delay: matched).  ``tone_phases``: "zero" (the DDS: every row starts at phase 0, a
  sine) or "schroeder" (low crest factor).  Clipping at the ADC range is always modelled.

Settings: ``settings``, an object of touch settings (the fields of
fmt.settings.TouchSettings, e.g. ``{"threshold": 1500, "blobs": true}``; those left out
keep their defaults), used by ``fmt.run_sim`` and ``bench.core.run_sim_rtl`` unless
``--settings FILE`` is given.

The DEFAULT PHYSICS: a finger is an 8 mm disk-profile contact of strength 1; the ADC
noise is white Gaussian, set so that a finger centred on a cell gives 30 dB SNR (peak
cell's noiseless heat-map value over the RMS noise of that cell) in one 6.144 us window
(M = 1); each doubling of M adds 3 dB.  ``default_physics_effects()`` returns that.
"""
from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import params as _params
from .params import SensorConfig

FINGER_MM = 8.0
DEFAULT_SNR_DB = 30.0


def default_physics_effects() -> dict:
    """Effects of the default physics: 30 dB SNR noise (clipping is always on)."""
    return {"noise": {"snr_db": DEFAULT_SNR_DB}}


@dataclass
class Contact:
    """One contact (see the module docstring for the fields)."""

    path: list                      # [[t_s, x_mm, y_mm], ...]
    name: str = ""
    diameter_mm: float = FINGER_MM
    strength: float = 1.0
    profile: str = "disk"
    minor_diameter_mm: float | None = None
    angle_deg: float = 0.0
    active: object = None           # None, [[on, off], ...] or {"repeat": {...}}
    active_units: str = "s"         # "s" or "samples"
    size_path: list | None = None   # [[t_s, strength, diameter_mm], ...] (a landing finger, a palm growing)

    def __post_init__(self):
        p = np.asarray(self.path, dtype=np.float64)
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 1:
            raise ValueError(f"contact '{self.name}': path must be [[t, x, y], ...]")
        if np.any(np.diff(p[:, 0]) < 0):
            raise ValueError(f"contact '{self.name}': waypoint times must not decrease")
        self._p = p
        if self.profile not in ("disk", "gaussian"):
            raise ValueError(f"contact '{self.name}': unknown profile '{self.profile}'")
        self._s = None
        if self.size_path is not None:
            q = np.asarray(self.size_path, dtype=np.float64)
            if q.ndim != 2 or q.shape[1] != 3 or q.shape[0] < 1:
                raise ValueError(f"contact '{self.name}': size_path must be [[t_s, strength, diameter_mm], ...]")
            if np.any(np.diff(q[:, 0]) < 0):
                raise ValueError(f"contact '{self.name}': size_path times must not decrease")
            if np.any(q[:, 1] < 0) or np.any(q[:, 2] <= 0):
                raise ValueError(f"contact '{self.name}': size_path needs strength >= 0 and diameter_mm > 0")
            self._s = q

    # -- geometry ---------------------------------------------------------------------
    @property
    def stationary(self) -> bool:
        """True when every waypoint is at the same position."""
        return bool(np.all(self._p[:, 1:] == self._p[0, 1:]))

    @property
    def fixed(self) -> bool:
        """True when the contact's map never changes: stationary, constant size and strength."""
        return self.stationary and (self._s is None or bool(np.all(self._s[:, 1:] == self._s[0, 1:])))

    @property
    def elliptical(self) -> bool:
        return self.minor_diameter_mm is not None

    def size(self, t) -> tuple:
        """(strength, diameter_mm) at time(s) t (seconds): ``size_path`` linearly
        interpolated (held before the first / after the last point), else the constants."""
        t = np.asarray(t, dtype=np.float64)
        if self._s is None:
            return np.full(t.shape, self.strength), np.full(t.shape, self.diameter_mm)
        q = self._s
        return np.interp(t, q[:, 0], q[:, 1]), np.interp(t, q[:, 0], q[:, 2])

    def shape_row(self) -> tuple:
        """(diameter, strength, minor_diameter, angle_rad) for ``sensor.contact_maps``
        (at time 0 for a contact with a ``size_path``)."""
        return tuple(self.shape_rows(np.zeros(1))[0])

    def shape_rows(self, t) -> np.ndarray:
        """(len(t), 4) shape rows at times t: with a ``size_path`` the diameter and
        strength follow it and the minor diameter keeps its ratio to the diameter."""
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        st, d = self.size(t)
        ratio = 1.0 if self.minor_diameter_mm is None else self.minor_diameter_mm / self.diameter_mm
        return np.column_stack([d, st, d * ratio, np.full(t.shape, math.radians(self.angle_deg))])

    def position(self, t) -> np.ndarray:
        """(..., 2) x, y in mm at time(s) t (seconds)."""
        t = np.asarray(t, dtype=np.float64)
        p = self._p
        if p.shape[0] == 1:
            return np.broadcast_to(p[0, 1:], t.shape + (2,)).copy()
        x = np.interp(t, p[:, 0], p[:, 1])
        y = np.interp(t, p[:, 0], p[:, 2])
        return np.stack([x, y], axis=-1)

    # -- activity -----------------------------------------------------------------------
    def intervals_samples(self, fs: float) -> np.ndarray:
        """Touching intervals as int64 (K, 2) sample indices [onset, lift); lift = 2**62
        for "never lifts"; an always-touching contact gives [[-2**62, 2**62]]."""
        BIG = 1 << 62
        a = self.active
        if a is None:
            return np.array([[-BIG, BIG]], dtype=np.int64)
        scale = 1.0 if self.active_units == "samples" else fs
        if isinstance(a, dict):
            r = a["repeat"]
            out = []
            for i in range(int(r["count"])):
                on = round((r["first_s"] + i * r["period_s"]) * fs) + i * int(r.get("step_samples", 0))
                out.append([on, on + round(r["on_s"] * fs)])
            return np.array(out, dtype=np.int64).reshape(-1, 2)
        out = []
        for on, off in a:
            on_n = round(on * scale)
            off_n = BIG if off is None else round(off * scale)
            out.append([on_n, off_n])
        return np.array(out, dtype=np.int64).reshape(-1, 2)

    def active_mask(self, n0: int, n1: int, fs: float) -> np.ndarray:
        """bool mask of samples n0 .. n1-1 where the contact touches."""
        n = np.arange(n0, n1, dtype=np.int64)
        m = np.zeros(n.size, dtype=bool)
        for on, off in self.intervals_samples(fs):
            m |= (n >= on) & (n < off)
        return m

    def active_fraction(self, edges: np.ndarray, fs: float) -> np.ndarray:
        """Fraction of samples touching in each span [edges[i], edges[i+1])."""
        edges = np.asarray(edges, dtype=np.int64)
        cover = np.zeros(edges.size - 1, dtype=np.float64)
        lo, hi = edges[:-1], edges[1:]
        for on, off in self.intervals_samples(fs):
            cover += np.clip(np.minimum(hi, off) - np.maximum(lo, on), 0, None)
        return cover / (hi - lo)

    def to_dict(self) -> dict:
        d = {"name": self.name, "diameter_mm": self.diameter_mm, "strength": self.strength,
             "profile": self.profile, "path": [list(map(float, w)) for w in self._p]}
        if self.minor_diameter_mm is not None:
            d["minor_diameter_mm"] = self.minor_diameter_mm
            d["angle_deg"] = self.angle_deg
        if self.active is not None:
            d["active"] = self.active
            if self.active_units != "s":
                d["active_units"] = self.active_units
        if self.size_path is not None:
            d["size_path"] = [list(map(float, w)) for w in self._s]
        return d


@dataclass
class Scene:
    """A scene: sensor, length, M, contacts, effects (see the module docstring)."""

    name: str = "scene"
    sensor: str = "default"
    frames: int = 100
    m: int = 1
    contacts: list = field(default_factory=list)
    effects: dict = field(default_factory=dict)
    seed: int = 1
    duration_s: float | None = None   # alternative to frames (rounded up to whole frames)
    description: str = ""
    settings: dict = field(default_factory=dict)   # touch settings (fmt.settings.TouchSettings fields)
    cfg_override: SensorConfig | None = field(default=None, repr=False)  # not saved

    def with_cfg(self, cfg: SensorConfig | None) -> "Scene":
        """A copy that runs on ``cfg`` instead of the named sensor (e.g. a build with other
        ADC or heat-map widths); ``None`` returns the scene itself."""
        if cfg is None or cfg is self.cfg:
            return self
        out = self.replace()
        out.cfg_override = cfg
        return out

    def __post_init__(self):
        self.contacts = [c if isinstance(c, Contact) else Contact(**c) for c in self.contacts]
        if self.m < 1:
            raise ValueError("m (windows per frame) must be >= 1")
        if self.duration_s is not None:
            fr = self.cfg.n_fft * self.m / self.cfg.fs_hz
            self.frames = int(math.ceil(self.duration_s / fr - 1e-9))
        unknown = set(self.effects) - EFFECT_KEYS
        if unknown:
            raise ValueError(f"scene '{self.name}': unknown effects {sorted(unknown)}")
        self.settings = dict(self.settings or {})
        dr = self.effects.get("drift")
        if dr is not None:
            if not isinstance(dr, dict) or set(dr) - {"gain_pct_per_s", "offset_pct_per_s"}:
                raise ValueError(f"effect drift: must be {{\"gain_pct_per_s\": g, \"offset_pct_per_s\": o}}, got {dr!r}")
            for k, v in dr.items():
                if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0 <= v <= 1e6:
                    raise ValueError(f"effect drift: {k} must be a number 0 .. 1e6 (% per second), got {v!r}")
        if any(k in self.effects for k in ("interferer", "display", "charger")):
            from .channel import oscillators
            oscillators(self)          # ValueError (one line naming the field) for a bad value

    def touch_settings(self):
        """The scene's touch settings (``settings`` key; defaults for the fields it leaves
        out), as fmt.settings.TouchSettings."""
        from .settings import TouchSettings
        return TouchSettings.from_dict(self.settings, f"scene '{self.name}': key 'settings'")

    # -- sizes and times ------------------------------------------------------------------
    @property
    def cfg(self) -> SensorConfig:
        if self.cfg_override is not None:
            return self.cfg_override
        return _params.get(self.sensor)

    @property
    def samples_per_frame(self) -> int:
        return self.cfg.n_fft * self.m

    @property
    def n_samples(self) -> int:
        return self.frames * self.samples_per_frame

    @property
    def frame_period_s(self) -> float:
        return self.samples_per_frame / self.cfg.fs_hz

    def frame_centre_s(self, frames=None) -> np.ndarray:
        f = np.arange(self.frames) if frames is None else np.asarray(frames)
        return (f + 0.5) * self.frame_period_s

    def onset_samples(self) -> dict:
        """{contact name or index: [onset samples]} of contacts that tap."""
        fs = self.cfg.fs_hz
        out = {}
        for i, c in enumerate(self.contacts):
            if c.active is not None:
                iv = c.intervals_samples(fs)
                out[c.name or str(i)] = [int(v) for v in iv[:, 0]]
        return out

    # -- truth --------------------------------------------------------------------------
    def truth(self, t) -> list:
        """True contacts touching at time t (seconds): a list of dicts with ``index``,
        ``name``, ``x_mm``, ``y_mm``, ``diameter_mm``, ``x_cells``, ``y_cells`` and
        ``edge_mm`` (distance of the centre from the nearest sensor edge)."""
        cfg = self.cfg
        n = int(round(t * cfg.fs_hz))
        out = []
        for i, c in enumerate(self.contacts):
            if not c.active_mask(n, n + 1, cfg.fs_hz)[0]:
                continue
            x, y = c.position(t)
            out.append({"index": i, "name": c.name, "x_mm": float(x), "y_mm": float(y),
                        "diameter_mm": float(c.size(t)[1]), "x_cells": float(x / cfg.pitch_mm),
                        "y_cells": float(y / cfg.pitch_mm),
                        "edge_mm": float(edge_distance_mm(cfg, x, y))})
        return out

    def truth_frames(self) -> list:
        """``truth`` at every frame's centre time."""
        return [self.truth(t) for t in self.frame_centre_s()]

    # -- I/O ------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        d = {"name": self.name, "description": self.description, "sensor": self.sensor,
             "frames": self.frames, "m": self.m, "seed": self.seed,
             "effects": copy.deepcopy(self.effects),
             "contacts": [c.to_dict() for c in self.contacts]}
        if self.settings:
            d["settings"] = copy.deepcopy(self.settings)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "Scene":
        d = dict(d)
        return cls(**d)

    def save(self, path) -> None:
        path = Path(path)
        if path.suffix in (".yaml", ".yml"):
            import yaml
            path.write_text(yaml.safe_dump(self.to_dict(), sort_keys=False))
        else:
            path.write_text(json.dumps(self.to_dict(), indent=1) + "\n")

    def replace(self, **kw) -> "Scene":
        d = self.to_dict()
        d.update(kw)
        out = Scene.from_dict(d)
        out.cfg_override = self.cfg_override
        return out


EFFECT_KEYS = {"noise", "enob", "dc_lsb", "interferer", "row_db_per_cell", "col_db_per_cell",
               "baseline", "fringe_mm", "delay_samples", "pn", "tone_phases", "display", "charger",
               "drift"}


def edge_distance_mm(cfg: SensorConfig, x, y):
    """Distance of (x, y) from the nearest sensor edge (the sensor spans -pitch/2 ..
    cols*pitch - pitch/2 in x, likewise in y)."""
    p = cfg.pitch_mm
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    return np.minimum.reduce([x + p / 2, (cfg.cols - 0.5) * p - x, y + p / 2,
                              (cfg.rows - 0.5) * p - y])


def check_dict(d, where: str = "scene") -> None:
    """Check a scene object before building it: unknown keys, wrong types and values out of
    range raise fmt.inputs.InputError with one line naming the key (contacts by index)."""
    from . import inputs as I
    I.check_fields(d, {
        "name": I.is_str(), "description": I.is_str(), "sensor": I.is_str(tuple(_params.CONFIGS)),
        "frames": I.is_int(1, 10**8), "m": I.is_int(1, 255), "seed": I.is_int(0, 2**63 - 1),
        "duration_s": I.is_num(0, 3600, lo_open=True, none_ok=True),
        "effects": I.is_type(dict, name="an object"), "contacts": I.is_type(list, name="a list"),
        "settings": I.is_type(dict, name="an object")}, where)
    if "settings" in d:
        from .settings import TouchSettings
        TouchSettings.from_dict(d["settings"], f"{where}: key 'settings'")
    unknown = set(d.get("effects", {})) - EFFECT_KEYS
    if unknown:
        raise I.InputError(f"{where}: key 'effects': unknown effects {sorted(unknown)} "
                           f"(known: {', '.join(sorted(EFFECT_KEYS))})")
    for i, c in enumerate(d.get("contacts", [])):
        cw = f"{where}: contacts[{i}]"
        I.check_fields(c, {
            "path": I.is_type(list, name="[[t_s, x_mm, y_mm], ...]"), "name": I.is_str(),
            "diameter_mm": I.is_num(0, 1e4, lo_open=True), "strength": I.is_num(0, 100),
            "profile": I.is_str(("disk", "gaussian")),
            "minor_diameter_mm": I.is_num(0, 1e4, lo_open=True, none_ok=True),
            "angle_deg": I.is_num(-360, 360),
            "active": lambda v: None if v is None or isinstance(v, (list, dict)) else
            "must be null, [[on, off], ...] or {\"repeat\": {...}}",
            "active_units": I.is_str(("s", "samples")),
            "size_path": I.is_type(list, name="[[t_s, strength, diameter_mm], ...]")}, cw)
        for j, w in enumerate(c.get("size_path") or []):
            if (not isinstance(w, list) or len(w) != 3 or any(I.is_num()(x) for x in w)
                    or w[1] < 0 or w[2] <= 0):
                raise I.InputError(f"{cw}: key 'size_path': point {j} must be [t_s, strength >= 0, "
                                   f"diameter_mm > 0] numbers, got {w!r}")
        _check_active(c.get("active"), cw, I)
        if "path" not in c:
            raise I.InputError(f"{cw}: key 'path' missing")
        for j, w in enumerate(c["path"]):
            if (not isinstance(w, list) or len(w) != 3
                    or any(I.is_num()(x) for x in w)):
                raise I.InputError(f"{cw}: key 'path': waypoint {j} must be [t_s, x_mm, y_mm] "
                                   f"numbers, got {w!r}")


def _check_active(a, where: str, I) -> None:
    """``active``: null, [[on, off or null], ...] or {"repeat": {count, first_s, period_s,
    on_s[, step_samples]}}."""
    if a is None:
        return
    if isinstance(a, dict):
        if set(a) != {"repeat"}:
            raise I.InputError(f"{where}: key 'active': an object must be {{\"repeat\": {{...}}}}, got {a!r}")
        I.check_fields(a["repeat"], {"count": I.is_int(0, 10**6), "first_s": I.is_num(-1e6, 1e6),
                                     "period_s": I.is_num(0, 1e6), "on_s": I.is_num(0, 1e6),
                                     "step_samples": I.is_int(-10**9, 10**9)}, f"{where}: key 'active.repeat'")
        missing = {"count", "first_s", "period_s", "on_s"} - set(a["repeat"])
        if missing:
            raise I.InputError(f"{where}: key 'active.repeat': missing {sorted(missing)}")
        return
    for j, iv in enumerate(a):
        # bounded so that the sample indices fit int64 (seconds or samples)
        if (not isinstance(iv, list) or len(iv) != 2 or I.is_num(-1e9, 1e9)(iv[0])
                or I.is_num(-1e9, 1e9, none_ok=True)(iv[1])):
            raise I.InputError(f"{where}: key 'active': interval {j} must be [on, off or null] "
                               f"numbers within +-1e9, got {iv!r}")


def load(path) -> Scene:
    """Load a scene from a .json or .yaml file.  Every problem (missing file, bad syntax,
    unknown key, wrong type, value out of range) raises fmt.inputs.InputError with one
    line that names the file and the key."""
    from .inputs import InputError, one_line
    path = Path(path)
    where = f"scene {path}"
    try:
        text = path.read_text()
    except OSError as e:
        raise InputError(f"{where}: {one_line(e)}") from None
    try:
        if path.suffix in (".yaml", ".yml"):
            import yaml
            d = yaml.safe_load(text)
        else:
            d = json.loads(text)
    except Exception as e:  # noqa: BLE001 -- json / yaml syntax errors
        raise InputError(f"{where}: not valid {'YAML' if path.suffix in ('.yaml', '.yml') else 'JSON'} "
                         f"({one_line(e)})") from None
    check_dict(d, where)
    try:
        return Scene.from_dict(d)
    except InputError:
        raise
    except (TypeError, ValueError, KeyError) as e:
        raise InputError(f"{where}: {one_line(e)}") from None


# ---- the scenes shipped in sim/scenes/ ----------------------------------------------------
SCENES_DIR = Path(__file__).resolve().parents[1] / "scenes"


def default_scene() -> Scene:
    """The ``make sim`` scene on the 30 x 40 sensor (sim/scenes/default.json)."""
    cfg = _params.DEFAULT
    fs, N = cfg.fs_hz, cfg.n_fft
    frames = 360
    T = frames * N / fs
    # taps: 15 frames (92 us) down, 45 frames (276 us, longer than the tracker's 200 us
    # hold-off) up; onsets 43 samples later in the window each time (0 .. 215)
    taps = {"repeat": {"first_s": 20 * N / fs, "period_s": 60 * N / fs, "on_s": 15 * N / fs,
                       "count": 6, "step_samples": 43}}
    return Scene(
        name="default", sensor="default", frames=frames, m=1, seed=1,
        description=("stationary finger (jitter), stationary finger 2.0 mm from the left edge, "
                     "a fast drag (5.4 mm in 2.2 ms, 2.4 m/s), and 6 taps whose onsets step 43 "
                     "samples through the window phase; default physics (8 mm disk, 30 dB "
                     "SNR, PN on, chip length 1)"),
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1}},
        contacts=[
            Contact(name="still", path=[[0.0, 61.3, 43.8]]),
            Contact(name="edge", path=[[0.0, -0.5, 112.0]]),
            Contact(name="drag", path=[[0.0, 110.0, 20.0], [T, 115.0, 22.0]]),
            Contact(name="taps", path=[[0.0, 150.0, 120.0]], active=taps),
        ])


def small_scene() -> Scene:
    """A few frames on the 4 x 6 sensor for fast tests (sim/scenes/small.json)."""
    cfg = _params.SMALL
    fs, N = cfg.fs_hz, cfg.n_fft
    frames = 40
    T = frames * N / fs
    return Scene(
        name="small", sensor="small", frames=frames, m=1, seed=2,
        description="one stationary finger and one short drag on the 4 x 6 sensor",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1}},
        contacts=[
            Contact(name="still", path=[[0.0, 6.3, 6.9]]),
            Contact(name="drag", path=[[0.0, 19.0, 8.0], [T, 21.0, 9.0]],
                    active=[[5 * N / fs + 17 / fs, None]]),
        ])


def _frames_s(cfg, frames):
    return frames * cfg.n_fft / cfg.fs_hz


def hard_clip_scene() -> Scene:
    """Hard case: a palm (40 mm) and a strip touching all rows of column 30 drive the ADC
    into clipping (reported), next to an ordinary finger."""
    cfg = _params.DEFAULT
    return Scene(
        name="hard_clip", sensor="default", frames=60, seed=3,
        description="palm + all rows touched on one column (ADC clipping) + one finger",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1}},
        contacts=[
            Contact(name="finger", path=[[0.0, 40.0, 40.0]]),
            Contact(name="palm", diameter_mm=40.0, path=[[0.0, 90.0, 100.0]],
                    active=[[_frames_s(cfg, 20), None]]),
            Contact(name="strip", diameter_mm=400.0, minor_diameter_mm=6.0, angle_deg=90.0,
                    path=[[0.0, 150.0, 72.5]], active=[[_frames_s(cfg, 40), None]]),
        ])


def interferer_scene() -> Scene:
    """Hard case: interfering tones on a row bin and between two bins, PN spreading on."""
    cfg = _params.DEFAULT
    return Scene(
        name="interferer", sensor="default", frames=100, seed=4,
        description="two fingers; an interferer of 200 LSB on row 10's bin and one of "
                    "200 LSB between rows 20 and 21, spread by PN (chip length 1)",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1},
                 "interferer": [{"bin": cfg.bins[10], "amp_lsb": 200.0},
                                {"bin": cfg.bins[20] + 0.5, "amp_lsb": 200.0}]},
        contacts=[Contact(name="a", path=[[0.0, 50.0, 50.0]]),
                  Contact(name="b", path=[[0.0, 140.0, 102.0]])])


def pinch_scene() -> Scene:
    """Two fingers closing from 40 mm to 16 mm centre distance (8 mm edge to edge, the
    separation that must still be resolved) at 1.2 m/s each, and two fingers crossing
    at 4 m/s each (they merge for ~2 ms and must keep their IDs), over 9.8 ms."""
    cfg = _params.DEFAULT
    frames = 1600
    T = _frames_s(cfg, frames)
    return Scene(
        name="pinch", sensor="default", frames=frames, seed=5,
        description="pinch to 8 mm edge-to-edge; two fingers crossing at 4 m/s each",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1}},
        contacts=[
            Contact(name="p1", path=[[0.0, 40.0, 50.0], [T, 52.0, 50.0]]),
            Contact(name="p2", path=[[0.0, 80.0, 50.0], [T, 68.0, 50.0]]),
            Contact(name="x1", path=[[0.0, 120.0, 100.0], [T, 160.0, 110.0]]),
            Contact(name="x2", path=[[0.0, 160.0, 100.0], [T, 120.0, 110.0]]),
        ])


def thumb_scene() -> Scene:
    """An elliptical Gaussian-profile contact (a thumb) for the Moore ellipse and angle,
    a rotating-free second one with the disk profile and a fringe, and row/column
    attenuation for the field flattening."""
    return Scene(
        name="thumb", sensor="default", frames=50, seed=6,
        description="elliptical contacts (16 x 9 mm at 30 deg, Gaussian; 14 x 8 mm at "
                    "-60 deg, disk), 1.5 mm fringe, 0.05/0.08 dB per cell attenuation",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "fringe_mm": 1.5,
                 "row_db_per_cell": 0.05, "col_db_per_cell": 0.08},
        contacts=[
            Contact(name="thumb", profile="gaussian", diameter_mm=16.0, minor_diameter_mm=9.0,
                    angle_deg=30.0, strength=0.8, path=[[0.0, 62.0, 71.0]]),
            Contact(name="oval", diameter_mm=14.0, minor_diameter_mm=8.0, angle_deg=-60.0,
                    path=[[0.0, 141.0, 52.0]]),
        ])


def _alternating_taps(name: str, seed: int, frames: int, spacing_mm: float, b_first: int,
                      period: int, count: int, description: str) -> Scene:
    """Fingers A at (80, 70) mm and B spacing_mm to its right tap in turn: each 20 frames
    down every ``period`` frames, A from frame 10, B from frame ``b_first``; each tap's
    landing moves 31 (A) / 57 (B) samples further into its window."""
    cfg = _params.DEFAULT
    f = lambda k: _frames_s(cfg, k)
    tap = lambda first, step: {"repeat": {"first_s": f(first), "period_s": f(period), "on_s": f(20),
                                          "count": count, "step_samples": step}}
    return Scene(
        name=name, sensor="default", frames=frames, seed=seed, description=description,
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1}},
        contacts=[Contact(name="A", path=[[0.0, 80.0, 70.0]], active=tap(10, 31)),
                  Contact(name="B", path=[[0.0, 80.0 + spacing_mm, 70.0]], active=tap(b_first, 57))])


def drumroll_scene() -> Scene:
    """Fast alternating taps A B A B 20 mm apart (must not merge into one moving contact)."""
    return _alternating_taps("drumroll", 7, 240, 20.0, 50, 80, 3,
                             "alternating taps 20 mm apart: 20 frames down, 20 frames between taps")


def taps8_scene() -> Scene:
    """Fast alternating taps 8 mm apart, B landing in the frame A lifts (and back), every
    landing and lift inside a window: the transition frames that gave ghost contacts
    before the touch-down confirmation (issue #11 item 4)."""
    return _alternating_taps("taps8", 8, 200, 8.0, 30, 40, 4,
                             "alternating taps 8 mm apart, 20 frames each, B lands as A lifts")


# crowding above the contact limit (issue #11 item 3; scripts/crowding.py runs the cases)
LAND = 10               # frame of the first landing
LATE = 150              # frames after it that the extra finger lands (one_lands), or
                        # that the N fingers lift (relands; the others land 5 later)
RELAND = 5


def crowd_scene(case: str, n: int, seed: int, frames: int, snr_db: float = 30.0) -> Scene:
    """N fingers (or 2 N) on a jittered 20 mm grid of the default sensor, 7-10 mm, some
    drifting at up to 0.2 m/s, 30 dB, M = 1; ``case``: ``together`` (N + 1 land at
    frame LAND), ``one_lands`` (N at LAND, the largest and strongest LATE frames later),
    ``relands`` (N lift at LAND + LATE, N others land RELAND frames later, while the
    first are in hold-off)."""
    if case not in ("together", "one_lands", "relands"):
        raise ValueError(f"crowding: unknown case {case!r} (together, one_lands, relands)")
    cfg = _params.DEFAULT
    rng = np.random.default_rng(1000 * seed + n)
    w, h = cfg.cols * cfg.pitch_mm, cfg.rows * cfg.pitch_mm
    grid = [(x, y) for y in np.arange(15.0, h - 10.0, 20.0) for x in np.arange(15.0, w - 10.0, 20.0)]
    if len(grid) < n + 1:
        raise ValueError(f"crowding: {n + 1} fingers do not fit the {w:g} x {h:g} mm sensor")
    pick = rng.choice(len(grid), size=2 * n if case == "relands" else n + 1, replace=False)
    t_end = frames * cfg.window_s
    contacts = []
    for k, g in enumerate(pick):
        x0, y0 = grid[g][0] + rng.uniform(-3, 3), grid[g][1] + rng.uniform(-3, 3)
        late = case == "one_lands" and k == n
        vx, vy = (rng.uniform(-0.2, 0.2, 2) * 1e3) if k % 3 == 0 else (0.0, 0.0)   # mm/s
        t0 = (LAND + (LATE if late else 0)) * cfg.window_s + rng.uniform(0, cfg.window_s)
        t1 = t_end + 1.0
        if case == "relands":
            lift = (LAND + LATE) * cfg.window_s + rng.uniform(0, cfg.window_s)
            t0, t1 = ((t0, lift) if k < n else
                      ((LAND + LATE + RELAND) * cfg.window_s + rng.uniform(0, cfg.window_s), t1))
        contacts.append(Contact(
            name=f"F{k}", diameter_mm=10.0 if late else float(rng.uniform(7.0, 9.0)),
            strength=1.0 if late else float(rng.uniform(0.85, 1.0)),
            path=[[0.0, x0, y0], [t_end, x0 + vx * t_end, y0 + vy * t_end]],
            active=[[t0, t1]]))
    return Scene(name=f"crowd_{case}_{n}_{seed}", sensor="default", frames=frames, seed=seed,
                 effects={"noise": {"snr_db": snr_db}, "pn": {"enable": True, "chip_len": 1}},
                 contacts=contacts)


def crowd_scene_shipped() -> Scene:
    """Sixteen fingers (the default contact limit), then a seventeenth, larger and
    stronger than all, lands among them: the same 16 contacts in every frame."""
    return crowd_scene("one_lands", 16, 1, 200)


def noise_scene() -> Scene:
    """Realistic noise (issue #12 item 2) on the default sensor: a still finger and a
    finger landing at frame 60 (strength 0.2 -> 1, 5 -> 8 mm over 6 frames); charger
    noise at 0.5 finger tones (120 kHz square wave, only through the fingers), display
    noise (67.5 kHz line rate, three harmonics inside the tone band), a 100 LSB
    interferer sweeping up from 5 MHz at 2 GHz/s in 50 us bursts every 200 us, and a
    baseline drifting 1 %/s (gain and offset)."""
    cfg = _params.DEFAULT
    t_land = _frames_s(cfg, 60)
    return Scene(
        name="noise", sensor="default", frames=240, seed=9,
        description="still finger + a finger landing (size_path); charger 0.5 finger tones, display "
                    "harmonics, a sweeping bursty interferer, 1 %/s drift; 30 dB, PN on",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1},
                 "charger": {"freq_hz": 120e3, "level": 0.5},
                 "display": {"line_hz": 67.5e3, "harmonics": [[90, 30.0], [110, 20.0], [130, 15.0]]},
                 "interferer": [{"freq_hz": 5.0e6, "amp_lsb": 100.0, "sweep_hz_per_s": 2.0e9,
                                 "burst": {"period_s": 2.0e-4, "on_s": 5.0e-5, "start_s": 2.0e-5}}],
                 "drift": {"gain_pct_per_s": 1.0, "offset_pct_per_s": 1.0}},
        contacts=[
            Contact(name="still", path=[[0.0, 61.3, 43.8]]),
            Contact(name="landing", path=[[0.0, 140.0, 100.0]], active=[[t_land, None]],
                    size_path=[[t_land, 0.2, 5.0], [t_land + _frames_s(cfg, 6), 1.0, 8.0]]),
        ])


def noise_small_scene() -> Scene:
    """``noise_scene`` on the 4 x 6 sensor for fast tests: a finger landing at frame 5
    (size_path), charger noise at 1 finger tone, display harmonics, a sweeping bursty
    interferer and a fast drift (100 %/s, so that a short run shows it)."""
    cfg = _params.SMALL
    t_land = _frames_s(cfg, 5) + 21 / cfg.fs_hz
    return Scene(
        name="noise_small", sensor="small", frames=40, seed=10,
        description="a still finger + a finger landing; charger 1 finger tone, display harmonics, "
                    "a sweeping bursty interferer, 100 %/s drift; 30 dB, PN on",
        effects={"noise": {"snr_db": DEFAULT_SNR_DB}, "pn": {"enable": True, "chip_len": 1},
                 "charger": {"freq_hz": 95e3, "level": 1.0},
                 "display": {"line_hz": 65e3, "harmonics": [[95, 30.0], [105, 20.0]]},
                 "interferer": [{"freq_hz": 5.5e6, "amp_lsb": 80.0, "sweep_hz_per_s": 2.0e10,
                                 "burst": {"period_s": 2.0e-5, "on_s": 6.0e-6}}],
                 "drift": {"gain_pct_per_s": 100.0, "offset_pct_per_s": 100.0}},
        contacts=[
            Contact(name="still", path=[[0.0, 6.3, 6.9]]),
            Contact(name="landing", path=[[0.0, 19.0, 8.0]], active=[[t_land, None]],
                    size_path=[[t_land, 0.2, 5.0], [t_land + _frames_s(cfg, 3), 1.0, 8.0]]),
        ])


SHIPPED = {
    "default.json": default_scene, "small.json": small_scene, "small.yaml": small_scene,
    "hard_clip.json": hard_clip_scene, "interferer.json": interferer_scene,
    "pinch.json": pinch_scene, "thumb.yaml": thumb_scene, "drumroll.json": drumroll_scene,
    "taps8.json": taps8_scene, "crowd.json": crowd_scene_shipped,
    "noise.json": noise_scene, "noise_small.json": noise_small_scene,
}


def write_shipped(directory=SCENES_DIR) -> list:
    """Regenerate the scene files of sim/scenes/ (``SHIPPED``)."""
    directory = Path(directory)
    out = []
    for fn, make in SHIPPED.items():
        p = directory / fn
        make().save(p)
        out.append(p)
    return out


if __name__ == "__main__":
    for p in write_shipped():
        print(f"wrote {p}")
