"""Reports of the core's event stream -> TUIO over OSC (python-osc), one bundle per report.

TUIO 1.1 (the reacTIVision profile)::

    /tuio/2Dcur source fmt@HOST          (first bundle only; every one with ``source``)
    /tuio/2Dcur alive s ...              fingers alive after the report
    /tuio/2Dcur set s x y X Y m          one per finger alive; X Y m = 0 (not estimated)
    /tuio/2Dcur fseq f                   frame sequence number (the core's frame, wrapped)
    /tuio/2Dblb alive / set s x y a w h f X Y A m r / fseq     blobs (palms), when any

TUIO 2.0::

    /tuio2/frm f t dim source            frame ID, time tag, dim = width << 16 | height
                                          (the sensor in 1/256 cell), "fmt:core@HOST"
    /tuio2/ptr s tu c x y a shear r press   one per finger (tu_id: type 1 finger, user 0)
    /tuio2/bnd s x y a w h f              one per blob (palm)
    /tuio2/alv s ...                      session IDs alive

Session IDs are the tracker's contact IDs (0..254; blobs 256 + k), positions are
normalised to the sensor (0..1 from the left / top edge, events.Sensor.norm), the
angle is the major axis against the x axis in radians, widths/heights the ellipse's
axes (twice the event's semi-axes) normalised to the sensor width / height, the radius
half the width, pressure the strength / 2^16 (clipped to 1).
:func:`messages` is the pure mapping; :class:`Sender` builds and sends the bundles.
"""
from __future__ import annotations

import math
import struct

from .events import BLOB_KEY, Sensor, Update

PRESS_FULL = 1 << 16          # strength of pressure 1.0


def _geom(c, sensor: Sensor):
    x, y = sensor.norm(c.x_q, c.y_q)
    a = c.angle * math.pi / 256.0
    w = 2 * c.axis_major_q / 256.0 / sensor.cols        # the axes are semi-axes
    h = 2 * c.axis_minor_q / 256.0 / sensor.rows
    return x, y, a, w, h


def messages(upd: Update, sensor: Sensor, version: str = "1.1", fseq: int | None = None,
             source: str = "fmt@localhost") -> list[tuple[str, list]]:
    """The OSC messages (address, args) of one report's bundle.  ``fseq``: the frame
    sequence number (default: the report's frame); the time tag of TUIO 2.0's frm is
    added by :class:`Sender` (args[1] here is None)."""
    f = upd.frame if fseq is None else fseq
    fingers = [c for c in upd.alive.values() if not c.palm]
    palms = [c for c in upd.alive.values() if c.palm]
    out: list[tuple[str, list]] = []
    if version == "1.1":
        if source:
            out.append(("/tuio/2Dcur", ["source", source]))
        out.append(("/tuio/2Dcur", ["alive", *[c.key for c in fingers]]))
        for c in fingers:
            x, y, *_ = _geom(c, sensor)
            out.append(("/tuio/2Dcur", ["set", c.key, x, y, 0.0, 0.0, 0.0]))
        out.append(("/tuio/2Dcur", ["fseq", f]))
        if palms or any(k >= BLOB_KEY for k in upd.removed):
            out.append(("/tuio/2Dblb", ["alive", *[c.key for c in palms]]))
            for c in palms:
                x, y, a, w, h = _geom(c, sensor)
                out.append(("/tuio/2Dblb", ["set", c.key, x, y, a, w, h, w * h, 0.0, 0.0, 0.0, 0.0, 0.0]))
            out.append(("/tuio/2Dblb", ["fseq", f]))
        return out
    if version == "2.0":
        dim = ((sensor.cols * 256) & 0xFFFF) << 16 | ((sensor.rows * 256) & 0xFFFF)
        out.append(("/tuio2/frm", [f, None, dim, source.replace("@", ":core@", 1)
                                   if "@" in source else source]))
        for c in fingers:
            x, y, a, w, h = _geom(c, sensor)
            r = 0.5 * w
            press = min(1.0, c.strength / PRESS_FULL)
            out.append(("/tuio2/ptr", [c.key, 1 << 16, 0, x, y, a, 0.0, r, press]))
        for c in palms:
            x, y, a, w, h = _geom(c, sensor)
            out.append(("/tuio2/bnd", [c.key, x, y, a, w, h, w * h]))
        out.append(("/tuio2/alv", [c.key for c in upd.alive.values()]))
        return out
    raise ValueError(f"TUIO version {version!r}: use 1.1 or 2.0")


def _osc_message(addr: str, args: list, now: float):
    from pythonosc.osc_message import OscMessage
    from pythonosc.osc_message_builder import OscMessageBuilder
    from pythonosc.parsing import ntp
    b = OscMessageBuilder(addr)
    timetag = None
    for v in args:
        if v is None:                          # frm's time tag: an 8-byte slot patched below
            timetag = ntp.system_time_to_ntp(now)
            b.add_arg(0, b.ARG_TYPE_INT64)
        elif isinstance(v, float):
            b.add_arg(v, b.ARG_TYPE_FLOAT)
        elif isinstance(v, int):
            b.add_arg(v, b.ARG_TYPE_INT)
        else:
            b.add_arg(v, b.ARG_TYPE_STRING)
    msg = b.build()
    if timetag is None:
        return msg
    # python-osc builds no 't' argument: the int64 slot has the time tag's size,
    # so its type letter and its 8 bytes are replaced in place
    dg = bytearray(msg.dgram)
    tags_at = dg.index(b",", len(addr))
    tags_end = dg.index(b"\0", tags_at)
    k = dg.index(b"h", tags_at, tags_end)
    dg[k] = ord("t")
    pos = (tags_end // 4 + 1) * 4
    for ch in dg[tags_at + 1:k].decode():  # args before the slot
        pos += 4 if ch in "if" else 8 if ch in "hdt" else 0
    dg[pos:pos + 8] = timetag
    return OscMessage(bytes(dg))


class Sender:
    """Sends one OSC bundle per report to host:port over UDP."""

    def __init__(self, host: str, port: int, sensor: Sensor, version: str = "1.1",
                 source: str = "fmt@localhost"):
        from pythonosc.udp_client import UDPClient      # (fmtctl checks the package first)
        self.client = UDPClient(host, port)
        self.sensor, self.version, self.source = sensor, version, source
        self.bundles = 0

    def send(self, upd: Update, now: float) -> None:
        from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
        b = OscBundleBuilder(IMMEDIATELY)
        for addr, args in messages(upd, self.sensor, self.version, source=self.source):
            b.add_content(_osc_message(addr, args, now))
        self.client.send(b.build())
        self.bundles += 1


def unpack_timetag(b: bytes) -> float:
    """Seconds since the epoch of an 8-byte NTP time tag (tests)."""
    sec, frac = struct.unpack(">II", b)
    return sec - 2208988800 + frac / 2 ** 32
