"""Event records of the core's stream, grouped into reports, and the contacts they describe.

An *event record* is a dict of the 24-byte event payload's integer fields
(docs/PROTOCOL.md), the unit every host output maps from::

    frame time id type last x_q y_q strength axis_major_q axis_minor_q angle flags

``type`` is 'new' | 'move' | 'lift' | 'blob'; x_q, y_q and the axes are cells in Q8.8
(cell (r, c) is centred on x = c, y = r), angle in units of pi/256 (the major axis
against the x axis, 0..255).  A *report* is the events of one frame (the core sends
whole frames; the last one carries ``last``).  :class:`Contacts` turns reports into the
set of contacts alive after each report: fingers keyed by their tracker ID (0..254),
blobs (palms; ID 0xFF on the wire, no tracking) keyed ``BLOB_KEY + k`` by their order
in the frame.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass, field

from fmt import protocol as P

FIELDS = ("frame", "time", "id", "type", "last", "x_q", "y_q", "strength", "axis_major_q",
          "axis_minor_q", "angle", "flags")
TYPE_CODES = {name: code for code, name in P.EVENT_TYPES.items()}
BLOB_KEY = 0x100            # contact key of the k-th blob of a frame: BLOB_KEY + k
_EV = struct.Struct(P._EV_STRUCT)


def from_payload(p: bytes) -> dict:
    """The event record of one 24-byte event payload."""
    if len(p) != P.EVENT_BYTES:
        raise P.ProtocolError(f"event payload of {len(p)} bytes, expected {P.EVENT_BYTES}")
    f, t, i, tl, x, y, s, ma, mi, a, fl, _ = _EV.unpack(p)
    return {"frame": f, "time": t, "id": i, "type": P.EVENT_TYPES[tl & 3], "last": bool(tl & 0x80),
            "x_q": x, "y_q": y, "strength": s, "axis_major_q": ma, "axis_minor_q": mi,
            "angle": a, "flags": fl}


def to_payload(rec: dict) -> bytes:
    """The 24-byte payload of an event record (inverse of :func:`from_payload`)."""
    return P.pack_event({"frame": rec["frame"], "time": rec["time"], "id": rec["id"],
                         "type": TYPE_CODES[rec["type"]], "last": rec["last"], "x": rec["x_q"],
                         "y": rec["y_q"], "strength": rec["strength"],
                         "axis_major": rec["axis_major_q"], "axis_minor": rec["axis_minor_q"],
                         "angle": rec["angle"], "flags": rec["flags"]})


def from_model(frames_events, period_clk: int = 768, first_time: int = 0) -> list[dict]:
    """Event records of the model's output (fmt.touch.process_frames: per frame a list
    of TouchEvent), ``last`` on each frame's final event, time = frame x period_clk."""
    out = []
    for evs in frames_events:
        for k, e in enumerate(evs):
            out.append({"frame": e.frame & 0xFFFF,
                        "time": (first_time + e.frame * period_clk) & 0xFFFFFFFF,
                        "id": e.id, "type": e.type, "last": k == len(evs) - 1, "x_q": e.x_q,
                        "y_q": e.y_q, "strength": e.strength, "axis_major_q": e.axis_major_q,
                        "axis_minor_q": e.axis_minor_q, "angle": e.angle, "flags": e.flags})
    return out


@dataclass(frozen=True)
class Sensor:
    """The sensor as the host sees it: rows x columns of cells (INFO), pitch in mm."""
    rows: int
    cols: int
    pitch_mm: float = 5.0

    @classmethod
    def from_info(cls, info: dict, pitch_mm: float = 5.0) -> "Sensor":
        return cls(int(info["rows"]), int(info["cols"]), pitch_mm)

    def norm(self, x_q: int, y_q: int) -> tuple[float, float]:
        """Q8.8 cells -> position normalised to the sensor's area, 0..1 from the left /
        top edge (a cell centre is half a cell inside the edge), clipped."""
        x = (x_q / 256.0 + 0.5) / self.cols
        y = (y_q / 256.0 + 0.5) / self.rows
        return min(max(x, 0.0), 1.0), min(max(y, 0.0), 1.0)


