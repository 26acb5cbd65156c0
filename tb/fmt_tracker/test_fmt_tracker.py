"""cocotb testbench of rtl/fmt_tracker.v against its twin sim/fmt/tracker.py.

Every frame's events (id, type, x, y, strength, axes, angle, flags, ev_last, in order)
must equal Tracker.step's, for: random touch streams (wandering fingers that appear,
vanish and flicker, random order, more than MAX_TOUCHES touches, random settings) and
scripted scenarios on a scaled timeline (drumroll, merge/split, fast crossing,
flicker, hold-off expiry, 17 touches with 16 slots), plus a reset in the middle of a
frame.  Also measures and checks the tail latency: the frame's last event is on the
output exactly tail_latency cycles after the tp_eof cycle (a cycle model of the RTL's
pipeline: the last touch's key reaches the sorted queue SB + 3 cycles after it came,
match_cycles replays the queue's assignments and stale pops on the model's candidate
matrix, then, with lifts or news, one cycle and one per lift and new), and that busy_o
falls 4 cycles after that (h + 5 with h contacts in hold-off, updated one per cycle).
The worst case of the match (all touches ranking the slots alike, 120 stale pops at
16) is a test of its own; the lazy model's stale picks (fmt.tracker.lazy_greedy) are logged beside.
"""
from __future__ import annotations

import math
import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import long_run, run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt import params
from fmt.tracker import NO_CAND, Touch, Tracker, TrackParams, lazy_greedy


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.mt = env_int("MAX_TOUCHES", 16)
        self.hm_w = env_int("HM_W", 16)
        self.cycle = 0
        self.events = []          # (cycle, tuple)
        self.eof_cycles = []
        self.stale_total = 0      # stale picks of the lazy match (model count)
        self.idle_cycle = 0
        self.last_touch = None    # edge that sampled the frame's last touch
        self.idle()
        cocotb.start_soon(self._count())
        cocotb.start_soon(self._monitor())

    def idle(self):
        d = self.dut
        d.tp_valid_i.value = 0
        d.tp_eof_i.value = 0
        for n in ("tp_frame_i", "tp_x_i", "tp_y_i", "tp_strength_i", "tp_axis_major_i",
                  "tp_axis_minor_i", "tp_angle_i", "tp_flags_i"):
            getattr(d, n).value = 0

    def set_params(self, p: TrackParams):
        d = self.dut
        d.max_jump_i.value = p.max_jump_q
        d.gate_step_i.value = p.gate_step_q
        d.hold_off_i.value = p.hold_off_frames
        d.vel_shift_i.value = p.vel_shift
        d.max_speed_i.value = p.max_speed_v
        d.on_thr_i.value = p.on_threshold
        d.confirm_i.value = p.confirm_frames

    async def _count(self):
        while True:
            await RisingEdge(self.clk)
            self.cycle += 1

    async def _monitor(self):
        d = self.dut
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            rst, v = d.rst.value, d.ev_valid_o.value
            if not (rst.is_resolvable and v.is_resolvable):
                continue                      # before the first reset
            if int(rst) == 0 and int(v):
                self.events.append((self.cycle, (
                    int(d.ev_frame_o.value), int(d.ev_id_o.value), int(d.ev_type_o.value),
                    int(d.ev_x_o.value), int(d.ev_y_o.value), int(d.ev_strength_o.value),
                    int(d.ev_axis_major_o.value), int(d.ev_axis_minor_o.value),
                    int(d.ev_angle_o.value), int(d.ev_flags_o.value)),
                    int(d.ev_last_o.value)))

    async def send_frame(self, frame: int, touches, rng: random.Random | None = None,
                         eof_with_last: bool = False):
        """Drive one frame's touches (random gaps when rng) then tp_eof (in the cycle of
        the last touch when eof_with_last); wait until the tracker is idle.  Returns
        the cycle of tp_eof."""
        d = self.dut
        await self.writable()
        self.last_touch = None
        for i, t in enumerate(touches):
            if eof_with_last and i == len(touches) - 1:
                d.tp_eof_i.value = 1
            d.tp_valid_i.value = 1
            d.tp_frame_i.value = frame
            d.tp_x_i.value = t.x_q
            d.tp_y_i.value = t.y_q
            d.tp_strength_i.value = t.strength
            d.tp_axis_major_i.value = t.axis_major_q
            d.tp_axis_minor_i.value = t.axis_minor_q
            d.tp_angle_i.value = t.angle
            d.tp_flags_i.value = t.flags
            await RisingEdge(self.clk)
            if eof_with_last and i == len(touches) - 1:
                break
            await self.writable()
            if i < self.mt:
                self.last_touch = self.cycle  # the edge that sampled this (kept) touch
            if rng and rng.random() < 0.3:
                d.tp_valid_i.value = 0
                for _ in range(rng.randrange(1, 3)):
                    await RisingEdge(self.clk)
                await self.writable()
        else:
            d.tp_valid_i.value = 0
            d.tp_eof_i.value = 1
            d.tp_frame_i.value = frame
            await RisingEdge(self.clk)
        await ReadOnly()
        eof = self.cycle               # the edge that samples tp_eof
        if eof_with_last and 0 < len(touches) <= self.mt:
            self.last_touch = eof
        await self.writable()
        d.tp_valid_i.value = 0
        d.tp_eof_i.value = 0
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if int(d.busy_o.value) == 0:
                break
        self.idle_cycle = self.cycle   # first cycle with busy_o low: the next frame's
        await self.writable()          # touches may come in this cycle (strictest case)
        return eof


