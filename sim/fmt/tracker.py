"""Frame matching (contact tracking): twin of ``rtl/fmt_tracker.v``.

Coordinates are integers (Q8.8 cells) and every step below is integer arithmetic, so
the floating-point reference and the fixed-point twin are the same function
(:func:`track_fixed` is both).

Per contact slot (``max_touches`` slots) the tracker keeps: ``active``, ``id``,
the predicted position ``p`` (Q8.(8+VF), VF = ``vel_frac`` extra fractional bits),
the velocity ``v`` (cells/frame with 8+VF fractional bits), ``miss`` (frames since
last seen) and the last measured position (for the lift event).

One frame (touches ``t`` in arrival order, at most ``max_touches``; further touches
of the frame are dropped and counted):

1. prediction of slot s: ``pred = (p + 2^(VF-1)) >> VF`` (round half up), per axis.
2. distance ``D[t][s] = |x_t - predx_s| + |y_t - predy_s|`` (L1, Q8.8 units).  A pair
   is a candidate when slot s is active and ``D <= gate_s``.  The gate is physical
   (:meth:`TrackParams.from_settings`): ``max_jump_q`` (the farthest a finger at the
   maximum speed can be from its prediction after one frame, plus the position noise)
   for a contact seen in the previous frame, growing by ``gate_step_q`` (the same
   bound for one more frame) with every frame a contact is missed (``gate_s`` is kept
   per slot: ``max_jump_q`` when it is matched or new, ``min(gate_s + gate_step_q,
   0xFFFF)`` when it is kept in hold-off).  A touch that no finger could have moved to
   is never matched: at 162.76 kHz two fingers tapping 10 mm apart are two contacts.
3. greedy global nearest pairs: repeat { take the candidate pair of smallest D among
   unassigned touches and slots; ties go to the smallest ``t * max_touches + s`` },
   each assignment emits a ``move`` event (in this order); for a *tentative* slot
   (below) it counts one more frame seen and emits ``new`` (with the touch) when that
   makes ``confirm_frames``, else nothing.
4. lifts: every active, unmatched slot that is tentative or has ``miss + 1 >=
   hold_off_frames`` is freed; a confirmed one emits a ``lift`` event (slot order)
   carrying its last measured x, y, a tentative one none.
5. news: every unassigned touch with ``strength >= on_threshold`` (the activation
   threshold; the localmax threshold below it is the deactivation threshold of
   continuing contacts), in arrival order, takes a free slot (round-robin: the first
   free slot at or after ``next_slot``, which then moves past it) and emits ``new``;
   with ``confirm_frames`` >= 2 the slot is tentative instead (seen 1 frame, no event,
   no hold-off: freed silently the first frame it is not matched), so a touch that
   lasts one frame (the spectral leakage of a finger landing or lifting inside a
   window gives such touches beside it) never becomes a contact, at the cost of
   ``confirm_frames - 1`` frames of touch-down latency.  With no free slot the touch
   takes the slot of the contact in hold-off that was seen longest ago (the earliest
   last move or new, in event order; the slot's ``lift`` event comes first, then the
   slot is allocated as above): a hold-off keeps an ID for a finger that comes back,
   it must not keep a new finger out.  With no contact in hold-off either the touch is
   dropped and counted.
6. update.  Matched slot: ``e = (meas << VF) - p`` (the prediction error at full
   precision); ``v = clamp(v + (e >> S), +-max_speed_v)`` per axis (arithmetic shift =
   floor; an alpha-beta filter with g = 1, h = 2^-S, i.e. an exponential average of the
   frame differences over ~2^S frames: S = floor(log2 velocity_window_frames), capped
   at VF); ``p = (meas << VF) + v`` (prediction for the next frame).  New slot:
   ``v = 0, p = meas << VF``.  Unmatched slot kept in hold-off: ``miss += 1, p += v``.
   Using the error before rounding matters: at 162.76 kHz a finger moves a fraction of
   one Q8.8 step per frame, and an error of rounded positions would be a dead zone of
   +-0.5 step per frame (~1.6 m/s).

IDs: ``id = (generation << SLOT_BITS) | slot`` with SLOT_BITS = clog2(max_touches)
and an ``ID_W - SLOT_BITS`` bit generation counter per slot that increments on every
allocation of that slot.  IDs of live contacts are therefore unique, and an ID comes
back only after 2^(ID_W-SLOT_BITS) allocations of the same slot; with the round-robin
slot choice that is at least 256 new contacts at ID_W = 8, max_touches = 16.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .params import SensorConfig
from .settings import TouchSettings

EV_NEW, EV_MOVE, EV_LIFT, EV_BLOB = 0, 1, 2, 3
CONFIRM_MAX = 7                         # confirm_frames limit (3-bit register)
NO_CAND = np.iinfo(np.int64).max        # distance of a pair that is not a candidate
EV_TYPES = ("new", "move", "lift", "blob")
EV_CODE = {n: i for i, n in enumerate(EV_TYPES)}


@dataclass(frozen=True)
class TouchEvent:
    """One touch event (ARCHITECTURE.md "Touch-event stream", without the time stamp)."""
    frame: int
    id: int
    type: str                 # 'new' | 'move' | 'lift' | 'blob'
    x_q: int
    y_q: int
    strength: int = 0
    axis_major_q: int = 0
    axis_minor_q: int = 0
    angle: int = 0
    flags: int = 0

    @property
    def type_code(self) -> int:
        return EV_CODE[self.type]

    def key(self) -> tuple:
        return (self.frame, self.id, self.type, self.x_q, self.y_q, self.strength,
                self.axis_major_q, self.axis_minor_q, self.angle, self.flags)


@dataclass(frozen=True)
class Touch:
    """One fine touch of a frame (the touch stream of fmt_interp)."""
    x_q: int
    y_q: int
    strength: int = 0
    axis_major_q: int = 0
    axis_minor_q: int = 0
    angle: int = 0
    flags: int = 0


TOUCH_FIELDS = ("x_q", "y_q", "strength", "axis_major_q", "axis_minor_q", "angle", "flags")


def as_touch(t) -> Touch:
    """Touch from a Touch, a dict or any object with the Touch field names."""
    if isinstance(t, Touch):
        return t
    if isinstance(t, dict):
        return Touch(**{k: int(t.get(k, 0)) for k in TOUCH_FIELDS})
    return Touch(**{k: int(getattr(t, k, 0)) for k in TOUCH_FIELDS})


@dataclass(frozen=True)
class TrackParams:
    """Tracker settings in RTL units (all integers; the RTL's run-time inputs)."""
    max_jump_q: int = 185          # L1 gate of a contact seen last frame (Q8.8 cells)
    gate_step_q: int = 4           # the gate's growth per frame missed (Q8.8 cells, L1)
    hold_off_frames: int = 33      # a contact missing this many frames is lifted
    vel_shift: int = 8             # S: velocity filter gain 2^-S (<= vel_frac)
    max_speed_v: int = 3865        # velocity clamp per axis, units 2^-(8+VF) cells/frame
    vel_frac: int = 12             # VF: extra fractional bits of p and v (RTL parameter)
    on_threshold: int = 0          # activation threshold: strength a touch needs to start a contact
    confirm_frames: int = 1        # frames a new contact is seen before its 'new' (1 = at once; <= 7)
    max_touches: int = 16          # slots (RTL parameter MAX_TOUCHES)
    id_w: int = 8                  # ID width (RTL parameter)
    v_w: int = 22                  # velocity register width (signed, RTL parameter)

    @property
    def slot_bits(self) -> int:
        return max(1, math.ceil(math.log2(self.max_touches)))

    @classmethod
    def from_settings(cls, cfg: SensorConfig, settings: TouchSettings | None = None,
                      frame_period_s: float | None = None, **kw) -> "TrackParams":
        """Convert the physical settings once.  ``frame_period_s`` defaults to one
        window (M = 1); the gates scale with it (:meth:`TouchSettings.converted`).
        ``max_touches`` (slots) is the sensor's ``max_touches`` (an RTL parameter);
        ``settings.max_touches`` limits the candidates upstream."""
        s = settings or TouchSettings()
        T = frame_period_s if frame_period_s is not None else cfg.window_s
        c = s.converted(cfg, T)
        vf = kw.get("vel_frac", cls.vel_frac)
        v_w = kw.get("v_w", cls.v_w)
        w = c["velocity_window_frames"]
        shift = min(vf, max(0, w.bit_length() - 1))
        vmax = int(round(s.max_speed_mm_s * T / cfg.pitch_mm * (1 << (cfg.frac_bits + vf))))
        vmax = min(vmax, (1 << (v_w - 1)) - 1)
        hold = min(c["hold_off_frames"], (1 << 12) - 1)   # HOLD_W = 12
        mt = cfg.max_touches           # slots = the RTL parameter; the run-time limit is
                                       # applied to the candidates (fmt.localmax)
        args = dict(max_jump_q=c["max_jump_q"], gate_step_q=c["gate_step_q"],
                    hold_off_frames=hold, on_threshold=s.on_threshold,
                    confirm_frames=s.confirm_frames, vel_shift=shift, max_speed_v=vmax, max_touches=mt)
        args.update(kw)
        return cls(**args)


@dataclass
class _Slot:
    active: bool = False
    gen: int = 0
    px: int = 0
    py: int = 0
    vx: int = 0
    vy: int = 0
    miss: int = 0
    gate: int = 0                 # L1 match gate (Q8.8): max_jump_q + gate_step_q per frame missed
    lx: int = 0
    ly: int = 0
    tent: bool = False            # tentative: not reported yet
    seen: int = 0                 # frames seen while tentative
    last_op: int = 0              # sequence number of its last move or new (the age order)


@dataclass
class TrackerStats:
    dropped_touches: int = 0      # touches beyond max_touches in one frame
    no_slot: int = 0              # new touches with every slot taken
    frames: int = 0
    lift_ops: int = 0             # slots freed in the last frame (also tentative ones: no event)
    new_ops: int = 0              # slots allocated in the last frame (also tentative ones)
    evictions: int = 0            # contacts in hold-off lifted early for a new touch (all frames)
    evict_ops: int = 0            # ... in the last frame (each costs the RTL one cycle more)


class Tracker:
    """The frame-matching state machine; :meth:`step` processes one frame."""

    def __init__(self, p: TrackParams):
        self.p = p
        self.slots = [_Slot() for _ in range(p.max_touches)]
        self.next_slot = 0
        self.op_seq = 0               # counts moves and news (silent ones too)
        self.stats = TrackerStats()

    def slot_id(self, s: int) -> int:
        p = self.p
        return ((self.slots[s].gen << p.slot_bits) | s) & ((1 << p.id_w) - 1)

    def step(self, frame: int, touches) -> list[TouchEvent]:
        p = self.p
        n = p.max_touches
        vf = p.vel_frac
        touches = [as_touch(t) for t in touches]
        if len(touches) > n:
            self.stats.dropped_touches += len(touches) - n
            touches = touches[:n]
        self.stats.frames += 1
        self.stats.lift_ops = self.stats.new_ops = self.stats.evict_ops = 0
        nt = len(touches)
        sl = self.slots
        events: list[TouchEvent] = []
        matched_touch = [-1] * n          # slot -> touch
        t_used = np.zeros(nt, dtype=bool)
        if nt:
            # 1-2. predictions and the distance matrix, shape (touch, slot)
            dm = self.candidates(touches)
            big = NO_CAND
            # 3. greedy global nearest pairs (argmin = lowest flat index t*n+s on ties)
            while True:
                k = int(np.argmin(dm))
                if dm.flat[k] == big:
                    break
                t, s = divmod(k, n)
                dm[t, :] = big
                dm[:, s] = big
                t_used[t] = True
                matched_touch[s] = t
                tt = touches[t]
                st = sl[s]
                self.op_seq += 1
                st.last_op = self.op_seq
                typ = "move"
                if st.tent:
                    st.seen = min(st.seen + 1, CONFIRM_MAX)
                    if st.seen < p.confirm_frames:
                        continue
                    st.tent = False
                    typ = "new"
                events.append(TouchEvent(frame, self.slot_id(s), typ, tt.x_q, tt.y_q,
                                         tt.strength, tt.axis_major_q, tt.axis_minor_q,
                                         tt.angle, tt.flags))
        # 4. lifts
        for s in range(n):
            st = sl[s]
            if st.active and matched_touch[s] < 0 and (st.tent or st.miss + 1 >= p.hold_off_frames):
                st.active = False
                self.stats.lift_ops += 1
                if not st.tent:
                    events.append(TouchEvent(frame, self.slot_id(s), "lift", st.lx, st.ly))
                st.tent = False
        # 6a. update matched slots (before news: a new slot is fresh state)
        vmax = p.max_speed_v
        sh = p.vel_shift
        for s in range(n):
            t = matched_touch[s]
            st = sl[s]
            if t >= 0:
                mx, my = touches[t].x_q, touches[t].y_q
                st.vx = max(-vmax, min(vmax, st.vx + (((mx << vf) - st.px) >> sh)))
                st.vy = max(-vmax, min(vmax, st.vy + (((my << vf) - st.py) >> sh)))
                st.px = (mx << vf) + st.vx
                st.py = (my << vf) + st.vy
                st.miss = 0
                st.gate = p.max_jump_q
                st.lx, st.ly = mx, my
            elif st.active:
                st.miss += 1
                st.gate = min(st.gate + p.gate_step_q, 0xFFFF)
                st.px += st.vx
                st.py += st.vy
        # 5. news (a contact in hold-off seen longest ago makes room when no slot is free)
        fresh = [False] * n
        for t in range(nt):
            if t_used[t] or touches[t].strength < p.on_threshold:
                continue
            s = self._alloc()
            if s < 0:
                held = [k for k in range(n) if sl[k].active and matched_touch[k] < 0 and not fresh[k]]
                if not held:
                    self.stats.no_slot += 1
                    continue
                k = min(held, key=lambda k: sl[k].last_op)
                sl[k].active = False
                self.stats.lift_ops += 1
                self.stats.evictions += 1
                self.stats.evict_ops += 1
                events.append(TouchEvent(frame, self.slot_id(k), "lift", sl[k].lx, sl[k].ly))
                s = self._alloc()
            tt = touches[t]
            st = sl[s]
            fresh[s] = True
            self.op_seq += 1
            st.last_op = self.op_seq
            self.stats.new_ops += 1
            st.active = True
            st.gen = (st.gen + 1) & ((1 << (p.id_w - p.slot_bits)) - 1)
            st.vx = st.vy = 0
            st.px, st.py = tt.x_q << vf, tt.y_q << vf
            st.miss = 0
            st.gate = p.max_jump_q
            st.lx, st.ly = tt.x_q, tt.y_q
            if p.confirm_frames > 1:
                st.tent, st.seen = True, 1
                continue
            events.append(TouchEvent(frame, self.slot_id(s), "new", tt.x_q, tt.y_q,
                                     tt.strength, tt.axis_major_q, tt.axis_minor_q,
                                     tt.angle, tt.flags))
        return events

    def candidates(self, touches) -> np.ndarray:
        """Steps 1-2 of :meth:`step` for this frame's touches (the first max_touches) and
        the current slot state: the L1 distance matrix, shape (touch, slot), with
        ``NO_CAND`` where the pair is not a candidate.  Does not change the state."""
        p = self.p
        vf = p.vel_frac
        sl = self.slots
        touches = [as_touch(t) for t in touches][:p.max_touches]
        half = 1 << (vf - 1)
        predx = np.array([(s.px + half) >> vf for s in sl], dtype=np.int64)
        predy = np.array([(s.py + half) >> vf for s in sl], dtype=np.int64)
        act = np.array([s.active for s in sl], dtype=bool)
        gate = np.array([s.gate for s in sl], dtype=np.int64)
        tx = np.array([t.x_q for t in touches], dtype=np.int64)
        ty = np.array([t.y_q for t in touches], dtype=np.int64)
        d = np.abs(tx[:, None] - predx[None, :]) + np.abs(ty[:, None] - predy[None, :])
        return np.where(act[None, :] & (d <= gate[None, :]), d, NO_CAND)

    def _alloc(self) -> int:
        n = self.p.max_touches
        for k in range(n):
            s = (self.next_slot + k) % n
            if not self.slots[s].active:
                self.next_slot = (s + 1) % n
                return s
        return -1


def lazy_greedy(dm: np.ndarray) -> tuple[list[tuple[int, int]], int]:
    """The lazy greedy match (the principle of rtl/fmt_tracker.v, MATCH) and its cost.

    ``dm``: candidate distances (touch, slot), ``NO_CAND`` where not a candidate (from
    :meth:`Tracker.candidates`).  Each touch caches its best key (D, s) over the free
    slots (ties to the lower slot); a pick takes the smallest cached (D, t); if its slot
    is still free the pair is assigned, else the pick was stale and the touch's key is
    recomputed over the free slots.  Cached keys are lower bounds of the current keys,
    so the pairs are exactly the greedy order of :meth:`Tracker.step` (smallest
    (D, t, s) first).  Returns (pairs in assignment order, number of stale picks).
    The RTL keeps the cached keys in a sorted queue and recomputes several stale keys
    at once in its pipeline (its cycle model: ``match_cycles`` in
    tb/fmt_tracker/test_fmt_tracker.py); the pairs are the same."""
    nt, ns = dm.shape
    free = np.ones(ns, dtype=bool)
    used = np.zeros(nt, dtype=bool)

    def row_min(t):
        row = np.where(free, dm[t], NO_CAND)
        s = int(np.argmin(row))
        return int(row[s]), s

    cache = [row_min(t) for t in range(nt)]
    pairs, stale = [], 0
    while True:
        best = -1
        for t in range(nt):
            if not used[t] and cache[t][0] != NO_CAND and (best < 0 or cache[t][0] < cache[best][0]):
                best = t
        if best < 0:
            return pairs, stale
        s = cache[best][1]
        if free[s]:
            pairs.append((best, s))
            used[best] = True
            free[s] = False
        else:
            stale += 1
            cache[best] = row_min(best)


def tail_cycles(events, stale: int, no_slot: int) -> int:
    """Timing of the previous (unpipelined) RTL, kept for comparison: tp_eof high in
    cycle c -> the frame's last event valid in cycle c + lat (a plain register would
    be lat = 1), for a frame with these events (m moves, l lifts, n news), ``stale``
    stale picks (:func:`lazy_greedy`) and ``no_slot`` new touches without a free
    slot: MATCH m + 2 stale + 1, LIFT l + 1, NEW n + no_slot + 1, holding register 1.
    The pipelined RTL (125 MHz) takes m + l + n + 7 without stale picks when the last
    touch came the cycle before tp_eof; its exact cycle model is ``tail_latency`` in
    tb/fmt_tracker/test_fmt_tracker.py."""
    return len(events) + 2 * stale + no_slot + 4


def track_fixed(touch_frames, params: TrackParams, first_frame: int = 0, tracker: Tracker | None = None):
    """Track a sequence of frames.  ``touch_frames``: list (per frame) of touches, or of
    ``(frame_number, touches)`` pairs.  Returns a list (per frame) of event lists."""
    tr = tracker or Tracker(params)
    out = []
    for i, item in enumerate(touch_frames):
        if isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], (int, np.integer)):
            fr, ts = int(item[0]), item[1]
        else:
            fr, ts = (first_frame + i) & 0xFFFF, item
        out.append(tr.step(fr, ts))
    return out

