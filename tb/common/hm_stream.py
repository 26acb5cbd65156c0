"""Heat-map stream driver shared by the testbenches of blocks that take the stream of
docs/ARCHITECTURE.md (hm_valid_i, hm_row_i, hm_data_i, hm_eof_i, hm_frame_i).

A schedule is a list with one item per cycle: ``None`` (idle), ``("row", r, values)``
or ``("eof", frame)``.  The TB passed in provides ``dut``, ``writable()``, ``pack(values)``
and a monitor cycle counter ``cycle``.

Why not a cocotb-bus ``BusDriver``: measured on fmt_localmax (small sensor, 300
frames, 26,400 cycles; a throw-away bench driving one schedule three ways), a BusDriver
fed one transaction per cycle gives the same candidate stream at the same speed (Icarus
21.0 k cycles/s against 20.0-20.6 k here; Verilator 44.0 k against 40.4-40.8 k), so it
brings nothing: the schedule is already one item per cycle, and
:func:`drive_hm_schedule` returns the cycle of each frame's last row and hm_eof that
the latency checks need (a BusDriver would need a callback per item for them).  The
output side uses cocotb-bus (tb/common/streams.py).
"""
from __future__ import annotations


def pack_row(values, w: int) -> int:
    """A heat-map row as the hm_data bus value: column c at bits [c*w +: w]."""
    v = 0
    for c, x in enumerate(values):
        v |= int(x) << (c * w)
    return v


def frame_schedule(rng, hms, n_rows: int, min_cycles, first_frame: int = 0,
                   gap_p: float = 0.0, order=None) -> list:
    """Schedule of whole frames: the rows of each frame (shuffled by ``rng`` unless
    ``order`` is given), random idle gaps (probability ``gap_p`` per cycle), hm_eof right
    after the last row.  Frame i spans at least ``min_cycles[i]`` cycles: a short frame is
    stretched by idle cycles before its last row (the block must finish a frame before a
    later one arrives)."""
    sched = []
    for i, hm in enumerate(hms):
        rows = list(range(n_rows)) if order is None else list(order)
        if order is None:
            rng.shuffle(rows)
        fr = []
        for r in rows:
            while rng.random() < gap_p:
                fr.append(None)
            fr.append(("row", r, hm[r]))
        pad = max(0, min_cycles[i] - len(fr) - 1)
        fr = fr[:-1] + [None] * pad + fr[-1:]
        sched += fr + [("eof", (first_frame + i) & 0xFFFF)]
    return sched


async def drive_hm_schedule(tb, sched, idle=None):
    """Drive the schedule; returns (cycle of the last row beat, cycle of hm_eof) per
    frame, in the TB's monitor cycle numbers.  ``idle``: if given, a function returning
    the (hm_row_i, hm_data_i, hm_frame_i) values to drive in every cycle without a row
    beat (hm_frame_i: without a row beat or hm_eof), e.g. X or garbage: the block must
    ignore them while hm_valid_i and hm_eof_i are low."""
    d = tb.dut
    marks, last_row = [], None
    for item in sched:
        await tb.writable()
        d.hm_valid_i.value = 0
        d.hm_eof_i.value = 0
        if idle is not None and (item is None or item[0] != "row"):
            row, data, frame = idle()
            d.hm_row_i.value = row
            d.hm_data_i.value = data
            if item is None:
                d.hm_frame_i.value = frame
        if item is not None and item[0] == "row":
            d.hm_valid_i.value = 1
            d.hm_row_i.value = item[1]
            d.hm_data_i.value = tb.pack(item[2])
            last_row = tb.cycle + 1
        elif item is not None:
            d.hm_eof_i.value = 1
            d.hm_frame_i.value = item[1]
            marks.append((last_row, tb.cycle + 1))
    await tb.writable()
    d.hm_valid_i.value = 0
    d.hm_eof_i.value = 0
    if idle is not None:
        d.hm_row_i.value, d.hm_data_i.value, d.hm_frame_i.value = idle()
    return marks