def ev_tuple(e):
    return (e.frame, e.id, e.type_code, e.x_q, e.y_q, e.strength, e.axis_major_q,
            e.axis_minor_q, e.angle, e.flags)


def tree_stages(mt: int) -> int:
    """Stages of the RTL's row-minimum tree (one level each): SB = clog2(MAX_TOUCHES)."""
    return max(1, math.ceil(math.log2(mt)))


def match_cycles(dm, sb: int) -> tuple[int, int]:
    """Cycle model of the RTL's MATCH (rtl/fmt_tracker.v): a queue of the touches' cached
    keys (D, t, slot) sorted by (D, t); per cycle the head is assigned (fresh, nothing in
    flight), or popped for a recompute of its row minimum over the free slots (stale:
    its slot was taken; the new key is inserted at the end of the (sb + 1)-th cycle
    after the pop: request, sb tree stages; no pair is assigned while a recompute is
    in flight), or MATCH ends (queue
    empty, nothing in flight).  ``dm``: the model's candidate matrix (touch, slot).
    Returns (cycles from the first MATCH decision to the cycle that ends it, stale pops)."""
    nt, ns = dm.shape
    free = [True] * ns

    def row_min(t):
        best = None
        for s in range(ns):
            if free[s] and dm[t, s] != NO_CAND and (best is None or int(dm[t, s]) < best[0]):
                best = (int(dm[t, s]), s)
        return best

    q = []
    for t in range(nt):
        k = row_min(t)
        if k:
            q.append([k[0], t, k[1], False])
    q.sort(key=lambda e: (e[0], e[1]))
    due, busy_until, c, pops = {}, -1, 0, 0
    while True:
        head = q[0] if q else None
        if head is not None and head[3]:
            q.pop(0)
            pops += 1
            k = row_min(head[1])
            if k:
                due.setdefault(c + sb + 1, []).append([k[0], head[1], k[1], False])
            busy_until = max(busy_until, c + sb + 1)
        elif head is not None and c > busy_until:
            q.pop(0)
            free[head[2]] = False
            for e in q:
                if e[2] == head[2]:
                    e[3] = True
        elif head is None and c > busy_until:
            return c, pops
        for e in due.pop(c, []):
            q.append(e)
            q.sort(key=lambda x: (x[0], x[1]))
        c += 1


