"""Touch-event port: cycle-level twin of ``rtl/fmt_event_port.v``.

The port takes the tracker's event stream (one beat per cycle at most, no
back-pressure, ``last`` on each frame's last event), time-stamps each event with the
processing-clock counter ``now`` of the cycle it arrives (``ev_time``), buffers it in
a FIFO of ``depth`` entries (inferred block RAM) and presents it on a valid/ready
output.

Fixed pipeline: an event that arrives in cycle c is on the output (``ev_valid``) in
cycle ``c + FIXED_LATENCY`` (= 3: RAM write, RAM read, output register) when the dial
is 0, the consumer is ready and nothing queues in front of it.

Dial-a-latency: the head event leaves the RAM only when ``now - ev_time >= delay + 2``
(modulo 2^TIME_W), so with ``delay`` = D the event is on the output in cycle exactly
``c + 3 + D``: the dial adds exactly D cycles, zero at D = 0.  Events keep their input
spacing, so this holds for every event while the FIFO does not overflow.  Maximum
delay without loss: the FIFO must hold every event younger than D, so D_max =
(depth / max_ev - 1) admitted frames (a frame may bring up to ``max_ev`` events); at
the default depth 2048, max_ev 32 that is 63 frames: 387 us at every frame
(162.76 kHz); with a report period (at most one frame per ``report_period`` cycles
enters the FIFO) of 4 ms (250 Hz) it is 252 ms, enough for the paper's 150 ms.

Admission (decided at a frame's first event, applied to the whole frame):
  * report-rate decimation: if ``report_period`` > 0 and fewer than ``report_period``
    cycles passed since the last admitted frame's first event, the frame is skipped
    (``skip_count``);
  * room: the frame is admitted only if ``depth - count >= max_ev`` (room for the
    largest possible frame); else the whole frame is dropped (``drop_count``, sticky
    ``overflow``).  A frame is thus never split and an event never corrupted, however
    long the consumer stalls.
Counters saturate at 2^CNT_W - 1.

Rule of reset: the port and the tracker share ``rst`` (the port would take the tail of
a frame cut by a port-only reset for a whole frame).
"""
from __future__ import annotations

from dataclasses import dataclass, field

FIXED_LATENCY = 3


@dataclass(frozen=True)
class PortParams:
    depth: int = 2048          # FIFO entries (power of two)
    max_ev: int = 32           # room reserved per frame (2 x MAX_TOUCHES)
    time_w: int = 32           # time stamp / delay / report period width
    cnt_w: int = 16            # drop / skip counter width


@dataclass
class PortOut:
    cycle: int                 # cycle of the handshake (valid & ready); port time in tick()
    event: object              # whatever was given as input event (TouchEvent)
    time: int                  # ev_time
    last: bool                 # ev_last


class EventPort:
    """Register-level model.  Call :meth:`tick` once per clock cycle."""

    def __init__(self, p: PortParams = PortParams()):
        self.p = p
        self.reset()

    def reset(self):
        self.now = 0
        self.mem = [None] * self.p.depth
        self.wr_ptr = 0
        self.rd_ptr = 0
        self.count = 0
        self.head_ok = False
        self.head = None           # (event, time, last)
        self.out_valid = False
        self.out = None
        self.in_frame = False
        self.admit = False
        self.have_admit = False
        self.last_admit = 0
        self.drop_count = 0
        self.skip_count = 0
        self.overflow = False

    # outputs of the current cycle (registers)
    def outputs(self):
        return self.out_valid, self.out

    def tick(self, in_valid: bool, in_event=None, in_last: bool = False, ready: bool = True,
             delay: int = 0, report_period: int = 0):
        """Advance one cycle.  Returns the PortOut handshaken in this cycle, or None."""
        p = self.p
        tmask = (1 << p.time_w) - 1
        cmax = (1 << p.cnt_w) - 1
        fired = None
        if self.out_valid and ready:
            ev, t, last = self.out
            fired = PortOut(self.now, ev, t, last)
        eligible = self.head_ok and ((self.now - self.head[1]) & tmask) >= delay + 2
        pop = eligible and (not self.out_valid or ready)
        # input side
        first = in_valid and not self.in_frame
        room = (p.depth - self.count) >= p.max_ev
        decim_ok = (report_period == 0 or not self.have_admit
                    or ((self.now - self.last_admit) & tmask) >= report_period)
        decide = room and decim_ok
        admit_cur = decide if first else self.admit
        wr = in_valid and admit_cur and self.count < p.depth
        # next state
        old_mem_rd = self.mem[(self.rd_ptr + (1 if pop else 0)) % p.depth]
        if first:
            if decide:
                self.last_admit = self.now
                self.have_admit = True
            elif decim_ok:
                self.drop_count = min(cmax, self.drop_count + 1)
                self.overflow = True
            else:
                self.skip_count = min(cmax, self.skip_count + 1)
            self.admit = decide
        if in_valid:
            self.in_frame = not in_last
        if pop:
            self.out = self.head
            self.out_valid = True
        elif ready:
            self.out_valid = False
        if wr:
            self.mem[self.wr_ptr] = (in_event, self.now, bool(in_last))
            self.wr_ptr = (self.wr_ptr + 1) % p.depth
        self.head_ok = (self.count - (1 if pop else 0)) > 0
        self.head = old_mem_rd
        if pop:
            self.rd_ptr = (self.rd_ptr + 1) % p.depth
        self.count += (1 if wr else 0) - (1 if pop else 0)
        self.now = (self.now + 1) & tmask
        return fired


def run_port(beats: dict, n_cycles: int, ready=None, delay: int = 0, report_period: int = 0,
             p: PortParams = PortParams(), reset_at=()):
    """Simulate ``n_cycles`` cycles.  ``beats``: {cycle: (event, last)} input beats
    (cycle 0 = first cycle after reset); ``ready``: sequence of 0/1 per cycle (default
    all 1); ``reset_at``: cycles in which ``rst`` is high (state cleared at the end of
    that cycle, as a synchronous reset; no input is taken then).
    Returns (list of PortOut, port)."""
    port = EventPort(p)
    out = []
    resets = set(reset_at)
    for c in range(n_cycles):
        r = True if ready is None else bool(ready[c])
        if c in resets:
            port.reset()
            continue
        b = beats.get(c)
        f = port.tick(b is not None, b[0] if b else None, b[1] if b else False, r,
                      delay, report_period)
        if f is not None:
            f.cycle = c                # run_port's cycle count (the port's own restarts at reset)
            out.append(f)
    return out, port


def frames_to_beats(frame_events, start: int = 0, gap: int = 0, period: int | None = None):
    """Lay out a list (per frame) of event lists as input beats: one event per cycle,
    ``last`` on a frame's last event; frame k starts at ``start + k * period`` (or right
    after the previous frame plus ``gap`` idle cycles when period is None)."""
    beats = {}
    c = start
    for k, evs in enumerate(frame_events):
        if period is not None:
            c = start + k * period
        for i, e in enumerate(evs):
            beats[c] = (e, i == len(evs) - 1)
            c += 1
        c += gap
    return beats
