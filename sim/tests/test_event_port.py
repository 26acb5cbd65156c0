"""Event-port model: exact dial-a-latency, decimation, whole-frame drops under stalls."""
from __future__ import annotations

import random

import pytest

from fmt.event_port import FIXED_LATENCY, EventPort, PortOut, PortParams, frames_to_beats, run_port
from fmt.tracker import TouchEvent


def mk_frames(n_frames, rng, max_ev=6):
    out = []
    for f in range(n_frames):
        k = rng.randrange(0, max_ev + 1)
        out.append([TouchEvent(f, i, "move", rng.randrange(1 << 16), rng.randrange(1 << 16))
                    for i in range(k)])
    return out


def frames_out(outs):
    """Group output beats into frames using ev_last."""
    fr, cur = [], []
    for o in outs:
        cur.append(o.event)
        if o.last:
            fr.append(cur)
            cur = []
    assert not cur, "stream ended inside a frame"
    return fr


@pytest.mark.parametrize("delay", [0, 1, 7, 500])
def test_exact_delay(delay):
    rng = random.Random(delay)
    frames = mk_frames(40, rng)
    beats = frames_to_beats(frames, start=5, period=40)
    outs, port = run_port(beats, 40 * 40 + delay + 100, delay=delay,
                          p=PortParams(depth=64, max_ev=8))
    inv = {id(b[0]): c for c, b in beats.items()}
    assert len(outs) == len(beats)
    for o in outs:
        c = inv[id(o.event)]
        assert o.cycle == c + FIXED_LATENCY + delay
        assert o.time == c
    assert port.drop_count == 0 and port.skip_count == 0


