"""Frame-matching model: the hard cases of the brief (drumroll, merge/split, crossing,
17 touches, flicker, hold-off expiry, ID allocation)."""
from __future__ import annotations

import math
import random

import numpy as np
import pytest

from fmt import params
from fmt.settings import TouchSettings
from fmt.tracker import Touch, TrackParams, Tracker, track_fixed

CFG = params.DEFAULT
FR = 1.0 / CFG.window_s          # 162.76 kHz frames
Q = 256 / CFG.pitch_mm           # Q8.8 units per mm


def tq(x_mm, y_mm, s=3000):
    return Touch(int(round(x_mm * Q)), int(round(y_mm * Q)), s)


def ids_of(evs, typ=None):
    return [e.id for e in evs if typ is None or e.type == typ]


def run(frames, p):
    return track_fixed(frames, p)


def test_conversion_defaults():
    p = TrackParams.from_settings(CFG, TouchSettings())
    # gates (issue #11 item 1), L1: (2 + sqrt 2) x 3 m/s x 6.144 us = 0.062928 mm a frame
    # (the finger sqrt 2 v T, its prediction 2 v T); + sqrt 2 x 2.5 mm of noise = 3.598481
    # mm = 184.24 Q8.8 units of a 5 mm cell -> 185; the step 0.062928 / 5 x 256 = 3.22 -> 4
    # (rounded up: bounds)
    assert p.max_jump_q == 185 and p.gate_step_q == 4
    assert (TrackParams().max_jump_q, TrackParams().gate_step_q) == (185, 4)
    assert p.hold_off_frames == 33
    assert p.vel_shift == 8                       # 326 frames -> 2^8
    # 3 m/s = 18.4 um/frame = 0.94 Q8.8 units = 3865 units of 2^-20 cells
    assert abs(p.max_speed_v - 3000 / FR / 5 * 2 ** 20) <= 0.5


def test_single_finger_move_and_lift():
    p = TrackParams(hold_off_frames=5)
    frames = [[tq(20 + 0.1 * k, 30)] for k in range(20)] + [[] for _ in range(10)]
    out = run(frames, p)
    assert [e.type for e in out[0]] == ["new"]
    for k in range(1, 20):
        assert [e.type for e in out[k]] == ["move"] and out[k][0].id == out[0][0].id
    # missing in frames 20..: lift exactly when miss reaches hold_off (frame 24)
    for k in range(20, 30):
        assert [e.type for e in out[k]] == (["lift"] if k == 24 else [])
    assert out[24][0].x_q == frames[19][0].x_q


def drumroll(on, off, n_taps, a=(40, 40), b=(50, 40)):
    """A and B alternately: A on for `on` frames, off for `off`, B on ..."""
    frames, who = [], []
    for k in range(n_taps):
        pos = a if k % 2 == 0 else b
        frames += [[tq(*pos)] for _ in range(on)]
        frames += [[] for _ in range(off)]
        who += ["AB"[k % 2]] * on + ["-"] * off
    return frames, who


@pytest.mark.parametrize("on_us,off_us", [(30000, 30000), (60, 60), (30, 15), (30, 0), (300, 0)])
def test_drumroll_stays_two_contacts(on_us, off_us):
    """A B A B 10 mm apart never becomes one moving contact: no event of one tap's ID
    at the other finger's place, and each tap's events stay at its finger.  At 30 ms
    on/off each tap is a new contact; with gaps shorter than the hold-off, the two
    contacts keep their own IDs across taps (flicker absorption), still two; also when
    one lands in the frame the other lifts (off 0: the gates of issue #11 item 1, a 15 mm
    gate made them one moving contact)."""
    p = TrackParams.from_settings(CFG, TouchSettings())
    on, off = round(on_us * 1e-6 * FR), round(off_us * 1e-6 * FR)
    frames, who = drumroll(on, off, 6)
    out = run(frames, p)
    pos_of = {}
    for evs in out:
        for e in evs:
            place = "A" if e.x_q < 45 * Q else "B"
            assert pos_of.setdefault(e.id, place) == place, f"ID {e.id} jumped {place}"
            if e.type == "move":
                assert abs(e.x_q - round((40 if place == "A" else 50) * Q)) <= 1
    # exactly one contact per touching frame
    live = set()
    for evs in out:
        for e in evs:
            if e.type == "lift":
                live.discard(e.id)
            else:
                live.add(e.id)
        assert len(live) <= 2
    ids = {e.id for evs in out for e in evs}
    if on + 2 * off < p.hold_off_frames:          # each finger is away for on + 2 off frames
        assert len(ids) == 2                       # A and B keep their IDs
    else:
        assert len(ids) == 6                       # one per tap, none reused


