"""``make sim`` (python -m bench.core.run_sim_rtl, C++ harness) with its output in a log, not
a terminal (issue #15 item 7): the progress comes as whole lines (no carriage return), at
most one per 10 % of the run or 10 s, and a clean run of the small scene exits 0 (a
dropped or missing frame or a golden mismatch exits 1: sim/tests/test_bad_input.py).
Verilator only; the harness is built at -O0 under its own tag."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.verilator_only
def test_run_sim_rtl_progress_in_a_log(sim, tmp_path):
    assert sim == "verilator"
    r = subprocess.run([sys.executable, "-m", "bench.core.run_sim_rtl",
                        "--scene", str(ROOT / "sim" / "scenes" / "small.json"), "--frames", "12",
                        "--no-plot", "--out", str(tmp_path), "--tag", "tb_progress", "--cflags=-O0"],
                       capture_output=True, text=True, timeout=1200, cwd=ROOT,
                       env=dict(os.environ, PYTHONPATH=os.pathsep.join(
                           [str(ROOT), str(ROOT / "sim"), str(ROOT / "tb"), os.environ.get("PYTHONPATH", "")])))
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "\r" not in r.stderr and "\r" not in r.stdout
    prog = [ln for ln in r.stderr.splitlines() if "C++ harness): frame" in ln]
    assert 1 <= len(prog) <= 11, r.stderr
    assert "100%" in prog[-1]
    assert "dropped 0" in r.stdout and "golden mismatches 0" in r.stdout
