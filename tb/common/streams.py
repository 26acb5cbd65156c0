"""cocotb-bus monitors of the core's internal streams (candidates, touch points, events).

:class:`StreamMonitor` is a ``cocotb_bus.monitors.BusMonitor`` over a group of ports
``<prefix>_<field>_o`` of the DUT.  After every rising clock edge (in the ReadOnly
phase) it counts the cycle and, while reset is low, records a beat when ``valid`` is
high (and ``ready``, for a valid/ready stream).  Each beat is a :class:`Beat`
(monitor cycle number, field values as ints); the cycle numbers are those of the
testbench's own counters (the first edge after the monitor starts is cycle 1), so
latencies and one-beat-per-cycle checks stay exact.

Two shapes of transaction, delivered through the BusMonitor interface (the monitor's
queue, ``wait_for_recv`` or a callback, e.g. a ``cocotb_bus.scoreboard.Scoreboard``):

* without ``eof``: one :class:`Beat` per handshake (the event stream of fmt_touch);
* with ``eof``: one :class:`FrameRecord` per frame, the beats since the last eof plus
  the ``eof_fields`` sampled in the eof cycle (the candidate stream of fmt_localmax:
  count, found, overflow, incomplete).  A reset drops a partly received frame.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from cocotb.triggers import ReadOnly, RisingEdge
from cocotb_bus.monitors import BusMonitor


@dataclass(frozen=True)
class Beat:
    cycle: int
    values: dict

    def __getitem__(self, name):
        return self.values[name]

    def tuple(self, names) -> tuple:
        return tuple(self.values[n] for n in names)


@dataclass(frozen=True)
class FrameRecord:
    cycle: int                       # the eof cycle
    beats: list = field(default_factory=list)
    eof: dict = field(default_factory=dict)

    def __getitem__(self, name):
        return self.eof[name]


def _resolvable(v) -> bool:
    return getattr(v, "is_resolvable", True)


class StreamMonitor(BusMonitor):
    """Monitor of the ports ``<prefix>_<name><suffix>`` (suffix ``_o`` by default).

    ``fields``: the data ports recorded per beat; ``valid``: the beat strobe;
    ``ready``: the consumer's ready (a DUT input, full name, e.g. ``ev_ready_i``) or
    None; ``eof`` / ``eof_fields``: the end-of-frame strobe and the ports recorded with
    it (frame mode) or None (beat mode); ``reset``: the reset handle (active high)."""

    def __init__(self, entity, prefix: str, clock, fields, valid: str = "valid",
                 ready: str | None = None, eof: str | None = None, eof_fields=(),
                 reset=None, suffix: str = "_o", callback=None):
        self.fields = tuple(fields)
        self.eof_fields = tuple(eof_fields)
        self._has_eof = eof is not None
        sig = {n: n + suffix for n in self.fields + self.eof_fields}
        sig["valid"] = valid + suffix
        if eof is not None:
            sig["eof"] = eof + suffix
        self._signals = sig
        self._ready = getattr(entity, ready) if ready else None
        self.cycle = 0
        self._cur: list[Beat] = []
        super().__init__(entity, prefix, clock, reset=reset, callback=callback)

    @property
    def in_reset(self) -> bool:
        r = self._reset
        if r is None:
            return False
        v = r.value
        return (not _resolvable(v)) or bool(int(v))

    async def _monitor_recv(self):
        bus, rd = self.bus, self._ready
        while True:
            await RisingEdge(self.clock)
            await ReadOnly()
            self.cycle += 1
            if self.in_reset:
                self._cur = []
                continue
            v = bus.valid.value
            if _resolvable(v) and int(v) and (rd is None or int(rd.value)):
                beat = Beat(self.cycle, {n: int(getattr(bus, n).value) for n in self.fields})
                if self._has_eof:
                    self._cur.append(beat)
                else:
                    self._recv(beat)
            if self._has_eof:
                e = bus.eof.value
                if _resolvable(e) and int(e):
                    rec = FrameRecord(self.cycle, self._cur,
                                      {n: int(getattr(bus, n).value) for n in self.eof_fields})
                    self._cur = []
                    self._recv(rec)