def two_fingers(path_a, path_b, merge_mm=8.0, merged_at="mid"):
    """Touch lists for two finger paths (mm); closer than merge_mm they are reported as
    one touch (at the midpoint, or at finger A)."""
    frames = []
    for (xa, ya), (xb, yb) in zip(path_a, path_b):
        if ((xa - xb) ** 2 + (ya - yb) ** 2) ** 0.5 < merge_mm:
            if merged_at == "mid":
                frames.append([tq((xa + xb) / 2, (ya + yb) / 2)])
            else:
                frames.append([tq(xa + (xb - xa) / 3, ya + (yb - ya) / 3)])
        else:
            frames.append([tq(xa, ya), tq(xb, yb)])
    return frames


def check_follow(out, path_a, path_b, tol_mm=1.0):
    """Every event near finger A (B) has A's (B's) ID; returns the two ID sets."""
    ida, idb = set(), set()
    for k, evs in enumerate(out):
        for e in evs:
            if e.type == "lift":
                continue
            x, y = e.x_q / Q, e.y_q / Q
            da = abs(x - path_a[k][0]) + abs(y - path_a[k][1])
            db = abs(x - path_b[k][0]) + abs(y - path_b[k][1])
            if da < tol_mm and db > 3:
                ida.add(e.id)
            if db < tol_mm and da > 3:
                idb.add(e.id)
    assert not (ida & idb), f"IDs swapped: A {ida} B {idb}"
    return ida, idb


def test_merge_split_short_no_swap():
    """Two fingers pinch from 20 mm to 6 mm apart and spread again (smooth, zero speed
    at the closest point); closer than 8 mm they are one touch at the midpoint (the
    worst case: no hint which finger it is).  The merge (~360 frames) is shorter than
    the hold-off (4 ms = 651 frames).  No swap: the finger that carries the merged
    touch keeps its ID; the hidden one is predicted along its last velocity (it drifts
    ~4 mm while hidden here, beyond the hold-off gate) and so may come back as a new
    contact, but never with the other finger's ID."""
    p = TrackParams.from_settings(CFG, TouchSettings(hold_off_us=4000))
    n = 1500
    sep = [13 + 7 * math.cos(2 * math.pi * k / n) for k in range(n)]
    pa = [(50 - s / 2, 40) for s in sep]
    pb = [(50 + s / 2, 40) for s in sep]
    out = run(two_fingers(pa, pb), p)
    ida, idb = check_follow(out, pa, pb)
    assert len(ida) == 1 and 1 <= len(idb) <= 2


def test_merge_split_long_no_swap():
    """Merged for longer than the hold-off (default 200 us): B is lifted, the merged
    touch (nearer the stronger finger A) stays A, B comes back with a new ID: never
    A's ID on B's finger."""
    p = TrackParams.from_settings(CFG, TouchSettings())
    n = 3000
    sep = [20 - 14 * min(1, k / 600) if k < 1500 else 6 + 14 * min(1, (k - 1500) / 600)
           for k in range(n)]
    pa = [(50 - s / 2, 40) for s in sep]
    pb = [(50 + s / 2, 40) for s in sep]
    out = run(two_fingers(pa, pb, merged_at="a"), p)
    ida, idb = check_follow(out, pa, pb)
    assert len(ida) == 1 and len(idb) == 2
    assert any(e.type == "lift" and e.id in idb for evs in out for e in evs)


def test_fast_crossing_follows_velocity():
    """Two fingers crossing at 1 m/s each on one line, reported as one touch while
    closer than 8 mm; with a hold-off covering the merge the hidden finger's
    prediction carries its ID across, and both IDs keep following their fingers."""
    p = TrackParams.from_settings(CFG, TouchSettings(hold_off_us=6000))
    v = 1000.0 / FR                  # mm per frame
    n = int(40 / (2 * v))            # from 40 mm apart to 40 mm apart (crossed)
    pa = [(30 + v * k, 40) for k in range(n + 300)]
    pb = [(70 - v * k, 40 + 0.0) for k in range(n + 300)]
    out = run(two_fingers(pa, pb), p)
    ida, idb = check_follow(out, pa, pb)
    assert len(ida) == 1 and len(idb) == 1
    # and without the velocity prediction (window 1 frame -> gain 1: single-frame
    # differences) the noise-free case still works, but a stationary hidden contact
    # would be left behind: check that prediction is what carried B
    hold_moves = [e for evs in out for e in evs if e.type == "move" and e.id in idb]
    assert hold_moves