def tail_latency(ops, dm, eof: int, last_touch, sb: int) -> tuple[int, int]:
    """RTL timing: tp_eof sampled by edge ``eof`` -> the frame's last event on the output
    after edge eof + lat - 1 (a plain register would be lat = 1).  The last touch (edge
    ``last_touch``) has its key in the queue sb + 3 cycles later (A1 distances, A2 row
    write, sb tree stages, insert), MATCH starts the cycle after tp_eof: first decision
    d0 = max(1, last_touch + sb + 3 - eof) cycles after it; then match_cycles; then, if
    the frame has lifts or news, one cycle (they issue from the cycle after MATCH ends)
    and one cycle per lift and new (``ops`` = lift + new operations, also the tentative
    contacts' silent ones, plus one per eviction); the cycle that ends the events, and the event hold's cycle
    that marks the last event.  Returns (lat, stale pops)."""
    mc, pops = match_cycles(dm, sb) if dm is not None else (0, 0)
    d0 = max(1, last_touch + sb + 3 - eof) if last_touch is not None else 1
    return d0 + mc + ops + (1 if ops else 0) + 2, pops


async def run_frames(tb, p: TrackParams, frames, rng=None, start_frame=0, model=None,
                     eof_with_last=False):
    """Drive frames and compare every frame's events with the model's."""
    model = model or Tracker(p)
    tail = []
    for k, touches in enumerate(frames):
        fr = (start_frame + k) & 0xFFFF
        n0 = len(tb.events)
        eof = await tb.send_frame(fr, touches, rng, eof_with_last)
        got = tb.events[n0:]
        dm = model.candidates(touches) if touches else None
        _, stale = lazy_greedy(dm) if touches else ([], 0)
        exp = model.step(fr, touches)
        g = [x[1] for x in got]
        e = [ev_tuple(x) for x in exp]
        assert g == e, f"frame {fr}: RTL {g}\nmodel {e}"
        if got:
            assert [x[2] for x in got] == [0] * (len(got) - 1) + [1], "ev_last"
            # tp_eof high in cycle c (sampled by edge `eof`) -> last event valid in
            # cycle c + lat (a plain register would be lat = 1)
            lat = got[-1][0] - eof + 1
            # an eviction (a new touch taking a hold-off slot) costs one cycle more
            ops = model.stats.lift_ops + model.stats.new_ops + model.stats.evict_ops
            exp_lat, pops = tail_latency(ops, dm, eof, tb.last_touch, tree_stages(tb.mt))
            assert lat == exp_lat, \
                f"tail latency {lat} (model {exp_lat}) for {len(got)} events, {pops} stale pops"
            # the update of the h contacts in hold-off (active, missed this frame), one
            # issued per cycle, then the E2..E4 pipeline drains: busy_o low 3 cycles after
            # the last event (h = 0), h + 4 (h > 0)
            h = sum(1 for st in model.slots if st.active and st.miss > 0)
            assert tb.idle_cycle - got[-1][0] == (h + 4 if h else 3), "busy after the last event"
            tail.append((len(got), stale, pops, lat, tb.idle_cycle - eof))
        tb.stale_total += stale
    return model, tail


def q(mm):
    return int(round(mm * 256 / 5))


def rand_touch(rng, x, y):
    return Touch(max(0, min(0xFFFF, x)), max(0, min(0xFFFF, y)), rng.randrange(1 << 16),
                 rng.randrange(1 << 10), rng.randrange(1 << 10), rng.randrange(256),
                 rng.randrange(16))


