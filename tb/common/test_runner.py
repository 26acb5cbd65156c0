"""tb/common/runner.py: a change in an `include'd header rebuilds an Icarus simulation
(cocotb's runner looks only at the sources' times), and a failing cocotb test raises also
outside pytest (cocotb's runner checks the results only under pytest).  Works on a
temporary copy of rtl/, never on the tree."""
import os
import shutil
from pathlib import Path

import pytest

from common.runner import ROOT, SimulationFailed, run_cocotb

SMOKE = '''
import cocotb
from cocotb.triggers import Timer


@cocotb.test()
async def smoke(dut):
    dut.crc_i.value = 0xFFFF
    dut.data_i.value = 0x31
    await Timer(1, "ns")
    assert int(dut.crc_o.value) == int(__import__("os").environ["WANT"], 0)
'''


def _run(tmp_path, rtl, want="0xc782"):
    run_cocotb(sim="icarus", toplevel="fmt_crc16", sources=[rtl / "fmt_crc16.v"],
               test_module="smoke_cocotb", test_dir=tmp_path, includes=[rtl],
               build_root=tmp_path / "build",
               extra_env={"WANT": want,
                          "PYTHONPATH": os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])})


def test_include_change_rebuilds_icarus(tmp_path):
    if not shutil.which("iverilog"):
        pytest.skip("no Icarus")
    rtl = tmp_path / "rtl"
    shutil.copytree(ROOT / "rtl", rtl, ignore=shutil.ignore_patterns("filelists", "ref"))
    (tmp_path / "smoke_cocotb.py").write_text(SMOKE)
    _run(tmp_path, rtl)                                  # builds and passes
    _run(tmp_path, rtl)                                  # reused, passes
    with open(rtl / "fmt_defaults.vh", "a") as f:         # the .v files stay older than the build
        f.write("\nthis is not verilog;\n")
    with pytest.raises((RuntimeError, SystemExit)):
        _run(tmp_path, rtl)
    with pytest.raises((RuntimeError, SystemExit)):      # the failed build is not reused either
        _run(tmp_path, rtl)


def test_failing_cocotb_test_raises_outside_pytest(tmp_path, monkeypatch):
    if not shutil.which("iverilog"):
        pytest.skip("no Icarus")
    (tmp_path / "smoke_cocotb.py").write_text(SMOKE)
    monkeypatch.delenv("PYTEST_CURRENT_TEST", raising=False)   # as scripts/replay_*.py run it
    _run(tmp_path, ROOT / "rtl")
    with pytest.raises(SimulationFailed, match="1 of 1"):
        _run(tmp_path, ROOT / "rtl", want="0x1234")
