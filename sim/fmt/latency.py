"""Latency counters: the cycle-level twin of ``rtl/fmt_latency.v``.

``LatencyCounters.step(inputs)`` advances one processing-clock cycle and returns the
registered outputs as they are after that clock edge.  Also helpers to turn the
counters into microseconds.
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class LatencyCounters:
    cnt_w: int = 16
    num_w: int = 32
    slots_w: int = 2
    bins_w: int = 4
    hist_shift: int = 5
    time_w: int = 32
    # state
    now: int = 0
    stamp: list = field(default_factory=list)
    seen_first: list = field(default_factory=list)
    trig_sync: list = field(default_factory=lambda: [0, 0, 0])
    trig_start: int = 0
    out: dict = field(default_factory=dict)
    hist: dict = field(default_factory=dict)

    def __post_init__(self):
        self.reset()

    @property
    def cnt_max(self):
        return (1 << self.cnt_w) - 1

    @property
    def num_max(self):
        return (1 << self.num_w) - 1

    def _clear_stats(self):
        o = self.out
        for k in ("first", "last", "trig"):
            o[f"{k}_last"] = 0
            o[f"{k}_min"] = self.cnt_max
            o[f"{k}_max"] = 0
            o[f"{k}_count"] = 0
        nb = 1 << self.bins_w
        self.hist = {"first": [0] * nb, "last": [0] * nb}

    def reset(self):
        slots = 1 << self.slots_w
        self.now = 0
        self.stamp = [0] * slots
        self.seen_first = [1] * slots
        self.trig_sync = [0, 0, 0]
        self.trig_start = 0
        self.out = {"trig_armed": 0, "sat": 0}
        self._clear_stats()

    def step(self, rst=0, clear=0, frame_end=0, frame_end_slot=0, ev_fire=0, ev_slot=0,
             ev_last=0, ev_new=0, trig=0) -> dict:
        if rst:
            self.reset()
            return dict(self.out)
        tmask = (1 << self.time_w) - 1
        o = self.out
        cm, nm = self.cnt_max, self.num_max
        age = (self.now - self.stamp[ev_slot]) & tmask
        big = age > cm
        lat = cm if big else age
        is_first = bool(ev_fire and not self.seen_first[ev_slot])
        is_last = bool(ev_fire and ev_last)
        nb = 1 << self.bins_w
        hidx = min(lat >> self.hist_shift, nb - 1)
        trig_rise = self.trig_sync[1] and not self.trig_sync[2]
        tage = (self.now - self.trig_start) & tmask
        tbig = tage > cm
        tlat = cm if tbig else tage
        trig_done = bool(o["trig_armed"] and ev_fire and ev_new)
        # sticky saturation (uses pre-update values, as the RTL does)
        if (is_first or is_last) and big:
            o["sat"] = 1
        if trig_done and tbig:
            o["sat"] = 1
        if ((is_first and (o["first_count"] == nm or self.hist["first"][hidx] == nm)) or
                (is_last and (o["last_count"] == nm or self.hist["last"][hidx] == nm)) or
                (trig_done and o["trig_count"] == nm)):
            o["sat"] = 1
        # statistics
        if clear:
            armed = o["trig_armed"]
            self._clear_stats()
        else:
            for kind, fire, v in (("first", is_first, lat), ("last", is_last, lat), ("trig", trig_done, tlat)):
                if fire:
                    o[f"{kind}_last"] = v
                    o[f"{kind}_min"] = min(o[f"{kind}_min"], v)
                    o[f"{kind}_max"] = max(o[f"{kind}_max"], v)
                    if o[f"{kind}_count"] != nm:
                        o[f"{kind}_count"] += 1
                    if kind != "trig" and self.hist[kind][hidx] != nm:
                        self.hist[kind][hidx] += 1
        # bookkeeping
        if clear:
            o["trig_armed"] = armed
        new_seen = list(self.seen_first)
        for i in range(len(new_seen)):
            if frame_end and frame_end_slot == i:
                new_seen[i] = 0
            elif is_first and ev_slot == i:
                new_seen[i] = 1
        self.seen_first = new_seen
        if frame_end:
            self.stamp[frame_end_slot] = self.now
        if trig_rise:
            o["trig_armed"] = 1
            self.trig_start = (self.now - 2) & tmask
        elif trig_done:
            o["trig_armed"] = 0
        self.trig_sync = [trig, self.trig_sync[0], self.trig_sync[1]]
        self.now = (self.now + 1) & tmask
        return dict(o)


def cycles_to_us(cycles: float, clk_hz: float) -> float:
    return cycles / clk_hz * 1e6