def test_17_touches_limit_16():
    p = TrackParams(max_touches=16)
    frame = [tq(10 + 8 * (i % 6), 10 + 8 * (i // 6)) for i in range(17)]
    tr = Tracker(p)
    out = track_fixed([frame, frame], p, tracker=tr)
    assert len(out[0]) == 16 and all(e.type == "new" for e in out[0])
    assert len(set(ids_of(out[0]))) == 16
    assert len(out[1]) == 16 and all(e.type == "move" for e in out[1])
    assert tr.stats.dropped_touches == 2
    # 16 live contacts + one more touch in a later frame: no slot, counted
    tr2 = Tracker(p)
    out = track_fixed([frame[:16], frame[:17][::-1][:1] + frame[:16]], p, tracker=tr2)
    assert tr2.stats.no_slot == 0                  # 17 given -> 16 kept (first 16)
    tr3 = Tracker(p)
    f16 = frame[:16]
    extra = tq(120, 100)
    track_fixed([f16, f16 + [extra]], p, tracker=tr3)
    assert tr3.stats.dropped_touches == 1
    tr4 = Tracker(TrackParams(max_touches=4))
    track_fixed([[tq(10, 10), tq(30, 10), tq(50, 10), tq(70, 10)],
           [tq(10, 10), tq(30, 10), tq(50, 10), tq(70, 10)]], tr4.p, tracker=tr4)
    ids = ids_of(track_fixed([[tq(10, 10), tq(30, 10), tq(50, 10), tq(70, 10)]], tr4.p,
                             tracker=tr4)[0])
    out = track_fixed([[tq(10, 10), tq(30, 10), tq(100, 50), tq(50, 10)]], tr4.p, tracker=tr4)
    # (70,10) is in hold-off and the only slot (100,50) can have: lifted for it
    assert tr4.stats.no_slot == 0 and tr4.stats.evictions == 1
    assert [e.type for e in out[0]] == ["move", "move", "move", "lift", "new"]
    assert out[0][3].id == ids[3] and out[0][4].id != ids[3]
    # a touch finds a slot whenever the frame has no more touches than slots: every
    # slot not matched is free, lifted or in hold-off


def test_new_touches_take_slots_in_hold_off():
    """More new touches than free slots while contacts are in hold-off (issue #11 item
    3): each takes the slot of the contact seen longest ago (lifted first), in arrival
    order; with the confirmation the new ones are tentative, so they are reported a frame
    later; contacts matched in the frame are never taken."""
    p = TrackParams(max_touches=4, hold_off_frames=33, confirm_frames=2)
    tr = Tracker(p)
    old = [tq(10, 10), tq(30, 10), tq(50, 10), tq(70, 10)]
    track_fixed([old, old, old], p, tracker=tr)                # four confirmed contacts
    ids = ids_of(track_fixed([old], p, tracker=tr)[0])
    track_fixed([old[:2]], p, tracker=tr)                      # (50,10), (70,10) missing
    track_fixed([[old[0]]], p, tracker=tr)                     # then (30,10) too
    new = [tq(100, 60), tq(130, 60), tq(160, 60)]
    out = track_fixed([[old[0]] + new], p, tracker=tr)[0]
    lifts = [e.id for e in out if e.type == "lift"]
    assert lifts == [ids[2], ids[3], ids[1]]                   # seen longest ago first
    assert [e.type for e in out] == ["move", "lift", "lift", "lift"]   # news tentative
    assert tr.stats.evictions == 3 and tr.stats.no_slot == 0
    out = track_fixed([[old[0]] + new], p, tracker=tr)[0]
    assert [e.type for e in out] == ["move", "new", "new", "new"]
    assert ids[0] in ids_of(out)


def test_flicker_absorbed():
    """A touch just above threshold flickering on and off (off runs shorter than the
    hold-off): one ID, one new event, one lift at the very end."""
    p = TrackParams.from_settings(CFG, TouchSettings())
    rng = random.Random(3)
    frames = []
    for k in range(3000):
        on = rng.random() < 0.6
        jitter = rng.uniform(-0.2, 0.2)
        frames.append([tq(77 + jitter, 33 - jitter)] if on or k == 0 else [])
    # ensure no off-run reaches the hold-off
    run_len = 0
    for f in frames:
        run_len = 0 if f else run_len + 1
        assert run_len < p.hold_off_frames
    frames += [[] for _ in range(p.hold_off_frames)]
    out = run(frames, p)
    evs = [e for f in out for e in f]
    assert [e.type for e in evs].count("new") == 1
    assert [e.type for e in evs].count("lift") == 1 and evs[-1].type == "lift"
    assert len({e.id for e in evs}) == 1


def test_ids_not_reused_immediately():
    """40 taps at one place, each longer apart than the hold-off: 40 distinct IDs; the
    round-robin slot choice spreads them over the slots."""
    p = TrackParams(hold_off_frames=3)
    frames = []
    for _ in range(40):
        frames += [[tq(50, 50)]] * 4 + [[]] * 5
    out = run(frames, p)
    news = [e.id for f in out for e in f if e.type == "new"]
    assert len(news) == 40 and len(set(news)) == 40


def test_velocity_clamp_and_prediction():
    """A finger moving at constant speed: the prediction error converges to < 1 Q8.8
    unit; velocity beyond the clamp is limited to max_speed_v."""
    p = TrackParams(vel_shift=4, hold_off_frames=50, max_speed_v=1 << 20)
    tr = Tracker(p)
    frames = [[Touch(1000 + 3 * k, 2000 - 2 * k)] for k in range(200)]
    track_fixed(frames, p, tracker=tr)
    s = next(s for s in tr.slots if s.active)
    assert abs(s.vx - (3 << p.vel_frac)) < 64 and abs(s.vy + (2 << p.vel_frac)) < 64
    p2 = TrackParams(vel_shift=4, max_speed_v=1 << p.vel_frac, hold_off_frames=50)
    tr2 = Tracker(p2)
    track_fixed(frames, p2, tracker=tr2)
    s2 = next(s for s in tr2.slots if s.active)
    assert s2.vx == 1 << p.vel_frac and s2.vy == -(1 << p.vel_frac)


def test_greedy_global_order_and_tiebreak():
    """Two contacts, two touches: the globally nearest pair is matched first even when
    the first touch's nearest contact is that pair's contact."""
    p = TrackParams(max_jump_q=1000)
    tr = Tracker(p)
    track_fixed([[Touch(1000, 1000), Touch(1400, 1000)]], p, tracker=tr)
    ida, idb = tr.slot_id(0), tr.slot_id(1)
    # touch 0 at 1250 is nearer contact B (150) than A (250); touch 1 at 1390 is nearer
    # B (10): greedy global gives B <- touch 1, A <- touch 0
    out = track_fixed([[Touch(1250, 1000), Touch(1390, 1000)]], p, tracker=tr)[0]
    got = {e.id: e.x_q for e in out}
    assert got == {ida: 1250, idb: 1390}
    assert [e.x_q for e in out] == [1390, 1250]       # match order = increasing distance
    # exact tie: equal distances -> lower touch index first, then lower slot
    tr = Tracker(p)
    track_fixed([[Touch(1000, 1000), Touch(1200, 1000)]], p, tracker=tr)
    out = track_fixed([[Touch(1100, 1000), Touch(1300, 1000)]], p, tracker=tr)[0]
    assert [(e.id, e.x_q) for e in out] == [(tr.slot_id(0), 1100), (tr.slot_id(1), 1300)]


def flat_greedy(dm):
    """Greedy nearest pairs by the flat argmin over the whole matrix (Tracker.step)."""
    from fmt.tracker import NO_CAND
    dm = dm.copy()
    n = dm.shape[1]
    pairs = []
    while dm.size and dm.min() != NO_CAND:
        t, s = divmod(int(np.argmin(dm)), n)
        pairs.append((t, s))
        dm[t, :] = NO_CAND
        dm[:, s] = NO_CAND
    return pairs


@pytest.mark.parametrize("seed", range(4))
def test_lazy_greedy_is_greedy(seed):
    """The RTL's lazily refreshed per-touch minima pick exactly the flat greedy pairs,
    in the same order, including ties (small distance ranges force many)."""
    from fmt.tracker import NO_CAND, lazy_greedy
    rng = np.random.default_rng(seed)
    stale_seen = 0
    for _ in range(400):
        nt, ns = int(rng.integers(0, 17)), int(rng.integers(1, 17))
        dm = rng.integers(0, int(rng.choice([3, 20, 65536])), size=(nt, ns)).astype(np.int64)
        dm[rng.random((nt, ns)) < rng.random()] = NO_CAND
        pairs, stale = lazy_greedy(dm)
        assert pairs == flat_greedy(dm)
        assert stale <= nt * (nt - 1) // 2     # once per remaining touch per assignment
        stale_seen += stale
    assert stale_seen > 0


def test_lazy_greedy_worst_case():
    """All touches ranking the slots alike: every remaining touch goes stale after each
    assignment, 15 + 14 + ... + 1 = 120 stale picks at 16 x 16."""
    from fmt.tracker import lazy_greedy
    n = 16
    dm = np.array([[100 * s + t for s in range(n)] for t in range(n)], dtype=np.int64)
    pairs, stale = lazy_greedy(dm)
    assert pairs == [(t, t) for t in range(n)]
    assert stale == n * (n - 1) // 2
    # spread fingers, each nearest its own slot: no stale pick
    dm = np.array([[abs(s - t) * 500 + 3 for s in range(n)] for t in range(n)], dtype=np.int64)
    assert lazy_greedy(dm)[1] == 0


def test_confirmation_and_activation():
    """A touch seen in fewer than confirm_frames frames never becomes a contact (no new,
    no lift); one seen confirm_frames frames is reported 'new' in the last of them; a
    touch below on_threshold starts no contact, a contact continues below it."""
    p = TrackParams(on_threshold=2500, confirm_frames=3, hold_off_frames=3)
    a, ghost = tq(40, 40, 9000), tq(40, 49, 2600)
    frames = [[a, ghost], [a], [a], [a], [tq(40, 40, 2100)], [], [], [],
              [tq(90, 40, 2400)] * 1, [tq(90, 40, 2400)], [tq(90, 40, 2400)],   # weak: never
              [tq(60, 60, 8000)], [tq(60, 60, 8000)], [], []]                     # 2 frames: never
    out = run(frames, p)
    types = [[e.type for e in f] for f in out]
    assert types[:5] == [[], [], ["new"], ["move"], ["move"]], types
    assert sum(t.count("lift") for t in types) == 1 and sum(t.count("new") for t in types) == 1
    # confirm_frames = 1, on_threshold = 0: the old behaviour, the ghost is a contact
    out1 = run(frames, TrackParams(hold_off_frames=3))
    assert sum(e.type == "new" for f in out1 for e in f) == 4


def test_tap_ghosts_sample():
    """Alternating taps 8 / 20 mm apart through the signal chain (scripts/tap_ghosts.py,
    a sample of its sweep): no ghost with the default confirmation; with it off and no
    activation threshold the transition frames give ghosts (the check can fail)."""
    import importlib.util
    from pathlib import Path
    path = Path(__file__).resolve().parents[2] / "scripts" / "tap_ghosts.py"
    spec = importlib.util.spec_from_file_location("tap_ghosts", path)
    tg = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tg)
    kw = dict(timings=((20, 0),), angles=(0.0,), quiet=True)    # B lands as A lifts
    on = tg.run([8, 20], [1], None, **kw)
    assert on["ghosts"] == 0 and on["swaps"] == 0 and on["lost"] == 0, on
    off = tg.run([8, 20], [1], TouchSettings(confirm_frames=1, on_threshold=0), **kw)
    assert off["ghosts"] > 0, off


def test_crowding_sample():
    """N + 1 fingers under a limit of N (scripts/crowding.py, a sample): the same N
    contacts in every frame, no new ID, no lift; without the ranking's hysteresis the
    count drops below N in some frames (the check can fail)."""
    import importlib.util
    from pathlib import Path
    from fmt import localmax
    path = Path(__file__).resolve().parents[2] / "scripts" / "crowding.py"
    spec = importlib.util.spec_from_file_location("crowding", path)
    cr = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cr)
    on = cr.run([1], [16], 200, quiet=True)
    assert on["frames_not_n"] == 0 and on["new_ids"] == 0 and on["lifts"] == 0, on
    saved = localmax.near_mask
    localmax.near_mask = lambda shape, prev: np.zeros(shape, dtype=bool)
    try:
        off = cr.run([1], [16], 200, quiet=True)
    finally:
        localmax.near_mask = saved
    assert off["frames_not_n"] > 0, off
