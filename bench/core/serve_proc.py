"""The serving simulation as a child process: ``python -m bench.core.run_sim_rtl ... --serve 0``
in its own session (so that Ctrl-C and a kill reach the whole group), its stdout read by a
thread.  Used by the serve tests (tb/fmt_core, tb/fmt_fmtctl) and scripts/fuzz_ctrl.py."""
from __future__ import annotations

import os
import queue
import re
import signal
import subprocess
import sys
import threading
from pathlib import Path
import time

ROOT = Path(__file__).resolve().parents[2]
SERVING = re.compile(r"serving the RTL UART on (socket://(127\.0\.0\.1):(\d+))$")


class ServeFailed(RuntimeError):
    """The simulation did not start serving, or did not end."""


class ServeProc:
    """run_sim_rtl with ``args`` (they must include --serve); stderr goes to
    ``out_dir``/serve_stderr.txt."""

    def __init__(self, out_dir: Path, args: list[str]):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(ROOT), str(ROOT / "sim"), str(ROOT / "tb"), os.environ.get("PYTHONPATH", "")]))
        out_dir.mkdir(parents=True, exist_ok=True)
        self.err = open(out_dir / "serve_stderr.txt", "w+")
        self.proc = subprocess.Popen([sys.executable, "-m", "bench.core.run_sim_rtl", *args],
                                     cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=self.err,
                                     text=True, start_new_session=True)
        self.lines: queue.Queue = queue.Queue()
        self.out: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.put(line)
        self.lines.put(None)

    def wait_serving(self, wall_s: float = 240.0) -> re.Match:
        """The serving line's match (group 1: socket://HOST:PORT, 2: HOST, 3: PORT);
        ServeFailed (after a kill) if it does not come within wall_s."""
        t0 = time.monotonic()
        while time.monotonic() - t0 < wall_s:
            try:
                line = self.lines.get(timeout=1.0)
            except queue.Empty:
                continue
            if line is None:
                break
            self.out.append(line)
            m = SERVING.match(line.strip())
            if m:
                return m
        self.kill()
        self.err.seek(0)
        raise ServeFailed(f"the simulation did not start serving: {''.join(self.out)[-2000:]} "
                          f"{self.err.read()[-3000:]}")

    def finish(self, wall_s: float = 120.0) -> tuple[int, str]:
        """Wait for the end: (exit status, stdout + stderr); ServeFailed after a kill if
        it does not end within wall_s."""
        try:
            rc = self.proc.wait(timeout=wall_s)
        except subprocess.TimeoutExpired:
            self.kill()
            raise ServeFailed("the serving simulation did not end") from None
        while True:
            line = self.lines.get(timeout=10)
            if line is None:
                break
            self.out.append(line)
        self.err.seek(0)
        text = "".join(self.out) + self.err.read()
        self.err.close()
        return rc, text

    def interrupt(self):                    # Ctrl-C: SIGINT to the whole process group
        os.killpg(self.proc.pid, signal.SIGINT)

    def kill(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
