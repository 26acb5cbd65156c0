"""Progress display of the long tools (``make sim``, the model run, the report sweep).

On a terminal the line is rewritten in place (carriage return); otherwise (a CI log, a
pipe, a file) whole lines are printed, at most one per ``every_pct`` percent of the work
or ``every_s`` seconds, whichever comes first, plus the final one.
"""
from __future__ import annotations

import sys
import time


def is_tty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class Progress:
    """``p = Progress(total); p.update(done, text); ...; p.close()``."""

    def __init__(self, total: int, stream=None, tty: bool | None = None,
                 every_pct: float = 10.0, every_s: float = 10.0, clock=time.monotonic):
        self.total = max(1, int(total))
        self.stream = stream if stream is not None else sys.stderr
        self.tty = is_tty(self.stream) if tty is None else tty
        self.every_pct, self.every_s, self.clock = every_pct, every_s, clock
        self._last_t = clock()
        self._last_step = 0
        self._shown = False
        self._pending = None

    def update(self, done: int, text: str) -> None:
        pct = 100.0 * done / self.total
        if self.tty:
            self.stream.write(f"\r{text}")
            self.stream.flush()
            self._shown = True
            return
        step = int(pct // self.every_pct)
        now = self.clock()
        if step > self._last_step or now - self._last_t >= self.every_s or done >= self.total:
            self.stream.write(text.strip() + "\n")
            self.stream.flush()
            self._last_step, self._last_t, self._pending = step, now, None
        else:
            self._pending = text

    def close(self) -> None:
        """End the display: a newline on a terminal, the last unprinted state otherwise."""
        if self.tty:
            if self._shown:
                self.stream.write("\n")
                self.stream.flush()
        elif self._pending is not None:
            self.stream.write(self._pending.strip() + "\n")
            self.stream.flush()
            self._pending = None