@cocotb.test()
async def random_streams(dut):
    """Wandering fingers appearing / vanishing / flickering, random settings."""
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    mt = tb.mt
    for trial in range(3):
        p = TrackParams(max_jump_q=rng.choice([300, 768, 2000]),
                        gate_step_q=rng.choice([0, 3, 100, 0xFFFF]),   # 0xFFFF: saturates
                        hold_off_frames=rng.choice([1, 2, 4, 7]),
                        vel_shift=rng.choice([0, 1, 3, 8, 12]),
                        max_speed_v=rng.choice([1000, 1 << 16, (1 << 21) - 1]),
                        on_threshold=rng.choice([0, 0, 9000, 30000]),
                        confirm_frames=rng.choice([1, 1, 2, 3, 7]),
                        max_touches=mt)
        tb.set_params(p)
        await tb.reset()
        nf = mt + 3
        fingers = [[rng.randrange(100, 12000), rng.randrange(100, 8000),
                    rng.randrange(-40, 40), rng.randrange(-40, 40), rng.random() < 0.5]
                   for _ in range(nf)]
        frames = []
        for k in range(60 if mt > 8 else 80):
            ts = []
            for f in fingers:
                f[0] += f[2] + rng.randrange(-3, 4)
                f[1] += f[3] + rng.randrange(-3, 4)
                if rng.random() < 0.05:
                    f[4] = not f[4]
                if f[4] and rng.random() < 0.85:
                    ts.append(rand_touch(rng, f[0], f[1]))
            rng.shuffle(ts)
            if rng.random() < 0.05:
                ts = []
            frames.append(ts)
        _, tail = await run_frames(tb, p, frames, rng, start_frame=rng.randrange(1 << 16))
        dut._log.info(f"trial {trial}: tail latency (events, stale picks, cycles) max "
                      f"{max(tail, key=lambda x: x[3]) if tail else None}")
    dut._log.info(f"stale picks in all trials: {tb.stale_total}")


