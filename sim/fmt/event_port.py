"""Touch-event port: cycle-level twin of ``rtl/fmt_event_port.v``.

The port takes the tracker's event stream (one beat per cycle at most, no
back-pressure, ``last`` on each frame's last event), time-stamps each event with the
processing-clock counter ``now`` of the cycle it arrives (``ev_time``), buffers it in
a FIFO of ``depth`` entries (inferred block RAM) and presents it on a valid/ready
output.

Fixed pipeline: an event that arrives in cycle c is on the output (``ev_valid``) in
cycle ``c + FIXED_LATENCY`` (= 5: RAM write, RAM read, head register, eligibility
register, output register) when the dial is 0, the consumer is ready and nothing
queues in front of it.

Dial-a-latency: the head event leaves only when ``now - ev_time >= delay + 4``
(modulo 2^TIME_W), so with ``delay`` = D the event is on the output in cycle exactly
``c + 5 + D``: the dial adds exactly D cycles, zero at D = 0.  Events keep their input
spacing, so this holds for every event while the FIFO does not overflow.  Maximum
delay without loss: the FIFO must hold every event younger than D, so D_max =
(depth / max_ev - 1) admitted frames (a frame may bring up to ``max_ev`` events); at
the default depth 2048, max_ev 32 that is 63 frames: 387 us at every frame
(162.76 kHz); with a report period (at most one frame per ``report_period`` cycles
enters the FIFO) of 4 ms (250 Hz) it is 252 ms, enough for the paper's 150 ms.

Structure (the RTL's registers): the RAM is read ahead through a chain of registers,
its read register ``q`` (in the block RAM), ``next`` (the flip-flops the read data goes
into) and ``head``; each moves when the one after it is free.  The decision that the
head leaves (``elig``) is a register computed one cycle ahead from the head's and the
next entry's time stamps against ``now + 1``, so nothing decided in a cycle depends on
the RAM's output.
The settings ``delay`` and ``report_period`` act one cycle after they change.

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

from dataclasses import dataclass

FIXED_LATENCY = 5
NEED_EXTRA = FIXED_LATENCY - 1        # the head leaves the RAM when age >= delay + 4



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
        self.mem = [None] * p.depth    # the RAM (no reset)
        self.reset()

    def reset(self):
        p = self.p
        tmask = (1 << p.time_w) - 1
        self.now = 0
        self.nxt = 1                   # now + 1
        self.need = NEED_EXTRA         # delay + 4 of the previous cycle (delay 0 at reset)
        self.wr_ptr = 0
        self.rd_ptr = 0                # next RAM address to read
        self.count = 0                 # events held (RAM, read register, window)
        self.room = True               # count <= depth - max_ev
        self.not_full = True           # count < depth
        self.q = None                  # RAM read register: (event, time, last)
        self.q_v = False
        self.n = None                  # next register (the RAM read data's first flip-flops)
        self.n_v = False
        self.h = None                  # head register
        self.h_v = False
        self.elig = False              # the head may leave this cycle (its age >= need)
        self.out_valid = False
        self.out = None
        self.in_frame = False
        self.admit = False
        self.have_admit = False
        self.last_admit_m1 = tmask     # last admitted first event's time - 1
        self.dok = True                # report-rate condition for a first event this cycle
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
        pop = self.elig and (not self.out_valid or ready)
        # read pipeline: RAM -> read register q -> next -> head (each moves when the one
        # after it is free)
        keep_h = self.h_v and not pop
        n_hold = keep_h and self.n_v                   # next cannot move into head
        q_hold = n_hold and self.q_v                   # read register cannot move into next
        issue = self.wr_ptr != self.rd_ptr and not q_hold
        # eligibility of the next cycle's head, from registers only
        r_h = self.h_v and ((self.nxt - self.h[1]) & tmask) >= self.need
        r_n = self.n_v and ((self.nxt - self.n[1]) & tmask) >= self.need
        elig = r_h if keep_h else r_n
        # input side
        first = in_valid and not self.in_frame
        decide = self.room and self.dok
        admit_cur = decide if first else self.admit
        wr = in_valid and admit_cur and self.not_full
        admit_now = first and decide
        if admit_now:
            dok = report_period <= 1
        else:
            dok = (report_period == 0 or not self.have_admit
                   or ((self.now - self.last_admit_m1) & tmask) >= report_period)
        # next state
        if first:
            if decide:
                self.last_admit_m1 = (self.now - 1) & tmask
                self.have_admit = True
            elif self.dok:
                self.drop_count = min(cmax, self.drop_count + 1)
                self.overflow = True
            else:
                self.skip_count = min(cmax, self.skip_count + 1)
            self.admit = decide
        self.dok = dok
        if in_valid:
            self.in_frame = not in_last
        if pop:
            self.out = self.h
            self.out_valid = True
        elif ready:
            self.out_valid = False
        if not keep_h:
            self.h = self.n
        if not n_hold:
            self.n = self.q
        self.h_v, self.n_v = keep_h or self.n_v, n_hold or self.q_v
        if issue:
            self.q = self.mem[self.rd_ptr]
            self.rd_ptr = (self.rd_ptr + 1) % p.depth
        self.q_v = issue or q_hold
        self.elig = elig
        if wr:
            self.mem[self.wr_ptr] = (in_event, self.now, bool(in_last))
            self.wr_ptr = (self.wr_ptr + 1) % p.depth
        self.count += (1 if wr else 0) - (1 if pop else 0)
        self.room = self.count <= p.depth - p.max_ev
        self.not_full = self.count < p.depth
        self.need = delay + NEED_EXTRA
        self.now = (self.now + 1) & tmask
        self.nxt = (self.nxt + 1) & tmask
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
