"""scripts/xst_pack_estimate.py on a hand-made netlist: which flip-flops count as packable."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("xpe", ROOT / "scripts" / "xst_pack_estimate.py")
xpe = importlib.util.module_from_spec(spec)
spec.loader.exec_module(xpe)

FF_DIRS = {"C": "input", "CE": "input", "D": "input", "Q": "output", "R": "input"}


def ff(d, q):
    return {"type": "FDRE", "port_directions": FF_DIRS,
            "connections": {"C": [1], "CE": ["1"], "D": [d], "Q": [q], "R": ["0"]}}


def test_counts(tmp_path):
    cells = {
        # two-stage A register (10 -> 11 -> A), a B register shared by a LUT (not packable)
        "a1": ff(9, 10), "a2": ff(10, 11), "b1": ff(12, 13),
        "lut": {"type": "LUT2", "port_directions": {"I0": "input", "I1": "input", "O": "output"},
                "connections": {"I0": [13], "I1": [9], "O": [14]}},
        "dsp": {"type": "DSP48E", "port_directions": {"A": "input", "B": "input", "P": "output"},
                "connections": {"A": [11], "B": [13], "P": [20, 21]}},
        # P[0] only into a flip-flop (PREG), P[1] also into the LUT-fed FF and another load
        "p0": ff(20, 30), "p1": ff(21, 31), "p1b": ff(21, 32),
        "ram": {"type": "RAMB18SDP", "port_directions": {"DO": "output", "DI": "input"},
                "connections": {"DO": [40], "DI": [14]}},
        "r0": ff(40, 41),
    }
    net = {"modules": {"top": {"attributes": {"top": 1}, "cells": cells, "netnames": {}}}}
    p = tmp_path / "n.json"
    p.write_text(json.dumps(net))
    r = xpe.estimate(str(p))
    assert r["ff"] == 7
    assert (r["dsp_in"], r["dsp_in2"], r["dsp_out"], r["ram_out"]) == (1, 1, 1, 1)
    assert r["fabric_after"] == 3 and r["dsp48e"] == 1 and r["ramb"] == 1
    assert xpe.main([]) == 2 and xpe.main([str(tmp_path / "missing.json")]) == 2
