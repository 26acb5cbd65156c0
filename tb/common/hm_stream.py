"""Heat-map stream driver shared by the testbenches of blocks that take the stream of
docs/ARCHITECTURE.md (hm_valid_i, hm_row_i, hm_data_i, hm_eof_i, hm_frame_i).

A schedule is a list with one item per cycle: ``None`` (idle), ``("row", r, values)``
or ``("eof", frame)``.  The TB passed in provides ``dut``, ``writable()``, ``pack(values)``
and a monitor cycle counter ``cycle``.
"""
from __future__ import annotations


async def drive_hm_schedule(tb, sched):
    """Drive the schedule; returns (cycle of the last row beat, cycle of hm_eof) per
    frame, in the TB's monitor cycle numbers."""
    d = tb.dut
    marks, last_row = [], None
    for item in sched:
        await tb.writable()
        d.hm_valid_i.value = 0
        d.hm_eof_i.value = 0
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
    return marks