def two_finger_frames(pa, pb, merge_q, merged_at="mid"):
    frames = []
    for (xa, ya), (xb, yb) in zip(pa, pb):
        if abs(xa - xb) + abs(ya - yb) < merge_q:
            if merged_at == "mid":
                frames.append([Touch((xa + xb) // 2, (ya + yb) // 2, 5000)])
            else:
                frames.append([Touch(xa + (xb - xa) // 3, ya + (yb - ya) // 3, 5000)])
        else:
            frames.append([Touch(xa, ya, 5000), Touch(xb, yb, 4000)])
    return frames


@cocotb.test()
async def scripted_scenarios(dut):
    """Drumroll, merge/split, crossing, flicker, hold-off expiry on a scaled timeline
    (fingers move ~100x faster per frame than at 162.76 kHz)."""
    tb = TB(dut)
    rng = random.Random(7)
    mt = tb.mt
    base = dict(max_jump_q=q(15), gate_step_q=q(1), max_touches=mt)
    # drumroll A B A B 10 mm apart, off-time shorter and longer than the hold-off (gates
    # of a finger that moves ~0.25 mm a frame: 4 mm, + 0.5 mm per frame missed)
    for on, off, hold in ((4, 2, 10), (3, 6, 3)):
        p = TrackParams(hold_off_frames=hold, vel_shift=2, max_speed_v=1 << 16,
                        max_jump_q=q(4), gate_step_q=q(0.5), max_touches=mt)
        tb.set_params(p)
        await tb.reset()
        frames = []
        for k in range(6):
            pos = (q(40), q(40)) if k % 2 == 0 else (q(50), q(40))
            frames += [[Touch(pos[0], pos[1], 3000)]] * on + [[]] * off
        n0 = len(tb.events)
        model, _ = await run_frames(tb, p, frames)
        ids = {x[1][1] for x in tb.events[n0:]}
        assert len(ids) == (2 if 2 * off + on < hold else 6), ids
    # merge / split (pinch with slow-down) and crossing at speed
    p = TrackParams(hold_off_frames=12, vel_shift=2, max_speed_v=1 << 20, **base)
    tb.set_params(p)
    await tb.reset()
    n = 60
    sep = [13 + 7 * math.cos(2 * math.pi * k / n) for k in range(n)]
    pa = [(q(50 - s / 2), q(40)) for s in sep]
    pb = [(q(50 + s / 2), q(40)) for s in sep]
    await run_frames(tb, p, two_finger_frames(pa, pb, q(8)))
    await tb.reset()
    pa = [(q(30 + 1.5 * k), q(40)) for k in range(30)]
    pb = [(q(70 - 1.5 * k), q(40)) for k in range(30)]
    model, _ = await run_frames(tb, p, two_finger_frames(pa, pb, q(8)))
    # flicker: one touch on 60 % of frames (off runs < hold-off), then gone
    p = TrackParams(hold_off_frames=5, vel_shift=3, max_speed_v=1 << 16, **base)
    tb.set_params(p)
    await tb.reset()
    frames, run_len = [], 0
    for k in range(50):
        on = rng.random() < 0.6 or run_len >= 3
        run_len = 0 if on else run_len + 1
        frames.append([Touch(q(77) + rng.randrange(-3, 4), q(33), 2100)] if on else [])
    frames += [[]] * 6
    n0 = len(tb.events)
    await run_frames(tb, p, frames)
    types = [x[1][2] for x in tb.events[n0:]]
    assert types.count(0) == 1 and types.count(2) == 1      # one new, one lift


@cocotb.test()
async def confirm_and_activation(dut):
    """Confirmation and the activation threshold: touches that last fewer than
    confirm_frames frames (the transition ghosts beside a landing or lifting finger
    last one) never become contacts and leave no lift; a finger seen confirm_frames
    frames is reported ('new') in the last of them; a touch below on_threshold starts no
    contact, but a contact goes on below it.  Bit-exact with the model, tail latency
    included."""
    tb = TB(dut)
    mt = tb.mt
    for conf in (2, 3):
        p = TrackParams(max_jump_q=q(15), gate_step_q=q(1), hold_off_frames=4, vel_shift=2,
                        on_threshold=2500, confirm_frames=conf, max_touches=mt)
        tb.set_params(p)
        await tb.reset()
        A, B = (q(40), q(40)), (q(60), q(40))
        frames = [[Touch(*A, 7000), Touch(A[0], A[1] + q(9), 2600)]]       # A lands, a ghost
        frames += [[Touch(*A, 10000)] for _ in range(5)]
        frames += [[Touch(*A, 6000), Touch(A[0], A[1] - q(9), 2600)]]      # A lifts, a ghost
        frames += [[] for _ in range(6)]
        frames += [[Touch(*B, 2000)] for _ in range(4)]                     # too weak to start
        frames += [[Touch(*B, 9000)] for _ in range(4)]
        frames += [[Touch(*B, 2100)] for _ in range(4)]                     # fading: goes on
        frames += [[] for _ in range(6)]
        frames += [[Touch(q(80), q(80), 8000)] for _ in range(conf - 1)]    # a short blip
        frames += [[] for _ in range(3)]
        n0 = len(tb.events)
        await run_frames(tb, p, frames)
        got = [x[1] for x in tb.events[n0:]]
        news = [g for g in got if g[2] == 0]
        lifts = [g for g in got if g[2] == 2]
        assert [(g[0], g[3]) for g in news] == [(conf - 1, A[0]), (17 + conf - 1, B[0])], got
        assert len(lifts) == 2 and all(g[4] == A[1] or g[4] == B[1] for g in lifts), got
        moves_b = [g for g in got if g[2] == 1 and g[3] == B[0]]
        assert len(moves_b) == 4 - conf + 4, got          # B's moves, also the weak ones


@cocotb.test()
async def gate_boundaries(dut):
    """The match gates include their bound: a touch exactly max_jump (L1, Q8.8) from a
    contact seen last frame continues it, one unit farther starts a new contact; the gate
    of a contact missed for m frames is max_jump + m gate_step, exactly (one unit farther:
    a new contact, at the bound: a move).  No velocity (max_speed 0): the prediction is
    the last position, so the distances are exact."""
    tb = TB(dut)
    mj, st = 300, 40
    p = TrackParams(max_jump_q=mj, gate_step_q=st, hold_off_frames=6, vel_shift=0,
                    max_speed_v=0, max_touches=tb.mt)
    tb.set_params(p)
    await tb.reset()
    a0 = (2000, 1500)
    a1 = (a0[0] + mj - 40, a0[1] + 40)                  # D = max_jump from a0
    b0 = (a1[0] + mj + 1 - 40, a1[1] + 40)              # D = max_jump + 1 from a1
    frames = [[Touch(*a0, 3000)],
              [Touch(*a1, 3000)],                       # move
              [Touch(*b0, 3000)],                       # new B; A missed once
              [],                                       # A missed twice, B once
              [Touch(b0[0], b0[1] + mj + st + 1, 3000)],  # B's gate + 1: new C; B missed twice
              [Touch(b0[0] + mj + 2 * st, b0[1], 3000)]]  # B's gate (mj + 2 st): move
    n0 = len(tb.events)
    await run_frames(tb, p, frames)
    per = {}
    for _, e, _ in tb.events[n0:]:
        per.setdefault(e[0], []).append((e[1], e[2]))    # frame -> [(id, type)]
    new, move = 0, 1
    first_id = per[0][0][0]
    assert per[0] == [(first_id, new)]
    assert per[1] == [(first_id, move)], f"D = max_jump must match: {per[1]}"
    assert [t for _, t in per[2]] == [new] and per[2][0][0] != first_id, \
        f"D = max_jump + 1 must not match: {per[2]}"
    second_id = per[2][0][0]
    assert [t for _, t in per[4]] == [new] and per[4][0][0] not in (first_id, second_id), \
        f"D = max_jump + gate_step + 1 after one missed frame must not match: {per[4]}"
    assert per[5] == [(second_id, move)], \
        f"D = max_jump + 2 gate_step after two missed frames must match: {per[5]}"


@cocotb.test()
async def over_limit_touches(dut):
    """MAX_TOUCHES + 1 touches in a frame, then a new touch while all slots are taken,
    one by a contact in hold-off: that contact is lifted for it (no touch without a slot)."""
    tb = TB(dut)
    mt = tb.mt
    p = TrackParams(hold_off_frames=3, vel_shift=4, max_touches=mt)
    tb.set_params(p)
    await tb.reset()
    full = [Touch(q(10 + 9 * (i % 8)), q(10 + 9 * (i // 8)), 1000 + i) for i in range(mt + 1)]
    frames = [full, full, full[:mt - 1], full[:mt - 1] + [Touch(q(190), q(140), 77)], [], [], []]
    model, _ = await run_frames(tb, p, frames)
    assert model.stats.evictions == 1 and model.stats.no_slot == 0
    assert int(dut.drop_flag_o.value) == 1
    assert int(dut.noslot_flag_o.value) == 0
    assert int(dut.overrun_flag_o.value) == 0


@cocotb.test()
async def hold_off_eviction(dut):
    """More new touches than free slots while contacts are in hold-off: each takes the
    slot of the contact seen longest ago (its lift first), with and without the
    confirmation; contacts that lost their touch in different frames, and in one frame
    (then the order of their last moves decides)."""
    tb = TB(dut)
    mt = tb.mt
    for confirm in (1, 2):
        p = TrackParams(hold_off_frames=20, vel_shift=4, confirm_frames=confirm, max_touches=mt)
        tb.set_params(p)
        await tb.reset()
        old = [Touch(q(10 + 12 * (i % 8)), q(10 + 12 * (i // 8)), 3000 + 7 * i) for i in range(mt)]
        new = [Touch(q(15 + 12 * (i % 8)), q(100 + 12 * (i // 8)), 5000 + i) for i in range(mt)]
        h = mt // 2
        frames = [old] * 3 + [old[:h + 1]] * 2 + [old[:h]] * 2
        frames += [old[:h - 1] + new[:h + 1]] * 3          # h + 1 new: h + 1 evictions
        frames += [new[:mt]] * 3                           # the rest: the last hold-offs go
        model, _ = await run_frames(tb, p, frames)
        # every old contact made room for a new one (h + 1, then the other mt - h - 1)
        assert model.stats.evictions == mt and model.stats.no_slot == 0
        dut._log.info(f"confirm {confirm}: {model.stats.evictions} evictions")
    assert int(dut.noslot_flag_o.value) == 0


@cocotb.test()
async def match_timing(dut):
    """Tail latency of 1, 3 and MAX_TOUCHES spread moving fingers (no stale pick), and
    the worst case of the lazy match: every touch ranks the slots alike (slots on a
    line, all touches left of it), MT(MT-1)/2 stale picks."""
    tb = TB(dut)
    mt = tb.mt
    p = TrackParams(max_jump_q=0xFFFF, gate_step_q=0xFFFF, hold_off_frames=2, vel_shift=3,
                    max_touches=mt)
    tb.set_params(p)
    for n in sorted({1, min(3, mt), mt}):
        await tb.reset()
        frames = [[Touch(q(10 + 12 * (i % 8)) + 40 * k, q(10 + 12 * (i // 8)) + 25 * k, 900 + i)
                   for i in range(n)] for k in range(4)]
        _, tail = await run_frames(tb, p, frames)
        dut._log.info(f"{n} spread fingers: (events, stale picks, stale pops, tail cycles, tp_eof -> idle) {tail}")
        assert all(st == 0 and sp == 0 for _, st, sp, _, _ in tail[1:])
    await tb.reset()
    slots = [Touch(1000 + 300 * s, 2000, 100 + s) for s in range(mt)]
    worst = [Touch(999 - t, 2000, 500 + t) for t in range(mt)]
    _, tail = await run_frames(tb, p, [slots, worst])
    dut._log.info(f"worst case: (events, stale picks, stale pops, tail cycles, tp_eof -> idle) {tail}")
    assert tail[1][1] == mt * (mt - 1) // 2 and tail[1][2] == mt * (mt - 1) // 2
    # the last touch in the tp_eof cycle: its row minimum is cached one cycle later
    await tb.reset()
    _, tail = await run_frames(tb, p, [slots, worst, worst[::-1], [], slots[1:]],
                               eof_with_last=True)
    dut._log.info(f"last touch with tp_eof: (events, stale picks, stale pops, tail cycles, tp_eof -> idle) {tail}")


@cocotb.test()
async def reset_mid_frame(dut):
    """A reset while the tracker is matching: afterwards it behaves like a fresh one."""
    tb = TB(dut)
    mt = tb.mt
    p = TrackParams(hold_off_frames=2, vel_shift=2, max_touches=mt)
    tb.set_params(p)
    await tb.reset()
    ts = [Touch(q(10 + 9 * i), q(20), 500) for i in range(min(mt, 6))]
    await run_frames(tb, p, [ts, ts])
    # third frame: cut by a reset right after tp_eof
    d = tb.dut
    await tb.writable()
    for t in ts:
        d.tp_valid_i.value = 1
        d.tp_x_i.value = t.x_q
        d.tp_y_i.value = t.y_q
        await RisingEdge(tb.clk)
        await tb.writable()
    d.tp_valid_i.value = 0
    d.tp_eof_i.value = 1
    await RisingEdge(tb.clk)
    await tb.writable()
    d.tp_eof_i.value = 0
    await RisingEdge(tb.clk)
    await RisingEdge(tb.clk)
    await tb.reset(cycles=1)
    await run_frames(tb, p, [ts, ts[:2], [], [], []], start_frame=100)


# ---- pytest entry ------------------------------------------------------------------
@pytest.mark.parametrize("cfg_name,max_touches", [("small", 5), ("medium", 16)])
def test_fmt_tracker(sim, cfg_name, max_touches):
    if sim == "icarus" and cfg_name != "small" and not long_run():
        pytest.skip("make test: both sizes under Verilator, the small one under Icarus; "
                    "medium under Icarus in make test-long (FMT_LONG=1), for make test's time")
    cfg = params.get(cfg_name)
    run_cocotb(
        sim=sim,
        toplevel="fmt_tracker",
        sources=sources("fmt_tracker"),
        test_module="test_fmt_tracker",
        test_dir=Path(__file__).parent,
        parameters={"MAX_TOUCHES": max_touches, "HM_W": cfg.hm_width},
        extra_env={"MAX_TOUCHES": max_touches, "HM_W": cfg.hm_width, "SEED": 1},
    )
