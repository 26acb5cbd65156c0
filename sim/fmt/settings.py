"""Run-time settings of the touch processing, shared by the model blocks and the RTL
register defaults.  Tracking settings are physical (mm, mm/s, us) and converted once
into cell / frame units by :meth:`TouchSettings.converted`.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from .params import SensorConfig


@dataclass(frozen=True)
class TouchSettings:
    threshold: int = 2000          # coarse-touch threshold on the flattened heat map (counts)
    neighbourhood: str = "moore"   # "moore" (3x3, Eq. 5-6) or "vn" (Von Neumann, Eq. 3-4)
    max_touches: int | None = None # contact limit; None = the sensor config's max_touches
    on_threshold: int = 2500       # activation: a new contact needs a touch this strong (counts);
                                   # ``threshold`` is the deactivation threshold of a continuing one
    confirm_frames: int = 2        # a new contact is reported once seen in this many frames (1..7)
    bias_correction: bool = True   # sub-cell bias correction of the paraboloid fits
    # frame matching (physical units)
    position_noise_mm: float = 2.5 # allowance for position noise in the match gate (below)
    hold_off_us: float = 200.0     # a contact missing for less than this keeps its ID
    velocity_window_us: float = 2000.0  # time base of the velocity estimate
    max_speed_mm_s: float = 3000.0 # clamp of the predicted velocity
    # blobs (the paper's future work; defined in fmt.blob)
    blobs: bool = False            # blob detection on: fingers inside blobs dropped, blob events
    blob_threshold: int = 1000     # cells above this belong to a connected region
    blob_min_cells: int = 12       # a region of at least this many cells is a blob

    def replace(self, **kw) -> "TouchSettings":
        return replace(self, **kw)

    @classmethod
    def from_dict(cls, d, where: str = "settings") -> "TouchSettings":
        """Checked construction from a JSON/YAML object: an unknown key, a wrong type or a
        value out of range raises fmt.inputs.InputError naming the key."""
        from . import inputs as I
        I.check_fields(d, {
            "threshold": I.is_int(0, 65535), "neighbourhood": I.is_str(("moore", "vn")),
            "max_touches": I.is_int(1, 255, none_ok=True), "bias_correction": I.is_bool,
            "on_threshold": I.is_int(0, 65535), "confirm_frames": I.is_int(1, 7),
            "position_noise_mm": I.is_num(0), "hold_off_us": I.is_num(0),
            "velocity_window_us": I.is_num(0), "max_speed_mm_s": I.is_num(0),
            "blobs": I.is_bool, "blob_threshold": I.is_int(0, 65535),
            "blob_min_cells": I.is_int(1, 65535)}, where)
        return cls(**d)

    def as_dict(self) -> dict:
        return asdict(self)

    def converted(self, cfg: SensorConfig, frame_period_s: float) -> dict:
        """Tracking settings in cells (Q8.8 integers) and frames.

        The match gate is physical, in the tracker's L1 distance (|dx| + |dy|): in a
        frame of T s a finger moves at most v T (v = ``max_speed_mm_s``), sqrt(2) v T in
        L1, and its prediction moves by the estimated velocity, clamped to v per axis,
        at most 2 v T in L1; the position noise r adds at most sqrt(2) r.  So a finger
        seen last frame is within ``max_jump_q`` = ceil((2 + sqrt 2) v T + sqrt(2) r)
        of its prediction, and each further frame it is missed adds ``gate_step_q`` =
        ceil((2 + sqrt 2) v T), both in Q8.8 cells, rounded up (bounds), at most
        0xFFFF."""
        cell = cfg.pitch_mm
        q = 1 << cfg.frac_bits
        frames = lambda us: max(1, int(round(us * 1e-6 / frame_period_s)))
        step_l1 = (2.0 + math.sqrt(2.0)) * self.max_speed_mm_s * frame_period_s
        cells = lambda mm: min(0xFFFF, math.ceil(mm / cell * q - 1e-9))
        return {
            "max_jump_q": cells(step_l1 + math.sqrt(2.0) * self.position_noise_mm),
            "gate_step_q": cells(step_l1),
            "hold_off_frames": frames(self.hold_off_us),
            "velocity_window_frames": frames(self.velocity_window_us),
            "max_speed_q_per_frame": int(round(self.max_speed_mm_s * frame_period_s / cell * q)),
        }


def load(path) -> TouchSettings:
    """TouchSettings from a JSON file of its fields (checked: :meth:`TouchSettings.from_dict`);
    every problem raises fmt.inputs.InputError with one line naming the file and key."""
    from .inputs import InputError, one_line
    path = Path(path)
    try:
        d = json.loads(path.read_text())
    except OSError as e:
        raise InputError(f"settings {path}: {one_line(e)}") from None
    except ValueError as e:
        raise InputError(f"settings {path}: not valid JSON ({one_line(e)})") from None
    return TouchSettings.from_dict(d, where=f"settings {path}")
