"""Latency-counter model: hand-worked numbers and saturation."""
from fmt.latency import LatencyCounters


def run(m, events):
    """events: {cycle: kwargs}; returns outputs 3 cycles after the last one (the
    statistics follow an event by 1 cycle, the histograms by 2)."""
    out = None
    for c in range(max(events) + 4):
        out = m.step(**events.get(c, {}))
    return out


def test_overlapping_frames():
    m = LatencyCounters()
    ev = {0: dict(frame_end=1, frame_end_slot=0),
          60: dict(frame_end=1, frame_end_slot=1),      # next frame ends before frame 0's events
          80: dict(ev_fire=1, ev_slot=0),               # frame 0 first: 80
          90: dict(ev_fire=1, ev_slot=0, ev_last=1),    # frame 0 last: 90
          150: dict(ev_fire=1, ev_slot=1, ev_last=1)}   # frame 1 first and last: 90
    o = run(m, ev)
    assert (o["first_min"], o["first_max"], o["first_count"]) == (80, 90, 2)
    assert (o["last_min"], o["last_max"], o["last_count"]) == (90, 90, 2)
    assert m.hist["first"][2] == 2          # 80 and 90 both fall in bin 2 (64..95)


def test_saturation():
    m = LatencyCounters(cnt_w=8)
    o = run(m, {0: dict(frame_end=1), 300: dict(ev_fire=1, ev_last=1)})
    assert o["first_last"] == 255 and o["last_last"] == 255 and o["sat"] == 1
    assert m.hist["first"][255 >> 5] == 1   # a saturated value lands in bin 7


def test_trigger_includes_synchroniser():
    m = LatencyCounters()
    o = run(m, {10: dict(trig=1), 11: dict(trig=1), 40: dict(ev_fire=1, ev_new=1)})
    assert o["trig_last"] == 30 and o["trig_count"] == 1 and o["trig_armed"] == 0


def test_back_to_back_same_bin_and_clear():
    """Pipelined read-modify-write: events on consecutive cycles into one bin all count
    (forwarding); a clear drops the events still in the pipeline."""
    m = LatencyCounters()
    ev = {f: dict(frame_end=1, frame_end_slot=f) for f in range(4)}
    ev.update({100 + f: dict(ev_fire=1, ev_slot=f, ev_last=1) for f in range(4)})
    run(m, ev)
    assert m.hist["first"][3] == 4 and m.hist["last"][3] == 4
    assert m.out["first_count"] == 4 and m.out["last_min"] == 100
    ev = {f: dict(frame_end=1, frame_end_slot=f) for f in range(4)}
    ev.update({100: dict(ev_fire=1, ev_slot=0, ev_last=1), 101: dict(ev_fire=1, ev_slot=1),
               102: dict(clear=1), 110: dict(ev_fire=1, ev_slot=2)})
    o = run(m, ev)
    assert o["first_count"] == 1 and o["last_count"] == 0 and o["first_min"] == 108   # slot 2 ended at cycle 2
    assert sum(m.hist["first"]) == 1 and sum(m.hist["last"]) == 0