class Reports:
    """Groups event records into reports: a report ends with its ``last`` event, or
    when an event of another frame arrives (a frame cut short)."""

    def __init__(self):
        self.cur: list[dict] = []

    def feed(self, rec: dict) -> list[list[dict]]:
        out = []
        if self.cur and rec["frame"] != self.cur[-1]["frame"]:
            out.append(self.cur)
            self.cur = []
        self.cur.append(rec)
        if rec["last"]:
            out.append(self.cur)
            self.cur = []
        return out

    def flush(self) -> list[list[dict]]:
        out = [self.cur] if self.cur else []
        self.cur = []
        return out


def group(records) -> list[list[dict]]:
    """Every report of a list of event records."""
    g = Reports()
    out = [r for rec in records for r in g.feed(rec)]
    return out + g.flush()


def auto_hold_frames(regs: dict, n_fft: int, clk_per_sample: int = 3) -> int:
    """How long a contact absent from the reports stays alive, in frames, from the
    registers (name -> value): the tracker's hold-off (TRACK_HOLD_OFF) plus two report
    periods (REPORT_PERIOD clk over a frame of clk_per_sample x N x WINDOWS_M clk).  The
    UART also drops an event that arrives while it is sending, so a report may lack a
    contact that is still there."""
    m = max(1, int(regs.get("WINDOWS_M", 1)))
    frame_clk = clk_per_sample * n_fft * m
    per = int(regs.get("REPORT_PERIOD", 0))
    return int(regs.get("TRACK_HOLD_OFF", 33)) + 2 * (-(-per // frame_clk))


@dataclass
class Contact:
    key: int                  # tracker ID 0..254, or BLOB_KEY + k for the k-th blob
    x_q: int
    y_q: int
    strength: int
    axis_major_q: int
    axis_minor_q: int
    angle: int
    palm: bool
    frame: int                # frame of the last report naming it

    @property
    def id(self) -> int:
        return self.key


@dataclass
class Update:
    """The contacts after one report."""
    frame: int
    alive: dict = field(default_factory=dict)      # key -> Contact, ascending keys
    added: list = field(default_factory=list)      # keys new in this report
    removed: list = field(default_factory=list)    # keys gone with this report


class Contacts:
    """The contacts alive after each report.

    A new or move event sets a finger; a lift ends it; a finger absent from a report
    stays alive for ``hold_frames`` frames after its last report (the tracker's
    hold-off gap in a full-rate stream; a decimated UART stream, REPORT_PERIOD, ends it
    at the next report).  Blobs live for their own report only."""

    def __init__(self, hold_frames: int = 40):
        self.hold = hold_frames
        self.alive: dict[int, Contact] = {}

    def update(self, report: list[dict], frame: int | None = None) -> Update:
        """The contacts after ``report`` (``frame``: of an empty report, default 0)."""
        if frame is None:
            frame = report[0]["frame"] if report else 0
        before = set(self.alive)
        nxt = {k: c for k, c in self.alive.items()
               if not c.palm and ((frame - c.frame) & 0xFFFF) <= self.hold}
        nb = 0
        for e in report:
            t = e["type"]
            if t == "lift":
                nxt.pop(e["id"], None)
                continue
            key = e["id"] if t != "blob" else BLOB_KEY + nb
            nb += t == "blob"
            nxt[key] = Contact(key, e["x_q"], e["y_q"], e["strength"], e["axis_major_q"],
                               e["axis_minor_q"], e["angle"], t == "blob", frame)
        self.alive = dict(sorted(nxt.items()))
        return Update(frame, dict(self.alive), sorted(set(nxt) - before), sorted(before - set(nxt)))
