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

        The match gate is physical: a finger moves at most ``max_speed_mm_s`` x T per
        frame of T s, and the prediction it is compared with (last position plus the
        estimated velocity, itself clamped to that speed) may be off by as much in the
        other direction, so after one frame a finger is within r1 = 2 v T +
        ``position_noise_mm`` of its prediction, and each further frame it is missed
        adds 2 v T.  The tracker's distance is L1 (|dx| + |dy| <= sqrt(2) r), so the
        gates are ``max_jump_q`` = ceil(sqrt(2) r1) and ``gate_step_q`` = ceil(sqrt(2)
        2 v T), in Q8.8 cells, rounded up (each is a bound), at most 0xFFFF."""
        cell = cfg.pitch_mm
        q = 1 << cfg.frac_bits
        frames = lambda us: max(1, int(round(us * 1e-6 / frame_period_s)))
        step_mm = 2.0 * self.max_speed_mm_s * frame_period_s
        l1 = lambda mm: min(0xFFFF, math.ceil(math.sqrt(2.0) * mm / cell * q - 1e-9))
        return {
            "max_jump_q": l1(step_mm + self.position_noise_mm),
            "gate_step_q": l1(step_mm),
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
