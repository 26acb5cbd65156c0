"""scripts/mutate.py's mutations still apply: each original text occurs exactly once in
its RTL file, and each names an existing test (no simulation runs here; `make mutate`
runs them)."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("fmt_mutate", ROOT / "scripts" / "mutate.py")
mutate = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mutate)


@pytest.mark.parametrize("name", sorted(mutate.MUTATIONS))
def test_mutation_applies(name):
    path, old, new, node, why = mutate.MUTATIONS[name]
    text = (ROOT / path).read_text()
    assert text.count(old) == 1, f"{name}: original text found {text.count(old)} times in {path}"
    assert new != old and why
    test_file = ROOT / "tb" / node.split("::")[0]
    assert test_file.is_file(), node
    func = node.split("::")[1].split("[")[0]
    assert f"def {func}(" in test_file.read_text(), node
