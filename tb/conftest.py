"""pytest configuration for the cocotb testbenches.

The ``sim`` parameter runs each test under Icarus and Verilator; ``SIM=icarus`` or
``SIM=verilator`` picks one.  A test that is Verilator-only (full-size builds, which
Icarus is too slow for) marks itself with ``@pytest.mark.verilator_only``.  A test marked
``@pytest.mark.long_only`` runs only when ``FMT_LONG`` is set (``make test-long``): slow
duplicates of what ``make test`` already covers at a smaller size, kept out of its 20 minutes.
"""
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))

ALL_SIMS = ("icarus", "verilator")


def _selected_sims():
    s = os.environ.get("SIM", "").strip()
    if not s:
        return list(ALL_SIMS)
    sims = [x.strip() for x in s.split(",") if x.strip()]
    bad = [x for x in sims if x not in ALL_SIMS]
    if bad:
        raise pytest.UsageError(f"SIM={s}: unknown simulator(s) {bad}; use icarus and/or verilator")
    return sims


def pytest_configure(config):
    config.addinivalue_line("markers", "verilator_only: run under Verilator only (too slow for Icarus)")
    config.addinivalue_line("markers", "long_only: run only in make test-long (FMT_LONG=1)")


def pytest_collection_modifyitems(config, items):
    from common.runner import long_run
    if long_run():
        return
    skip = pytest.mark.skip(reason="make test-long (FMT_LONG=1) runs it; make test covers it at a smaller size")
    for item in items:
        if item.get_closest_marker("long_only"):
            item.add_marker(skip)


def pytest_generate_tests(metafunc):
    if "sim" in metafunc.fixturenames:
        sims = _selected_sims()
        if metafunc.definition.get_closest_marker("verilator_only"):
            sims = [s for s in sims if s == "verilator"]
        metafunc.parametrize("sim", sims)
