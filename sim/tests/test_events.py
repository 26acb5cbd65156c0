"""Event-port model: exact dial-a-latency, decimation, whole-frame drops under stalls."""
from __future__ import annotations

import random

import pytest

from fmt.events import FIXED_LATENCY, PortParams, frames_to_beats, run_port
from fmt.tracking import TouchEvent


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
    # before: frames whose last event left before the reset (c + 3 + 30 < 203)
    assert fr == [f for f in range(20) if 20 * f + 3 + 33 < 203 or f >= 11]
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
