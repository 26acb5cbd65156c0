"""Run-time settings of the touch processing, shared by the model blocks and the RTL
register defaults.  Tracking settings are physical (mm, mm/s, us) and converted once
into cell / frame units by :meth:`TouchSettings.converted`.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, replace

from .params import SensorConfig


@dataclass(frozen=True)
class TouchSettings:
    threshold: int = 2000          # coarse-touch threshold on the flattened heat map (counts)
    neighbourhood: str = "moore"   # "moore" (3x3, Eq. 5-6) or "vn" (Von Neumann, Eq. 3-4)
    max_touches: int | None = None # contact limit; None = the sensor config's max_touches
    bias_correction: bool = True   # sub-cell bias correction of the paraboloid fits
    # frame matching (physical units)
    max_jump_mm: float = 15.0      # a contact farther than this from its prediction is new
    hold_off_us: float = 200.0     # a contact missing for less than this keeps its ID
    velocity_window_us: float = 2000.0  # time base of the velocity estimate
    max_speed_mm_s: float = 3000.0 # clamp of the predicted velocity
    # blobs (the paper's future work; defined in fmt.blob)
    blobs: bool = False            # blob detection on: fingers inside blobs dropped, blob events
    blob_threshold: int = 1000     # cells above this belong to a connected region
    blob_min_cells: int = 12       # a region of at least this many cells is a blob

    def replace(self, **kw) -> "TouchSettings":
        return replace(self, **kw)

    def as_dict(self) -> dict:
        return asdict(self)

    def converted(self, cfg: SensorConfig, frame_period_s: float) -> dict:
        """Tracking settings in cells (Q8.8 integers) and frames."""
        cell = cfg.pitch_mm
        q = 1 << cfg.frac_bits
        frames = lambda us: max(1, int(round(us * 1e-6 / frame_period_s)))
        return {
            "max_jump_q": int(round(self.max_jump_mm / cell * q)),
            "hold_off_frames": frames(self.hold_off_us),
            "velocity_window_frames": frames(self.velocity_window_us),
            "max_speed_q_per_frame": int(round(self.max_speed_mm_s * frame_period_s / cell * q)),
        }
