"""Latency counters: the cycle-level twin of ``rtl/fmt_latency.v``.

``LatencyCounters.step(inputs)`` advances one processing-clock cycle and returns the
registered outputs as they are after that clock edge.  Also helpers to turn the
counters into microseconds.

Pipeline (as the RTL): in the cycle of an event (stage 0) its latency is measured
(``now`` minus the frame-end stamp, or minus the trigger time); the statistics
(last/min/max/count, the saturation flag) take it one cycle later (stage 1), which
also reads the histogram bin; the bin + 1 (saturating) is written back one cycle after
that (stage 2),
with the value of a write to the same bin in the previous cycle forwarded.  A clear
drops the events of its own and the earlier cycles still in the pipeline.
"""
from __future__ import annotations


class LatencyCounters:
    def __init__(self, cnt_w: int = 16, num_w: int = 32, slots_w: int = 2, bins_w: int = 4,
                 hist_shift: int = 5, time_w: int = 32):
        self.cnt_w, self.num_w, self.slots_w = cnt_w, num_w, slots_w
        self.bins_w, self.hist_shift, self.time_w = bins_w, hist_shift, time_w
        nb = 1 << bins_w
        self.mem = {"first": [0] * nb, "last": [0] * nb}   # the RAMs (no reset)
        self.reset()

    @property
    def cnt_max(self):
        return (1 << self.cnt_w) - 1

    @property
    def num_max(self):
        return (1 << self.num_w) - 1

    @property
    def hist(self) -> dict:
        """Histogram contents as read through hist_data_o (bins not written since the
        clear read 0)."""
        return {k: [m if ok else 0 for m, ok in zip(self.mem[k], self.ok[k])]
                for k in ("first", "last")}

    def _clear_stats(self):
        o = self.out
        for k in ("first", "last", "trig"):
            o[f"{k}_last"] = 0
            o[f"{k}_min"] = self.cnt_max
            o[f"{k}_max"] = 0
            o[f"{k}_count"] = 0
        nb = 1 << self.bins_w
        self.ok = {"first": [0] * nb, "last": [0] * nb}

    def reset(self):
        slots = 1 << self.slots_w
        self.now = 0
        self.stamp = [0] * slots
        self.stamp_ok = [0] * slots
        self.seen_first = [1] * slots
        self.trig_sync = [0, 0, 0]
        self.trig_start = 0
        self.out = {"trig_armed": 0, "sat": 0}
        self._clear_stats()
        # stage 1 / stage 2 registers and the forwarding registers
        self.s1 = dict(f=0, l=0, t=0, age=0, big=0, tage=0, tbig=0)
        self.s2 = dict(f=0, l=0, bin=0, rd={"first": 0, "last": 0})
        self.fw = {"first": (0, 0, 0), "last": (0, 0, 0)}       # (valid, bin, value)

    def step(self, rst=0, clear=0, frame_end=0, frame_end_slot=0, ev_fire=0, ev_slot=0,
             ev_last=0, ev_new=0, trig=0) -> dict:
        if rst:
            self.reset()
            return dict(self.out)
        tmask = (1 << self.time_w) - 1
        o = self.out
        cm, nm = self.cnt_max, self.num_max
        nb = 1 << self.bins_w
        # ---- stage 0: the event of this cycle
        stamp = self.stamp[ev_slot] if self.stamp_ok[ev_slot] else 0
        age = (self.now - stamp) & tmask
        is_first = bool(ev_fire and not self.seen_first[ev_slot])
        is_last = bool(ev_fire and ev_last)
        trig_rise = self.trig_sync[1] and not self.trig_sync[2]
        tage = (self.now - self.trig_start) & tmask
        trig_done = bool(o["trig_armed"] and ev_fire and ev_new)
        s1n = dict(f=int(is_first and not clear), l=int(is_last and not clear),
                   t=int(trig_done and not clear), age=age & cm, big=int(age > cm),
                   tage=tage & cm, tbig=int(tage > cm))
        # ---- stage 1: statistics and the histogram read
        s1 = self.s1
        lat = cm if s1["big"] else s1["age"]
        tlat = cm if s1["tbig"] else s1["tage"]
        hidx = min(lat >> self.hist_shift, nb - 1)
        if (s1["f"] or s1["l"]) and s1["big"]:
            o["sat"] = 1
        if s1["t"] and s1["tbig"]:
            o["sat"] = 1
        if ((s1["f"] and o["first_count"] == nm) or (s1["l"] and o["last_count"] == nm) or
                (s1["t"] and o["trig_count"] == nm)):
            o["sat"] = 1
        rd = {k: (self.mem[k][hidx] if self.ok[k][hidx] else 0) for k in ("first", "last")}
        s2n = dict(f=int(s1["f"] and not clear), l=int(s1["l"] and not clear), bin=hidx, rd=rd)
        # ---- stage 2: histogram write-back (forwarding a write to the same bin)
        s2 = self.s2
        fwn = {}
        writes = []
        for k, fire in (("first", s2["f"]), ("last", s2["l"])):
            fv, fb, fval = self.fw[k]
            v = fval if (fv and fb == s2["bin"]) else s2["rd"][k]
            if fire and v == nm:
                o["sat"] = 1
            we = bool(fire and not clear)
            new = min(v + 1, nm)                     # saturating
            fwn[k] = (int(we), s2["bin"], new)
            if we:
                writes.append((k, s2["bin"], new))
        for k, b, v in writes:                      # the RAM write (no reset)
            self.mem[k][b] = v
        # statistics (cleared by clear)
        if clear:
            armed = o["trig_armed"]
            self._clear_stats()
            o["trig_armed"] = armed
        else:
            for kind, fire, v in (("first", s1["f"], lat), ("last", s1["l"], lat),
                                  ("trig", s1["t"], tlat)):
                if fire:
                    o[f"{kind}_last"] = v
                    o[f"{kind}_min"] = min(o[f"{kind}_min"], v)
                    o[f"{kind}_max"] = max(o[f"{kind}_max"], v)
                    if o[f"{kind}_count"] != nm:
                        o[f"{kind}_count"] += 1
            for k, b, _ in writes:
                self.ok[k][b] = 1
        self.s1, self.s2, self.fw = s1n, s2n, fwn
        # bookkeeping of stage 0
        new_seen = list(self.seen_first)
        for i in range(len(new_seen)):
            if frame_end and frame_end_slot == i:
                new_seen[i] = 0
            elif is_first and ev_slot == i:
                new_seen[i] = 1
        self.seen_first = new_seen
        if frame_end:
            self.stamp[frame_end_slot] = self.now
            self.stamp_ok[frame_end_slot] = 1
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
