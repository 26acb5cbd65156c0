"""Cycle twin of rtl/fmt_report_fifo.v: the UART event stream's FIFO that admits a
frame's events all together or not at all, and only when no earlier report still waits
(the host gets whole, fresh reports).

``step`` is one clock: it takes the inputs of the cycle, returns the outputs seen during
it (out_valid, out_data, drop, drop_count: the combinational ones from the state before
the edge, the registered ones as they were) and then advances the state."""
from __future__ import annotations


class ReportFifo:
    def __init__(self, aw: int = 5):
        if aw < 1:
            raise ValueError(f"ReportFifo: aw = {aw}, must be >= 1")
        self.aw = aw
        self.depth = 1 << aw
        self.mem = [0] * self.depth
        self.reset()

    def reset(self) -> None:
        self.wp = self.cp = self.rp = 0      # pointers of aw + 1 bits
        self.skip = False
        self.mid = False
        self.drop = False
        self.drop_count = 0

    def _full(self) -> bool:
        return ((self.wp - self.rp) % (2 * self.depth)) == self.depth

    def step(self, en: bool, in_valid: bool, data: int, last: bool, out_ready: bool):
        m = 2 * self.depth
        out_valid = self.rp != self.cp
        out = (out_valid, self.mem[self.rp % self.depth], self.drop, self.drop_count)
        full = self._full()
        busy = not self.mid and self.wp != self.rp     # a frame starts, a report still waits
        ovf = in_valid and en and not self.skip and (full or busy)
        wr = in_valid and en and not self.skip and not ovf
        if wr:
            self.mem[self.wp % self.depth] = data
        mid_next = (not last) if in_valid else self.mid
        if not en:
            self.wp = self.cp = self.rp = 0
            self.skip = mid_next
        else:
            if out_valid and out_ready:
                self.rp = (self.rp + 1) % m
            if in_valid and self.skip:
                self.skip = not last
            elif ovf:
                self.wp = self.cp
                self.skip = not last
            elif wr:
                self.wp = (self.wp + 1) % m
                if last:
                    self.cp = self.wp
        self.mid = mid_next
        self.drop = ovf
        if ovf and self.drop_count != 0xFFFF:
            self.drop_count += 1
        return out
