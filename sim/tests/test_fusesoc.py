"""fmt_core.core (FuseSoC CAPI2) is current with its sources (scripts/gen_fusesoc.py:
rtl/filelists/fmt_core.f, rtl/fmt_core.v, rtl/fmt_defaults.vh) and FuseSoC's own parser
accepts it: `fusesoc core show`, then `fusesoc run --setup` of every target writes the
tool's project with every source, header, ROM and parameter."""
from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CORE = ROOT / "fmt_core.core"


def gen():
    spec = importlib.util.spec_from_file_location("gen_fusesoc", ROOT / "scripts" / "gen_fusesoc.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_core_file_is_current():
    g = gen()
    assert CORE.read_text() == g.render(), "fmt_core.core is stale: run python scripts/gen_fusesoc.py"
    srcs, incs, roms = g.files()
    assert "rtl/fmt_core.v" in srcs and "rtl/fmt_defaults.vh" in incs and roms
    names = [p[0] for p in g.parameters()]
    assert names[:3] == ["ROWS", "COLS", "LOG2_N"] and "BLOBS" in names and "REGMAP_ID" not in names


def fusesoc():
    exe = shutil.which("fusesoc") or str(Path(sys.executable).parent / "fusesoc")
    if not Path(exe).exists():
        pytest.skip("fusesoc is not installed (pinned in requirements.txt: make setup)")
    return exe


def test_fusesoc_parses_the_core(tmp_path):
    exe = fusesoc()
    g = gen()
    name = g.NAME
    r = subprocess.run([exe, "--cores-root", str(ROOT), "core", "show", name], capture_output=True,
                       text=True, timeout=120, cwd=tmp_path)
    assert r.returncode == 0 and name in r.stdout, r.stdout + r.stderr
    for t in ("lint", "sim", "synth", "ise"):
        assert re.search(rf"^{t}\s*:", r.stdout, re.M), (t, r.stdout)
    srcs, incs, roms = g.files()
    for target, tool in (("lint", "verilator"), ("sim", "icarus"), ("synth", "yosys"), ("ise", "ise")):
        r = subprocess.run([exe, "--cores-root", str(ROOT), "run", "--setup", "--build-root",
                            str(tmp_path / target), "--target", target, name],
                           capture_output=True, text=True, timeout=300, cwd=tmp_path)
        assert r.returncode == 0, (target, r.stdout + r.stderr)
        work = next((tmp_path / target).glob(f"*/{target}-{tool}"))
        text = "".join(p.read_text(errors="replace") for p in work.iterdir() if p.is_file()
                       and p.suffix in (".scr", ".vc", ".tcl", ".eda", ".yml", ".xtcl", ".mk", "")
                       and p.stat().st_size < 2_000_000)
        for s in srcs:
            assert Path(s).name in text, (target, s)
        if target == "sim":
            assert "fmt_core.ROWS=30" in text and "fmt_core.BLOBS=1" in text
            for rom in roms:
                assert (work / Path(rom).name).exists(), rom          # copied for $readmemh
        if target == "ise":
            assert "fmt_core.ucf" in text and "xc5vsx95t" in text