def test_max_delay_at_full_rate():
    """Frames of max_ev events every F cycles: a delay up to (depth/max_ev - 1) frames
    loses nothing; one more frame of delay drops frames (whole, counted)."""
    p = PortParams(depth=64, max_ev=8)
    F = 20
    rng = random.Random(1)
    frames = [[TouchEvent(f, i, "move", rng.randrange(99), 0) for i in range(8)]
              for f in range(60)]
    beats = frames_to_beats(frames, period=F)
    dmax = (p.depth // p.max_ev - 1) * F - 8
    outs, port = run_port(beats, 60 * F + dmax + 50, delay=dmax, p=p)
    assert port.drop_count == 0 and len(outs) == 480
    outs, port = run_port(beats, 60 * F + dmax + 50 + 2 * F, delay=dmax + 2 * F, p=p)
    assert port.drop_count > 0 and port.overflow
    got = frames_out(outs)
    assert all(len(g) == 8 for g in got)
    assert len(got) + port.drop_count == 60


def test_decimation():
    """report_period R: a frame is admitted only R cycles after the last admitted one."""
    rng = random.Random(2)
    frames = [[TouchEvent(f, 0, "move", 1, 1)] + [TouchEvent(f, 1, "move", 2, 2)]
              for f in range(50)]
    beats = frames_to_beats(frames, period=30)
    outs, port = run_port(beats, 50 * 30 + 20, report_period=100)
    got = frames_out(outs)
    # admitted frames: 0, 4, 8, ... (120 >= 100 cycles apart, 90 is not)
    assert [g[0].frame for g in got] == list(range(0, 50, 4))
    assert port.skip_count == 50 - len(got) and port.drop_count == 0


def test_stall_drops_whole_frames_never_corrupts():
    rng = random.Random(5)
    frames = mk_frames(300, rng, max_ev=8)
    beats = frames_to_beats(frames, period=12)
    n = 300 * 12 + 400
    ready = [1 if (c // 97) % 3 else 0 for c in range(n)]     # long stalls
    ready = [r if rng.random() < 0.7 else 0 for r in ready]
    p = PortParams(depth=32, max_ev=8)
    outs, port = run_port(beats, n, ready=ready, p=p)
    got = frames_out(outs)
    sent = [f for f in frames if f]
    # the output is a subsequence of whole input frames, in order, unchanged
    it = iter(sent)
    for g in got:
        for f in it:
            if f[0].frame == g[0].frame:
                assert [e.key() for e in f] == [e.key() for e in g]
                break
        else:
            raise AssertionError("frame out of order or corrupted")
    assert port.drop_count > 0
    assert len(got) + port.drop_count == len(sent)
    # valid/ready: handshakes only on ready cycles
    assert all(ready[o.cycle] for o in outs)


def test_reset_mid_frame():
    """A reset (shared with the tracker, which then stops the cut frame) in the middle
    of frame 10: everything in flight is gone, frames before it that were already out
    are whole, later frames come out whole and on time again."""
    rng = random.Random(9)
    frames = [[TouchEvent(f, i, "move", i, f) for i in range(4)] for f in range(20)]
    beats = frames_to_beats(frames, period=20)
    beats = {c: b for c, b in beats.items() if not 203 < c < 220}   # tracker reset too
    outs, port = run_port(beats, 20 * 20 + 50, delay=30, reset_at=[203])
    got = frames_out([o for o in outs if o.cycle < 203 or o.cycle > 203])
    fr = [g[0].frame for g in got]
    # before: frames whose last event left before the reset (c + 5 + 30 < 203)
    assert fr == [f for f in range(20) if 20 * f + 3 + FIXED_LATENCY + 30 < 203 or f >= 11]
    for g in got:
        assert [e.key() for e in frames[g[0].frame]] == [e.key() for e in g]
    # time stamps restart at the reset
    first_after = next(o for o in outs if o.cycle > 203)
    assert first_after.time == 220 - 204


def test_long_delay_with_report_period():
    """The Pong case, scaled: with a report period R the loss-free delay is
    (depth / max_ev - 1) x R cycles (full frames arriving faster than R)."""
    p = PortParams(depth=64, max_ev=8)
    R, F = 50, 10
    frames = [[TouchEvent(f, i, "move", i, f) for i in range(8)] for f in range(200)]
    beats = frames_to_beats(frames, period=F)
    d = (p.depth // p.max_ev - 1) * R - p.max_ev
    outs, port = run_port(beats, 200 * F + d + 100, delay=d, report_period=R, p=p)
    assert port.drop_count == 0 and port.skip_count == 200 - 40
    got = frames_out(outs)
    assert [g[0].frame for g in got] == list(range(0, 200, 5))
    outs, port = run_port(beats, 200 * F + d + 100, delay=d + 2 * R, report_period=R, p=p)
    assert port.drop_count > 0


# ---- the register-level twin against a behavioural reference ------------------------
class RefPort:
    """Behavioural reference: the head leaves when now - time >= delay + K - 1 and the
    output register is free (the old single-cycle port with K - 1 instead of 2)."""
    def __init__(self, p, k=FIXED_LATENCY):
        self.p, self.k = p, k
        self.reset()

    def reset(self):
        self.now = 0; self.fifo = []; self.out_valid = False; self.out = None
        self.in_frame = False; self.admit = False; self.have_admit = False
        self.last_admit = 0; self.drop_count = 0; self.skip_count = 0; self.overflow = False

    def tick(self, in_valid, in_event=None, in_last=False, ready=True, delay=0, report_period=0):
        p = self.p; tmask = (1 << p.time_w) - 1; cmax = (1 << p.cnt_w) - 1
        fired = None
        if self.out_valid and ready:
            ev, t, last = self.out
            fired = PortOut(self.now, ev, t, last)
        head = self.fifo[0] if self.fifo else None
        elig = head is not None and ((self.now - head[1]) & tmask) >= delay + self.k - 1
        pop = elig and (not self.out_valid or ready)
        first = in_valid and not self.in_frame
        room = (p.depth - len(self.fifo)) >= p.max_ev
        decim_ok = (report_period == 0 or not self.have_admit
                    or ((self.now - self.last_admit) & tmask) >= report_period)
        decide = room and decim_ok
        admit_cur = decide if first else self.admit
        wr = in_valid and admit_cur and len(self.fifo) < p.depth
        if first:
            if decide:
                self.last_admit = self.now; self.have_admit = True
            elif decim_ok:
                self.drop_count = min(cmax, self.drop_count + 1); self.overflow = True
            else:
                self.skip_count = min(cmax, self.skip_count + 1)
            self.admit = decide
        if in_valid:
            self.in_frame = not in_last
        if pop:
            self.out = self.fifo.pop(0); self.out_valid = True
        elif ready:
            self.out_valid = False
        if wr:
            self.fifo.append((in_event, self.now, bool(in_last)))
        self.now = (self.now + 1) & tmask
        return fired



def _run(cls, beats, n, ready, delay, period, p):
    port = cls(p)
    out = []
    for c in range(n):
        b = beats.get(c)
        f = port.tick(b is not None, b[0] if b else None, b[1] if b else False,
                      bool(ready[c]) if ready else True, delay, period)
        if f:
            out.append((c, f.event, f.time, f.last))
    return out, (port.drop_count, port.skip_count, port.overflow)


@pytest.mark.parametrize("seed", range(4))
def test_twin_equals_reference(seed):
    """The pipelined port (read-ahead window, pop decision registered one cycle ahead)
    behaves exactly as the single-cycle reference with the head leaving at
    age >= delay + FIXED_LATENCY - 1: same handshake cycles, events, time stamps and
    counters, under random frames, stalls, dials and report periods."""
    rng = random.Random(seed)
    for _ in range(100):
        p = PortParams(depth=rng.choice([16, 32, 64]), max_ev=rng.choice([2, 4, 8]))
        beats, c, f = {}, rng.randrange(0, 5), 0
        n = rng.randrange(200, 1200)
        while c < n - 50:
            k = rng.randrange(0, p.max_ev + 1)
            for i in range(k):
                beats[c] = ((f, i), i == k - 1)
                c += 1
                if rng.random() < 0.2:
                    c += rng.randrange(1, 4)
            f += 1
            c += rng.choice([0, 0, 1, 2, 5, 20])
        mode = rng.randrange(4)
        ready = None if mode == 0 else [int(rng.random() < (1, .9, .5, .2)[mode]) for _ in range(n)]
        if mode == 3:
            ready = [1 if (cc // 60) % 3 else r for cc, r in enumerate(ready)]
        delay = rng.choice([0, 0, 1, 2, 3, 5, 17, 100])
        period = rng.choice([0, 0, 0, 1, 2, 7, 30])
        assert _run(EventPort, beats, n, ready, delay, period, p) == \
            _run(RefPort, beats, n, ready, delay, period, p)
