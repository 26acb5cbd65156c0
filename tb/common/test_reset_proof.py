"""scripts/reset_proof.py in make test: the quick blocks' reset proofs pass, and the
check fails on a block whose reset leaves out one register (so it can fail).  The
whole list runs with `make reset-proof`."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("reset_proof", ROOT / "scripts" / "reset_proof.py")
rp = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rp)

QUICK = ["fmt_pn_gen", "fmt_sorted_list", "fmt_report_fifo", "fmt_div", "fmt_regfile"]


@pytest.mark.parametrize("block", QUICK)
def test_reset_proof(block, tmp_path):
    top, ok, _, why = rp.prove(block, rp.BLOCKS[block], work=tmp_path / block)
    assert ok, f"{top}: {why}"


def test_mutant_without_a_reset_fails(tmp_path):
    """fmt_pn_gen with its receive-delay history left out of the reset: the receive
    sign then depends on the state before the reset, and the proof must fail."""
    src = (ROOT / "rtl" / "fmt_pn_gen.v").read_text()
    line = "            history_q    <= {DEPTH{1'b0}};\n"
    assert src.count(line) == 1, "the mutated line moved: update this test"
    mutant = tmp_path / "fmt_pn_gen.v"
    mutant.write_text(src.replace(line, ""))
    _, ok, _, why = rp.prove("fmt_pn_gen", rp.BLOCKS["fmt_pn_gen"], files=[mutant],
                             work=tmp_path / "work")
    assert not ok and "proof did fail" in why, why


def test_every_block_known():
    """Every listed block has a source list; skipped ones give a reason."""
    for b in rp.BLOCKS:
        assert rp.sources(b)
    assert all(rp.SKIPPED.values())


def test_too_shallow_is_refused(tmp_path):
    """A depth that never reaches the divider's output (valid after QW + 1 = 5 cycles)
    is reported, not passed: the data behind a valid must be compared at least once."""
    spec = dict(rp.BLOCKS["fmt_div"], depth=4)
    _, ok, _, why = rp.prove("fmt_div", spec, work=tmp_path / "div")
    assert not ok and "never high" in why, why
